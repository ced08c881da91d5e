// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/boundary.hpp"

#include <algorithm>

#include "common/rise.hpp"

namespace arlequin::dem {

Vec3 BoundaryCondition::displacement_at(double t) const {
  switch (kind) {
    case BoundaryKind::velocity: return value * rise_travel(t, rise);  // the integral of velocity_at
    case BoundaryKind::displacement: return value * std::min(t / ramp, 1.0);
    default: return {};
  }
}

Vec3 BoundaryCondition::velocity_at(double t) const {
  switch (kind) {
    case BoundaryKind::velocity: return value * rise_speed_share(t, rise);
    case BoundaryKind::displacement: return t < ramp ? value / ramp : Vec3{};
    default: return {};
  }
}

}  // namespace arlequin::dem
