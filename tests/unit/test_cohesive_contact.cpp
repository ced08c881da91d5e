// SPDX-License-Identifier: GPL-3.0-or-later
// The bilinear cohesive contact on two DEs against its closed forms (docs/theory.md#cohesive-contact):
// the bilinear traction-opening curve in mode I and mode II, the quadratic onset and the
// Benzeggagh-Kenane toughness along a fixed mixed path, the energy dissipated per unit area at
// failure (G_I, G_II, G_c(B)) to 1e-6, unloading and reloading on the damaged stiffness, no
// energy created over a load-unload cycle, compression as a penalty contact, no opening from a
// rigid rotation of the pair, and a pre-cracked link that carries nothing. Also the crack's tip,
// damage front and dissipated energy measured on a row of links opened by known amounts.
#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <memory>
#include <cmath>
#include <numbers>

#include "common/quat.hpp"
#include "dem/bonds/cohesive_contact.hpp"
#include "dem/crack_front.hpp"

namespace arlequin::dem {
namespace {

// Two unit DEs L apart along x, one link (contact point midway). L is large against the
// openings so that the line of centres barely turns: a shear opening s turns it by s / L, which
// moves s^2 / L into the normal opening (2e-7 of it at the largest mixed opening used here);
// the geometry is checked apart (ARigidRotationOfThePairOpensNothing).
constexpr double sigma_n = 10.0, sigma_s = 15.0;  // Pa
constexpr double G_I = 5e-3, G_II = 7.5e-3;       // J/m^2
constexpr double k = 1e6;                         // Pa/m
constexpr double L = 2000.0;                      // m
constexpr double S = std::numbers::pi;            // R = 1
constexpr double dn0 = sigma_n / k, dnf = 2 * G_I / sigma_n;  // 1e-5, 1e-3 m
constexpr double ds0 = sigma_s / k, dsf = 2 * G_II / sigma_s; // 1.5e-5, 1e-3 m

ForceScan criterion_scan() {
  ForceScan scan;
  scan.criterion = true;
  return scan;
}

struct CohesivePair : ::testing::Test {
  ParticleSet p;
  std::unique_ptr<CohesiveContactSet> link;
  double eta = 2.0;

