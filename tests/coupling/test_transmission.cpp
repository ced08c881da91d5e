// SPDX-License-Identifier: GPL-3.0-or-later
// Dynamic transmission through the overlap (docs/validation.md R6): a tone burst sent from the DEM
// side; R = energy left in the DEM after the pulse has passed / initial energy. Energy
// conservation without damping, and stability at 0.9 of the reported critical step.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "coupling_test_util.hpp"

using namespace arlequin;
using namespace arlequin::coupling;
using namespace arlequin::coupling::testing;

namespace {

struct WaveCase {
  std::string method = "fe";
  Mediator mediator = Mediator::coarse;
  double h = 1.0;          // element length (DE spacing a = 1, wave speed c = 1)
  double lambda = 10.0;    // carrier wavelength
  double overlap = 4.0;    // overlap length
  double safety = 0.9;     // dt / reported critical step
  WeightShape shape = WeightShape::linear;
  int substeps = 1;        // the continuum's internal force once every this many steps (0: auto)
  double mass_floor = 0.05;  // the weights' floor on the masses
  double continuum_density = 1.0;  // the DE bar's is 1
};

struct WaveResult {
  double R = 0.0;             // energy left in the DEM / initial (velocity Verlet invariants)
  double energy_error = 0.0;  // max |E(t) - E(0)| / E(0), E = velocity Verlet's invariant
  double plain_error = 0.0;   // the same for kinetic + elastic
  double energy_max = 0.0;    // max E(t) / E(0)
  double dt_dem = 0.0, dt_continuum = 0.0, dt_coupled = 0.0;
  int substeps = 0;  // the model's m
  double mismatch = 0.0;      // max velocity mismatch over the run / pulse velocity amplitude
  double residual = 0.0;      // max |G v| / |G_d v_d| after correction
  double coupling_work = 0.0; // / E(0)
  int steps = 0;
};

std::string label(const WaveCase& c) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s %s h=%g lambda=%g overlap=%g %s dt=%.2f dt_c substeps %d", c.method.c_str(),
                mediator_name(c.mediator), c.h, c.lambda, c.overlap, weight_shape_name(c.shape), c.safety, c.substeps);
  return buf;
}

// The 4-line DE bar on [0, X2] and the one-cell-thick mesh on [X1, X2 + 10 sigma], nu = 0, so the
// axial waves of both are the same mass-spring chains when h = 1. The burst starts 5 sigma into
// the DEM, 5 sigma before the overlap.
WaveResult run_wave(const WaveCase& c) {
  const double sigma = 2.0 * c.lambda;
  const double x0 = 5.0 * sigma, X1 = std::round(10.0 * sigma / c.h) * c.h, X2 = X1 + c.overlap;
  const int n_dem = static_cast<int>(std::lround(X2)) + 1;
  const int n_el = static_cast<int>(std::lround((c.overlap + 10.0 * sigma) / c.h));
  char mesh_name[96];
  std::snprintf(mesh_name, sizeof mesh_name, "wave_h%g_x%g_n%d", c.h, X1, n_el);
  const std::string mesh = write_box_mesh(mesh_name, X1, n_el, c.h, 1, 1.0, 1, 1.0);
  auto cont = make_continuum(c.method, mesh, 1.0, 0.0, c.continuum_density);
  dem::DemModel dem;
  build_four_lines(dem, n_dem, 1.0, 1.0, 1.0, 1.0);
  const ToneBurst burst{1e-4, c.lambda, sigma, x0, 1.0, 1.0};
  for (std::size_t i = 0; i < dem.particles.size(); ++i) {
    const auto [u, v] = burst.at(dem.particles.reference[i].x);
    dem.particles.position[i].x += u;
    dem.particles.velocity[i].x = v;
  }
  CoupledOptions options;
  options.coupling.mediator = c.mediator;
  options.continuum_substeps = c.substeps;
  const OverlapZone zone = OverlapZone::box({{X1, -1, -1}, {X2, 2, 2}}, 0, true, {c.shape, c.mass_floor, 0.5});
  CoupledModel model(dem, *cont, zone, options);

  WaveResult r;
  r.dt_dem = model.time_steps().dem;
  r.dt_continuum = model.time_steps().continuum;
  r.dt_coupled = model.critical_time_step();
  r.substeps = model.time_steps().continuum_substeps;
  const double dt = c.safety * model.critical_time_step();
  const double e0 = model.energies().total(), s0 = model.energies().shadow_total(dt);
  // Until the transmitted burst is 4 sigma past the overlap (group velocity).
  const double t_end = (X2 + 4.0 * sigma - x0) / burst.group_velocity();
  r.steps = static_cast<int>(std::ceil(t_end / dt));
  r.energy_max = 1.0;
  const double v_amp = burst.omega() * burst.amplitude;
  for (int n = 0; n < r.steps; ++n) {
    model.step(dt);
    const CoupledEnergies energies = model.energies();  // each is evaluated on call
    const CouplingMonitor monitor = model.monitor();
    const double e = energies.total();
    r.energy_error = std::max(r.energy_error, std::abs(energies.shadow_total(dt) - s0) / s0);
    r.plain_error = std::max(r.plain_error, std::abs(e - e0) / e0);
    r.energy_max = std::max(r.energy_max, e / e0);
    r.mismatch = std::max(r.mismatch, monitor.max_velocity_mismatch / v_amp);
    r.residual = std::max(r.residual, monitor.constraint_residual);
  }
  r.R = model.energies().dem_shadow(dt) / s0;
  r.coupling_work = model.energies().coupling_work / e0;
  std::printf("[wave %s] R = %.4f %%, energy error %.2e (plain %.2e), E_max/E0 - 1 = %.2e, steps %d, dt_c DEM %.4f "
              "continuum %.4f, max |G v|/|G_d v_d| %.1e, max velocity mismatch / v_amp %.3f, coupling work / E0 %.1e\n",
              label(c).c_str(), 100 * r.R, r.energy_error, r.plain_error, r.energy_max - 1.0, r.steps, r.dt_dem, r.dt_continuum,
              r.residual, r.mismatch, r.coupling_work);
  return r;
}

}  // namespace

