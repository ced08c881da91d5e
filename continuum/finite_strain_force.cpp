// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/finite_strain_force.hpp"

#include <algorithm>
#include <array>
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
                                     const std::vector<Stiffness>& stiffness,
                                     const std::vector<std::array<Vec3, 3>>& basis, const std::vector<Vec3>& coef) {
  const bool factored = !basis.empty();
  // Cells: runs of consecutive points with the same nodes, in the same order, material and
  // basis.
  const int points = static_cast<int>(offset.size()) - 1;
  const auto same_cell = [&](int q, int r) {
    return material[q] == material[r] && offset[q + 1] - offset[q] == offset[r + 1] - offset[r] &&
           std::equal(node.begin() + offset[q], node.begin() + offset[q + 1], node.begin() + offset[r]) &&
           (!factored || basis[static_cast<size_t>(q)] == basis[static_cast<size_t>(r)]);
  };
  // Factored cells of one batch share their points' combinations: one table per batch.
  std::map<std::vector<double>, int> tables;
  std::vector<std::vector<double>> table_of;
  // (node count, point count, material, table or -1) -> first points
  std::map<std::tuple<int, int, int, int>, std::vector<int>> groups;
  for (int q = 0; q < points;) {
    int p = 1;
    while (q + p < points && same_cell(q, q + p)) ++p;
    int table = -1;
    if (factored) {
      std::vector<double> combination;
      for (int e = offset[q]; e < offset[q + p]; ++e)
        combination.insert(combination.end(), {coef[static_cast<size_t>(e)].x, coef[static_cast<size_t>(e)].y, coef[static_cast<size_t>(e)].z});
      const auto [it, added] = tables.try_emplace(combination, static_cast<int>(table_of.size()));
      if (added) table_of.push_back(combination);
      table = it->second;
    }
    groups[{offset[q + 1] - offset[q], p, material[q], table}].push_back(q);
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
    if (std::get<3>(key) >= 0) b.coef = table_of[static_cast<size_t>(std::get<3>(key))];
    // Whole tiles: the padding lanes have node 0, the batch's first point and zero gradients
    // (zero basis).
    const size_t m = static_cast<size_t>(b.nodes_per_point), np = static_cast<size_t>(b.points_per_cell);
    const size_t T = static_cast<size_t>(b.tile), lanes = static_cast<size_t>(b.tiles()) * T;
    b.point.assign(np * lanes, firsts[0]);
    b.dof.assign(m * lanes, 0);
    (b.factored() ? b.basis : b.grad).assign(b.factored() ? 9 * lanes : 3 * np * m * lanes, 0.0);
    for (size_t i = 0; i < firsts.size(); ++i) {
      const size_t n = i / T, t = i % T;
      if (b.factored())
        for (size_t r = 0; r < 3; ++r) {
          const Vec3& v = basis[static_cast<size_t>(firsts[i])][r];
          double* g = &b.basis[(n * 3 + r) * 3 * T + t];
          g[0] = v.x, g[T] = v.y, g[2 * T] = v.z;
        }
      for (size_t j = 0; j < np; ++j) {
        const int q = firsts[i] + static_cast<int>(j);
        b.point[(n * np + j) * T + t] = q;
        for (size_t k = 0; k < m; ++k) {
          const int e = offset[q] + static_cast<int>(k);
          if (j == 0) b.dof[(n * m + k) * T + t] = 3 * node[e];
          if (b.factored()) continue;
          double* g = &b.grad[((n * np + j) * T + t / kVec * kVec) * m * 3 + k * 3 * kVec + t % kVec];
          g[0] = grad[e].x, g[kVec] = grad[e].y, g[2 * kVec] = grad[e].z;
        }
      }
    }
    batches_.push_back(std::move(b));
  }
  // Tiles in colours: no two tiles of a colour share a node, so a colour's tiles add their
  // cells' forces straight into f_int on any threads, and each node's sum runs in one order
  // (colour, tile, entry) on any thread count. Greedy, in the tiles' order: a colour takes every
  // tile left that shares no node with one it holds.
  int nodes = 0;
  for (int n : node) nodes = std::max(nodes, n + 1);
  std::vector<std::pair<int, int>> left;
  for (int bi = 0; bi < static_cast<int>(batches_.size()); ++bi) {
    const Batch& b = batches_[static_cast<size_t>(bi)];
    for (int n = 0; n < b.tiles(); ++n) left.emplace_back(bi, n);
    entries_ += static_cast<long>(b.nodes_per_point) * b.cells;
  }
  std::vector<int> taken_by(static_cast<size_t>(nodes), -1);  // the last colour that took the node
  colour_start_.push_back(0);
  for (int colour = 0; !left.empty(); ++colour) {
    std::vector<std::pair<int, int>> later;
    for (const auto& [bi, n] : left) {
      const Batch& b = batches_[static_cast<size_t>(bi)];
      const size_t m = static_cast<size_t>(b.nodes_per_point), T = static_cast<size_t>(b.tile);
      const int* dof = b.dof.data() + static_cast<size_t>(n) * m * T;
      const size_t count = static_cast<size_t>(std::min(b.tile, b.cells - n * b.tile));
      bool free = true;
      for (size_t k = 0; k < m && free; ++k)
        for (size_t t = 0; t < count && free; ++t) free = taken_by[static_cast<size_t>(dof[k * T + t] / 3)] != colour;
      if (!free) {
        later.emplace_back(bi, n);
        continue;
      }
      for (size_t k = 0; k < m; ++k)
        for (size_t t = 0; t < count; ++t) taken_by[static_cast<size_t>(dof[k * T + t] / 3)] = colour;
      tiles_.emplace_back(bi, n);
    }
    colour_start_.push_back(static_cast<int>(tiles_.size()));
    left.swap(later);
  }
  tile_energy_.resize(tiles_.size());
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

// From H, lane by lane: the Green-Lagrange strain in Voigt order (xx, yy, zz, yz, xz, xy;
// engineering shears 2 E_ij = H_ij + H_ji + sum_k H_ki H_kj) and S = C E.
inline void strain_and_stress(const Lanes (&H)[3][3], const double (&c)[6][6], Lanes (&strain)[6], Lanes (&s)[6]) {
  const Lanes h00 = H[0][0], h01 = H[0][1], h02 = H[0][2], h10 = H[1][0], h11 = H[1][1], h12 = H[1][2],
              h20 = H[2][0], h21 = H[2][1], h22 = H[2][2];
  strain[0] = h00 + 0.5 * (h00 * h00 + h10 * h10 + h20 * h20);
  strain[1] = h11 + 0.5 * (h01 * h01 + h11 * h11 + h21 * h21);
  strain[2] = h22 + 0.5 * (h02 * h02 + h12 * h12 + h22 * h22);
  strain[3] = h12 + h21 + h01 * h02 + h11 * h12 + h21 * h22;
  strain[4] = h02 + h20 + h00 * h02 + h10 * h12 + h20 * h22;
  strain[5] = h01 + h10 + h00 * h01 + h10 * h11 + h20 * h21;
  for (int r = 0; r < 6; ++r)
    s[r] = c[r][0] * strain[0] + c[r][1] * strain[1] + c[r][2] * strain[2] + c[r][3] * strain[3] +
           c[r][4] * strain[4] + c[r][5] * strain[5];
}

// w P = w (I + H) S, S symmetric: rows (xx, xy, xz), (xy, yy, yz), (xz, yz, zz).
inline void weighted_piola(const Lanes (&H)[3][3], const Lanes (&s)[6], Lanes w, Lanes (&P)[3][3]) {
  const Lanes h00 = H[0][0], h01 = H[0][1], h02 = H[0][2], h10 = H[1][0], h11 = H[1][1], h12 = H[1][2],
              h20 = H[2][0], h21 = H[2][1], h22 = H[2][2];
  P[0][0] = w * ((1 + h00) * s[0] + h01 * s[5] + h02 * s[4]);
  P[0][1] = w * ((1 + h00) * s[5] + h01 * s[1] + h02 * s[3]);
  P[0][2] = w * ((1 + h00) * s[4] + h01 * s[3] + h02 * s[2]);
  P[1][0] = w * (h10 * s[0] + (1 + h11) * s[5] + h12 * s[4]);
  P[1][1] = w * (h10 * s[5] + (1 + h11) * s[1] + h12 * s[3]);
  P[1][2] = w * (h10 * s[4] + (1 + h11) * s[3] + h12 * s[2]);
  P[2][0] = w * (h20 * s[0] + h21 * s[5] + (1 + h22) * s[4]);
  P[2][1] = w * (h20 * s[5] + h21 * s[1] + (1 + h22) * s[3]);
  P[2][2] = w * (h20 * s[4] + h21 * s[3] + (1 + h22) * s[2]);
}

}  // namespace

