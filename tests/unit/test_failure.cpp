// SPDX-License-Identifier: GPL-3.0-or-later
// Bond failure against closed forms: BBF thresholds in pure tension and pure bending, the mode a
// break reports (torsion, and shear where a pair is closer than half its beam radius), springs at
// their maximum elongation, no force after a break, the RDEF virial stress of a uniformly
// strained lattice, the largest principal and von Mises stresses of rotated principal values,
// RDEF breaking every bond of a DE, its average weighted by the DEs' volumes, and contact
// between former partners.
// Also: RDEF's shortcut threshold test against the full eigenvalue, the force pass that
// records the failure measures and energies giving the same bits on 1 and 2 threads, and the
// output rows' energies read from that record.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <random>

#include "dem/contacts/penalty_contact.hpp"
#include "dem/bonds/spring_bond.hpp"
#include "support/dem_fixtures.hpp"
#include "support/omp_threads.hpp"

namespace arlequin::dem {
namespace {

// A force pass that records the failure measures, as a breakable step's does.
ForceScan criterion_scan() {
  ForceScan scan;
  scan.criterion = true;
  return scan;
}

using test::R1Beam;

// The failures one beam set reports after a force pass with the failure scan, as in a step.
std::vector<BreakEvent> failures_of(BeamBondSet& beam, ParticleSet& p) {
  p.clear_forces();
  beam.accumulate_forces(p, criterion_scan());
  std::vector<BreakEvent> events;
  beam.find_failures(p, 0, 0.0, events);
  return events;
}

struct BreakablePair : ::testing::Test {
  static constexpr double sigma_f = 200.0;  // N/mm^2 (R1 units)
  ParticleSet p;
  BeamBondSet beam{{R1Beam::E, R1Beam::nu, R1Beam::r_mu, sigma_f}};
  void SetUp() override {
    p.add({0, 0, 0}, R1Beam::R, 1.0);
    p.add({R1Beam::L, 0, 0}, R1Beam::R, 1.0);
    beam.add(0, 1, p);
    beam.finalize(2);
  }
  std::vector<BreakEvent> failures() { return failures_of(beam, p); }
};

TEST_F(BreakablePair, BreaksExactlyAtTheThresholdInPureTension) {
  // N / S = E (L - L0) / L0 = sigma_f at L - L0 = sigma_f L0 / E.
  const double critical = sigma_f * R1Beam::L / R1Beam::E;
  p.position[1].x = R1Beam::L + critical * (1.0 - 1e-9);
  EXPECT_TRUE(failures().empty());
  p.position[1].x = R1Beam::L + critical * (1.0 + 1e-9);
  const auto events = failures();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].mode, FailureMode::tension);
  EXPECT_NEAR(events[0].stress, sigma_f, 1e-6 * sigma_f);
  // Its energy is the axial spring's: E S / L0 (dL)^2 / 2.
  EXPECT_NEAR(events[0].energy, 0.5 * R1Beam::E * R1Beam::S / R1Beam::L * critical * critical, 1e-6 * events[0].energy);
}

TEST_F(BreakablePair, BreaksExactlyAtTheThresholdInPureBending) {
  // DE i turned by t, j fixed: M_a = 2EI/L (2t), r_b M_a / I = 4 E r_b t / L = sigma_f.
  const double critical = sigma_f * R1Beam::L / (4.0 * R1Beam::E * R1Beam::rb);
  p.orientation[0] = from_rotation_vector({0, 0, critical * (1.0 - 1e-9)});
  EXPECT_TRUE(failures().empty());
  p.orientation[0] = from_rotation_vector({0, 0, critical * (1.0 + 1e-9)});
  const auto events = failures();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].mode, FailureMode::bending);
}

// The mode a break reports is its largest stress (beam_bond.hpp): |N/S|, r_b |M| / I, the shear
// stress V/S = 1.5 E r_b^2 |theta_a + theta_b| / L0^2 and the torsion stress G r_b |phi| / L0.
TEST_F(BreakablePair, ReportsTheLargestStressAsItsMode) {
  // Stretched just past the threshold (N / S = sigma_f, the criterion's only term here) and
  // twisted by phi with G r_b phi / L0 = 1.5 sigma_f: torsion.
  p.position[1].x = R1Beam::L * (1.0 + sigma_f / R1Beam::E * (1.0 + 1e-9));
  p.orientation[1] = from_rotation_vector({1.5 * sigma_f * R1Beam::L / (R1Beam::G * R1Beam::rb), 0.0, 0.0});
  const auto twisted = failures();
  ASSERT_EQ(twisted.size(), 1u);
  EXPECT_EQ(twisted[0].mode, FailureMode::torsion);
}

// Shear exceeds bending only where r_b > 2 L0: with both ends' rotations locked and DE j moved
// sideways, theta_a = theta_b = theta, bending 6 E r_b |theta| / L0 and shear 3 E r_b^2 |theta| / L0^2.
// A pair 0.4 R apart with r_mu = 1.9 (r_b / (2 L0) = 2.375), bent to twice the threshold: shear.
TEST(BeamFailureMode, ShearDominatesAPairCloserThanHalfItsBeamRadius) {
  constexpr double sigma_f = 200.0, L0 = 0.4;
  ParticleSet p;
  p.add({0, 0, 0}, R1Beam::R, 1.0);
  p.add({L0, 0, 0}, R1Beam::R, 1.0);
  BeamBondSet beam{{R1Beam::E, R1Beam::nu, 1.9, sigma_f}};
  beam.add(0, 1, p);
  beam.finalize(2);
  const double theta = 2.0 * sigma_f * L0 / (6.0 * R1Beam::E * 1.9 * R1Beam::R);
  p.position[1].y = L0 * std::tan(theta);
  const auto events = failures_of(beam, p);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].mode, FailureMode::shear);
}

