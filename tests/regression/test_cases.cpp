// SPDX-License-Identifier: GPL-3.0-or-later
// The cases of cases/ run through the `arlequin` executable, checked against their references.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <thread>
#include <type_traits>
#include <vector>

#include "app/runner.hpp"
#include "app/scene.hpp"
#include "app/sweep.hpp"
#include "common/error.hpp"
#include "common/interrupt.hpp"
#include "common/json.hpp"
#ifdef ARLEQUIN_WITH_CONTINUUM
#include "continuum/continuum_solver.hpp"
#endif
#include "dem/bonds/bond_set.hpp"
#include "dem/boundary.hpp"
#include "dem/contacts/contact_law.hpp"
#include "dem/sample_file.hpp"
#include "support/cli.hpp"
#include "support/omp_threads.hpp"

namespace arlequin {
namespace {

const std::string cases = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/";

// Every output was renamed into place: no ".tmp.<pid>" or ".part.<pid>" file is left.
bool no_temporary_files(const std::filesystem::path& dir) {
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.find(".tmp.") != std::string::npos || name.find(".part.") != std::string::npos) return false;
  }
  return true;
}

// The scratch folder of case `name` in the running test: a folder of the test's own, since
// ctest runs tests side by side and two tests running one case in one folder saw each other's
// temporary files.
std::string case_folder(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string folder = std::string(info->test_suite_name()) + "." + info->name() + "." + name;
  std::replace(folder.begin(), folder.end(), '/', '_');
  return folder;
}

Json run_case(const std::string& name, const std::string& extra = "") {
  const auto out = test::scratch_dir(case_folder(name));
  const auto r = test::run_arlequin("run " + cases + name + "/case.yaml --quiet --out " + out.string() + " " + extra);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"series.csv", "summary.json", "case.resolved.yaml"})
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
  EXPECT_TRUE(no_temporary_files(out));
  return read_json_file(out / "summary.json");
}

// What is stored plus what was lost less the work put in (the runs start at rest, from zero).
double energy_balance(const Json& summary) {
  const Json& e = summary.at("energies");
  return e.at("total").get<double>() + e.at("dissipated").get<double>() + e.at("fracture").get<double>() -
         e.at("external_work").get<double>();
}

// R1 chain through the case file: tip deflection P L^3 / (3 E I), the case's own checks (the
// run exits 0 only if they pass), and the energy balance. Bounds about 2x what the damped
// relaxation leaves at t = 0.25 s.
TEST(Cases, CantileverChainMatchesBeamTheory) {
  const Json s = run_case("cantilever_chain");
  EXPECT_EQ(s.at("status").get<std::string>(), "completed");
  const double inertia = std::numbers::pi * std::pow(0.5e-3, 4) / 4.0, deflection = 0.01 * std::pow(0.02, 3) / (3.0 * 1e11 * inertia);
  EXPECT_NEAR(s.at("sensors").at("tip_deflection").get<double>(), deflection, 1.5e-7 * deflection);
  EXPECT_NEAR(s.at("sensors").at("clamp_reaction").get<double>(), -0.01, 1e-11);
  ASSERT_EQ(s.at("checks").size(), 2u);
  for (const auto& check : s.at("checks")) EXPECT_TRUE(check.at("passed").get<bool>()) << check.dump();
  // Static equilibrium: half the load's work is stored, half was damped out.
  EXPECT_NEAR(energy_balance(s), 0.0, 8e-7 * s.at("energies").at("external_work").get<double>());
}

TEST(Cases, DemoBeamImpactConservesEnergyAndWritesFields) {
  const auto out = test::scratch_dir("demo");
  const auto r = test::run_arlequin("run " + cases + "demo_beam_impact/case.yaml --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json s = read_json_file(out / "summary.json");
  // The ball's kinetic energy, m = 7800 * 4/3 pi (3 mm)^3, v = 20 m/s, kept by velocity Verlet
  // (bound about 1.5x its oscillation about the shadow energy at the end).
  const double initial = 0.5 * 7800.0 * 4.0 / 3.0 * std::numbers::pi * std::pow(3e-3, 3) * 400.0;
  EXPECT_NEAR(s.at("energies").at("total").get<double>(), initial, 7e-5 * initial);
  EXPECT_TRUE(std::filesystem::exists(out / "fields.h5"));
  EXPECT_TRUE(std::filesystem::exists(out / "fields.xdmf"));
  EXPECT_TRUE(no_temporary_files(out));
  EXPECT_GT(s.at("counts").at("neighbour_rebuilds").get<std::int64_t>(), 0);
}

// The checks are stated for the whole case: a run cut short by --steps is not judged (it
// would fail them), and says so.
TEST(Cases, ChecksAreNotJudgedOnARunCutShortBySteps) {
  const auto out = test::scratch_dir("cut_short");
  const auto r = test::run_arlequin("run " + cases + "wave_bar_dem/case.yaml --quiet --steps 5 --out " + out.string(), "stdout");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("checks not evaluated: the run stopped at step 5 of "), std::string::npos) << r.output;
  const Json s = read_json_file(out / "summary.json");
  EXPECT_TRUE(s.at("checks").empty());
  EXPECT_NE(s.at("checks_skipped").get<std::string>().find("--steps"), std::string::npos);
#ifdef ARLEQUIN_WITH_CONTINUUM
  // A static case is one solve whatever --steps says: its checks are judged.
  const Json solved = run_case("cantilever_continuum", "--steps 0");
  EXPECT_TRUE(solved.at("checks").at(0).at("passed").get<bool>());
  EXPECT_FALSE(solved.contains("checks_skipped"));
#endif
}

// A maximum judged over a range of another column (`versus`, `over`; e.g. a peak load before a
// specimen splits) against the same maximum taken here from series.csv, and unrestricted: the
// wave reaches the probe in the run's second half, so the two differ by orders of magnitude.
TEST(Cases, ExtremumChecksOverARangeOfAnotherColumn) {
  const auto out = test::scratch_dir("extremum_over");
  const auto r = test::run_arlequin("run " + cases + "wave_bar_dem/case.yaml --quiet --out " + out.string() +
                                    " --set output.fields=[] --set \"checks=[{column: u_probe, statistic: max, versus: time, "
                                    "over: [0, 2.5e-5], at_most: 1, note: first half}, {column: u_probe, statistic: max, "
                                    "at_most: 1, note: whole run}]\"",
                                    "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  double first_half = -INFINITY, whole = -INFINITY;
  for (const auto& row : test::read_csv(out / "series.csv")) {
    const double u = std::stod(row.at("u_probe"));
    if (std::stod(row.at("time")) <= 2.5e-5) first_half = std::max(first_half, u);
    whole = std::max(whole, u);
  }
  const Json checks = read_json_file(out / "summary.json").at("checks");
  EXPECT_NEAR(checks.at(0).at("value").get<double>() / first_half, 1.0, 1e-11);  // series.csv keeps 12 digits
  EXPECT_NEAR(checks.at(1).at("value").get<double>() / whole, 1.0, 1e-11);
  EXPECT_LT(first_half, 1e-3 * whole);
  EXPECT_EQ(checks.at(0).at("kind").get<std::string>(), "maximum over time in [0, 2.5e-05]");
  // `over` belongs to a reference curve or an extremum.
  const auto bad = test::run_arlequin("check " + cases + "wave_bar_dem/case.yaml --set \"checks=[{column: u_probe, "
                                      "versus: time, over: [0, 1], at_most: 1, note: n}]\"");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("checks[0].versus: is read with a reference curve or with statistic: max | min"), std::string::npos)
      << bad.output;
}

