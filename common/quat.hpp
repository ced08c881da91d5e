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

constexpr Quat operator*(const Quat& a, const Quat& b) {
  return {a.w * b.w - dot(a.v, b.v), a.w * b.v + b.w * a.v + cross(a.v, b.v)};
}
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
constexpr Quat renormalized(const Quat& q) {
  const double s = 1.5 - 0.5 * (q.w * q.w + norm2(q.v));
  return {q.w * s, q.v * s};
}

// Exact rotation by the rotation vector phi (angle a = |phi| about phi/|phi|). Below
// a = 1e-2 rad, cos(a/2) and sin(a/2)/a are their Taylor series to a^4: the first terms
// left out, a^6/46080 and a^6/645120, are below 2.2e-17, i.e. round-off, and a time step's
// small angles need no square root, sine or cosine.
inline Quat from_rotation_vector(const Vec3& phi) {
  const double a2 = norm2(phi);
  if (a2 < 1e-4) {
    // Products by the reciprocals, not quotients: no division in a drift.
    constexpr double one_8th = 1.0 / 8.0, one_48th = 1.0 / 48.0, one_80th = 1.0 / 80.0;
    const double c = 1.0 - a2 * one_8th * (1.0 - a2 * one_48th);   // cos(a/2)
    const double s = 0.5 - a2 * one_48th * (1.0 - a2 * one_80th);  // sin(a/2)/a
    return {c, phi * s};
  }
  const double a = std::sqrt(a2);
  return {std::cos(0.5 * a), phi * (std::sin(0.5 * a) / a)};
}

}  // namespace arlequin