TEST_F(BreakablePair, ABrokenBondCarriesNoForce) {
  p.position[1] = {R1Beam::L + 0.01, 0.02, -0.01};
  p.orientation[0] = from_rotation_vector({0.01, 0.0, 0.02});
  beam.break_bond(0);
  p.clear_forces();
  beam.accumulate_forces(p, {});
  EXPECT_EQ(norm(p.force[0]) + norm(p.force[1]) + norm(p.torque[0]) + norm(p.torque[1]), 0.0);
  EXPECT_EQ(beam.energy(p), 0.0);
  EXPECT_TRUE(failures().empty());  // broken once, never reported again
}

TEST(SpringFailure, BreaksAtTheMaximumElongation) {
  ParticleSet p;
  p.add({0, 0, 0}, 1.0, 1.0);
  p.add({2, 0, 0}, 1.0, 1.0);
  SpringBondSet spring(100.0, 0.05);
  spring.add(0, 1, p);
  spring.finalize(2);
  std::vector<BreakEvent> events;
  p.position[1].x = 2.0 * (1.05 - 1e-9);
  spring.accumulate_forces(p, criterion_scan());
  spring.find_failures(p, 0, 0.0, events);
  EXPECT_TRUE(events.empty());
  p.position[1].x = 2.0 * (1.05 + 1e-9);
  spring.accumulate_forces(p, criterion_scan());
  spring.find_failures(p, 0, 0.0, events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].criterion, FailureCriterion::elongation);
}

// A simple-cubic lattice (spacing a, compaction pi/6) stretched uniformly by eps along x: each
// x-bond carries N = E S eps, so the applied stress is sigma_xx = N / a^2 and the other
// components vanish. The virial stress of an interior DE, (1/V) sum of r (x) f over its bonds with
// V = a^3 (its sphere over the compaction) and r the stretched arm a (1 + eps), is that stress
// times (1 + eps), exactly (to round-off).
TEST(VirialStress, EqualsTheAppliedStressInAUniformlyStrainedLattice) {
  DemModel model;
  const double R = 1e-3, a = 2 * R, eps = 1e-4, E = 2e11;
  build_lattice(model.particles, {0, 0, 0}, {5, 5, 5}, a, R, 7800.0);
  test::bond_all_touching(model, {E, 0.3, 0.5});
  model.finalize();
  for (auto& x : model.particles.position) x.x *= 1.0 + eps;
  const auto sigma = model.virial_stress(std::numbers::pi / 6.0);
  const double S = std::numbers::pi * 0.25 * R * R;
  const double applied = E * S * eps / (a * a);
  const std::size_t centre = 2 + 5 * (2 + 5 * 2);
  EXPECT_NEAR(sigma[centre][0], applied * (1.0 + eps), 1e-12 * applied);
  for (int c = 1; c < 6; ++c) EXPECT_NEAR(sigma[centre][c], 0.0, 1e-9 * applied);
  EXPECT_NEAR(max_principal(sigma[centre]), sigma[centre][0], 1e-9 * applied);
  // Uniaxial: von Mises equals the axial stress, the hydrostatic stress a third of it.
  EXPECT_NEAR(equivalent_stress(sigma[centre], RdefEquivalent::von_mises), sigma[centre][0], 1e-9 * applied);
  EXPECT_NEAR(equivalent_stress(sigma[centre], RdefEquivalent::hydrostatic), sigma[centre][0] / 3.0, 1e-9 * applied);
}

// The largest principal stress and the von Mises stress of R diag(s1, s2, s3) R^T are those of
// diag(s1, s2, s3): max(s1, s2, s3) and sqrt(((s1 - s2)^2 + (s2 - s3)^2 + (s3 - s1)^2) / 2)
// (invariance under rotation), over random rotations and principal values, distinct, two equal
// and all three equal. A pure shear tau gives tau and sqrt(3) tau. Bounds, relative to the
// largest |s|, about ten times the errors measured (5.8e-14, 1.3e-8, 2.7e-15): the largest
// eigenvalue 1e-12 where the three differ, 1e-7 where two meet (the cosine form loses digits
// there: acos near +-1, an error of about sqrt(ulp)); von Mises, a root of a sum of squares, 3e-14.
TEST(EquivalentStress, PrincipalAndVonMisesAreThoseOfTheRotatedPrincipalValues) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  double worst_principal[2] = {0.0, 0.0}, worst_mises = 0.0;  // [two or three equal]
  for (int n = 0; n < 3000; ++n) {
    std::array<double, 3> s{uni(rng), uni(rng), uni(rng)};
    const bool meet = n % 3 == 1 || n % 30 == 2;
    if (n % 3 == 1) s[2] = s[n % 2];
    if (n % 30 == 2) s[1] = s[2] = s[0];
    const Quat q = from_rotation_vector(Vec3{uni(rng), uni(rng), uni(rng)} * 3.0);
    const Vec3 e[3] = {rotate(q, Vec3{1, 0, 0}), rotate(q, Vec3{0, 1, 0}), rotate(q, Vec3{0, 0, 1})};
    Sym3 t{};  // sum_k s_k e_k (x) e_k, Voigt order xx, yy, zz, yz, xz, xy
    for (int k = 0; k < 3; ++k) {
      const Vec3& a = e[k];
      const Sym3 ek{a.x * a.x, a.y * a.y, a.z * a.z, a.y * a.z, a.x * a.z, a.x * a.y};
      for (int c = 0; c < 6; ++c) t[c] += s[k] * ek[c];
    }
    const double scale = std::max({std::abs(s[0]), std::abs(s[1]), std::abs(s[2])});
    const double mises = std::sqrt(0.5 * ((s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) + (s[2] - s[0]) * (s[2] - s[0])));
    double& worst = worst_principal[meet];
    worst = std::max(worst, std::abs(max_principal(t) - std::max({s[0], s[1], s[2]})) / scale);
    worst_mises = std::max(worst_mises, std::abs(von_mises(t) - mises) / scale);
  }
  EXPECT_LT(worst_principal[0], 1e-12);
  EXPECT_LT(worst_principal[1], 1e-7);
  EXPECT_LT(worst_mises, 3e-14);
  const double tau = 3.0;
  for (int c = 3; c < 6; ++c) {
    Sym3 shear{};
    shear[c] = tau;
    EXPECT_NEAR(max_principal(shear), tau, 1e-15 * tau);
    EXPECT_NEAR(von_mises(shear), std::sqrt(3.0) * tau, 1e-15 * tau);
  }
}

