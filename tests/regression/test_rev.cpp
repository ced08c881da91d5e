// SPDX-License-Identifier: GPL-3.0-or-later
// Virtual material tests, the calibration of beam bonds and the composite REV
// (app/virtual_tests.hpp, app/calibrate.hpp, cases/rev_elastic; docs/validation.md R2, R3).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>

#include "app/runner.hpp"
#include "app/virtual_tests.hpp"
#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/json.hpp"
#include "support/cli.hpp"
#include "support/omp_threads.hpp"

namespace arlequin {
namespace {

const std::filesystem::path rev_case = std::filesystem::path(ARLEQUIN_SOURCE_DIR) / "cases" / "rev_elastic";

void write(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

// A homogeneous packing of ~2.4k DEs (1.6 mm cube, mean radius 60 um), cached in `dir`.
std::filesystem::path homogeneous_case(const std::filesystem::path& dir) {
  write(dir / "sample.yaml",
        "name: homogeneous\n"
        "time: {end: 1.0e-6}\n"
        "dem:\n"
        "  sample: {build: packing, region: {box: [[0, 0, 0], [1.6e-3, 1.6e-3, 1.6e-3]]}, radius: {mean: 6.0e-5, std: 0.25},\n"
        "           seed: 3, file: sample.h5}\n"
        "  density: 1200\n"
        "  bond: {law: beam, E_mu: 1.0e11, nu_mu: 0.3, r_mu: 0.3}\n");
  return dir / "sample.yaml";
}

// homogeneous_case's packing with BBF bonds (sigma_f 2 GPa), written as dir/bbf_case.yaml.
std::filesystem::path bbf_case(const std::filesystem::path& dir) {
  std::string text = test::read_text(homogeneous_case(dir));
  text.replace(text.find("r_mu: 0.3}"), 10, "r_mu: 0.3, sigma_f: 2.0e9}");
  write(dir / "bbf_case.yaml", text);
  return dir / "bbf_case.yaml";
}

app::LoadCase load_case(const char* name, int face, int direction) {
  app::LoadCase load;
  load.name = name;
  load.face = face;
  load.direction = direction;
  return load;
}

// The engineering constants of a composite suite from its tests.csv rows of one sample.
struct RevConstants {
  double E_L, E_T, nu_LT, nu_TT, G_LT, G_TT;
};
RevConstants rev_constants(const std::filesystem::path& tests_csv) {
  std::map<std::string, std::map<std::string, std::string>> by_test;
  for (const auto& row : test::read_csv(tests_csv)) {
    EXPECT_EQ(row.at("status"), "ok") << row.at("test");
    by_test[row.at("test")] = row;
  }
  const auto& L = by_test.at("L");
  const auto& T = by_test.at("T");
  return {test::number(L, "modulus"),
          test::number(T, "modulus"),
          0.5 * (test::number(L, "poisson_x") + test::number(L, "poisson_y")),
          test::number(T, "poisson_y"),
          test::number(by_test.at("LT"), "modulus"),
          test::number(by_test.at("TT"), "modulus")};
}

// Tension along two axes and simple shear of a homogeneous packing: the moduli of an isotropic
// solid, measured quasi-statically, and E_M proportional to E_mu (the calibration's premise).
TEST(VirtualTests, HomogeneousPackingIsIsotropicAndScalesWithEmu) {
  const auto dir = test::scratch_dir("virtual_tests_homogeneous");
  const auto case_file = homogeneous_case(dir);
  app::SceneOptions options;
  app::QuasiStatic plan;
  plan.ramp = plan.plateau = 4.0;  // the affine estimate of the shear modulus is well above the clamped cube's
  const auto run = [&](const app::LoadCase& load, const std::string& tag, double E_mu) {
    options.out_dir = dir / tag;
    options.overrides = {"dem.bond.E_mu=" + std::to_string(E_mu)};
    return app::run_virtual_test(case_file, options, load, plan);
  };
  const app::VirtualTestResult z = run(load_case("z", 2, 2), "z", 1e11);
  const app::VirtualTestResult x = run(load_case("x", 0, 0), "x", 1e11);
  const app::VirtualTestResult z2 = run(load_case("z", 2, 2), "z2", 2e11);
  const app::VirtualTestResult shear = run(load_case("s", 2, 0), "s", 1e11);
  for (const auto* r : {&z, &x, &shear}) {
    EXPECT_LT(r->modulus.uncertainty, 0.02 * r->modulus.value) << r->load.name;
    EXPECT_LT(r->force_imbalance, 0.02) << r->load.name;  // quasi-static: both faces carry the same force
    EXPECT_TRUE(std::filesystem::exists(r->out_dir / "test.json"));
  }
  EXPECT_NEAR(x.modulus.value / z.modulus.value, 1.0, 0.1);  // isotropic packing, to its ~2.4k DEs' scatter
  for (int k : {0, 1}) EXPECT_NEAR(z.poisson[k].value, 0.3, 0.05) << k;  // r_mu = 0.3: nu_M near 0.3
  EXPECT_TRUE(std::isnan(z.poisson[2].value));
  // Stiffness proportional to E_mu, the time scale following it: the same run, rescaled.
  EXPECT_NEAR(z2.modulus.value / z.modulus.value, 2.0, 1e-6);
  EXPECT_NEAR(z2.poisson[0].value, z.poisson[0].value, 1e-6);
  // Simple shear of a clamped cube: the apparent modulus is below E / (2 (1 + nu)), bending included.
  const double G = z.modulus.value / (2.0 * (1.0 + z.poisson[0].value));
  EXPECT_LT(shear.modulus.value, G);
  EXPECT_GT(shear.modulus.value, 0.5 * G);
}

// The time scale's affine estimate (virtual_tests.hpp), M = 2 W / (eps^2 V), against its closed
// forms on a simple-cubic lattice of n^3 DEs (radius R, spacing a = 2R, box V = (n a)^3, beam
// bonds of radius r_b = r_mu R): tension along z stretches only the (n - 1) n^2 z-bonds,
// W = (n - 1) n^2 E S a eps^2 / 2, so M = (n - 1)/n E S / a^2; simple shear u_x = gamma z tilts
// them with the DEs unturned, theta_a = theta_b = gamma, W = (n - 1) n^2 (2 E I / a) 3 gamma^2,
// so M = 12 (n - 1)/n E I / a^4. Measured: 4e-11 and 1e-10 of them (the stretch, eps a, is
// the difference of two lengths 1e6 times larger); bound 1e-9.
TEST(VirtualTests, AffineEstimatesOfALatticeAreItsBondsClosedForms) {
  const auto dir = test::scratch_dir("virtual_tests_affine");
  write(dir / "lattice.yaml",
        "name: lattice\n"
        "time: {end: 1.0e-6}\n"
        "dem:\n"
        "  sample: {build: lattice, origin: [0, 0, 0], counts: [4, 4, 4], radius: 1.0e-3}\n"
        "  density: 7800\n"
        "  bond: {law: beam, E_mu: 2.0e11, nu_mu: 0.3, r_mu: 0.5}\n");
  write(dir / "spec.yaml", "case: lattice.yaml\ntests: [{name: L, tension: z}, {name: S, shear: [z, x]}]\n");
  const auto r = test::run_arlequin("virtual-test " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double n = 4, E = 2e11, a = 2e-3, rb = 0.5e-3;
  const double S = std::numbers::pi * rb * rb, I = 0.25 * std::numbers::pi * rb * rb * rb * rb;
  const double tension = read_json_file(dir / "out" / "base" / "L" / "test.json").at("modulus_estimate").get<double>();
  const double shear = read_json_file(dir / "out" / "base" / "S" / "test.json").at("modulus_estimate").get<double>();
  const double tension_closed = (n - 1) / n * E * S / (a * a), shear_closed = 12.0 * (n - 1) / n * E * I / (a * a * a * a);
  std::printf("affine estimates / closed forms - 1: tension %.1e, shear %.1e\n", tension / tension_closed - 1.0,
              shear / shear_closed - 1.0);
  EXPECT_NEAR(tension / tension_closed, 1.0, 1e-9);
  EXPECT_NEAR(shear / shear_closed, 1.0, 1e-9);
}

// A coarse calibration through the command line: the pair hits the target on its packing, the
// curve is written and plotted, and a second calibration reuses the cached curve points.
// A grid value or an axis given twice would only repeat runs: refused, as is a bond section that
// is none, at the spec's own line.
TEST(Calibration, RepeatsAndAWrongBondSectionAreRefused) {
  const auto dir = test::scratch_dir("calibration_bad_spec");
  homogeneous_case(dir);
  const std::string run = "calibrate " + (dir / "calibration.yaml").string() + " --out " + (dir / "out").string();
  const std::string targets = "targets: [{name: epoxy, E: 3.45e9, nu: 0.3, reference: {E_mu: 89.0e9, r_mu: 0.33}}]\n";
  write(dir / "calibration.yaml", "case: sample.yaml\nr_mu: [0.3, 0.2, 0.2]\n" + targets);
  auto r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("calibration.yaml:2: r_mu: a grid value is given twice"), std::string::npos) << r.output;
  write(dir / "calibration.yaml", "case: sample.yaml\nr_mu: [0.2, 0.3]\naxes: [x, x]\n" + targets);
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("calibration.yaml:3: axes: axis x is given twice"), std::string::npos) << r.output;
  write(dir / "calibration.yaml", "case: sample.yaml\nbond: dem.bnd\nr_mu: [0.2, 0.3]\n" + targets);
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("calibration.yaml:2: bond: dem.bnd.E_mu=1: dem.bnd: unknown key"), std::string::npos) << r.output;
}

// A bonded packing at rest, run as it is: its bonds' forces are round-off (each rest length is a
// computed distance), and the motion they cause grows; it must not read as a blow-up (it did
// after 350 steps here, and `arlequin run cases/rev_elastic/case.yaml` after 400). 5700 steps:
// the kinetic energy grows from 5e-33 J to ~1.5e-27 J (DEs at ~3e-11 m/s), far below the check's
// round-off floor (app/runner.cpp).
TEST(Runs, BondedPackingAtRestRunsToTheEnd) {
  const auto dir = test::scratch_dir("packing_at_rest");
  homogeneous_case(dir);
  const auto r = test::run_arlequin("run " + (dir / "sample.yaml").string() + " --set time.end=2e-5 --out " + (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json summary = read_json_file(dir / "out" / "summary.json");
  EXPECT_EQ(summary.at("status").get<std::string>(), "completed");
  EXPECT_LT(summary.at("energies").at("kinetic").get<double>(), 1e-24);
}

// The same packing at rest with a step above the stability limit (forced past the input check):
// the round-off motion grows exponentially, and the energy balance of the first series row (step
// 6) stops it, 1.1e-23 J against 4.2e-25 J (the round-off floor), before any velocity is
// non-finite and before the kinetic energy's look at step 50 (which had stopped it at ~1e86 J).
TEST(Runs, UnstableStepOnAPackingAtRestIsABlowUp) {
  const auto dir = test::scratch_dir("packing_at_rest_unstable");
  app::Scene scene = app::build_scene(homogeneous_case(dir), {.overrides = {}, .out_dir = dir / "out", .petsc_options = ""});
  scene.dt = 3.0 * scene.dt_critical;  // the estimate is safe: at 1.5 x it ran without a blow-up
  app::RunOptions options;
  options.max_steps = 2000;
  try {
    app::run_scene(scene, options);
    FAIL() << "the run should have stopped";
  } catch (const RunError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("step 6 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("the energy balance is off"), std::string::npos) << msg;
    EXPECT_NE(msg.find("likely cause: a time step too close to the stability limit"), std::string::npos) << msg;
  }
}

// The overrides of a verify sample and of a failure target are read before the r_mu grid's
// first run, not after it, as is the check that an RDEF target's case has no BBF strength.
TEST(Calibration, VerifyAndTargetOverridesAreReadBeforeAnyRun) {
  const auto dir = test::scratch_dir("calibration_early_overrides");
  homogeneous_case(dir);
  const std::string run = "calibrate " + (dir / "calibration.yaml").string() + " --out " + (dir / "out").string();
  const std::string grid = "case: sample.yaml\nr_mu: [0.2, 0.3]\ntargets: [{name: epoxy, E: 3.45e9, nu: 0.3}]\n";
  write(dir / "calibration.yaml", grid + "verify: [{name: other, set: [dem.dampng=1]}]\n");
  auto r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("calibration.yaml:4: verify[0].set: dem.dampng=1: dem.dampng: unknown key; did you mean 'damping'?"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "curve")) << "a grid run started";
  write(dir / "calibration.yaml", grid +
                                      "failure:\n  targets:\n    - {name: epoxy, criterion: rdef, variant: averaged, stress: 7.0e7, "
                                      "reference: 1.48e8,\n       set: [dem.failure.rdef.average=bonded_neighbour]}\n");
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("calibration.yaml:7: failure.targets[0].set: dem.failure.rdef.average=bonded_neighbour"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "curve")) << "a grid run started";
  bbf_case(dir);
  write(dir / "calibration.yaml", "case: bbf_case.yaml\nr_mu: [0.2, 0.3]\ntargets: [{name: epoxy, E: 3.45e9, nu: 0.3}]\n"
                                  "failure:\n  targets: [{name: epoxy, criterion: rdef, stress: 7.0e7, reference: 1.48e8}]\n");
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("has a BBF strength (sigma_f); the RDEF target 'epoxy' needs a case without one"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "curve")) << "a grid run started";
}

TEST(Calibration, CoarseCurveHitsTheTargetAndIsCached) {
  const auto dir = test::scratch_dir("calibration_coarse");
  homogeneous_case(dir);
  write(dir / "calibration.yaml",
        "case: sample.yaml\n"
        "r_mu: [0.2, 0.3, 0.4]\n"
        "tolerance: 0.005\n"
        "targets: [{name: epoxy, E: 3.45e9, nu: 0.3, reference: {E_mu: 89.0e9, r_mu: 0.33}}]\n");
  const auto first = test::run_arlequin("calibrate " + (dir / "calibration.yaml").string() + " --out " + (dir / "a").string(), "stdout");
  ASSERT_EQ(first.exit_code, 0) << first.output;
  for (const char* f : {"curve.csv", "curve.png", "calibration.md", "calibration.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / "a" / f)) << f;
  EXPECT_TRUE(std::filesystem::exists(dir / "calibration_cache.json"));  // next to the sample
  const Json pair = read_json_file(dir / "a" / "calibration.json").at("pairs").at(0);
  const Json& achieved = pair.at("achieved").at(0);
  EXPECT_NEAR(achieved.at("E_M").at("value").get<double>(), 3.45e9, 0.05 * 3.45e9);
  EXPECT_NEAR(achieved.at("nu_M").at("value").get<double>(), 0.3, 0.02);
  const double r_mu = pair.at("r_mu").get<double>();
  EXPECT_GT(r_mu, 0.2);
  EXPECT_LT(r_mu, 0.4);
  EXPECT_GE(test::read_csv(dir / "a" / "curve.csv").size(), 3u);

  const auto second = test::run_arlequin("calibrate " + (dir / "calibration.yaml").string() + " --out " + (dir / "b").string(), "stdout");
  ASSERT_EQ(second.exit_code, 0) << second.output;
  EXPECT_EQ(second.output.find("(grid)"), std::string::npos) << second.output;
  EXPECT_EQ(second.output.find("(refinement)"), std::string::npos) << second.output;
  const Json again = read_json_file(dir / "b" / "calibration.json").at("pairs").at(0);
  EXPECT_EQ(again.at("r_mu").get<double>(), r_mu);
}

// Failure calibration (issue: REV failure): BBF and RDEF strengths of the epoxy pair reproduce
// its tensile failure stress on the small packing within the tolerance (3 %), from the seed's
// values as first guesses; the rounds' stress follows the threshold about proportionally (the
// premise of the update), and a BBF case is refused for an RDEF target.
TEST(Calibration, StrengthsReproduceTheTargetFailureStress) {
  const auto dir = test::scratch_dir("calibration_strength");
  homogeneous_case(dir);
  const std::string targets =
      "    - {name: epoxy, criterion: bbf, stress: 7.0e7, E: 3.45e9, E_mu: 1.1527e11, r_mu: 0.2872, reference: 2.0e9}\n"
      "    - {name: epoxy, criterion: rdef, stress: 7.0e7, E: 3.45e9, E_mu: 1.1527e11, r_mu: 0.2872, reference: 1.48e8}\n";
  write(dir / "strength.yaml", "case: sample.yaml\nfailure:\n  tolerance: 0.03\n  targets:\n" + targets);
  const auto r = test::run_arlequin("calibrate " + (dir / "strength.yaml").string() + " --out " + (dir / "out").string(), "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"strength.csv", "calibration.md", "calibration.json"}) EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
  const Json strengths = read_json_file(dir / "out" / "calibration.json").at("strengths");
  ASSERT_EQ(strengths.size(), 2u);
  for (const Json& s : strengths) {
    EXPECT_TRUE(s.at("converged").get<bool>());
    EXPECT_NEAR(s.at("failure_stress").get<double>(), 7.0e7, 0.05 * 7.0e7) << s.at("criterion").get<std::string>();
  }
  // Every round: stress / threshold within 25 % of the first round's (near proportionality).
  const auto rounds = test::read_csv(dir / "out" / "strength.csv");
  ASSERT_GE(rounds.size(), 3u);  // each criterion needed at least one update from the seed's value
  std::map<std::string, double> first;
  for (const auto& row : rounds) {
    const double ratio = test::number(row, "failure_stress") / test::number(row, "threshold");
    if (!first.count(row.at("criterion"))) first[row.at("criterion")] = ratio;
    EXPECT_NEAR(ratio / first[row.at("criterion")], 1.0, 0.25) << row.at("criterion") << " round " << row.at("round");
  }

  bbf_case(dir);
  write(dir / "bad.yaml", "case: bbf_case.yaml\nfailure:\n  targets:\n" + targets.substr(targets.find("    - {name: epoxy, criterion: rdef")));
  const auto bad = test::run_arlequin("calibrate " + (dir / "bad.yaml").string() + " --out " + (dir / "bad").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("needs a case without one"), std::string::npos) << bad.output;
}

// cases/rev_failure reduced to ~2.4k DEs (mean radius 75 um, as the reduced elastic REV), BBF
// and RDEF (per DE, averaged, and over Laguerre cells) with the case's calibrated strengths: the
// suite writes its table with the seed's
// rows, each run softens after a peak stress near the rule of mixtures (1.30 GPa; looser bounds
// than R4's, which needs >= 40k DEs), with broken fractions per bond set, breaks.csv, fields and
// the plot of seed Figs. 5-6; the energy of the broken bonds is booked.
TEST(RevFailure, ReducedRevBreaksNearTheFibreStrain) {
  const auto dir = test::scratch_dir("rev_failure_reduced");
  const auto spec = std::filesystem::path(ARLEQUIN_SOURCE_DIR) / "cases" / "rev_failure" / "failure_tests.yaml";
  const auto r = test::run_arlequin("virtual-test " + spec.string() + " --sample rev_10k --set dem.sample.radius.mean=7.5e-5 --set dem.sample.file=" +
                                        (dir / "sample.h5").string() + " --out " + (dir / "out").string(),
                                    "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string md = test::read_text(dir / "out" / "failure.md");
  const auto rows = test::read_csv(dir / "out" / "failure.csv");
  ASSERT_EQ(rows.size(), 4u);  // L_bbf, L_rdef, L_rdef_averaged, L_rdef_laguerre
  for (const auto& row : rows) {
    const std::string test = row.at("test");
    // The table shows each run's own values (in GPa and 1e-3, as failure.csv has them in SI).
    char values[64];
    std::snprintf(values, sizeof values, "| %.3f | %.2f |", test::number(row, "failure_stress") / 1e9,
                  test::number(row, "failure_strain") * 1e3);
    EXPECT_NE(md.find("| rev_10k | " + test + " | " + row.at("particles") + " " + values), std::string::npos) << values << md;
    EXPECT_EQ(row.at("status"), "ok") << test;
    // BBF breaks abruptly (the stress falls below half its peak); RDEF softens more gradually.
    if (test == "L_bbf") {
      EXPECT_EQ(row.at("broke"), "1");
    }
    EXPECT_LT(test::number(row, "final_stress"), 0.9 * test::number(row, "failure_stress")) << test;
    // Bounds 1.4x the largest deviation of the four criteria on this sample: the peak within
    // 12 % of the rule of mixtures, the strain at it within 1.0e-3 of the four's mean.
    EXPECT_NEAR(test::number(row, "failure_strain"), 10.6e-3, 1.0e-3) << test;
    EXPECT_NEAR(test::number(row, "failure_stress"), 1.30e9, 0.12 * 1.30e9) << test;
    EXPECT_GT(test::number(row, "fracture_energy"), 0.0) << test;
    const auto run = dir / "out" / "rev_10k" / test;
    const Json j = read_json_file(run / "test.json");
    // Damage spreads to every bond set after the peak, and most of the fibre's breaks come after it.
    for (const char* set : {"fibre", "matrix", "interface"}) EXPECT_GT(j.at("broken_at_end").at(set).get<double>(), 0.0) << set;
    EXPECT_GT(j.at("broken_at_end").at("fibre").get<double>(), 2.0 * j.at("broken_at_peak").at("fibre").get<double>()) << test;
    for (const char* f : {"failure.png", "fields.xdmf", "breaks.csv"}) EXPECT_TRUE(std::filesystem::exists(run / f)) << test << " " << f;
  }
}

// The end rule of a test to failure: a brittle break rings through zero; with stop_after the
// run goes on until the stress stays low, without it the first low row ends it.
// The REV's failure test (the reduced REV of the test above) on one and two threads: its bond
// passes gather on threads, its per-DE loops (kicks, damping, the finite check) run on threads
// split alike; BBF, and RDEF whose virial the gather records. The series and breaks are the same
// byte for byte, and --test runs only the named test.
TEST(RevFailure, RunsAreBitIdenticalOnOneAndTwoThreads) {
  const auto dir = test::scratch_dir("rev_failure_threads");
  const auto spec = std::filesystem::path(ARLEQUIN_SOURCE_DIR) / "cases" / "rev_failure" / "failure_tests.yaml";
  std::map<std::string, std::string> files[2];
  for (int threads : {1, 2}) {
    const test::OmpThreadsOfRuns scope(threads);
    const auto out = dir / ("threads_" + std::to_string(threads));
    const auto r = test::run_arlequin("virtual-test " + spec.string() + " --sample rev_10k --test L_bbf --test L_rdef" +
                                      " --set dem.sample.radius.mean=7.5e-5 --set dem.sample.file=" + (dir / "sample.h5").string() +
                                      " --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(test::read_csv(out / "failure.csv").size(), 2u);
    for (const char* name : {"L_bbf", "L_rdef"})
      for (const char* file : {"series.csv", "breaks.csv"})
        files[threads - 1][std::string(name) + "/" + file] = test::read_text(out / "rev_10k" / name / file);
  }
  for (const auto& [name, text] : files[0]) {
    EXPECT_GT(std::count(text.begin(), text.end(), '\n'), 50) << name;  // rows; breaks: both break
    EXPECT_EQ(text, files[1][name]) << name;
  }
}

TEST(RevFailure, EndRuleWaitsOutTheRingingOfABreakWhenAsked) {
  app::FailurePlan plan;
  plan.expected_strain = 1e-2;
  plan.stop_below = 0.1;
  plan.rows_per_transit = 4;
  const std::vector<std::pair<double, double>> rows{  // stress Pa, strain
      {0.0, 1e-3},   {0.0, 1.5e-3},  // low, but before 0.2 expected_strain: never the end
      {1.0e9, 5e-3}, {1.3e9, 1e-2},  // the peak
      {-0.2e9, 1.01e-2}, {0.5e9, 1.02e-2}, {-0.1e9, 1.03e-2}, {0.05e9, 1.04e-2}, {0.02e9, 1.05e-2},
      {0.01e9, 1.06e-2}};
  const auto first_stop = [&](const app::FailurePlan& p) {
    app::FailureStop stop(p);
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (stop.after_row(rows[i].first, rows[i].second)) return static_cast<int>(i);
    return -1;
  };
  EXPECT_EQ(first_stop(plan), 4);  // stop_after 0: the first dip of the ringing
  plan.stop_after = 1.0;           // one transit = 4 rows in a row below 0.13 GPa
  EXPECT_EQ(first_stop(plan), 9);
  plan.stop_after = 2.0;
  EXPECT_EQ(first_stop(plan), -1);
}

TEST(VirtualTests, CompositeSpecNeedsItsFourTests) {
  const auto dir = test::scratch_dir("virtual_tests_bad_spec");
  homogeneous_case(dir);
  write(dir / "spec.yaml",
        "case: sample.yaml\n"
        "tests: [{name: L, tension: z}, {name: T, tension: x}, {name: LT, shear: [x, z]}]\n"
        "composite: {fibre: {E: 260.0e9, nu: 0.3}, matrix: {E: 3.45e9, nu: 0.3}, fibre_fraction: 0.513}\n");
  const auto r = test::run_arlequin("virtual-test " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("a composite suite needs a test named TT"), std::string::npos) << r.output;
}

// Each test and sample writes into a folder of its name: two of one name are refused, and an
// unknown --sample gets the closest name.
TEST(VirtualTests, NamesAreUniqueAndSamplesAreSuggested) {
  const auto dir = test::scratch_dir("virtual_tests_names");
  homogeneous_case(dir);
  const std::string run = "virtual-test " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string();
  write(dir / "spec.yaml", "case: sample.yaml\ntests: [{name: L, tension: z}, {name: L, tension: x}]\n");
  auto r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("spec.yaml:2: tests[1].name: test 'L' is defined twice"), std::string::npos) << r.output;
  write(dir / "spec.yaml", "case: sample.yaml\nsamples: [{name: a}, {name: a}]\ntests: [{name: L, tension: z}]\n");
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("samples[1].name: sample 'a' is defined twice"), std::string::npos) << r.output;
  write(dir / "spec.yaml", "case: sample.yaml\nsamples: [{name: dense}]\ntests: [{name: L, tension: z}]\n");
  r = test::run_arlequin(run + " --sample dens");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--sample dens: no sample of that name; did you mean 'dense'?"), std::string::npos) << r.output;
  r = test::run_arlequin(run + " --test l");  // --test: the same for a test's name
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--test l: no test of that name; did you mean 'L'?"), std::string::npos) << r.output;
  // A spec's own override names its line and key, not a --set the user never typed.
  write(dir / "spec.yaml", "case: sample.yaml\nsamples: [{name: a, set: [dem.dampng=1]}]\ntests: [{name: L, tension: z}]\n");
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("spec.yaml:2: samples[0].set: dem.dampng=1: dem.dampng: unknown key; did you mean 'damping'?"),
            std::string::npos)
      << r.output;
  write(dir / "spec.yaml", "case: sample.yaml\ntests: [{name: LT, shaer: [x, z]}]\n");
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("give exactly one of tension: axis or shear: [face, direction]; is 'shaer' (line 2) a misspelling of "
                          "'shear'?"),
            std::string::npos)
      << r.output;
}

// Every sample with every test is read before the first run: a bad override of the second test,
// a reference to a bond set the case lacks, or a test to failure whose case (with that test's
// overrides) cannot break, stops the suite before the first test runs.
TEST(VirtualTests, EveryTestIsReadBeforeTheFirstRuns) {
  const auto dir = test::scratch_dir("virtual_tests_early_overrides");
  homogeneous_case(dir);
  const std::string run = "virtual-test " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string();
  write(dir / "spec.yaml", "case: sample.yaml\ntests: [{name: L, tension: z}, {name: T, tension: x, set: [dem.dampng=1]}]\n");
  auto r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("spec.yaml:2: tests[1].set: dem.dampng=1: dem.dampng: unknown key; did you mean 'damping'?"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "base" / "L")) << "test L ran";
  // A case that can break (BBF), so that test L would run to its end if the reference were not read first.
  bbf_case(dir);
  write(dir / "spec.yaml",
        "case: bbf_case.yaml\nfailure: {expected_strain: 0.01}\ntests:\n  - {name: L, tension: z,\n"
        "     reference: {name: seed, stress: [1.0e9, 2.0e9], strain: [0.01, 0.02], broken: {bond: [1, 2]}}}\n");
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("spec.yaml:5: tests[0].reference.broken.bond: the case has no bond set 'bond'; did you mean 'bonds'?"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "base" / "L")) << "test L ran";
  write(dir / "spec.yaml",
        "case: bbf_case.yaml\nfailure: {expected_strain: 0.01}\n"
        "tests: [{name: L, tension: z}, {name: T, tension: x, set: [dem.bond.sigma_f=0]}]\n");
  r = test::run_arlequin(run);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("test T runs to failure but the case has no failure criterion"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "base" / "L")) << "test L ran";
}

