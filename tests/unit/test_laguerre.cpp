// SPDX-License-Identifier: GPL-3.0-or-later
// Laguerre cells (dem/laguerre_cells.hpp), the RDEF volume shares, against closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "common/convex_polyhedron.hpp"
#include "common/error.hpp"
#include "common/region.hpp"
#include "dem/laguerre_cells.hpp"
#include "support/omp_threads.hpp"

using namespace arlequin;

namespace {

// `count` spheres, centres uniform in the unit cube, radii uniform in [0.02, 0.08].
void random_spheres(unsigned seed, int count, std::vector<Vec3>& c, std::vector<double>& r) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(0.0, 1.0), rad(0.02, 0.08);
  for (int i = 0; i < count; ++i) {
    c.push_back({pos(rng), pos(rng), pos(rng)});
    r.push_back(rad(rng));
  }
}

// Cuts `cell` by the radical plane between spheres i and j (the part on i's side kept).
void clip_by_radical_plane(Polyhedron& cell, const std::vector<Vec3>& c, const std::vector<double>& r, std::size_t i, std::size_t j,
                           double tol) {
  const Vec3 e = c[j] - c[i];
  const double d = norm(e);
  clip(cell, e / d, (norm2(c[j]) - norm2(c[i]) - r[j] * r[j] + r[i] * r[i]) / (2.0 * d), int(j), tol);
}

}  // namespace

// Two touching spheres, R 1 and 0.5, centres 1.5 apart: the radical plane 2 (1.5) x = 1.5^2 -
// 0.25 + 1 is x = 1; in the box [-1, 2] x [-1, 1]^2 the cells are 2 x 2 x 2 and 1 x 2 x 2.
TEST(LaguerreCells, TwoSpheresSplitAtTheRadicalPlane) {
  const auto v = dem::laguerre_volumes({{0, 0, 0}, {1.5, 0, 0}}, {1.0, 0.5});
  EXPECT_NEAR(v[0], 8.0, 1e-12);
  EXPECT_NEAR(v[1], 4.0, 1e-12);
}

// A simple-cubic lattice of equal touching spheres: every cell, boundary ones included (the box
// is the spheres' bounding box), is the lattice cube (2R)^3.
TEST(LaguerreCells, CubicLatticeGivesTheLatticeCube) {
  const double R = 0.3;
  std::vector<Vec3> c;
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 6; ++i) c.push_back({2 * R * i, 2 * R * j, 2 * R * k});
  const auto v = dem::laguerre_volumes(c, std::vector<double>(c.size(), R));
  for (double vi : v) EXPECT_NEAR(vi, 8 * R * R * R, 1e-12);
}

// Random radii and positions: the cells tile the box, and a small sphere among large ones gets
// more than its share by R^3 (the point of using them).
TEST(LaguerreCells, RandomSpheresTileTheirBox) {
  std::vector<Vec3> c;
  std::vector<double> r;
  random_spheres(3, 400, c, r);
  const auto v = dem::laguerre_volumes(c, r);
  Vec3 lo = c[0], hi = c[0];
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], c[i][k] - r[i]), hi[k] = std::max(hi[k], c[i][k] + r[i]);
  double sum = 0.0;
  for (double vi : v) {
    EXPECT_GT(vi, 0.0);
    sum += vi;
  }
  EXPECT_NEAR(sum, (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z), 1e-10 * sum);
}

// Faces: in the two-sphere box above the shared face is the square x = 1, |y|, |z| <= 1 (area
// 4, centroid (1, 0, 0)), pointing out of each cell; the box faces are not listed.
TEST(LaguerreCells, TwoSpheresShareOneFace) {
  const auto f = dem::laguerre_faces({{0, 0, 0}, {1.5, 0, 0}}, {1.0, 0.5}, {1, 0});
  ASSERT_EQ(f.size(), 2u);
  ASSERT_EQ(f[0].size(), 1u);
  ASSERT_EQ(f[1].size(), 1u);
  EXPECT_EQ(f[0][0].neighbour, 0u);  // cell of sphere 1, listed first
  EXPECT_EQ(f[1][0].neighbour, 1u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(f[0][0].area[k], k == 0 ? -4.0 : 0.0, 1e-12);
    EXPECT_NEAR(f[1][0].area[k], k == 0 ? 4.0 : 0.0, 1e-12);
    EXPECT_NEAR(f[0][0].centroid[k], k == 0 ? 1.0 : 0.0, 1e-12);
  }
}

