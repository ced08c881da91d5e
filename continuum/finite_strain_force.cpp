// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/finite_strain_force.hpp"

#include <algorithm>
#include <map>
#include <utility>

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
    b.force.resize(3 * m * kTile);
    for (size_t i = 0; i < lanes; ++i)
      for (size_t k = 0; k < m; ++k) {
        const int e = offset[points[i]] + static_cast<int>(k);
        b.dof[k * lanes + i] = 3 * node[e];
        b.gx[k * lanes + i] = grad[e].x, b.gy[k * lanes + i] = grad[e].y, b.gz[k * lanes + i] = grad[e].z;
      }
    batches_.push_back(std::move(b));
  }
}

// Lanes [first, first + count) of a batch, vectorised across lanes: H, the Green-Lagrange strain
// in Voigt order (xx, yy, zz, yz, xz, xy; engineering shears 2 E_ij = H_ij + H_ji + sum_k H_ki
// H_kj), S = C E, w P = w F S, and each entry's w P grad N. M > 0: the batch's node count known
// at compile time, so that the loops over entries unroll and the loop over lanes vectorises;
// M = 0: any count.
template <int M>
void FiniteStrainForce::tile_forces(const Batch& b, int first, int count, const double* u, const double* w) {
  const int lanes = static_cast<int>(b.point.size()), m = M > 0 ? M : b.nodes_per_point;
  double c[6][6];
  for (int r = 0; r < 6; ++r)
    for (int s = 0; s < 6; ++s) c[r][s] = b.C(r, s);
  const int* dof = b.dof.data();
  const int* point = b.point.data();
  const double *gx = b.gx.data(), *gy = b.gy.data(), *gz = b.gz.data();
  double* force = b.force.data();
#pragma omp simd
  for (int t = 0; t < count; ++t) {
    const int i = first + t;
    double h00 = 0, h01 = 0, h02 = 0, h10 = 0, h11 = 0, h12 = 0, h20 = 0, h21 = 0, h22 = 0;
#pragma GCC unroll 16
    for (int k = 0; k < m; ++k) {
      const int e = k * lanes + i, a = dof[e];
      const double x = gx[e], y = gy[e], z = gz[e], u0 = u[a], u1 = u[a + 1], u2 = u[a + 2];
      h00 += u0 * x, h01 += u0 * y, h02 += u0 * z;
      h10 += u1 * x, h11 += u1 * y, h12 += u1 * z;
      h20 += u2 * x, h21 += u2 * y, h22 += u2 * z;
    }
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
    const double wq = w[point[i]];
    const double p00 = wq * ((1 + h00) * s[0] + h01 * s[5] + h02 * s[4]);
    const double p01 = wq * ((1 + h00) * s[5] + h01 * s[1] + h02 * s[3]);
    const double p02 = wq * ((1 + h00) * s[4] + h01 * s[3] + h02 * s[2]);
    const double p10 = wq * (h10 * s[0] + (1 + h11) * s[5] + h12 * s[4]);
    const double p11 = wq * (h10 * s[5] + (1 + h11) * s[1] + h12 * s[3]);
    const double p12 = wq * (h10 * s[4] + (1 + h11) * s[3] + h12 * s[2]);
    const double p20 = wq * (h20 * s[0] + h21 * s[5] + (1 + h22) * s[4]);
    const double p21 = wq * (h20 * s[5] + h21 * s[1] + (1 + h22) * s[3]);
    const double p22 = wq * (h20 * s[4] + h21 * s[3] + (1 + h22) * s[2]);
#pragma GCC unroll 16
    for (int k = 0; k < m; ++k) {
      const int e = k * lanes + i;
      const double x = gx[e], y = gy[e], z = gz[e];
      force[(3 * k) * kTile + t] = p00 * x + p01 * y + p02 * z;
      force[(3 * k + 1) * kTile + t] = p10 * x + p11 * y + p12 * z;
      force[(3 * k + 2) * kTile + t] = p20 * x + p21 * y + p22 * z;
    }
  }
}

void FiniteStrainForce::compute(const std::vector<double>& u, const std::vector<double>& w,
                                std::vector<double>& f_int) const {
  f_int.assign(u.size(), 0.0);
  for (const Batch& b : batches_) {
    const int lanes = static_cast<int>(b.point.size()), m = b.nodes_per_point;
    for (int first = 0; first < lanes; first += kTile) {
      const int count = std::min(kTile, lanes - first);
      switch (m) {  // P1 tetrahedra have 4 nodes per point, P2 10
        case 4: tile_forces<4>(b, first, count, u.data(), w.data()); break;
        case 10: tile_forces<10>(b, first, count, u.data(), w.data()); break;
        default: tile_forces<0>(b, first, count, u.data(), w.data());
      }
      for (int t = 0; t < count; ++t)
        for (int k = 0; k < m; ++k) {
          double* f = &f_int[static_cast<size_t>(b.dof[static_cast<size_t>(k) * lanes + first + t])];
          f[0] += b.force[(3 * k) * kTile + t];
          f[1] += b.force[(3 * k + 1) * kTile + t];
          f[2] += b.force[(3 * k + 2) * kTile + t];
        }
    }
  }
}

}  // namespace arlequin::continuum
