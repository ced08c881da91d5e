// SPDX-License-Identifier: GPL-3.0-or-later
// FiniteStrainForce: the internal force of finite kinematics (docs/theory.md#finite-kinematics)
// over a method's integration points,
//   f_int,a = sum_q w_q F_q S_q grad_q N_a,  F = I + H,  S = C (H + H^T + H^T H) / 2.
//
// Contract
//  - Built once from the points (compressed rows: point q has the nodes node[offset[q] ..
//    offset[q+1]) with gradients grad[...] and material index material[q] into `stiffness`).
//    Optionally factored: where each gradient is a fixed combination of three vectors of its
//    element, grad[e] = sum_b coef[e]_b basis[q][b] (fe: the barycentric gradients), `basis` (per
//    point) and `coef` (per entry) let the force read nine numbers an element instead of its
//    points' gradients (empty: not factored).
//  - compute(u, w, f_int) overwrites f_int (3 values per node) with the force for the point
//    weights w (w_q = alpha(x_q) |cell_q|, read at every call, so weights may change between
//    calls); energy(u, w) the strain energy sum_q w_q E_q . C E_q / 2 (the same tiles, H
//    computed as for the force). Nothing is allocated per call.
//  - Layout (why a class): consecutive points with the same nodes and material form a cell (an
//    element's quadrature points; nem's points are cells of one point each). The cells are
//    grouped into batches of equal node count, point count and material and stored tile by
//    tile, lane-major within a tile (entry k of lane t at k * tile + t), so that a pass over a
//    tile computes H, E, S and P of a vector of points at once, for any node count, and sums
//    each cell's points' forces on its nodes before they leave it: one entry per node of a
//    cell, not per node of a point (a quadratic tetrahedron's four points write a quarter of
//    the entries). The tiles are coloured so that no two tiles of a colour share a node; a
//    colour's tiles run on the OpenMP threads (above parallel_threshold entries), each adding its
//    cells' node forces straight into f_int, a barrier between colours: every node's sum runs in
//    one order (colour, tile, entry), the same bits on any thread count, and no per-entry array
//    is written and read back (docs/performance.md says why).
#pragma once
#include <array>
#include <utility>
#include <vector>

#include "common/vec3.hpp"
#include "continuum/material.hpp"

namespace arlequin::continuum {

class FiniteStrainForce {
 public:
  FiniteStrainForce() = default;
  FiniteStrainForce(const std::vector<int>& offset, const std::vector<int>& node, const std::vector<Vec3>& grad,
                    const std::vector<int>& material, const std::vector<Stiffness>& stiffness,
                    const std::vector<std::array<Vec3, 3>>& basis = {}, const std::vector<Vec3>& coef = {});
  void compute(const std::vector<double>& u, const std::vector<double>& w, std::vector<double>& f_int) const;
  // The strain energy sum_q w_q E_q . C E_q / 2 of the same points and weights.
  double energy(const std::vector<double>& u, const std::vector<double>& w) const;

 private:
  // Lanes are computed a tile at a time (its cells' node displacements and forces stay in the
  // first-level cache): at most kTileLanes lanes and kTileEntries node entries, in vectors of
  // kVec lanes.
  static constexpr int kVec = 8, kTileLanes = 64, kTileEntries = 1024;
  // A batch's arrays are tile by tile (tile n holds cells n * tile ..), so that a tile reads
  // each in one contiguous run.
  struct Batch {
    int nodes_per_point = 0;  // m
    int points_per_cell = 0;  // p
    int cells = 0;            // its cells; the arrays are padded to whole tiles
    int tile = 0;             // lanes a tile, whole vectors: m * tile <= kTileEntries
    Stiffness C;
    std::vector<int> point;     // [(n * p + j) * tile + t]: point j of the cell in lane t of tile n
    std::vector<int> dof;       // [(n * m + k) * tile + t]: 3 x node k of that cell
    // Not factored: the gradients.
    // [((n * p + j) * tile + v) * m * 3 + (k * 3 + c) * kVec + l]: grad N_k at point j, component c,
    // lane t = v + l (v a multiple of kVec): a vector of lanes reads its points' gradients in one run.
    std::vector<double> grad;
    // Factored: each cell's basis and the batch's combinations.
    std::vector<double> basis;  // [((n * 3 + b) * 3 + c) * tile + t]: basis vector b, component c
    std::vector<double> coef;   // [(j * m + k) * 3 + b]: grad N_k at point j = sum_b coef B_b
    int tiles() const { return (cells + tile - 1) / tile; }
    bool factored() const { return !coef.empty(); }
  };
  template <bool factored, bool energy>
  static double tile_pass(const Batch& b, int n, const double* u, const double* w, double* f_int);
  // tile_pass of tiles_[t], for its batch's kind of gradients.
  template <bool energy>
  double tile(long t, const double* u, const double* w, double* f) const;
  std::vector<Batch> batches_;
  std::vector<std::pair<int, int>> tiles_;  // (batch, tile) of every tile, colour by colour
  std::vector<int> colour_start_;           // colour c's tiles are tiles_[colour_start_[c] .. colour_start_[c + 1])
  mutable std::vector<double> tile_energy_;
  long entries_ = 0;
};

}  // namespace arlequin::continuum