// compare builds both scenes before it runs either: a bad second case, or two cases with no
// sensor in common, cost no run, nor does --ensemble without a whole number of pairs. sweep refuses an axis
// without values.
TEST(Cli, CompareAndSweepRefuseBadInputBeforeAnyRun) {
  const auto out = test::scratch_dir("compare_bad");
  auto r = test::run_arlequin("compare " + cases + "cantilever_chain/case.yaml " + cases + "wave_bar_dem/case.yaml --out " +
                              out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("shares no sensor column with"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out / "reference" / "series.csv"));
  r = test::run_arlequin("compare " + cases + "cantilever_chain/case.yaml " + (out / "missing.yaml").string() + " --out " +
                         out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("missing.yaml: cannot open case file"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out / "reference" / "series.csv"));
  r = test::run_arlequin("compare " + cases + "cantilever_chain/case.yaml " + cases + "cantilever_chain/case.yaml --ensemble 0");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--ensemble: expected a whole number of pairs from 1 to 1000, got '0'"), std::string::npos) << r.output;
  r = test::run_arlequin("sweep " + cases + "cantilever_chain/case.yaml --over dem.damping=,,");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--over dem.damping=,,: no values after '='"), std::string::npos) << r.output;
  // A bad value found at its run ends the sweep; the rows finished before it stay in sweep.csv.
  const auto sweep_out = test::scratch_dir("sweep_bad_value");
  r = test::run_arlequin("sweep " + cases + "cantilever_chain/case.yaml --set time.end=1e-3 --over dem.damping=400,abc --out " +
                         sweep_out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(test::read_text(sweep_out / "sweep.csv").find("\n400,11,0,"), std::string::npos);
  EXPECT_NE(r.output.find("--over dem.damping=abc: dem.damping: expected a number"), std::string::npos) << r.output;
}

// --steps takes a whole number >= 0 and nothing else: an empty value, spaces, a sign, a fraction
// or a number past a long are refused in one line, exit 2, before any run.
TEST(BadInput, StepsThatAreNotAWholeNumber) {
  for (const std::string bad : {"", " 5", "-1", "2.5", "5x", "99999999999999999999"}) {
    const auto r = test::run_arlequin("run " + cases + "cantilever_chain/case.yaml --quiet --steps '" + bad + "' --out " +
                                      test::scratch_path("steps_bad").string());
    EXPECT_EQ(r.exit_code, 2) << "'" << bad << "': " << r.output;
    EXPECT_NE(r.output.find("--steps: expected a whole number >= 0, got '" + bad + "'"), std::string::npos) << r.output;
  }
}

// compare's --set applies to both cases, --set-reference and --set-other to one, after it: each
// run's resolved case has its own, and a key the other case cannot take is refused under its
// option's name before any run (the pure DEM has no continuum to swap).
TEST(Cli, CompareSetsEachCaseApart) {
  const auto out = test::scratch_dir("compare_sides");
  const std::string chain = cases + "cantilever_chain/case.yaml ";
  auto r = test::run_arlequin("compare " + chain + chain + "--set time.end=2e-3 --set checks=[] --set dem.damping=300 --set-reference "
                              "dem.damping=200 --set-other dem.damping=100 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto damping = [&](const char* side) {
    const std::string text = test::read_text(out / side / "case.resolved.yaml");
    const std::size_t at = text.find("damping: ");
    return at == std::string::npos ? std::string() : text.substr(at + 9, text.find('\n', at) - at - 9);
  };
  EXPECT_EQ(damping("reference"), "200");
  EXPECT_EQ(damping("other"), "100");
  const auto bad_out = test::scratch_dir("compare_sides_bad");
  r = test::run_arlequin("compare " + chain + chain + "--set-other continuum.solver=nem --out " + bad_out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--set-other continuum.solver=nem: continuum"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(bad_out / "reference" / "series.csv"));
}

// compare --window COLUMN=LO:HI judges the reference's rows whose COLUMN lies in [LO, HI] only
// (docs/decisions.md#d51): the chain against itself less damped, over the middle of its run, gives
// the figures computed here from the two series over those rows, not those of the whole run; its
// plots are drawn against the window's column. A window on no column of both runs, or not of the
// form COLUMN=LO:HI, is refused before any run.
TEST(Cli, CompareOverAWindowJudgesItsRowsOnly) {
  const auto out = test::scratch_dir("compare_window");
  const std::string pair = "compare " + cases + "cantilever_chain/case.yaml " + cases + "cantilever_chain/case.yaml "
                           "--set time.end=2e-3 --set output.every=5e-5 --set checks=[] --set output.fields=[] "
                           "--set-other dem.damping=100 --out " + out.string();
  const auto r = test::run_arlequin(pair + " --window time=5e-4:1.5e-3", "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto a = test::read_csv(out / "reference" / "series.csv"), b = test::read_csv(out / "other" / "series.csv");
  // b's deflection at a's output times (its damping changes its step and output times), linear
  // between its rows; b's peak over its own rows in the window.
  double max_diff = 0, max_ref = 0, sum_diff = 0, sum_ref = 0, whole_diff = 0, whole_ref = 0, b_peak = 0;
  int rows = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double t = test::number(a[k], "time"), va = test::number(a[k], "tip_deflection");
    const double d = std::abs(test::value_at(b, "time", t, "tip_deflection") - va);
    whole_diff = std::max(whole_diff, d), whole_ref = std::max(whole_ref, std::abs(va));
    if (t < 5e-4 || t > 1.5e-3) continue;
    ++rows;
    max_diff = std::max(max_diff, d), max_ref = std::max(max_ref, std::abs(va));
    sum_diff += d * d, sum_ref += va * va;
  }
  for (const auto& row : b)
    if (const double t = test::number(row, "time"); 5e-4 <= t && t <= 1.5e-3)
      b_peak = std::max(b_peak, std::abs(test::number(row, "tip_deflection")));
  ASSERT_GE(rows, 19);
  EXPECT_NE(r.output.find("over the rows of cantilever_chain with time in [0.0005, 0.0015]: " + std::to_string(rows) + " of"),
            std::string::npos) << r.output;
  const Json c = read_json_file(out / "compare.json");
  EXPECT_EQ(c.at("window").at("column").get<std::string>(), "time");
  const double expected = max_diff / max_ref, whole = whole_diff / whole_ref;
  ASSERT_GT(std::abs(expected / whole - 1), 0.05);  // the window changes the figure
  ASSERT_EQ(c.at("sensors").at(0).at("sensor").get<std::string>(), "tip_deflection");
  EXPECT_NEAR(c.at("sensors").at(0).at("max_relative_difference").get<double>(), expected, 1e-9 * expected);
  const double rms = std::sqrt(sum_diff / sum_ref), peak = (b_peak - max_ref) / max_ref;
  EXPECT_NEAR(c.at("sensors").at(0).at("rms_relative_difference").get<double>(), rms, 1e-9 * rms);
  EXPECT_NEAR(c.at("sensors").at(0).at("peak_relative_difference").get<double>(), peak, 1e-9 * std::abs(peak));
  EXPECT_EQ(read_json_file(out / "plots.json").at("plots").at(0).at("x_label").get<std::string>(), "time [s]");
  // A window on a sensor column that holds every row: the whole run's figure, and the plots drawn
  // against that column (the other sensor's only).
  const auto along = test::run_arlequin(pair + " --window tip_deflection=-1:1", "stdout");
  ASSERT_EQ(along.exit_code, 0) << along.output;
  EXPECT_NEAR(read_json_file(out / "compare.json").at("sensors").at(0).at("max_relative_difference").get<double>(), whole,
              1e-9 * whole);
  const Json plots = read_json_file(out / "plots.json").at("plots");
  ASSERT_EQ(plots.size(), 1u);
  EXPECT_EQ(plots.at(0).at("x_label").get<std::string>(), "tip_deflection [m]");
  EXPECT_EQ(plots.at(0).at("y_label").get<std::string>(), "clamp_reaction [N]");

  for (const auto& [window, message] : std::vector<std::pair<std::string, std::string>>{
           {"tip_deflection", "--window 'tip_deflection': expected COLUMN=LO:HI with numbers LO <= HI"},
           {"time=2e-3:1e-3", "--window 'time=2e-3:1e-3': expected COLUMN=LO:HI"},
           {"time=0:x", "--window 'time=0:x': expected COLUMN=LO:HI"},
           {"Delta=0:1", "--window Delta=...: 'Delta' is not a column of both runs; they share time, tip_deflection, clamp_reaction"}}) {
    const auto bad_out = test::scratch_dir("compare_window_bad");
    const auto bad = test::run_arlequin("compare " + cases + "cantilever_chain/case.yaml " + cases +
                                        "cantilever_chain/case.yaml --window " + window + " --out " + bad_out.string());
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find(message), std::string::npos) << bad.output;
    EXPECT_FALSE(std::filesystem::exists(bad_out / "reference" / "series.csv"));
  }
  // A window beyond the runs is found once they have run: no figure over no row.
  const auto empty = test::run_arlequin(pair + " --window time=1:2");
  EXPECT_EQ(empty.exit_code, 2) << empty.output;
  EXPECT_NE(empty.output.find("--window time=...: no row of cantilever_chain's series.csv has time in [1, 2]"), std::string::npos)
      << empty.output;
}

// --out must name a folder that can be written: refused before the run, as bad input. `check`
// writes nothing and does not judge it.
TEST(BadInput, OutputFolderThatIsAFile) {
  const auto r = test::run_arlequin("run " + cases + "cantilever_chain/case.yaml --quiet --out /dev/null/x");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--out: cannot write the outputs to '/dev/null/x': '/dev/null' is not a folder"), std::string::npos)
      << r.output;
  const auto from_case = test::run_arlequin("run " + cases + "cantilever_chain/case.yaml --quiet --set output.dir=/dev/null/x");
  EXPECT_EQ(from_case.exit_code, 2) << from_case.output;
  EXPECT_NE(from_case.output.find("--set output.dir=/dev/null/x: output.dir: cannot write the outputs to '/dev/null/x'"),
            std::string::npos)
      << from_case.output;
  const auto checked = test::run_arlequin("check " + cases + "cantilever_chain/case.yaml --set output.dir=/dev/null/x", "stdout");
  EXPECT_EQ(checked.exit_code, 0) << checked.output;
}

// An overlap that misses the mesh or the DEs is reported at the overlap's line.
TEST(BadInput, OverlapMissingTheModelsNamesTheOverlap) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::string check = "check " + cases + "wave_bar_coupled/case.yaml --set coupling.overlap.box=";
  const auto beyond_mesh = test::run_arlequin(check + "[[5,5,5],[6,6,6]]");
  EXPECT_EQ(beyond_mesh.exit_code, 2) << beyond_mesh.output;
  EXPECT_NE(beyond_mesh.output.find("every tetrahedron lies in the pure-DEM zone of coupling.overlap (" + cases +
                                    "wave_bar_coupled/case.yaml:27: box (5, 5, 5)-(6, 6, 6)"),
            std::string::npos)
      << beyond_mesh.output;
  const auto no_de = test::run_arlequin(check + "[[0.044,0.02,-0.001],[0.060,0.03,0.009]]");
  EXPECT_EQ(no_de.exit_code, 2) << no_de.output;
  EXPECT_NE(no_de.output.find("wave_bar_coupled/case.yaml:27: coupling.overlap: no DE lies in the overlap"),
            std::string::npos)
      << no_de.output;
}

TEST(Cases, BondedBlockShortRunBalancesEnergyWithoutContactSearch) {
  const Json s = run_case("bonded_block_tension", "--steps 50");
  EXPECT_EQ(s.at("steps").get<std::int64_t>(), 50);
  EXPECT_EQ(s.at("counts").at("particles").get<std::int64_t>(), 20000);
  EXPECT_FALSE(s.at("counts").contains("contact_candidates"));  // bonded-only: no contact search
  const double work = s.at("energies").at("external_work").get<double>();
  EXPECT_GT(work, 0.0);
  // Velocity Verlet's oscillation about its shadow energy while the pull starts (bound 1.5x).
  EXPECT_NEAR(energy_balance(s), 0.0, 3e-4 * work);
}

// Continuum cases: the run's own checks (closed forms) decide the exit code.
TEST(Cases, ContinuumCasesPassTheirChecksWithBothSolvers) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  for (const char* solver : {"fe", "nem"}) {
    const Json cantilever = run_case("cantilever_continuum", std::string("--set continuum.solver=") + solver);
    EXPECT_TRUE(cantilever.at("checks").at(0).at("passed").get<bool>()) << solver;
    const Json bar = run_case("bar_wave_continuum", std::string("--set continuum.solver=") + solver);
    EXPECT_TRUE(bar.at("checks").at(0).at("passed").get<bool>()) << solver;
  }
}

// A continuum velocity condition with a rise moves its group as a DE condition with the same keys
// moves its DEs (dem::BoundaryCondition, a (1 - cos) rise): a coupled case's load strips then
// follow the pure-DEM case's load line. A linear rise (as the continuum had) is ahead by up to
// 0.034 V T (at T / 2: 0.125 against 0.091 V T; its acceleration jumps at 0 and T); the bound is
// 1e-10 V T, the CSV's 12 digits.
TEST(Cases, ContinuumVelocityRisesAsTheDemConditionDoes) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const double rise = 8.0e-5, speed = 1.0;  // the case's left face: 1 m/s along x after 80 us
  const auto out = test::scratch_dir(case_folder("bar_wave_continuum"));
  const auto r = test::run_arlequin("run " + cases + "bar_wave_continuum/case.yaml --quiet --out " + out.string() +
                                    " --set time.end=1.0e-4 --set output.fields=[] --set checks=[] --set \"sensors=[{name: "
                                    "u_left, type: displacement, group: left, component: x}]\"");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  dem::BoundaryCondition dem_condition;
  dem_condition.kind = dem::BoundaryKind::velocity;
  dem_condition.value = {speed, 0.0, 0.0};
  dem_condition.rise = rise;
  int rows = 0;
  for (const auto& row : test::read_csv(out / "series.csv")) {
    const double t = std::stod(row.at("time"));
    EXPECT_NEAR(std::stod(row.at("u_left")), dem_condition.displacement_at(t).x, 1e-10 * speed * rise) << "t = " << t;
    ++rows;
  }
  EXPECT_GE(rows, 60);  // one a step (1.68 us, the critical step with its safety) to 100 us
}

