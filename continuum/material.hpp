// SPDX-License-Identifier: GPL-3.0-or-later
// Material: linear elastic stiffness in Voigt form and density.
// Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear strains (gamma = 2 eps), so
// sigma = C eps and the strain energy density is eps.C.eps / 2.
#pragma once
#include <Eigen/Dense>
#include <array>

#include "common/vec3.hpp"

namespace arlequin::continuum {

using Voigt = Eigen::Matrix<double, 6, 1>;
using Stiffness = Eigen::Matrix<double, 6, 6>;

struct Material {
  Stiffness C = Stiffness::Zero();
  double density = 0.0;
  // The share of the mass that a motion along x, y, z carries (1 each: a solid). A homogenised
  // dry weave, whose yarn families slide along each other, moves only its x-running yarns along
  // x (docs/theory.md#directional-inertia).
  Vec3 inertia{1.0, 1.0, 1.0};

  // InputError unless E > 0, -1 < nu < 0.5, density > 0.
  static Material isotropic(double E, double nu, double density);
  // Transversely isotropic about `axis` (need not be unit): E_L, nu_LT, G_LT along/around the
  // axis, E_T and nu_TT in the isotropic plane (G_TT = E_T / (2 (1 + nu_TT))). InputError unless
  // the compliance is positive definite.
  static Material transversely_isotropic(double E_L, double E_T, double nu_LT, double nu_TT, double G_LT,
                                         const Vec3& axis, double density);
  // Orthotropic in the x, y, z axes: E = (E_x, E_y, E_z), G = (G_yz, G_xz, G_xy) (Voigt order),
  // nu = (nu_xy, nu_xz, nu_yz) with nu_ij = -eps_j / eps_i under uniaxial stress along i.
  // InputError unless the moduli and density are positive and the compliance positive definite.
  static Material orthotropic(const std::array<double, 3>& E, const std::array<double, 3>& G,
                              const std::array<double, 3>& nu, double density);
};

}  // namespace arlequin::continuum
