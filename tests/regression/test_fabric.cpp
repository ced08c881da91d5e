// SPDX-License-Identifier: GPL-3.0-or-later
// The dry-fabric impact (cases/fabric_impact, docs/validation.md#r8) reduced to a 10 x 10 mm
// target (reduced.yaml): the sphere's kinetic energy 1/2 m v^2 = 2.557 J (R8), kept by the
// yarns, springs and contacts without damping, and with breakage by the broken springs'
// fracture energy too; bad weaves and impactors refused in one line naming the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/json.hpp"
#include "support/cli.hpp"

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

// No breakage (failure_strain 0): the total energy stays within 1e-4 of the impact energy over
// the 40 us (measured 4.8e-5), the sphere is stopped and sent back (the fabric holds it), and
// the starting total is the sphere's 1/2 m v^2 (plus the yarns' contact energy at rest, below
// 1e-5 of it: the builder's overlap tolerance).
TEST(Fabric, ReducedImpactWithoutBreakageKeepsTheImpactEnergy) {
  const auto out = test::scratch_dir("fabric_reduced_unbreakable");
  const auto r = test::run_arlequin("run " + reduced_case + " --set dem.sample.yarn.failure_strain=0 --set output.dir=" + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = test::read_csv(out / "series.csv");
  const double E0 = impact_energy();
  EXPECT_NEAR(at(rows.front(), "E_total") / E0, 1.0, 1e-5);
  EXPECT_LT(worst_balance(rows), 1e-4 * E0);
  EXPECT_GT(at(rows.back(), "sphere_velocity"), 0.0);  // rebounding
  EXPECT_EQ(at(rows.back(), "E_fracture"), 0.0);
}

// With the Kevlar's failure strain (3.5 %), springs break; their fracture energy closes the
// balance within 2e-3 of the impact energy (measured 1.1e-3; the bound is 1 %), and the
// summary gives the first break's time, which the breaks file's first row repeats.
TEST(Fabric, ReducedImpactBreakageIsClosedByTheFractureEnergy) {
  const auto out = test::scratch_dir("fabric_reduced_breakable");
  const auto r = test::run_arlequin("run " + reduced_case + " --set output.dir=" + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = test::read_csv(out / "series.csv");
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
