// SPDX-License-Identifier: GPL-3.0-or-later
// Closed-form UD composite moduli against the theory row of docs/validation.md R3 (seed Table 3).
#include <gtest/gtest.h>

#include "app/micromechanics.hpp"

namespace {

using arlequin::app::IsotropicPhase;
using arlequin::app::unidirectional_moduli;

constexpr IsotropicPhase carbon{260.0, 0.3}, epoxy{3.45, 0.3};  // GPa
constexpr double fibre_fraction = 0.513;

void expect_relative(double value, double expected, double tolerance) {
  EXPECT_NEAR(value / expected, 1.0, tolerance) << value << " vs " << expected;
}

TEST(Micromechanics, ReproducesTheR3TheoryRow) {
  constexpr auto c = unidirectional_moduli(carbon, epoxy, fibre_fraction);
  expect_relative(c.E_L, 135.06, 1e-3);
  expect_relative(c.E_T, 9.52, 1e-3);
  expect_relative(c.nu_LT, 0.3, 1e-3);
  expect_relative(c.G_LT, 3.98, 1e-3);
  expect_relative(c.G_TT, 3.41, 1e-3);
  // R3 lists nu_TT' = 0.3, which its own E_T and G_TT' contradict (see micromechanics.hpp);
  // transverse isotropy with the values above gives E_T / (2 G_TT') - 1 = 0.39461 [derived].
  expect_relative(c.nu_TT, 0.39461, 1e-4);
}

TEST(Micromechanics, EqualPhasesGiveThePhase) {
  constexpr IsotropicPhase same{70.0, 0.25};
  const auto c = unidirectional_moduli(same, same, 0.4);
  const double G = same.shear();
  expect_relative(c.E_L, 70.0, 1e-14);
  expect_relative(c.E_T, 70.0, 1e-14);
  expect_relative(c.nu_LT, 0.25, 1e-14);
  expect_relative(c.nu_TT, 0.25, 1e-14);
  expect_relative(c.G_LT, G, 1e-14);
  expect_relative(c.G_TT, G, 1e-14);
}

TEST(Micromechanics, PureMatrixLimit) {
  const auto c = unidirectional_moduli(carbon, epoxy, 0.0);
  expect_relative(c.E_T, epoxy.young, 1e-14);
  expect_relative(c.G_TT, epoxy.shear(), 1e-14);
  EXPECT_THROW(unidirectional_moduli(carbon, epoxy, 1.5), std::invalid_argument);
}

}  // namespace
