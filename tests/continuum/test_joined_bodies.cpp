// SPDX-License-Identifier: GPL-3.0-or-later
// Bodies meshed apart and joined by MeshSource::joined (continuum/mesh.hpp): the coupled DCB's
// two arms (meshes/dcb_arms_coarse.geo, the same structured nodes on both sides of the
// mid-plane z = h) become one body where they are joined.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "common/error.hpp"
#include "continuum_test_util.hpp"

using namespace arlequin;
using namespace arlequin::continuum;
using namespace arlequin::continuum::testing;

namespace {

constexpr double kArmThickness = 1.5e-3;  // h of meshes/dcb_arms_layout.geo: the mid-plane is z = h

bool on_mid_plane(const Vec3& x) { return std::abs(x.z - kArmThickness) < 1e-9; }

MeshSource arms(const std::string& file, int order, std::function<bool(const Vec3&)> joined = {}) {
  MeshSource source{mesh_path(file), 0.0, order, {}};
  source.joined = std::move(joined);
  return source;
}

// Node index by position (rounded to 1e-9 m), to compare two meshes of the same nodes.
std::map<std::array<long long, 3>, int> index_by_position(const std::vector<Vec3>& nodes) {
  std::map<std::array<long long, 3>, int> index;
  for (int n = 0; n < static_cast<int>(nodes.size()); ++n)
    index[{std::llround(nodes[n].x * 1e9), std::llround(nodes[n].y * 1e9), std::llround(nodes[n].z * 1e9)}] = n;
  return index;
}

}  // namespace

// Joined beyond x = 30 mm, each pair of mid-plane nodes there becomes one node, shared by both
// arms' groups; nothing else changes (tetrahedra, volume, the other nodes).
TEST(ContinuumJoin, CoincidentNodesInTheRegionBecomeOne) {
  for (int order : {1, 2}) {
    const Mesh apart = Mesh::load(arms("dcb_arms_coarse.geo", order));
    const auto beyond = [](const Vec3& x) { return x.x >= 0.030 - 1e-9; };
    const Mesh joined = Mesh::load(arms("dcb_arms_coarse.geo", order, beyond));
    const long pairs = std::count_if(apart.nodes().begin(), apart.nodes().end(),
                                     [&](const Vec3& x) { return on_mid_plane(x) && beyond(x); }) / 2;
    // 16 node planes along x (30 to 45 mm) of 7 nodes across; P2 has 31 of 13.
    EXPECT_EQ(pairs, order == 1 ? 16 * 7 : 31 * 13) << "order " << order;
    EXPECT_EQ(joined.nodes_joined(), pairs) << "order " << order;
    EXPECT_EQ(apart.nodes_joined(), 0);
    EXPECT_EQ(joined.num_nodes(), apart.num_nodes() - pairs) << "order " << order;
    EXPECT_EQ(joined.num_tets(), apart.num_tets());
    EXPECT_NEAR(joined.volume(), apart.volume(), 1e-12 * apart.volume());
    std::vector<int> shared;
    const auto& lower = joined.group("lower").nodes;
    const auto& upper = joined.group("upper").nodes;
    std::set_intersection(lower.begin(), lower.end(), upper.begin(), upper.end(), std::back_inserter(shared));
    EXPECT_EQ(static_cast<long>(shared.size()), pairs) << "order " << order;
    for (int n : shared) EXPECT_TRUE(on_mid_plane(joined.nodes()[n]) && beyond(joined.nodes()[n]));
    // The pre-crack's faces stay apart: the mid-plane before x = 30 mm is boundary on both sides.
    long faces_apart = 0;
    for (const auto& f : joined.boundary_triangles())
      faces_apart += on_mid_plane(joined.nodes()[f[0]]) && on_mid_plane(joined.nodes()[f[1]]) && on_mid_plane(joined.nodes()[f[2]]);
    EXPECT_EQ(faces_apart, 2 * 30 * 6 * 2) << "order " << order;  // two sides of 30 x 6 squares of two triangles
    // A region starting between two node planes joins from the next vertex plane on: a P2 edge
    // node is joined with both of its edge's vertices or not at all.
    const Mesh from_mid_edge = Mesh::load(arms("dcb_arms_coarse.geo", order, [](const Vec3& x) { return x.x >= 0.0295; }));
    EXPECT_EQ(from_mid_edge.nodes_joined(), pairs) << "order " << order;
  }
}

