// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "common/error.hpp"
#include "continuum/mesh.hpp"
#include "support/omp_threads.hpp"
#include "continuum_test_util.hpp"

using namespace arlequin;
using namespace arlequin::continuum;
using arlequin::continuum::testing::mesh_path;

TEST(ContinuumMesh, GeoIsMeshedWithNamedGroups) {
  const Mesh m = Mesh::load({mesh_path("unit_cube.geo"), 0.5, 1, {}});
  EXPECT_EQ(m.order(), 1);
  EXPECT_NEAR(m.volume(), 1.0, 1e-12);
  EXPECT_EQ(m.group("domain").dim, 3);
  EXPECT_EQ(static_cast<int>(m.group("domain").tets.size()), m.num_tets());
  for (int n : m.group("xmax").nodes) EXPECT_NEAR(m.nodes()[n].x, 1.0, 1e-12);
  EXPECT_GT(m.group("boundary").triangles.size(), m.group("xmin").triangles.size());
  EXPECT_EQ(m.boundary_triangles().size(), m.group("boundary").triangles.size());
}

#ifdef _OPENMP
// gmsh applies its General.NumThreads (1, for reproducible meshes) to the whole process; a mesh
// load must leave the OpenMP thread count as it found it, or every later parallel loop of the
// scene (DEM bonds, continuum forces) runs on one thread.
TEST(ContinuumMesh, LoadingAMeshKeepsTheOpenMpThreadCount) {
  const test::OmpThreads three(3);
  Mesh::load({mesh_path("unit_cube.geo"), 0.5, 1, {}});
  EXPECT_EQ(omp_get_max_threads(), 3);
}
#endif

TEST(ContinuumMesh, QuadraticEdgeNodesAreMidpoints) {
  const Mesh m = Mesh::load({mesh_path("unit_cube.geo"), 0.5, 2, {}});
  ASSERT_EQ(m.order(), 2);
  for (int e = 0; e < m.num_tets(); ++e)
    for (int k = 0; k < 6; ++k) {
      const Vec3 mid = 0.5 * (m.nodes()[m.tet(e)[kTetEdges[k][0]]] + m.nodes()[m.tet(e)[kTetEdges[k][1]]]);
      EXPECT_LT(norm(m.nodes()[m.tet(e)[4 + k]] - mid), 1e-12);
    }
}

// An Arlequin cut (MeshSource::left_out, here x <= 0.5): exactly the tetrahedra with all four
// vertices in x <= 0.5 go, with the nodes only they used; the groups keep what is left of them
// and xmin, wholly in the cut, is dropped. The kept volume is the tetrahedra's, counted apart.
TEST(ContinuumMesh, LeftOutRegionCutsTetrahedraNodesAndGroups) {
  for (int order : {1, 2}) {
    const Mesh full = Mesh::load({mesh_path("unit_cube.geo"), 0.25, order, {}});
    const auto cut = [](const Vec3& x) { return x.x <= 0.5 + 1e-12; };
    const auto tet_in_cut = [&cut](const std::array<Vec3, 4>& v) { return std::all_of(v.begin(), v.end(), cut); };
    const Mesh m = Mesh::load({mesh_path("unit_cube.geo"), 0.25, order, tet_in_cut});
    int dropped = 0;
    double kept_volume = 0.0;
    for (int e = 0; e < full.num_tets(); ++e) {
      const int* t = full.tet(e);
      if (cut(full.nodes()[t[0]]) && cut(full.nodes()[t[1]]) && cut(full.nodes()[t[2]]) && cut(full.nodes()[t[3]]))
        ++dropped;
      else
        kept_volume += full.tet_volume(e);
    }
    ASSERT_GT(dropped, 0);
    EXPECT_EQ(m.tets_left_out(), dropped);
    EXPECT_EQ(m.num_tets(), full.num_tets() - dropped);
    EXPECT_NEAR(m.volume(), kept_volume, 1e-12);
    std::vector<char> used(m.num_nodes(), 0);
    for (int e = 0; e < m.num_tets(); ++e)
      for (int k = 0; k < m.nodes_per_tet(); ++k) used[m.tet(e)[k]] = 1;
    EXPECT_EQ(std::count(used.begin(), used.end(), 1), m.num_nodes());  // no orphan node
    EXPECT_FALSE(m.has_group("xmin"));
    EXPECT_EQ(m.group("xmax").nodes.size(), full.group("xmax").nodes.size());
    EXPECT_EQ(static_cast<int>(m.group("domain").tets.size()), m.num_tets());
    EXPECT_LT(m.group("ymin").triangles.size(), full.group("ymin").triangles.size());
  }
}

TEST(ContinuumMesh, ProblemsAreClearErrors) {
  const Mesh m = Mesh::load({mesh_path("unit_cube.geo"), 0.5, 1, {}});
  try {
    m.group("nonexistent");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("xmin"), std::string::npos);  // lists the known names
  }
  EXPECT_THROW(Mesh::load({mesh_path("no_such_mesh.geo"), 0.5, 1, {}}), InputError);
  // Inverted tetrahedron.
  std::vector<Vec3> x{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_NO_THROW(Mesh(1, x, {0, 1, 2, 3}, {}));
  EXPECT_THROW(Mesh(1, x, {0, 2, 1, 3}, {}), InputError);
  // Empty region.
  PhysicalGroup empty{"hole", 3, {}, {}, {}};
  EXPECT_THROW(Mesh(1, x, {0, 1, 2, 3}, {empty}), InputError);
}

