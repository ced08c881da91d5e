// SPDX-License-Identifier: GPL-3.0-or-later
// The rotation update of the drift (common/quat.hpp): the small-angle series of the rotation
// quaternion against the sine and cosine in long double, and the division-free
// renormalisation against the norm it must keep.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/quat.hpp"

namespace arlequin {
namespace {

// cos(a/2) and sin(a/2)/a from the library's long-double functions: an independent reference.
Quat reference_rotation(const Vec3& phi) {
  const long double a = std::sqrt((long double)norm2(phi));
  const long double s = std::sin(a / 2) / a;
  return {double(std::cos(a / 2)), Vec3{double(phi.x * s), double(phi.y * s), double(phi.z * s)}};
}

TEST(Quaternion, SmallAngleSeriesIsTheRotationToRoundOff) {
  const Vec3 axis = Vec3{0.3, -0.4, 0.5} / std::sqrt(0.5);
  // Both sides of the series' limit a = 1e-2 rad, and down to angles of a tiny time step.
  for (double a : {1e-12, 1e-8, 1e-5, 1e-3, 5e-3, 0.99e-2, 1.01e-2, 0.1, 1.0}) {
    const Quat q = from_rotation_vector(axis * a), exact = reference_rotation(axis * a);
    EXPECT_NEAR(q.w, exact.w, 2.3e-16) << "angle " << a;
    EXPECT_LT(norm(q.v - exact.v), 2.3e-16 * a) << "angle " << a;
    EXPECT_NEAR(q.w * q.w + norm2(q.v), 1.0, 4.5e-16) << "angle " << a;
  }
}

TEST(Quaternion, RenormalisationRemovesTheNormErrorToSecondOrder) {
  const Quat q = from_rotation_vector({0.2, -0.7, 0.4});
  for (double e : {1e-4, 1e-6, 1e-8}) {  // |q|^2 = 1 + e before; O(e^2) after
    const double scale = std::sqrt(1.0 + e);
    const Quat r = renormalized({q.w * scale, q.v * scale});
    EXPECT_NEAR(r.w * r.w + norm2(r.v), 1.0, 1.0 * e * e + 4.5e-16) << "e " << e;
  }
}

TEST(Quaternion, ManyRenormalisedProductsStayUnit) {
  // 1e6 drifts by random small rotations: the norm error does not accumulate.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-1e-3, 1e-3);
  Quat q;
  for (int n = 0; n < 1000000; ++n) q = renormalized(from_rotation_vector({angle(rng), angle(rng), angle(rng)}) * q);
  EXPECT_NEAR(q.w * q.w + norm2(q.v), 1.0, 1e-15);
}

}  // namespace
}  // namespace arlequin
