// SPDX-License-Identifier: GPL-3.0-or-later
// The sample reader: libFuzzer's bytes as the particle table (dem.sample.table, CSV) of a case
// whose DEs are bonded where they touch and in contact elsewhere, so the bytes reach the
// table's parser, the bond search and the contact's neighbour grid.
#include <string_view>

#include "app/scene.hpp"
#include "fuzz_input.hpp"

namespace {
constexpr std::string_view table_case =
    "name: fuzz_table\n"
    "time: {end: 1.0e-6}\n"
    "dem:\n"
    "  density: 7800\n"
    "  sample: {build: particles, table: table.csv}\n"
    "  bond: {law: beam, E_mu: 2.0e11, r_mu: 0.5}\n"
    "  contact: {law: penalty, stiffness: 1.0e7}\n";
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  arlequin::fuzz::set_small_machine_budget();
  arlequin::fuzz::write_input("table_case.yaml", reinterpret_cast<const std::uint8_t*>(table_case.data()), table_case.size());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  arlequin::fuzz::write_input("table.csv", data, size);
  arlequin::fuzz::expect_refusal_at_most([&] { arlequin::app::build_scene(arlequin::fuzz::scratch() / "table_case.yaml", arlequin::app::writing_nothing({})); });
  return 0;
}
