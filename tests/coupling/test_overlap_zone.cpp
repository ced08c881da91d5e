// SPDX-License-Identifier: GPL-3.0-or-later
// Overlap zone and weight functions: alpha_d + alpha_c = 1, shapes across the ramp, membership.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>

#include "common/error.hpp"
#include "coupling/overlap_zone.hpp"

using namespace arlequin;
using namespace arlequin::coupling;

TEST(CouplingOverlapZone, BoxSlabWeights) {
  const Box b{{2, 0, 0}, {6, 1, 1}};
  const OverlapZone lin = OverlapZone::box(b, 0, true, {WeightShape::linear, 0.05, 0.5});
  EXPECT_DOUBLE_EQ(lin.alpha_d({1, 0.5, 0.5}), 1.0);
  EXPECT_DOUBLE_EQ(lin.alpha_d({2, 0.5, 0.5}), 1.0);
  EXPECT_DOUBLE_EQ(lin.alpha_d({3, 0.5, 0.5}), 0.75);
  EXPECT_DOUBLE_EQ(lin.alpha_d({6, 0.5, 0.5}), 0.0);
  EXPECT_DOUBLE_EQ(lin.alpha_d({7, 0.5, 0.5}), 0.0);
  EXPECT_DOUBLE_EQ(lin.alpha_d({3, 0.5, 0.5}) + lin.alpha_c({3, 0.5, 0.5}), 1.0);
  EXPECT_TRUE(lin.contains({2, 0, 0}));
  EXPECT_TRUE(lin.contains({6, 1, 1}));
  EXPECT_FALSE(lin.contains({6.01, 0.5, 0.5}));
  const OverlapZone cub = OverlapZone::box(b, 0, true, {WeightShape::cubic, 0.05, 0.5});
  EXPECT_DOUBLE_EQ(cub.alpha_d({4, 0.5, 0.5}), 0.5);
  EXPECT_NEAR(cub.alpha_d({3, 0.5, 0.5}), 1.0 - (3 * 0.0625 - 2 * 0.015625), 1e-15);
  const OverlapZone con = OverlapZone::box(b, 0, false, {WeightShape::constant, 0.05, 0.3});
  EXPECT_DOUBLE_EQ(con.alpha_d({1, 0.5, 0.5}), 0.0);  // DEM on the upper side now
  EXPECT_DOUBLE_EQ(con.alpha_d({2, 0.5, 0.5}), 0.3);
  EXPECT_DOUBLE_EQ(con.alpha_d({6, 0.5, 0.5}), 0.3);
  EXPECT_DOUBLE_EQ(con.alpha_d({6.5, 0.5, 0.5}), 1.0);
}

// A point a round-off away from an overlap face (a mesh node at 2 (1 + 1e-16)) gets the weight
// of the face exactly: alpha_c = 0 on the DEM-side face, not 1e-16 (a natural-neighbour node
// mass that small once took the coupled critical step down to 1e-13 s). Domain tests agree.
TEST(CouplingOverlapZone, RoundOffOffAFaceGetsTheFaceWeight) {
  const Box b{{0.044, 0, 0}, {0.060, 1, 1}};
  for (WeightShape shape : {WeightShape::linear, WeightShape::cubic}) {
    const OverlapZone z = OverlapZone::box(b, 0, true, {shape, 0.05, 0.5});
    for (double x : {0.044 * (1 + 2e-16), 0.044 * (1 - 2e-16), 0.004 + 5 * 0.008}) {
      EXPECT_EQ(z.alpha_c({x, 0.5, 0.5}), 0.0) << x;
      EXPECT_TRUE(z.in_pure_dem_zone({x, 0.5, 0.5})) << x;
    }
    for (double x : {0.060 * (1 + 2e-16), 0.060 * (1 - 2e-16)}) {
      EXPECT_EQ(z.alpha_d({x, 0.5, 0.5}), 0.0) << x;
      EXPECT_TRUE(z.in_dem_domain({x, 0.5, 0.5})) << x;
    }
    EXPECT_FALSE(z.in_dem_domain({0.0601, 0.5, 0.5}));
    EXPECT_FALSE(z.in_pure_dem_zone({0.0441, 0.5, 0.5}));
  }
}

