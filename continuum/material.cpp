// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/material.hpp"

#include <cmath>
#include <string>

#include "common/error.hpp"

namespace arlequin::continuum {

namespace {

// Voigt index of the symmetric pair (i, j).
constexpr int voigt(int i, int j) {
  if (i == j) return i;
  return 6 - i - j;  // (1,2)->3 yz, (0,2)->4 xz, (0,1)->5 xy
}

// C = S^-1 for a compliance S that must be positive definite (InputError naming the model).
Stiffness stiffness_of_compliance(const Stiffness& S, const char* model) {
  Eigen::SelfAdjointEigenSolver<Stiffness> eig(S);
  if (eig.eigenvalues().minCoeff() <= 0)
    throw InputError(std::string(model) + " constants give a compliance that is not positive definite");
  return S.inverse();
}

}  // namespace

Material Material::isotropic(double E, double nu, double density) {
  if (!(E > 0) || !(nu > -1.0 && nu < 0.5) || !(density > 0))
    throw InputError("isotropic material needs E > 0, -1 < nu < 0.5, density > 0 (got E=" + std::to_string(E) +
                     ", nu=" + std::to_string(nu) + ", density=" + std::to_string(density) + ")");
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  Material m;
  m.density = density;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.C(i, j) = lambda;
    m.C(i, i) = lambda + 2 * mu;
    m.C(3 + i, 3 + i) = mu;
  }
  return m;
}

Material Material::transversely_isotropic(double E_L, double E_T, double nu_LT, double nu_TT, double G_LT,
                                          const Vec3& axis, double density) {
  if (!(E_L > 0 && E_T > 0 && G_LT > 0 && density > 0) || !(norm(axis) > 0))
    throw InputError("transversely isotropic material needs E_L, E_T, G_LT, density > 0 and a non-zero axis");
  // Compliance in the material frame, axis 0 = L (e.g. Jones, Mechanics of Composite Materials, Eq. 2.27-2.31).
  Stiffness S = Stiffness::Zero();
  S(0, 0) = 1 / E_L;
  S(1, 1) = S(2, 2) = 1 / E_T;
  S(0, 1) = S(1, 0) = S(0, 2) = S(2, 0) = -nu_LT / E_L;
  S(1, 2) = S(2, 1) = -nu_TT / E_T;
  S(3, 3) = 2 * (1 + nu_TT) / E_T;  // 1 / G_TT
  S(4, 4) = S(5, 5) = 1 / G_LT;
  const Stiffness C_local = stiffness_of_compliance(S, "transversely isotropic");

  // Material frame: rows of R are the local axes (e_L, e_T1, e_T2), x_local = R x.
  Eigen::Vector3d a(axis.x, axis.y, axis.z);
  a.normalize();
  Eigen::Vector3d helper = std::abs(a.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  Eigen::Vector3d t1 = a.cross(helper).normalized(), t2 = a.cross(t1);
  Eigen::Matrix3d R;
  R.row(0) = a;
  R.row(1) = t1;
  R.row(2) = t2;

  // C_ijkl = R_ai R_bj R_ck R_dl C'_abcd on the full tensor; Voigt stiffness entries equal
  // tensor entries because the engineering shear factor sits in the strain vector.
  Material m;
  m.density = density;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = k; l < 3; ++l) {
          double c = 0;
          for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q)
              for (int r = 0; r < 3; ++r)
                for (int s = 0; s < 3; ++s) c += R(p, i) * R(q, j) * R(r, k) * R(s, l) * C_local(voigt(p, q), voigt(r, s));
          m.C(voigt(i, j), voigt(k, l)) = c;
        }
  return m;
}

Material Material::orthotropic(const std::array<double, 3>& E, const std::array<double, 3>& G,
                               const std::array<double, 3>& nu, double density) {
  if (!(E[0] > 0 && E[1] > 0 && E[2] > 0 && G[0] > 0 && G[1] > 0 && G[2] > 0 && density > 0))
    throw InputError("orthotropic material needs E_x, E_y, E_z, G_yz, G_xz, G_xy, density > 0");
  // Compliance in the x, y, z axes (docs/references.md#jones1999, chapter 2), with
  // nu_ij = -eps_j / eps_i under a stress along i, so S_ij = -nu_ij / E_i = -nu_ji / E_j.
  Stiffness S = Stiffness::Zero();
  for (int i = 0; i < 3; ++i) {
    S(i, i) = 1 / E[i];
    S(3 + i, 3 + i) = 1 / G[i];
  }
  S(0, 1) = S(1, 0) = -nu[0] / E[0];  // nu_xy
  S(0, 2) = S(2, 0) = -nu[1] / E[0];  // nu_xz
  S(1, 2) = S(2, 1) = -nu[2] / E[1];  // nu_yz
  Material m;
  m.density = density;
  m.C = stiffness_of_compliance(S, "orthotropic");
  return m;
}

}  // namespace arlequin::continuum