// In a simple-cubic lattice an interior cell has its six lattice neighbours' faces, (2R)^2 each
// at the bond midpoints, and their area vectors close (sum 0: the discrete divergence of a
// constant); a corner cell has three, and their sum is minus its three box faces.
TEST(LaguerreCells, CubicLatticeFacesAreTheBondCrossSections) {
  const double R = 0.3, a = 2 * R;
  std::vector<Vec3> c;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) c.push_back({a * i, a * j, a * k});
  const std::uint32_t interior = 1 + 4 * (1 + 4 * 1), corner = 0;
  const auto faces = dem::laguerre_faces(c, std::vector<double>(c.size(), R), {interior, corner});
  ASSERT_EQ(faces[0].size(), 6u);
  Vec3 sum{};
  for (const auto& f : faces[0]) {
    EXPECT_NEAR(norm(f.area), a * a, 1e-12);
    const Vec3 mid = 0.5 * (c[interior] + c[f.neighbour]);
    EXPECT_NEAR(norm(f.centroid - mid), 0.0, 1e-12);
    EXPECT_NEAR(dot(f.area, c[f.neighbour] - c[interior]), a * a * a, 1e-12);  // outward
    sum += f.area;
  }
  EXPECT_NEAR(norm(sum), 0.0, 1e-12);
  ASSERT_EQ(faces[1].size(), 3u);
  Vec3 corner_sum{};
  for (const auto& f : faces[1]) corner_sum += f.area;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(corner_sum[k], a * a, 1e-12);
}

// Random spheres: for a cell clear of the box, its faces are all neighbour faces, so the
// divergence theorem gives sum_f A_f = 0 and sum_f c_f (x) A_f = V I (int_dV x_k n_j dS =
// V delta_kj; exact with the faces' area centroids c_f, as x is linear on a face; the mean of a
// face's vertices would not do for these irregular polygons).
TEST(LaguerreCells, FacesCloseEveryInteriorCell) {
  std::vector<Vec3> c;
  std::vector<double> r;
  random_spheres(5, 300, c, r);
  std::vector<std::uint32_t> all(c.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  const auto volumes = dem::laguerre_volumes(c, r);
  const auto faces = dem::laguerre_faces(c, r, all);
  int interior = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    Vec3 sum{};
    double moment[3][3] = {}, area = 0.0;
    for (const auto& f : faces[i]) {
      sum += f.area, area += norm(f.area);
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j) moment[k][j] += f.centroid[k] * f.area[j];
    }
    if (norm(sum) > 1e-9 * area) continue;  // a box face closes this cell
    ++interior;
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(moment[k][j], k == j ? volumes[i] : 0.0, 1e-10 * volumes[i]) << "cell " << i;
  }
  EXPECT_GT(interior, 50);
}

// An impactor among small spheres (a radius far above the median, kept out of the search's
// bins): every cell equals its brute force (the box clipped by every other sphere's radical
// plane), and the cells tile the box.
TEST(LaguerreCells, ALargeSphereAmongSmallOnesGivesTheBruteForceCells) {
  std::vector<Vec3> c;
  std::vector<double> r;
  random_spheres(5, 300, c, r);
  c.push_back({0.5, 0.5, 1.3});  // an impactor above the cloud, radius 0.35 (> 4 x the median)
  r.push_back(0.35);
  Vec3 lo = c[0], hi = c[0];
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], c[i][k] - r[i]), hi[k] = std::max(hi[k], c[i][k] + r[i]);
  const auto v = dem::laguerre_volumes(c, r);
  double sum = 0.0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    // Brute force: the box clipped by the radical plane of every other sphere.
    Polyhedron cell = box_polyhedron(lo, hi, -1);
    for (std::size_t j = 0; j < c.size(); ++j)
      if (j != i) clip_by_radical_plane(cell, c, r, i, j, 1e-12);
    EXPECT_NEAR(v[i], volume(cell), 1e-12) << "sphere " << i;
    sum += v[i];
  }
  EXPECT_NEAR(sum, (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z), 1e-10 * sum);
}