// The threshold test of RDEF decides as equivalent_stress does, bit for bit, with or without
// the shortcut: random tensors and rotated diag(a, b, b) ones (where the bound q + 2p equals
// the largest eigenvalue), thresholds at the value, at the bound and one ulp either side.
TEST(Rdef, ThresholdTestMatchesTheEquivalentStressExactly) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const auto rotated_diagonal = [&] {  // R diag(a, b, b) R^T, R from a random rotation vector
    const double a = uni(rng), b = uni(rng);
    const Quat q = from_rotation_vector(Vec3{uni(rng), uni(rng), uni(rng)} * 3.0);
    const Vec3 e = rotate(q, Vec3{1, 0, 0});
    // a e e^T + b (I - e e^T)
    return Sym3{b + (a - b) * e.x * e.x, b + (a - b) * e.y * e.y, b + (a - b) * e.z * e.z,
                (a - b) * e.x * e.y,     (a - b) * e.y * e.z,     (a - b) * e.x * e.z};
  };
  for (int n = 0; n < 20000; ++n) {
    Sym3 t;
    if (n % 2) {
      t = rotated_diagonal();
    } else {
      for (double& c : t) c = uni(rng);
      if (n % 8 == 0) t[3] = t[4] = t[5] = 0.0;  // diagonal: the other branch
    }
    const double q = (t[0] + t[1] + t[2]) / 3.0;
    const double d0 = t[0] - q, d1 = t[1] - q, d2 = t[2] - q;
    const double bound = q + 2.0 * std::sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5])) / 6.0);
    for (auto kind : {RdefEquivalent::max_principal, RdefEquivalent::von_mises, RdefEquivalent::hydrostatic}) {
      const double e = equivalent_stress(t, kind);
      for (double threshold : {e, std::nextafter(e, 2.0), std::nextafter(e, -2.0), bound, std::nextafter(bound, 2.0),
                               std::nextafter(bound, -2.0), e + 0.5, e - 0.5}) {
        const double expected = e >= threshold ? e : -1.0;
        ASSERT_EQ(equivalent_stress_reaching(t, kind, threshold), expected) << n;
      }
    }
  }
}

// A damped breakable model on a lattice of `counts` DEs: beams with BBF, springs with a
// maximum elongation on the same pairs, and RDEF on Laguerre cells (radical branch), started
// from random velocities that break bonds by every criterion within 40 steps. Returns the step.
double build_breakable_model(DemModel& model, std::array<int, 3> counts) {
  const double R = 1e-3, a = 2 * R;
  build_lattice(model.particles, {0, 0, 0}, counts, a, R, 7800.0);
  test::bond_all_touching(model, {2e11, 0.3, 0.5, 2.5e8});
  auto springs = std::make_unique<SpringBondSet>(1e6, 4e-4);
  for (auto [i, j] : close_pairs(model.particles, 0.01)) springs->add(i, j, model.particles);
  model.add_bond_set(std::move(springs));
  DemModel::RdefSettings rdef;
  rdef.threshold = 1.0e7;
  rdef.volume = RdefVolume::laguerre;
  model.enable_rdef(rdef);
  model.set_damping(0.05);
  model.finalize();
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (auto& v : model.particles.velocity) v = Vec3{uni(rng), uni(rng), uni(rng)} * 2.0;  // m/s
  return 0.5 * model.critical_time_step();
}

// Moves every DE by up to 2e-3 of `spacing` (m) along each axis and turns it by up to 2e-3 rad
// about each axis, at random (seed 3): bonds loaded in every mode.
void perturb(ParticleSet& p, double spacing) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.position[i] += Vec3{uni(rng), uni(rng), uni(rng)} * (2e-3 * spacing);
    p.orientation[i] = from_rotation_vector(Vec3{uni(rng), uni(rng), uni(rng)} * 2e-3);
  }
}

// Output rows read the bonds' energies that the step's force pass recorded (on request): the
// same bits as a bond pass of their own, also in steps where bonds break (the forces and the
// record are then taken again without them); steps without the request evaluate the bonds.
TEST(ForceScan, RecordedEnergiesAreThoseOfABondPass) {
  DemModel recorded, evaluated;
  const double dt = build_breakable_model(recorded, {6, 5, 5});
  build_breakable_model(evaluated, {6, 5, 5});
  constexpr int group = 0;  // every third DE
  for (DemModel* m : {&recorded, &evaluated}) {
    std::vector<std::uint32_t> every_third;
    for (std::uint32_t i = 0; i < m->particles.size(); i += 3) every_third.push_back(i);
    ASSERT_EQ(m->add_group("every_third", every_third), group);
  }
  std::size_t steps_with_breaks = 0;
  for (int n = 0; n < 40; ++n) {
    if (n % 3 != 2) recorded.record_energies_in_next_step();  // every third step: none
    const std::size_t before = recorded.breaks().size();
    recorded.step(dt);
    evaluated.step(dt);
    steps_with_breaks += recorded.breaks().size() > before;
    for (std::size_t i = 0; i < recorded.particles.size(); ++i) {  // recording changes no motion
      ASSERT_EQ(recorded.particles.position[i], evaluated.particles.position[i]) << "step " << n << ", DE " << i;
      ASSERT_EQ(recorded.particles.velocity[i], evaluated.particles.velocity[i]) << "step " << n << ", DE " << i;
    }
    const Energies a = recorded.energies(), b = evaluated.energies();
    ASSERT_EQ(a.bond, b.bond) << "step " << n;
    ASSERT_EQ(a.kinetic, b.kinetic) << "step " << n;
    ASSERT_EQ(recorded.group_energy(group), evaluated.group_energy(group)) << "step " << n;
  }
  EXPECT_GT(steps_with_breaks, 3u);
  // Per bond, the record is bond_energy() (0 for a broken bond).
  for (const auto& set : recorded.bond_sets())
    for (std::size_t b = 0; b < set->size(); ++b) {
      ASSERT_EQ(set->recorded_energies()[b], set->bond_energy(b, recorded.particles)) << b;
      if (set->broken()[b]) {
        ASSERT_EQ(set->recorded_energies()[b], 0.0) << b;
      }
    }
}

