// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/boundary.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace arlequin::dem {

Vec3 BoundaryCondition::displacement_at(double t) const {
  switch (kind) {
    case BoundaryKind::velocity:  // the integral of velocity_at
      if (t < rise) return value * (0.5 * t - rise / (2.0 * std::numbers::pi) * std::sin(std::numbers::pi * t / rise));
      return value * (t - 0.5 * rise);
    case BoundaryKind::displacement: return value * std::min(t / ramp, 1.0);
    default: return {};
  }
}

Vec3 BoundaryCondition::velocity_at(double t) const {
  switch (kind) {
    case BoundaryKind::velocity: return t < rise ? value * (0.5 * (1.0 - std::cos(std::numbers::pi * t / rise))) : value;
    case BoundaryKind::displacement: return t < ramp ? value / ramp : Vec3{};
    default: return {};
  }
}

}  // namespace arlequin::dem
