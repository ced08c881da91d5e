// SPDX-License-Identifier: GPL-3.0-or-later
// The dry-fabric impact (cases/fabric_impact, docs/validation.md#r8) reduced to a 10 x 10 mm
// target (reduced.yaml): the sphere's kinetic energy 1/2 m v^2 = 2.557 J (R8), kept by the
// yarns, springs and contacts without damping, and with breakage by the broken springs'
// fracture energy too; bad weaves and impactors refused in one line naming the key. The coupled
// target (cases/fabric_impact_coupled) reduced likewise, and a yarn pulse through its overlap.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "common/json.hpp"
#include "support/cli.hpp"
#include "support/hdf5_read.hpp"

namespace arlequin {
namespace {

const std::string reduced_case = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/fabric_impact/reduced.yaml";

double at(const std::map<std::string, std::string>& row, const std::string& column) { return test::number(row, column); }

// R8: a steel sphere of 5.43 mm (7530 kg/m^3) at 90 m/s.
double impact_energy() {
  const double r = 2.715e-3, m = 7530.0 * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  return 0.5 * m * 90.0 * 90.0;
}

double worst_balance(const std::vector<std::map<std::string, std::string>>& rows) {
  double worst = 0.0;
  for (const auto& row : rows) worst = std::max(worst, std::abs(at(row, "E_balance")));
  return worst;
}

// The reduced impact with `sets` (--set options) run into the scratch folder `name` (out): its
// series rows, none if the run failed (which is reported).
std::vector<std::map<std::string, std::string>> run_reduced(const std::string& name, const std::string& sets,
                                                           std::filesystem::path& out) {
  out = test::scratch_dir(name);
  const auto r = test::run_arlequin("run " + reduced_case + sets + " --set output.dir=" + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.exit_code == 0 ? test::read_csv(out / "series.csv") : std::vector<std::map<std::string, std::string>>{};
}

// No breakage (failure_strain 0): the total energy stays within 1e-4 of the impact energy over
// the 40 us (measured 4.8e-5), the sphere is stopped and sent back (the fabric holds it), and
// the starting total is the sphere's 1/2 m v^2 (plus the yarns' contact energy at rest, below
// 1e-5 of it: the builder's overlap tolerance).
TEST(Fabric, ReducedImpactWithoutBreakageKeepsTheImpactEnergy) {
  std::filesystem::path out;
  const auto rows = run_reduced("fabric_reduced_unbreakable", " --set dem.sample.yarn.failure_strain=0", out);
  ASSERT_FALSE(rows.empty());
  const double E0 = impact_energy();
  EXPECT_NEAR(at(rows.front(), "E_total") / E0, 1.0, 1e-5);
  EXPECT_LT(worst_balance(rows), 1e-4 * E0);
  EXPECT_GT(at(rows.back(), "sphere_velocity"), 0.0);  // rebounding
  EXPECT_EQ(at(rows.back(), "E_fracture"), 0.0);
}

// With the Kevlar's failure strain (3.5 %), springs break; their fracture energy closes the
// balance within 2e-3 of the impact energy (measured 1.1e-3; the issue's bound is 1 %), and the
// summary gives the first break's time, which the breaks file's first row repeats.
TEST(Fabric, ReducedImpactBreakageIsClosedByTheFractureEnergy) {
  std::filesystem::path out;
  const auto rows = run_reduced("fabric_reduced_breakable", "", out);
  ASSERT_FALSE(rows.empty());
  const double E0 = impact_energy();
  EXPECT_LT(worst_balance(rows), 2e-3 * E0);
  EXPECT_GT(at(rows.back(), "E_fracture"), 0.01 * E0);
  const Json summary = Json::parse(test::read_text(out / "summary.json"));
  const double first = summary.at("first_break_time").get<double>();
  const auto breaks = test::read_csv(out / "breaks.csv");
  ASSERT_FALSE(breaks.empty());
  EXPECT_NEAR(at(breaks.front(), "time"), first, 1e-9 * first);  // the CSV has 12 digits
  EXPECT_GT(first, 0.0);
  EXPECT_LT(first, 4e-5);
  // A broken spring stretched to the failure strain.
  EXPECT_GE(at(breaks.front(), "stress"), 0.035);
}

// The fields of the last frame (40 us, in the thick of the impact): every intact spring's
// strain (the stretch of its line) is below the failure strain it would have broken at, and some
// are near it (the field is the stretch, not zero); a broken one was stretched to it. Each DE's
// `group` is its smallest group: the first weft yarn's DEs are in group 0 (`weft_0_0`, also in
// the larger `weft` and `edges`), the sphere in its own group, the last defined.
TEST(Fabric, FieldsGiveEachSpringsStrainAndEachDesYarn) {
  std::filesystem::path out;
  const auto rows = run_reduced("fabric_reduced_fields", " --set output.fields=[particles,bonds] --set output.fields_every=4e-5", out);
  ASSERT_FALSE(rows.empty());
  const hid_t file = H5Fopen((out / "fields.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const std::string last = "/frames/000001";  // t = 0 and t = 40 us
  const auto strain = test::read_dataset<double>(file, last + "/bonds/cell/strain", H5T_NATIVE_DOUBLE);
  const auto broken = test::read_dataset<std::int32_t>(file, last + "/bonds/cell/broken", H5T_NATIVE_INT32);
  const auto group = test::read_dataset<std::int32_t>(file, last + "/particles/point/group", H5T_NATIVE_INT32);
  H5Fclose(file);
  ASSERT_EQ(strain.size(), broken.size());
  ASSERT_FALSE(strain.empty());
  double intact_max = 0.0;
  std::size_t broken_count = 0;
  for (std::size_t b = 0; b < strain.size(); ++b)
    if (broken[b]) ++broken_count;
    else intact_max = std::max(intact_max, strain[b]);
  EXPECT_LT(intact_max, 0.035);
  EXPECT_GT(intact_max, 0.02);
  EXPECT_GT(broken_count, 5u);
  ASSERT_FALSE(group.empty());
  EXPECT_EQ(group.front(), 0);
  EXPECT_EQ(group.back(), 3 * 5 + 2 * 5 + 4 + 3 + 1);  // 29 yarns, 3 families, edges: then the sphere
}

// cases/yarn_wave: a Kevlar yarn's front. A chain of spacing s disperses (omega = (2c/s)
// sin(ks/2)): the front of a velocity step spreads like an Airy function, so the time at which
// the velocity reaches half the driven one lags n s / c by a term in n^(1/3). Fitting the
// arrival times at five probes to t = n s / c + b n^(1/3) gives c; R8 asks for 2 % of
// sqrt(E / rho) = 6880 m/s, the fit is within 1e-4 of it, bounded here at 1e-3. Without the
// correction the half-level speed at the nearest probe (100 DEs) is 0.9 % low: the bound there
// checks that the dispersion is as stated.
TEST(YarnWave, FrontTravelsAtTheYarnWaveSpeedOnceTheChainsDispersionIsTakenOut) {
  const auto out = test::scratch_dir("yarn_wave");
  const auto r = test::run_arlequin("run " + std::string(ARLEQUIN_SOURCE_DIR) + "/cases/yarn_wave/case.yaml --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = test::read_csv(out / "series.csv");
  const double s = 3e-4, c = std::sqrt(62e9 / 1310.0);
  double Snn = 0, Snm = 0, Smm = 0, Snt = 0, Smt = 0;  // normal equations of t = a n + b n^(1/3)
  double raw_first = 0.0;
  for (const int n : {100, 200, 300, 400, 500}) {
    const std::string column = std::string("v").append(std::to_string(n));
    double arrival = 0.0;
    for (std::size_t k = 1; k < rows.size() && arrival == 0.0; ++k) {
      const double v0 = at(rows[k - 1], column), v1 = at(rows[k], column);
      if (v1 >= 0.5)
        arrival = at(rows[k - 1], "time") + (at(rows[k], "time") - at(rows[k - 1], "time")) * (0.5 - v0) / (v1 - v0);
    }
    ASSERT_GT(arrival, 0.0) << column << " never reached half the driven velocity";
    if (n == 100) raw_first = n * s / arrival;
    const double m = std::cbrt(double(n));
    Snn += double(n) * n, Snm += n * m, Smm += m * m, Snt += n * arrival, Smt += m * arrival;
  }
  const double a = (Snt * Smm - Smt * Snm) / (Snn * Smm - Snm * Snm);
  EXPECT_NEAR(s / a / c, 1.0, 1e-3);
  EXPECT_NEAR(raw_first / c, 0.991, 0.003);
}

// The coupled target (cases/fabric_impact_coupled) reduced: reduced.yaml's DEM patch of 6 x 6 mm
// (overlap included) in a homogenised plate of the 10 x 10 mm target, 40 us. Its sphere is not
// compared with the pure DEM here (on this target the patch is barely the sphere's size; the
// comparison is the full case's, README.md): what is judged is the coupled model's bookkeeping.
const std::string coupled_dir = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/fabric_impact_coupled/";

std::vector<std::map<std::string, std::string>> run_coupled(const std::string& name, const std::string& sets,
                                                           std::filesystem::path& out) {
  out = test::scratch_dir(name);
  const auto r = test::run_arlequin("run " + coupled_dir + "reduced.yaml" + sets + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.exit_code == 0 ? test::read_csv(out / "series.csv") : std::vector<std::map<std::string, std::string>>{};
}

// A DEM band across the seed target's whole free width (x 1..21 mm, y 17..33 mm; the
// case's patch stops 2 mm short of the clamps: README.md compares the two) has its clamped
// yarn ends as DEM, held by a DEM condition, and the 12 clamped stuffer DEs at x = 21 mm lie in
// the overlap on the plate's held side face, where both sides of their constraint are
// prescribed. They carry no multiplier, and the multipliers keep the low-rank form (a driven DE,
// tied, leaves D singular, and A went to the general factor of all 1464 rows); with fe and nem.
TEST(FabricCoupled, ClampedDesInTheOverlapCarryNoMultiplier) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::string band = " --set 'coupling.overlap.shell.inner=[[0.001, 0.017, -0.726e-3], [0.021, 0.033, 1.926e-3]]'"
                           " --set 'coupling.overlap.shell.outer=[[0.001, 0.016, -0.726e-3], [0.021, 0.034, 1.926e-3]]'"
                           " --set 'boundary=[{group: edges, type: fixed}]'";
  for (const std::string solver : {"fe", "nem"}) {
    const auto r = test::run_arlequin("check " + coupled_dir + "case.yaml" + band + " --set continuum.solver=" + solver, "stdout");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("1464 coupled DEs, 1464 multipliers per component (12 of them untied: driven DEs where the continuum is held)"),
              std::string::npos)
        << solver << ": " << r.output;
    EXPECT_NE(r.output.find("coupling matrix A: diagonal + low rank (Woodbury)"), std::string::npos) << solver << ": " << r.output;
  }
}

// A union of shells (coupling.overlap.shells) that is empty, or whose shell does not nest, is a
// one-line error naming the key.
TEST(FabricCoupled, BadShellsAreOneLineErrorsNamingTheKey) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"coupling.overlap={shells: []}", {"coupling.overlap.shells", "expected 1 to 4 shells"}},
      {"coupling.overlap={shells: [{inner: [[0, 0, 0], [1, 1, 1]]}]}", {"outer", "missing"}},
      {"coupling.overlap={shells: [{inner: [[0, 0, 0], [0.01, 0.01, 0.001]], outer: [[-0.001, -0.001, -0.001], [0.011, 0.011, 0.002]]}, "
       "{inner: [[0, 0, 0], [0.02, 0.01, 0.001]], outer: [[0, 0, 0], [0.01, 0.01, 0.001]]}]}",
       {"coupling.overlap", "the inner box strictly inside the outer one"}},
  };
  for (const auto& [set, expected] : cases) {
    const auto r = test::run_arlequin("check " + coupled_dir + "reduced.yaml --set '" + set + "'");
    EXPECT_EQ(r.exit_code, 2) << set << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    for (const auto& piece : expected) EXPECT_NE(r.output.find(piece), std::string::npos) << set << ": " << r.output;
  }
}

// Without breakage, with the plate in P2 elements (the case's) and in natural neighbours (one key;
// the plate with the patch's hole cut into convex pieces, docs/decisions.md#d45): the balance
// (both models and the multipliers' work) stays within 6e-4 of the impact energy (measured 4.2e-4
// with fe and 3.5e-4 with nem, the plate's force once every 4 steps: velocity Verlet's error of
// the plate at its macro step, theory.md#continuum-substeps; 1.2e-4 every step with fe), the
// multipliers do no work (1e-12 of it; measured 2e-17 and 1e-16 J), and the plate takes its share
// (measured 0.51 and 0.63 J at 40 us; bound 0.1 J).
TEST(FabricCoupled, ReducedImpactWithoutBreakageKeepsTheImpactEnergy) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  for (const std::string solver : {"fe", "nem"}) {
    std::filesystem::path out;
    const auto rows = run_coupled("fabric_coupled_unbreakable_" + solver,
                                  " --set dem.sample.yarn.failure_strain=0 --set continuum.solver=" + solver, out);
    ASSERT_FALSE(rows.empty()) << solver;
    const double E0 = impact_energy();
    EXPECT_NEAR(at(rows.front(), "E_total") / E0, 1.0, 1e-5) << solver;
    EXPECT_LT(worst_balance(rows), 6e-4 * E0) << solver;
    double coupling_work = 0.0;
    for (const auto& row : rows) coupling_work = std::max(coupling_work, std::abs(at(row, "W_coupling")));
    EXPECT_LT(coupling_work, 1e-12 * E0) << solver;
    EXPECT_GT(at(rows.back(), "C_kinetic") + at(rows.back(), "C_strain"), 0.1) << solver;
  }
}

// The plate's internal force once every 4 steps (reduced.yaml's continuum_substeps, r-RESPA's
// impulses) against every step, without breakage. From about 20 us the weave's contacts make the
// run chaotic: pairs of runs whose plate E_z differs by 2e-9 to 2 % (16 pairs, two builds whose
// multiplier solves differ in round-off) put the sphere's velocity 0.12 to 2.15 m/s apart over
// the whole run and the plate's peak strain energy -2.9 % to +2.6 %, while up to 20 us the
// sub-cycling's own difference is 0.052 to 0.094 m/s. So the bounds: the velocity within
// 0.15 m/s of the every-step run's up to 20 us (measured 0.073) and within 3 m/s over the run
// (measured 1.44), the peak strain energy within 5 % (measured -0.20 %), the sub-cycled run's
// balance within 6e-4 of the impact energy (measured 4.2e-4) and the every-step run's within
// 2e-4 (measured 1.0e-4). An opening impulse of 0.6 m dt instead of 0.5 leaves 12 % of the
// strain energy out and the balance 18 times the impact energy.
TEST(FabricCoupled, ThePlateForcedEveryFourthStepFollowsTheEveryStepRun) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  std::filesystem::path out;
  const auto substeps = run_coupled("fabric_coupled_substeps_4", " --set dem.sample.yarn.failure_strain=0", out);
  const auto every_step = run_coupled("fabric_coupled_substeps_1",
                                      " --set dem.sample.yarn.failure_strain=0 --set coupling.continuum_substeps=1", out);
  ASSERT_EQ(substeps.size(), every_step.size());
  ASSERT_FALSE(substeps.empty());
  double early = 0.0, velocity = 0.0, peak_4 = 0.0, peak_1 = 0.0;
  for (std::size_t k = 0; k < substeps.size(); ++k) {
    const double difference = std::abs(at(substeps[k], "sphere_velocity") - at(every_step[k], "sphere_velocity"));
    if (at(substeps[k], "time") <= 20e-6) early = std::max(early, difference);
    velocity = std::max(velocity, difference);
    peak_4 = std::max(peak_4, at(substeps[k], "C_strain"));
    peak_1 = std::max(peak_1, at(every_step[k], "C_strain"));
  }
  EXPECT_LT(early, 0.15);
  EXPECT_LT(velocity, 3.0);
  EXPECT_NEAR(peak_4 / peak_1, 1.0, 0.05);
  EXPECT_LT(worst_balance(substeps), 6e-4 * impact_energy());
  EXPECT_LT(worst_balance(every_step), 2e-4 * impact_energy());
}