TEST(CouplingOverlapZone, ShellAndCylinder) {
  const OverlapZone shell = OverlapZone::shell({{-1, -1, -1}, {1, 1, 1}}, {{-3, -2, -1}, {3, 2, 1}}, {});
  EXPECT_DOUBLE_EQ(shell.alpha_d({0, 0, 0}), 1.0);
  EXPECT_FALSE(shell.contains({0, 0, 0}));
  EXPECT_DOUBLE_EQ(shell.alpha_d({2, 0, 0}), 0.5);   // half way from x = 1 to x = 3
  EXPECT_DOUBLE_EQ(shell.alpha_d({0, 1.5, 0}), 0.5);  // half way from y = 1 to y = 2
  EXPECT_TRUE(shell.contains({2, 0, 0.5}));
  EXPECT_DOUBLE_EQ(shell.alpha_d({3, 2, 0}), 0.0);
  const OverlapZone cyl = OverlapZone::cylinder({{0, 0, 0}, {0, 0, 1}, 1.0, 4.0}, true, {});
  EXPECT_DOUBLE_EQ(cyl.alpha_d({0, 0, 1}), 0.75);
  EXPECT_TRUE(cyl.contains({0.5, 0, 1}));
  EXPECT_FALSE(cyl.contains({1.5, 0, 1}));
}

// A band along x from 0 to 10, across z within 1 of z = 0, its overlap 0.25 wide: the weight ramps
// on both faces and at both ends, and beyond `to` the DEM domain ends (a band that ends inside a
// body is tied to it there, not left running on into it).
TEST(CouplingOverlapZone, BandRampsOnItsFacesAndAtBothEnds) {
  const OverlapZone band = OverlapZone::band(2, 0.0, 1.0, 0.25, 0, 0.0, 10.0, {});
  EXPECT_DOUBLE_EQ(band.alpha_d({5, 0, 0}), 1.0);
  EXPECT_DOUBLE_EQ(band.alpha_d({5, 70, 0.875}), 0.5);  // half way across the upper face's overlap, any y
  EXPECT_DOUBLE_EQ(band.alpha_d({5, -3, -0.9375}), 0.25);
  EXPECT_DOUBLE_EQ(band.alpha_d({0.125, 0, 0}), 0.5);  // the end at `from`
  EXPECT_DOUBLE_EQ(band.alpha_d({9.875, 0, 0}), 0.5);  // and the end at `to`
  EXPECT_DOUBLE_EQ(band.alpha_d({9.8125, 0, 0.9375}), 0.25);  // the corner: the larger ramp
  EXPECT_TRUE(band.contains({9.9, 0, 0}));
  for (const Vec3& x : {Vec3{10.5, 0, 0}, Vec3{-0.5, 0, 0}, Vec3{5, 0, 1.5}}) {
    EXPECT_EQ(band.alpha_d(x), 0.0) << x[0] << " " << x[2];
    EXPECT_FALSE(band.in_dem_domain(x)) << x[0] << " " << x[2];
  }
  EXPECT_TRUE(band.in_pure_dem_zone({9.7, 0, 0.7}));
  EXPECT_THROW(OverlapZone::band(2, 0.0, 1.0, 1.0, 0, 0.0, 10.0, {}), InputError);  // no pure-DEM core across
  EXPECT_THROW(OverlapZone::band(2, 0.0, 1.0, 0.25, 0, 0.0, 0.5, {}), InputError);  // none along
  EXPECT_THROW(OverlapZone::band(0, 0.0, 1.0, 0.25, 0, 0.0, 10.0, {}), InputError);  // along its own axis
}

