// SPDX-License-Identifier: GPL-3.0-or-later
// CouplingOperators: the discrete Arlequin constraint G_d u_d + G_c u_c = 0 between the DE
// translations and the continuum displacements in the overlap.
//
// Contract
//  - Small-displacement coupling, in the reference configuration: coupled DEs are those whose
//    reference centre X_p lies in the overlap (OverlapZone::contains); the centres must lie in
//    the continuum mesh (else the continuum's InputError names the point).
//  - N = continuum.interpolation(X_p): u_c(X_p) = sum_I N(p, I) u_I. Everything else is built
//    from N, so any ContinuumSolver (fe, nem) works unchanged.
//  - Quadrature of the overlap by the DEs (Xiao & Belytschko, CMAME 193 (2004) section 3):
//    int_overlap f dV ~ sum_p W_p f(x_p), W_p = the volume of the part of DE p's Laguerre cell
//    that lies in the overlap (OverlapZone::volume_inside; docs/theory.md#overlap-quadrature).
//    The cells tile space, so the W_p tile the overlap, and a DE on the overlap's boundary
//    brings only its cell's part inside (half of it on a lattice plane): counted whole, it
//    left the coarse mediator a ghost force at h = 2a (docs/decisions.md#d29).
//  - Coupling inner product on the particle cloud (Guidault & Belytschko, IJNME 70 (2007)):
//      L2:  (l, w) = sum_p W_p l(x_p).w(x_p)                      S = W
//      H1:  (l, w) += length^2 sum_p W_p grad l(x_p) : grad w(x_p)  S = W + length^2 sum_k D_k^T W D_k
//    with D_k the least-squares gradient on the DE cloud: grad w(x_p) = (sum_j (w_j - w_p) d_j^T)
//    (sum_j d_j d_j^T)^+, d_j = x_j - x_p over coupled DEs within gradient_radius (exact for
//    affine fields). The continuum field enters through its values at the DEs, N u_c.
//  - Mediator space (where the multiplier lambda lives), both fields tested against it:
//      coarse (default): lambda = sum_I N_I lambda_I over the continuum nodes of the overlap
//             (closed) that carry DEs (rows = mediator_nodes):   G_d = N^T S,   G_c = -N^T S N.
//             A natural-neighbour node beyond the overlap can still carry a DE on its edge
//             (Sibson support reaches past the next node plane) but only weakly: as a mediator
//             row it made A near-singular (NEM, h = 2a), so it is not one.
//      fine:  lambda at every coupled DE (rows = particles):  G_d = S,  G_c = -S N
//    Columns of G_d: coupled DEs (order of `particles`); columns of G_c: all continuum nodes.
//    The operators are scalar and act on x, y and z alike. For the fine mediator S is
//    invertible, so H1 and L2 have the same constraint kernel (same corrected velocities).
//  - Kinematic patch test: for any affine field u(x), u_p = u(x_p) and u_I = u(X_I) give
//    G_d u_d + G_c u_c = 0 to round-off (N reproduces affine fields, D is exact for them).
#pragma once
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "continuum/continuum_solver.hpp"
#include "coupling/overlap_zone.hpp"
#include "dem/particles.hpp"

namespace arlequin::coupling {

enum class Mediator { coarse, fine };
enum class CouplingType { l2, h1 };
Mediator mediator_from_name(const std::string& name);          // "coarse"/"continuum", "fine"/"particles"
CouplingType coupling_type_from_name(const std::string& name);  // "l2", "h1"
const char* mediator_name(Mediator m);
const char* coupling_type_name(CouplingType t);

struct CouplingSettings {
  Mediator mediator = Mediator::coarse;
  CouplingType type = CouplingType::l2;
  double length = 0.0;           // H1 length scale l, m (> 0 for H1)
  double gradient_radius = 0.0;  // H1 gradient neighbourhood, m; 0 = 1.5 x the median nearest-DE distance
  // A multiplier per DE and G_d = W diagonal: what partial ties and the Woodbury form need.
  bool fine_l2() const { return mediator == Mediator::fine && type == CouplingType::l2; }
};

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

struct CouplingOperators {
  CouplingSettings settings;
  std::vector<std::uint32_t> particles;  // coupled DEs = columns of Gd
  std::vector<double> weight;            // W_p, m^3 (> 0)
  std::vector<int> mediator_nodes;       // coarse: continuum node of each row; fine: empty
  SparseMatrix N;                        // particles x continuum nodes
  SparseMatrix Gd;                       // rows x particles
  SparseMatrix Gc;                       // rows x continuum nodes
  // Which components of each row the constraint holds (1) or leaves free (0); empty: all.
  // Set by tie_components; MultiplierSolver drops the free ones (no multiplier, no correction).
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> tied;

  // InputError if no DE lies in the overlap or the H1 settings are invalid.
  static CouplingOperators build(const OverlapZone& zone, const dem::ParticleSet& particles,
                                 const continuum::ContinuumSolver& continuum, const CouplingSettings& settings);
  // Partial ties (fine mediator, L2: a row is one DE): the components of DE i that follow the
  // continuum are components[i] (indexed by the scene's DEs); the others move with the DEM alone.
  // A woven plate moves each yarn family along its own axis only (docs/theory.md#partial-ties).
  // SettingError("ties") for another mediator or coupling type.
  void tie_components(const std::vector<std::array<bool, 3>>& components);
  int rows() const { return static_cast<int>(Gd.rows()); }
  int num_particles() const { return static_cast<int>(particles.size()); }
};

}  // namespace arlequin::coupling