// Matched discretisations (h = a), lambda >= 5a, overlap 8a: R <= 0.3 %; energy (velocity
// Verlet's invariant) conserved to 1e-4; the constraint holds to round-off.
TEST(CouplingTransmission, MatchedChainAndBarReflectLittle) {
  for (Mediator m : {Mediator::coarse, Mediator::fine})
    for (double lambda : {5.0, 10.0}) {
      WaveCase c;
      c.mediator = m;
      c.lambda = lambda;
      c.overlap = 8.0;
      const WaveResult r = run_wave(c);
      EXPECT_LE(r.R, 0.003) << label(c);
      EXPECT_LE(r.energy_error, 1e-4) << label(c);
      EXPECT_LT(r.residual, 1e-10) << label(c);
      EXPECT_LT(std::abs(r.coupling_work), 1e-10) << label(c);
    }
}

// h = 2a: cut-off wavelength lambda_c = pi a / arcsin(a/h) = 6a. lambda >= 1.6 lambda_c passes
// (R <= 0.5 %); lambda <= 0.8 lambda_c cannot live in the continuum and is reflected (R >= 90 %),
// never amplified.
TEST(CouplingTransmission, CoarseContinuumPassesLongWavesAndReflectsShortOnes) {
  for (Mediator m : {Mediator::coarse, Mediator::fine}) {
    WaveCase c;
    c.mediator = m;
    c.h = 2.0;
    c.lambda = 10.0;
    c.overlap = 8.0;
    const WaveResult pass = run_wave(c);
    EXPECT_LE(pass.R, 0.005) << label(c);
    EXPECT_LE(pass.energy_error, 1e-4) << label(c);
    c.lambda = 4.5;
    const WaveResult stop = run_wave(c);
    EXPECT_GE(stop.R, 0.90) << label(c);
    EXPECT_LE(stop.R, 1.0 + 1e-6) << label(c);
    EXPECT_LE(stop.energy_error, 1e-4) << label(c);
  }
}