// A coupled DE's share of the overlap (coupling_operators.hpp): the part of its cell inside,
// against the volumes of the clipped boxes worked out by hand.
TEST(CouplingOverlapZone, CellVolumeInsideTheOverlap) {
  auto cube = [](const Vec3& centre, double side) {
    return box_polyhedron(centre - Vec3{side / 2, side / 2, side / 2}, centre + Vec3{side / 2, side / 2, side / 2}, 0);
  };
  const OverlapZone slab = OverlapZone::box({{0, -5, -5}, {1, 5, 5}}, 0, true, {});
  EXPECT_NEAR(slab.volume_inside(cube({0.5, 0, 0}, 0.5)), 0.125, 1e-15);     // inside: whole
  EXPECT_NEAR(slab.volume_inside(cube({0, 0, 0}, 0.5)), 0.0625, 1e-15);      // on the DEM-side face: half
  EXPECT_NEAR(slab.volume_inside(cube({1, 0.3, 0}, 0.5)), 0.0625, 1e-15);    // on the continuum-side face: half
  EXPECT_NEAR(slab.volume_inside(cube({0.9, 0, 0}, 0.4)), 0.3 * 0.16, 1e-15);  // 0.3 of its 0.4 length inside
  EXPECT_EQ(slab.volume_inside(cube({2, 0, 0}, 0.5)), 0.0);                 // outside
  // Shell: a unit cube with a corner in the inner box keeps 1 - 1/8.
  const OverlapZone shell = OverlapZone::shell({{-1, -1, -1}, {1, 1, 1}}, {{-3, -3, -3}, {3, 3, 3}}, {});
  EXPECT_NEAR(shell.volume_inside(cube({1, 1, 1}, 1.0)), 0.875, 1e-14);
  EXPECT_NEAR(shell.volume_inside(cube({3, 0, 0}, 1.0)), 0.5, 1e-14);
  EXPECT_EQ(shell.volume_inside(cube({0, 0, 0}, 1.0)), 0.0);
  // Cylinder of radius 1 along z from 0 to 2: a box around it cut at z = 1 keeps the
  // circumscribed polygon's prism of height 1, n tan(pi / n) r^2, within 2.1e-4 of pi.
  const OverlapZone cyl = OverlapZone::cylinder({{0, 0, 0}, {0, 0, 1}, 1.0, 2.0}, true, {});
  const double n = OverlapZone::kCylinderSides;
  const double prism = cyl.volume_inside(box_polyhedron({-2, -2, -1}, {2, 2, 1}, 0));
  EXPECT_NEAR(prism, n * std::tan(std::numbers::pi / n), 1e-12);
  EXPECT_NEAR(prism / std::numbers::pi - 1.0, 2.0e-4, 0.1e-4);
  EXPECT_NEAR(cyl.volume_inside(cube({0, 0, 1}, 0.5)), 0.125, 1e-15);  // well inside the side
}

TEST(CouplingOverlapZone, BadInputIsAnInputError) {
  EXPECT_THROW(OverlapZone::box({{0, 0, 0}, {0, 1, 1}}, 0, true, {}), InputError);
  EXPECT_THROW(OverlapZone::box({{0, 0, 0}, {1, 1, 1}}, 0, true, {WeightShape::linear, 0.0, 0.5}), InputError);
  EXPECT_THROW(OverlapZone::shell({{0, 0, 0}, {2, 2, 2}}, {{1, 1, 1}, {3, 3, 3}}, {}), InputError);
  EXPECT_THROW(weight_shape_from_name("quadratic"), InputError);
  EXPECT_EQ(weight_shape_from_name("cubic"), WeightShape::cubic);
}