// The REV of cases/rev_elastic reduced to ~2.4k DEs (mean radius 75 um: the matrix between the
// fibre and a face is about one DE thick), all four tests through the command line. R3's bounds
// need >= 40k DEs; this sample is stiffer across the fibre than the seed's FEM row (coarse
// samples are), so its transverse moduli are held in bands of +-10 points around its own ratio
// to that row; E_L within 1.4x its deviation from the rule of mixtures, nu_LT and nu_TT' within
// 0.03 of the seed's 0.29 and of this sample's 0.30 (the values: the composite table it writes).
TEST(RevElastic, ReducedRevGivesTheCompositeConstants) {
  const auto dir = test::scratch_dir("rev_reduced");
  write(dir / "spec.yaml",
        "case: " + (rev_case / "case.yaml").string() + "\n"
        "samples: [{name: reduced, set: [\"dem.sample.radius.mean=7.5e-5\", \"dem.sample.file=" + (dir / "sample.h5").string() + "\"]}]\n"
        "tests: [{name: L, tension: z}, {name: T, tension: x}, {name: LT, shear: [x, z]}, {name: TT, shear: [y, x]}]\n"
        "composite:\n"
        "  fibre: {E: 260.0e9, nu: 0.3}\n"
        "  matrix: {E: 3.45e9, nu: 0.3}\n"
        "  fibre_fraction: 0.513\n"
        "  references: [{name: seed FEM, E_L: 134.0e9, E_T: 10.7e9, G_LT: 2.32e9, G_TT: 2.21e9}]\n");
  const auto r = test::run_arlequin("virtual-test " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string(), "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string table = test::read_text(dir / "out" / "composite.md");
  EXPECT_NE(table.find("| theory (ROM; Hashin K23; Halpin-Tsai) | | 135.1 |"), std::string::npos) << table;
  const RevConstants c = rev_constants(dir / "out" / "tests.csv");
  // The DEM row shows the sample's own moduli (GPa, 4 significant digits).
  char shown[64];
  std::snprintf(shown, sizeof shown, "| DEM reduced | 2415 | %.4g ± ", c.E_L * 1e-9);
  EXPECT_NE(table.find(shown), std::string::npos) << shown << table;
  std::snprintf(shown, sizeof shown, "| %.4g ± ", c.E_T * 1e-9);
  EXPECT_NE(table.find(shown), std::string::npos) << shown << table;
  EXPECT_NEAR(c.E_L, 135.06e9, 0.105 * 135.06e9);
  EXPECT_NEAR(c.nu_LT, 0.29, 0.028);
  EXPECT_NEAR(c.nu_TT, 0.30, 0.03);
  struct Band {
    double value, fem, ratio;  // the sample's ratio to the seed's FEM row
  };
  for (const Band& b : {Band{c.E_T, 10.7e9, 1.26}, Band{c.G_LT, 2.32e9, 1.50}, Band{c.G_TT, 2.21e9, 1.33}})
    EXPECT_NEAR(b.value / b.fem, b.ratio, 0.10) << b.value;
  for (const auto& row : test::read_csv(dir / "out" / "tests.csv")) EXPECT_LT(test::number(row, "force_imbalance"), 0.02) << row.at("test");
}

// R2: the calibration of cases/rev_elastic (curve points are cached next to its sample, so a
// second run only verifies): both Table 1 materials within 5 % on E_M and 0.02 on nu_M, on the
// calibration packing and on another seed; case.yaml carries the calibrated pairs.
TEST(ValidationRev, CalibrationReproducesTable1Materials) {
  const auto dir = test::scratch_dir("rev_calibration");
  std::string spec = test::read_text(rev_case / "calibration.yaml");
  spec = spec.substr(0, spec.find("verify:"));  // the 40k and 80k verifications are README figures
  spec.replace(spec.find("case: homogeneous.yaml"), 22, "case: " + (rev_case / "homogeneous.yaml").string());
  write(dir / "calibration.yaml",
        spec + "verify: [{name: seed_8, set: [\"name=rev_homogeneous_10k_seed8\", \"dem.sample.seed=8\"]}]\n");
  const auto r = test::run_arlequin("calibrate " + (dir / "calibration.yaml").string() + " --out " + (dir / "out").string(), "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json pairs = read_json_file(dir / "out" / "calibration.json").at("pairs");
  ASSERT_EQ(pairs.size(), 2u);
  CaseFile rev = CaseFile::load(rev_case / "case.yaml");
  CaseNode materials = rev.root().child("dem").child("materials");
  for (const Json& pair : pairs) {
    for (const Json& a : pair.at("achieved")) {
      const double E = pair.at("target_E_M").get<double>();
      EXPECT_NEAR(a.at("E_M").at("value").get<double>(), E, 0.05 * E) << pair.at("name").get<std::string>() << " " << a.at("sample").get<std::string>();
      EXPECT_NEAR(a.at("nu_M").at("value").get<double>(), 0.3, 0.02) << pair.at("name").get<std::string>() << " " << a.at("sample").get<std::string>();
    }
    CaseNode bond = materials.child_named(pair.at("name").get<std::string>() == "carbon_fibre" ? "fibre" : "matrix").child("bond");
    EXPECT_NEAR(bond.number("E_mu", Range::positive(), "Pa"), pair.at("E_mu").get<double>(), 0.01 * pair.at("E_mu").get<double>());
    EXPECT_NEAR(bond.number("r_mu", Range::positive(), "1"), pair.at("r_mu").get<double>(), 0.001);
  }
}

// R4 on the 40k-DE REV, longitudinal tension to failure (docs/validation.md#r4, as decided):
// BBF sigma_fail 1.30-1.50 GPa at eps_fail (9.6 +- 1.0)e-3; RDEF, the seed's criterion as written
// (per DE, its own volume share), sigma_fail within 10 % of the seed's RDEF range (1.21-1.60 GPa)
// and eps_fail above BBF's. The averaged and Laguerre variants the README quotes are options, not
// the seed's criterion: held to the same stress band and to the strain window of the seed's
// RDEF and BBF rows widened by R4's 1e-3 (7.9-11.9e-3); they fail before BBF (README), which is
// why they are not R4's RDEF.
TEST(ValidationRev, Rev40kFailureMatchesSeedTable4) {
  const auto dir = test::scratch_dir("rev_40k_failure");
  const auto r = test::run_arlequin("virtual-test " + (std::filesystem::path(ARLEQUIN_SOURCE_DIR) / "cases" / "rev_failure" /
                                                       "failure_tests.yaml").string() +
                                        " --sample rev_40k --out " + dir.string(),
                                    "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::map<std::string, std::map<std::string, std::string>> by_test;
  for (const auto& row : test::read_csv(dir / "failure.csv")) by_test[row.at("test")] = row;
  ASSERT_EQ(by_test.size(), 4u);
  for (const auto& [test, row] : by_test) EXPECT_EQ(row.at("status"), "ok") << test;
  const auto stress = [&](const char* test) { return test::number(by_test.at(test), "failure_stress"); };
  const auto strain = [&](const char* test) { return test::number(by_test.at(test), "failure_strain"); };
  EXPECT_GE(stress("L_bbf"), 1.30e9);
  EXPECT_LE(stress("L_bbf"), 1.50e9);
  EXPECT_NEAR(strain("L_bbf"), 9.6e-3, 1.0e-3);
  for (const char* rdef : {"L_rdef", "L_rdef_averaged", "L_rdef_laguerre"}) {
    EXPECT_GE(stress(rdef), 1.21e9) << rdef;
    EXPECT_LE(stress(rdef), 1.60e9) << rdef;
    EXPECT_GE(strain(rdef), 7.9e-3) << rdef;
    EXPECT_LE(strain(rdef), 11.9e-3) << rdef;
  }
  EXPECT_GT(strain("L_rdef"), strain("L_bbf"));
}

// R3 on the 40k-DE REV: E_L within -5 % / +15 % of 135.06 GPa, nu_LT 0.29 +- 0.02, E_T, G_LT and
// G_TT' within 20 % of the seed's FEM row (10.7 / 2.32 / 2.21 GPa).
TEST(ValidationRev, Rev40kMatchesSeedTable3) {
  const auto dir = test::scratch_dir("rev_40k");
  const auto r = test::run_arlequin("virtual-test " + (rev_case / "virtual_tests.yaml").string() + " --sample rev_40k --out " +
                                        dir.string(), "stdout");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const RevConstants c = rev_constants(dir / "tests.csv");
  EXPECT_GE(c.E_L, 0.95 * 135.06e9);
  EXPECT_LE(c.E_L, 1.15 * 135.06e9);
  EXPECT_NEAR(c.nu_LT, 0.29, 0.02);
  EXPECT_NEAR(c.E_T, 10.7e9, 0.2 * 10.7e9);
  EXPECT_NEAR(c.G_LT, 2.32e9, 0.2 * 2.32e9);
  EXPECT_NEAR(c.G_TT, 2.21e9, 0.2 * 2.21e9);
}

}  // namespace
}  // namespace arlequin