// `check` writes nothing: a packing it has to build is not cached beside the case (it was, in
// <case folder>/results/, though the README says check writes nothing); `run` caches it there.
TEST(Cli, CheckWritesNothingNotEvenThePackingCache) {
  const auto dir = test::scratch_dir("check_writes_nothing");
  std::ofstream(dir / "case.yaml") << "name: small_packing\n"
                                      "time: {end: 1.0e-6}\n"
                                      "dem:\n"
                                      "  density: 1600\n"
                                      "  sample: {build: packing, region: {box: [[0, 0, 0], [0.003, 0.003, 0.003]]}, compaction: 0.55, min_coordination: 4, "
                                      "radius: {mean: 2.5e-4}}\n"
                                      "  bond: {law: beam, E_mu: 1.0e11, r_mu: 0.5}\n";
  const auto r = test::run_arlequin("check " + (dir / "case.yaml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "results")) << "check wrote into the case folder";
  const auto out = test::scratch_dir("check_writes_nothing_out");
  const auto run = test::run_arlequin("run " + (dir / "case.yaml").string() + " --quiet --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "results" / "small_packing" / "sample.h5"));
}

// dem.sample.keep cuts a piece out of a packing: the DEs of the whole packing whose centre lies
// in the region, at the same positions and in the same order, while the cache keeps the whole
// packing for the specimen it belongs to; a region holding no DE is an error at the key.
TEST(Samples, KeepCutsAPieceOfTheCachedPacking) {
  const auto dir = test::scratch_dir("sample_keep");
  const std::string head = "name: keep\n"
                           "time: {end: 1.0e-6}\n"
                           "dem:\n"
                           "  density: 1600\n"
                           "  bond: {law: beam, E_mu: 1.0e11, r_mu: 0.5}\n"
                           "  sample:\n"
                           "    build: packing\n"
                           "    region: {box: [[0, 0, 0], [0.003, 0.003, 0.003]]}\n"
                           "    compaction: 0.55\n"
                           "    min_coordination: 4\n"
                           "    radius: {mean: 2.5e-4}\n";
  std::ofstream(dir / "whole.yaml") << head;
  std::ofstream(dir / "piece.yaml") << head << "    file: results/keep/sample.h5\n"
                                    << "    keep: {box: [[-1, -1, 0.0015], [0.002, 1, 1]]}\n";
  std::ofstream(dir / "nothing.yaml") << head << "    keep: {box: [[1, 1, 1], [2, 2, 2]]}\n";
  const app::Scene whole = app::build_scene(dir / "whole.yaml", {});
  const app::Scene piece = app::build_scene(dir / "piece.yaml", {});
  const auto& all = whole.dem.particles;
  const auto& kept = piece.dem.particles;
  std::size_t k = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Vec3 x = all.position[i];
    if (!(x.x <= 0.002 && x.z >= 0.0015)) continue;
    ASSERT_LT(k, kept.size());
    EXPECT_EQ(kept.position[k].x, x.x);
    EXPECT_EQ(kept.position[k].z, x.z);
    EXPECT_EQ(kept.radius[k], all.radius[i]);
    ++k;
  }
  EXPECT_EQ(k, kept.size());
  EXPECT_GT(k, all.size() / 5);
  EXPECT_LT(k, all.size() / 2);
  dem::ParticleSet cached;
  dem::load_sample(dir / "results" / "keep" / "sample.h5", cached, 1600.0);
  EXPECT_EQ(cached.size(), all.size()) << "the cache must hold the whole packing";
  try {
    (void)app::build_scene(dir / "nothing.yaml", {});
    ADD_FAILURE() << "a keep region holding no DE was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("keep"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no DE"), std::string::npos) << e.what();
  }
}

// A run killed outright (SIGKILL, a second Ctrl-C) leaves an index whose frames open: the XDMF
// names the HDF5 file as it is on disk (the .part file until the run closes it; it named a
// fields.h5 that did not exist). The next run into the folder removes the dead run's .part
// and .tmp files, and a run without fields the fields of a run before.
TEST(Cli, KilledRunLeavesReadableFieldsAndTheNextRunCleansUp) {
  const auto out = test::scratch_dir("killed_run");
  const std::string exe = std::string(ARLEQUIN_BINARY_DIR) + "/app/arlequin";
  const std::string command = exe + " run " + cases + "demo_beam_impact/case.yaml --quiet --set time.end=1 --out " +
                              out.string() + " > /dev/null 2>&1 & echo $! > " + (out / "pid").string();
  ASSERT_EQ(std::system(command.c_str()), 0);
  const pid_t pid = static_cast<pid_t>(std::stol(test::read_text(out / "pid")));
  std::filesystem::remove(out / "pid");
  for (int wait = 0; wait < 600 && !std::filesystem::exists(out / "fields.xdmf"); ++wait)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  ::waitpid(pid, nullptr, 0);  // reaped by the shell already, or here: either way it is gone
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const std::string part = "fields.h5.part." + std::to_string(pid);
  const std::string index = test::read_text(out / "fields.xdmf");
  EXPECT_NE(index.find(part + ":/frames/"), std::string::npos) << index.substr(0, 400);
  EXPECT_TRUE(std::filesystem::exists(out / part));
  EXPECT_FALSE(std::filesystem::exists(out / "fields.h5"));

  const auto rerun = test::run_arlequin("run " + cases + "demo_beam_impact/case.yaml --quiet --steps 5 --set output.fields=[] --out " +
                                        out.string());
  ASSERT_EQ(rerun.exit_code, 0) << rerun.output;
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(name.find(".part."), std::string::npos) << name;
    EXPECT_EQ(name.find(".tmp."), std::string::npos) << name;
    EXPECT_NE(name, "fields.xdmf");
  }
}

TEST(Cli, SweepTabulatesErrorAgainstRunTime) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  // --with pairs its values with the axis before it: two runs, (0.5, fe) and (0.4, nem), not four.
  const auto out = test::scratch_dir("sweep");
  const auto r = test::run_arlequin("sweep " + cases + "cantilever_continuum/case.yaml --over continuum.mesh.size=0.5,0.4 "
                                        "--with continuum.solver=fe,nem --out " + out.string(), "stdout");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const std::string csv = test::read_text(out / "sweep.csv");
  EXPECT_NE(csv.find("continuum.mesh.size,continuum.solver,particles,continuum_nodes,steps,tip_deflection,"
                     "tip_deflection_relative_error,wall_seconds,status\n0.5,fe,"),
            std::string::npos) << csv;
  EXPECT_NE(csv.find("\n0.4,nem,"), std::string::npos) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  EXPECT_TRUE(std::filesystem::exists(out / "sweep.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "sweep_time.png"));
}

// A swept box is one field of sweep.csv: quoted, so every row has the header's columns.
TEST(Cli, SweepCsvQuotesValuesWithCommas) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto out = test::scratch_dir("sweep_boxes");
  const std::string boxes = "[[0.044,-0.001,-0.001],[0.052,0.009,0.009]],[[0.044,-0.001,-0.001],[0.060,0.009,0.009]]";
  const auto r = test::run_arlequin("sweep " + cases + "wave_bar_coupled/case.yaml --set output.fields=[] --set checks=[] --set time.end=2e-5 --over \"coupling.overlap.box=" +
                                        boxes + "\" --out " + out.string(), "stdout");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::istringstream csv(test::read_text(out / "sweep.csv"));
  const auto fields = [](const std::string& line) {  // commas outside quotes, plus one
    std::size_t n = 1;
    bool quoted = false;
    for (const char c : line) quoted = c == '"' ? !quoted : quoted, n += c == ',' && !quoted;
    return n;
  };
  std::string header, row;
  std::getline(csv, header);
  int rows = 0;
  for (; std::getline(csv, row); ++rows) {
    EXPECT_EQ(fields(row), fields(header)) << row;
    EXPECT_EQ(row.rfind("\"[[0.044,-0.001,-0.001],[0.0", 0), 0u) << row;
  }
  EXPECT_EQ(rows, 2);
}

// Sweep values split at commas outside brackets, so a box or a vector can be swept.
TEST(Cli, SweepAxisValuesMayBeLists) {
  const app::SweepAxis box = app::parse_sweep_axis("coupling.overlap.box=[[0,0,0],[1,1,1]],[[0,0,0],[2,1,1]]");
  EXPECT_EQ(box.key, "coupling.overlap.box");
  EXPECT_EQ(box.values, (std::vector<std::string>{"[[0,0,0],[1,1,1]]", "[[0,0,0],[2,1,1]]"}));
  EXPECT_EQ(app::parse_sweep_axis("a.b=1,2,3").values, (std::vector<std::string>{"1", "2", "3"}));
  EXPECT_THROW(app::parse_sweep_axis("a=[1,2"), InputError);
  EXPECT_THROW(app::parse_sweep_axis("a=1]"), InputError);
}

// The static patch test (R6, last line), classical form: with the block's boundary held on a
// uniform strain, the coupled interior keeps it to 1e-10 with either continuum solver and
// weight shape, for both mediators on the matched mesh and the fine mediator on the coarser one
// (the case's consistent overlap quadrature: README). The deviation at t = 0 is the round-off
// of eps X.
void expect_patch_test_passes(const std::string& solver) {
  const std::string h2 = " --set continuum.mesh.file=../../meshes/coupled_bar_h2.geo";
  for (const std::string weight : {"constant", "linear", "cubic"})
    for (const std::string& variant : std::vector<std::string>{"--set coupling.mediator=coarse", "--set coupling.mediator=fine",
                                                               "--set coupling.mediator=fine" + h2}) {
      const std::string extra = "--set output.fields=[] --set continuum.solver=" + solver + " --set coupling.weight=" + weight + " " + variant;
      const Json s = run_case("patch_coupled", extra);
      const Json& check = s.at("checks").at(0);
      EXPECT_TRUE(check.at("passed").get<bool>()) << extra;
      EXPECT_LE(check.at("value").get<double>(), 1e-10) << extra;
    }
  const std::string csv = test::read_text(test::scratch_path(case_folder("patch_coupled")) / "series.csv");
  const auto second_line = csv.find('\n') + 1;
  const std::string first_row = csv.substr(second_line, csv.find('\n', second_line) - second_line);
  // time, step, deviation, ...
  const auto c1 = first_row.find(','), c2 = first_row.find(',', c1 + 1), c3 = first_row.find(',', c2 + 1);
  EXPECT_LT(std::stod(first_row.substr(c2 + 1, c3 - c2 - 1)), 1e-12) << first_row;
}

TEST(Cases, PatchCoupledReproducesTheUniformStrainFe) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  expect_patch_test_passes("fe");
}

TEST(Cases, PatchCoupledReproducesTheUniformStrainNem) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  expect_patch_test_passes("nem");
}

// A coupled DE's share of the overlap is the part of its Laguerre cell inside it (decisions.md#d29):
// with linear weights the coarse mediator then balances the weighted lattice's residual on a
// mesh two and four times the lattice spacing too, with the plain quadrature (a DE on the
// overlap's faces counted with its whole volume leaves a ghost force there).
TEST(Cases, PatchCoupledCoarseMediatorPassesOnCoarserMeshes) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  for (const std::string mesh : {"coupled_bar_h2.geo", "coupled_bar_h4.geo"}) {
    const std::string extra = "--set output.fields=[] --set coupling.weight=linear --set coupling.mediator=coarse "
                              "--set coupling.quadrature=plain --set continuum.mesh.file=../../meshes/" + mesh;
    const Json s = run_case("patch_coupled", extra);
    EXPECT_LE(s.at("checks").at(0).at("value").get<double>(), 1e-10) << extra;
  }
}