// The continuum's internal force once every m steps (r-RESPA's impulses, CoupledModel's
// continuum_substeps): the coupled step becomes min(DEM, continuum / m), the long wave of the
// coarse bar (h = 4a, lambda = 20a >= 1.6 lambda_c) passes as with m = 1 (R within 1e-4 of it;
// measured 8e-6, both 0.35 %), and the energy error grows with m but stays bounded: at m = 2 the
// kinetic + elastic energy stays within 1.6e-3 of E(0) (measured 1.07e-3; 1.8e-4 at m = 1,
// 3.2e-3 at m = 3: the continuum's force arrives at the overlap's DEs as impulses, which is why
// the substeps are a case's choice and 1 by default).
TEST(CouplingTransmission, AContinuumForcedEverySecondStepPassesTheSameWave) {
  WaveCase c;
  c.mediator = Mediator::fine;
  c.h = 4.0;
  c.lambda = 20.0;
  c.overlap = 8.0;
  const WaveResult every = run_wave(c);
  c.substeps = 2;
  const WaveResult second = run_wave(c);
  EXPECT_EQ(second.dt_coupled, std::min(second.dt_dem, second.dt_continuum / 2));
  EXPECT_LT(second.dt_coupled, every.dt_coupled);  // this bar's continuum sets the step
  EXPECT_LE(second.R, 0.005);
  EXPECT_NEAR(second.R, every.R, 1e-4);
  EXPECT_LT(second.plain_error, 1.6e-3);
  EXPECT_LT(second.energy_max, 1.0 + 1.6e-3);
}

// continuum_substeps: auto takes the most steps whose sum stays within the continuum's critical
// step, m = floor(dt_continuum / dt_DEM): with a continuum sixteen times denser than the DE bar
// (a quarter of its wave speed) that is m = 2, the DEM keeps setting the step, and the run
// stays as stable as with the force every step.
TEST(CouplingTransmission, AutoSubstepsKeepTheDemsStep) {
  WaveCase c;
  c.mediator = Mediator::fine;
  c.h = 8.0;
  c.lambda = 40.0;
  c.overlap = 16.0;
  c.continuum_density = 16.0;  // a quarter of the wave speed: a critical step 2.7 times the DEM's here
  const WaveResult every = run_wave(c);
  c.substeps = 0;
  const WaveResult automatic = run_wave(c);
  std::printf("auto: m = %d (critical steps: DEM %g, continuum %g), plain energy error %g (every step %g)\n",
              automatic.substeps, automatic.dt_dem, automatic.dt_continuum, automatic.plain_error, every.plain_error);
  EXPECT_EQ(automatic.substeps, static_cast<int>(std::floor(automatic.dt_continuum / automatic.dt_dem)));
  EXPECT_GE(automatic.substeps, 2);
  EXPECT_EQ(automatic.dt_coupled, automatic.dt_dem);
  EXPECT_EQ(every.substeps, 1);
  EXPECT_LT(automatic.plain_error, 4e-3);  // measured 2.7e-3 (2.4e-3 with the force every step)
  EXPECT_LT(automatic.energy_max, 1.0 + 4e-3);
}

// Natural neighbours (SCNI) disperse more than the DE chain (their smoothed gradient spans two
// cells), so only long waves match: lambda = 20a passes with R <= 0.5 %.
TEST(CouplingTransmission, NaturalNeighbourContinuumPassesLongWaves) {
  WaveCase c;
  c.method = "nem";
  c.lambda = 20.0;
  c.overlap = 8.0;
  const WaveResult r = run_wave(c);
  EXPECT_LE(r.R, 0.005) << label(c);
  EXPECT_LE(r.energy_error, 1e-4) << label(c);
}

