// SPDX-License-Identifier: GPL-3.0-or-later
// Our natural-neighbour coordinates (continuum/nem/natural_neighbours.hpp) against CGAL's, an
// independent implementation of the same definitions; against linear reproduction where CGAL
// has none (Laplace in 2D); and their bits against the insertion order of the triangulation.
#include <CGAL/natural_neighbor_coordinates_2.h>
#include <CGAL/natural_neighbor_coordinates_3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "continuum/nem/natural_neighbours.hpp"

using namespace arlequin;
using namespace arlequin::continuum::nem;

namespace {

using P3 = Kernel::Point_3;
using P2 = Kernel::Point_2;

// Nodes: the corners of the unit cube (so the hull is the cube) and either random points or a
// regular grid (every cube of eight cospherical nodes: the degenerate case of structured meshes).
std::vector<Vec3> cloud(bool grid, unsigned seed) {
  std::vector<Vec3> x;
  if (grid) {
    for (int i = 0; i <= 4; ++i)
      for (int j = 0; j <= 4; ++j)
        for (int k = 0; k <= 4; ++k) x.push_back({0.25 * i, 0.25 * j, 0.25 * k});
    return x;
  }
  for (int c = 0; c < 8; ++c) x.push_back({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0, 1);
  for (int i = 0; i < 300; ++i) x.push_back({uni(rng), uni(rng), uni(rng)});
  return x;
}

// The triangulation of x, its points inserted in the order `order` (node numbers stay).
template <class Dt, class Point>
void build(Dt& dt, const std::vector<Point>& x, const std::vector<int>& order) {
  std::vector<std::pair<Point, int>> pts;
  for (int i : order) pts.push_back({x[i], i});
  dt.insert(pts.begin(), pts.end());
}

std::vector<int> identity(size_t n) {
  std::vector<int> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = static_cast<int>(i);
  return order;
}

// Random points inside the cube, and points of the grid's degenerate places (on its planes and
// lines between nodes, where Delaunay facets and edges lie, and at cell centres, where eight
// nodes are cospherical): those exercise the symbolic perturbation of the conflict tests.
std::vector<Vec3> queries(unsigned seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0.02, 0.98);
  std::vector<Vec3> q;
  for (int i = 0; i < count; ++i) q.push_back({uni(rng), uni(rng), uni(rng)});
  for (const Vec3& special : {Vec3{0.25, 0.3, 0.4}, Vec3{0.5, 0.5, 0.37}, Vec3{0.375, 0.375, 0.375}, Vec3{0.625, 0.125, 0.875},
                              Vec3{0.5, 0.375, 0.625}, Vec3{0.3125, 0.3125, 0.25}})
    q.push_back(special);
  return q;
}

// Every cell's scratch index is back to "outside" after a query.
bool all_cells_unmarked(const Dt3& dt) {
  for (auto c = dt.all_cells_begin(); c != dt.all_cells_end(); ++c)
    if (c->info().index != -1) return false;
  return true;
}

std::map<int, double> cgal_3d(const Dt3& dt, const Vec3& q, Coordinates kind) {
  std::vector<std::pair<Dt3::Vertex_handle, double>> nn;
  double norm_coeff = 0;
  const P3 Q(q.x, q.y, q.z);
  const auto r = kind == Coordinates::sibson ? CGAL::sibson_natural_neighbor_coordinates_3(dt, Q, std::back_inserter(nn), norm_coeff)
                                             : CGAL::laplace_natural_neighbor_coordinates_3(dt, Q, std::back_inserter(nn), norm_coeff);
  EXPECT_TRUE(r.third);
  std::map<int, double> out;
  for (const auto& [v, c] : nn) out[v->info()] += c / norm_coeff;
  return out;
}

void expect_same_values(const Coords& ours, std::map<int, double> theirs, const std::string& what) {
  for (const auto& [J, value] : ours) {
    theirs[J] -= value;  // a node CGAL does not list counts as 0 there
  }
  for (const auto& [J, difference] : theirs) EXPECT_NEAR(difference, 0.0, 1e-12) << what << " node " << J;
}

void expect_linear_reproduction(const Coords& phi, const std::vector<Vec3>& x, const Vec3& q, const std::string& what) {
  double sum = 0;
  Vec3 r{};
  for (const auto& [J, value] : phi) sum += value, r += value * x[J];
  EXPECT_NEAR(sum, 1.0, 1e-13) << what;
  EXPECT_LT(norm(r - q), 1e-13) << what;
}

}  // namespace

