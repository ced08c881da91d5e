// SPDX-License-Identifier: GPL-3.0-or-later
// The mesh reading path: libFuzzer's bytes as a gmsh .msh file, loaded as a continuum's mesh
// (gmsh's reader, then the tetrahedra, nodes and physical groups taken from it). Only .msh: a
// .geo is a script that gmsh runs (it can call the shell), so it is trusted input, not data.
#include "continuum/mesh.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  arlequin::fuzz::set_small_machine_budget();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = arlequin::fuzz::write_input("mesh.msh", data, size);
  arlequin::fuzz::expect_refusal_at_most([&] {
    arlequin::continuum::MeshSource source;
    source.path = file.string();
    arlequin::continuum::Mesh::load(source);
  });
  return 0;
}