// Two bodies whose faces touch without the same nodes (different structured counts) would be
// joined at their corners only: refused, naming the region.
TEST(ContinuumJoin, FacesWithDifferentMeshesAreRefused) {
  MeshSource source{mesh_path("two_blocks_unmatched.geo"), 0.0, 1, {}};
  source.joined = [](const Vec3&) { return true; };
  source.joined_name = "the test's region";
  try {
    Mesh::load(source);
    FAIL() << "joining unmatched faces was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the test's region"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("surface meshes differ"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(Mesh::load({mesh_path("two_blocks_unmatched.geo"), 0.0, 1, {}}));
}

// The two arms joined over the whole mid-plane are the fused mesh (dcb_arms_coarse_fused.geo):
// the same nodes and elements, so the same motion. Both are pulled apart at the load strips for
// 200 explicit steps; every node's displacement agrees to round-off for fe P1 and P2, within
// 1e-13 of the largest (measured: 2.0e-15 and 4.4e-15, the sums taken in another order), and
// for nem within 5e-3 (measured: 1.8e-3, at the corners of the end face x = 0). Natural neighbours
// on a structured grid meet many cospherical nodes, whose cells depend on the order the nodes
// come in, which joining changes; the largest differences are on the outer boundary, none on
// the joined face.
TEST(ContinuumJoin, JoinedArmsMoveAsTheFusedBody) {
  struct Method {
    const char* name;
    int order;
  };
  for (const Method method : {Method{"fe", 1}, Method{"fe", 2}, Method{"nem", 1}}) {
    // One step for both (the critical step's Lanczos estimate depends on the nodes' order).
    double dt = 0.0;
    const auto run = [&](const std::string& file, bool join) {
      ContinuumSettings s = settings(file, 0.0, method.order, Material::isotropic(110e9, 0.24, 1600));
      if (join) s.mesh.joined = [](const Vec3&) { return true; };
      auto solver = make_continuum_solver(method.name, s);
      solver->add_traction("load_top", [](const Vec3&, double) { return Vec3{0, 0, 1e6}; });
      solver->add_traction("load_bottom", [](const Vec3&, double) { return Vec3{0, 0, -1e6}; });
      if (dt == 0.0) dt = 0.9 * solver->critical_time_step();
      solver->compute_forces();
      for (int k = 0; k < 200; ++k) solver->step(dt);
      return solver;
    };
    const auto fused = run("dcb_arms_coarse_fused.geo", false);
    const auto joined = run("dcb_arms_coarse.geo", true);
    ASSERT_EQ(joined->num_nodes(), fused->num_nodes()) << method.name << " P" << method.order;
    const auto fused_index = index_by_position(fused->nodes());
    double largest = 0.0, difference = 0.0;
    for (int n = 0; n < joined->num_nodes(); ++n) {
      const Vec3& x = joined->nodes()[n];
      const auto it = fused_index.find({std::llround(x.x * 1e9), std::llround(x.y * 1e9), std::llround(x.z * 1e9)});
      ASSERT_NE(it, fused_index.end()) << "node at (" << x.x << ", " << x.y << ", " << x.z << ")";
      for (int c = 0; c < 3; ++c) {
        largest = std::max(largest, std::abs(fused->displacement()[3 * it->second + c]));
        difference = std::max(difference, std::abs(joined->displacement()[3 * n + c] - fused->displacement()[3 * it->second + c]));
      }
    }
    EXPECT_GT(largest, 1e-9) << method.name;  // the strips moved
    EXPECT_LT(difference, (method.name == std::string("nem") ? 5e-3 : 1e-13) * largest) << method.name << " P" << method.order;
  }
}

// Arms joined beyond x = 30 mm only: one body with a slit along the pre-crack, which ends inside
// it. Natural neighbours cut it into convex pieces that meet on whole faces (the slit's plane,
// and the plane across the slit's end, nem_solver.cpp; without the latter the body is refused).
// Their shape functions are a partition of unity and reproduce linear fields at every point, to
// round-off, and a point beside the slit takes the nodes of its own arm only.
TEST(ContinuumJoin, ASlitEndingInsideTheBodyIsCutIntoPiecesThatMeetOnWholeFaces) {
  ContinuumSettings s = settings("dcb_arms_coarse.geo", 0.0, 1, Material::isotropic(110e9, 0.24, 1600));
  s.mesh.joined = [](const Vec3& x) { return x.x >= 0.030 - 1e-9; };
  auto nem = make_continuum_solver("nem", s);
  ASSERT_EQ(nem->mesh().nodes_joined(), 16 * 7);
  std::vector<Vec3> points;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> along(0.0, 0.045), across(0.0, 0.006), through(0.0, 2 * kArmThickness);
  for (int i = 0; i < 400; ++i) points.push_back({along(rng), across(rng), through(rng)});
  const InterpolationOperator N = nem->interpolation(points);
  double worst_sum = 0.0, worst_position = 0.0;
  int beside_the_slit = 0;
  for (std::size_t p = 0; p < points.size(); ++p) {
    const bool slit = points[p].x < 0.029, upper = points[p].z > kArmThickness;
    beside_the_slit += slit;
    double sum = 0.0;
    Vec3 x{};
    for (InterpolationOperator::InnerIterator it(N, static_cast<long>(p)); it; ++it) {
      sum += it.value();
      x += it.value() * nem->nodes()[it.col()];
      const double z = nem->nodes()[it.col()].z;
      if (slit) {
        EXPECT_TRUE(upper ? z >= kArmThickness - 1e-12 : z <= kArmThickness + 1e-12) << "point " << p << " takes node " << it.col();
      }
    }
    worst_sum = std::max(worst_sum, std::abs(sum - 1.0));
    worst_position = std::max(worst_position, norm(x - points[p]));
  }
  EXPECT_GT(beside_the_slit, 200);
  EXPECT_LT(worst_sum, 1e-12);
  EXPECT_LT(worst_position, 1e-12 * 0.045);
}