// Whatever a force pass records (failure measures, virials, energies), its forces and torques
// are the plain pass's to the bit, for beams and springs: output rows and failure checks leave
// the motion unchanged. (Springs needed their file built without FMA contraction; see
// dem/CMakeLists.txt.)
TEST(ForceScan, RecordingLeavesTheForcesUnchanged) {
  DemModel model;
  build_breakable_model(model, {6, 5, 5});
  ParticleSet& p = model.particles;
  perturb(p, 2e-3);
  std::vector<Sym3> virial(p.size());
  ASSERT_EQ(model.bond_sets().size(), 2u);  // beams and springs
  for (const auto& set : model.bond_sets()) {
    p.clear_forces();
    set->accumulate_forces(p, ForceScan{});
    const std::vector<Vec3> force = p.force, torque = p.torque;
    for (int flags = 1; flags < 8; ++flags) {
      ForceScan scan;
      scan.criterion = flags & 1;
      if (flags & 2) scan.virial = virial;
      scan.energy = flags & 4;
      p.clear_forces();
      set->accumulate_forces(p, scan);
      for (std::size_t i = 0; i < p.size(); ++i) {
        ASSERT_EQ(p.force[i], force[i]) << set->law() << ", scan " << flags << ", DE " << i;
        ASSERT_EQ(p.torque[i], torque[i]) << set->law() << ", scan " << flags << ", DE " << i;
      }
    }
  }
}

// A bond set's colours go on threads with more than parallel_threshold_bonds bonds per colour
// on average, in a scene of more than parallel_threshold_bond_particles DEs.
TEST(BondColouring, ThreadsOnlyForLargeColoursInLargeScenes) {
  const auto chain_on_threads = [](std::uint32_t bonds, std::size_t scene_particles) {
    std::vector<std::uint32_t> first, second;  // a chain: two colours
    for (std::uint32_t i = 0; i < bonds; ++i) first.push_back(i), second.push_back(i + 1);
    BondColouring colouring;
    colouring.build(first, second, scene_particles);
    EXPECT_EQ(colouring.offsets.size(), 3u);
    return colouring.threaded;
  };
  const auto large_colours = static_cast<std::uint32_t>(2 * parallel_threshold_bonds + 1);
  const auto large_scene = static_cast<std::size_t>(parallel_threshold_bond_particles + 1);
  EXPECT_TRUE(chain_on_threads(large_colours, large_scene));
  EXPECT_FALSE(chain_on_threads(large_colours, large_scene - 1));
  EXPECT_FALSE(chain_on_threads(large_colours - 1, 10 * large_scene));
}

// A DE bonded to hundreds of others (a large DE among small ones; a particle table found it):
// every bond at it needs a colour of its own. The colouring had a cap of 64 colours and threw;
// it now colours any degree, and no two bonds at one DE share a colour.
TEST(BondColouring, ColoursAStarOfThreeHundredBondsAndKeepsEachDeSBondsApart) {
  std::vector<std::uint32_t> first, second;
  for (std::uint32_t j = 1; j <= 300; ++j) first.push_back(0), second.push_back(j);  // the star
  for (std::uint32_t j = 1; j < 300; ++j) first.push_back(j), second.push_back(j + 1);  // its rim, a chain
  BondColouring colouring;
  const std::vector<std::uint32_t> order = colouring.build(first, second, 301);
  ASSERT_EQ(order.size(), first.size());
  EXPECT_GE(colouring.offsets.size(), 301u);  // at least one colour per star bond
  EXPECT_LE(colouring.offsets.size(), 2u * 302u);  // greedy: at most 2 d - 1 colours, d = 302
  std::vector<std::vector<std::uint32_t>> colours_at(301);
  for (std::size_t c = 0; c + 1 < colouring.offsets.size(); ++c)
    for (std::uint32_t k = colouring.offsets[c]; k < colouring.offsets[c + 1]; ++k)
      for (std::uint32_t de : {first[order[k]], second[order[k]]}) colours_at[de].push_back(std::uint32_t(c));
  for (auto& colours : colours_at) {
    std::sort(colours.begin(), colours.end());
    EXPECT_EQ(std::adjacent_find(colours.begin(), colours.end()), colours.end());
  }
}

#ifdef _OPENMP
// A force pass that records everything (measures, virials into `virial`, zeroed, and energies),
// on p with its forces cleared.
ForceScan recording_scan(ParticleSet& p, std::vector<Sym3>& virial) {
  virial.assign(p.size(), Sym3{});
  ForceScan scan = criterion_scan();
  scan.virial = virial;
  scan.energy = true;
  p.clear_forces();
  return scan;
}