// The static patch test on a random packing (README, "Random packing"): the packing relaxes off
// the affine field by itself, so the deviation is not round-off. Bounds at about 1.35 x the
// measured maxima (fine 0.044, coarse 0.32); the floor says the packing does relax (an affine
// packing would mean its bonds carry nothing); the coarse mediator's loose edge DEs drift
// several times further than the fine mediator lets any DE (measured 7.3 x).
TEST(Cases, PatchCoupledRandomPackingReachesItsOwnRelaxation) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  auto deviation = [](const std::string& mediator) {
    const auto out = test::scratch_dir("patch_random_" + mediator);
    const auto r = test::run_arlequin("run " + cases + "patch_coupled/random_packing.yaml --quiet --set output.fields=[] "
                                      "--set coupling.mediator=" + mediator + " --out " + out.string());
    const Json s = read_json_file(out / "summary.json");
    return s.at("checks").at(0).at("value").get<double>();
  };
  const double fine = deviation("fine"), coarse = deviation("coarse");
  EXPECT_LT(fine, 0.06);
  EXPECT_GT(fine, 0.02);
  EXPECT_LT(coarse, 0.45);
  EXPECT_GT(coarse, 3.0 * fine);
}

// Without the consistent quadrature, natural neighbours leave a residual of the varying weight
// (their reach past the next node plane): the README's plain rows. And the consistent one
// refuses a free surface through the overlap, where its targets cannot be met.
TEST(Cases, PatchCoupledPlainQuadratureAndItsLimits) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto plain = test::scratch_dir(case_folder("patch_coupled"));
  const auto p = test::run_arlequin("run " + cases + "patch_coupled/case.yaml --quiet --set output.fields=[] "
                                    "--set continuum.solver=nem --set coupling.quadrature=plain --out " + plain.string());
  EXPECT_NE(p.exit_code, 0);  // its check fails
  const Json summary = read_json_file(plain / "summary.json");
  const double deviation = summary.at("checks").at(0).at("value").get<double>();
  EXPECT_GT(deviation, 1e-6);
  EXPECT_LT(deviation, 1e-3);
  const auto out = test::scratch_dir(case_folder("free_surface"));
  const auto r = test::run_arlequin("run " + cases + "patch_coupled/free_surface.yaml --quiet --set output.fields=[] "
                                    "--set coupling.quadrature=consistent --out " + out.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("coupling.quadrature: consistent"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("free surface"), std::string::npos) << r.output;
}

// The same bar with free side faces: the lattice's 25 equal line forces against the P1 nodal
// shares leave a ghost force at the overlap; the case's check guards its measured level.
TEST(Cases, PatchCoupledFreeSurfaceBoundsTheGhostForces) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto out = test::scratch_dir("patch_coupled_free_surface");
  const auto r = test::run_arlequin("run " + cases + "patch_coupled/free_surface.yaml --quiet --set output.fields=[] --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json s = read_json_file(out / "summary.json");
  EXPECT_TRUE(s.at("checks").at(0).at("passed").get<bool>());
}

// Without the plotting package's interpreter a run still succeeds, keeps plots.json, and says
// in one line which plots it skipped and why.
TEST(Cases, APlotThatCannotBeDrawnIsSkippedInOneLine) {
  const auto out = test::scratch_dir("plot_skipped");
  setenv("ARLEQUIN_PYTHON", "/nonexistent/python3", 1);
  const auto r = test::run_arlequin("run " + cases + "cantilever_chain/case.yaml --quiet --steps 20 --out " + out.string() +
                                    " --set \"output.plots=[{file: tip.svg, x: time, y: [tip_deflection]}]\"");
  unsetenv("ARLEQUIN_PYTHON");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("plots skipped (tip.svg): cannot run /nonexistent/python3; install python3 and python3-matplotlib\n"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(std::filesystem::exists(out / "plots.json"));
  EXPECT_FALSE(std::filesystem::exists(out / "tip.svg"));
}

// BBF in a structure: a simple-cubic lattice bar fails at 36 S sigma_f (the case's own check),
// its breaks are recorded, and the fracture energy closes the energy balance.
// The demo's ball at 2e5 m/s moved 19 mm per step and went through the beam unseen, and at
// 2000 m/s the penalty (2e7 N/m) could not stop it within the beam: both passed silently. Now
// the critical step keeps the ball within its radius per step, and the too-soft contact stops
// the run naming the pair.
TEST(Cases, FastImpactIsResolvedOrStopped) {
  for (const std::string speed : {"2e5", "2000"}) {
    const auto out = test::scratch_dir("fast_impact_" + speed);
    const auto r = test::run_arlequin("run " + cases + "demo_beam_impact/case.yaml --quiet --set output.fields=[] --set time.end=2e-4 "
                                      "--set \"dem.sample.particles=[{position: [0.05, 0.003, 0.0115], radius: 0.003, "
                                      "velocity: [0, 0, -" + speed + "]}]\" --out " + out.string());
    EXPECT_NE(r.exit_code, 0) << r.output;
    const Json s = read_json_file(out / "summary.json");
    EXPECT_EQ(s.at("status").get<std::string>(), "failed");
    EXPECT_NE(s.at("error").get<std::string>().find("too soft to stop this impact"), std::string::npos) << s.dump();
    if (speed == "2e5") {
      EXPECT_LE(s.at("dt_critical").get<double>(), 0.003 / 2e5);
    }
  }
}

// A run that will last more than a minute says so once, after 2 s, even where no progress line
// is drawn (a log): a time.end of 1e10 steps ran on without a word. Stopped after 4 s.
TEST(Cases, LongRunAnnouncesItsRunTime) {
  const auto out = test::scratch_dir("long_run");
  const std::string command = "timeout 4 " + std::string(ARLEQUIN_BINARY_DIR) + "/app/arlequin run " + cases +
                              "cantilever_chain/case.yaml --set output.fields=[] --set time.end=1000 --out " + out.string() +
                              " > /dev/null 2> " + (out / "stderr.txt").string();
  EXPECT_NE(std::system(command.c_str()), 0);  // cut by the timeout
  const std::string err = test::read_text(out / "stderr.txt");
  EXPECT_EQ(err.rfind("  run time: about ", 0), 0u) << err;
  EXPECT_NE(err.find(" to go at "), std::string::npos) << err;
}

// A run shorter than one step is one step of time.end (the calibration's placeholder packing,
// E_mu = 1 Pa, ran 750 times past its time.end), and the closing line's steps/s is the summary's.
TEST(Cases, RunShorterThanAStepEndsAtTimeEnd) {
  const auto out = test::scratch_dir("shorter_than_a_step");
  const auto r = test::run_arlequin("run " + cases + "cantilever_chain/case.yaml --set time.end=1e-12 --set checks=[] --out " + out.string(), "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json s = read_json_file(out / "summary.json");
  EXPECT_EQ(s.at("steps").get<long>(), 1);
  EXPECT_EQ(s.at("simulated_time").get<double>(), 1e-12);
  EXPECT_EQ(s.at("dt").get<double>(), 1e-12);
  char rate[64];
  std::snprintf(rate, sizeof rate, "%.0f steps/s without output", s.at("wall_time").at("steps_per_second").get<double>());
  EXPECT_NE(r.output.find(rate), std::string::npos) << r.output;
}

// The continuum's energy balance closes at any safety (docs/theory.md#energy): the work of its
// moving supports and tractions is counted (it was not: E_balance was 100 % of the energy on the
// pushed bar) and velocity Verlet's shadow term taken off (a free vibration at 0.9 of the
// critical step showed 4 %). Measured: 2e-14 of the largest energy, fe and nem; bound 1e-12
// (round-off accumulated over the run's 500-560 steps).
TEST(Cases, ContinuumEnergyBalanceClosesAtNineTenthsOfTheCriticalStep) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::string free = " --set continuum.boundary=[] --set checks=[] "
                           "--set \"initial_strain={gradient: [[1.0e-3, 0, 0], [0, 5.0e-4, 0], [0, 0, 0]]}\"";
  for (const std::string& variant : std::vector<std::string>{"", free, free + " --set continuum.solver=nem"}) {
    const auto out = test::scratch_dir("continuum_balance");
    const auto r = test::run_arlequin("run " + cases + "bar_wave_continuum/case.yaml --quiet --set output.fields=[] --out " +
                                      out.string() + variant);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    double largest = 0.0, worst = 0.0;
    for (const auto& row : test::read_csv(out / "series.csv")) {
      largest = std::max({largest, std::abs(test::number(row, "E_total")), std::abs(test::number(row, "W_external"))});
      worst = std::max(worst, std::abs(test::number(row, "E_balance")));
    }
    EXPECT_GT(largest, 0.0) << variant;
    EXPECT_LT(worst, 1e-12 * largest) << variant;
  }
}

// The continuum's viscous damping (continuum.damping, as the DEM's): the critical step is the
// damped closed form 4 / (c + sqrt(c^2 + 4 omega^2)) with omega from the undamped step, the
// bar's free vibration decays, and the balance counts what the damping took (E_dissipated).
TEST(Cases, ContinuumDampingLowersTheStepAndItsWorkClosesTheBalance) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::string run = "run " + cases + "bar_wave_continuum/case.yaml --quiet --set output.fields=[] --set continuum.boundary=[] "
                          "--set checks=[] --set \"initial_strain={gradient: [[1.0e-3, 0, 0], [0, 5.0e-4, 0], [0, 0, 0]]}\"";
  const auto undamped = test::scratch_dir("continuum_undamped"), damped = test::scratch_dir("continuum_damped");
  ASSERT_EQ(test::run_arlequin(run + " --out " + undamped.string()).exit_code, 0);
  const double c = 2.0e4;  // 1/s: c T = 5.6 over the run
  const auto r = test::run_arlequin(run + " --set continuum.damping=2.0e4 --out " + damped.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double omega = 2.0 / read_json_file(undamped / "summary.json").at("dt_critical").get<double>();
  EXPECT_NEAR(read_json_file(damped / "summary.json").at("dt_critical").get<double>() * (c + std::sqrt(c * c + 4.0 * omega * omega)) / 4.0,
              1.0, 1e-12);
  const auto rows = test::read_csv(damped / "series.csv");
  const double initial = test::number(rows.front(), "E_total");
  double previous = 0.0, worst = 0.0;
  for (const auto& row : rows) {
    EXPECT_GE(test::number(row, "E_dissipated"), previous);
    previous = test::number(row, "E_dissipated");
    worst = std::max(worst, std::abs(test::number(row, "E_balance")));
  }
  // Damping from the half-step velocity closes the balance to O(c dt) of the energy moved in a
  // step: measured 5.1e-4 of the initial energy, in the first steps.
  EXPECT_LT(worst, 1e-3 * initial);
  // Every mode's energy decays as exp(-c t) on average (mass-proportional damping): 0.0037 at the
  // end; the strain energy's share decays more slowly in the first steps, measured 0.0068.
  EXPECT_LT(test::number(rows.back(), "E_total"), 0.01 * initial);
  EXPECT_GT(previous, 0.98 * initial);
}

// Heavy damping (c dt up to 3.3 at the undamped step's 0.1) blew up with a message that blamed
// the bonds: the critical step now includes the damping (dt^2 omega^2 + 2 c dt < 4), so the run
// completes, and a step above the damped limit is refused saying so.
TEST(Cases, HeavyDampingLowersTheCriticalStep) {
  const auto out = test::scratch_dir("lattice_bar_damped");
  const std::string run = "run " + cases + "lattice_bar_failure/case.yaml --quiet --set output.fields=[] --set dem.damping=1e8 ";
  test::run_arlequin(run + "--set time.end=3e-5 --out " + out.string());
  const Json s = read_json_file(out / "summary.json");
  EXPECT_EQ(s.at("status").get<std::string>(), "completed") << s.dump();
  EXPECT_LT(s.at("dt_critical").get<double>(), 2.0 / 1e8);
  const auto refused = test::run_arlequin(run + "--set time.dt=3e-8 --out " + out.string());
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("lowered by damping"), std::string::npos) << refused.output;
}

