// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/failure.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace arlequin::dem {

namespace {

// Smith's trigonometric form of a symmetric 3x3 matrix's eigenvalues (CACM 4 (1961) 168):
// q + 2 p cos(phi + 2 pi k / 3), q the mean of the diagonal, p the deviator's scale (> 0 when
// p1, the sum of the squared off-diagonal terms, is not 0).
struct SmithScale {
  double q, p;
};
SmithScale smith_scale(const Sym3& t, double p1) {
  const double q = (t[0] + t[1] + t[2]) / 3.0;
  const double p2 = (t[0] - q) * (t[0] - q) + (t[1] - q) * (t[1] - q) + (t[2] - q) * (t[2] - q) + 2.0 * p1;
  return {q, std::sqrt(p2 / 6.0)};
}
double off_diagonal_squares(const Sym3& t) { return t[3] * t[3] + t[4] * t[4] + t[5] * t[5]; }
// The largest eigenvalue, q + 2 p cos(acos(r) / 3), for p1 != 0.
double largest_of(const Sym3& t, SmithScale s) {
  const auto [q, p] = s;
  // B = (A - q I) / p; r = det(B) / 2, clamped to [-1, 1] against round-off.
  const double b0 = (t[0] - q) / p, b1 = (t[1] - q) / p, b2 = (t[2] - q) / p;
  const double b3 = t[3] / p, b4 = t[4] / p, b5 = t[5] / p;
  const double det = b0 * (b1 * b2 - b3 * b3) - b5 * (b5 * b2 - b3 * b4) + b4 * (b5 * b3 - b1 * b4);
  const double r = std::clamp(0.5 * det, -1.0, 1.0);
  return q + 2.0 * p * std::cos(std::acos(r) / 3.0);
}

}  // namespace

double max_principal(const Sym3& t) {
  const double p1 = off_diagonal_squares(t);
  if (p1 == 0.0) return std::max({t[0], t[1], t[2]});
  return largest_of(t, smith_scale(t, p1));
}

double von_mises(const Sym3& t) {
  const double d01 = t[0] - t[1], d12 = t[1] - t[2], d20 = t[2] - t[0];
  return std::sqrt(0.5 * (d01 * d01 + d12 * d12 + d20 * d20) + 3.0 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5]));
}

double hydrostatic(const Sym3& t) { return (t[0] + t[1] + t[2]) / 3.0; }

double equivalent_stress_reaching(const Sym3& t, RdefEquivalent kind, double threshold) {
  if (kind == RdefEquivalent::max_principal) {
    const double p1 = off_diagonal_squares(t);
    if (p1 != 0.0) {
      // largest_of returns q + 2 p c with c = cos(...) <= 1 and 2 p >= 0, so q + 2 p bounds it
      // after rounding too; one (q, p) serves both, so the decision is largest_of's.
      const SmithScale s = smith_scale(t, p1);
      if (s.q + 2.0 * s.p < threshold) return -1.0;
      const double value = largest_of(t, s);
      return value >= threshold ? value : -1.0;
    }
  }
  const double equivalent = equivalent_stress(t, kind);
  return equivalent >= threshold ? equivalent : -1.0;
}

double equivalent_stress(const Sym3& t, RdefEquivalent kind) {
  switch (kind) {
    case RdefEquivalent::max_principal: return max_principal(t);
    case RdefEquivalent::von_mises: return von_mises(t);
    case RdefEquivalent::hydrostatic: return hydrostatic(t);
  }
  return 0.0;
}

std::string_view name_of(FailureCriterion c) {
  switch (c) {
    case FailureCriterion::bbf: return "bbf";
    case FailureCriterion::elongation: return "elongation";
    case FailureCriterion::rdef: return "rdef";
    case FailureCriterion::cohesive: return "cohesive";
  }
  return "";
}

std::string_view name_of(FailureMode m) {
  switch (m) {
    case FailureMode::tension: return "tension";
    case FailureMode::compression: return "compression";
    case FailureMode::bending: return "bending";
    case FailureMode::shear: return "shear";
    case FailureMode::torsion: return "torsion";
  }
  return "";
}

}  // namespace arlequin::dem
