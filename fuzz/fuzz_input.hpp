// SPDX-License-Identifier: GPL-3.0-or-later
// What the fuzz targets share: libFuzzer's bytes written as a file in a scratch folder of this
// process, and the one outcome allowed besides success: the reader's refusal (InputError, or
// RunError for a sample that cannot be built). Any other exception is a defect: the program
// would end in "internal error" (exit 4) instead of naming the file, the key and what was
// expected. Crashes, leaks of control (UB) and memory errors are caught by ASan and UBSan.
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/error.hpp"
#include "common/memory.hpp"

namespace arlequin::fuzz {

// The scratch folder of this process: <tmp>/arlequin_fuzz_<pid>/case/, with <tmp>/.../meshes a
// link to the source tree's meshes/, so that a case's "../meshes/x.geo" is found as from cases/.
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    const auto root = std::filesystem::temp_directory_path() / ("arlequin_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(root / "cases" / "fuzz");
    std::error_code ignored;
    std::filesystem::create_directory_symlink(std::filesystem::path(ARLEQUIN_SOURCE_DIR) / "meshes", root / "meshes", ignored);
    return root / "cases" / "fuzz";
  }();
  return dir;
}

inline std::filesystem::path write_input(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const auto path = scratch() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return path;
}

// Inputs may ask for any size: the budget refuses what a small machine would (common/memory.hpp:
// about 1 000 DEs, 500 mesh nodes), so an input is refused in microseconds instead of built
// for minutes.
inline void set_small_machine_budget() { memory_budget_bytes() = 5e5; }

template <class Read>
void expect_refusal_at_most(Read read) {
  try {
    read();
  } catch (const InputError&) {
  } catch (const RunError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: an exception other than the reader's refusal: %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: a thrown object that is not an exception\n");
    std::abort();
  }
}

}  // namespace arlequin::fuzz