TEST(Cases, LatticeBarFailsAtTheBondStrength) {
  const auto out = test::scratch_dir("lattice_bar_failure");
  const auto r = test::run_arlequin("run " + cases + "lattice_bar_failure/case.yaml --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json s = read_json_file(out / "summary.json");
  EXPECT_TRUE(s.at("checks").at(0).at("passed").get<bool>());
  const long broken = s.at("counts").at("broken_bonds").get<std::int64_t>();
  EXPECT_GT(broken, 0);
  const std::string breaks = test::read_text(out / "breaks.csv");
  EXPECT_EQ(std::count(breaks.begin(), breaks.end(), '\n'), broken + 1);
  EXPECT_NE(breaks.find(",bonds,bbf,tension,"), std::string::npos);
  // The case's plot: described in plots.json by series.csv columns the run wrote, then drawn.
  const Json plot = read_json_file(out / "plots.json").at("plots").at(0);
  EXPECT_EQ(plot.at("file").get<std::string>(), "failure.png");
  const std::string header = test::read_text(out / "series.csv").substr(0, test::read_text(out / "series.csv").find('\n'));
  ASSERT_EQ(plot.at("series").size(), 2u);
  const std::string columns = std::string(",").append(header).append(",");
  for (const Json& curve : plot.at("series")) {
    EXPECT_EQ(curve.at("csv").get<std::string>(), "series.csv");
    for (const char* axis : {"x", "y"})
      EXPECT_NE(columns.find(std::string(",").append(curve.at(axis).get<std::string>()).append(",")), std::string::npos)
          << curve.dump();
  }
  EXPECT_TRUE(plot.at("series").at(1).at("right_axis").get<bool>());
  EXPECT_TRUE(std::filesystem::exists(out / "failure.png"));
  EXPECT_GT(s.at("energies").at("fracture").get<double>(), 0.0);
  // A break releases its bond's energy within one step: the balance closes to O((omega dt)^2),
  // 0.5 % of the work for this damped run at the case's safety factor 0.1 (1.6 % at 0.3).
  EXPECT_NEAR(energy_balance(s), 0.0, 1e-2 * s.at("energies").at("external_work").get<double>());
}

// The multiplier solve is a runtime choice: PETSc's (default: preonly + cholesky; here also
// an iterative one from the case's options) and our own LDL^T give R to 1e-9; options for the
// direct solver, an unknown type and an option nothing reads are refused (exit 2, naming the
// key), and a PETSc solve that does not converge stops the run (exit 3).
TEST(Cases, WaveBarCoupledMultiplierSolverIsARuntimeChoice) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto R = [](const Json& s) { return s.at("checks").at(0).at("value").get<double>(); };
  const double petsc = R(run_case("wave_bar_coupled", "--set output.fields=[]"));
  EXPECT_NEAR(R(run_case("wave_bar_coupled", "--set output.fields=[] --set coupling.solver=direct")), petsc, 1e-9 * petsc);
  EXPECT_NEAR(R(run_case("wave_bar_coupled", "--set output.fields=[] --set 'coupling.petsc_options=\"-ksp_type cg -pc_type jacobi -ksp_rtol 1e-14\"'")),
              petsc, 1e-9 * petsc);
  const auto out = test::scratch_dir(case_folder("refused"));
  const auto direct = test::run_arlequin("run " + cases + "wave_bar_coupled/case.yaml --quiet --out " + out.string() +
                                         " --set coupling.solver=direct --set coupling.petsc_options=-ksp_type");
  EXPECT_EQ(direct.exit_code, 2);
  EXPECT_NE(direct.output.find("coupling.petsc_options: is read by coupling.solver: petsc only"), std::string::npos) << direct.output;
  for (const auto& [options, message] : std::vector<std::pair<std::string, std::string>>{
           {"-ksp_type cgg", "PETSc refused '-ksp_type cgg'"}, {"-ksp_rtoll 1e-9", "PETSc did not use '-ksp_rtoll 1e-9'"}}) {
    const auto bad = test::run_arlequin("run " + cases + "wave_bar_coupled/case.yaml --quiet --out " + out.string() +
                                        " --set 'coupling.petsc_options=\"" + options + "\"'");
    EXPECT_EQ(bad.exit_code, 2) << options;
    EXPECT_NE(bad.output.find("coupling.petsc_options: " + message), std::string::npos) << bad.output;
  }
  const auto stalled = test::run_arlequin("run " + cases + "wave_bar_coupled/case.yaml --quiet --out " + out.string() +
                                          " --set 'coupling.petsc_options=\"-ksp_type cg -pc_type none -ksp_max_it 2\"'");
  EXPECT_EQ(stalled.exit_code, 3);
  EXPECT_NE(stalled.output.find("the multiplier solve did not converge (DIVERGED_ITS"), std::string::npos) << stalled.output;
}

// A coupled step above the smaller critical step of the two models is refused at set-up, with
// the limit in the message (R6's stability point; runs at 0.9 of it: CouplingStability.*).
TEST(Cases, WaveBarCoupledRefusesAStepAboveTheCriticalOne) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto out = test::scratch_dir(case_folder("wave_bar_coupled"));
  const auto r = test::run_arlequin("run " + cases + "wave_bar_coupled/case.yaml --quiet --out " + out.string() + " --set time.dt=1e-6");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("time.dt: time step 1e-06 s is above the critical time step"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("and the continuum, lowered by damping; docs/theory.md#critical-step); use dt <= "), std::string::npos) << r.output;
}

// R6 on a 3D bar: the pulse leaves the DEM through the overlap; the energy left behind is R.
TEST(Cases, WaveBarCoupledTransmitsThePulse) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  // Default (h = 4a, lambda = 1.6 lambda_c): the case's own check, R <= 0.5 %.
  const Json coarse = run_case("wave_bar_coupled");
  EXPECT_TRUE(coarse.at("checks").at(0).at("passed").get<bool>());
  // The coupling's monitor at every row (series.csv): the largest and the rms velocity mismatch
  // between a coupled DE and the continuum at its centre, and the velocity constraint, which
  // holds to round-off (bound about 20x). On this mesh (h = 4a) the coarse mediator leaves the
  // three DE planes between node planes free, and the mismatch is of the order of P1's
  // interpolation error of the pulse, h^2/8 max |v''| = 0.0099 m/s (bounds 1.5x the measured
  // largest and rms mismatch, cases/wave_bar_coupled/README.md).
  struct Monitor {
    double residual = 0.0, mismatch = 0.0, mismatch_rms = 0.0;
  };
  const auto monitor = [] {
    Monitor m;
    const auto rows = test::read_csv(test::scratch_path(case_folder("wave_bar_coupled")) / "series.csv");
    EXPECT_GT(rows.size(), 10u);
    for (const auto& row : rows) {
      m.residual = std::max(m.residual, test::number(row, "G_residual"));
      m.mismatch = std::max(m.mismatch, test::number(row, "V_mismatch_max"));
      m.mismatch_rms = std::max(m.mismatch_rms, test::number(row, "V_mismatch_rms"));
    }
    EXPECT_LT(m.residual, 1e-14);
    return m;
  };
  const Monitor h4 = monitor();
  EXPECT_LT(h4.mismatch, 0.032);
  EXPECT_LT(h4.mismatch_rms, 0.0086);
  EXPECT_GT(h4.mismatch_rms, 0.0);
  // The lattice (119 x 5 x 5) and the mesh (x >= 2a) cover the bar; the overlap 22a..30a cuts
  // them: DEs up to x = 30a (31 x 25), tetrahedra from 22a on (5 elements of h = 4a, 6 each, go).
  const Json& counts = coarse.at("counts");
  EXPECT_EQ(counts.at("particles").get<std::int64_t>(), 31 * 25);
  EXPECT_EQ(counts.at("particles_not_created").get<std::int64_t>(), 88 * 25);
  EXPECT_EQ(counts.at("continuum_tetrahedra_left_out").get<std::int64_t>(), 5 * 6);
  EXPECT_EQ(counts.at("continuum_nodes").get<std::int64_t>(), 25 * 4);
  // Matched (h = a), lambda = 20a >= 5a: R <= 0.3 %.
  const Json matched = run_case("wave_bar_coupled", "--set continuum.mesh.file=../../meshes/coupled_bar_h1.geo");
  EXPECT_LE(matched.at("checks").at(0).at("value").get<double>(), 0.003);
  // Every coupled DE on a node: tied one by one, no mismatch but round-off.
  EXPECT_LT(monitor().mismatch, 1e-15);
  // Natural neighbours by swapping the solver only, at 1.6 lambda_c on h = 4a and on h = 2a
  // (lambda_c = 6a, 1.6 lambda_c = 9.6a): R <= 0.5 % with the case's stabilization (README).
  const std::string nem = "--set continuum.solver=nem";
  EXPECT_TRUE(run_case("wave_bar_coupled", nem).at("checks").at(0).at("passed").get<bool>());
  const Json fine = run_case("wave_bar_coupled", nem + " --set continuum.mesh.file=../../meshes/coupled_bar_h2.geo" +
                                                     " --set pulse.wavelength=0.0192");
  EXPECT_LE(fine.at("checks").at(0).at("value").get<double>(), 0.005);
}

// R6's "R >= 90 % for lambda <= 0.8 lambda_c", with a narrow-band tone burst (a raised cosine
// spreads over all wavelengths longer than its own): reflected, for fe and nem alike.
TEST(Cases, WaveBarAboveCutOffIsReflected) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  for (const std::string solver : {"fe", "nem"}) {
    const auto out = test::scratch_dir("above_cutoff_" + solver);
    const auto r = test::run_arlequin("run " + cases + "wave_bar_coupled/above_cutoff.yaml --set continuum.solver=" + solver +
                                          " --out " + out.string(), "stdout");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Json s = read_json_file(out / "summary.json");
    EXPECT_GE(s.at("checks").at(0).at("value").get<double>(), 0.9) << solver;
  }
}