// The force pass with a failure scan runs the colours' bonds on threads (BondColouring):
// forces, torques, BBF measures and virials are the same to the bit on 1 and 2 threads, and so
// are the failures found.
TEST(ForceScan, ForcesMeasuresAndVirialsAreTheSameOnAnyThreadCount) {
  DemModel model;
  const double R = 1e-3, a = 2 * R;
  build_lattice(model.particles, {0, 0, 0}, {16, 16, 16}, a, R, 7800.0);
  BeamBondSet& beam = test::bond_all_touching(model, {2e11, 0.3, 0.5, 1.0e9});
  model.finalize();
  ParticleSet& p = model.particles;
  perturb(p, a);
  struct Pass {
    std::vector<Vec3> force, torque;
    std::vector<Sym3> virial;
    std::vector<BreakEvent> events;
    std::vector<double> energy;  // per bond
    double total_energy;
  };
  const auto pass = [&](int threads) {
    const test::OmpThreads scope(threads);
    Pass out;
    const ForceScan scan = recording_scan(p, out.virial);
    beam.accumulate_forces(p, scan);
    beam.find_failures(p, 0, 0.0, out.events);
    out.force = p.force;
    out.torque = p.torque;
    out.energy.assign(beam.recorded_energies().begin(), beam.recorded_energies().end());
    out.total_energy = beam.recorded_energy();
    return out;
  };
  const Pass one = pass(1), two = pass(2);
  EXPECT_TRUE(beam.runs_on_threads());
  // The beams gather per DE (BeamBondSet::accumulate_forces): their sums are those of a scatter
  // of each bond's actions, evaluated alone, in bond order from zero, the same additions in the
  // same order at every DE.
  std::vector<Vec3> force(p.size()), torque(p.size());
  for (std::size_t b = 0; b < beam.size(); ++b) {
    const BeamBondSet::Actions actions = beam.actions(b, p);
    const std::uint32_t i = beam.first()[b], j = beam.second()[b];
    force[i] -= actions.force_on_j;
    force[j] += actions.force_on_j;
    torque[i] += actions.torque_on_i;
    torque[j] += actions.torque_on_j;
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_EQ(force[i], one.force[i]) << i;
    ASSERT_EQ(torque[i], one.torque[i]) << i;
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_EQ(one.force[i], two.force[i]) << i;
    ASSERT_EQ(one.torque[i], two.torque[i]) << i;
    ASSERT_EQ(one.virial[i], two.virial[i]) << i;
  }
  ASSERT_FALSE(one.events.empty());  // the perturbation overloads some bonds
  ASSERT_EQ(one.events.size(), two.events.size());
  for (std::size_t k = 0; k < one.events.size(); ++k) {
    EXPECT_EQ(one.events[k].bond, two.events[k].bond);
    EXPECT_EQ(one.events[k].stress, two.events[k].stress);
  }
  // The virial of the force pass is accumulate_virial's; the energies are bond_energy()'s and
  // their sum energy()'s.
  std::vector<Sym3> reference(p.size(), Sym3{});
  beam.accumulate_virial(p, VirialBranch::half, reference);
  for (std::size_t i = 0; i < p.size(); ++i) ASSERT_EQ(reference[i], one.virial[i]) << i;
  for (std::size_t b = 0; b < beam.size(); ++b) {
    ASSERT_EQ(one.energy[b], two.energy[b]) << b;
    ASSERT_EQ(one.energy[b], beam.bond_energy(b, p)) << b;
  }
  EXPECT_EQ(one.total_energy, two.total_energy);
  EXPECT_EQ(one.total_energy, beam.energy(p));
}

// Two beam sets in two halves of a lattice (two materials, each set's bonds at half the DEs, so
// at one thread's DEs on two threads): the one pass of both (accumulate_gathered_forces, what
// DemModel runs for consecutive gather sets) adds to every DE what the two sets' own passes add
// one after the other, to the bit, with the same measures and energies, on 1 and 2 threads.
TEST(ForceScan, BeamSetsInOnePassAddWhatTheirOwnPassesAdd) {
  DemModel model;
  const double R = 1e-3, a = 2 * R;
  build_lattice(model.particles, {0, 0, 0}, {16, 16, 16}, a, R, 7800.0);
  ParticleSet& p = model.particles;
  auto lower = std::make_unique<BeamBondSet>(BeamBondSet::Parameters{2e11, 0.3, 0.5, 1.0e9});
  auto upper = std::make_unique<BeamBondSet>(BeamBondSet::Parameters{1e11, 0.25, 0.4, 0.8e9});
  for (auto [i, j] : close_pairs(p, 0.01)) (p.position[i].z + p.position[j].z < 15 * a ? *lower : *upper).add(i, j, p);
  const BondSet& lower_set = model.add_bond_set(std::move(lower));
  const BondSet& upper_set = model.add_bond_set(std::move(upper));
  model.finalize();
  perturb(p, a);
  struct Pass {
    std::vector<Vec3> force, torque;
    std::vector<Sym3> virial;
    std::vector<double> energy;  // per bond of both sets
    std::vector<BreakEvent> events;
  };
  const auto pass = [&](int threads, bool together) {
    const test::OmpThreads scope(threads);
    Pass out;
    const ForceScan scan = recording_scan(p, out.virial);
    const BondSet* sets[] = {&lower_set, &upper_set};
    if (together) accumulate_gathered_forces(sets, p, scan);
    else
      for (const BondSet* set : sets) set->accumulate_forces(p, scan);
    out.force = p.force;
    out.torque = p.torque;
    for (std::uint32_t s = 0; s < 2; ++s) {
      out.energy.insert(out.energy.end(), sets[s]->recorded_energies().begin(), sets[s]->recorded_energies().end());
      sets[s]->find_failures(p, s, 0.0, out.events);
    }
    return out;
  };
  ASSERT_GT(lower_set.size(), 5000u);
  ASSERT_GT(upper_set.size(), 5000u);
  EXPECT_TRUE(lower_set.runs_on_threads() && upper_set.runs_on_threads());
  const Pass separate = pass(1, false);
  for (int threads : {1, 2}) {
    const Pass together = pass(threads, true);
    for (std::size_t i = 0; i < p.size(); ++i) {
      ASSERT_EQ(separate.force[i], together.force[i]) << i << ", " << threads << " thread(s)";
      ASSERT_EQ(separate.torque[i], together.torque[i]) << i << ", " << threads << " thread(s)";
      ASSERT_EQ(separate.virial[i], together.virial[i]) << i << ", " << threads << " thread(s)";
    }
    EXPECT_EQ(separate.energy, together.energy) << threads << " thread(s)";
    ASSERT_EQ(separate.events.size(), together.events.size()) << threads << " thread(s)";
    for (std::size_t k = 0; k < separate.events.size(); ++k) {
      EXPECT_EQ(separate.events[k].set, together.events[k].set);
      EXPECT_EQ(separate.events[k].bond, together.events[k].bond);
      EXPECT_EQ(separate.events[k].stress, together.events[k].stress);
    }
  }
  for (std::uint32_t s = 0; s < 2; ++s)  // the perturbation overloads some bonds of each set
    EXPECT_TRUE(std::any_of(separate.events.begin(), separate.events.end(), [s](const BreakEvent& e) { return e.set == s; })) << s;
}

