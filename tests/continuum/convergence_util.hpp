// SPDX-License-Identifier: GPL-3.0-or-later
// Exact elastic fields and error norms shared by the convergence and cantilever tests.
#pragma once
#include <cmath>

#include "continuum_test_util.hpp"

namespace arlequin::continuum::testing {

// u = grad phi with phi = sin x sin y sinh(sqrt2 z) harmonic: div u = 0 and lap u = 0, so u
// solves the isotropic Navier equations without body force for any E, nu.
inline Vec3 harmonic_field(const Vec3& p) {
  const double c = std::sqrt(2.0);
  return {std::cos(p.x) * std::sin(p.y) * std::sinh(c * p.z), std::sin(p.x) * std::cos(p.y) * std::sinh(c * p.z),
          c * std::sin(p.x) * std::sin(p.y) * std::cosh(c * p.z)};
}

// Relative L2 error of the discrete displacement against `exact`, by a 27-point collapsed
// (Duffy) Gauss rule on every mesh tetrahedron, evaluated through the solver's interpolation.
template <class Exact>
double relative_l2_error(const ContinuumSolver& s, Exact exact) {
  const double g[3] = {0.5 - std::sqrt(0.15), 0.5, 0.5 + std::sqrt(0.15)};
  const double w[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
  std::vector<Vec3> pts;
  std::vector<double> wts;
  const Mesh& m = s.mesh();
  for (int e = 0; e < m.num_tets(); ++e) {
    const int* t = m.tet(e);
    const Vec3 &a = m.nodes()[t[0]], &b = m.nodes()[t[1]], &c = m.nodes()[t[2]], &d = m.nodes()[t[3]];
    const double V6 = 6.0 * m.tet_volume(e);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) {
          const double u = g[i], v = g[j] * (1 - u), z = g[k] * (1 - u) * (1 - g[j]);
          pts.push_back(a + u * (b - a) + v * (c - a) + z * (d - a));
          wts.push_back(V6 * w[i] * w[j] * w[k] * (1 - u) * (1 - u) * (1 - g[j]));
        }
  }
  const InterpolationOperator N = s.interpolation(pts);
  Eigen::MatrixXd U(s.num_nodes(), 3);
  for (int n = 0; n < s.num_nodes(); ++n)
    for (int c = 0; c < 3; ++c) U(n, c) = s.displacement()[3 * n + c];
  const Eigen::MatrixXd Uh = N * U;
  double err = 0, ref = 0;
  for (size_t p = 0; p < pts.size(); ++p) {
    const Vec3 ue = exact(pts[p]);
    for (int c = 0; c < 3; ++c) {
      err += wts[p] * std::pow(Uh(p, c) - ue[c], 2);
      ref += wts[p] * ue[c] * ue[c];
    }
  }
  return std::sqrt(err / ref);
}

// L2 convergence rate between two gmsh element sizes h1 > h2 on the unit cube. The mesh size
// is measured, not assumed: h = (volume / tetrahedra)^(1/3), since gmsh rounds edge divisions.
inline double convergence_rate(const std::string& method, int order, double h1, double h2) {
  const Material mat = Material::isotropic(1.0, 0.3, 1.0);
  double err[2], h[2];
  const double sizes[2] = {h1, h2};
  for (int i = 0; i < 2; ++i) {
    auto s = make_continuum_solver(method, settings("unit_cube.geo", sizes[i], order, mat));
    s->fix("boundary", {true, true, true}, [](const Vec3& x, double) { return harmonic_field(x); });
    s->solve_static();
    err[i] = relative_l2_error(*s, harmonic_field);
    h[i] = std::cbrt(1.0 / s->mesh().num_tets());
  }
  return std::log(err[0] / err[1]) / std::log(h[0] / h[1]);
}

// Tip deflection of the 10 x 1 x 1 cantilever (meshes/cantilever.geo) under a total shear
// load P on the tip face, relative to Timoshenko beam theory with Cowper's shear coefficient
// for a rectangle, kappa = 10 (1 + nu) / (12 + 11 nu): delta = P L^3 / (3 E I) + P L / (kappa G A).
inline double cantilever_tip_ratio(const std::string& method, int order, double size) {
  const double E = 1000.0, nu = 0.3, P = 1e-2, L = 10, A = 1, I = 1.0 / 12;
  auto s = make_continuum_solver(method, settings("cantilever.geo", size, order, Material::isotropic(E, nu, 1.0)));
  s->fix("clamp", {true, true, true}, [](const Vec3&, double) { return Vec3{}; });
  s->add_traction("tip", [&](const Vec3&, double) { return Vec3{0, 0, P / A}; });
  s->solve_static();
  const InterpolationOperator N = s->interpolation({{L, 0.5, 0.5}});
  double w = 0;
  for (InterpolationOperator::InnerIterator it(N, 0); it; ++it) w += it.value() * s->displacement()[3 * it.col() + 2];
  const double G = E / (2 * (1 + nu)), kappa = 10 * (1 + nu) / (12 + 11 * nu);
  return w / (P * L * L * L / (3 * E * I) + P * L / (kappa * G * A));
}

}  // namespace arlequin::continuum::testing