// With breakage and `on_damage_in_overlap: hold`: springs of the overlap that reach the failure
// strain are held intact and said so (the summary counts them), every break is a spring of the
// pure-DEM patch (its midpoint inside the inner box, x and y in [3, 7] mm, where the DEM's weight
// is 1), and the balance closes with the fracture energy within 5 % of it plus 2e-4 of the impact
// energy (measured 3.4 % of 0.21 J: velocity Verlet's error across a break, 4 % in the pure DEM).
TEST(FabricCoupled, ReducedImpactHoldsTheOverlapsSpringsAndTheFractureClosesTheBalance) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  std::filesystem::path out;
  const auto rows = run_coupled("fabric_coupled_breakable", " --set output.fields=[particles] --set output.fields_every=4e-5", out);
  ASSERT_FALSE(rows.empty());
  const double E0 = impact_energy(), fracture = at(rows.back(), "E_fracture");
  EXPECT_GT(fracture, 0.01 * E0);
  EXPECT_LT(worst_balance(rows), 0.05 * fracture + 2e-4 * E0);
  const Json summary = Json::parse(test::read_text(out / "summary.json"));
  EXPECT_NE(summary.at("damage_in_overlap").get<std::string>().find("held intact"), std::string::npos);
  EXPECT_GT(summary.at("damage_in_overlap_breaks").get<double>(), 0.0);
  const hid_t file = H5Fopen((out / "fields.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const auto x = test::read_dataset<double>(file, "/frames/000000/particles/points", H5T_NATIVE_DOUBLE);  // at t = 0
  H5Fclose(file);
  const auto breaks = test::read_csv(out / "breaks.csv");
  ASSERT_FALSE(breaks.empty());
  for (const auto& b : breaks) {
    const auto i = static_cast<std::size_t>(at(b, "first")), j = static_cast<std::size_t>(at(b, "second"));
    ASSERT_LT(3 * std::max(i, j) + 1, x.size());
    for (int k = 0; k < 2; ++k) {
      const double mid = 0.5 * (x[3 * i + k] + x[3 * j + k]);
      EXPECT_TRUE(mid >= 3e-3 && mid <= 7e-3) << "a break at " << mid << " m (axis " << k << "), in the overlap";
    }
  }
}

// cases/fabric_impact_coupled/yarn_pulse.yaml: a pulse 8 mm long along the weft yarns leaves the
// DEM through the overlap into the plate; the case's check bounds what comes back at 4.5 % (measured
// 3.5 %, with the plate's inertia along x the weft's and the stuffers and binders free along x).
// Every DE of the overlap held along x (no ties) puts the stuffers' and binders' mass on the weft's
// motion there: 8.1 % comes back. With the coarse mediator the yarns slide through the overlap's
// elements and 31 % comes back.
TEST(FabricCoupled, AYarnPulseLeavesThroughTheOverlapIntoThePlate) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto reflected = [](const std::string& name, const std::string& sets) {
    const auto out = test::scratch_dir(name);
    const auto r = test::run_arlequin("run " + coupled_dir + "yarn_pulse.yaml" + sets + " --out " + out.string());
    const Json summary = Json::parse(test::read_text(out / "summary.json"));
    return std::make_pair(r.exit_code, summary.at("checks").at(0).at("value").get<double>());
  };
  const auto [code, R] = reflected("fabric_yarn_pulse", "");
  EXPECT_EQ(code, 0);  // the case's own check: R <= 0.045
  EXPECT_LT(R, 0.045);
  const auto [untied_code, untied_R] = reflected("fabric_yarn_pulse_untied", " --set coupling.ties=[]");
  EXPECT_EQ(untied_code, 5);  // its check failed
  EXPECT_GT(untied_R, 0.07);
  const auto [coarse_code, coarse_R] = reflected("fabric_yarn_pulse_coarse", " --set coupling.mediator=coarse --set coupling.ties=[]");
  EXPECT_EQ(coarse_code, 5);  // its check failed
  EXPECT_GT(coarse_R, 0.2);
}

