// SPDX-License-Identifier: GPL-3.0-or-later
#include "coupling/coupling_operators.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "common/convex_polyhedron.hpp"
#include "common/error.hpp"
#include "dem/laguerre_cells.hpp"

namespace arlequin::coupling {

namespace {

using Triplet = Eigen::Triplet<double>;

// Uniform bucket grid over the coupled DE centres for neighbour queries within r.
struct Buckets {
  Vec3 lo;
  double cell;
  std::array<int, 3> dims{};
  std::vector<std::vector<int>> items;

  Buckets(const std::vector<Vec3>& x, double r) : cell(r) {
    Vec3 hi = x.front();
    lo = x.front();
    for (const Vec3& p : x)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    for (int k = 0; k < 3; ++k) dims[k] = std::max(1, static_cast<int>((hi[k] - lo[k]) / cell) + 1);
    items.resize(static_cast<size_t>(dims[0]) * dims[1] * dims[2]);
    for (size_t i = 0; i < x.size(); ++i) items[index(cell_of(x[i]))].push_back(static_cast<int>(i));
  }
  std::array<int, 3> cell_of(const Vec3& p) const {
    std::array<int, 3> c;
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(static_cast<int>((p[k] - lo[k]) / cell), 0, dims[k] - 1);
    return c;
  }
  size_t index(const std::array<int, 3>& c) const { return (static_cast<size_t>(c[2]) * dims[1] + c[1]) * dims[0] + c[0]; }
  template <class F>
  void for_near(const Vec3& p, F&& f) const {
    const auto c = cell_of(p);
    for (int k = std::max(0, c[2] - 1); k <= std::min(dims[2] - 1, c[2] + 1); ++k)
      for (int j = std::max(0, c[1] - 1); j <= std::min(dims[1] - 1, c[1] + 1); ++j)
        for (int i = std::max(0, c[0] - 1); i <= std::min(dims[0] - 1, c[0] + 1); ++i)
          for (int q : items[index({i, j, k})]) f(q);
  }
};

double median_nearest_distance(const std::vector<Vec3>& x) {
  // A first radius from the bounding box and the count, then exact nearest distances.
  Vec3 lo = x.front(), hi = x.front();
  for (const Vec3& p : x)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  double extent = 0.0;
  for (int k = 0; k < 3; ++k) extent = std::max(extent, hi[k] - lo[k]);
  double r = std::max(extent / std::cbrt(static_cast<double>(x.size())), 1e-300);
  for (int attempt = 0; attempt < 60; ++attempt, r *= 2.0) {
    Buckets grid(x, r);
    std::vector<double> nearest(x.size(), std::numeric_limits<double>::infinity());
    bool all = true;
    for (size_t p = 0; p < x.size(); ++p) {
      grid.for_near(x[p], [&](int q) {
        if (static_cast<size_t>(q) != p) nearest[p] = std::min(nearest[p], norm(x[q] - x[p]));
      });
      all = all && nearest[p] <= r;
    }
    if (all) {
      std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
      return nearest[nearest.size() / 2];
    }
  }
  throw SettingError("overlap", "could not find neighbours of the coupled DEs");
}

// H1 part: sum_k D_k^T W D_k for the least-squares gradient on the DE cloud.
SparseMatrix gradient_gram(const std::vector<Vec3>& x, const std::vector<double>& w, double radius) {
  const int n = static_cast<int>(x.size());
  Buckets grid(x, radius);
  std::array<std::vector<Triplet>, 3> trip;
  std::vector<int> nb;
  for (int p = 0; p < n; ++p) {
    nb.clear();
    Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
    grid.for_near(x[p], [&](int q) {
      const Vec3 d = x[q] - x[p];
      if (q == p || norm(d) > radius) return;
      nb.push_back(q);
      const Eigen::Vector3d e(d.x, d.y, d.z);
      M += e * e.transpose();
    });
    if (nb.empty()) continue;
    const Eigen::Matrix3d P = M.completeOrthogonalDecomposition().pseudoInverse();
    for (int q : nb) {
      const Vec3 d = x[q] - x[p];
      const Eigen::Vector3d g = P * Eigen::Vector3d(d.x, d.y, d.z);
      for (int k = 0; k < 3; ++k) {
        trip[k].emplace_back(p, q, g[k]);
        trip[k].emplace_back(p, p, -g[k]);
      }
    }
  }
  SparseMatrix W(n, n);
  {
    std::vector<Triplet> t;
    for (int p = 0; p < n; ++p) t.emplace_back(p, p, w[p]);
    W.setFromTriplets(t.begin(), t.end());
  }
  SparseMatrix sum(n, n);
  for (int k = 0; k < 3; ++k) {
    SparseMatrix D(n, n);
    D.setFromTriplets(trip[k].begin(), trip[k].end());
    sum += SparseMatrix(D.transpose() * W * D);
  }
  return sum;
}

}  // namespace

Mediator mediator_from_name(const std::string& name) {
  if (name == "coarse" || name == "continuum") return Mediator::coarse;
  if (name == "fine" || name == "particles") return Mediator::fine;
  throw InputError("unknown mediator '" + name + "' (known: coarse (= continuum), fine (= particles))");
}

CouplingType coupling_type_from_name(const std::string& name) {
  if (name == "l2" || name == "L2") return CouplingType::l2;
  if (name == "h1" || name == "H1") return CouplingType::h1;
  throw InputError("unknown coupling type '" + name + "' (known: l2, h1)");
}

const char* mediator_name(Mediator m) { return m == Mediator::coarse ? "coarse" : "fine"; }
const char* coupling_type_name(CouplingType t) { return t == CouplingType::l2 ? "l2" : "h1"; }

CouplingOperators CouplingOperators::build(const OverlapZone& zone, const dem::ParticleSet& p,
                                           const continuum::ContinuumSolver& continuum,
                                           const CouplingSettings& settings) {
  CouplingOperators op;
  op.settings = settings;
  std::vector<std::uint32_t> inside;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (zone.contains(p.reference[i])) inside.push_back(static_cast<std::uint32_t>(i));
  if (inside.empty()) throw SettingError("overlap", "no DE lies in the overlap (" + zone.description() + ")");
  // W_p: the part of DE p's Laguerre cell (of the whole packing) inside the overlap. A DE whose
  // centre lies on the overlap's boundary brings the part of its cell on the overlap's side only.
  // The cells are cut to the overlap's bounds first, which leaves that part as it is.
  const std::vector<double> share = dem::laguerre_cell_measures(
      p.reference, p.radius, inside, [&zone](const Polyhedron& cell) { return zone.volume_inside(cell); }, &zone.bounds());
  std::vector<Vec3> x;
  for (std::size_t k = 0; k < inside.size(); ++k)
    if (share[k] > 0.0) {  // a centre on the boundary within its tolerance, with no cell inside, has nothing to carry
      op.particles.push_back(inside[k]);
      x.push_back(p.reference[inside[k]]);
      op.weight.push_back(share[k]);
    }
  if (settings.type == CouplingType::h1 && !(settings.length > 0.0))
    throw SettingError("length", "H1 coupling needs a positive length scale");
  if (settings.gradient_radius < 0.0) throw SettingError("overlap", "the gradient radius must not be negative");

  const int np = static_cast<int>(x.size()), nn = continuum.num_nodes();
  op.N = continuum.interpolation(x);

  // S = W (+ l^2 sum_k D_k^T W D_k for H1).
  SparseMatrix S(np, np);
  {
    std::vector<Triplet> t;
    for (int q = 0; q < np; ++q) t.emplace_back(q, q, op.weight[q]);
    S.setFromTriplets(t.begin(), t.end());
  }
  if (settings.type == CouplingType::h1) {
    const double radius = settings.gradient_radius > 0.0 ? settings.gradient_radius : 1.5 * median_nearest_distance(x);
    S += settings.length * settings.length * gradient_gram(x, op.weight, radius);
  }

  if (settings.mediator == Mediator::fine) {
    op.Gd = S;
    op.Gc = -(S * op.N);
  } else {
    // Mediator nodes: continuum nodes of the overlap whose shape function the DE quadrature sees.
    Eigen::VectorXd seen = Eigen::VectorXd::Zero(nn);
    for (int q = 0; q < np; ++q)
      for (SparseMatrix::InnerIterator it(op.N, q); it; ++it) seen[it.col()] += op.weight[q] * std::abs(it.value());
    const double tol = 1e-12 * seen.maxCoeff();
    std::vector<Triplet> t;
    for (int I = 0; I < nn; ++I)
      if (seen[I] > tol && zone.contains(continuum.nodes()[I])) {
        t.emplace_back(static_cast<int>(op.mediator_nodes.size()), I, 1.0);
        op.mediator_nodes.push_back(I);
      }
    SparseMatrix R(static_cast<int>(op.mediator_nodes.size()), nn);  // restriction to mediator nodes
    R.setFromTriplets(t.begin(), t.end());
    const SparseMatrix NtS = R * SparseMatrix(op.N.transpose()) * S;
    op.Gd = NtS;
    op.Gc = -(NtS * op.N);
  }
  op.Gd.prune(0.0);
  op.Gc.prune(0.0);
  op.Gd.makeCompressed();
  op.Gc.makeCompressed();
  return op;
}

void CouplingOperators::tie_components(const std::vector<std::array<bool, 3>>& components) {
  if (!settings.fine_l2())
    throw SettingError("ties", "ties of some components need the fine mediator and l2 coupling (a row per DE)");
  tied.resize(num_particles(), 3);
  for (int p = 0; p < num_particles(); ++p)
    for (int c = 0; c < 3; ++c) tied(p, c) = components.at(particles[static_cast<std::size_t>(p)])[static_cast<std::size_t>(c)] ? 1.0 : 0.0;
}

}  // namespace arlequin::coupling
