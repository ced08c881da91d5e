// SPDX-License-Identifier: GPL-3.0-or-later
// Prescribed motions of boundary conditions (dem/boundary.hpp) against their closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/boundary.hpp"

namespace arlequin::dem {
namespace {

// A velocity with a rise time: v = V (1 - cos(pi t / T)) / 2 up to T, then V; the displacement
// is its integral, V T / 2 at t = T and V (t - T / 2) after.
TEST(Boundary, VelocityRiseIsSmoothAndItsDisplacementIsTheIntegral) {
  BoundaryCondition bc;
  bc.kind = BoundaryKind::velocity;
  bc.value = {0.0, 0.0, 2.0};
  bc.rise = 1e-6;
  EXPECT_EQ(bc.velocity_at(0.0).z, 0.0);
  EXPECT_NEAR(bc.velocity_at(0.5e-6).z, 1.0, 1e-12);
  EXPECT_EQ(bc.velocity_at(2e-6).z, 2.0);
  EXPECT_NEAR(bc.displacement_at(1e-6).z, 1e-6, 1e-18);
  EXPECT_NEAR(bc.displacement_at(3e-6).z, 2.0 * 2.5e-6, 1e-18);
  // Central differences of the displacement give the velocity (second order in h).
  const double h = 1e-10;
  for (double t : {0.1e-6, 0.4e-6, 0.9e-6, 1.5e-6})
    EXPECT_NEAR((bc.displacement_at(t + h).z - bc.displacement_at(t - h).z) / (2 * h), bc.velocity_at(t).z, 1e-6) << t;
  // Without a rise time the velocity is constant from the start.
  bc.rise = 0.0;
  EXPECT_EQ(bc.velocity_at(0.0).z, 2.0);
  EXPECT_NEAR(bc.displacement_at(1e-6).z, 2e-6, 1e-18);
}

// A still condition never moves its DEs (the model then skips their kinetic energy and work):
// fixed, or a kinematic condition whose value is zero; not a moving or a force condition.
TEST(Boundary, StillConditionsAreTheOnesThatNeverMove) {
  BoundaryCondition bc;
  bc.kind = BoundaryKind::fixed;
  EXPECT_TRUE(bc.still());
  bc.kind = BoundaryKind::velocity;
  EXPECT_TRUE(bc.still());
  bc.value = {0.0, 1e-9, 0.0};
  EXPECT_FALSE(bc.still());
  bc.kind = BoundaryKind::displacement;
  bc.ramp = 1e-6;
  EXPECT_FALSE(bc.still());
  bc.value = {};
  EXPECT_TRUE(bc.still());
  bc.kind = BoundaryKind::force;
  EXPECT_FALSE(bc.still());
  bc.kind = BoundaryKind::free;
  EXPECT_FALSE(bc.still());
}

}  // namespace
}  // namespace arlequin::dem