// The entry of sensor `name` in a compare report; it must be there exactly once (else the test
// fails, and reading the empty entry throws).
Json sensor_entry(const Json& report, const std::string& name) {
  Json found;
  int count = 0;
  for (const auto& sensor : report.at("sensors"))
    if (sensor.at("sensor").get<std::string>() == name) found = sensor, ++count;
  EXPECT_EQ(count, 1) << name;
  return found;
}

// The issue's bounds on a comparison of the coupled target with the pure DEM (compare.json, and
// the first break's relative difference, a pair's or the ensemble's median): the sphere's velocity
// history within 5 % (max relative), the peak impact force within 10 %, the first break within 10 %.
void expect_within_the_issues_bounds(const Json& report, double first_break, const std::string& label) {
  EXPECT_LT(sensor_entry(report, "sphere_velocity").at("max_relative_difference").get<double>(), 0.05) << label;
  EXPECT_LT(std::abs(sensor_entry(report, "impact_force").at("peak_relative_difference").get<double>()), 0.10) << label;
  EXPECT_LT(std::abs(first_break), 0.10) << label;
}

// Validation: the coupled seed target (its 16 mm DEM core, docs/decisions.md#d64) against the
// pure-DEM run, both with breakage, with the plate in P1 elements (the case's) and in natural
// neighbours (`--set-other continuum.solver=nem`: the plate with the patch's hole as eight convex
// pieces). One comparison is one draw (d43), so the issue's bounds are asserted on the medians of
// seven pairs (`arlequin compare --ensemble 7`, d44; about 3 and 4 minutes): the sphere's
// velocity history within 5 % (max over the 100 us of the difference relative to its largest
// value: measured 4.41 % with fe, the pairs 2.89 to 8.36 %, and 4.62 % with nem on an AMD EPYC
// VM, 4.59 and 4.61 % on an Intel Xeon VM, the pure run against itself up to 4.08 %; the 14 mm
// core's nem median, 4.67 % on the Intel VM, was 5.26 % on the AMD VM and failed), the peak
// impact force within 10 % (rows every 0.1 us; measured +0.56 % with fe and -0.54 % with nem, the
// pairs -15.8 to +16.3 %; a build of an earlier model on another machine drew -10.47 % and
// -10.28 %: the median of seven pairs is still a draw to about ten points, the pure run's own
// peak spreading over -17 to +1.6 %, cases/fabric_impact_coupled/README.md), the first break
// within 10 % (measured -0.76 % and +1.64 %). Without breakage, the model's own error (d43): the
// sphere within 5 % of 90 m/s of the pure run's (measured 2.47 % with fe and 2.45 % with nem; nem
// on the nodes of P2 elements, 10.1 %, failed it: d62), and the coupled balance within 1 % of the
// impact energy (measured 2.4e-4 and 2.2e-4).
TEST(ValidationFabric, CoupledSeedTargetMatchesThePureDem) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const std::string pure = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/fabric_impact/case.yaml";
  for (const std::string solver : {"fe", "nem"}) {
    const auto out = test::scratch_dir("fabric_compare_" + solver);
    const auto r = test::run_arlequin("compare " + pure + " " + coupled_dir + "case.yaml --ensemble 7 --set output.fields=[] " +
                                      "--set-other continuum.solver=" + solver + " --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << solver << ": " << r.output;
    const Json report = Json::parse(test::read_text(out / "compare.json"));
    ASSERT_EQ(report.at("ensemble").at("pairs").get<int>(), 7);
    expect_within_the_issues_bounds(report, report.at("ensemble").at("first_break_relative_difference").get<double>(), solver);

    // Without breakage, one comparison (not a draw): compare's largest velocity difference is
    // relative to the pure run's largest velocity, the impact's 90 m/s.
    const auto unbreakable = test::scratch_dir("fabric_compare_seed_unbreakable_" + solver);
    const auto u = test::run_arlequin("compare " + pure + " " + coupled_dir + "case.yaml --set dem.sample.yarn.failure_strain=0 " +
                                      "--set output.fields=[] --set-other continuum.solver=" + solver + " --out " + unbreakable.string());
    ASSERT_EQ(u.exit_code, 0) << solver << ": " << u.output;
    const Json unbroken = Json::parse(test::read_text(unbreakable / "compare.json"));
    EXPECT_LT(sensor_entry(unbroken, "sphere_velocity").at("max_relative_difference").get<double>(), 0.05) << solver;
    EXPECT_LT(worst_balance(test::read_csv(unbreakable / "other" / "series.csv")), 0.01 * impact_energy()) << solver;
  }
}

