// Runs the `arlequin` executable as a user would and captures what it prints.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace arlequin::test {

struct CliResult {
  int exit_code = -1;
  std::string output;  // stdout or stderr, as asked
};

// args are appended to the executable path; stream: "stdout" or "stderr".
inline CliResult run_arlequin(const std::string& args, const std::string& stream = "stderr") {
  const std::string exe = std::string(ARLEQUIN_BINARY_DIR) + "/app/arlequin";
  const std::string redirect = stream == "stderr" ? " 2>&1 >/dev/null" : " 2>/dev/null";
  FILE* pipe = popen((exe + " " + args + redirect).c_str(), "r");
  CliResult r;
  std::array<char, 4096> buffer;
  while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe)) r.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A fresh scratch folder under the system temp directory.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("arlequin_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace arlequin::test
