// SPDX-License-Identifier: GPL-3.0-or-later
// Closed-form elastic moduli of a unidirectional fibre composite with isotropic phases: the
// "theory" row of docs/validation.md R3 (seed Table 3), against which DEM REV tests are judged.
//
// Contract: fibre and matrix are isotropic and linear elastic (E > 0, -1 < nu < 0.5), the
// fibre volume fraction is in [0, 1]; any consistent unit for the moduli (the results are
// in the same unit). L is the fibre direction, T and T' two transverse directions.
//
// Header-only (constexpr): the functions are small, exact and used by the unit tests, which
// link the DEM and common libraries only.
#pragma once
#include <stdexcept>

namespace arlequin::app {

struct IsotropicPhase {
  double young;    // E
  double poisson;  // nu

  constexpr double shear() const { return young / (2.0 * (1.0 + poisson)); }
  // Plane-strain bulk modulus k = K + G/3 = E / (2 (1 + nu)(1 - 2 nu)): the modulus relating
  // the mean transverse stress to the transverse area change under zero axial strain.
  constexpr double plane_strain_bulk() const { return young / (2.0 * (1.0 + poisson) * (1.0 - 2.0 * poisson)); }
};

// Transversely isotropic engineering constants of the composite.
struct UnidirectionalModuli {
  double E_L, E_T, nu_LT, nu_TT, G_LT, G_TT;
};

// Halpin–Tsai interpolation (Halpin & Kardos, Polym. Eng. Sci. 16 (1976) 344):
//   M / M_m = (1 + xi eta V_f) / (1 - eta V_f),  eta = (M_f/M_m - 1) / (M_f/M_m + xi).
constexpr double halpin_tsai(double fibre, double matrix, double xi, double fibre_fraction) {
  const double ratio = fibre / matrix;
  const double eta = (ratio - 1.0) / (ratio + xi);
  return matrix * (1.0 + xi * eta * fibre_fraction) / (1.0 - eta * fibre_fraction);
}

// Transverse plane-strain bulk modulus K23 of the composite cylinder assemblage
// (Hashin & Rosen, J. Appl. Mech. 31 (1964) 223; Hashin, J. Appl. Mech. 46 (1979) 543;
// Christensen, Mechanics of Composite Materials (1979) ch. IV):
//   K23 = k_m + V_f / (1/(k_f - k_m) + V_m/(k_m + G_m)),
// exact for the assemblage and equal to the Hashin–Shtrikman lower bound when k_f > k_m.
constexpr double composite_cylinder_k23(const IsotropicPhase& fibre, const IsotropicPhase& matrix,
                                        double fibre_fraction) {
  const double k_f = fibre.plane_strain_bulk(), k_m = matrix.plane_strain_bulk();
  return k_m + fibre_fraction / (1.0 / (k_f - k_m) + (1.0 - fibre_fraction) / (k_m + matrix.shear()));
}

// The R3 theory row: rule of mixtures for E_L and nu_LT; Halpin–Tsai for G_LT (xi = 1) and
// G_TT' (xi = (1 + nu_m)/(3 - nu_m - 4 nu_m^2) = 1/(3 - 4 nu_m) = k_m/(k_m + 2 G_m), k_m the
// plane-strain bulk modulus: Tucker & Liang, Compos. Sci. Technol. 59 (1999) 655, Table 1);
// E_T from Hashin's relation with K23, nu_TT' from transverse isotropy.
//
// Note: for the R3 phases this gives nu_TT' = 0.3946, not the 0.3 of the seed's theory row;
// that 0.3 contradicts the row's own E_T and G_TT' (9.52 / (2 x 3.41) - 1 = 0.396) and is the
// rule of mixtures of two phases that both have nu = 0.3.
constexpr UnidirectionalModuli unidirectional_moduli(const IsotropicPhase& fibre, const IsotropicPhase& matrix,
                                                     double fibre_fraction) {
  if (!(fibre_fraction >= 0.0 && fibre_fraction <= 1.0))
    throw std::invalid_argument("unidirectional_moduli: fibre volume fraction must be in [0, 1]");
  const double vf = fibre_fraction, vm = 1.0 - fibre_fraction;
  UnidirectionalModuli c{};
  // Voigt (iso-strain) along the fibres: exact to O((nu_f - nu_m)^2) (Hill, JMPS 12 (1964) 199).
  c.E_L = fibre.young * vf + matrix.young * vm;
  c.nu_LT = fibre.poisson * vf + matrix.poisson * vm;
  c.G_LT = halpin_tsai(fibre.shear(), matrix.shear(), 1.0, vf);
  const double nu_m = matrix.poisson;
  c.G_TT = halpin_tsai(fibre.shear(), matrix.shear(), (1.0 + nu_m) / (3.0 - nu_m - 4.0 * nu_m * nu_m), vf);
  // Hashin (1979): 4/E_T = 1/K23 + 1/G_TT' + 4 nu_LT^2 / E_L.
  const double k23 = composite_cylinder_k23(fibre, matrix, vf);
  c.E_T = 1.0 / (1.0 / (4.0 * k23) + 1.0 / (4.0 * c.G_TT) + c.nu_LT * c.nu_LT / c.E_L);
  // Isotropy in the transverse plane: G_TT' = E_T / (2 (1 + nu_TT')).
  c.nu_TT = c.E_T / (2.0 * c.G_TT) - 1.0;
  return c;
}

}  // namespace arlequin::app