// Whole steps of a damped breakable model on 1 and 2 threads: beams with BBF, springs with a
// maximum elongation on the same pairs, and RDEF on Laguerre cells (radical branch), started
// from random velocities that break bonds by every criterion within the run. Same breaks, same
// positions and the same energies (bond, damping work), to the bit.
TEST(ForceScan, BreakableStepsAreTheSameOnAnyThreadCount) {
  struct Run {
    std::vector<Vec3> position;
    std::vector<BreakEvent> breaks;
    Energies energies;
  };
  const auto run = [](int threads) {
    const test::OmpThreads scope(threads);
    DemModel model;
    const double dt = build_breakable_model(model, {17, 16, 16});  // above parallel_threshold DEs
    for (const auto& set : model.bond_sets()) EXPECT_TRUE(set->runs_on_threads()) << set->law();
    for (int n = 0; n < 40; ++n) model.step(dt);
    return Run{model.particles.position, model.breaks(), model.energies()};
  };
  const Run one = run(1), two = run(2);
  std::array<int, 3> by_criterion{};
  for (const auto& e : one.breaks) ++by_criterion[static_cast<int>(e.criterion)];
  EXPECT_GT(by_criterion[static_cast<int>(FailureCriterion::bbf)], 0);
  EXPECT_GT(by_criterion[static_cast<int>(FailureCriterion::elongation)], 0);
  EXPECT_GT(by_criterion[static_cast<int>(FailureCriterion::rdef)], 0);
  ASSERT_EQ(one.breaks.size(), two.breaks.size());
  for (std::size_t k = 0; k < one.breaks.size(); ++k) {
    EXPECT_EQ(one.breaks[k].set, two.breaks[k].set);
    EXPECT_EQ(one.breaks[k].bond, two.breaks[k].bond);
    EXPECT_EQ(one.breaks[k].time, two.breaks[k].time);
  }
  for (std::size_t i = 0; i < one.position.size(); ++i) ASSERT_EQ(one.position[i], two.position[i]) << i;
  EXPECT_GT(one.energies.dissipated, 0.0);
  EXPECT_EQ(one.energies.bond, two.energies.bond);
  EXPECT_EQ(one.energies.dissipated, two.energies.dissipated);
  EXPECT_EQ(one.energies.kinetic, two.energies.kinetic);
  EXPECT_EQ(one.energies.fracture, two.energies.fracture);
}
#endif

// Laguerre volume shares (volume: laguerre): in a simple-cubic lattice every cell is the
// lattice cube a^3 = sphere volume / (pi/6), so RDEF breaks exactly what it breaks with the
// sphere share at compaction pi/6: just under the applied stress, the DEs with both x-bonds;
// just over it, nothing.
TEST(Rdef, LaguerreSharesInACubicLatticeAreTheLatticeCube) {
  const double R = 1e-3, a = 2 * R, eps = 1e-4, E = 2e11;
  const double applied = E * std::numbers::pi * 0.25 * R * R * eps / (a * a);
  const auto breaks = [&](RdefVolume volume, double threshold_factor) {
    DemModel model;
    build_lattice(model.particles, {0, 0, 0}, {4, 3, 3}, a, R, 7800.0);
    test::bond_all_touching(model, {E, 0.3, 0.5});
    DemModel::RdefSettings settings{threshold_factor * applied, RdefEquivalent::max_principal, std::numbers::pi / 6.0, {}};
    settings.volume = volume;
    model.enable_rdef(settings);
    model.finalize();
    for (auto& x : model.particles.position) x.x *= 1.0 + eps;
    model.step(1e-12);
    return model.breaks().size();
  };
  // The 2 x 3 x 3 DEs with both x-bonds; their bonds: the 3 x-bonds of each of the 9 rows, and
  // the 12 lateral bonds of each of their 2 planes of 3 x 3.
  const std::size_t expected = 9 * 3 + 2 * 12;
  EXPECT_EQ(breaks(RdefVolume::sphere, 0.99), expected);
  EXPECT_EQ(breaks(RdefVolume::laguerre, 0.99), expected);
  EXPECT_EQ(breaks(RdefVolume::laguerre, 1.01), 0u);
}

