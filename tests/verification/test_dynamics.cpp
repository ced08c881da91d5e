// SPDX-License-Identifier: GPL-3.0-or-later
// Verification of the explicit step against closed forms: free flight and spin, a bonded
// pair's axial frequency, energy drift and momentum conservation of a bonded block, the
// long-wave speed of a bonded chain, and an elastic head-on contact; the critical step's bound
// against a bonded pair's eigenvalues and a contact pair's frequency.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "dem/bonds/cohesive_contact.hpp"
#include "dem/bonds/spring_bond.hpp"
#include "dem/contacts/penalty_contact.hpp"
#include "support/dem_fixtures.hpp"
#include "support/omp_threads.hpp"

namespace arlequin::dem {
namespace {

constexpr double steel = 7800.0;                      // kg/m^3
const BeamBondSet::Parameters beam{2e11, 0.3, 0.5};   // Pa, 1, 1

TEST(FreeMotion, FlightAndSpinAreExact) {
  DemModel model;
  model.particles.add({0.1, -0.2, 0.3}, 1e-3, steel);
  const Vec3 v{1.0, -2.0, 0.5}, w{30.0, -20.0, 50.0};
  model.particles.velocity[0] = v;
  model.particles.angular_velocity[0] = w;
  model.finalize();
  const double dt = 1e-4;
  for (int n = 0; n < 1000; ++n) model.step(dt);
  const double t = model.time();
  const Vec3 x = model.particles.position[0];
  EXPECT_LT(norm(x - (Vec3{0.1, -0.2, 0.3} + v * t)), 1e-12);
  // The body axes have turned by w t about w: compare where a body vector points.
  const Vec3 a{0.3, 0.4, -0.5};
  const Vec3 exact = rotate(from_rotation_vector(w * t), a);
  EXPECT_LT(norm(rotate(model.particles.orientation[0], a) - exact), 1e-12);
  EXPECT_NEAR(norm2(model.particles.orientation[0].v) + std::pow(model.particles.orientation[0].w, 2), 1.0, 1e-15);
}

// The drift takes DEs eight at a time, one a vector lane: a DE's new position and orientation
// must not depend on the DEs beside it (its bits: the threads split the DEs differently), and
// must be the exact free flight and rotation. Three blocks and a tail of three: some DEs without
// spin (their orientation is left as it is), one beyond the rotation vector's series, and a block
// whose only turning DE is its last, about z (the block's last double of omega: a block that
// seemed not to turn would leave it as it was).
// Bounds: 50 steps of round-off on coordinates of order 1 (an ulp is 2.2e-16) and on a unit
// quaternion.
TEST(FreeMotion, DesDriftTheSameInABlockAndAlone) {
  ParticleSet blocks;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 27;
  const double dt = 1e-4;
  for (int i = 0; i < n; ++i) {
    blocks.add({u(rng), u(rng), u(rng)}, 1e-3, steel);
    blocks.velocity[i] = {u(rng), u(rng), u(rng)};
    if (i % 5 != 2) blocks.angular_velocity[i] = Vec3{u(rng), u(rng), u(rng)} * 40.0;  // |omega| dt < 7e-3 rad
    blocks.orientation[i] = from_rotation_vector({3 * u(rng), 3 * u(rng), 3 * u(rng)});
  }
  blocks.angular_velocity[11] = {0.0, 200.0, 0.0};  // 2e-2 rad a step: beyond the series (1e-2)
  for (int i = 16; i < 23; ++i) blocks.angular_velocity[i] = {};
  blocks.angular_velocity[23] = {0.0, 0.0, 50.0};
  ParticleSet alone = blocks;
  const ParticleSet start = blocks;
  const int steps = 50;
  for (int step = 0; step < steps; ++step) {
    blocks.drift(0, n, dt);
    for (int i = 0; i < n; ++i) alone.drift(i, i + 1, dt);
  }
  const Vec3 a{0.3, 0.4, -0.5};
  for (int i = 0; i < n; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(blocks.position[i], alone.position[i]);
    EXPECT_EQ(blocks.orientation[i].w, alone.orientation[i].w);
    EXPECT_EQ(blocks.orientation[i].v, alone.orientation[i].v);
    const Vec3 w = blocks.angular_velocity[i];
    const Vec3 exact = rotate(from_rotation_vector(w * (steps * dt)), rotate(start.orientation[i], a));
    EXPECT_LT(norm(rotate(blocks.orientation[i], a) - exact), 2e-14);
    EXPECT_LT(norm(blocks.position[i] - (start.position[i] + start.velocity[i] * (steps * dt))), 2e-14);
  }
}

// Two touching DEs of radius R = 1 mm joined by one beam; omega_axial = sqrt(2 k / m) for the
// two equal masses on the axial spring k = E S / L0.
struct BondedPair : ::testing::Test {
  static constexpr double R = 1e-3;
  DemModel model;
  double axial_stiffness = 0.0;  // E S / L0, N/m
  double omega_axial = 0.0;
  void SetUp() override {
    model.particles.add({0, 0, 0}, R, steel);
    model.particles.add({2 * R, 0, 0}, R, steel);
    test::bond_all_touching(model, beam);
    axial_stiffness = beam.young * std::numbers::pi * std::pow(beam.radius_ratio * R, 2) / (2 * R);
    omega_axial = std::sqrt(2.0 * axial_stiffness / model.particles.mass(0));
  }
};

// The energy sensor of a group: its DEs' kinetic energy and half the energy of each bond they
// hold. Stretched by delta, the pair's bond holds k delta^2 / 2 (k = E S / L0): DE 0's group
// gets a quarter of k delta^2 with its own kinetic energy, the pair's group both DEs' and the
// whole bond, which is the model's total. Measured: 5e-15 of each; bound 2e-13 of the total
// (the stretch is the difference of two lengths 200 times larger).
TEST_F(BondedPair, AGroupsEnergyIsItsKineticEnergyAndHalfOfEachOfItsBonds) {
  const int left = model.add_group("left", {0}), both = model.add_group("both", {0, 1});
  model.finalize();
  const double delta = 1e-5;
  model.particles.position[1].x += delta;
  model.particles.velocity[0] = {-0.2, 0.0, 0.0};
  model.particles.velocity[1] = {0.0, 0.3, 0.0};
  const double m = model.particles.mass(0), bond = 0.5 * axial_stiffness * delta * delta, total = model.energies().total();
  const double left_closed = 0.5 * bond + 0.5 * m * 0.04, both_closed = bond + 0.5 * m * (0.04 + 0.09);
  std::printf("group energies / closed forms - 1: one DE %.1e, both %.1e\n", model.group_energy(left) / left_closed - 1.0,
              model.group_energy(both) / both_closed - 1.0);
  EXPECT_NEAR(model.group_energy(left), left_closed, 2e-13 * total);
  EXPECT_NEAR(model.group_energy(both), both_closed, 2e-13 * total);
  EXPECT_NEAR(model.group_energy(both), total, 1e-14 * total);
}

TEST_F(BondedPair, AxialOscillationAtTheClosedFormFrequency) {
  model.particles.velocity[0] = {-1e-3, 0, 0};
  model.particles.velocity[1] = {1e-3, 0, 0};
  model.finalize();
  const double omega = omega_axial;
  const double dt = 0.02 / omega;
  // Times where the relative velocity changes sign, linearly interpolated.
  std::vector<double> crossings;
  double previous = 2e-3, t_previous = 0.0;
  while (crossings.size() < 41) {
    model.step(dt);
    const double rel = model.particles.velocity[1].x - model.particles.velocity[0].x;
    if ((rel < 0) != (previous < 0))
      crossings.push_back(t_previous + dt * previous / (previous - rel));
    previous = rel;
    t_previous = model.time();
  }
  const double period = (crossings.back() - crossings.front()) / 20.0;
  EXPECT_NEAR(2 * std::numbers::pi / period, omega, 1e-3 * omega);
}

// DE 0 clamped (fixed, rotation locked): DE 1 oscillates on the axial spring alone, at
// omega = sqrt(k / m) = omega_axial / sqrt(2), x1 = 2R + (v0 / omega) sin(omega t). The clamped
// DE's own initial motion is dropped when the model is finalized (it could never move), so the
// balance from there holds with no work by the clamp, whose DE does not move.
TEST_F(BondedPair, AClampedEndHoldsItsDeAndDoesNoWork) {
  const double v0 = 1e-3;
  model.particles.velocity[0] = {0.2, -0.1, 0.05};
  model.particles.angular_velocity[0] = {5.0, 0.0, -3.0};
  model.particles.velocity[1] = {v0, 0, 0};
  model.add_group("clamp", {0});
  model.add_boundary({"clamp", BoundaryKind::fixed, {}, 0.0, true});
  model.finalize();
  EXPECT_EQ(model.particles.velocity[0], Vec3{});
  EXPECT_EQ(model.particles.angular_velocity[0], Vec3{});
  const double e0 = model.energies().total();
  const double omega = omega_axial / std::sqrt(2.0), amplitude = v0 / omega, dt = 0.01 / omega;
  double worst = 0.0, worst_balance = 0.0;
  while (model.time() < 2.5 * std::numbers::pi / omega) {  // 1.25 periods
    model.step(dt);
    worst = std::max(worst, std::abs(model.particles.position[1].x - (2 * R + amplitude * std::sin(omega * model.time()))));
    const auto e = model.energies();
    worst_balance = std::max(worst_balance, std::abs(e.balance(e0)));
    ASSERT_EQ(model.particles.position[0], Vec3{});
    ASSERT_EQ(e.external_work, 0.0);
  }
  // Velocity Verlet's phase lags by (omega dt)^2 / 24 a radian: 3.3e-5 of the amplitude over
  // the run (3.1e-5 measured); its energy oscillates by (omega dt)^2 / 4 of the energy (2.5e-5).
  // Bounds 3x above.
  EXPECT_LT(worst, 1e-4 * amplitude);
  EXPECT_LT(worst_balance, 7.5e-5 * e0);
}

// A 4 x 4 x 4 bonded block with random velocities and spins, no boundary conditions.
struct FreeBlock : ::testing::Test {
  DemModel model;
  void SetUp() override {
    build_lattice(model.particles, {0, 0, 0}, {4, 4, 4}, 2e-3, 1e-3, steel);
    test::bond_all_touching(model, beam);
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (std::size_t i = 0; i < model.particles.size(); ++i) {
      model.particles.velocity[i] = {1e-2 * u(rng), 1e-2 * u(rng), 1e-2 * u(rng)};
      model.particles.angular_velocity[i] = {10 * u(rng), 10 * u(rng), 10 * u(rng)};
    }
    model.finalize();
  }
  Vec3 momentum() const {
    Vec3 P{};
    for (std::size_t i = 0; i < model.particles.size(); ++i) P += model.particles.velocity[i] * model.particles.mass(i);
    return P;
  }
  Vec3 angular_momentum() const {
    Vec3 L{};
    const ParticleSet& p = model.particles;
    for (std::size_t i = 0; i < p.size(); ++i)
      L += cross(p.position[i], p.velocity[i] * p.mass(i)) + p.angular_velocity[i] * p.inertia(i);
    return L;
  }
};

TEST_F(FreeBlock, EnergyDriftBelow1e4Over1e5StepsAtHalfTheCriticalStep) {
  const double dt = 0.5 * model.critical_time_step();
  const int steps = 100000, every = 100;
  std::vector<double> energy;
  for (int n = 0; n <= steps; ++n) {
    if (n % every == 0) energy.push_back(model.energies().total());
    if (n < steps) model.step(dt);
  }
  // Drift: mean over the last tenth against the first tenth (the step's bounded
  // oscillation of the energy is not drift).
  const std::size_t tenth = energy.size() / 10;
  double first = 0, last = 0;
  for (std::size_t k = 0; k < tenth; ++k) first += energy[k], last += energy[energy.size() - 1 - k];
  EXPECT_LT(std::abs(last - first) / first, 1e-4);
}

TEST_F(FreeBlock, MomentumIsConservedToRoundOff) {
  const Vec3 P0 = momentum(), L0 = angular_momentum();
  double p_scale = 0, l_scale = 0;
  for (std::size_t i = 0; i < model.particles.size(); ++i) {
    p_scale += model.particles.mass(i) * norm(model.particles.velocity[i]);
    l_scale += model.particles.inertia(i) * norm(model.particles.angular_velocity[i]);
  }
  const double dt = 0.3 * model.critical_time_step();
  for (int n = 0; n < 2000; ++n) model.step(dt);
  EXPECT_LT(norm(momentum() - P0), 1e-12 * p_scale);
  EXPECT_LT(norm(angular_momentum() - L0), 1e-11 * l_scale);
}

TEST(BondedChain, PulseTravelsAtTheLongWaveSpeed) {
  DemModel model;
  const double R = 1e-3, L0 = 2 * R;
  const int n = 400, probe = 300;
  build_chain(model.particles, {0, 0, 0}, {1, 0, 0}, n, L0, R, steel);
  test::bond_all_touching(model, beam);
  model.add_group("driver", {0});
  const double v0 = 1e-3;
  model.add_boundary({"driver", BoundaryKind::velocity, {v0, 0, 0}, 0.0, false});
  model.finalize();
  const double k = beam.young * std::numbers::pi * std::pow(beam.radius_ratio * R, 2) / L0;
  const double c = L0 * std::sqrt(k / model.particles.mass(0));  // long-wave speed of the chain
  const double dt = 0.3 * model.critical_time_step();
  // Arrival: the probe's velocity reaches half the driven velocity (the centre of the
  // dispersive front of a step travels at c).
  double arrival = 0.0, previous = 0.0;
  while (arrival == 0.0) {
    model.step(dt);
    const double v = model.particles.velocity[probe].x;
    if (v >= 0.5 * v0) arrival = model.time() - dt * (v - 0.5 * v0) / (v - previous);
    previous = v;
    ASSERT_LT(model.time(), 10.0 * probe * L0 / c);
  }
  const double speed = probe * L0 / arrival;
  EXPECT_NEAR(speed, c, 0.02 * c);
}

// Gravity: velocity Verlet integrates a constant force exactly, so a free DE falls by g t^2 / 2
// and reaches g t to round-off; a fixed DE does not fall and gravity does no work on it; the
// kinetic energy gained is gravity's work (the potential's drop), so the balance is zero.
TEST(Gravity, AFreeDeFallsByTheClosedFormAndTheBalanceHolds) {
  DemModel model;
  const double R = 1e-3;
  model.particles.add({0, 0, 0}, R, steel);
  model.particles.add({1, 0, 0}, R, steel);
  model.particles.velocity[0] = {0.5, 0, 0};
  model.add_group("held", {1});
  model.add_boundary({"held", BoundaryKind::fixed, {}, 0.0, false});
  const Vec3 g{0, 0, -9.81};
  model.set_gravity(g);
  model.finalize();
  const double e0 = model.energies().total();
  const double dt = 1e-4;
  for (int n = 0; n < 1000; ++n) model.step(dt);
  const double t = model.time();
  EXPECT_NEAR(model.particles.position[0].z, 0.5 * g.z * t * t, 1e-12);
  EXPECT_NEAR(model.particles.position[0].x, 0.5 * t, 1e-12);
  EXPECT_NEAR(model.particles.velocity[0].z, g.z * t, 1e-12);
  EXPECT_EQ(model.particles.position[1].z, 0.0);
  const auto e = model.energies();
  EXPECT_NEAR(e.external_work, model.particles.mass(0) * 9.81 * 9.81 * t * t / 2, 1e-12 * e.kinetic);
  EXPECT_NEAR(e.balance(e0), 0.0, 1e-12 * e.kinetic);
}

TEST(PenaltyContact, HeadOnImpactConservesEnergy) {
  DemModel model;
  const double R = 1e-3, K = 1e6;
  model.particles.add({0, 0, 0}, R, steel);
  model.particles.add({2 * R + 1e-4, 0, 0}, R, steel);
  model.particles.velocity[0] = {1.0, 0, 0};
  model.particles.velocity[1] = {-1.0, 0, 0};
  model.set_contact(std::make_unique<PenaltyContact>(K), 0.2 * R);
  model.finalize();
  const double e0 = model.energies().total();
  // Velocity Verlet's energy error while in contact is bounded, O((omega dt)^2).
  const double dt = 0.01 * model.critical_time_step();
  double worst = 0.0, max_contact = 0.0;
  while (model.time() < 4e-4) {
    model.step(dt);
    const Energies e = model.energies();
    worst = std::max(worst, std::abs(e.total() - e0));
    max_contact = std::max(max_contact, e.contact);
  }
  EXPECT_GT(max_contact, 0.5 * e0);  // the DEs did meet and store most of the energy
  EXPECT_NEAR(model.particles.velocity[0].x, -1.0, 1e-4);  // they bounced back, elastically
  EXPECT_NEAR(model.particles.velocity[1].x, 1.0, 1e-4);
  EXPECT_NEAR(model.energies().total(), e0, 1e-4 * e0);
  EXPECT_LT(worst, 1e-3 * e0);
}

// The head-on pair made too fast or too soft for its contact (docs/theory.md#critical-step):
// the critical step keeps a DE within its radius per step at its speed, a run forced past that
// stops naming the DE, and an overlap beyond the smaller radius (the penalty cannot stop the
// impact: K delta^2 / 2 < m v^2 / 2 with delta = R) stops naming the pair. Both passed silently.
TEST(PenaltyContact, TooFastOrTooSoftStopsTheRun) {
  const double R = 1e-3, v = 1e3;  // m, m/s
  const auto pair = [&](double K, double gap) {
    auto model = std::make_unique<DemModel>();
    model->particles.add({0, 0, 0}, R, steel);
    model->particles.add({2 * R + gap, 0, 0}, R, steel);
    model->particles.velocity[0] = {v, 0, 0};
    model->set_contact(std::make_unique<PenaltyContact>(K), 0.2 * R);
    model->finalize();
    return model;
  };
  auto fast = pair(1e6, 10 * R);  // not in contact during the step
  fast->particles.velocity[1] = {-v, 0, 0};
  fast->particles.velocity[0] = {0.6 * v, 0, 0};  // too fast as well, but the message names the fastest
  EXPECT_LE(fast->critical_time_step(), R / v);
  fast->step(2.5 * R / v);
  try {
    fast->check_finite();
    FAIL() << "a DE moving 2.5 radii per step was not stopped";
  } catch (const RunError& e) {
    EXPECT_NE(std::string(e.what()).find("DE 1 at"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("moves 2.5 of its radius per step"), std::string::npos) << e.what();
  }
  // m v^2 = 0.033 J, K R^2 = 1e-4 J: the spheres go through each other.
  auto soft = pair(100.0, 1e-4);
  const double dt = 0.3 * soft->critical_time_step();
  try {
    for (int n = 0; n < 100; ++n) {
      soft->step(dt);
      soft->check_finite();
    }
    FAIL() << "an overlap beyond the radius was not stopped";
  } catch (const RunError& e) {
    EXPECT_NE(std::string(e.what()).find("the contact of DEs 0 and 1 overlaps"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("too soft"), std::string::npos) << e.what();
  }
}

// Friction (docs/theory.md#contact-friction): DE 1 overlaps the resting DE 0 by delta and slides
// past it along y at v. Sliding faster than v_slip: F_t = -mu K delta y on DE 1, applied at the
// contact point, delta/2 inside each sphere, so its torque is (-(R - delta/2) x) x F_t (and the
// pair's angular momentum is kept); the power dissipated mu K delta v. Slower: the force is
// scaled by v / v_slip.
TEST(PenaltyContact, FrictionOpposesSlidingWithTheCoulombForce) {
  const double R = 1e-3, K = 1e6, delta = 1e-5, mu = 0.3, v_slip = 1e-3;
  for (double v : {0.5, 0.25 * v_slip}) {
    ParticleSet p;
    p.add({0, 0, 0}, R, steel);
    p.add({2 * R - delta, 0, 0}, R, steel);
    p.velocity[1] = {0, v, 0};
    NeighbourList list(0.2 * R);
    list.build(p);
    const PenaltyContact law(K, mu, v_slip);
    p.clear_forces();
    const double power = law.accumulate_forces(list, p).friction_power;
    const double f_t = mu * K * delta * std::min(1.0, v / v_slip);
    EXPECT_NEAR(p.force[1].x, K * delta, 1e-9 * K * delta);
    EXPECT_NEAR(p.force[1].y, -f_t, 1e-9 * f_t);
    EXPECT_NEAR(p.force[0].y, f_t, 1e-9 * f_t);
    const double arm = R - delta / 2;
    EXPECT_NEAR(p.torque[1].z, arm * f_t, 1e-9 * R * f_t);
    EXPECT_NEAR(p.torque[0].z, arm * f_t, 1e-9 * R * f_t);
    EXPECT_NEAR(power, f_t * v, 1e-9 * f_t * v);
  }
}

// The neighbour list keeps a DE far larger than the median (an impactor) out of its cells and
// tests it against every DE: the pairs are those of a brute-force search over all pairs
// (within R_i + R_j + skin, excluded pairs left out), in (i, j) order, with the impactor among
// small DEs, a second impactor near it, and small DEs at a distance from both; built on one and
// on two threads (above the threshold, each thread collecting the pairs of its cells).
TEST(NeighbourList, LargeDesAmongSmallOnesFindTheSamePairsAsBruteForce) {
  ParticleSet p;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double r = 1e-4, skin = 3e-5;
  static_assert(6000 > parallel_threshold);
  for (int k = 0; k < 6000; ++k) p.add({u(rng) * 8e-3, u(rng) * 8e-3, u(rng) * 2e-3}, r * (0.9 + 0.2 * u(rng)), 1000.0);
  p.add({4e-3, 4e-3, 2.5e-3}, 2e-3, 7530.0);   // the impactor, touching the bed
  p.add({4e-3, 7e-3, 3.3e-3}, 1.5e-3, 7530.0);  // another, touching the first and the bed
  const std::uint32_t n = static_cast<std::uint32_t>(p.size());
  std::vector<std::pair<std::uint32_t, std::uint32_t>> within;
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = i + 1; j < n; ++j) {
      const double reach = p.radius[i] + p.radius[j] + skin;
      if (norm2(p.position[j] - p.position[i]) < reach * reach) within.emplace_back(i, j);
    }
  // Every fifth pair within reach but the two impactors' excluded (as a bond would), given
  // either way round, and two pairs out of reach; the list is the rest.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> excluded{{3, 4}, {n - 1, 17}}, expected;
  for (std::size_t k = 0; k < within.size(); ++k)
    if (k % 5 == 2 && within[k] != std::pair{n - 2, n - 1}) excluded.push_back(k % 2 ? within[k] : std::pair{within[k].second, within[k].first});
    else expected.push_back(within[k]);
  ASSERT_GT(std::count_if(excluded.begin(), excluded.end(), [&](auto q) { return q.first >= n - 2 || q.second >= n - 2; }), 5);
  for (const int threads : {1, 2}) {
#ifdef _OPENMP
    const test::OmpThreads scope(threads);
#endif
    NeighbourList list(skin);
    list.set_exclusions(excluded);
    list.build(p);
    const auto pairs = list.pairs();
    EXPECT_EQ(std::vector(pairs.begin(), pairs.end()), expected) << threads << " thread(s)";
  }
  // The case is the one it is meant to be: both large DEs have many neighbours, and meet.
  const auto with = [&](std::uint32_t d) { return std::count_if(expected.begin(), expected.end(), [&](auto q) { return q.first == d || q.second == d; }); };
  EXPECT_GT(with(n - 2), 50);
  EXPECT_GT(with(n - 1), 10);
  EXPECT_NE(std::find(expected.begin(), expected.end(), std::pair{n - 2, n - 1}), expected.end());
}

// A DE 2e34 m from the others (a fuzzer's table) made the grid's cell count overflow: the cells
// grow to fit and the pairs are still exact; DEs farther apart than a double measures are a
// RunError, not undefined behaviour.
TEST(NeighbourList, AFarAwayDeGrowsTheCellsAndBeyondMeasureIsARunError) {
  ParticleSet p;
  for (int k = 0; k < 4; ++k) p.add({0.0019 * k, 0, 0}, 1e-3, 1000.0);
  p.add({0.003, 2.2e34, 0.0035}, 1e-3, 1000.0);
  NeighbourList list(1e-4);
  list.build(p);
  const auto pairs = list.pairs();
  EXPECT_EQ(std::vector(pairs.begin(), pairs.end()), (std::vector<std::pair<std::uint32_t, std::uint32_t>>{{0, 1}, {1, 2}, {2, 3}}));
  p.position[4].y = 1e308;
  p.position[0].y = -1e308;
  EXPECT_THROW(list.build(p), RunError);
}

TEST_F(BondedPair, CriticalTimeStepBoundsTheTrueFrequency) {
  model.finalize();
  EXPECT_LE(model.critical_time_step(), 2.0 / omega_axial);
  // A bound, not a wild one: within a factor of four of the axial mode's limit.
  EXPECT_GT(model.critical_time_step(), 0.25 * 2.0 / omega_axial);
}

// The highest natural frequency of the model's DEs and bonds, linearised about their present
// state, computed apart from the bound critical_time_step() takes: the stiffness K by central
// differences of the bonds' forces and torques (moves of 1e-7 of a radius, turns of 1e-7 rad
// about the global axes, to which the torques are conjugate), M = diag(m, m, m, I, I, I) per
// DE, and omega_max^2 the largest eigenvalue of M^-1/2 K M^-1/2.
double highest_frequency(const DemModel& model) {
  const ParticleSet& start = model.particles;
  ParticleSet p = start;
  const int n = 6 * static_cast<int>(p.size());
  const auto actions = [&] {
    p.clear_forces();
    for (const auto& set : model.bond_sets()) set->accumulate_forces(p, ForceScan{});
    Eigen::VectorXd a(n);
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int c = 0; c < 3; ++c) a(6 * i + c) = p.force[i][c], a(6 * i + 3 + c) = p.torque[i][c];
    return a;
  };
  Eigen::MatrixXd K(n, n);
  for (int d = 0; d < n; ++d) {
    const std::size_t i = static_cast<std::size_t>(d / 6);
    const int c = d % 6;
    const double h = c < 3 ? 1e-7 * p.radius[i] : 1e-7;
    const auto moved = [&](double by) {
      p = start;
      Vec3 e{};
      e[c % 3] = by;
      if (c < 3) p.position[i] += e;
      else p.orientation[i] = from_rotation_vector(e) * p.orientation[i];
      return actions();
    };
    K.col(d) = (moved(-h) - moved(h)) / (2.0 * h);
  }
  EXPECT_LT((K - K.transpose()).norm(), 1e-6 * K.norm()) << "a conservative bond's stiffness is symmetric";
  Eigen::VectorXd scale(n);  // M^-1/2
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int c = 0; c < 3; ++c) scale(6 * i + c) = std::sqrt(p.inv_mass[i]), scale(6 * i + 3 + c) = std::sqrt(p.inv_inertia(i));
  const Eigen::MatrixXd A = scale.asDiagonal() * (0.5 * (K + K.transpose())) * scale.asDiagonal();
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff());
}

