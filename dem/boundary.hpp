// SPDX-License-Identifier: GPL-3.0-or-later
// Boundary conditions on groups of DEs, applied from t = 0.
//
//   fixed         x = x_ref, v = 0, rotation locked (clamped)
//   velocity      v = value (m/s); x = x_ref + value t; with a rise time (s) the velocity grows
//                 as value (1 - cos(pi t / rise)) / 2 first (common/rise.hpp: no jump of the
//                 velocity or the acceleration, no ringing), x its integral
//   displacement  linear ramp to value (m) over ramp (s), then held: v = value/ramp, then 0
//   force         total force value (N) shared equally by the group's DEs (a dead load)
//   free          nothing imposed; declares that the group must not be constrained
// Kinematic conditions (fixed, velocity, displacement) act on the listed components (default
// x, y, z: a roller imposes one), and lock rotations when rotation: fixed (default for fixed,
// free otherwise). Two kinematic conditions may share a DE if their components differ. Force sensors report the quasi-static reaction,
// -(sum of bond and contact forces on the group); the external work of a kinematic condition
// is the work of that reaction plus the change of the driven DEs' kinetic energy.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "common/vec3.hpp"

namespace arlequin::dem {

enum class BoundaryKind { fixed, velocity, displacement, force, free };

struct BoundaryCondition {
  std::string group;
  BoundaryKind kind = BoundaryKind::free;
  Vec3 value{};             // m/s, m or N depending on kind
  double ramp = 0.0;        // s, displacement only
  bool lock_rotation = false;
  std::array<bool, 3> components{true, true, true};  // kinematic: which translations are imposed
  double rise = 0.0;        // s, velocity only

  bool kinematic() const {
    return kind == BoundaryKind::fixed || kind == BoundaryKind::velocity || kind == BoundaryKind::displacement;
  }
  // Kinematic with no motion at any time (fixed, or a zero velocity or displacement): its DEs'
  // imposed components stay at rest, so their kinetic energy and their reactions' work are 0.
  bool still() const { return kind == BoundaryKind::fixed || (kinematic() && value == Vec3{}); }
  Vec3 displacement_at(double t) const;
  Vec3 velocity_at(double t) const;
};

}  // namespace arlequin::dem