// The radical branch: two touching DEs, R 1 and 0.5 mm (d = 1.5 mm): the radical plane is at
// d_0 = (d^2 + R_0^2 - R_1^2) / 2d = 1 mm from DE 0 (the contact point), so DE 0 gets
// 2 d_0 f = 2 mm f and DE 1 2 d_1 f = 1 mm f (with the 1/2 of Eq. 1); half-way, both get d f.
// Either way the two add up to 2 d f, the bond's whole virial.
TEST(VirialStress, RadicalBranchEndsAtTheContactPoint) {
  ParticleSet p;
  p.add({0, 0, 0}, 1e-3, 1.0);
  p.add({1.5e-3, 0, 0}, 0.5e-3, 1.0);
  const Vec3 f_0{2.0, 0, 0};  // tension: DE 0 pulled towards DE 1
  std::vector<Sym3> radical(2), half(2);
  add_bond_virial(p, 0, 1, f_0, VirialBranch::radical, radical);
  add_bond_virial(p, 0, 1, f_0, VirialBranch::half, half);
  EXPECT_NEAR(radical[0][0], 2 * 1.0e-3 * 2.0, 1e-15);
  EXPECT_NEAR(radical[1][0], 2 * 0.5e-3 * 2.0, 1e-15);
  EXPECT_NEAR(half[0][0], 1.5e-3 * 2.0, 1e-15);
  EXPECT_NEAR(half[1][0], 1.5e-3 * 2.0, 1e-15);
  EXPECT_NEAR(radical[0][0] + radical[1][0], half[0][0] + half[1][0], 1e-15);
}

TEST(Rdef, BreaksEveryBondOfTheOverloadedDeAndCountsTheirEnergyAsFracture) {
  DemModel model;
  const double R = 1e-3;
  build_chain(model.particles, {0, 0, 0}, {1, 0, 0}, 5, 2 * R, R, 7800.0);
  test::bond_all_touching(model, {2e11, 0.3, 0.5});
  // DE 2 carries 2.36e7 Pa (both bonds stretched 1e-6 m), DEs 1 and 3 half of it.
  model.enable_rdef({1.8e7, RdefEquivalent::max_principal, 0.63, {}});
  model.finalize();
  // Stretch the middle DE's two bonds only: move DEs 3 and 4 right, 0 and 1 left.
  for (std::size_t i : {0u, 1u}) model.particles.position[i].x -= 1e-6;
  for (std::size_t i : {3u, 4u}) model.particles.position[i].x += 1e-6;
  const double stored = model.energies().bond;
  model.step(1e-12);
  const auto& breaks = model.breaks();
  ASSERT_EQ(breaks.size(), 2u);
  for (const auto& e : breaks) {
    EXPECT_EQ(e.criterion, FailureCriterion::rdef);
    const auto& set = *model.bond_sets()[e.set];
    EXPECT_TRUE(set.first()[e.bond] == 2 || set.second()[e.bond] == 2);
  }
  EXPECT_NEAR(model.damage()[2], 1.0, 0.0);
  EXPECT_NEAR(model.energies().fracture, stored, 1e-6 * stored);
}

// Per-group thresholds (one per material in a composite): the same loading as above, DE 2
// (2.36e7 Pa) below its group's threshold, DE 1 (1.18e7 Pa) above its group's, DE 3
// (1.18e7 Pa) in no listed group and under the default threshold: only DE 1's bonds break.
TEST(Rdef, EachGroupFailsAtItsOwnThreshold) {
  DemModel model;
  const double R = 1e-3;
  build_chain(model.particles, {0, 0, 0}, {1, 0, 0}, 5, 2 * R, R, 7800.0);
  test::bond_all_touching(model, {2e11, 0.3, 0.5});
  const int hub = model.add_group("hub", {2}), side = model.add_group("side", {1});
  DemModel::RdefSettings settings{1.5e7, RdefEquivalent::max_principal, 0.63, {}};
  settings.group_thresholds = {{hub, 3.0e7}, {side, 1.0e7}};
  model.enable_rdef(settings);
  model.finalize();
  for (std::size_t i : {0u, 1u}) model.particles.position[i].x -= 1e-6;
  for (std::size_t i : {3u, 4u}) model.particles.position[i].x += 1e-6;
  model.step(1e-12);
  ASSERT_EQ(model.breaks().size(), 2u);
  for (const auto& e : model.breaks()) {
    const auto& set = *model.bond_sets()[e.set];
    EXPECT_TRUE(set.first()[e.bond] == 1 || set.second()[e.bond] == 1);
  }
  EXPECT_EQ(model.damage()[3], 0.0);
}

// Averaged RDEF: DE i is judged by sum_k R_k^3 sigma_k / sum_k R_k^3 over itself and its
// bonded partners. Same loading as above (equal radii): DE 2's average is the mean of the
// per-DE stresses of DEs 1, 2, 3; a threshold 1 % under it breaks DE 2's two bonds only (DE 1's
// average, (sigma_0 + sigma_1 + sigma_2) / 3 with sigma_0 = 0, is 25 % lower), 1 % over it none,
// though the per-DE stress of DE 2 is 50 % above.
TEST(Rdef, AveragedOverBondedNeighboursBreaksAtTheNeighbourhoodMean) {
  const double R = 1e-3;
  const auto run = [&](double threshold_factor) {
    auto model = std::make_unique<DemModel>();
    build_chain(model->particles, {0, 0, 0}, {1, 0, 0}, 5, 2 * R, R, 7800.0);
    test::bond_all_touching(*model, {2e11, 0.3, 0.5});
    for (std::size_t i : {0u, 1u}) model->particles.position[i].x -= 1e-6;
    for (std::size_t i : {3u, 4u}) model->particles.position[i].x += 1e-6;
    const auto sigma = model->virial_stress(0.63);  // per DE, before any step
    const double mean = (sigma[1][0] + sigma[2][0] + sigma[3][0]) / 3.0;
    EXPECT_NEAR(sigma[2][0], 1.5 * mean, 1e-9 * mean);
    DemModel::RdefSettings settings{threshold_factor * mean, RdefEquivalent::max_principal, 0.63, {}};
    settings.average = RdefAverage::bonded_neighbours;
    model->enable_rdef(settings);
    model->finalize();
    model->step(1e-12);
    return model;
  };
  const auto below = run(0.99);
  ASSERT_EQ(below->breaks().size(), 2u);
  for (const auto& e : below->breaks()) {
    const auto& set = *below->bond_sets()[e.set];
    EXPECT_TRUE(set.first()[e.bond] == 2 || set.second()[e.bond] == 2);
  }
  EXPECT_TRUE(run(1.01)->breaks().empty());
}

