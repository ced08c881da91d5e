// SPDX-License-Identifier: GPL-3.0-or-later
// The case reader: libFuzzer's bytes as a case file, read as `arlequin check` reads one (the
// whole scene is built: YAML, schema, every section's reader, samples, meshes of the meshes/
// folder, the critical step), writing nothing.
#include "app/scene.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  arlequin::fuzz::set_small_machine_budget();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = arlequin::fuzz::write_input("case.yaml", data, size);
  arlequin::fuzz::expect_refusal_at_most([&] { arlequin::app::build_scene(file, arlequin::app::writing_nothing({})); });
  return 0;
}