// A cross of two bands in the plane z in [0, 1] (a woven target's DEM along its principal yarns):
// band A along x (inner |y| <= 1, outer |y| <= 2), band B along y (inner |x| <= 1, outer
// |x| <= 2), each 20 long. The DEM weight is the larger of the two bands' (s the smaller ramp),
// and a cell's share of the overlap is its volume in the union of the outer boxes less that in
// the union of the inner ones, against volumes worked out by hand.
TEST(CouplingOverlapZone, UnionOfShellsIsACrossOfBands) {
  const Box inner_a{{-10, -1, 0}, {10, 1, 1}}, outer_a{{-10, -2, 0}, {10, 2, 1}};
  const Box inner_b{{-1, -10, 0}, {1, 10, 1}}, outer_b{{-2, -10, 0}, {2, 10, 1}};
  const OverlapZone cross = OverlapZone::shells({{inner_a, outer_a}, {inner_b, outer_b}}, {});
  EXPECT_DOUBLE_EQ(cross.alpha_d({5, 0, 0.5}), 1.0);   // inside band A's core
  EXPECT_DOUBLE_EQ(cross.alpha_d({0, 5, 0.5}), 1.0);   // inside band B's core
  EXPECT_DOUBLE_EQ(cross.alpha_d({5, 1.5, 0.5}), 0.5);  // half way across band A's overlap
  EXPECT_DOUBLE_EQ(cross.alpha_d({1.5, 1.5, 0.5}), 0.5);  // in both overlaps: the larger weight
  EXPECT_DOUBLE_EQ(cross.alpha_d({1.25, 1.75, 0.5}), 0.75);
  EXPECT_DOUBLE_EQ(cross.alpha_d({0.5, 1.75, 0.5}), 1.0);  // band B's core, band A's overlap
  EXPECT_DOUBLE_EQ(cross.alpha_d({5, 5, 0.5}), 0.0);    // between the arms: continuum
  EXPECT_TRUE(cross.contains({5, 1.5, 0.5}));
  EXPECT_TRUE(cross.contains({1.5, 1.5, 0.5}));
  EXPECT_FALSE(cross.contains({0.5, 1.75, 0.5}));
  EXPECT_FALSE(cross.contains({5, 5, 0.5}));
  EXPECT_TRUE(cross.in_pure_dem_zone({0, 5, 0.5}));
  EXPECT_FALSE(cross.in_dem_domain({5, 5, 0.5}));
  auto cell = [](double x0, double y0, double x1, double y1) { return box_polyhedron({x0, y0, 0}, {x1, y1, 1}, 0); };
  // The corner square between the arms' overlaps, [1, 2]^2: all overlap.
  EXPECT_NEAR(cross.volume_inside(cell(1, 1, 2, 2)), 1.0, 1e-14);
  // [0, 3]^2: the L of the outer arms there, 2 x 3 + 3 x 2 - 2 x 2 = 8, less the inner L,
  // 1 x 3 + 3 x 1 - 1 x 1 = 5.
  EXPECT_NEAR(cross.volume_inside(cell(0, 0, 3, 3)), 3.0, 1e-14);
  // Across band A only, far from B: the two 1-wide strips of its overlap.
  EXPECT_NEAR(cross.volume_inside(cell(5, -3, 6, 3)), 2.0, 1e-14);
  EXPECT_EQ(cross.volume_inside(cell(4, 4, 6, 6)), 0.0);
  // A tetrahedron across the re-entrant corner at (1, 1): each vertex in a band's core, the edge
  // between the first two through (1.4, 1.4), in both overlaps. It is not left out of the mesh;
  // one in band A's core is.
  const std::array<Vec3, 4> across{Vec3{1.9, 0.9, 0}, Vec3{0.9, 1.9, 0}, Vec3{1.9, 0.9, 1}, Vec3{0.5, 0.5, 1}};
  for (const Vec3& v : across) EXPECT_TRUE(cross.in_pure_dem_zone(v));
  EXPECT_FALSE(cross.hull_in_pure_dem_zone(across));
  EXPECT_TRUE(cross.hull_in_pure_dem_zone(std::array<Vec3, 4>{Vec3{5, 0, 0}, Vec3{6, 0.9, 0}, Vec3{5, -0.9, 1}, Vec3{0.5, 0.5, 1}}));
  // One shell is the shell, to the bit.
  const OverlapZone one = OverlapZone::shells({{inner_a, outer_a}}, {}), shell = OverlapZone::shell(inner_a, outer_a, {});
  EXPECT_EQ(one.description(), shell.description());
  EXPECT_EQ(one.volume_inside(cell(1, 1, 2, 2)), shell.volume_inside(cell(1, 1, 2, 2)));
  // Bad input: none, too many, one not nested.
  EXPECT_THROW(OverlapZone::shells({}, {}), InputError);
  EXPECT_THROW(OverlapZone::shells(std::vector<std::pair<Box, Box>>(OverlapZone::kMaxShells + 1, {inner_a, outer_a}), {}), InputError);
  EXPECT_THROW(OverlapZone::shells({{inner_a, outer_a}, {outer_b, inner_b}}, {}), InputError);
}