// The pulse's displacement is the integral of its velocity, u(s) = (1/c) int_s^inf v, so that
// v = -c du/ds (a wave running one way): checked on a fine chain by central differences, for
// both shapes; the raised cosine leaves A lambda / 2c behind it, the tone burst nothing.
TEST(Cases, PulseDisplacementIsTheIntegralOfItsVelocity) {
  const double a = 1e-4, lambda = 0.02, A = 0.1, c = 3000.0;
  for (const int cycles : {0, 3}) {
    const auto dir = test::scratch_dir("pulse_" + std::to_string(cycles));
    const std::string burst = cycles ? ", cycles: " + std::to_string(cycles) : "";
    const std::string text =
        "name: pulse\ntime: {end: 1.0e-9, dt: auto, safety: 0.5}\n"
        "dem:\n  density: 7800\n  sample: {build: lattice, origin: [0, 0, 0], counts: [1001, 1, 1], radius: 5.0e-5}\n"
        "  bond: {law: beam, E_mu: 2.0e11, nu_mu: 0.3, r_mu: 0.5}\n"
        "groups:\n  - {name: all, region: {box: [[-1, -1, -1], [1, 1, 1]]}}\n"
        "pulse: {group: all, direction: [1, 0, 0], center: [0.05, 0, 0], wavelength: 0.02, amplitude: 0.1, speed: 3000" +
        burst + "}\n";
    std::ofstream(dir / "case.yaml") << text;
    const app::Scene scene = app::build_scene(dir / "case.yaml", {});
    const auto& p = scene.dem.particles;
    ASSERT_EQ(p.size(), 1001u);
    const auto u = [&](std::size_t i) { return p.position[i].x - p.reference[i].x; };
    double worst = 0.0;
    for (std::size_t i = 1; i + 1 < p.size(); ++i)
      worst = std::max(worst, std::abs(p.velocity[i].x + c * (u(i + 1) - u(i - 1)) / (2 * a)));
    EXPECT_LT(worst, 1e-3 * A) << cycles;  // O((k a)^2) of the central difference
    EXPECT_NEAR(u(p.size() - 1), 0.0, 1e-15) << cycles;  // ahead
    EXPECT_NEAR(u(0), cycles ? 0.0 : A * lambda / (2 * c), 1e-12) << cycles;  // behind
  }
}

// `run --profile` prints the step's phases after the run: the DEM's, one per bond set, and the
// runner's, each with its share, and the step's row; on one thread all of it runs serially.
TEST(Cases, ProfilePrintsThePhasesOfTheStep) {
  const test::OmpThreadsOfRuns scope(1);
  const auto out = test::scratch_dir("profile_block");
  const auto r = test::run_arlequin("run " + cases + "bonded_block_tension/case.yaml --steps 20 --profile --quiet --out " +
                                        out.string(),
                                    "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto at = r.output.find("profile of the step, 1 thread(s):");
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::string table = r.output.substr(at);
  for (const char* phase : {"kicks", "drift and clear forces", "bonds bonds (beam, gather)", "group reactions", "finite check",
                            "sensors, energies, output"})
    EXPECT_NE(table.find(std::string("\n") + phase + " "), std::string::npos) << phase << "\n" << table;
  std::istringstream step_row(table.substr(table.find("\nstep ") + 1));
  std::string name, ms, share, serial;
  step_row >> name >> ms >> share >> serial;
  EXPECT_GT(std::stod(ms), 0.0) << table;
  EXPECT_EQ(share, "100.0%") << table;
  EXPECT_EQ(serial, "100.0%") << table;
}

// Results independent of the thread count, to the bit, for whole runs (not only the bond pass):
// a breaking lattice bar, the bonded block of the benchmark (20 000 DEs: its kicks and drift on
// threads too), a coupled bar, the coupled fabric and the first steps of the coupled DCB, each
// large enough that its bond pass runs on threads (above common/parallel.hpp's threshold), on one
// and two threads: series.csv and breaks.csv byte for byte. (The REV's failure test:
// RevFailure.RunsAreBitIdenticalOnOneAndTwoThreads.)
TEST(Cases, WholeRunsAreBitIdenticalOnOneAndTwoThreads) {
  struct Run {
    std::string name, args;
    bool needs_continuum;
  };
  const std::vector<Run> runs = {
      {"lattice_bar_failure", "lattice_bar_failure/case.yaml --set \"dem.sample.counts=[16,16,20]\"", false},
      {"bonded_block_tension", "bonded_block_tension/case.yaml", false},
      // Contacts (their gathered pass) with friction, and yarn springs that break.
      {"fabric_impact", "fabric_impact/reduced.yaml --set dem.contact.friction=0.3 --set time.end=2.5e-5", false},
      {"wave_bar_coupled", "wave_bar_coupled/case.yaml --set \"coupling.overlap.box=[[0.200, -0.001, -0.001], [0.216, 0.009, 0.009]]\" "
                           "--set \"groups=[{name: dem_only, region: {box: [[-1, -1, -1], [0.199, 1, 1]]}}, {name: bar, region: "
                           "{box: [[-1, -1, -1], [1, 1, 1]]}}]\" --set \"sensors=[{name: E_dem_side, type: energy, group: dem_only}]\"",
       true},
      // The finite-strain P1 plate (its tiles and gather on threads), the low-rank multipliers
      // (the coupling's loops over its 2 502 coupled DEs' rows on threads, above
      // parallel_threshold_rows), weighted contacts, to just past the first breaks (30 us).
      {"fabric_impact_coupled", "fabric_impact_coupled/case.yaml --set time.end=3.2e-5", true},
      // The coupled DCB at 40k: the coupling's per-DE and per-node loops (5142 coupled DEs, above
      // the threshold), the multipliers' solves in two parts (one per arm), beam sets in one
      // pass and cohesive links; its packing built once into the scratch folder (about 25 s).
      {"dcb_coupled", "dcb_coupled/case.yaml --steps 400 --set output.every=1.0e-7 --set dem.sample.file=" +
                          (test::scratch_dir("threads_dcb_coupled_sample") / "sample.h5").string(),
       true}};
  for (const Run& run : runs) {
#ifndef ARLEQUIN_WITH_CONTINUUM
    if (run.needs_continuum) continue;
#endif
    std::string series[2], breaks[2];
    for (int threads : {1, 2}) {
      const test::OmpThreadsOfRuns scope(threads);
      const auto out = test::scratch_dir("threads_" + run.name + "_" + std::to_string(threads));
      const auto r = test::run_arlequin("run " + cases + run.args + " --quiet --set output.fields=[] --set checks=[] --out " + out.string());
      ASSERT_EQ(r.exit_code, 0) << r.output;
      series[threads - 1] = test::read_text(out / "series.csv");
      breaks[threads - 1] = test::read_text(out / "breaks.csv");  // empty where nothing broke
    }
    EXPECT_GT(std::count(series[0].begin(), series[0].end(), '\n'), 10) << run.name;
    EXPECT_EQ(series[0], series[1]) << run.name;
    EXPECT_EQ(breaks[0], breaks[1]) << run.name;
    if (run.name == "lattice_bar_failure") {
      EXPECT_GT(std::count(breaks[0].begin(), breaks[0].end(), '\n'), 100);
    }
    if (run.name == "fabric_impact") {
      EXPECT_GT(std::count(breaks[0].begin(), breaks[0].end(), '\n'), 5);
    }
  }
}

// nem's stabilization (1.9) was fitted on wave_bar_coupled's bar; second_bar.yaml is a bar it
// was not fitted on (a longer DEM zone, a 22a pulse): nem meets R6's gate there too, and with
// the default stabilization (1) it would not, so the bar tests the fitted value.
TEST(Cases, NemStabilizationHoldsOnASecondBar) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::string run = "run " + cases + "wave_bar_coupled/second_bar.yaml --quiet --set output.fields=[] --set continuum.solver=nem ";
  const auto out = test::scratch_dir("second_bar");
  const auto fitted = test::run_arlequin(run + "--out " + (out / "fitted").string());
  EXPECT_EQ(fitted.exit_code, 0) << fitted.output;
  EXPECT_LE(read_json_file(out / "fitted" / "summary.json").at("checks").at(0).at("value").get<double>(), 0.005);
  const auto plain = test::run_arlequin(run + "--set continuum.stabilization=1 --out " + (out / "plain").string());
  EXPECT_EQ(plain.exit_code, 5) << plain.output;
}

// A bond that the coupling weights (weight < 1 at its set-up midpoint) breaking: the run says so
// in one line and in summary.json, and stops (coupling.on_damage_in_overlap: stop, the default)
// or goes on (warn). Breaks in the pure-DEM zone of a coupled run say nothing.
TEST(Cases, DamageInTheOverlapStopsOrWarnsAndDamageElsewhereDoesNot) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto out = test::scratch_dir("overlap_damage");
  // The patch starts on a uniform strain of 1e-3 (200 MPa in the bonds): with sigma_f = 10 MPa
  // bonds break at the first step, in the overlap too.
  const std::string patch = "run " + cases + "patch_coupled/case.yaml --quiet --set output.fields=[] --set checks=[] --set dem.bond.sigma_f=1e7 ";
  const auto stopped = test::run_arlequin(patch + "--out " + (out / "stop").string());
  EXPECT_EQ(stopped.exit_code, 3) << stopped.output;
  EXPECT_NE(stopped.output.find("step 1: damage reached the coupling overlap: bond "), std::string::npos) << stopped.output;
  EXPECT_NE(stopped.output.find("the run stops (coupling.on_damage_in_overlap: stop"), std::string::npos) << stopped.output;
  const Json s = read_json_file(out / "stop" / "summary.json");
  EXPECT_EQ(s.at("status").get<std::string>(), "failed");
  EXPECT_EQ(s.at("steps").get<long>(), 1);
  EXPECT_GT(s.at("damage_in_overlap_breaks").get<long>(), 0);

  const auto warned = test::run_arlequin(patch + "--set coupling.on_damage_in_overlap=warn --out " + (out / "warn").string());
  EXPECT_EQ(warned.exit_code, 0) << warned.output;
  EXPECT_EQ(std::count(warned.output.begin(), warned.output.end(), '\n'), 1) << warned.output;
  EXPECT_EQ(warned.output.rfind("  warning: step 1: damage reached the coupling overlap", 0), 0u) << warned.output;
  const Json w = read_json_file(out / "warn" / "summary.json");
  EXPECT_EQ(w.at("status").get<std::string>(), "completed");
  EXPECT_GT(w.at("damage_in_overlap_breaks").get<long>(), s.at("damage_in_overlap_breaks").get<long>());

  // Any weight below 1 is the overlap's: with a constant DEM weight of 0.9 there, a bond breaking
  // next to the pure-DEM zone stops the run as well.
  const auto near_one = test::run_arlequin(patch + "--set coupling.weight=constant --set coupling.constant_value=0.9 --out " +
                                           (out / "near_one").string());
  EXPECT_EQ(near_one.exit_code, 3) << near_one.output;
  EXPECT_NE(near_one.output.find("where the DEM's weight is 0.9 "), std::string::npos) << near_one.output;

  // A tensile pulse breaking bonds in the pure-DEM zone of the wave bar, the overlap far ahead.
  const auto elsewhere = test::run_arlequin(
      "run " + cases + "wave_bar_coupled/case.yaml --quiet --set output.fields=[] --set checks=[] --set time.end=3e-5 "
      "--set pulse.amplitude=-0.1 --set dem.bond.sigma_f=3e6 --set \"coupling.overlap.box=[[0.200, -0.001, -0.001], [0.216, 0.009, 0.009]]\" "
      "--set \"groups=[{name: dem_only, region: {box: [[-1, -1, -1], [0.199, 1, 1]]}}, {name: bar, region: {box: [[-1, -1, -1], "
      "[1, 1, 1]]}}]\" --set \"sensors=[{name: E_dem_side, type: energy, group: dem_only}]\" --out " + (out / "elsewhere").string());
  EXPECT_EQ(elsewhere.exit_code, 0) << elsewhere.output;
  const Json e = read_json_file(out / "elsewhere" / "summary.json");
  EXPECT_GT(e.at("counts").at("broken_bonds").get<long>(), 100);
  EXPECT_FALSE(e.contains("damage_in_overlap"));
}

