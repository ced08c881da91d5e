#include "dem/boundary.hpp"

#include <algorithm>

namespace arlequin::dem {

Vec3 BoundaryCondition::displacement_at(double t) const {
  switch (kind) {
    case BoundaryKind::velocity: return value * t;
    case BoundaryKind::displacement: return value * std::min(t / ramp, 1.0);
    default: return {};
  }
}

Vec3 BoundaryCondition::velocity_at(double t) const {
  switch (kind) {
    case BoundaryKind::velocity: return value;
    case BoundaryKind::displacement: return t < ramp ? value / ramp : Vec3{};
    default: return {};
  }
}

}  // namespace arlequin::dem
