// SPDX-License-Identifier: GPL-3.0-or-later
// FeSolver ("fe"): Lagrange tetrahedra, linear (4 nodes) or quadratic (10 nodes) from the mesh
// order, straight-sided (affine geometry).
// Integration: P1 one point (exact, constant strain); P2 the symmetric 4-point degree-2 rule,
// exact for the stiffness of straight P2 elements (B linear, B^T C B quadratic).
// Lumped mass: P1 row sum, m_I = int alpha rho N_I; P2 HRZ (Hinton, Rock & Zienkiewicz,
// Earthquake Eng. Struct. Dyn. 4 (1976)): diagonal of the consistent mass scaled to the element
// mass, which for straight P2 tetrahedra is m_e/36 per vertex and 4 m_e/27 per edge node
// (int N_v^2 = V/70, int N_e^2 = 8V/105).
// Interpolation: point location on a uniform bucket grid, barycentric tolerance 1e-10.
#pragma once
#include <memory>

#include "continuum/continuum_solver.hpp"

namespace arlequin::continuum {

class FeSolver : public ContinuumSolver {
 public:
  explicit FeSolver(const ContinuumSettings& settings);
  static std::unique_ptr<ContinuumSolver> create(const ContinuumSettings& settings);

  InterpolationOperator interpolation(const std::vector<Vec3>& points) const override;

 protected:
  std::vector<double> weighted_lumped_mass(const ScalarFunction& alpha) const override;

 private:
  // Barycentric coordinates of x in tetrahedron e and the gradients of the vertex ones.
  std::array<double, 4> barycentric(int e, const Vec3& x) const;
  std::vector<std::array<Vec3, 4>> grad_lambda_;  // per tetrahedron
  // Bucket grid over tetrahedron bounding boxes for point location.
  Vec3 grid_lo_;
  double cell_ = 1.0;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<int> bucket_offset_, bucket_tets_;
};

}  // namespace arlequin::continuum
