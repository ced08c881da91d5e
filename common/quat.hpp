// SPDX-License-Identifier: GPL-3.0-or-later
// Unit quaternion for rigid rotations: q = (w, v), rotation R(q) x = q x q*.
#pragma once
#include <cmath>

#include "vec3.hpp"

namespace arlequin {

struct Quat {
  double w = 1.0;
  Vec3 v{};
};

// The quaternion algebra below is written once for one quaternion and for eight in vector lanes
// (dem/lanes.hpp's LaneQuat): Q is any type with a scalar part w and a vector part v whose dot,
// cross and vector operators exist, Real a double or a vector of doubles. One expression serves
// both, so that a DE's turn is the same arithmetic in the drift's lanes and alone.
template <class Q>
constexpr Q quaternion_product(const Q& a, const Q& b) {
  return {a.w * b.w - dot(a.v, b.v), a.w * b.v + b.w * a.v + cross(a.v, b.v)};
}
constexpr Quat operator*(const Quat& a, const Quat& b) { return quaternion_product(a, b); }
constexpr Quat conjugate(const Quat& q) { return {q.w, -q.v}; }

// R(q) a = a + 2w (v x a) + 2 v x (v x a): 30 flops, no matrix.
constexpr Vec3 rotate(const Quat& q, const Vec3& a) {
  const Vec3 t = 2.0 * cross(q.v, a);
  return a + q.w * t + cross(q.v, t);
}
// R(q)^T a (rotation by the inverse).
constexpr Vec3 rotate_inverse(const Quat& q, const Vec3& a) { return rotate(conjugate(q), a); }

// Rescales a quaternion whose norm is 1 up to round-off (a product of unit quaternions) back
// to 1: one Newton step for 1/sqrt(n2) about n2 = 1, q (3 - |q|^2)/2, leaves a norm error of
// O((|q|^2 - 1)^2), so the error cannot accumulate over steps; no square root, no division.
template <class Q>
constexpr Q quaternion_renormalized(const Q& q) {
  const auto s = 1.5 - 0.5 * (q.w * q.w + dot(q.v, q.v));
  return {q.w * s, q.v * s};
}
constexpr Quat renormalized(const Quat& q) { return quaternion_renormalized(q); }

// cos(a/2) and sin(a/2)/a of the angle a from a2 = a^2, by their Taylor series to a^4: valid
// below a = 1e-2 rad (from_rotation_vector). Products by the reciprocals, not quotients: no
// division in a drift.
template <class Real>
struct HalfAngle {
  Real cos_half, sin_half_over_angle;
};
template <class Real>
constexpr HalfAngle<Real> half_angle_series(Real a2) {
  constexpr double one_8th = 1.0 / 8.0, one_48th = 1.0 / 48.0, one_80th = 1.0 / 80.0;
  return {1.0 - a2 * one_8th * (1.0 - a2 * one_48th), 0.5 - a2 * one_48th * (1.0 - a2 * one_80th)};
}

// Exact rotation by the rotation vector phi (angle a = |phi| about phi/|phi|). Below
// a = 1e-2 rad, cos(a/2) and sin(a/2)/a are their Taylor series to a^4: the first terms
// left out, a^6/46080 and a^6/645120, are below 2.2e-17, i.e. round-off, and a time step's
// small angles need no square root, sine or cosine.
inline Quat from_rotation_vector(const Vec3& phi) {
  const double a2 = norm2(phi);
  if (a2 < 1e-4) {
    const HalfAngle<double> h = half_angle_series(a2);
    return {h.cos_half, phi * h.sin_half_over_angle};
  }
  const double a = std::sqrt(a2);
  return {std::cos(0.5 * a), phi * (std::sin(0.5 * a) / a)};
}

}  // namespace arlequin