  void make(std::optional<Region> precrack = std::nullopt) {
    p.add({0, 0, 0}, 1.0, 1.0);
    p.add({L, 0, 0}, 1.0, 1.0);
    CohesiveContactSet::Parameters q;
    q.strength_normal = sigma_n;
    q.strength_shear = sigma_s;
    q.toughness_I = G_I;
    q.toughness_II = G_II;
    q.stiffness = k;
    q.bk_exponent = eta;
    q.precrack = precrack;
    link = std::make_unique<CohesiveContactSet>(q);
    link->add(0, 1, p);
    link->finalize(2);
  }
  void SetUp() override { make(); }
  // DE 1 moved by u from its reference; a force pass (which keeps the history); the force on DE 1.
  Vec3 pull(const Vec3& u) {
    p.position[1] = Vec3{L, 0, 0} + u;
    p.clear_forces();
    link->accumulate_forces(p, criterion_scan());
    return p.force[1];
  }
  double dissipated() const { return link->dissipated_values()[0]; }
  double damage() const { return link->damage_values()[0]; }
  // The failure event of the link in its present state (the test fails unless there is one).
  BreakEvent failure() const {
    std::vector<BreakEvent> events;
    link->find_failures(p, 0, 0.0, events);
    EXPECT_EQ(events.size(), 1u);
    return events.empty() ? BreakEvent{} : events[0];
  }
};

// Bilinear envelope of one mode: traction at opening u, Pa.
double envelope(double u, double d0, double df, double sigma) {
  return u <= d0 ? sigma * u / d0 : u >= df ? 0.0 : sigma * (df - u) / (df - d0);
}

TEST_F(CohesivePair, ModeIFollowsTheBilinearCurveAndDissipatesGI) {
  for (int step = 1; step <= 1100; ++step) {
    const double u = step * dnf / 1000;
    const Vec3 f = pull({u, 0, 0});
    ASSERT_NEAR(-f.x / S, envelope(u, dn0, dnf, sigma_n), 1e-6 * sigma_n) << "u = " << u;
    ASSERT_NEAR(f.y, 0.0, 1e-12);
  }
  EXPECT_EQ(damage(), 1.0);
  EXPECT_NEAR(dissipated() / S, G_I, 1e-6 * G_I);
  const BreakEvent event = failure();
  EXPECT_EQ(event.criterion, FailureCriterion::cohesive);
  EXPECT_EQ(event.mode, FailureMode::tension);
  EXPECT_NEAR(event.energy / S, G_I, 1e-6 * G_I);
  EXPECT_NEAR(event.mode_mix, 0.0, 1e-12);
}

TEST_F(CohesivePair, ModeIIFollowsTheBilinearCurveAndDissipatesGII) {
  for (int step = 1; step <= 1100; ++step) {
    const double s = step * dsf / 1000;
    const Vec3 f = pull({0, s, 0});
    // The traction is along -u (the force keeps the opening's direction): its magnitude.
    ASSERT_NEAR(norm(f) / S, envelope(s, ds0, dsf, sigma_s), 2e-6 * sigma_s) << "s = " << s;
  }
  EXPECT_EQ(damage(), 1.0);
  EXPECT_NEAR(dissipated() / S, G_II, 1e-6 * G_II);
  const BreakEvent event = failure();
  EXPECT_EQ(event.mode, FailureMode::shear);
  EXPECT_NEAR(event.mode_mix, 1.0, 1e-6);
}

// A fixed mix: opening u (cos psi, sin psi, 0). beta = tan psi; quadratic onset
// lambda_0 = dn0 ds0 sqrt((1 + beta^2) / (ds0^2 + beta^2 dn0^2)); B = sin^2 psi;
// G_c = G_I + (G_II - G_I) B^eta (Camanho and Davila 2002).
TEST_F(CohesivePair, AFixedMixedPathStartsOnTheQuadraticCriterionAndDissipatesTheBKToughness) {
  const double psi = 0.6, beta = std::tan(psi), B = std::sin(psi) * std::sin(psi);
  const double lambda0 = dn0 * ds0 * std::sqrt((1 + beta * beta) / (ds0 * ds0 + beta * beta * dn0 * dn0));
  const double Gc = G_I + (G_II - G_I) * std::pow(B, eta);
  const double lambda_f = 2 * Gc / (k * lambda0);
  const Vec3 direction{std::cos(psi), std::sin(psi), 0};
  // At the onset the undamaged tractions meet the quadratic criterion.
  Vec3 f = pull(direction * (lambda0 * (1 - 1e-6)));
  EXPECT_EQ(damage(), 0.0);
  const double tn = -f.x / S, ts = -f.y / S;
  EXPECT_NEAR(tn * tn / (sigma_n * sigma_n) + ts * ts / (sigma_s * sigma_s), 1.0, 1e-5);
  pull(direction * (lambda0 * (1 + 1e-3)));
  EXPECT_GT(damage(), 0.0);
  p = ParticleSet{};  // a fresh link for the whole curve
  make();
  for (int step = 1; step <= 1100; ++step) {
    const double lambda = step * lambda_f / 1000;
    f = pull(direction * lambda);
    ASSERT_NEAR(norm(f) / S, envelope(lambda, lambda0, lambda_f, k * lambda0), 2e-6 * k * lambda0) << lambda;
  }
  EXPECT_EQ(damage(), 1.0);
  EXPECT_NEAR(dissipated() / S, Gc, 1e-6 * Gc);
}

TEST_F(CohesivePair, UnloadingAndReloadingFollowTheDamagedStiffness) {
  const double peak = 0.5 * (dn0 + dnf);
  const Vec3 at_peak = pull({peak, 0, 0});
  const double d = damage();
  EXPECT_NEAR(d, dnf * (peak - dn0) / (peak * (dnf - dn0)), 1e-12);
  for (double u : {0.75 * peak, 0.25 * peak, 0.0, 0.5 * peak, peak}) {
    const Vec3 f = pull({u, 0, 0});
    EXPECT_NEAR(-f.x, (1 - d) * k * S * u, 1e-9 * k * S * peak) << "u = " << u;
    EXPECT_EQ(damage(), d);
  }
  EXPECT_NEAR(pull({peak, 0, 0}).x, at_peak.x, 1e-12 * std::abs(at_peak.x));
  // Beyond the peak the softening goes on along the envelope.
  const double further = 0.75 * dnf;
  EXPECT_NEAR(-pull({further, 0, 0}).x / S, envelope(further, dn0, dnf, sigma_n), 1e-9 * sigma_n);
}

// Work done on the link (trapezoids on a piecewise-linear force, with a node on every kink,
// hence exact) equals its elastic energy plus what it dissipated, at every step of a cycle that
// loads into softening, unloads to zero, reloads, and unloads again: nothing is created.
TEST_F(CohesivePair, NoEnergyIsCreatedOverALoadUnloadCycle) {
  std::vector<double> path;
  const double h = dn0 / 8;
  for (double u = 0; u < 40 * dn0; u += h) path.push_back(u);   // into softening
  for (double u = 40 * dn0; u > 0; u -= h) path.push_back(u);   // unload
  for (double u = 0; u < 60 * dn0; u += h) path.push_back(u);   // reload past the last peak
  for (double u = 60 * dn0; u >= 0; u -= h) path.push_back(u);  // unload
  double work = 0.0, u_prev = 0.0, f_prev = 0.0;
  for (double u : path) {
    const double f = -pull({u, 0, 0}).x;
    work += 0.5 * (f + f_prev) * (u - u_prev);
    u_prev = u, f_prev = f;
    const double elastic = link->energy(p);
    ASSERT_NEAR(work, elastic + dissipated(), 1e-9 * G_I * S) << "u = " << u;
  }
  EXPECT_NEAR(link->energy(p), 0.0, 1e-15);
  EXPECT_GT(dissipated(), 0.0);
}

TEST_F(CohesivePair, CompressionIsAPenaltyContactEvenWhenDamaged) {
  // Positions of size L carry a round-off of L eps, 1e-7 of the opening here.
  const double u = -0.5 * dn0;
  EXPECT_NEAR(-pull({u, 0, 0}).x, k * S * u, 1e-7 * k * S * dn0);  // pushes DE 1 back out
  pull({0.5 * (dn0 + dnf), 0, 0});  // damage it
  ASSERT_GT(damage(), 0.5);
  EXPECT_NEAR(-pull({u, 0, 0}).x, k * S * u, 1e-7 * k * S * dn0);
}

// Turning the whole pair (centres and orientations) by 30 degrees about z opens nothing.
TEST_F(CohesivePair, ARigidRotationOfThePairOpensNothing) {
  const Quat q = from_rotation_vector({0, 0, std::numbers::pi / 6});
  p.orientation[0] = p.orientation[1] = q;
  p.position[1] = rotate(q, Vec3{L, 0, 0});
  p.clear_forces();
  link->accumulate_forces(p, criterion_scan());
  EXPECT_EQ(damage(), 0.0);  // not a link that failed and so carries nothing
  EXPECT_LT(norm(p.force[1]), 1e-12 * sigma_n * S);
  EXPECT_LT(norm(p.torque[1]), 1e-12 * sigma_n * S);
}

TEST_F(CohesivePair, APrecrackedLinkCarriesNoTension) {
  p = ParticleSet{};
  make(Region(Box{{0.5 * L - 1, -1, -1}, {0.5 * L + 1, 1, 1}}));
  EXPECT_EQ(link->broken()[0], 1);
  EXPECT_EQ(damage(), 1.0);
  EXPECT_EQ(norm(pull({0.5 * dnf, 0, 0})), 0.0);
  EXPECT_EQ(link->energy(p), 0.0);
}

// Twenty links, each between its own two DEs 2 m apart (no shared DE: one colour, so blocks of
// eight hold every state side by side): opened below the onset, into softening and past failure,
// sheared, mixed, compressed, pre-cracked, with turned DEs. A force pass evaluates them eight at
// a time; each link's actions, damage, dissipation and energy are those of the same link
// evaluated alone (count 1, the other lanes idle), to the bit: a block's lanes never mix.
TEST(CohesiveBlocks, ALinkInABlockActsAsTheLinkAlone) {
  constexpr int links = 20;
  const std::array<Vec3, 6> openings = {Vec3{0.5 * dn0, 0, 0},  Vec3{3 * dn0, 0, 0},       Vec3{2 * dnf, 0, 0},
                                        Vec3{0, 0, 3 * ds0},    Vec3{2 * dn0, 2 * ds0, 0}, Vec3{-0.5 * dn0, 0, 0}};
  const auto build = [&](ParticleSet& p) {
    CohesiveContactSet::Parameters q{sigma_n, sigma_s, G_I, G_II, k, 2.0, Region(Box{{0.5, 69, -1}, {1.5, 71, 1}}), 0.0};
    auto set = std::make_unique<CohesiveContactSet>(q);  // the link at y = 70 m starts failed
    for (int m = 0; m < links; ++m) {
      p.add({0, 10.0 * m, 0}, 1.0, 1.0);
      p.add({2, 10.0 * m, 0}, 1.0, 1.0);
      set->add(2 * m, 2 * m + 1, p);
    }
    set->finalize(p.size());
    for (int m = 0; m < links; ++m) {
      p.position[2 * m + 1] += openings[m % openings.size()];
      if (m % 3 == 1) p.orientation[2 * m] = from_rotation_vector({1e-5 * m, 0, -2e-6});
    }
    return set;
  };
  ParticleSet blocks, alone;
  const auto in_blocks = build(blocks), single = build(alone);
  ASSERT_EQ(in_blocks->colours(), 1u);
  ForceScan scan = criterion_scan();
  scan.energy = true;
  blocks.clear_forces();
  in_blocks->accumulate_forces(blocks, scan);
  int elastic = 0, softening = 0, failed = 0, pushed = 0;
  for (int m = 0; m < links; ++m) {
    const auto e = single->evaluate(m, alone);
    const std::uint32_t i = single->first()[m], j = single->second()[m];
    EXPECT_EQ(blocks.force[j], e.force_on_j) << m;
    EXPECT_EQ(blocks.force[i], -e.force_on_j) << m;
    EXPECT_EQ(blocks.torque[i], e.torque_on_i) << m;
    EXPECT_EQ(blocks.torque[j], e.torque_on_j) << m;
    EXPECT_EQ(in_blocks->damage_values()[m], e.damage) << m;
    EXPECT_EQ(in_blocks->dissipated_values()[m], e.dissipation) << m;
    EXPECT_EQ(in_blocks->recorded_energies()[m], e.elastic) << m;
    elastic += e.damage == 0.0;
    softening += e.damage > 0.0 && e.damage < 1.0;
    failed += e.damage == 1.0;
    pushed += e.force_on_j.x > 0.0;
  }
  EXPECT_EQ(elastic, 7);  // the states the openings make, in every block
  EXPECT_EQ(softening, 9);
  EXPECT_EQ(failed, 4);
  EXPECT_EQ(pushed, 3);
}

// The force pass passes over a block whose eight links have all failed (a delamination's wake):
// 24 links between their own DEs, one colour, in three blocks: pre-cracked; opened past failure
// (d = 1 after the first pass, failed only once find_failures has seen them); below the onset.
// After a plain pass and a scanning pass, the failed block's DEs have no force, its links keep
// their damage and dissipate nothing, and the second block, at d = 1 but not yet failed, is still
// evaluated: its eight failures are reported (a skip that went by the damage, not by the failed
// flag, would report none); every DE's actions are those of its link evaluated alone.
TEST(CohesiveBlocks, AWholeBlockOfFailedLinksIsPassedOver) {
  constexpr int links = 24;
  CohesiveContactSet::Parameters q{sigma_n, sigma_s, G_I, G_II, k, 2.0, Region(Box{{0.5, -1, -1}, {1.5, 75, 1}}), 0.0};
  const auto build = [&](ParticleSet& p) {
    auto set = std::make_unique<CohesiveContactSet>(q);  // the links at y = 0 .. 70 m start failed
    for (int m = 0; m < links; ++m) {
      p.add({0, 10.0 * m, 0}, 1.0, 1.0);
      p.add({2, 10.0 * m, 0}, 1.0, 1.0);
      set->add(2 * m, 2 * m + 1, p);
    }
    set->finalize(p.size());
    for (int m = 0; m < links; ++m) p.position[2 * m + 1] += Vec3{m < 16 ? 2 * dnf : 0.5 * dn0, 0, 0};
    return set;
  };
  ParticleSet blocks, alone;
  const auto set = build(blocks), single = build(alone);
  ASSERT_EQ(set->colours(), 1u);
  for (int m = 0; m < links; ++m) ASSERT_EQ(set->first()[m], std::uint32_t(2 * m));  // blocks of eight in this order
  blocks.clear_forces();
  set->accumulate_forces(blocks, ForceScan{});
  blocks.clear_forces();
  set->accumulate_forces(blocks, criterion_scan());
  std::vector<BreakEvent> events;
  set->find_failures(blocks, 0, 0.0, events);
  ASSERT_EQ(events.size(), 8u);
  for (int n = 0; n < 8; ++n) EXPECT_EQ(events[n].bond, std::uint32_t(8 + n));
  for (int m = 0; m < links; ++m) {
    const auto e = single->evaluate(m, alone);  // its stored damage is 0 but for the pre-cracked
    EXPECT_EQ(blocks.force[2 * m + 1], e.force_on_j) << m;
    EXPECT_EQ(blocks.torque[2 * m], e.torque_on_i) << m;
    if (m < 8) {
      EXPECT_EQ(blocks.force[2 * m + 1], Vec3{}) << m;
      EXPECT_EQ(set->damage_values()[m], 1.0) << m;
      EXPECT_EQ(set->dissipated_values()[m], 0.0) << m;
    } else if (m < 16) {
      EXPECT_EQ(set->damage_values()[m], 1.0) << m;
      EXPECT_NEAR(set->dissipated_values()[m], G_I * S, 1e-9 * G_I * S) << m;  // in the first pass, once
    } else {
      EXPECT_EQ(set->damage_values()[m], 0.0) << m;
    }
  }
}

TEST(CohesiveParameters, AreRefusedWhenTheSofteningOpeningIsNotBeyondTheElasticOne) {
  CohesiveContactSet::Parameters q{sigma_n, sigma_s, G_I, G_II, k, 2.0, std::nullopt, 0.0};
  EXPECT_NO_THROW(CohesiveContactSet{q});
  q.stiffness = sigma_n * sigma_n / (2 * G_I) * 0.99;  // u_p^n just below sigma / k
  try {
    CohesiveContactSet{q};
    FAIL() << "accepted u_p below the elastic opening";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("G_I: ", 0), 0u) << e.what();
  }
  q.stiffness = k;
  q.toughness_I = 0.0;
  EXPECT_THROW(CohesiveContactSet{q}, std::invalid_argument);
}

// covered_area on closed forms: a flat interface of 20 x 10 links on a square lattice of spacing
// s covers 200 s^2 (each link its square); the hull of the contact points (19 x 9 s^2) widened
// by half the spacing gives 197.6 s^2, -1.2 %. Turned in space, the same. Links on a cylinder
// (not one plane) and fewer than three links give 0.
TEST(CohesiveArea, TheLinksCoverTheirLatticeCells) {
  const double s = 2.0e-4, R = 0.5 * s;  // the DEs touch across the interface and along it
  const auto lattice = [&](const std::function<Vec3(double, double, double)>& place) {
    ParticleSet p;
    CohesiveContactSet::Parameters q;
    q.strength_normal = q.strength_shear = 1e6;
    q.toughness_I = q.toughness_II = 100;
    q.stiffness = 1e15;
    auto set = std::make_unique<CohesiveContactSet>(q);
    for (int i = 0; i < 20; ++i)
      for (int j = 0; j < 10; ++j) {
        p.add(place(i * s, j * s, -R), R, 1000);
        p.add(place(i * s, j * s, R), R, 1000);
        set->add(static_cast<std::uint32_t>(p.size() - 2), static_cast<std::uint32_t>(p.size() - 1), p);
      }
    return set->covered_area(p) / (200 * s * s);
  };
  const double flat = lattice([](double x, double y, double z) { return Vec3{x, y, z}; });
  EXPECT_NEAR(flat, 197.6 / 200, 0.001);
  // Turned about (1, 2, 3) by 0.7 rad and moved.
  const Vec3 axis = normalized(Vec3{1, 2, 3});
  const Quat turn{std::cos(0.35), std::sin(0.35) * axis};
  EXPECT_NEAR(lattice([&](double x, double y, double z) { return Vec3{0.1, -0.2, 0.3} + rotate(turn, Vec3{x, y, z}); }), flat, 1e-9);
  // Wrapped around a cylinder of radius 1 mm about x: the contact points leave the plane.
  EXPECT_EQ(lattice([](double x, double y, double z) {
              const double a = y / 1e-3, r = 1e-3 + z;
              return Vec3{x, r * std::sin(a), r * std::cos(a)};
            }),
            0.0);
}

// A row of ten links along x (DEs of radius 1 at x = 2k, z = 0 and z = 2), each opened along z
// by its own u_k in one pass: three beyond u_f (failed), then 5e-4, 1e-4 and 1.5e-5 m (damage
// 0.99, 0.91 and 0.34 by d = u_f (u - u_0) / (u (u_f - u_0))), then 5e-6 m, below u_0 (none).
// The tip is the last failed link (x = 4), the damage front the last damaged one (x = 10); the
// energy dissipated is G_I S (u_k - u_0) / (u_f - u_0) a link, G_I S once failed (the bilinear
// law's area up to the largest opening).
TEST(CrackFront, TipIsTheLastFailedLinkAndTheFrontTheLastDamagedOne) {
  const double openings[10] = {2e-3, 2e-3, 2e-3, 5e-4, 1e-4, 1.5e-5, 5e-6, 5e-6, 5e-6, 5e-6};
  ParticleSet p;
  CohesiveContactSet::Parameters q;
  q.strength_normal = q.strength_shear = sigma_n;
  q.toughness_I = q.toughness_II = G_I;
  q.stiffness = k;
  CohesiveContactSet row(q);
  for (int i = 0; i < 10; ++i) {
    p.add({2.0 * i, 0, 0}, 1.0, 1.0);
    p.add({2.0 * i, 0, 2.0}, 1.0, 1.0);
    row.add(2 * i, 2 * i + 1, p);
  }
  row.finalize(p.size());
  double expected = 0.0;
  for (int i = 0; i < 10; ++i) {
    p.position[2 * i + 1].z += openings[i];
    expected += G_I * S * std::clamp((openings[i] - dn0) / (dnf - dn0), 0.0, 1.0);
  }
  p.clear_forces();
  row.accumulate_forces(p, criterion_scan());
  EXPECT_NEAR(row.damage_values()[4], 0.909, 1e-3);  // the case is the one described
  EXPECT_NEAR(row.damage_values()[5], 0.337, 1e-3);
  const CrackFront crack = measure_crack(row, p, {1, 0, 0}, {0, 1, 0}, 1);
  EXPECT_DOUBLE_EQ(crack.tip, 4.0);
  EXPECT_DOUBLE_EQ(crack.damage_front, 10.0);
  EXPECT_NEAR(crack.dissipated, expected, 1e-9 * expected);
}

}  // namespace
}  // namespace arlequin::dem