namespace {

// Random velocities (all wavelengths, DE lines along x only: they have no lateral stiffness)
// on the matched bar, `steps` steps at 0.9 of the reported critical step. Returns the growth of
// kinetic + elastic energy (its largest value over the last tenth of the run / over the first
// tenth: near the stability limit it oscillates by tens of % but must not grow) and the drift of
// the integrator's invariant.
std::pair<double, double> random_run(const std::string& method, int steps, double nem_stabilization = 1.0) {
  const std::string mesh = write_box_mesh("stability", 20.0, 40, 1.0, 1, 1.0, 1, 1.0);
  auto cont = make_continuum(method, mesh, 1.0, 0.0, 1.0, nem_stabilization);
  dem::DemModel dem;
  build_four_lines(dem, 29, 1.0, 1.0, 1.0, 1.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(-1e-4, 1e-4);
  for (auto& v : dem.particles.velocity) v.x = uni(rng);
  for (double& v : cont->velocity()) v = uni(rng);
  CoupledModel model(dem, *cont, OverlapZone::box({{20, -1, -1}, {28, 2, 2}}, 0, true, {}), {});
  std::printf("%s", model.summary().c_str());
  const double dt = 0.9 * model.critical_time_step();
  const double e0 = model.energies().total(), s0 = model.energies().shadow_total(dt);
  double first = 0.0, last = 0.0, drift = 0.0;
  for (int n = 0; n < steps; ++n) {
    model.step(dt);
    const auto e = model.energies();
    if (n < steps / 10) first = std::max(first, e.total() / e0);
    if (n >= steps - steps / 10) last = std::max(last, e.total() / e0);
    drift = std::max(drift, std::abs(e.shadow_total(dt) - s0) / s0);
  }
  std::printf("[stability %s] %d steps at 0.9 dt_c: max E/E0 first tenth %.4f, last tenth %.4f, invariant drift "
              "%.2e, |G v|/|G_d v_d| %.1e\n",
              method.c_str(), steps, first, last, drift, model.monitor().constraint_residual);
  return {last / first, drift};
}

}  // namespace

TEST(CouplingStability, RandomStateAtNineTenthsOfCriticalStep) {
  const auto [growth, drift] = random_run("fe", 10000);
  EXPECT_LT(growth, 1.001);
  EXPECT_LT(drift, 1e-4);
}

// The same over ten times the steps. The growth is the stability gate. The invariant's drift is
// a regression guard at 1.5 times the largest level measured. It grows with the run's length
// (nem, a = 1: 1.1e-5 after 10 000 steps, 4.0e-5 after 50 000, 1.20e-4 after 100 000) while the
// energy does not grow, and it falls with the velocities' amplitude (1e-6 instead of 1e-4: fe
// 1.2e-7, nem 3.8e-7 and 3.7e-7): velocity Verlet's invariant is exact only for a linear system,
// and the springs act along their current direction as the unheld bar moves. Measured: fe
// 2.22e-5; nem 1.20e-4 (a = 1) and 7.98e-5 (a = 1.9), against 9.44e-5 and 2.74e-5 while the
// continuum's mass floor also floored its stiffness (docs/decisions.md#d9: nem's nodes at the
// overlap's DEM-side edge have alpha_c = 0 at all their points, and the floor had given the
// material eps E wherever alpha_c < eps).
TEST(ValidationCouplingStability, RandomStateAtNineTenthsOfCriticalStepLong) {
  // nem also with the wave bar's stabilization a = 1.9 (stiffer grid-scale modes, smaller step).
  for (const auto& [method, a] : {std::pair{"fe", 1.0}, {"nem", 1.0}, {"nem", 1.9}}) {
    const auto [growth, drift] = random_run(method, 100000, a);
    EXPECT_LT(growth, 1.001) << method << " a " << a;
    EXPECT_LT(drift, 1.8e-4) << method << " a " << a;
  }
}

namespace {

// 3D bar: simple-cubic block n x 4 x 4 (nearest + face-diagonal springs, cell shares, E = 1,
// nu = 0.25) and the matched Kuhn mesh 3 x 3 cells across (h = a = 1), an axial tone burst with
// the bar speed sqrt(E / rho). Returns R and the invariant's error.
std::pair<double, double> run_bar3d(Mediator mediator, double lambda, double overlap) {
  const double sigma = 2.0 * lambda;
  const double x0 = 5.0 * sigma, X1 = std::round(10.0 * sigma), X2 = X1 + overlap;
  const int n_dem = static_cast<int>(X2) + 1, n_el = static_cast<int>(overlap + 10.0 * sigma);
  const std::string mesh = write_box_mesh("bar3d_" + std::to_string(n_el), X1, n_el, 1.0, 3, 1.0, 3, 1.0);
  auto cont = make_continuum("fe", mesh, 1.0, 0.25, 1.0);
  dem::DemModel dem;
  build_block(dem, {n_dem, 4, 4}, 1.0, 1.0, 1.0);
  const ToneBurst burst{1e-4, lambda, sigma, x0, 1.0, 1.0};
  for (std::size_t i = 0; i < dem.particles.size(); ++i) {
    const auto [u, v] = burst.at(dem.particles.reference[i].x);
    dem.particles.position[i].x += u;
    dem.particles.velocity[i].x = v;
  }
  CoupledOptions options;
  options.coupling.mediator = mediator;
  CoupledModel model(dem, *cont, OverlapZone::box({{X1, -1, -1}, {X2, 4, 4}}, 0, true, {}), options);
  const double dt = 0.9 * model.critical_time_step();
  const double s0 = model.energies().shadow_total(dt);
  const int steps = static_cast<int>((X2 + 4.0 * sigma - x0) / burst.group_velocity() / dt);
  double err = 0.0;
  for (int n = 0; n < steps; ++n) {
    model.step(dt);
    err = std::max(err, std::abs(model.energies().shadow_total(dt) - s0) / s0);
  }
  const double R = model.energies().dem_shadow(dt) / s0;
  std::printf("[bar3d %s lambda=%g overlap=%g] R = %.4f %%, energy error %.2e, %d steps, %d coupled DEs\n",
              mediator_name(mediator), lambda, overlap, 100 * R, err, steps, model.operators().num_particles());
  return {R, err};
}

}  // namespace

// 3D bar (matched lattice and Kuhn mesh, nu = 0.25): energy conserved, constraint exact. R is
// printed but only loosely gated: the plane initial burst is not a right-moving mode of the 3D
// lattice bar, so part of its energy never leaves the DEM whatever the coupling does (a reference
// run of the lattice alone would be needed to separate it).
TEST(CouplingTransmission, ThreeDimensionalBarConservesEnergy) {
  const auto [R, err] = run_bar3d(Mediator::coarse, 10.0, 8.0);
  EXPECT_LE(err, 1e-4);
  EXPECT_LE(R, 0.25);
}

// Kinetic damping of a coupled model between two steps (CoupledModel::arrest, a moved zone's
// settling): the 1D wave case with the burst in the overlap; the DEs of the overlap's first half
// stop. The velocities go back onto the constraint, and the kinetic energy taken out is booked
// exactly: the DEs' as the DEM's dissipation, the projection's as the multipliers' work.
TEST(CouplingTransmission, AnArrestStaysOnTheConstraintAndBooksWhatItTakesOut) {
  const double lambda = 10.0, sigma = 2.0 * lambda, X1 = 10.0 * sigma, X2 = X1 + 8.0;
  const std::string mesh = write_box_mesh("arrest_wave", X1, 60, 1.0, 1, 1.0, 1, 1.0);
  auto cont = make_continuum("fe", mesh, 1.0, 0.0, 1.0);
  dem::DemModel dem;
  build_four_lines(dem, static_cast<int>(X2) + 1, 1.0, 1.0, 1.0, 1.0);
  const ToneBurst burst{1e-4, lambda, sigma, X1 - 5.0, 1.0, 1.0};  // its middle near the overlap
  for (std::size_t i = 0; i < dem.particles.size(); ++i) {
    const auto [u, v] = burst.at(dem.particles.reference[i].x);
    dem.particles.position[i].x += u;
    dem.particles.velocity[i].x = v;
  }
  const OverlapZone zone = OverlapZone::box({{X1, -1, -1}, {X2, 2, 2}}, 0, true, {WeightShape::linear, 0.05, 0.5});
  CoupledModel model(dem, *cont, zone, CoupledOptions{});
  const double dt = 0.9 * model.critical_time_step();
  for (int n = 0; n < 10; ++n) model.step(dt);  // a few steps: the burst is where it was put
  std::vector<std::uint32_t> ids;
  for (std::size_t i = 0; i < dem.particles.size(); ++i)
    if (dem.particles.reference[i].x >= X1 - 10.0 && dem.particles.reference[i].x <= X1 + 4.0) ids.push_back(static_cast<std::uint32_t>(i));
  const CoupledEnergies before = model.energies();
  const double kinetic = dem.kinetic_energy(ids);
  ASSERT_GT(kinetic, 1e-3 * before.total());  // the burst is there
  const double arrested = model.arrest(ids);
  const CoupledEnergies after = model.energies();
  EXPECT_NEAR(arrested, kinetic, 1e-12 * kinetic);
  EXPECT_NEAR(after.dem.dissipated - before.dem.dissipated, arrested, 1e-12 * kinetic);
  // What the arrest and the projection took out is what both booked (measured to 1e-16 of the total).
  const double booked = (after.dem.dissipated - before.dem.dissipated) - (after.coupling_work - before.coupling_work);
  EXPECT_NEAR(before.total() - after.total(), booked, 1e-12 * before.total());
  // The projection (least squares in the mass norm) only takes kinetic energy out.
  EXPECT_LT(after.coupling_work - before.coupling_work, 0.0);
  EXPECT_LT(model.monitor().constraint_residual, 1e-10);  // back on G v = 0 (measured 1.3e-16)
  std::printf("[arrest] DEs %.6e J, projection %.6e J, booked - taken %.2e, residual %.2e\n", arrested,
              after.coupling_work - before.coupling_work, booked - (before.total() - after.total()), model.monitor().constraint_residual);
}