// A coupled run's energy bookkeeping, read from series.csv: E_balance (with the coupling's
// work) over the largest E_total, and W_coupling, the multipliers' work, which is zero in exact
// arithmetic. The wave bar's balance is velocity Verlet's oscillation (bound 1.5x what fe and
// nem achieve); the static patch's and W_coupling are round-off (bound about 20x).
TEST(Cases, CoupledRunsCloseTheirEnergyBalance) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  struct Run {
    std::string case_name, solver;
    double balance_bound, coupling_work_bound;
  };
  for (const Run& run : std::vector<Run>{{"wave_bar_coupled", "fe", 3.5e-5, 2e-15},
                                         {"wave_bar_coupled", "nem", 5.4e-5, 2e-15},
                                         {"patch_coupled", "fe", 2.4e-12, 2e-16},
                                         {"patch_coupled", "nem", 1.3e-12, 2e-16}}) {
    const auto out = test::scratch_dir("energy_" + run.case_name + "_" + run.solver);
    const auto r = test::run_arlequin("run " + cases + run.case_name + "/case.yaml --quiet --set output.fields=[] --set continuum.solver=" +
                                      run.solver + " --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    double balance = 0.0, coupling_work = 0.0, energy = 0.0;
    for (const auto& row : test::read_csv(out / "series.csv")) {
      balance = std::max(balance, std::abs(test::number(row, "E_balance")));
      coupling_work = std::max(coupling_work, std::abs(test::number(row, "W_coupling")));
      energy = std::max(energy, std::abs(test::number(row, "E_total")));
    }
    EXPECT_LE(balance, run.balance_bound * energy) << run.case_name << " " << run.solver;
    EXPECT_LE(coupling_work, run.coupling_work_bound * energy) << run.case_name << " " << run.solver;
  }
}

// The user's error-against-run-time view on the README's window (cases/wave_bar_coupled/README.md:
// 4 ms, the pulse's passage and its return from the far end): the coupled bar's probe against
// the all-DEM bar, bounded at about 1.3x what it achieves (the speed-up is a benchmark's,
// bench_coupled_step). Each run is judged by its own case's checks: compare exits 5 when one
// fails (it exited 0 whatever they said).
TEST(Cli, CompareBoundsTheCoupledErrorAndHonoursChecks) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto out = test::scratch_dir("compare");
  const std::string pair = "compare " + cases + "wave_bar_dem/case.yaml " + cases + "wave_bar_coupled/case.yaml";
  const auto r = test::run_arlequin(pair + " --set time.end=4e-3 --set output.fields=[] --set checks=[] --out " + out.string(), "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json c = read_json_file(out / "compare.json");
  EXPECT_EQ(c.at("reference").at("particles").get<std::int64_t>(), 2975);
  EXPECT_EQ(c.at("other").at("particles").get<std::int64_t>(), 775);
  const auto& sensors = c.at("sensors");
  ASSERT_EQ(sensors.size(), 2u);
  EXPECT_EQ(sensors[0].at("sensor").get<std::string>(), "E_dem_side");
  EXPECT_EQ(sensors[1].at("sensor").get<std::string>(), "u_probe");
  EXPECT_LT(sensors[1].at("rms_relative_difference").get<double>(), 8.5e-3);
  EXPECT_LT(sensors[1].at("max_relative_difference").get<double>(), 1.6e-2);
  EXPECT_TRUE(std::filesystem::exists(out / "compare_u_probe.png"));
  const Json plots = read_json_file(out / "plots.json").at("plots");  // each sensor's plot, in its unit
  ASSERT_EQ(plots.size(), 2u);
  EXPECT_EQ(plots.at(0).at("y_label").get<std::string>(), "E_dem_side [J]");
  EXPECT_EQ(plots.at(1).at("y_label").get<std::string>(), "u_probe [m]");
  EXPECT_TRUE(std::filesystem::exists(out / "compare.csv"));

  const auto failed = test::run_arlequin(pair + " --set output.fields=[] --set \"checks=[{column: E_dem_side, statistic: "
                                                "final_over_initial, at_most: 1.0e-9}]\" --out " + (out / "failing").string(), "stdout");
  EXPECT_EQ(failed.exit_code, 5) << failed.output;
  EXPECT_NE(failed.output.find("wave_bar_coupled: a check of its case FAILED"), std::string::npos) << failed.output;
  EXPECT_FALSE(read_json_file(out / "failing" / "compare.json").at("other").at("checks_passed").get<bool>());
}

