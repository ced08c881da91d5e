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

inline Quat normalized(const Quat& q) {
  const double s = 1.0 / std::sqrt(q.w * q.w + norm2(q.v));
  return {q.w * s, q.v * s};
}

// Exact rotation by the rotation vector phi (angle |phi| about phi/|phi|). Uses the
// Taylor form of sin(a/2)/a below 1e-4 rad so tiny steps lose no digits.
inline Quat from_rotation_vector(const Vec3& phi) {
  const double a2 = norm2(phi);
  if (a2 < 1e-8) {
    const double s = 0.5 - a2 / 48.0;  // sin(a/2)/a
    return normalized(Quat{1.0 - a2 / 8.0, phi * s});
  }
  const double a = std::sqrt(a2);
  return {std::cos(0.5 * a), phi * (std::sin(0.5 * a) / a)};
}

}  // namespace arlequin
