// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/finite_strain_force.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "common/parallel.hpp"

namespace arlequin::continuum {

FiniteStrainForce::FiniteStrainForce(const std::vector<int>& offset, const std::vector<int>& node,
                                     const std::vector<Vec3>& grad, const std::vector<int>& material,
                                     const std::vector<Stiffness>& stiffness) {
  // Cells: runs of consecutive points with the same nodes, in the same order, and material.
  const int points = static_cast<int>(offset.size()) - 1;
  const auto same_cell = [&](int q, int r) {
    return material[q] == material[r] && offset[q + 1] - offset[q] == offset[r + 1] - offset[r] &&
           std::equal(node.begin() + offset[q], node.begin() + offset[q + 1], node.begin() + offset[r]);
  };
  std::map<std::tuple<int, int, int>, std::vector<int>> groups;  // (node count, point count, material) -> first points
  for (int q = 0; q < points;) {
    int p = 1;
    while (q + p < points && same_cell(q, q + p)) ++p;
    groups[{offset[q + 1] - offset[q], p, material[q]}].push_back(q);
    q += p;
  }
  for (const auto& [key, firsts] : groups) {
    Batch b;
    b.nodes_per_point = std::get<0>(key);
    b.points_per_cell = std::get<1>(key);
    if (b.nodes_per_point * kVec > kTileEntries)
      throw std::invalid_argument("FiniteStrainForce: a point of " + std::to_string(b.nodes_per_point) +
                                  " nodes; at most " + std::to_string(kTileEntries / kVec) + " are supported");
    b.tile = std::min(kTileLanes, kTileEntries / b.nodes_per_point) / kVec * kVec;
    b.C = stiffness[static_cast<size_t>(std::get<2>(key))];
    b.cells = static_cast<int>(firsts.size());
    // Whole tiles: the padding lanes have node 0, the batch's first point and zero gradients.
    const size_t m = static_cast<size_t>(b.nodes_per_point), np = static_cast<size_t>(b.points_per_cell);
    const size_t T = static_cast<size_t>(b.tile), lanes = static_cast<size_t>(b.tiles()) * T;
    b.point.assign(np * lanes, firsts[0]);
    b.dof.assign(m * lanes, 0);
    b.grad.assign(3 * np * m * lanes, 0.0);
    for (size_t i = 0; i < firsts.size(); ++i) {
      const size_t n = i / T, t = i % T;
      for (size_t j = 0; j < np; ++j) {
        const int q = firsts[i] + static_cast<int>(j);
        b.point[(n * np + j) * T + t] = q;
        for (size_t k = 0; k < m; ++k) {
          const int e = offset[q] + static_cast<int>(k);
          if (j == 0) b.dof[(n * m + k) * T + t] = 3 * node[e];
          double* g = &b.grad[((n * np + j) * m + k) * 3 * T + t];
          g[0] = grad[e].x, g[T] = grad[e].y, g[2 * T] = grad[e].z;
        }
      }
    }
    batches_.push_back(std::move(b));
  }
  // Tiles, and each entry's slot: node by node, each node's entries in the serial scatter's
  // order (batch, lane, entry).
  int nodes = 0;
  for (int n : node) nodes = std::max(nodes, n + 1);
  slot_start_.assign(static_cast<size_t>(nodes) + 1, 0);
  for (int bi = 0; bi < static_cast<int>(batches_.size()); ++bi) {
    Batch& b = batches_[static_cast<size_t>(bi)];
    const size_t m = static_cast<size_t>(b.nodes_per_point), T = static_cast<size_t>(b.tile);
    for (int n = 0; n < b.tiles(); ++n) tiles_.emplace_back(bi, n);
    for (size_t i = 0; i < static_cast<size_t>(b.cells); ++i)
      for (size_t k = 0; k < m; ++k) ++slot_start_[static_cast<size_t>(b.dof[(i / T * m + k) * T + i % T] / 3) + 1];
    entries_ += static_cast<long>(m) * b.cells;
  }
  for (int n = 0; n < nodes; ++n) slot_start_[static_cast<size_t>(n) + 1] += slot_start_[static_cast<size_t>(n)];
  std::vector<int> next(slot_start_.begin(), slot_start_.end() - 1);
  for (Batch& b : batches_) {
    const size_t m = static_cast<size_t>(b.nodes_per_point), T = static_cast<size_t>(b.tile);
    b.slot.assign(b.dof.size(), 0);
    for (size_t i = 0; i < static_cast<size_t>(b.cells); ++i)
      for (size_t k = 0; k < m; ++k) {
        const size_t at = (i / T * m + k) * T + i % T;
        b.slot[at] = next[static_cast<size_t>(b.dof[at] / 3)]++;
      }
  }
  slot_force_.resize(3 * static_cast<size_t>(entries_));
}

namespace {

// One vector of lanes, FiniteStrainForce::kVec of them (one AVX-512 register; the compiler
// splits it on narrower CPUs).
using Lanes = double __attribute__((vector_size(8 * sizeof(double))));
inline Lanes load(const double* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store(double* p, Lanes v) { std::memcpy(p, &v, sizeof v); }

}  // namespace

// Tile n of a batch, its lanes rounded up to whole vectors (the padding lanes have zero
// gradients, so zero force, and are not written). The cells' node displacements are gathered
// once for all their points; then, point by point and a vector of lanes at a time:
// H = sum_k u_k (x) grad N_k, the Green-Lagrange strain in Voigt order (xx, yy, zz, yz, xz, xy;
// engineering shears 2 E_ij = H_ij + H_ji + sum_k H_ki H_kj), S = C E and w P = w F S, all in
// registers, and each entry's w P grad N added to the cell's force on that node. The cells' node
// forces go to their slots at the end.
void FiniteStrainForce::tile_forces(const Batch& b, int n, const double* u, const double* w, double* slots) {
  static_assert(sizeof(Lanes) == kVec * sizeof(double));
  const int m = b.nodes_per_point, np = b.points_per_cell, T = b.tile;
  const int count = std::min(T, b.cells - n * T), padded = (count + kVec - 1) / kVec * kVec;
  const int* dof = b.dof.data() + static_cast<size_t>(n) * m * T;
  const int* slot = b.slot.data() + static_cast<size_t>(n) * m * T;
  double c[6][6];
  for (int r = 0; r < 6; ++r)
    for (int s = 0; s < 6; ++s) c[r][s] = b.C(r, s);
  double ux[kTileEntries], uy[kTileEntries], uz[kTileEntries];  // [k * T + t]
  double fx[kTileEntries], fy[kTileEntries], fz[kTileEntries];
  for (int e = 0; e < m * T; ++e) ux[e] = u[dof[e]], uy[e] = u[dof[e] + 1], uz[e] = u[dof[e] + 2];
  double wq[kTileLanes];
  for (int j = 0; j < np; ++j) {
    const double* grad = b.grad.data() + (static_cast<size_t>(n) * np + j) * m * 3 * T;
    const int* point = b.point.data() + (static_cast<size_t>(n) * np + j) * T;
    for (int t = 0; t < padded; ++t) wq[t] = w[point[t]];
    for (int t = 0; t < padded; t += kVec) {
      Lanes h00{}, h01{}, h02{}, h10{}, h11{}, h12{}, h20{}, h21{}, h22{};
      for (int k = 0; k < m; ++k) {
        const double* g = grad + 3 * k * T + t;
        const Lanes ax = load(g), ay = load(g + T), az = load(g + 2 * T);
        const Lanes u0 = load(ux + k * T + t), u1 = load(uy + k * T + t), u2 = load(uz + k * T + t);
        h00 += u0 * ax, h01 += u0 * ay, h02 += u0 * az;
        h10 += u1 * ax, h11 += u1 * ay, h12 += u1 * az;
        h20 += u2 * ax, h21 += u2 * ay, h22 += u2 * az;
      }
      const Lanes strain[6] = {h00 + 0.5 * (h00 * h00 + h10 * h10 + h20 * h20),
                               h11 + 0.5 * (h01 * h01 + h11 * h11 + h21 * h21),
                               h22 + 0.5 * (h02 * h02 + h12 * h12 + h22 * h22),
                               h12 + h21 + h01 * h02 + h11 * h12 + h21 * h22,
                               h02 + h20 + h00 * h02 + h10 * h12 + h20 * h22,
                               h01 + h10 + h00 * h01 + h10 * h11 + h20 * h21};
      Lanes s[6];
      for (int r = 0; r < 6; ++r)
        s[r] = c[r][0] * strain[0] + c[r][1] * strain[1] + c[r][2] * strain[2] + c[r][3] * strain[3] +
               c[r][4] * strain[4] + c[r][5] * strain[5];
      // w P = w (I + H) S, S symmetric: rows (xx, xy, xz), (xy, yy, yz), (xz, yz, zz).
      const Lanes wt = load(wq + t);
      const Lanes p00 = wt * ((1 + h00) * s[0] + h01 * s[5] + h02 * s[4]);
      const Lanes p01 = wt * ((1 + h00) * s[5] + h01 * s[1] + h02 * s[3]);
      const Lanes p02 = wt * ((1 + h00) * s[4] + h01 * s[3] + h02 * s[2]);
      const Lanes p10 = wt * (h10 * s[0] + (1 + h11) * s[5] + h12 * s[4]);
      const Lanes p11 = wt * (h10 * s[5] + (1 + h11) * s[1] + h12 * s[3]);
      const Lanes p12 = wt * (h10 * s[4] + (1 + h11) * s[3] + h12 * s[2]);
      const Lanes p20 = wt * (h20 * s[0] + h21 * s[5] + (1 + h22) * s[4]);
      const Lanes p21 = wt * (h20 * s[5] + h21 * s[1] + (1 + h22) * s[3]);
      const Lanes p22 = wt * (h20 * s[4] + h21 * s[3] + (1 + h22) * s[2]);
      for (int k = 0; k < m; ++k) {
        const double* g = grad + 3 * k * T + t;
        const Lanes ax = load(g), ay = load(g + T), az = load(g + 2 * T);
        const Lanes x = p00 * ax + p01 * ay + p02 * az;
        const Lanes y = p10 * ax + p11 * ay + p12 * az;
        const Lanes z = p20 * ax + p21 * ay + p22 * az;
        double *ox = fx + k * T + t, *oy = fy + k * T + t, *oz = fz + k * T + t;
        if (j == 0) {
          store(ox, x), store(oy, y), store(oz, z);
        } else {
          store(ox, load(ox) + x), store(oy, load(oy) + y), store(oz, load(oz) + z);
        }
      }
    }
  }
  for (int k = 0; k < m; ++k)
    for (int t = 0; t < count; ++t) {
      double* out = slots + 3 * static_cast<size_t>(slot[k * T + t]);
      out[0] = fx[k * T + t], out[1] = fy[k * T + t], out[2] = fz[k * T + t];
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
      const auto [bi, n] = tiles_[static_cast<size_t>(t)];
      tile_forces(batches_[static_cast<size_t>(bi)], n, u.data(), w.data(), slots);
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