// Two DEs, their axis along no global axis, joined by one bond of each law: the critical step
// 2 / omega from the block-Gershgorin bound (docs/theory.md#critical-step) is at most 2 / omega_max
// of the pair's own modes, and not wildly below it. Two pairs: equal radii (1 mm), where the
// spring's bound is its exact sqrt(2 K / m) (so the bound allows the 1e-9 or so of the central
// differences) and the cohesive link's rotational rows need their coupling of the two DEs'
// turns; and 1 and 1.6 mm (masses 1 : 4.1), where a row that counts one end's mass alone falls
// below sqrt(K (1/m_1 + 1/m_2)). Measured ratios of the bound to 2 / omega_max: beam 0.88 and
// 0.80, spring 1.0 and 0.91, cohesive link 0.93 and 0.85.
TEST(CriticalStep, BoundsThePairsHighestFrequencyForEveryBondLaw) {
  for (const double R2 : {1e-3, 1.6e-3}) {
    const double R1 = 1e-3;
    std::vector<std::pair<std::string, std::unique_ptr<BondSet>>> laws;
    laws.emplace_back("beam", std::make_unique<BeamBondSet>(beam));
    laws.emplace_back("spring", std::make_unique<SpringBondSet>(1e7, 0.0));
    CohesiveContactSet::Parameters cohesive;
    cohesive.strength_normal = cohesive.strength_shear = 5e7;
    cohesive.toughness_I = cohesive.toughness_II = 300.0;
    cohesive.stiffness = 1e15;
    laws.emplace_back("cohesive", std::make_unique<CohesiveContactSet>(cohesive));
    for (auto& [name, set] : laws) {
      SCOPED_TRACE(name + ", R2 = " + std::to_string(R2));
      DemModel model;
      model.particles.add({0, 0, 0}, R1, steel);
      model.particles.add(Vec3{0.6, -0.3, 0.2} * ((R1 + R2) / 0.7), R2, steel);  // |(0.6, -0.3, 0.2)| = 0.7
      set->add(0, 1, model.particles);
      model.add_bond_set(std::move(set));
      model.finalize();
      const double bound = model.critical_time_step(), exact = 2.0 / highest_frequency(model);
      EXPECT_LE(bound, exact * (1.0 + 1e-6));
      EXPECT_GT(bound, 0.75 * exact);
    }
  }
}