// Validation: the 44 x 100 mm target in pure DEM (143 944 DEs, about a minute on two threads)
// and coupled (large.yaml: the cross of DEM along the principal yarns, 39 780 DEs). One comparison
// is one draw (d43): pair 0 alone met the issue's bounds on an Intel Xeon VM (0.961 %, +3.45 %,
// -0.307 %) and failed them on an AMD EPYC VM (5.56 %, -6.13 %, first break -13.9 %), the pure
// run's first break the same on both. So, as for the seed target, the bounds are asserted on the
// medians of seven pairs (`compare --ensemble 7`, d44; about 11 minutes): the sphere's velocity
// within 5 % (measured 2.75 % on the AMD VM, the pairs 0.817 to 5.65 %, the pure run against
// itself up to 7.33 %; 20.4 % with the 16 mm core alone, one draw), the peak force within 10 %
// (measured +3.62 %), the first break within 10 % (measured -0.783 %, the pairs -13.9 to
// +15.6 %, the pure run's own spread up to 16.8 %), and pair 0's coupled balance with the fracture
// energy within 1 % of the impact energy (measured 2.7e-4). Its speed-up is the README's, not
// asserted.
TEST(ValidationFabric, LargerTargetMatchesThePureDem) {
#ifndef ARLEQUIN_WITH_CONTINUUM
  GTEST_SKIP() << "built without the continuum";
#endif
  const auto out = test::scratch_dir("fabric_compare_large");
  const std::string pure = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/fabric_impact/large.yaml";
  const auto r = test::run_arlequin("compare " + pure + " " + coupled_dir + "large.yaml --ensemble 7 --set output.fields=[] --out " +
                                    out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json report = Json::parse(test::read_text(out / "compare.json"));
  ASSERT_EQ(report.at("ensemble").at("pairs").get<int>(), 7);
  EXPECT_TRUE(report.at("reference").at("completed").get<bool>());
  EXPECT_TRUE(report.at("other").at("completed").get<bool>());
  expect_within_the_issues_bounds(report, report.at("ensemble").at("first_break_relative_difference").get<double>(), "large");
  EXPECT_LT(worst_balance(test::read_csv(out / "other" / "series.csv")), 0.01 * impact_energy());
}

TEST(Fabric, BadWeavesAndImpactorsAreOneLineErrorsNamingTheKey) {
  const std::pair<std::string, std::vector<std::string>> cases[] = {
      {"dem.sample.chains=[0,1]", {"dem.sample.chains[0]", "expected a number >= 1"}},
      {"dem.sample.crimp=0.3", {"dem.sample.crimp", "cut through the weft", "smallest crimp that clears"}},
      {"dem.sample.warp_spacing=1.5e-3", {"dem.sample.warp_spacing", "cuts them"}},
      {"dem.sample.particles=[{position: [0.005, 0.005, 0.002], radius: 2.715e-3, density: 7530}]",
       {"dem.sample.particles[0].position", "starts inside the fabric"}},
      {"dem.sample.particles=[{position: [0.005, 0.005, 0.0047], radius: 2.715e-3}]",
       {"dem.sample.particles[0].density", "no dem.density"}},
      {"dem.bond={law: spring, stiffness: 1}", {"dem.bond", "a weave makes its own springs"}},
  };
  for (const auto& [set, expected] : cases) {
    const auto r = test::run_arlequin("check " + reduced_case + " --set '" + set + "'");
    EXPECT_EQ(r.exit_code, 2) << set << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    for (const auto& piece : expected) EXPECT_NE(r.output.find(piece), std::string::npos) << set << ": " << r.output;
  }
}

}  // namespace
}  // namespace arlequin
