// SPDX-License-Identifier: GPL-3.0-or-later
// OverlapZone: where the DEM and the continuum coexist, and the Arlequin weights there.
//
// Contract
//  - A ramp coordinate s(x) runs across the overlap: s = 0 on its DEM-side boundary, s = 1 on
//    its continuum-side boundary, s < 0 in the pure-DEM zone, s > 1 in the pure-continuum zone.
//  - Weights (Ben Dhia & Rateau, IJNME 62 (2005) section 2; Xiao & Belytschko, CMAME 193 (2004)
//    Eq. 8): alpha_d(x) + alpha_c(x) = 1 everywhere, alpha_d = 1 in the pure-DEM zone and 0 in
//    the pure-continuum zone; across the overlap (s in [0, 1], boundaries included):
//      constant  alpha_d = c (default 1/2), a jump at both boundaries
//      linear    alpha_d = 1 - s
//      cubic     alpha_d = 1 - (3 s^2 - 2 s^3)   (C1 at both boundaries)
//  - mass_floor eps: DE masses are weighted by max(alpha_d, eps) (DemModel::apply_arlequin_weight),
//    so no DE has a zero mass at the continuum-side edge. Stiffness is never floored.
//  - contains(x): x in the overlap (its boundaries included, relative tolerance 1e-9), which is
//    where DEs are coupled. DEs beyond the overlap on the continuum side (alpha_d = 0) must not
//    exist: their bonds would carry no stiffness and nothing would hold them. in_dem_domain(x)
//    (s <= 1) is where DEs may be; in_pure_dem_zone(x) (s <= 0) is where a continuum
//    tetrahedron with all its vertices there has alpha_c = 0 throughout and is left out.
//  - volume_inside(cell): the volume of a convex polyhedron's part in the overlap, a coupled DE's
//    share of the overlap's integrals (its Laguerre cell clipped by the overlap,
//    coupling_operators.hpp). The overlap is held as a signed sum of convex polyhedra (lists of
//    half-spaces: a shell is its outer box minus its inner one); the cylinder's curved side is the circumscribed
//    regular polygon of kCylinderSides sides (its area exceeds the circle's by 2.0e-4 of it; only
//    cells the side cuts see the difference).
//  - Shapes: a box slab (ramp along one axis), a finite cylinder (ramp along its axis), the
//    shell between two nested boxes (DEM inside the inner box, continuum outside the outer one),
//    or a union of such shells (DEM inside any inner box: a cross of two bands, s the smallest
//    of the shells' ramps, so alpha_d the largest of their weights; its volume by inclusion and
//    exclusion over the boxes).
//  - Bad input (empty slab, non-nested shell, unknown shape name) is an InputError.
#pragma once
#include <functional>
#include <span>
#include <string>

#include <vector>

#include "common/convex_polyhedron.hpp"
#include "common/region.hpp"
#include "common/vec3.hpp"

namespace arlequin::coupling {

enum class WeightShape { constant, linear, cubic };
// "constant", "linear" or "cubic"; InputError otherwise (the message lists the names).
WeightShape weight_shape_from_name(const std::string& name);
const char* weight_shape_name(WeightShape shape);

class OverlapZone {
 public:
  using RampCoordinate = std::function<double(const Vec3&)>;
  using Membership = std::function<bool(const Vec3&)>;

  struct Weighting {
    WeightShape shape = WeightShape::linear;
    double mass_floor = 0.05;     // eps in (0, 1]
    double constant_value = 0.5;  // alpha_d inside the overlap for the constant shape, in (0, 1)
  };

  // Box slab; the ramp runs along `axis` (0, 1, 2). dem_on_lower_side: the DEM lies at
  // x[axis] < box.lower[axis] (s = 0 on the lower face), else on the upper side.
  static OverlapZone box(const Box& box, int axis, bool dem_on_lower_side, Weighting weighting);
  // Finite cylinder (length > 0); the ramp runs along the axis, DEM beyond the base
  // (dem_at_base) or beyond the top.
  static OverlapZone cylinder(const Cylinder& cylinder, bool dem_at_base, Weighting weighting);
  // Shell outer \ inner between nested boxes: DEM inside `inner`, continuum outside `outer`.
  // s = max over axes and sides of the fractional distance from the inner face to the outer
  // face; a side where the two faces coincide does not ramp.
  static OverlapZone shell(const Box& inner, const Box& outer, Weighting weighting);
  // A slab |x[axis] - center| <= half_thickness from x[along] = from to x[along] = to, across all
  // of the third direction: the DEM inside, the overlap its outer `width` on both faces and at
  // both ends (from, to), so that a band that ends inside a body is tied to it there too; a band
  // that runs out of the body ends `width` or more beyond it. Needs axis != along, 0 < width <
  // half_thickness and to - from > 2 width (a pure-DEM core); a SettingError naming the key
  // (along, width, to) otherwise.
  static OverlapZone band(int axis, double center, double half_thickness, double width, int along, double from,
                          double to, Weighting weighting);
  // The union of shells (inner, outer), at most kMaxShells: DEM inside any inner box, continuum
  // outside every outer one; s = the smallest of the shells' s. One shell is shell().
  static OverlapZone shells(const std::vector<std::pair<Box, Box>>& inner_outer, Weighting weighting);

  bool contains(const Vec3& x) const { return contains_(x); }
  double ramp(const Vec3& x) const { return ramp_(x); }
  bool in_dem_domain(const Vec3& x) const;
  bool in_pure_dem_zone(const Vec3& x) const;
  // Whether the convex hull of `points` lies in the pure-DEM zone (a continuum tetrahedron that
  // can be left out): all of them in one convex piece of it (a shell's inner side, a slab's or a
  // cylinder's half-space). For a union of shells, vertices in the zone are not enough: a
  // tetrahedron across the re-entrant corner where two bands meet has them all there and
  // covers overlap.
  bool hull_in_pure_dem_zone(std::span<const Vec3> points) const;
  double alpha_d(const Vec3& x) const;
  double alpha_c(const Vec3& x) const { return 1.0 - alpha_d(x); }
  double mass_floor() const { return weighting_.mass_floor; }
  const Weighting& weighting() const { return weighting_; }
  const std::string& description() const { return description_; }
  double volume_inside(const Polyhedron& cell) const;
  // A box that contains the overlap (for a cylinder, not the tightest).
  const Box& bounds() const { return shape_.bounds; }

  static constexpr int kCylinderSides = 128;
  static constexpr int kMaxShells = 4;  // inclusion-exclusion takes 2 (2^n - 1) clipped volumes a cell

 private:
  struct Plane {  // the half-space n.x <= d, n unit
    Vec3 n;
    double d;
  };
  // The overlap = sum over the terms of sign x (the intersection of the term's half-spaces).
  struct Term {
    std::vector<Plane> planes;
    double sign = 1.0;
  };
  struct Polyhedral {
    std::vector<Term> terms;
    Box bounds;  // contains the overlap
  };
  // convex_pieces: ramps whose s <= 0 regions are convex and make up the pure-DEM zone
  // (empty: the ramp's own, a convex zone).
  OverlapZone(Membership contains, RampCoordinate ramp, Polyhedral shape, Weighting weighting, std::string description,
              std::vector<RampCoordinate> convex_pieces = {});
  static std::vector<Plane> box_planes(const Box& box);
  Membership contains_;
  RampCoordinate ramp_;
  std::vector<RampCoordinate> convex_pieces_;
  Polyhedral shape_;
  Weighting weighting_;
  std::string description_;
};

}  // namespace arlequin::coupling