TEST(NaturalNeighbours, ThreeDMatchCgal) {
  for (bool grid : {false, true}) {
    const std::vector<Vec3> x = cloud(grid, 1);
    std::vector<P3> p;
    for (const Vec3& v : x) p.push_back({v.x, v.y, v.z});
    Dt3 dt;
    build(dt, p, identity(p.size()));
    for (Coordinates kind : {Coordinates::sibson, Coordinates::laplace}) {
      const std::string what = std::string(grid ? "grid " : "random ") + (kind == Coordinates::sibson ? "sibson" : "laplace");
      Coords phi;
      for (const Vec3& q : queries(2, 200)) {
        ASSERT_TRUE(natural_neighbour_coordinates(dt, q, kind, phi)) << what;
        EXPECT_TRUE(std::is_sorted(phi.begin(), phi.end())) << what;
        expect_same_values(phi, cgal_3d(dt, q, kind), what);
        expect_linear_reproduction(phi, x, q, what);
      }
      EXPECT_TRUE(all_cells_unmarked(dt)) << what;
      ASSERT_TRUE(natural_neighbour_coordinates(dt, x[17], kind, phi));  // at a node: its own function only
      ASSERT_EQ(phi.size(), 1u);
      EXPECT_EQ(phi[0].first, 17);
      EXPECT_FALSE(natural_neighbour_coordinates(dt, Vec3{1.5, 0.5, 0.5}, kind, phi)) << "outside the hull";
      EXPECT_FALSE(natural_neighbour_coordinates(dt, Vec3{1.0, 0.3, 0.6}, kind, phi)) << "on a hull face";
      EXPECT_FALSE(natural_neighbour_coordinates(dt, Vec3{1.0, 0.0, 0.6}, kind, phi)) << "on a hull edge";
      EXPECT_TRUE(all_cells_unmarked(dt)) << what;
    }
  }
}

TEST(NaturalNeighbours, TwoDMatchCgalAndReproduceLinearFields) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uni(0, 1);
  std::vector<P2> p{{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  for (int i = 0; i < 100; ++i) p.push_back({uni(rng), uni(rng)});
  std::vector<Vec3> x;
  for (const P2& v : p) x.push_back({v.x(), v.y(), 0.0});
  Dt2 dt;
  build(dt, p, identity(p.size()));
  Coords phi;
  for (const Vec3& q3 : queries(5, 200)) {
    const P2 q(q3.x, q3.y);
    const Vec3 q_plane{q3.x, q3.y, 0.0};
    ASSERT_TRUE(natural_neighbour_coordinates(dt, q, Coordinates::sibson, phi));
    struct NodeOf {
      std::pair<int, double> operator()(const std::pair<Dt2::Vertex_handle, double>& vc) const { return {vc.first->info(), vc.second}; }
    };
    std::vector<std::pair<int, double>> nn;
    const auto r = CGAL::natural_neighbor_coordinates_2(dt, q, std::back_inserter(nn), NodeOf());
    ASSERT_TRUE(r.third);
    std::map<int, double> theirs;
    for (const auto& [J, c] : nn) theirs[J] += c / r.second;
    expect_same_values(phi, theirs, "2D sibson");
    expect_linear_reproduction(phi, x, q_plane, "2D sibson");
    ASSERT_TRUE(natural_neighbour_coordinates(dt, q, Coordinates::laplace, phi));
    expect_linear_reproduction(phi, x, q_plane, "2D laplace");
    for (const auto& [J, value] : phi) EXPECT_GT(value, 0.0);
  }
  // Laplace at the centre of a square of four nodes with no other natural neighbour: 1/4 each.
  Dt2 square;
  build(square, std::vector<P2>{{0, 0}, {2, 0}, {0, 2}, {2, 2}}, identity(4));
  ASSERT_TRUE(natural_neighbour_coordinates(square, P2(1.0, 1.0), Coordinates::laplace, phi));
  ASSERT_EQ(phi.size(), 4u);
  for (const auto& [J, value] : phi) EXPECT_NEAR(value, 0.25, 1e-15);
}

// The bits depend on the nodes and the query only: the same triangulation built from the nodes
// in another order (other cell addresses and vertex orders) gives the same values.
TEST(NaturalNeighbours, SameBitsWhateverTheInsertionOrder) {
  for (bool grid : {false, true}) {
    const std::vector<Vec3> x = cloud(grid, 6);
    std::vector<P3> p;
    for (const Vec3& v : x) p.push_back({v.x, v.y, v.z});
    std::vector<int> shuffled = identity(p.size());
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(7));
    Dt3 a, b;
    build(a, p, identity(p.size()));
    build(b, p, shuffled);
    // In 2D: the grid's bottom face, or the square's corners and the random nodes' (x, y).
    std::vector<P2> p2;
    for (size_t i = 0; i < x.size(); ++i)
      if (grid ? x[i].z == 0.0 : (i < 4 || i >= 8)) p2.push_back({x[i].x, x[i].y});
    std::vector<int> shuffled2 = identity(p2.size());
    std::shuffle(shuffled2.begin(), shuffled2.end(), std::mt19937(8));
    Dt2 a2, b2;
    build(a2, p2, identity(p2.size()));
    build(b2, p2, shuffled2);
    for (Coordinates kind : {Coordinates::sibson, Coordinates::laplace}) {
      Coords pa, pb;
      for (const Vec3& q : queries(9, 200)) {
        ASSERT_TRUE(natural_neighbour_coordinates(a, q, kind, pa));
        ASSERT_TRUE(natural_neighbour_coordinates(b, q, kind, pb));
        EXPECT_EQ(pa, pb) << (grid ? "grid" : "random");
        ASSERT_TRUE(natural_neighbour_coordinates(a2, P2(q.x, q.y), kind, pa));
        ASSERT_TRUE(natural_neighbour_coordinates(b2, P2(q.x, q.y), kind, pb));
        EXPECT_EQ(pa, pb) << (grid ? "grid" : "random") << " 2D";
      }
    }
  }
}