// The search passes over the planes that cannot cut a cell (those clear of its bounding box, and
// all of them once the nearest left is beyond twice its extent) and looks far out through wide
// bins: every cell is the one the box clipped by every other sphere's radical plane, nearest
// first, gives, to round-off. The wide bins' shells clip in another order: 3.3e-16 at most, on a
// cell of 0.78 in a box of 2.5; the bound is 1e-15 of the box, where one plane missed moves a
// cell by a share of itself. Two slabs of spheres with a gap between them, so the cells facing
// the gap reach across it and their search far out (the cells of a coupling's overlap facing the
// continuum, among thousands of planes); an impactor above them (a large sphere, looked at on its
// own), and small spheres among large ones, whose cells the neighbours' power can leave empty.
TEST(LaguerreCells, PassingOverPlanesThatCannotCutGivesEveryPlanesCell) {
  std::vector<Vec3> c;
  std::vector<double> r;
  random_spheres(11, 400, c, r);
  for (Vec3& x : c) x.z = x.z < 0.5 ? 0.3 * x.z : 0.7 + 0.3 * x.z;  // slabs z in [0, 0.15], [0.85, 1]
  c.push_back({0.5, 0.5, 1.5});  // the impactor, radius 0.4
  r.push_back(0.4);
  Vec3 lo = c[0], hi = c[0];
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], c[i][k] - r[i]), hi[k] = std::max(hi[k], c[i][k] + r[i]);
  const double tol = 1e-12 * norm(hi - lo);
  const auto v = dem::laguerre_volumes(c, r);
  const double box_volume = volume(box_polyhedron(lo, hi, -1));
  int empty = 0, reaching = 0;
  std::vector<std::pair<double, std::size_t>> nearest_first;
  for (std::size_t i = 0; i < c.size(); ++i) {
    nearest_first.clear();
    for (std::size_t j = 0; j < c.size(); ++j)
      if (j != i) nearest_first.emplace_back(norm2(c[j] - c[i]), j);
    std::sort(nearest_first.begin(), nearest_first.end());
    Polyhedron cell = box_polyhedron(lo, hi, -1);
    for (const auto& [d2, j] : nearest_first) clip_by_radical_plane(cell, c, r, i, j, tol);
    EXPECT_NEAR(v[i], volume(cell), 1e-15 * box_volume) << "sphere " << i;
    empty += cell.empty();
    double extent = 0.0;
    for (const PolyFace& f : cell)
      for (const Vec3& p : f.pts) extent = std::max(extent, std::abs(p.z - c[i].z));
    reaching += extent > 0.3;
  }
  EXPECT_GT(empty, 0);      // small spheres with no cell
  EXPECT_GT(reaching, 50);  // cells across the gap
}

// Cells cut to a box `within` first (the coupling's overlap bounds) measure inside it what the
// whole cells measure there: the volume inside the box, each cell against its brute force.
TEST(LaguerreCells, CellsCutToABoxMeasureWhatTheWholeCellsDoInside) {
  std::vector<Vec3> c;
  std::vector<double> r;
  random_spheres(9, 300, c, r);
  const Box within{{0.2, 0.3, 0.25}, {0.7, 0.6, 0.5}};
  std::vector<std::uint32_t> inside;
  for (std::size_t i = 0; i < c.size(); ++i)
    if (Region{within}.contains(c[i])) inside.push_back(static_cast<std::uint32_t>(i));
  ASSERT_GT(inside.size(), 5u);
  const auto in_box = [&within](const Polyhedron& cell) {
    Polyhedron p = cell;
    for (int k = 0; k < 3; ++k) {
      Vec3 n{};
      n[k] = 1.0;
      clip(p, n, within.upper[k], -1, 1e-12);
      clip(p, -1.0 * n, -within.lower[k], -1, 1e-12);
    }
    return volume(p);
  };
  const auto whole = dem::laguerre_cell_measures(c, r, inside, in_box);
  const auto cut = dem::laguerre_cell_measures(c, r, inside, in_box, &within);
  double sum = 0.0;
  for (std::size_t k = 0; k < inside.size(); ++k) {
    EXPECT_NEAR(cut[k], whole[k], 1e-14) << "sphere " << inside[k];
    EXPECT_GT(cut[k], 0.0);
    sum += cut[k];
  }
  EXPECT_LT(sum, 0.5 * 0.3 * 0.25);  // the cells of the spheres inside cover part of the box
}

// The cells are built on the threads: the same bits on one and on two threads, and a failure (two
// spheres with one centre, here among 400 so that the threads take the cells) is the one a
// serial loop meets first, the lowest such cell.
TEST(LaguerreCells, CellsOnTheThreadsAreTheSerialOnesAndFailTheSameWay) {
  std::vector<Vec3> c;
  std::vector<double> r;
  random_spheres(5, 400, c, r);
#ifdef _OPENMP
  std::vector<double> v[2];
  for (int threads : {1, 2}) {
    const test::OmpThreads scope(threads);
    v[threads - 1] = dem::laguerre_volumes(c, r);
  }
  EXPECT_EQ(v[0], v[1]);
#endif
  c[300] = c[200];
  c[350] = c[120];
  try {
    dem::laguerre_volumes(c, r);
    ADD_FAILURE() << "spheres with one centre were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("spheres 120 and 350 share a centre"), std::string::npos) << e.what();
  }
}
