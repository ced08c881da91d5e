// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/finite_strain_force.hpp"

#include <algorithm>
#include <map>
#include <utility>

#include "common/parallel.hpp"

namespace arlequin::continuum {

FiniteStrainForce::FiniteStrainForce(const std::vector<int>& offset, const std::vector<int>& node,
                                     const std::vector<Vec3>& grad, const std::vector<int>& material,
                                     const std::vector<Stiffness>& stiffness) {
  std::map<std::pair<int, int>, std::vector<int>> groups;  // (node count, material) -> points
  for (int q = 0; q + 1 < static_cast<int>(offset.size()); ++q)
    groups[{offset[q + 1] - offset[q], material[q]}].push_back(q);
  for (const auto& [key, points] : groups) {
    Batch b;
    b.nodes_per_point = key.first;
    b.C = stiffness[key.second];
    b.point = points;
    const size_t lanes = points.size(), m = static_cast<size_t>(key.first);
    b.dof.resize(m * lanes);
    b.gx.resize(m * lanes), b.gy.resize(m * lanes), b.gz.resize(m * lanes);
    for (size_t i = 0; i < lanes; ++i)
      for (size_t k = 0; k < m; ++k) {
        const int e = offset[points[i]] + static_cast<int>(k);
        b.dof[k * lanes + i] = 3 * node[e];
        b.gx[k * lanes + i] = grad[e].x, b.gy[k * lanes + i] = grad[e].y, b.gz[k * lanes + i] = grad[e].z;
      }
    batches_.push_back(std::move(b));
  }
  // Tiles, and each entry's slot: node by node, each node's entries in the serial scatter's
  // order (batch, lane, entry).
  int nodes = 0;
  for (int n : node) nodes = std::max(nodes, n + 1);
  slot_start_.assign(static_cast<size_t>(nodes) + 1, 0);
  for (int bi = 0; bi < static_cast<int>(batches_.size()); ++bi) {
    const Batch& b = batches_[static_cast<size_t>(bi)];
    const int lanes = static_cast<int>(b.point.size());
    for (int first = 0; first < lanes; first += kTile) tiles_.emplace_back(bi, first);
    for (int d : b.dof) ++slot_start_[static_cast<size_t>(d / 3) + 1];
    entries_ += static_cast<long>(b.dof.size());
  }
  for (int n = 0; n < nodes; ++n) slot_start_[static_cast<size_t>(n) + 1] += slot_start_[static_cast<size_t>(n)];
  std::vector<int> next(slot_start_.begin(), slot_start_.end() - 1);
  for (Batch& b : batches_) {
    const size_t lanes = b.point.size(), m = static_cast<size_t>(b.nodes_per_point);
    b.slot.resize(m * lanes);
    for (size_t i = 0; i < lanes; ++i)
      for (size_t k = 0; k < m; ++k) b.slot[k * lanes + i] = next[static_cast<size_t>(b.dof[k * lanes + i] / 3)]++;
  }
  slot_force_.resize(3 * static_cast<size_t>(entries_));
}

// Lanes [first, first + count) of a batch, in three passes that each vectorise across lanes
// for any node count: H = sum_k u_k (x) grad N_k, entry by entry; then per lane the
// Green-Lagrange strain in Voigt order (xx, yy, zz, yz, xz, xy; engineering shears 2 E_ij = H_ij +
// H_ji + sum_k H_ki H_kj), S = C E and w P = w F S; then each entry's w P grad N.
void FiniteStrainForce::tile_forces(const Batch& b, int first, int count, const double* u, const double* w, double* slots) {
  const int lanes = static_cast<int>(b.point.size()), m = b.nodes_per_point;
  double c[6][6];
  for (int r = 0; r < 6; ++r)
    for (int s = 0; s < 6; ++s) c[r][s] = b.C(r, s);
  double h[9][kTile], p[9][kTile];
  for (auto& row : h) std::fill(row, row + count, 0.0);
  for (int k = 0; k < m; ++k) {
    const size_t e0 = static_cast<size_t>(k) * lanes + first;
    const int* dof = b.dof.data() + e0;
    const double *gx = b.gx.data() + e0, *gy = b.gy.data() + e0, *gz = b.gz.data() + e0;
#pragma omp simd
    for (int t = 0; t < count; ++t) {
      const double u0 = u[dof[t]], u1 = u[dof[t] + 1], u2 = u[dof[t] + 2];
      h[0][t] += u0 * gx[t], h[1][t] += u0 * gy[t], h[2][t] += u0 * gz[t];
      h[3][t] += u1 * gx[t], h[4][t] += u1 * gy[t], h[5][t] += u1 * gz[t];
      h[6][t] += u2 * gx[t], h[7][t] += u2 * gy[t], h[8][t] += u2 * gz[t];
    }
  }
  const int* point = b.point.data() + first;
#pragma omp simd
  for (int t = 0; t < count; ++t) {
    const double h00 = h[0][t], h01 = h[1][t], h02 = h[2][t], h10 = h[3][t], h11 = h[4][t], h12 = h[5][t],
                 h20 = h[6][t], h21 = h[7][t], h22 = h[8][t];
    const double strain[6] = {h00 + 0.5 * (h00 * h00 + h10 * h10 + h20 * h20),
                              h11 + 0.5 * (h01 * h01 + h11 * h11 + h21 * h21),
                              h22 + 0.5 * (h02 * h02 + h12 * h12 + h22 * h22),
                              h12 + h21 + h01 * h02 + h11 * h12 + h21 * h22,
                              h02 + h20 + h00 * h02 + h10 * h12 + h20 * h22,
                              h01 + h10 + h00 * h01 + h10 * h11 + h20 * h21};
    double s[6];
    for (int r = 0; r < 6; ++r)
      s[r] = c[r][0] * strain[0] + c[r][1] * strain[1] + c[r][2] * strain[2] + c[r][3] * strain[3] +
             c[r][4] * strain[4] + c[r][5] * strain[5];
    // w P = w (I + H) S, S symmetric: rows (xx, xy, xz), (xy, yy, yz), (xz, yz, zz).
    const double wq = w[point[t]];
    p[0][t] = wq * ((1 + h00) * s[0] + h01 * s[5] + h02 * s[4]);
    p[1][t] = wq * ((1 + h00) * s[5] + h01 * s[1] + h02 * s[3]);
    p[2][t] = wq * ((1 + h00) * s[4] + h01 * s[3] + h02 * s[2]);
    p[3][t] = wq * (h10 * s[0] + (1 + h11) * s[5] + h12 * s[4]);
    p[4][t] = wq * (h10 * s[5] + (1 + h11) * s[1] + h12 * s[3]);
    p[5][t] = wq * (h10 * s[4] + (1 + h11) * s[3] + h12 * s[2]);
    p[6][t] = wq * (h20 * s[0] + h21 * s[5] + (1 + h22) * s[4]);
    p[7][t] = wq * (h20 * s[5] + h21 * s[1] + (1 + h22) * s[3]);
    p[8][t] = wq * (h20 * s[4] + h21 * s[3] + (1 + h22) * s[2]);
  }
  for (int k = 0; k < m; ++k) {
    const size_t e0 = static_cast<size_t>(k) * lanes + first;
    const double *gx = b.gx.data() + e0, *gy = b.gy.data() + e0, *gz = b.gz.data() + e0;
    const int* slot = b.slot.data() + e0;
#pragma omp simd
    for (int t = 0; t < count; ++t) {
      double* f = slots + 3 * static_cast<size_t>(slot[t]);
      f[0] = p[0][t] * gx[t] + p[1][t] * gy[t] + p[2][t] * gz[t];
      f[1] = p[3][t] * gx[t] + p[4][t] * gy[t] + p[5][t] * gz[t];
      f[2] = p[6][t] * gx[t] + p[7][t] * gy[t] + p[8][t] * gz[t];
    }
  }
}

void FiniteStrainForce::compute(const std::vector<double>& u, const std::vector<double>& w,
                                std::vector<double>& f_int) const {
  f_int.assign(u.size(), 0.0);
  const long nodes = static_cast<long>(slot_start_.size()) - 1;
  double* slots = slot_force_.data();
  run_threaded_if(entries_ > parallel_threshold, [&] {
#pragma omp for schedule(static)
    for (long t = 0; t < static_cast<long>(tiles_.size()); ++t) {
      const auto [bi, first] = tiles_[static_cast<size_t>(t)];
      const Batch& b = batches_[static_cast<size_t>(bi)];
      tile_forces(b, first, std::min(kTile, static_cast<int>(b.point.size()) - first), u.data(), w.data(), slots);
    }
#pragma omp for schedule(static)
    for (long n = 0; n < nodes; ++n) {
      double f[3] = {0.0, 0.0, 0.0};
      for (int s = slot_start_[static_cast<size_t>(n)]; s < slot_start_[static_cast<size_t>(n) + 1]; ++s)
        for (int c = 0; c < 3; ++c) f[c] += slots[3 * static_cast<size_t>(s) + c];
      for (int c = 0; c < 3; ++c) f_int[static_cast<size_t>(3 * n + c)] = f[c];
    }
  });
}

}  // namespace arlequin::continuum