// A surface group whose triangle stands on a node no tetrahedron uses (found by fuzz_mesh): an
// InputError naming the group and the node, not an out-of-range exception.
TEST(ContinuumMesh, SurfaceOnANodeNoTetrahedronUsesIsAClearError) {
  const std::string path = ::testing::TempDir() + "loose_triangle.msh";
  {
    std::ofstream f(path);
    f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
         "$PhysicalNames\n2\n2 1 \"loose\"\n3 2 \"body\"\n$EndPhysicalNames\n"
         "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n$EndNodes\n"
         "$Elements\n2\n1 2 2 1 1 1 2 5\n2 4 2 2 2 1 2 3 4\n$EndElements\n";
  }
  try {
    Mesh::load({path, 0.0, 1, {}});
    FAIL() << "a triangle on an unused node was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'loose'"), std::string::npos) << what;
    EXPECT_NE(what.find("node 5"), std::string::npos) << what;
  }
  std::remove(path.c_str());
}

TEST(ContinuumRegistry, NamesAndUnknown) {
  std::vector<std::string> names;
  for (const auto& e : continuum_solvers()) names.push_back(e.name);
  EXPECT_EQ(names, (std::vector<std::string>{"fe", "nem"}));
  const ContinuumSettings none;
  EXPECT_THROW(make_continuum_solver("xfem", none), InputError);
}

TEST(ContinuumMaterial, TransverselyIsotropicCompliance) {
  // Uniaxial stress along the (oblique) axis: strain along it sigma/E_L, across -nu_LT sigma/E_L.
  const Vec3 a = normalized(Vec3{1, 2, 2});
  const Material m = Material::transversely_isotropic(135e9, 9.5e9, 0.3, 0.35, 4e9, a, 1600);
  const Stiffness S = m.C.inverse();
  Eigen::Vector3d av(a.x, a.y, a.z);
  Eigen::Matrix3d sig = av * av.transpose();  // unit stress along a
  Voigt s;
  s << sig(0, 0), sig(1, 1), sig(2, 2), sig(1, 2), sig(0, 2), sig(0, 1);
  const Voigt e = S * s;
  Eigen::Matrix3d eps;
  eps << e[0], e[5] / 2, e[4] / 2, e[5] / 2, e[1], e[3] / 2, e[4] / 2, e[3] / 2, e[2];
  EXPECT_NEAR(av.dot(eps * av) * 135e9, 1.0, 1e-9);
  const Eigen::Vector3d t = av.cross(Eigen::Vector3d::UnitX()).normalized();
  EXPECT_NEAR(t.dot(eps * t) * 135e9, -0.3, 1e-9);
  // Isotropic limit equals the isotropic stiffness.
  const Material iso = Material::isotropic(2e11, 0.3, 7800);
  const Material ti = Material::transversely_isotropic(2e11, 2e11, 0.3, 0.3, 2e11 / 2.6, a, 7800);
  EXPECT_LT((iso.C - ti.C).norm(), 1e-6 * iso.C.norm());
}

TEST(ContinuumMaterial, OrthotropicComplianceAndItsLimits) {
  // Unit uniaxial stresses and shears in the x, y, z axes give the engineering constants back:
  // eps_i = 1 / E_i, eps_j = -nu_ij / E_i, gamma = 1 / G (a woven plate's constants).
  const std::array<double, 3> E{7.3e9, 4.8e9, 5e6}, G{4e6, 3e6, 2e6}, nu{0.01, 0.05, 0.3};
  const Material m = Material::orthotropic(E, G, nu, 338.0);
  const Stiffness S = m.C.inverse();
  EXPECT_NEAR(S(0, 0) * E[0], 1.0, 1e-12);
  EXPECT_NEAR(S(1, 1) * E[1], 1.0, 1e-12);
  EXPECT_NEAR(S(2, 2) * E[2], 1.0, 1e-10);
  EXPECT_NEAR(-S(1, 0) * E[0], nu[0], 1e-12);  // eps_y under sigma_x
  EXPECT_NEAR(-S(2, 0) * E[0], nu[1], 1e-12);  // eps_z under sigma_x
  EXPECT_NEAR(-S(2, 1) * E[1], nu[2], 1e-12);  // eps_z under sigma_y
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(S(3 + k, 3 + k) * G[k], 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(m.density, 338.0);
  // The isotropic limit, and a compliance that is not positive definite refused.
  const Material iso = Material::isotropic(2e11, 0.3, 7800);
  const Material ortho = Material::orthotropic({2e11, 2e11, 2e11}, {2e11 / 2.6, 2e11 / 2.6, 2e11 / 2.6}, {0.3, 0.3, 0.3}, 7800);
  EXPECT_LT((iso.C - ortho.C).norm(), 1e-6 * iso.C.norm());
  EXPECT_THROW(Material::orthotropic({1e9, 1e9, 1e9}, {1e8, 1e8, 1e8}, {0.9, 0.9, 0.9}, 1000), InputError);
  EXPECT_THROW(Material::orthotropic({1e9, 1e9, 1e9}, {1e8, 0.0, 1e8}, {0, 0, 0}, 1000), InputError);
}