// Tile n of a batch, its lanes rounded up to whole vectors (the padding lanes have zero
// gradients, so zero force and energy, and are not added). With `energy`: only the tile's
// strain energy, sum over its points of w E . S / 2, summed lane by lane and then over the
// lanes in order, is computed (and returned; 0 otherwise). The cells' node displacements are gathered
// once for all their points; then a vector of lanes at a time, point by point: H = sum_k u_k (x)
// grad N_k, w P, and each entry's w P grad N added to the cell's force on that node, in
// registers. A factored batch never reads a gradient: with grad N_k = sum_b A_kb B_b (B the
// cell's basis, A the batch's table at that point), H = sum_b U_b (x) B_b with U_b = sum_k A_kb
// u_k, and w P grad N_k = sum_b A_kb Q_b with Q_b = w P B_b. The cells' node forces are added to
// f at the end (no other tile of the colour touches those nodes).
template <bool factored, bool energy>
double FiniteStrainForce::tile_pass(const Batch& b, int n, const double* u, const double* w, double* f_int) {
  static_assert(sizeof(Lanes) == kVec * sizeof(double));
  const int m = b.nodes_per_point, np = b.points_per_cell, T = b.tile;
  const int count = std::min(T, b.cells - n * T), padded = (count + kVec - 1) / kVec * kVec;
  const int* dof = b.dof.data() + static_cast<size_t>(n) * m * T;
  double c[6][6];
  for (int r = 0; r < 6; ++r)
    for (int s = 0; s < 6; ++s) c[r][s] = b.C(r, s);
  double ux[kTileEntries], uy[kTileEntries], uz[kTileEntries];  // [k * T + t]
  double fx[kTileEntries], fy[kTileEntries], fz[kTileEntries];
  for (int e = 0; e < m * T; ++e) ux[e] = u[dof[e]], uy[e] = u[dof[e] + 1], uz[e] = u[dof[e] + 2];
  Lanes tile_energy{};
  for (int t = 0; t < padded; t += kVec) {
    Lanes B[3][3];  // factored: B[b][d], component d of the cell's basis vector b
    if constexpr (factored)
      for (int r = 0; r < 3; ++r)
        for (int d = 0; d < 3; ++d) B[r][d] = load(b.basis.data() + ((static_cast<size_t>(n) * 3 + r) * 3 + d) * T + t);
    for (int j = 0; j < np; ++j) {
      const double* A = nullptr;     // factored: A[3 k + b]
      const double* grad = nullptr;  // not: the points' gradients
      if constexpr (factored) A = b.coef.data() + 3 * j * m;
      else grad = b.grad.data() + ((static_cast<size_t>(n) * np + j) * T + t) * m * 3;
      Lanes H[3][3];
      if constexpr (factored) {
        Lanes U[3][3] = {};  // U[b][c]
        for (int k = 0; k < m; ++k) {
          const Lanes uk[3] = {load(ux + k * T + t), load(uy + k * T + t), load(uz + k * T + t)};
          for (int r = 0; r < 3; ++r)
            for (int cc = 0; cc < 3; ++cc) U[r][cc] += A[3 * k + r] * uk[cc];
        }
        for (int cc = 0; cc < 3; ++cc)
          for (int d = 0; d < 3; ++d) H[cc][d] = U[0][cc] * B[0][d] + U[1][cc] * B[1][d] + U[2][cc] * B[2][d];
      } else {
        for (auto& row : H) row[0] = row[1] = row[2] = Lanes{};
        for (int k = 0; k < m; ++k) {
          const double* g = grad + 3 * k * kVec;
          const Lanes a[3] = {load(g), load(g + kVec), load(g + 2 * kVec)};
          const Lanes uk[3] = {load(ux + k * T + t), load(uy + k * T + t), load(uz + k * T + t)};
          for (int cc = 0; cc < 3; ++cc)
            for (int d = 0; d < 3; ++d) H[cc][d] += uk[cc] * a[d];
        }
      }
      const int* point = b.point.data() + (static_cast<size_t>(n) * np + j) * T + t;
      Lanes wt;
      for (int l = 0; l < kVec; ++l) wt[l] = w[point[l]];
      Lanes strain[6], S[6];
      strain_and_stress(H, c, strain, S);
      if constexpr (energy) {
        tile_energy += 0.5 * wt * (strain[0] * S[0] + strain[1] * S[1] + strain[2] * S[2] + strain[3] * S[3] + strain[4] * S[4] + strain[5] * S[5]);
        continue;
      }
      Lanes P[3][3];
      weighted_piola(H, S, wt, P);
      Lanes Q[3][3];  // factored: Q[c][b] = (w P B_b)_c
      if constexpr (factored)
        for (int cc = 0; cc < 3; ++cc)
          for (int r = 0; r < 3; ++r) Q[cc][r] = P[cc][0] * B[r][0] + P[cc][1] * B[r][1] + P[cc][2] * B[r][2];
      for (int k = 0; k < m; ++k) {
        Lanes f[3];
        if constexpr (factored) {
          for (int cc = 0; cc < 3; ++cc) f[cc] = A[3 * k] * Q[cc][0] + A[3 * k + 1] * Q[cc][1] + A[3 * k + 2] * Q[cc][2];
        } else {
          const double* g = grad + 3 * k * kVec;
          const Lanes a[3] = {load(g), load(g + kVec), load(g + 2 * kVec)};
          for (int cc = 0; cc < 3; ++cc) f[cc] = P[cc][0] * a[0] + P[cc][1] * a[1] + P[cc][2] * a[2];
        }
        double* out[3] = {fx + k * T + t, fy + k * T + t, fz + k * T + t};
        for (int cc = 0; cc < 3; ++cc) store(out[cc], j == 0 ? f[cc] : load(out[cc]) + f[cc]);
      }
    }
  }
  if constexpr (energy) {
    double sum = 0.0;
    for (int l = 0; l < kVec; ++l) sum += tile_energy[l];
    return sum;
  }
  for (int k = 0; k < m; ++k)
    for (int t = 0; t < count; ++t) {
      double* out = f_int + dof[k * T + t];
      out[0] += fx[k * T + t], out[1] += fy[k * T + t], out[2] += fz[k * T + t];
    }
  return 0.0;
}

