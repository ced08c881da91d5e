// SPDX-License-Identifier: GPL-3.0-or-later
// The stability suite (ctest -L stability; docs/stability.md): stiff and extreme inputs, each
// run through the `arlequin` executable as a user would. A row either runs with its energy
// error under a stated bound, and then a step 1 % above its critical step is refused with the
// limit, or it is refused (or stopped) with the reason. Rows named Validation* are the long ones
// (label validation as well); the others are in the default suite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "common/json.hpp"
#include "support/cli.hpp"

namespace arlequin {
namespace {

struct Row {
  std::string name;       // the test's name, and the limits table's row (docs/stability.md)
  std::string case_file;  // relative to the source tree
  std::string overrides;  // --set arguments, each one quoted
  double bound;           // largest |E_balance| over the energy scale; 0: the row is refused
  std::string refusal;    // refused rows: what the message says
  bool needs_continuum = false;
};

void PrintTo(const Row& row, std::ostream* os) { *os << row.name; }

std::string sets(std::initializer_list<std::string> overrides) {
  std::string args;
  for (const std::string& o : overrides) args.append(" --set '").append(o).append("'");
  return args;
}

// The energy error of a run: the largest |E_balance| over its series, divided by the largest
// energy the run held or exchanged (E_total, |W_external|, E_dissipated).
double energy_error(const std::filesystem::path& series) {
  double balance = 0.0, scale = 0.0;
  for (const auto& row : test::read_csv(series)) {
    balance = std::max(balance, std::abs(test::number(row, "E_balance")));
    scale = std::max({scale, std::abs(test::number(row, "E_total")), std::abs(test::number(row, "W_external")),
                      std::abs(test::number(row, "E_dissipated"))});
  }
  return scale > 0.0 ? balance / scale : balance;
}

class Stability : public ::testing::TestWithParam<Row> {
 protected:
  void check_row() {
    const Row& row = GetParam();
#ifndef ARLEQUIN_WITH_CONTINUUM
    if (row.needs_continuum) GTEST_SKIP() << "built without the continuum";
#endif
    const auto out = test::scratch_dir("stability_" + row.name);
    const std::string case_file = std::string(ARLEQUIN_SOURCE_DIR) + "/" + row.case_file;
    const auto run = test::run_arlequin("run " + case_file + " --quiet --out " + out.string() + row.overrides);
    if (row.bound == 0.0) {  // refused before the first step, or stopped with the reason
      EXPECT_NE(run.exit_code, 0) << run.output;
      EXPECT_NE(run.output.find(row.refusal), std::string::npos) << run.output;
      return;
    }
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const double error = energy_error(out / "series.csv");
    const Json summary = read_json_file(out / "summary.json");
    const double dt_c = summary.at("dt_critical").get<double>();
    std::printf("%s: energy error %.3g (bound %.3g), %ld steps, dt %.4g s, dt_c %.4g s\n", row.name.c_str(), error,
                row.bound, summary.at("steps").get<long>(), summary.at("dt").get<double>(), dt_c);
    EXPECT_LE(error, row.bound);
    // The same scene with a step 1 % above its critical step is refused before it starts.
    std::ostringstream above;
    above.precision(17);
    above << " --set time.dt=" << 1.01 * dt_c;
    const auto refused = test::run_arlequin("check " + case_file + row.overrides + above.str());
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_NE(refused.output.find("is above the critical time step"), std::string::npos) << refused.output;
  }
};
class ValidationStability : public Stability {};

TEST_P(Stability, RunsWithinItsEnergyBoundOrIsRefused) { check_row(); }
TEST_P(ValidationStability, RunsWithinItsEnergyBoundOrIsRefused) { check_row(); }

const std::string lattice = "tests/stability/data/lattice_two_materials.yaml";
const std::string packing = "tests/stability/data/packing_spread.yaml";
const std::string impact = "cases/demo_beam_impact/case.yaml";
const std::string bar = "cases/bar_wave_continuum/case.yaml";
const std::string coupled = "cases/wave_bar_coupled/case.yaml";

std::string soft(const std::string& key_value) {
  return sets({"dem.materials.soft.bond." + key_value, "dem.interface.bond." + key_value});
}
std::string all_r_mu(const std::string& r_mu) {
  return soft("r_mu=" + r_mu) + sets({"dem.materials.stiff.bond.r_mu=" + r_mu});
}
// The demo's ball at this speed, with this contact stiffness (N/m).
std::string ball(const std::string& speed, const std::string& stiffness) {
  return sets({"dem.sample.particles=[{position: [0.05, 0.003, 0.0115], radius: 0.003, velocity: [0, 0, -" + speed + "]}]",
               "dem.contact.stiffness=" + stiffness, "time.end=1e-4", "output.fields=[]"});
}
const std::string at_099 = sets({"time.safety=0.99"});
const std::string no_checks = sets({"checks=[]", "output.fields=[]"});

// Bounds: docs/stability.md gives each row's measured error; a bound is about 1.5x that
// (integrator error, O((omega dt)^2)) or 20x for round-off (a balance exact in exact arithmetic).
const std::vector<Row> quick_rows = {
    // DEM, bonded: the stiffness contrast, the beam radius, damping, 0.99 of the critical step.
    {"lattice_at_099", lattice, at_099, 2.1e-2, ""},
    {"lattice_at_099_for_61k_steps", lattice, at_099 + sets({"time.end=2e-2", "output.every=2e-5"}), 2.2e-2, ""},
    {"contrast_1e4", lattice, at_099 + soft("E_mu=2e7"), 2.0e-2, ""},
    {"contrast_1e4_soft_stiffer", lattice, at_099 + soft("E_mu=2e15"), 3.2e-6, ""},
    {"r_mu_001", lattice, at_099 + all_r_mu("0.01") + sets({"time.end=2e-2", "output.fields=[]"}), 1.2e-2, ""},
    {"r_mu_01", lattice, at_099 + all_r_mu("0.1") + sets({"time.end=2e-3"}), 4.5e-3, ""},
    {"r_mu_1", lattice, at_099 + all_r_mu("1.0"), 3.4e-2, ""},
    {"damping_1e4", lattice, at_099 + sets({"dem.damping=1e4"}), 1.6e-2, ""},
    {"damping_1e6", lattice, at_099 + sets({"dem.damping=1e6"}), 7e-4, ""},
    {"damping_1e8", lattice, at_099 + sets({"dem.damping=1e8"}), 1.1e-9, ""},
    {"damping_step_above_2_over_c", lattice, sets({"dem.damping=1e8", "time.dt=2.1e-8"}), 0.0,
     "is above the critical time step 1.99"},
    // DEM, random packings: the radius spread.
    {"packing_std_0", packing, at_099 + sets({"dem.sample.radius.std=0"}), 3.4e-2, ""},
    {"packing_std_015", packing, at_099, 3.5e-2, ""},
    {"packing_std_025", packing, at_099 + sets({"dem.sample.radius.std=0.25", "time.end=5e-4"}), 1.6e-2, ""},
    {"packing_std_045", packing, at_099 + sets({"dem.sample.radius.std=0.45", "dem.sample.bond_tolerance=0.1"}), 1.6e-3, ""},
    {"packing_std_05", packing, sets({"dem.sample.radius.std=0.5"}), 0.0, "relative_std x truncation must be below 1"},
    // DEM, impacts (time.safety 0.3, the demo's).
    {"impact_20", impact, ball("20", "2e7"), 8.2e-5, ""},
    {"impact_200", impact, ball("200", "2e9"), 3.1e-3, ""},
    {"impact_2000", impact, ball("2000", "2e9"), 1.2e-2, ""},
    {"impact_2000_stiff", impact, ball("2000", "2e10"), 1.7e-2, ""},
    {"impact_2000_soft_contact", impact, ball("2000", "2e7"), 0.0, "is too soft to stop this impact within the spheres"},
    {"impact_2000_at_099", impact, ball("2000", "2e10") + at_099, 0.0, "DEs at once: with its bonds and 2e+10 N/m per contact"},
    // Continuum, fe and nem: a nearly incompressible bar.
    {"continuum_nu_04999_fe", bar, at_099 + no_checks + sets({"continuum.material.nu=0.4999"}), 4.5e-10, "", true},
    {"continuum_nu_04999_nem", bar, at_099 + no_checks + sets({"continuum.material.nu=0.4999", "continuum.solver=nem",
                                                               "continuum.mesh.size=0.04"}), 1.5e-10, "", true},
    {"continuum_nu_05", bar, sets({"continuum.material.nu=0.5"}), 0.0, "continuum.material.nu", true},
    // Coupled, fe and nem: 0.99 of the critical step, the mass floor, a one-plane overlap, a
    // continuum 1e4 stiffer or softer than the DEM, a nearly incompressible continuum.
    {"coupled_at_099_fe", coupled, at_099 + no_checks, 4.4e-5, "", true},
    {"coupled_at_099_nem", coupled, at_099 + no_checks + sets({"continuum.solver=nem"}), 7e-5, "", true},
    {"coupled_mass_floor_1e6_fe", coupled, no_checks + sets({"coupling.mass_floor=1e-6"}), 7e-9, "", true},
    {"coupled_mass_floor_1e6_nem", coupled, no_checks + sets({"coupling.mass_floor=1e-6", "continuum.solver=nem"}), 1e-8, "", true},
    {"coupled_one_plane_overlap_fe", coupled,
     at_099 + no_checks + sets({"coupling.overlap.box=[[0.0435, -0.001, -0.001], [0.0445, 0.009, 0.009]]"}), 1.3e-4, "", true},
    {"coupled_one_plane_overlap_nem", coupled,
     at_099 + no_checks + sets({"coupling.overlap.box=[[0.0435, -0.001, -0.001], [0.0445, 0.009, 0.009]]", "continuum.solver=nem"}),
     2.8e-4, "", true},
    {"coupled_empty_overlap", coupled, sets({"coupling.overlap.box=[[0.0445, -0.001, -0.001], [0.0455, 0.009, 0.009]]"}), 0.0,
     "coupling.overlap: no DE lies in the overlap", true},
    {"coupled_continuum_1e4_stiffer_fe", coupled, at_099 + no_checks + sets({"continuum.material.E=6.13592e14"}), 2.3e-6, "", true},
    {"coupled_continuum_1e4_softer_nem", coupled,
     at_099 + no_checks + sets({"continuum.material.E=6.13592e6", "continuum.solver=nem"}), 1.2e-3, "", true},
    {"coupled_nu_04999_fe", coupled, at_099 + no_checks + sets({"continuum.material.nu=0.4999"}), 1.8e-6, "", true},
    {"coupled_nu_04999_nem", coupled, at_099 + no_checks + sets({"continuum.material.nu=0.4999", "continuum.solver=nem"}),
     7.5e-6, "", true},
};

const std::vector<Row> long_rows = {
    {"damping_1e9", lattice, at_099 + sets({"dem.damping=1e9"}), 5.5e-11, ""},
    {"impact_2000_stiffest", impact, ball("2000", "2e11"), 2.1e-2, ""},
    {"continuum_nu_04999_fe_p2", bar, at_099 + no_checks + sets({"continuum.material.nu=0.4999", "continuum.mesh.order=2"}), 1e-9,
     "", true},
    {"continuum_nu_04999_nem_fine", bar, at_099 + no_checks + sets({"continuum.material.nu=0.4999", "continuum.solver=nem"}),
     2.3e-10, "", true},
    {"coupled_at_099_fe_100x", coupled, at_099 + no_checks + sets({"time.end=5e-3", "output.every=1e-5"}), 5.7e-4, "", true},
    {"coupled_at_099_nem_100x", coupled, at_099 + no_checks + sets({"time.end=5e-3", "output.every=1e-5", "continuum.solver=nem"}),
     9e-4, "", true},
    {"coupled_mass_floor_1e7_fe", coupled, no_checks + sets({"coupling.mass_floor=1e-7"}), 6.2e-10, "", true},
    {"coupled_nu_04999_fe_p2", coupled, at_099 + no_checks + sets({"continuum.material.nu=0.4999", "continuum.mesh.order=2"}),
     1.8e-7, "", true},
};

std::string row_name(const ::testing::TestParamInfo<Row>& info) { return info.param.name; }
INSTANTIATE_TEST_SUITE_P(Quick, Stability, ::testing::ValuesIn(quick_rows), row_name);
INSTANTIATE_TEST_SUITE_P(Long, ValidationStability, ::testing::ValuesIn(long_rows), row_name);

}  // namespace
}  // namespace arlequin
