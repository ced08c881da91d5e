// SPDX-License-Identifier: GPL-3.0-or-later
// R1 (docs/validation.md): single beam bond responses against the closed forms of a linear
// Euler-Bernoulli beam element, to 1e-9 relative. Small displacements (1e-5 of L) keep the
// geometric non-linearity (O(d^2/L^2)) and the round-off well below that.
#include <gtest/gtest.h>

#include <cmath>

#include "dem/bonds/spring_bond.hpp"
#include "support/dem_fixtures.hpp"

namespace arlequin::dem {
namespace {

using test::R1Beam;

struct TwoDEs : ::testing::Test {
  ParticleSet p;
  BeamBondSet beam{{R1Beam::E, R1Beam::nu, R1Beam::r_mu}};
  void SetUp() override {
    p.add({0, 0, 0}, R1Beam::R, 1.0);
    p.add({R1Beam::L, 0, 0}, R1Beam::R, 1.0);
    beam.add(0, 1, p);
    beam.finalize(2);
  }
  BeamBondSet::Actions act() const { return beam.actions(0, p); }
};

void expect_relative(double value, double expected, double tol = 1e-9) {
  EXPECT_NEAR(value, expected, tol * std::abs(expected)) << "expected " << expected;
}

TEST_F(TwoDEs, AxialPull) {
  const double d = 1e-3;
  p.position[1].x += d;
  const auto a = act();
  expect_relative(a.axial_force, 39269.908169872416 * d);  // E S / L
  expect_relative(a.axial_force, R1Beam::E * R1Beam::S / R1Beam::L * d);
  expect_relative(-a.force_on_j.x, a.axial_force);
  EXPECT_NEAR(norm(a.torque_on_i) + norm(a.torque_on_j), 0.0, 1e-12);
}

TEST_F(TwoDEs, SidewaysWithRotationsLocked) {
  const double d = 2e-5;
  p.position[1].y += d;
  const auto a = act();
  const double V = 12 * R1Beam::E * R1Beam::I / std::pow(R1Beam::L, 3) * d;  // 7363.11 d
  const double M = 6 * R1Beam::E * R1Beam::I / std::pow(R1Beam::L, 2) * d;   // 7363.11 d
  expect_relative(V / d, 7363.107781851077, 1e-9);
  // The shear force is perpendicular to the (slightly turned) chord; its y part carries V.
  expect_relative(-dot(a.force_on_j, cross({0, 0, 1}, a.axis)), V);
  expect_relative(a.torque_on_i.z, M);
  expect_relative(a.torque_on_j.z, M);
}

TEST_F(TwoDEs, SidewaysWithEndFreeToRotate) {
  const double d = 2e-5;
  p.position[1].y += d;
  // Turn DE j about z until it carries no moment (the response is linear: two evaluations).
  const auto moment_at = [&](double psi) {
    p.orientation[1] = from_rotation_vector({0, 0, psi});
    return act().torque_on_j.z;
  };
  const double m0 = moment_at(0.0), m1 = moment_at(1e-5);
  const double psi = -m0 * 1e-5 / (m1 - m0);
  expect_relative(psi, 1.5 * d / R1Beam::L, 1e-8);  // slope of a cantilever tip: 3d/(2L)
  p.orientation[1] = from_rotation_vector({0, 0, psi});
  const auto a = act();
  EXPECT_NEAR(a.torque_on_j.z, 0.0, 1e-9 * std::abs(m0));
  expect_relative(-dot(a.force_on_j, cross({0, 0, 1}, a.axis)), 1840.7769454627693 * d, 1e-8);  // 3EI/L^3
}

TEST_F(TwoDEs, RotateOneEnd) {
  const double t = 1e-6;
  for (const Vec3 axis : {Vec3{0, 0, 1}, Vec3{0, 1, 0}}) {
    p.orientation[0] = from_rotation_vector(axis * t);
    const auto a = act();
    expect_relative(-dot(a.torque_on_i, axis), 9817.477042468104 * t);  // 4EI/L
    expect_relative(-dot(a.torque_on_j, axis), 4908.738521234052 * t);  // 2EI/L
    expect_relative(norm(a.force_on_j), 7363.107781851077 * t);         // 6EI/L^2
  }
}

TEST_F(TwoDEs, TwistAboutTheAxis) {
  const double t = 1e-6;
  p.orientation[1] = from_rotation_vector({t, 0, 0});
  const auto a = act();
  const double GJ_over_L = R1Beam::G * R1Beam::J / R1Beam::L;
  expect_relative(GJ_over_L, 1887.98, 5e-6);  // R1 table value, 6 digits
  expect_relative(-a.torque_on_j.x, GJ_over_L * t);
  expect_relative(a.torque_on_i.x, GJ_over_L * t);
  EXPECT_NEAR(norm(a.force_on_j), 0.0, 1e-12);
}

TEST_F(TwoDEs, ForcesAndMomentsBalanceInAnyConfiguration) {
  p.position[1] = {1.7, 0.6, -0.4};
  p.orientation[0] = from_rotation_vector({0.2, -0.1, 0.3});
  p.orientation[1] = from_rotation_vector({-0.3, 0.25, 0.1});
  const auto a = act();
  // Moments about DE i: its torque, DE j's torque and the lever of DE j's force.
  const Vec3 total = a.torque_on_i + a.torque_on_j + cross(p.position[1] - p.position[0], a.force_on_j);
  EXPECT_LT(norm(total), 1e-9 * (norm(a.torque_on_i) + norm(a.torque_on_j)));
}

TEST_F(TwoDEs, EnergyIsThePotentialOfTheForces) {
  // Central difference of the energy against the force, along a mixed direction.
  p.position[1] = {2.001, 0.0007, -0.0004};
  p.orientation[0] = from_rotation_vector({1e-4, -2e-4, 3e-4});
  const Vec3 dir = normalized(Vec3{0.3, -0.8, 0.5});
  const double h = 1e-7;
  const Vec3 x = p.position[1];
  p.position[1] = x + dir * h;
  const double e_plus = beam.energy(p);
  p.position[1] = x - dir * h;
  const double e_minus = beam.energy(p);
  p.position[1] = x;
  const double work_rate = dot(act().force_on_j, dir);
  EXPECT_NEAR(-(e_plus - e_minus) / (2 * h), work_rate, 1e-4 * std::abs(work_rate));
}

// Bonds are evaluated BeamBondSet::block at a time, one per SIMD lane (a full block and a part
// one here). Each lane is its own bond: a block gives the bits of each bond evaluated alone.
// Each lane has its own rest length and direction (in the xz-plane, so its reference normal
// p0 is (-sin phi, 0, cos phi)), its own end rotation about p0, twist about the axis and
// stretch, in the atan series (below 2.9 degrees), beyond it (atan2) or exactly zero, and gives
// them back: the rotation, the twist, the axial force E S / L0 times the stretch, and BBF's
// stresses (computed in the lanes too): E times the strain, and 2 E r_b / L0 times 2 |turn|.
TEST(BeamBlock, EachLaneIsItsOwnBond) {
  const double turns[] = {0.0, 1e-9, 1e-6, 0.01, 0.049, 0.051, 0.2, 1.0, 2.5, -0.3, -1e-3};  // rad
  const double twists[] = {0.3, 0.0, -1e-3, 2.0, 1e-7, -0.04, 0.06, 0.0, 1e-5, -1.2, 0.5};  // rad
  constexpr std::size_t n = std::size(turns);
  static_assert(n > BeamBondSet::block && n < 2 * BeamBondSet::block && std::size(twists) == n);
  const auto rest_length = [](std::size_t k) { return R1Beam::L * (1.0 + 0.05 * double(k)); };
  const auto phi = [](std::size_t k) { return 0.2 * double(k) - 1.0; };  // rad, from the x axis
  const auto direction = [&](std::size_t k) { return Vec3{std::cos(phi(k)), 0.0, std::sin(phi(k))}; };
  const auto normal = [&](std::size_t k) { return Vec3{-std::sin(phi(k)), 0.0, std::cos(phi(k))}; };
  const auto stretch = [](std::size_t k) { return 1e-5 * R1Beam::L * (double(k) - 4.0); };  // m
  ParticleSet p;
  BeamBondSet beam{{R1Beam::E, R1Beam::nu, R1Beam::r_mu}};
  for (std::size_t k = 0; k < n; ++k) {
    p.add({0, 3.0 * k, 0}, R1Beam::R, 1.0);
    p.add(Vec3{0, 3.0 * k, 0} + direction(k) * rest_length(k), R1Beam::R, 1.0);
    beam.add(static_cast<std::uint32_t>(2 * k), static_cast<std::uint32_t>(2 * k + 1), p);
  }
  beam.finalize(p.size());
  for (std::size_t k = 0; k < n; ++k) {
    p.orientation[2 * k] = from_rotation_vector(normal(k) * turns[k]);
    p.orientation[2 * k + 1] = from_rotation_vector(direction(k) * twists[k]);
    p.position[2 * k + 1] += direction(k) * stretch(k);
  }
  BeamBondSet::ActionsBlock blocks[2];
  beam.actions(0, BeamBondSet::block, p, blocks[0], true);
  beam.actions(BeamBondSet::block, n - BeamBondSet::block, p, blocks[1], true);
  for (std::size_t b = 0; b < n; ++b) {
    const BeamBondSet::Actions alone = beam.actions(b, p), a = blocks[b / BeamBondSet::block][b % BeamBondSet::block];
    EXPECT_EQ(a.length, alone.length) << b;
    EXPECT_EQ(a.axial_force, alone.axial_force) << b;
    EXPECT_EQ(a.twist, alone.twist) << b;
    EXPECT_EQ(a.axial_stress, alone.axial_stress) << b;
    EXPECT_EQ(a.bending_stress, alone.bending_stress) << b;
    for (const auto& [x, y] : {std::pair{a.axis, alone.axis}, {a.theta_a, alone.theta_a}, {a.theta_b, alone.theta_b},
                               {a.force_on_j, alone.force_on_j}, {a.torque_on_i, alone.torque_on_i},
                               {a.torque_on_j, alone.torque_on_j}})
      EXPECT_EQ(x, y) << b;
    const std::size_t k = beam.first()[b] / 2;
    // DE i turned about p0: theta_a along p0 (the series: 5e-12 relative); DE j about the axis.
    EXPECT_NEAR(dot(a.theta_a, normal(k)), turns[k], 5e-12 * std::abs(turns[k]) + 1e-15) << b;
    EXPECT_LT(norm(cross(a.theta_a, normal(k))), 1e-15 * (1.0 + std::abs(turns[k]))) << b;
    EXPECT_LT(norm(a.theta_b), 1e-15) << b;
    EXPECT_NEAR(a.twist, twists[k], 5e-12 * std::abs(twists[k]) + 1e-15) << b;
    expect_relative(a.axial_force, R1Beam::E * R1Beam::S / rest_length(k) * stretch(k), 1e-9);
    const double unit_strain = R1Beam::E * 1e-5;  // the stresses' scale: E times a strain of 1e-5
    EXPECT_NEAR(a.axial_stress, R1Beam::E * stretch(k) / rest_length(k), 1e-9 * unit_strain) << b;
    const double bending = 4.0 * R1Beam::E * R1Beam::r_mu * R1Beam::R / rest_length(k) * std::abs(turns[k]);
    EXPECT_NEAR(a.bending_stress, bending, 5e-12 * bending + 1e-9 * unit_strain) << b;
  }
}

// A force pass needs finalize() (the bonds' order, their passes): asked before it, it says so
// instead of reading the passes' empty lists.
TEST(BeamChain, AForcePassBeforeFinalizeIsRefused) {
  DemModel model;
  build_chain(model.particles, {0, 0, 0}, {1, 0, 0}, 3, 2e-3, 1e-3, 7800.0);
  test::bond_all_touching(model, {1e11, 0.3, 0.5});
  const auto refusal = [](auto&& call) {
    try {
      call();
    } catch (const std::logic_error& e) {
      return std::string(e.what());
    }
    return std::string("none");
  };
  EXPECT_EQ(refusal([&] { model.step(1e-9); }), "DemModel: a force pass before finalize()");
  StepProfile profile;
  EXPECT_EQ(refusal([&] { model.set_profile(&profile); }), "DemModel: set_profile before finalize()");
  model.finalize();
  EXPECT_EQ(refusal([&] { model.step(1e-9); }), "none");
}

// R1 chain: 10 bonds (20 mm), clamped, 0.01 N sideways at the tip, relaxed with viscous
// damping: tip deflection P L^3/(3EI) = 5.432489e-3 mm and rotation P L^2/(2EI) =
// 4.074367e-4 rad to 1e-4 (SI units here: the deflection is in m).
// The R1 chain's DEs, bonds and conditions, not finalized.
void build_clamped_cantilever(DemModel& model) {
  build_chain(model.particles, {0, 0, 0}, {1, 0, 0}, 11, 2e-3, 1e-3, 7800.0);
  test::bond_all_touching(model, {1e11, 0.3, 0.5});
  model.add_group("clamp", {0});
  model.add_group("tip", {10});
  model.add_boundary({"clamp", BoundaryKind::fixed, {}, 0.0, true});
  model.add_boundary({"tip", BoundaryKind::force, {0, 0.01, 0}, 0.0, false});
}

TEST(BeamChain, ClampedCantileverRelaxesToBeamTheory) {
  DemModel model;
  build_clamped_cantilever(model);
  model.set_damping(400.0);
  model.finalize();
  const double dt = 0.3 * model.critical_time_step();
  while (model.time() < 0.25) model.step(dt);
  const double deflection = model.particles.position[10].y;
  const Quat q = model.particles.orientation[10];
  const double rotation = 2.0 * std::atan2(q.v.z, q.w);
  expect_relative(deflection, 5.432489e-6, 1e-4);
  expect_relative(rotation, 4.074367e-4, 1e-4);
}

// The same cantilever relaxed by kinetic damping instead (DemModel::arrest whenever the kinetic
// energy falls, dynamic relaxation): the same beam theory, and the energy balance closes with
// what the arrests took out booked as dissipation (the tip force's work is the bond energy plus
// it).
TEST(BeamChain, KineticDampingRelaxesTheCantileverToBeamTheory) {
  DemModel model;
  build_clamped_cantilever(model);
  model.finalize();
  std::vector<std::uint32_t> all(11);
  for (std::uint32_t i = 0; i < 11; ++i) all[i] = i;
  const double dt = 0.3 * model.critical_time_step();
  double last = 0.0, arrested = 0.0;
  int arrests = 0;
  for (int n = 0; n < 200000; ++n) {
    model.step(dt);
    if (const double kinetic = model.kinetic_energy(); kinetic < last) {
      arrested += model.arrest(all), ++arrests;
      last = 0.0;
    } else {
      last = kinetic;
    }
  }
  expect_relative(model.particles.position[10].y, 5.432489e-6, 1e-4);
  const Quat q = model.particles.orientation[10];
  expect_relative(2.0 * std::atan2(q.v.z, q.w), 4.074367e-4, 1e-4);
  const Energies e = model.energies();
  EXPECT_NEAR(e.dissipated, arrested, 1e-12 * arrested);
  EXPECT_NEAR(e.balance(0.0), 0.0, 2e-6 * e.external_work);  // measured 4e-7
  // A load put on at once: half its work P delta is stored (P delta / 2), half taken out.
  expect_relative(arrested, 0.5 * e.external_work, 1e-4);
  std::printf("[kinetic damping] %d arrests, dissipated %.6e J of work %.6e J, balance %.2e J\n", arrests, arrested,
              e.external_work, e.balance(0.0));
}

// An arrest keeps the components a kinematic condition imposes and books the rest.
TEST(BeamChain, AnArrestKeepsImposedMotion) {
  DemModel model;
  build_chain(model.particles, {0, 0, 0}, {1, 0, 0}, 2, 2e-3, 1e-3, 7800.0);
  test::bond_all_touching(model, {1e11, 0.3, 0.5});
  model.add_group("driven", {0});
  BoundaryCondition pull{"driven", BoundaryKind::velocity, {1.0, 0.0, 0.0}, 0.0, false};
  pull.components = {true, false, false};
  model.add_boundary(pull);
  model.finalize();
  model.particles.velocity[0] = {1.0, 2.0, 0.0};
  model.particles.velocity[1] = {0.5, 0.0, 3.0};
  model.particles.angular_velocity[1] = {0.0, 0.0, 100.0};
  const std::vector<std::uint32_t> both{0, 1};
  const double free_part = 0.5 * model.particles.mass(0) * 4.0 + model.kinetic_energy(std::vector<std::uint32_t>{1});
  EXPECT_NEAR(model.arrest(both), free_part, 1e-12 * free_part);
  EXPECT_EQ(model.particles.velocity[0].x, 1.0);
  EXPECT_EQ(model.particles.velocity[0].y, 0.0);
  EXPECT_EQ(norm(model.particles.velocity[1]), 0.0);
  EXPECT_EQ(norm(model.particles.angular_velocity[1]), 0.0);
  EXPECT_NEAR(model.energies().dissipated, free_part, 1e-12 * free_part);
}

TEST(SpringBond, ForceAndEnergyClosedForm) {
  ParticleSet p;
  p.add({0, 0, 0}, 1.0, 1.0);
  p.add({1, 1, 0}, 1.0, 1.0);
  SpringBondSet spring(250.0);
  spring.add(0, 1, p);
  spring.finalize(2);
  p.position[1] = {1.3, 1.4, 0.0};
  p.clear_forces();
  spring.accumulate_forces(p, {});
  const double L = std::hypot(1.3, 1.4), L0 = std::sqrt(2.0);
  expect_relative(norm(p.force[1]), 250.0 * (L - L0));
  expect_relative(dot(p.force[1], Vec3{1.3, 1.4, 0} / L), -250.0 * (L - L0));
  expect_relative(spring.energy(p), 0.5 * 250.0 * (L - L0) * (L - L0));
}

}  // namespace
}  // namespace arlequin::dem