template <bool energy>
double FiniteStrainForce::tile(long t, const double* u, const double* w, double* f) const {
  const auto [bi, n] = tiles_[static_cast<size_t>(t)];
  const Batch& b = batches_[static_cast<size_t>(bi)];
  return b.factored() ? tile_pass<true, energy>(b, n, u, w, f) : tile_pass<false, energy>(b, n, u, w, f);
}

void FiniteStrainForce::compute(const std::vector<double>& u, const std::vector<double>& w,
                                std::vector<double>& f_int) const {
  f_int.assign(u.size(), 0.0);
  double* f = f_int.data();
  run_threaded_if(entries_ > parallel_threshold, [&] {
    for (size_t c = 0; c + 1 < colour_start_.size(); ++c) {
#pragma omp for schedule(static)
      for (long t = colour_start_[c]; t < colour_start_[c + 1]; ++t) tile<false>(t, u.data(), w.data(), f);
    }
  });
}

// Each tile's energy on the threads, then their sum in tile order: the same bits on any thread
// count.
double FiniteStrainForce::energy(const std::vector<double>& u, const std::vector<double>& w) const {
  double* tile_energy = tile_energy_.data();
  run_threaded_if(entries_ > parallel_threshold, [&] {
#pragma omp for schedule(static)
    for (long t = 0; t < static_cast<long>(tiles_.size()); ++t) tile_energy[t] = tile<true>(t, u.data(), w.data(), nullptr);
  });
  double sum = 0.0;
  for (double e : tile_energy_) sum += e;
  return sum;
}

}  // namespace arlequin::continuum
