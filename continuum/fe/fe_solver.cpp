// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/fe/fe_solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "common/error.hpp"

namespace arlequin::continuum {

namespace {

// Symmetric 4-point degree-2 rule on the tetrahedron (e.g. Zienkiewicz & Taylor, Table 5.4).
constexpr double kQa = 0.5854101966249685, kQb = 0.1381966011250105;
constexpr std::array<std::array<double, 4>, 4> kQuad{
    {{kQa, kQb, kQb, kQb}, {kQb, kQa, kQb, kQb}, {kQb, kQb, kQa, kQb}, {kQb, kQb, kQb, kQa}}};

// Values of the element shape functions (4 or 10, order of Mesh::tet) at barycentric l.
void shape_values(int order, const std::array<double, 4>& l, double* N) {
  if (order == 1) {
    std::copy(l.begin(), l.end(), N);
    return;
  }
  for (int i = 0; i < 4; ++i) N[i] = l[i] * (2 * l[i] - 1);
  for (int k = 0; k < 6; ++k) N[4 + k] = 4 * l[kTetEdges[k][0]] * l[kTetEdges[k][1]];
}

void shape_gradients(int order, const std::array<double, 4>& l, const std::array<Vec3, 4>& gl, Vec3* G) {
  if (order == 1) {
    std::copy(gl.begin(), gl.end(), G);
    return;
  }
  for (int i = 0; i < 4; ++i) G[i] = (4 * l[i] - 1) * gl[i];
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1];
    G[4 + k] = 4 * (l[a] * gl[b] + l[b] * gl[a]);
  }
}

}  // namespace

std::unique_ptr<ContinuumSolver> FeSolver::create(const ContinuumSettings& settings) {
  return std::make_unique<FeSolver>(settings);
}

FeSolver::FeSolver(const ContinuumSettings& settings) : ContinuumSolver(settings) {
  const int ne = mesh_.num_tets(), npe = mesh_.nodes_per_tet(), order = mesh_.order();
  const auto& X = nodes();
  grad_lambda_.resize(ne);
  for (int e = 0; e < ne; ++e) {
    const int* t = mesh_.tet(e);
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) {
      const Vec3 d = X[t[k + 1]] - X[t[0]];
      J.col(k) << d.x, d.y, d.z;
    }
    const Eigen::Matrix3d Ji = J.inverse();
    for (int k = 0; k < 3; ++k) grad_lambda_[e][k + 1] = {Ji(k, 0), Ji(k, 1), Ji(k, 2)};
    grad_lambda_[e][0] = -(grad_lambda_[e][1] + grad_lambda_[e][2] + grad_lambda_[e][3]);
  }

  // Integration points: P1 centroid (strain constant), P2 the 4-point rule.
  const std::vector<std::array<double, 4>> rule =
      order == 1 ? std::vector<std::array<double, 4>>{{0.25, 0.25, 0.25, 0.25}}
                 : std::vector<std::array<double, 4>>(kQuad.begin(), kQuad.end());
  // Every gradient is a combination of the element's barycentric gradients grad lambda_1..3
  // (grad lambda_0 = -their sum), the same at the same point of every element: the shape
  // gradients with grad lambda_b the unit vectors are those combinations, one set per point.
  const std::array<Vec3, 4> unit{Vec3{-1.0, -1.0, -1.0}, Vec3{1.0, 0.0, 0.0}, Vec3{0.0, 1.0, 0.0}, Vec3{0.0, 0.0, 1.0}};
  std::vector<std::array<Vec3, 10>> combination(rule.size());
  for (size_t r = 0; r < rule.size(); ++r) shape_gradients(order, rule[r], unit, combination[r].data());
  std::array<Vec3, 10> G;
  for (int e = 0; e < ne; ++e) {
    const int* t = mesh_.tet(e);
    const double V = mesh_.tet_volume(e);
    for (size_t r = 0; r < rule.size(); ++r) {
      const auto& l = rule[r];
      points_.x.push_back(l[0] * X[t[0]] + l[1] * X[t[1]] + l[2] * X[t[2]] + l[3] * X[t[3]]);
      points_.volume.push_back(V / static_cast<double>(rule.size()));
      points_.material.push_back(tet_material_[e]);
      shape_gradients(order, l, grad_lambda_[e], G.data());
      points_.basis.push_back({grad_lambda_[e][1], grad_lambda_[e][2], grad_lambda_[e][3]});
      for (int a = 0; a < npe; ++a) {
        points_.node.push_back(t[a]);
        points_.grad.push_back(G[a]);
        points_.coef.push_back(combination[r][static_cast<size_t>(a)]);
      }
      points_.offset.push_back(static_cast<int>(points_.node.size()));
    }
  }

  // Bucket grid, about two tetrahedra per bucket side.
  Vec3 lo = X[0], hi = X[0];
  for (const Vec3& p : X)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const Vec3 span = hi - lo;
  cell_ = std::max(1e-300, 2.0 * std::cbrt(std::max(span.x, 1e-12) * std::max(span.y, 1e-12) * std::max(span.z, 1e-12) / ne));
  grid_lo_ = lo;
  for (int k = 0; k < 3; ++k) dims_[k] = std::max(1, static_cast<int>(std::ceil(span[k] / cell_)));
  const size_t nb = static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2];
  std::vector<std::vector<int>> buckets(nb);
  auto index = [&](const Vec3& p, int k) {
    return std::clamp(static_cast<int>(std::floor((p[k] - grid_lo_[k]) / cell_)), 0, dims_[k] - 1);
  };
  for (int e = 0; e < ne; ++e) {
    const int* t = mesh_.tet(e);
    std::array<int, 3> a{}, b{};
    for (int k = 0; k < 3; ++k) {
      double mn = X[t[0]][k], mx = mn;
      for (int v = 1; v < 4; ++v) mn = std::min(mn, X[t[v]][k]), mx = std::max(mx, X[t[v]][k]);
      a[k] = index(Vec3{mn, mn, mn}, k);
      b[k] = index(Vec3{mx, mx, mx}, k);
    }
    for (int i = a[0]; i <= b[0]; ++i)
      for (int j = a[1]; j <= b[1]; ++j)
        for (int k = a[2]; k <= b[2]; ++k) buckets[(static_cast<size_t>(k) * dims_[1] + j) * dims_[0] + i].push_back(e);
  }
  bucket_offset_.assign(1, 0);
  for (auto& bk : buckets) {
    bucket_tets_.insert(bucket_tets_.end(), bk.begin(), bk.end());
    bucket_offset_.push_back(static_cast<int>(bucket_tets_.size()));
  }
  finish_setup();
}