// Two DEs in penalty contact (stiffness K, one neighbour each): the pair's only mode has
// omega^2 = K (1/m_1 + 1/m_2); the contact law's bound K (1/m_i + 1/sqrt(m_i m_min)) gives it
// exactly for equal masses (so the bound allows round-off) and 0.79 of 2 / omega for radii 1 and
// 1.6 mm.
TEST(CriticalStep, BoundsAContactPairsFrequency) {
  const double K = 1e6;  // N/m
  for (const double R2 : {1e-3, 1.6e-3}) {
    SCOPED_TRACE(R2);
    const double R1 = 1e-3;
    DemModel model;
    model.particles.add({0, 0, 0}, R1, steel);
    model.particles.add({0.999 * (R1 + R2), 0, 0}, R2, steel);
    model.set_contact(std::make_unique<PenaltyContact>(K), 0.2 * R1);
    model.finalize();
    const double exact = 2.0 / std::sqrt(K * (model.particles.inv_mass[0] + model.particles.inv_mass[1]));
    EXPECT_LE(model.critical_time_step(), exact * (1.0 + 1e-12));
    EXPECT_GT(model.critical_time_step(), 0.75 * exact);
  }
}

// Viscous damping applied from the half-step velocity multiplies a free DE's half-step velocity
// by (1 - c dt) per step: stable for c dt < 2 only, so the critical step of DEs without bonds is
// 2/c. A step 2 % above it makes the motion grow (1.04^400 = 6.5e6, less the two factors
// 1 - c dt/2 = -0.02 between full and half steps), 2 % below it decays (0.96^400 = 8e-8).
TEST(Damping, CriticalStepOfFreeDesIsTwoOverC) {
  const double c = 1e8;  // 1/s
  for (const double factor : {0.98, 1.02}) {
    DemModel model;
    model.particles.add({0, 0, 0}, 1e-3, steel);
    model.particles.velocity[0] = {1.0, 0, 0};
    model.set_damping(c);
    model.finalize();
    EXPECT_DOUBLE_EQ(model.critical_time_step(), 2.0 / c);
    for (int n = 0; n < 400; ++n) model.step(factor * model.critical_time_step());
    const double speed = norm(model.particles.velocity[0]);
    if (factor < 1.0) EXPECT_LT(speed, 1e-6);
    else EXPECT_GT(speed, 1e3);
  }
}

// With bonds the limit is dt^2 omega^2 + 2 c dt < 4 (docs/theory.md#critical-step): the damped
// step follows from the undamped one's omega, and is that step to the bit without damping.
TEST_F(BondedPair, DampingLowersTheCriticalStepByTheClosedForm) {
  model.finalize();
  const double undamped = model.critical_time_step();
  const double omega = 2.0 / undamped, c = 0.5 * omega;
  model.set_damping(c);
  const double damped = model.critical_time_step();
  EXPECT_DOUBLE_EQ(damped, 4.0 / (c + std::sqrt(c * c + 4.0 * omega * omega)));
  EXPECT_NEAR(damped * damped * omega * omega + 2.0 * c * damped, 4.0, 1e-12);
  model.set_damping(0.0);
  EXPECT_EQ(model.critical_time_step(), undamped);
}

}  // namespace
}  // namespace arlequin::dem
