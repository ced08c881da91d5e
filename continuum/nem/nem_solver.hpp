// SPDX-License-Identifier: GPL-3.0-or-later
// NemSolver ("nem"): natural element method in the spirit of CNEM, on the nodes of the mesh.
// - Shape functions: Sibson or Laplace natural-neighbour coordinates of the 3D Delaunay
//   tessellation of the nodes (CGAL::Delaunay_triangulation_3; the coordinates are ours,
//   natural_neighbours.hpp, summed in node order). They form a partition of unity, reproduce
//   linear fields and are Kronecker-delta at the nodes. They are undefined on the convex hull itself, so on a
//   flat boundary face the 2D coordinates of the face's own nodes are used (the limit of the
//   3D ones on a convex hull), and on an edge of the domain the 1D linear interpolant.
// - Integration: stabilised conforming nodal integration (SCNI; Chen, Wu, Yoon & You, IJNME 50
//   (2001)) with sub-cells in the spirit of Puso, Chen, Zywicz & Elmer, IJNME 74 (2008)
//   ("MSCNI"). Per node L its Voronoi cell V_L clipped to the domain, cut into sub-cells V_LK.
//   On any region W the smoothed gradient is
//       b_J(W) = (1/|W|) int_{dW} phi_J n dS                                      (SCNI)
//   and MSCNI's strain energy is
//       E = 1/2 sum_L [ |V_L| e_L.C e_L + a sum_K |V_LK| (e_LK - e_L).C (e_LK - e_L) ],
//   e_L, e_LK the smoothed strains on V_L and V_LK. The sub-cell faces inside V_L cancel, so
//   sum_K |V_LK| e_LK = |V_L| e_L, and the energy is sum_L sum_K |V_LK| e'_LK.C e'_LK with
//   e'_LK = e_L + sqrt(a) (e_LK - e_L): each sub-cell is an integration point, which is how it is
//   done here; with a = 1 (the default) e'_LK = e_LK. The case sets a (`continuum.
//   stabilization`): it weighs only strains that vary within a cell (an affine field has none, so
//   the patch tests hold for any a), stiffening the grid-scale modes: a larger a lowers the
//   dispersion of a coarse cloud and raises its cut-off, but stiffens bending on coarse clouds
//   (cantilever_continuum at size 0.5: tip error 0.4 % at a = 1, 4.2 % at 1.6) and a point then couples every node of its
//   cell (K has more blocks: steps ~1.4x dearer); continuum/README.md has the measurements. Plain SCNI (a -> 0)
//   has spurious low-energy modes in 3D: on the unit cube, the lowest Dirichlet eigenvalues of
//   M^-1 K were oscillating modes at 1/7 of the lowest FE one, with an error that did not
//   decrease under refinement (L2 rate 0.9).
//   Our sub-cells: one per vertex v of the cell, the union of the tetrahedra (x_L, centre of a
//   face at v, midpoint of an edge of that face at v, v); its surface is the part of each face
//   around v and the triangles (x_L, face centre, edge midpoint) it shares with the sub-cells of
//   the neighbouring vertices. Puso et al. use the pyramids from the node to each face; on a
//   regular grid the pyramid on a face parallel to the x axis spans the whole cell along x, so
//   its e_xx is the central difference (u_{I+1} - u_{I-1}) / 2h, blind to the mode alternating
//   from node to node: two thirds of a cubic cell's volume then carried no stiffness for that
//   mode, the cut-off frequency dropped to ~0.6 of P1's and a pulse crossing into a coarse
//   cloud rang (cases/wave_bar_coupled: 6.2 % reflected at 1.6 lambda_c against P1's 0.4 %).
//   A vertex sub-cell lies on one side of the node along each axis of a regular grid, so its
//   strain is a one-sided difference: the alternating mode keeps 0.63 of its P1 energy (0.35
//   with pyramids; not 1, as the interpolant on a node's plane also draws on the planes beside
//   it) and the reflection there drops to 2.1 %. L2 rate 2.0 on the unit cube.
//   Sub-cells under 1e-2 |V_L| (short cell edges, left by nearly cospherical nodes; the corner
//   of a cell where its node sits) are merged into the cell's largest one: their surface-to-
//   volume ratio amplifies round-off in the gradients; a union of closed smoothing domains is one.
//   Surface integrals use the midpoint rule on triangles (two per face corner, from the face
//   centre; exact for linear fields, so grad of x = I to round-off and the patch test is
//   passed); cell faces shared by two nodes, and triangles shared by two sub-cells, are
//   integrated once, for both, so their fluxes cancel exactly (the integration constraint).
// - Tractions use the same rule on the cell faces lying on the boundary (each point belongs to
//   the mesh boundary triangle that holds it), so loads and smoothed gradients satisfy the same
//   integration constraint and the traction (Neumann) patch test is passed exactly.
// - Lumped mass m_i = alpha(x_i) rho |V_i|.
// Supported domains: one or more bodies, each a connected set of tetrahedra (joined through
// shared nodes); bodies share no node (e.g. the two arms of the coupled DCB, meshed apart). A
// convex body (its boundary the convex hull of its nodes) is tessellated alone; its nodes' cells,
// shape functions and gradients see only its own nodes. A body that is not convex is cut into
// convex pieces by the planes of its boundary faces (docs/decisions.md#d45; a tetrahedron one of
// them cuts is an InputError): each piece is tessellated alone, neighbouring pieces share the
// nodes of the face between them, where both give the 2D coordinates of the face's nodes, and the
// fluxes through that face are integrated on the overlay of the two pieces' cells there, so
// that they cancel between the pieces and the patch tests hold. A point takes the shape functions
// of the first piece holding it. See continuum/README.md for what a constrained version (curved
// re-entrant boundaries, cracks) needs.
#pragma once
#include <memory>

#include "continuum/continuum_solver.hpp"

namespace arlequin::continuum {

class NemSolver : public ContinuumSolver {
 public:
  explicit NemSolver(const ContinuumSettings& settings);
  ~NemSolver() override;
  static std::unique_ptr<ContinuumSolver> create(const ContinuumSettings& settings);

  // Const, but not to be called from two threads at once on one solver: a query marks the cells
  // of its triangulation (natural_neighbours.hpp).
  InterpolationOperator interpolation(const std::vector<Vec3>& points) const override;
  // Clipped Voronoi cell volumes |V_i| (their sum is the domain volume).
  const std::vector<double>& cell_volumes() const { return cell_volume_; }

 protected:
  std::vector<double> weighted_lumped_mass(const ScalarFunction& alpha) const override;
  SurfaceRule surface_rule(const std::vector<std::array<int, 3>>& triangles) const override;

 private:
  struct Geometry;  // CGAL triangulations and domain planes, confined to nem_solver.cpp
  std::unique_ptr<Geometry> geo_;
  std::vector<double> cell_volume_;
  std::vector<double> node_density_;
  // The boundary part of the integration rule: points, weights, shape functions, and the mesh
  // boundary triangle holding each point (vertex triple, sorted).
  SurfaceRule boundary_;
  std::vector<std::array<int, 3>> boundary_owner_;
};

}  // namespace arlequin::continuum