std::array<double, 4> FeSolver::barycentric(int e, const Vec3& x) const {
  const Vec3 d = x - nodes()[mesh_.tet(e)[0]];
  std::array<double, 4> l{};
  for (int k = 1; k < 4; ++k) l[k] = dot(grad_lambda_[e][k], d);
  l[0] = 1.0 - l[1] - l[2] - l[3];
  return l;
}

InterpolationOperator FeSolver::interpolation(const std::vector<Vec3>& points) const {
  const int npe = mesh_.nodes_per_tet();
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(points.size() * npe);
  std::array<double, 10> N;
  for (size_t p = 0; p < points.size(); ++p) {
    const Vec3& x = points[p];
    int best = -1;
    std::array<double, 4> best_l{};
    double best_min = -1e-10;  // accept points on faces up to round-off
    std::array<int, 3> c{};
    bool inside_grid = true;
    for (int k = 0; k < 3; ++k) {
      const double r = (x[k] - grid_lo_[k]) / cell_;
      if (r < -1e-9 || r > dims_[k] + 1e-9) inside_grid = false;
      c[k] = std::clamp(static_cast<int>(std::floor(r)), 0, dims_[k] - 1);
    }
    if (inside_grid) {
      const size_t b = (static_cast<size_t>(c[2]) * dims_[1] + c[1]) * dims_[0] + c[0];
      for (int i = bucket_offset_[b]; i < bucket_offset_[b + 1]; ++i) {
        const int e = bucket_tets_[i];
        const auto l = barycentric(e, x);
        const double m = *std::min_element(l.begin(), l.end());
        if (m >= best_min) best = e, best_l = l, best_min = m;
      }
    }
    if (best < 0)
      throw InputError("interpolation point (" + std::to_string(x.x) + ", " + std::to_string(x.y) + ", " +
                       std::to_string(x.z) + ") lies outside the continuum mesh");
    shape_values(mesh_.order(), best_l, N.data());
    for (int a = 0; a < npe; ++a) trip.emplace_back(static_cast<int>(p), mesh_.tet(best)[a], N[a]);
  }
  InterpolationOperator op(static_cast<int>(points.size()), num_nodes());
  op.setFromTriplets(trip.begin(), trip.end());
  return op;
}

std::vector<double> FeSolver::weighted_lumped_mass(const ScalarFunction& alpha) const {
  std::vector<double> m(num_nodes(), 0.0);
  const auto& X = nodes();
  for (int e = 0; e < mesh_.num_tets(); ++e) {
    const int* t = mesh_.tet(e);
    const double rhoV4 = materials_[tet_material_[e]].density * mesh_.tet_volume(e) / 4.0;
    if (mesh_.order() == 1) {
      // Row sum: int alpha rho N_I with the degree-2 rule (exact for linear alpha).
      for (const auto& l : kQuad) {
        const double w = rhoV4 * alpha(l[0] * X[t[0]] + l[1] * X[t[1]] + l[2] * X[t[2]] + l[3] * X[t[3]]);
        for (int a = 0; a < 4; ++a) m[t[a]] += w * l[a];
      }
    } else {
      double me = 0;  // int alpha rho over the element
      for (const auto& l : kQuad) me += rhoV4 * alpha(l[0] * X[t[0]] + l[1] * X[t[1]] + l[2] * X[t[2]] + l[3] * X[t[3]]);
      for (int a = 0; a < 4; ++a) m[t[a]] += me / 36.0;
      for (int k = 0; k < 6; ++k) m[t[4 + k]] += 4.0 * me / 27.0;
    }
  }
  return m;
}

}  // namespace arlequin::continuum