// A single comparison reports the first break's relative difference where both runs broke (the
// figure compare prints): the lattice bar against itself with bonds of 90 instead of 200 MPa,
// which break earlier under the same slow stretch. And its speed-up: of the time loops less their
// output.
TEST(Cli, CompareReportsTheFirstBreaksRelativeDifference) {
  const auto out = test::scratch_dir("compare_first_break");
  const auto r = test::run_arlequin("compare " + cases + "lattice_bar_failure/case.yaml " + cases + "lattice_bar_failure/case.yaml"
                                    " --set \"dem.sample.counts=[16,16,20]\" --set-other dem.bond.sigma_f=9.0e7"
                                    " --set output.fields=[] --set checks=[] --out " + out.string(), "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json c = read_json_file(out / "compare.json");
  const double t_reference = c.at("reference").at("first_break_time").get<double>();
  const double t_other = c.at("other").at("first_break_time").get<double>();
  EXPECT_LT(t_other, t_reference);
  EXPECT_DOUBLE_EQ(c.at("first_break_relative_difference").get<double>(), (t_other - t_reference) / t_reference);
  EXPECT_FALSE(c.contains("ensemble"));
  // Each run's compute time from its summary.json.
  double compute[2];
  for (int k = 0; k < 2; ++k) {
    const std::string side = k == 0 ? "reference" : "other";
    const Json wall = read_json_file(out / side / "summary.json").at("wall_time");
    compute[k] = c.at(side).at("compute_seconds").get<double>();
    EXPECT_DOUBLE_EQ(compute[k], wall.at("time_loop").get<double>() - wall.at("output").get<double>()) << side;
  }
  EXPECT_DOUBLE_EQ(c.at("speedup_compute").get<double>(), compute[0] / compute[1]);
}

// compare --ensemble: pairs of runs with both time steps moved by k 1e-9 (docs/decisions.md#d44).
// The wave bar is linear, not chaotic: the perturbation moves its runs in proportion to it (the
// reference's own spread 1.3e-9 and 2.5e-9 of the probe's largest value for pairs 1 and 2,
// bounded at 1e-8; zero would mean no perturbation), every pair then tells the same (to 4e-8 of
// the difference, bounded at 2e-7), and the figure reported is the median over the pairs; a
// figure no pair has (a first break) is null per pair and has no median; each model's runs are
// drawn in one colour.
TEST(Cli, CompareEnsembleReportsTheMedianAndTheReferencesOwnSpread) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto out = test::scratch_dir("compare_ensemble");
  const auto r = test::run_arlequin("compare " + cases + "wave_bar_dem/case.yaml " + cases + "wave_bar_coupled/case.yaml"
                                    " --ensemble 3 --set time.end=2e-3 --set output.fields=[] --set checks=[] --out " +
                                        out.string(), "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* run : {"pair_1/reference", "pair_1/other", "pair_2/reference", "pair_2/other"})
    EXPECT_TRUE(std::filesystem::exists(out / run / "series.csv")) << run;
  const Json c = read_json_file(out / "compare.json");
  ASSERT_EQ(c.at("ensemble").at("pairs").get<int>(), 3);
  const Json& probe = c.at("sensors").at(1);
  ASSERT_EQ(probe.at("sensor").get<std::string>(), "u_probe");
  std::vector<double> pairs = probe.at("pairs").at("max_relative_difference").get<std::vector<double>>();
  ASSERT_EQ(pairs.size(), 3u);
  const std::vector<double> spread = probe.at("reference_spread_max_relative").get<std::vector<double>>();
  ASSERT_EQ(spread.size(), 2u);
  for (double s : spread) {
    EXPECT_GT(s, 0.0);
    EXPECT_LT(s, 1e-8);
  }
  for (double p : pairs) EXPECT_NEAR(p, pairs[0], 2e-7 * pairs[0]);
  std::sort(pairs.begin(), pairs.end());
  EXPECT_EQ(probe.at("max_relative_difference").get<double>(), pairs[1]);
  // No break in a bar: each pair's first break is null, and no median is made up.
  const Json& ensemble = c.at("ensemble");
  EXPECT_EQ(ensemble.at("first_break_relative_difference_pairs"), Json::parse("[null, null, null]"));
  EXPECT_FALSE(ensemble.contains("first_break_relative_difference"));
  EXPECT_EQ(ensemble.at("speedup_compute_pairs").size(), 3u);
  // Each sensor's plot: the three pairs' runs, each model's in one colour.
  const Json plots = read_json_file(out / "plots.json");  // kept: a range over a temporary's member dangles
  ASSERT_EQ(plots.at("plots").size(), 2u);
  for (const Json& plot : plots.at("plots")) {
    std::vector<int> colours;
    for (const Json& series : plot.at("series")) colours.push_back(series.at("colour").get<int>());
    EXPECT_EQ(colours, (std::vector<int>{0, 1, 0, 1, 0, 1})) << plot.at("file");
  }
  EXPECT_NE(test::read_text(out / "compare.csv").find(",reference_spread_max_relative,"), std::string::npos);
  EXPECT_NE(r.output.find("wave_bar_coupled (pair 0): 775 DEs"), std::string::npos) << r.output;
}

// case.resolved.yaml (also what `arlequin check` prints) is a case file: read back, it resolves
// to itself (box regions as [[x, y, z], [x, y, z]], defaults included).
TEST(Cases, ResolvedCaseReadsBackToItself) {
  const auto dir = test::scratch_dir("resolved_round_trip");
  std::vector<std::string> files{cases + "demo_beam_impact/case.yaml", cases + "lattice_bar_failure/case.yaml",
                                 std::string(ARLEQUIN_SOURCE_DIR) + "/tests/regression/data/two_materials.yaml"};
#ifdef ARLEQUIN_WITH_CONTINUUM
  files.insert(files.end(), {cases + "wave_bar_coupled/case.yaml", cases + "cantilever_continuum/case.yaml"});
#endif
  for (const std::string& file : files) {
    const app::Scene first = app::build_scene(file, {});
    const auto copy = dir / (std::filesystem::path(file).parent_path().filename().string() + ".yaml");
    std::ofstream(copy) << first.resolved_case;
    app::Scene second;
    ASSERT_NO_THROW(second = app::build_scene(copy, {})) << file << "\n" << first.resolved_case;
    EXPECT_EQ(second.resolved_case, first.resolved_case) << file;
  }
}

// `arlequin laws` lists every registry row, each law by its case-file name and summary.
TEST(Cli, LawsListsEveryRegisteredLaw) {
  const auto r = test::run_arlequin("laws", "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const auto& law : dem::bond_laws())
    EXPECT_NE(r.output.find("  " + std::string(law.name) + " "), std::string::npos) << law.name << "\n" << r.output;
  for (const auto& law : dem::contact_laws())
    EXPECT_NE(r.output.find(std::string(law.summary)), std::string::npos) << law.name << "\n" << r.output;
  EXPECT_LT(r.output.find("bond laws"), r.output.find("contact laws")) << r.output;
  EXPECT_EQ(test::run_arlequin("laws extra.yaml").exit_code, 2);
}

TEST(Cli, VersionHelpAndCheck) {
  EXPECT_EQ(test::run_arlequin("--version", "stdout").exit_code, 0);
  EXPECT_NE(test::run_arlequin("run --help", "stdout").output.find("--steps"), std::string::npos);
  const auto check = test::run_arlequin("check " + cases + "cantilever_chain/case.yaml", "stdout");
  EXPECT_EQ(check.exit_code, 0);
  EXPECT_NE(check.output.find("critical time step"), std::string::npos);
  EXPECT_NE(check.output.find("safety: 0.3"), std::string::npos);  // resolved case with defaults
  EXPECT_NE(check.output.find("tolerance: 0.01"), std::string::npos);
}

// A non-finite state stops the run with a message naming the step and the DE, and the
// outputs written so far stay readable (series.csv rows, summary.json with the failure).
TEST(Runner, NonFiniteStateStopsTheRunAndKeepsOutputs) {
  const auto out = test::scratch_dir("nan_stop");
  app::Scene scene = app::build_scene(cases + "demo_beam_impact/case.yaml", {.overrides = {}, .out_dir = out, .petsc_options = ""});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  app::RunOptions options;
  options.max_steps = 400;
  // Poison one DE's velocity: the check after the first step must stop the run.
  scene.dem.particles.velocity[17] = {nan, 0.0, 0.0};
  try {
    app::run_scene(scene, options);
    FAIL() << "the run should have stopped";
  } catch (const RunError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("step 1 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-finite velocity"), std::string::npos) << msg;
    EXPECT_NE(msg.find("likely cause"), std::string::npos) << msg;
  }
  const Json s = read_json_file(out / "summary.json");
  EXPECT_EQ(s.at("status").get<std::string>(), "failed");
  EXPECT_NE(test::read_text(out / "series.csv").find("time,step"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(out / "fields.xdmf"));
}

// A step above the stability limit (forced past the input check) makes the energy grow
// exponentially: the energy check stops the run as a blow-up, naming the step and the likely
// cause, before any velocity is non-finite. (From rest: Runs.UnstableStepOnAPackingAtRestIsABlowUp.)
TEST(Runner, UnstableStepStopsTheRunAsABlowUp) {
  const auto out = test::scratch_dir("blow_up");
  // A bonded scene without contact: with contact the step check stops a DE that moves more than
  // its radius per step first (PenaltyContact.TooFastOrTooSoftStopsTheRun).
  app::Scene scene = app::build_scene(cases + "cantilever_chain/case.yaml", {.overrides = {}, .out_dir = out, .petsc_options = ""});
  scene.dt = 2.5 * scene.dt_critical;
  app::RunOptions options;
  options.max_steps = 5000;
  try {
    app::run_scene(scene, options);
    FAIL() << "the run should have stopped";
  } catch (const RunError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("exceeds the blow-up limit"), std::string::npos) << msg;
    EXPECT_NE(msg.find("likely cause: a time step too close to the stability limit"), std::string::npos) << msg;
  }
  EXPECT_EQ(read_json_file(out / "summary.json").at("status").get<std::string>(), "failed");
}

// The energy balance's verdict on a row (runner.hpp): within a quarter of the energy that
// started in, entered, left or broke in the scene it says nothing, beyond it (either sign; not
// when it is not finite: the finite check names the DE) it says why the run stops, naming the energies it
// lists and the likely cause.
TEST(Runner, EnergyBalanceBeyondAQuarterOfTheBudgetStopsTheRun) {
  const std::vector<std::pair<std::string, double>> parts{{"DEM kinetic", 0.5}, {"bonds", 0.25}};
  EXPECT_EQ(app::unbalanced(0.24, 1.0, parts, "a cause"), "");
  EXPECT_EQ(app::unbalanced(-0.24, 1.0, parts, "a cause"), "");
  const std::string msg = app::unbalanced(-0.26, 1.0, parts, "a cause");
  EXPECT_NE(msg.find("the energy balance is off by -0.26 J, 26 % of the 1 J"), std::string::npos) << msg;
  EXPECT_NE(msg.find("now DEM kinetic 0.5 J, bonds 0.25 J"), std::string::npos) << msg;
  EXPECT_NE(msg.find("likely cause: a cause"), std::string::npos) << msg;
  EXPECT_NE(app::unbalanced(0.26, 1.0, parts, "a cause"), "");
  EXPECT_EQ(app::unbalanced(std::nan(""), 1.0, parts, "a cause"), "");
}

// Ctrl-C during the time loop: the run stops after the step it is in, closes every output as
// after a failure (series.csv rows, fields.h5 renamed into place, summary.json "interrupted")
// and throws Interrupted, which is not a RunError, so sweeps and suites do not carry on.
// Outside the run the signal's previous handler is back.
TEST(Runner, CtrlCStopsTheRunAndKeepsOutputs) {
  static_assert(!std::is_base_of_v<RunError, Interrupted>);
  const auto out = test::scratch_dir("interrupted");
  app::Scene scene = app::build_scene(cases + "demo_beam_impact/case.yaml", {.overrides = {}, .out_dir = out, .petsc_options = ""});
  app::RunOptions options;
  int rows = 0;
  options.stop_after_row = [&](const auto&) {
    if (++rows == 3) std::raise(SIGINT);
    return std::string();
  };
  try {
    app::run_scene(scene, options);
    FAIL() << "the run should have stopped";
  } catch (const Interrupted& e) {
    EXPECT_EQ(e.signal(), SIGINT);
    EXPECT_NE(std::string(e.what()).find("interrupted by SIGINT"), std::string::npos) << e.what();
  }
  EXPECT_EQ(rows, 3);
  const Json s = read_json_file(out / "summary.json");
  EXPECT_EQ(s.at("status").get<std::string>(), "interrupted");
  const std::string series = test::read_text(out / "series.csv");
  EXPECT_EQ(std::count(series.begin(), series.end(), '\n'), 4);  // the header and the three rows
  EXPECT_TRUE(std::filesystem::exists(out / "fields.h5"));
  EXPECT_TRUE(no_temporary_files(out));
  struct sigaction now {};
  sigaction(SIGINT, nullptr, &now);
  EXPECT_EQ(now.sa_handler, SIG_DFL);
}

// A Ctrl-C after the last step (while the final outputs are written) must not be lost: the run
// completes, and the command still ends, so a suite does not carry on.
TEST(Runner, CtrlCAfterTheLastStepStillEndsTheCommand) {
  const auto out = test::scratch_dir("interrupted_at_end");
  app::Scene scene = app::build_scene(cases + "demo_beam_impact/case.yaml", {.overrides = {}, .out_dir = out, .petsc_options = ""});
  app::RunOptions options;
  options.max_steps = 1;  // rows at steps 0 and 1: the second is the last
  int rows = 0;
  options.stop_after_row = [&](const auto&) {
    if (++rows == 2) std::raise(SIGINT);
    return std::string();
  };
  EXPECT_THROW(app::run_scene(scene, options), Interrupted);
  EXPECT_EQ(rows, 2);
  const Json s = read_json_file(out / "summary.json");
  EXPECT_EQ(s.at("status").get<std::string>(), "completed");
  EXPECT_TRUE(no_temporary_files(out));
}

// The same through the executable, by SIGTERM (a batch system's stop): exit code 128 + 15.
TEST(Runner, SigtermEndsTheCommandWithItsExitCode) {
  const auto out = test::scratch_dir("sigterm");
  // The shell runs arlequin in the background, waits until its fields file is open (the time
  // loop starts right after), stops it and reports its exit code.
  const std::string fields_open = "ls " + out.string() + "/fields.h5.part.* >/dev/null 2>&1";
  const auto r = test::run_arlequin("run " + cases + "demo_beam_impact/case.yaml --quiet --set time.end=10 --out " +
                                    out.string() + " 2>&1 >/dev/null & pid=$!; for i in $(seq 300); do " + fields_open +
                                    " && break; sleep 0.1; done; sleep 0.5; kill -TERM $pid; wait $pid");
  EXPECT_EQ(r.exit_code, 128 + SIGTERM) << r.output;
  EXPECT_NE(r.output.find("interrupted by SIGTERM"), std::string::npos) << r.output;
  EXPECT_EQ(read_json_file(out / "summary.json").at("status").get<std::string>(), "interrupted");
  EXPECT_TRUE(no_temporary_files(out));
}

#ifdef ARLEQUIN_WITH_CONTINUUM
// Output rows do not change the motion of a coupled run, and their energies are those of a
// bond pass. The coupled wave bar for 300 steps with a row every ~3.4 steps (the case's) and
// with rows only at the start and the end, with fe and with nem: the same DEs and continuum
// velocities to the bit, and the last row's bond energy (recorded in the last step's force
// pass) is the bond sets' own evaluation. All four scenes are built in this process, which
// also checks that a second solver of one mesh is the same bits as the first (nem's
// coordinates follow node numbers, not memory addresses: continuum/nem/natural_neighbours.hpp).
TEST(Runner, OutputRowsLeaveTheCoupledMotionUnchanged) {
  struct Outcome {
    std::vector<Vec3> position, velocity;
    std::vector<double> continuum_velocity;
    double evaluated_bond_energy = 0.0;  // the bond sets' own pass, no record
    app::RunResult result;
  };
  for (const std::string solver : {"fe", "nem"}) {
    const auto run = [&](const std::string& every) {
      // The scene stays where it is built: its coupling holds references into it.
      app::Scene scene = app::build_scene(
          cases + "wave_bar_coupled/case.yaml",
          {.overrides = {"output.fields=[]", "output.every=" + every, "continuum.solver=" + solver},
           .out_dir = test::scratch_dir("rows_" + solver + "_" + every), .petsc_options = ""});
      app::RunOptions options;
      options.max_steps = 300;
      Outcome out;
      out.result = app::run_scene(scene, options);
      out.position = scene.dem.particles.position;
      out.velocity = scene.dem.particles.velocity;
      out.continuum_velocity = scene.continuum->solver().velocity();
      for (const auto& set : scene.dem.bond_sets()) out.evaluated_bond_energy += set->energy(scene.dem.particles);
      return out;
    };
    const Outcome dense = run("1.0e-6"), sparse = run("1.0");
    EXPECT_EQ(dense.position, sparse.position) << solver;
    EXPECT_EQ(dense.velocity, sparse.velocity) << solver;
    EXPECT_EQ(dense.continuum_velocity, sparse.continuum_velocity) << solver;
    EXPECT_GT(dense.evaluated_bond_energy, 0.0) << solver;
    EXPECT_EQ(dense.result.energies.bond, dense.evaluated_bond_energy) << solver;
    EXPECT_EQ(dense.result.energies.bond, sparse.result.energies.bond) << solver;
    EXPECT_EQ(dense.result.sensors, sparse.result.sensors) << solver;
  }
}
#endif

}  // namespace
}  // namespace arlequin