// The average stays within a material: with DE 3 in a group of its own (another threshold),
// DE 2's neighbourhood is DEs 1 and 2 only, mean 1.5 sigma_1 instead of 4/3 sigma_1.
TEST(Rdef, AverageLeavesOutPartnersOfAnotherThresholdGroup) {
  DemModel model;
  const double R = 1e-3;
  build_chain(model.particles, {0, 0, 0}, {1, 0, 0}, 5, 2 * R, R, 7800.0);
  test::bond_all_touching(model, {2e11, 0.3, 0.5});
  const int other = model.add_group("other", {3});
  for (std::size_t i : {0u, 1u}) model.particles.position[i].x -= 1e-6;
  for (std::size_t i : {3u, 4u}) model.particles.position[i].x += 1e-6;
  const double sigma_1 = model.virial_stress(0.63)[1][0];
  DemModel::RdefSettings settings{1.45 * sigma_1, RdefEquivalent::max_principal, 0.63, {{other, 1e30}}};
  settings.average = RdefAverage::bonded_neighbours;
  model.enable_rdef(settings);
  model.finalize();
  model.step(1e-12);
  ASSERT_EQ(model.breaks().size(), 2u);
  EXPECT_EQ(model.damage()[2], 1.0);
}

// The average weighs each DE's stress by its volume: sum Omega sigma / sum Omega. A chain of
// unequal DEs (radii 1, 0.8, 1.5, 0.9, 1 mm, volumes 4/3 pi R^3 / compaction), its two middle
// bonds stretched; the averages are computed here from the per-DE stresses, and a threshold 1 %
// under the largest breaks that DE's bonds only, 1 % over it none.
TEST(Rdef, AverageWeighsEachStressByItsVolume) {
  const double radii[5] = {1e-3, 0.8e-3, 1.5e-3, 0.9e-3, 1e-3}, compaction = 0.63;
  const auto run = [&](double threshold_factor, std::size_t* highest) {
    auto model = std::make_unique<DemModel>();
    double x = 0.0;
    for (int i = 0; i < 5; ++i) {
      if (i > 0) x += radii[i - 1] + radii[i];
      model->particles.add({x, 0, 0}, radii[i], 7800.0);
    }
    test::bond_all_touching(*model, {2e11, 0.3, 0.5});
    for (std::size_t i : {0u, 1u}) model->particles.position[i].x -= 1e-6;
    for (std::size_t i : {3u, 4u}) model->particles.position[i].x += 1e-6;
    const auto sigma = model->virial_stress(compaction);
    std::vector<double> omega(5), average(5);
    for (int i = 0; i < 5; ++i) omega[i] = 4.0 / 3.0 * std::numbers::pi * std::pow(radii[i], 3) / compaction;
    for (int i = 0; i < 5; ++i) {
      double weighted = 0.0, volume = 0.0;
      for (int j = std::max(0, i - 1); j <= std::min(4, i + 1); ++j) weighted += omega[j] * sigma[j][0], volume += omega[j];
      average[i] = weighted / volume;
    }
    *highest = static_cast<std::size_t>(std::max_element(average.begin(), average.end()) - average.begin());
    std::vector<double> others = average;
    others.erase(others.begin() + static_cast<long>(*highest));
    EXPECT_LT(*std::max_element(others.begin(), others.end()), 0.97 * average[*highest]);
    DemModel::RdefSettings settings{threshold_factor * average[*highest], RdefEquivalent::max_principal, compaction, {}};
    settings.average = RdefAverage::bonded_neighbours;
    model->enable_rdef(settings);
    model->finalize();
    model->step(1e-12);
    return model;
  };
  std::size_t highest = 0;
  const auto below = run(0.99, &highest);
  ASSERT_EQ(below->breaks().size(), 2u);
  for (const auto& e : below->breaks()) {
    const auto& set = *below->bond_sets()[e.set];
    EXPECT_TRUE(set.first()[e.bond] == highest || set.second()[e.bond] == highest);
  }
  EXPECT_TRUE(run(1.01, &highest)->breaks().empty());
}

// Two DEs bonded by a weak beam are pulled apart until it breaks; sent back towards each other,
// they meet by penalty contact and bounce elastically.
TEST(Failure, FormerPartnersInteractByContact) {
  DemModel model;
  const double R = 1e-3;
  model.particles.add({0, 0, 0}, R, 7800.0);
  model.particles.add({2 * R, 0, 0}, R, 7800.0);
  test::bond_all_touching(model, {2e11, 0.3, 0.5, 1e6});
  model.set_contact(std::make_unique<PenaltyContact>(1e6), 0.2 * R);
  model.particles.velocity[0] = {-0.5, 0, 0};
  model.particles.velocity[1] = {0.5, 0, 0};
  model.finalize();
  const double dt = 0.05 * model.critical_time_step();
  while (model.breaks().empty()) model.step(dt);
  EXPECT_EQ(model.breaks()[0].criterion, FailureCriterion::bbf);
  for (int n = 0; n < 200; ++n) model.step(dt);
  model.particles.velocity[0] = {1.0, 0, 0};
  model.particles.velocity[1] = {-1.0, 0, 0};
  double max_contact = 0.0, contact = 0.0;
  for (int n = 0; n < 20000 && (max_contact == 0.0 || contact > 0.0); ++n) {  // until they part again
    model.step(dt);
    contact = model.energies().contact;
    max_contact = std::max(max_contact, contact);
  }
  EXPECT_GT(max_contact, 0.0);
  EXPECT_LT(model.particles.velocity[0].x, 0.0);  // bounced back
  EXPECT_NEAR(model.particles.velocity[0].x, -1.0, 0.01);
}

}  // namespace
}  // namespace arlequin::dem
