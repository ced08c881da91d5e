// SPDX-License-Identifier: GPL-3.0-or-later
// Shared set-up for the continuum tests: mesh paths, settings, affine fields, patch tests.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

#include "continuum/registry.hpp"

namespace arlequin::continuum::testing {

inline std::string mesh_path(const std::string& name) { return std::string(ARLEQUIN_SOURCE_DIR) + "/meshes/" + name; }

inline ContinuumSettings settings(const std::string& mesh, double size, int order, const Material& m) {
  ContinuumSettings s;
  s.mesh = {mesh_path(mesh), size, order, {}};
  s.materials = {{"", m}};
  return s;
}

// A generic affine displacement field u = A x + c.
inline Vec3 affine(const Vec3& x) {
  return {1e-3 + 2e-3 * x.x - 1e-3 * x.y + 0.5e-3 * x.z, -2e-3 + 0.7e-3 * x.x + 1.5e-3 * x.y - 0.4e-3 * x.z,
          0.5e-3 - 0.3e-3 * x.x + 0.9e-3 * x.y + 1.1e-3 * x.z};
}
inline Voigt affine_strain() {
  Voigt e;
  e << 2e-3, 1.5e-3, 1.1e-3, 0.9e-3 - 0.4e-3, 0.5e-3 - 0.3e-3, -1e-3 + 0.7e-3;
  return e;
}

// Affine patch test on a solver of unit_cube.geo with material `mat`: the affine field is
// prescribed on the whole boundary or, with `traction`, on xmin only while the five other faces
// carry its traction sigma n. Returns the largest nodal displacement error relative to the
// field's size (3e-3) and the largest relative stress error at the integration points; both are
// round-off for a method that passes the test.
struct PatchErrors {
  double displacement = 0, stress = 0;
};
inline PatchErrors patch_test(ContinuumSolver& s, const Material& mat, bool traction) {
  const Voigt sigma = mat.C * affine_strain();
  s.fix(traction ? "xmin" : "boundary", {true, true, true}, [](const Vec3& x, double) { return affine(x); });
  if (traction) {
    const std::pair<const char*, Vec3> faces[] = {
        {"xmax", {1, 0, 0}}, {"ymin", {0, -1, 0}}, {"ymax", {0, 1, 0}}, {"zmin", {0, 0, -1}}, {"zmax", {0, 0, 1}}};
    for (const auto& [group, n] : faces) {
      const Vec3 t{sigma[0] * n.x + sigma[5] * n.y + sigma[4] * n.z, sigma[5] * n.x + sigma[1] * n.y + sigma[3] * n.z,
                   sigma[4] * n.x + sigma[3] * n.y + sigma[2] * n.z};
      s.add_traction(group, [t](const Vec3&, double) { return t; });
    }
  }
  s.solve_static("-ksp_type preonly -pc_type lu");
  PatchErrors e;
  for (int n = 0; n < s.num_nodes(); ++n) {
    const Vec3 u = affine(s.nodes()[n]);
    for (int c = 0; c < 3; ++c) e.displacement = std::max(e.displacement, std::abs(s.displacement()[3 * n + c] - u[c]) / 3e-3);
  }
  for (const Voigt& st : s.point_stress()) e.stress = std::max(e.stress, (st - sigma).norm() / sigma.norm());
  return e;
}

// internal_force and strain_energy use the assembled K (ContinuumSolver::stiffness). Checked
// against the integration points themselves: E(w) = 1/2 sum_q w_q eps_q.C eps_q from
// point_strain() and point_stress(), and the bilinear form f_int(u).v = a(u, v) =
// (E(u + v) - E(u - v)) / 2, for random u and v.
inline void expect_force_is_the_points_bilinear_form(ContinuumSolver& s) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(-1e-3, 1e-3);
  Field u(s.displacement().size()), v(u.size());
  for (double& x : u) x = uni(rng);
  for (double& x : v) x = uni(rng);
  const auto energy_of = [&](double sign) {
    for (size_t d = 0; d < u.size(); ++d) s.displacement()[d] = u[d] + sign * v[d];
    const std::vector<Voigt> strain = s.point_strain(), stress = s.point_stress();
    double e = 0;
    for (size_t q = 0; q < strain.size(); ++q) e += 0.5 * s.point_weights()[q] * strain[q].dot(stress[q]);
    EXPECT_NEAR(s.strain_energy() / e, 1.0, 1e-12);
    return e;
  };
  const double a_uv = 0.5 * (energy_of(1.0) - energy_of(-1.0));
  Field f;
  s.internal_force(u, f);
  double fv = 0;
  for (size_t d = 0; d < u.size(); ++d) fv += f[d] * v[d];
  EXPECT_NEAR(fv / a_uv, 1.0, 1e-10);
}

}  // namespace arlequin::continuum::testing
