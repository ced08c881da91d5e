// SPDX-License-Identifier: GPL-3.0-or-later
#include "coupling/overlap_zone.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "common/error.hpp"

namespace arlequin::coupling {

namespace {

constexpr double kRampTolerance = 1e-9;  // s within [-tol, 1 + tol] counts as in the overlap

void check_weighting(const OverlapZone::Weighting& w) {
  if (!(w.mass_floor > 0.0 && w.mass_floor <= 1.0))
    throw SettingError("mass_floor", "must lie in (0, 1], got " + std::to_string(w.mass_floor));
  if (w.shape == WeightShape::constant && !(w.constant_value > 0.0 && w.constant_value < 1.0))
    throw SettingError("constant_value", "must lie in (0, 1), got " + std::to_string(w.constant_value));
}

std::string vec(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

}  // namespace

WeightShape weight_shape_from_name(const std::string& name) {
  if (name == "constant") return WeightShape::constant;
  if (name == "linear") return WeightShape::linear;
  if (name == "cubic") return WeightShape::cubic;
  throw InputError("unknown weight shape '" + name + "' (known: constant, linear, cubic)");
}

const char* weight_shape_name(WeightShape shape) {
  switch (shape) {
    case WeightShape::constant: return "constant";
    case WeightShape::linear: return "linear";
    case WeightShape::cubic: return "cubic";
  }
  return "?";
}

OverlapZone::OverlapZone(Membership contains, RampCoordinate ramp, Polyhedral shape, Weighting weighting,
                         std::string description, std::vector<RampCoordinate> convex_pieces)
    : contains_(std::move(contains)),
      ramp_(std::move(ramp)),
      convex_pieces_(convex_pieces.empty() ? std::vector<RampCoordinate>{ramp_} : std::move(convex_pieces)),
      shape_(std::move(shape)),
      weighting_(weighting),
      description_(std::move(description)) {
  check_weighting(weighting_);
}

std::vector<OverlapZone::Plane> OverlapZone::box_planes(const Box& b) {
  std::vector<Plane> planes;
  for (int k = 0; k < 3; ++k) {
    Vec3 n{};
    n[k] = 1.0;
    planes.push_back({n, b.upper[k]});
    planes.push_back({-1.0 * n, -b.lower[k]});
  }
  return planes;
}

double OverlapZone::volume_inside(const Polyhedron& cell) const {
  double extent = 0.0;
  const Vec3 first = cell.empty() || cell.front().pts.empty() ? Vec3{} : cell.front().pts.front();
  for (const PolyFace& f : cell)
    for (const Vec3& p : f.pts) extent = std::max(extent, norm(p - first));
  const double tol = 1e-12 * extent;
  auto clipped = [&](Polyhedron poly, const std::vector<Plane>& planes) {
    for (const Plane& plane : planes) clip(poly, plane.n, plane.d, /*tag, not read here*/ -1, tol);
    return poly;
  };
  double v = 0.0;
  for (const Term& term : shape_.terms) v += term.sign * volume(clipped(cell, term.planes));
  return std::max(v, 0.0);
}

bool OverlapZone::in_dem_domain(const Vec3& x) const { return ramp_(x) <= 1.0 + kRampTolerance; }
bool OverlapZone::in_pure_dem_zone(const Vec3& x) const { return ramp_(x) <= kRampTolerance; }

bool OverlapZone::hull_in_pure_dem_zone(std::span<const Vec3> points) const {
  return std::any_of(convex_pieces_.begin(), convex_pieces_.end(), [&points](const RampCoordinate& s) {
    return std::all_of(points.begin(), points.end(), [&s](const Vec3& x) { return s(x) <= kRampTolerance; });
  });
}

double OverlapZone::alpha_d(const Vec3& x) const {
  const double s = ramp_(x);
  if (s < -kRampTolerance) return 1.0;
  if (s > 1.0 + kRampTolerance) return 0.0;
  // On a boundary within the tolerance, exactly on it: a node at x = 22a that gmsh places at
  // 22a (1 + 1e-16) must get alpha_c = 0, not 1e-14 (a natural-neighbour node mass of 1e-14 of
  // its cell's took the critical step down to 1e-13 s).
  const double t = s <= kRampTolerance ? 0.0 : s >= 1.0 - kRampTolerance ? 1.0 : s;
  switch (weighting_.shape) {
    case WeightShape::constant: return weighting_.constant_value;
    case WeightShape::linear: return 1.0 - t;
    case WeightShape::cubic: return 1.0 - t * t * (3.0 - 2.0 * t);
  }
  return 1.0;
}

OverlapZone OverlapZone::box(const Box& b, int axis, bool dem_on_lower_side, Weighting weighting) {
  if (axis < 0 || axis > 2) throw SettingError("overlap", "the box axis must be 0, 1 or 2");
  const double lo = b.lower[axis], hi = b.upper[axis];
  if (!(hi > lo)) throw SettingError("overlap", "the box has no extent along its ramp axis");
  RampCoordinate ramp = dem_on_lower_side ? RampCoordinate([=](const Vec3& x) { return (x[axis] - lo) / (hi - lo); })
                                          : RampCoordinate([=](const Vec3& x) { return (hi - x[axis]) / (hi - lo); });
  const Region region{b};
  std::ostringstream d;
  d << "box " << vec(b.lower) << "-" << vec(b.upper) << ", ramp along axis " << axis << " with the DEM on the "
    << (dem_on_lower_side ? "lower" : "upper") << " side";
  return OverlapZone([region](const Vec3& x) { return region.contains(x); }, std::move(ramp), {{{box_planes(b), 1.0}}, b},
                     weighting, d.str());
}

OverlapZone OverlapZone::cylinder(const Cylinder& c, bool dem_at_base, Weighting weighting) {
  if (!(c.length > 0.0)) throw SettingError("overlap", "an overlap cylinder needs a positive length");
  const Vec3 base = c.base, axis = c.axis;
  const double length = c.length;
  RampCoordinate ramp = [=](const Vec3& x) {
    const double s = dot(x - base, axis) / length;
    return dem_at_base ? s : 1.0 - s;
  };
  // The end planes, and the curved side as the circumscribed regular polygon: its faces touch
  // the circle at their middles, at distance `radius` from the axis.
  Polyhedral shape;
  std::vector<Plane>& solid = shape.terms.emplace_back().planes;
  solid.push_back({axis, dot(axis, base) + length});
  solid.push_back({-1.0 * axis, -dot(axis, base)});
  const Vec3 e1 = normalized(std::abs(axis.x) < 0.9 ? cross(axis, Vec3{1, 0, 0}) : cross(axis, Vec3{0, 1, 0}));
  const Vec3 e2 = cross(axis, e1);
  for (int k = 0; k < kCylinderSides; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / kCylinderSides;
    const Vec3 n = std::cos(phi) * e1 + std::sin(phi) * e2;
    solid.push_back({n, dot(n, base) + c.radius});
  }
  const Vec3 top = base + length * axis;
  for (int k = 0; k < 3; ++k)
    shape.bounds.lower[k] = std::min(base[k], top[k]) - c.radius, shape.bounds.upper[k] = std::max(base[k], top[k]) + c.radius;
  const Region region{c};
  std::ostringstream d;
  d << "cylinder base " << vec(base) << " axis " << vec(axis) << " radius " << c.radius << " length " << length
    << ", ramp along the axis with the DEM at the " << (dem_at_base ? "base" : "top");
  return OverlapZone([region](const Vec3& x) { return region.contains(x); }, std::move(ramp), std::move(shape),
                     weighting, d.str());
}

namespace {

// A shell's ramp (OverlapZone::shell); InputError unless the boxes nest and differ somewhere.
OverlapZone::RampCoordinate shell_ramp(const Box& inner, const Box& outer) {
  bool ramps = false;
  for (int k = 0; k < 3; ++k) {
    if (!(outer.lower[k] <= inner.lower[k] && inner.lower[k] < inner.upper[k] && inner.upper[k] <= outer.upper[k]))
      throw SettingError("overlap", "the shell needs the inner box strictly inside the outer one");
    ramps = ramps || outer.lower[k] < inner.lower[k] || inner.upper[k] < outer.upper[k];
  }
  if (!ramps) throw SettingError("overlap", "the shell has the same inner and outer box");
  return [=](const Vec3& x) {
    double s = -1e300;
    for (int k = 0; k < 3; ++k) {
      if (outer.lower[k] < inner.lower[k])
        s = std::max(s, (inner.lower[k] - x[k]) / (inner.lower[k] - outer.lower[k]));
      if (inner.upper[k] < outer.upper[k])
        s = std::max(s, (x[k] - inner.upper[k]) / (outer.upper[k] - inner.upper[k]));
    }
    return s;
  };
}

std::string shell_description(const Box& inner, const Box& outer) {
  std::ostringstream d;
  d << "shell between box " << vec(inner.lower) << "-" << vec(inner.upper) << " (DEM inside) and box "
    << vec(outer.lower) << "-" << vec(outer.upper);
  return d.str();
}

}  // namespace

OverlapZone OverlapZone::shell(const Box& inner, const Box& outer, Weighting weighting) {
  RampCoordinate ramp = shell_ramp(inner, outer);
  const Region out{outer};
  Membership contains = [out, ramp](const Vec3& x) { return out.contains(x) && ramp(x) >= -kRampTolerance; };
  // The inner box's volume is taken inside the outer one's (its planes after the outer's).
  std::vector<Plane> both = box_planes(outer);
  for (const Plane& plane : box_planes(inner)) both.push_back(plane);
  return OverlapZone(std::move(contains), std::move(ramp), {{{box_planes(outer), 1.0}, {std::move(both), -1.0}}, outer},
                     weighting, shell_description(inner, outer));
}

OverlapZone OverlapZone::band(int axis, double center, double half_thickness, double width, int along, double from,
                              double to, Weighting weighting) {
  if (axis < 0 || axis > 2 || along < 0 || along > 2 || axis == along)
    throw SettingError("along", "must differ from axis");
  if (!(width > 0.0 && width < half_thickness))
    throw SettingError("width", "must be below half_thickness (the band needs a pure-DEM core)");
  if (!(to - from > 2.0 * width))
    throw SettingError("to", "must lie beyond from + 2 width (the overlaps at both ends and a pure-DEM core)");
  constexpr double everywhere = 1e3;  // m: the third direction's extent
  Box inner{Vec3{-everywhere, -everywhere, -everywhere}, Vec3{everywhere, everywhere, everywhere}}, outer = inner;
  outer.lower[axis] = center - half_thickness, outer.upper[axis] = center + half_thickness;
  inner.lower[axis] = outer.lower[axis] + width, inner.upper[axis] = outer.upper[axis] - width;
  outer.lower[along] = from, outer.upper[along] = to;
  inner.lower[along] = from + width, inner.upper[along] = to - width;
  return shell(inner, outer, weighting);
}

OverlapZone OverlapZone::shells(const std::vector<std::pair<Box, Box>>& inner_outer, Weighting weighting) {
  const int n = static_cast<int>(inner_outer.size());
  if (n < 1 || n > kMaxShells)
    throw SettingError("overlap", "a union of shells takes 1 to " + std::to_string(kMaxShells) + " shells, got " + std::to_string(n));
  if (n == 1) return shell(inner_outer[0].first, inner_outer[0].second, weighting);
  std::vector<RampCoordinate> ramps;
  std::vector<Region> outers;
  Polyhedral shape;
  shape.bounds = inner_outer[0].second;
  std::ostringstream description;
  description << "union of " << n << " shells";
  for (const auto& [inner, outer] : inner_outer) {
    ramps.push_back(shell_ramp(inner, outer));
    outers.push_back(Region{outer});
    for (int k = 0; k < 3; ++k) {
      shape.bounds.lower[k] = std::min(shape.bounds.lower[k], outer.lower[k]);
      shape.bounds.upper[k] = std::max(shape.bounds.upper[k], outer.upper[k]);
    }
    description << (ramps.size() == 1 ? ": " : "; ") << shell_description(inner, outer);
  }
  // |cell in the union of the outer boxes| - |cell in the union of the inner boxes| (each inner
  // box inside its outer one), each union by inclusion and exclusion: the boxes of a subset S
  // intersected, with the sign (-1)^(|S| + 1).
  for (unsigned subset = 1; subset < (1u << n); ++subset) {
    Term outer_term, inner_term;
    int members = 0;
    for (int k = 0; k < n; ++k)
      if (subset >> k & 1u) {
        ++members;
        for (const Plane& plane : box_planes(inner_outer[static_cast<std::size_t>(k)].second)) outer_term.planes.push_back(plane);
        for (const Plane& plane : box_planes(inner_outer[static_cast<std::size_t>(k)].first)) inner_term.planes.push_back(plane);
      }
    outer_term.sign = members % 2 == 1 ? 1.0 : -1.0;
    inner_term.sign = -outer_term.sign;
    shape.terms.push_back(std::move(outer_term));
    shape.terms.push_back(std::move(inner_term));
  }
  RampCoordinate ramp = [ramps](const Vec3& x) {
    double s = 1e300;
    for (const RampCoordinate& r : ramps) s = std::min(s, r(x));
    return s;
  };
  Membership contains = [outers, ramp](const Vec3& x) {
    return std::any_of(outers.begin(), outers.end(), [&x](const Region& r) { return r.contains(x); }) && ramp(x) >= -kRampTolerance;
  };
  return OverlapZone(std::move(contains), std::move(ramp), std::move(shape), weighting, description.str(), std::move(ramps));
}

}  // namespace arlequin::coupling
