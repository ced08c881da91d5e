// SPDX-License-Identifier: GPL-3.0-or-later
// FiniteStrainForce: the internal force of finite kinematics (docs/theory.md#finite-kinematics)
// over a method's integration points,
//   f_int,a = sum_q w_q F_q S_q grad_q N_a,  F = I + H,  S = C (H + H^T + H^T H) / 2.
//
// Contract
//  - Built once from the points (compressed rows: point q has the nodes node[offset[q] ..
//    offset[q+1]) with gradients grad[...] and material index material[q] into `stiffness`).
//  - compute(u, w, f_int) overwrites f_int (3 values per node) with the force for the point
//    weights w (w_q = alpha(x_q) |cell_q|, read at every call, so weights may change between
//    calls). Nothing is allocated per call.
//  - Layout (why a class): the points are grouped into batches of equal node count and material
//    and stored lane-major (entry k of lane i at k * lanes + i), so that passes over a tile of
//    lanes compute H, E, S and P of many points at once, vectorised for any node count. The
//    tiles run on the OpenMP threads (above parallel_threshold entries), each writing its own
//    entries' node forces into the entry's slot of one array ordered by node (each node's
//    entries in the order of a serial scatter: batch, lane, entry); then every node sums its
//    slots, a contiguous run, in that order, the nodes split over the threads: the same bits on
//    any thread count, and the sum reads memory in sequence rather than an entry here and there.
#pragma once
#include <utility>
#include <vector>

#include "common/vec3.hpp"
#include "continuum/material.hpp"

namespace arlequin::continuum {

class FiniteStrainForce {
 public:
  FiniteStrainForce() = default;
  FiniteStrainForce(const std::vector<int>& offset, const std::vector<int>& node, const std::vector<Vec3>& grad,
                    const std::vector<int>& material, const std::vector<Stiffness>& stiffness);
  void compute(const std::vector<double>& u, const std::vector<double>& w, std::vector<double>& f_int) const;

 private:
  struct Batch {
    int nodes_per_point = 0;  // m
    Stiffness C;
    std::vector<int> point;          // q of each lane
    std::vector<int> dof;            // [k * lanes + i]: 3 x node of entry k of lane i
    std::vector<double> gx, gy, gz;  // [k * lanes + i]
    std::vector<int> slot;           // [k * lanes + i]: where entry k of lane i puts its force
  };
  // Lanes are computed a tile at a time (the tile's H and P stay in registers and cache).
  static constexpr int kTile = 256;
  static void tile_forces(const Batch& b, int first, int count, const double* u, const double* w, double* slots);
  std::vector<Batch> batches_;
  std::vector<std::pair<int, int>> tiles_;  // (batch, first lane) of every tile
  // Every entry's force w_q P_q grad N_k (3 values) in its slot; node n's slots are
  // slot_start_[n] .. slot_start_[n + 1].
  std::vector<int> slot_start_;
  mutable std::vector<double> slot_force_;
  long entries_ = 0;
};

}  // namespace arlequin::continuum
