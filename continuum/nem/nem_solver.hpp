// NemSolver ("nem"): natural element method in the spirit of CNEM, on the nodes of the mesh.
// - Shape functions: Sibson or Laplace natural-neighbour coordinates of the 3D Delaunay
//   tessellation of the nodes (CGAL::Delaunay_triangulation_3 and
//   CGAL/natural_neighbor_coordinates_3.h). They form a partition of unity, reproduce linear
//   fields and are Kronecker-delta at the nodes. CGAL fails on the convex hull itself, so on a
//   flat boundary face the 2D coordinates of the face's own nodes are used (the limit of the
//   3D ones on a convex hull), and on an edge of the domain the 1D linear interpolant.
// - Integration: stabilised conforming nodal integration (SCNI; Chen, Wu, Yoon & You, IJNME 50
//   (2001)): per node i the Voronoi cell V_i clipped to the domain; the smoothed gradient
//   b_iJ = (1/|V_i|) int_{dV_i} phi_J n dS is evaluated with the midpoint rule on a fan
//   triangulation of every cell face (exact for linear fields, so grad of x = I to round-off and
//   the patch test is passed). Interior faces are integrated once and shared by both cells.
// - Lumped mass m_i = alpha(x_i) rho |V_i|.
// Supported domains: convex polyhedra (the mesh boundary must be the convex hull of the nodes;
// otherwise InputError). See continuum/README.md for what a constrained version needs.
#pragma once
#include <memory>

#include "continuum/continuum_solver.hpp"

namespace arlequin::continuum {

class NemSolver : public ContinuumSolver {
 public:
  explicit NemSolver(const ContinuumSettings& settings);
  ~NemSolver() override;
  static std::unique_ptr<ContinuumSolver> create(const ContinuumSettings& settings);

  InterpolationOperator interpolation(const std::vector<Vec3>& points) const override;
  // Clipped Voronoi cell volumes |V_i| (their sum is the domain volume).
  const std::vector<double>& cell_volumes() const { return cell_volume_; }

 protected:
  std::vector<double> weighted_lumped_mass(const ScalarFunction& alpha) const override;

 private:
  struct Geometry;  // CGAL triangulations and domain planes, confined to nem_solver.cpp
  std::unique_ptr<Geometry> geo_;
  std::vector<double> cell_volume_;
  std::vector<double> node_density_;
};

}  // namespace arlequin::continuum
