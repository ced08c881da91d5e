// SPDX-License-Identifier: GPL-3.0-or-later
// Arlequin weighting of the DEM side: masses by max(alpha, floor) at the DE, bond stiffness
// by alpha at the bond midpoint, contacts by the smaller alpha of their two DEs
// (docs/theory.md#weighted-models).
#include <gtest/gtest.h>

#include "dem/contacts/penalty_contact.hpp"
#include "support/dem_fixtures.hpp"

namespace arlequin::dem {
namespace {

TEST(ArlequinWeight, ScalesMassesWithFloorAndBondsAtMidpoint) {
  DemModel model;
  build_chain(model.particles, {0, 0, 0}, {1, 0, 0}, 3, 2.0, 1.0, 1.0);  // x = 0, 2, 4
  auto& beam = test::bond_all_touching(model, {1e5, 0.3, 0.5});
  const double m0 = model.particles.mass(0);
  // alpha falls linearly from 1 at x = 0 to 0 at x = 4.
  model.apply_arlequin_weight([](const Vec3& x) { return 1.0 - x.x / 4.0; }, 0.05);
  model.finalize();
  EXPECT_DOUBLE_EQ(model.particles.mass(0), m0);
  EXPECT_DOUBLE_EQ(model.particles.mass(1), 0.5 * m0);
  EXPECT_DOUBLE_EQ(model.particles.mass(2), 0.05 * m0);  // the floor
  EXPECT_DOUBLE_EQ(model.particles.inertia(1), 0.5 * 0.4 * m0);
  // Bond midpoints at x = 1 and 3: weights 3/4 and 1/4 of the axial stiffness E S / L.
  const double k = test::R1Beam::E * test::R1Beam::S / test::R1Beam::L;
  model.particles.position[1].x += 1e-3;
  for (std::size_t b = 0; b < beam.size(); ++b) {
    const auto a = beam.actions(b, model.particles);
    const double midpoint = 0.5 * (model.particles.reference[beam.first()[b]].x + model.particles.reference[beam.second()[b]].x);
    EXPECT_NEAR(std::abs(a.axial_force), (1.0 - midpoint / 4.0) * k * 1e-3, 1e-9 * k * 1e-3);
  }
}

// Two DEs of radius 1 overlapping by 0.1, weights 0.8 and 0.3: the contact force and energy are
// 0.3 of the penalty's, and the critical step is the unweighted one (the weighted stiffness
// over the weighted mass, 0.3 K / (0.3 m), is K / m).
TEST(ArlequinWeight, AContactWeighsAsItsLighterDe) {
  const double K = 1e6, delta = 0.1;
  const auto two_des = [&](bool weighted) {
    auto model = std::make_unique<DemModel>();
    model->particles.add({0, 0, 0}, 1.0, 1000.0);
    model->particles.add({2.0 - delta, 0, 0}, 1.0, 1000.0);
    model->set_contact(std::make_unique<PenaltyContact>(K), 0.05);
    if (weighted) model->apply_arlequin_weight([](const Vec3& x) { return x.x < 1.0 ? 0.8 : 0.3; }, 0.05);
    model->finalize();
    return model;
  };
  const auto plain = two_des(false), weighted = two_des(true);
  EXPECT_NEAR(plain->particles.force[1].x, K * delta, 1e-9 * K * delta);
  EXPECT_NEAR(weighted->particles.force[1].x, 0.3 * K * delta, 1e-9 * K * delta);
  EXPECT_NEAR(weighted->particles.force[0].x, -0.3 * K * delta, 1e-9 * K * delta);
  EXPECT_NEAR(weighted->energies().contact, 0.3 * 0.5 * K * delta * delta, 1e-12 * K);
  EXPECT_NEAR(weighted->critical_time_step(), plain->critical_time_step(), 1e-12 * plain->critical_time_step());
}

}  // namespace
}  // namespace arlequin::dem
