// SPDX-License-Identifier: GPL-3.0-or-later
// Eight DEs or bonds at once, one a lane of a GCC vector (one AVX-512 register; the compiler
// splits it on narrower CPUs): the Vec3 and Quat algebra of common/vec3.hpp and quat.hpp, lane by
// lane, and the loads that put eight DEs' data into lanes. Lane operations never mix lanes, so
// an item's results do not depend on the items it shares a block with: the beam kernel
// (bonds/beam_bond.cpp) and the drift (particles.cpp) pass every item through their lanes,
// alone or with seven others, and their results are the same on any thread count.
#pragma once
#include <cmath>
#include <cstddef>

#if defined(__AVX512F__)
// GCC 12's _mm512_sqrt_pd starts from _mm512_undefined_pd: a false -Wuninitialized (or
// -Wmaybe-uninitialized, by where it is inlined).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#if !defined(__clang__)  // a GCC warning; clang (the fuzz build) warns of the unknown name
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <immintrin.h>
#pragma GCC diagnostic pop
#endif

#include "common/quat.hpp"
#include "common/vec3.hpp"

namespace arlequin::dem::simd {

inline constexpr std::size_t lanes = 8;
using Lanes = double __attribute__((vector_size(lanes * sizeof(double))));

struct LaneVec {
  Lanes x, y, z;
};
struct LaneQuat {
  Lanes w;
  LaneVec v;
};
inline LaneVec operator+(const LaneVec& a, const LaneVec& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline LaneVec operator-(const LaneVec& a, const LaneVec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline LaneVec operator*(const LaneVec& a, Lanes s) { return {a.x * s, a.y * s, a.z * s}; }
inline LaneVec operator*(Lanes s, const LaneVec& a) { return a * s; }
inline LaneVec operator*(double s, const LaneVec& a) { return {a.x * s, a.y * s, a.z * s}; }
inline Lanes dot(const LaneVec& a, const LaneVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline LaneVec cross(const LaneVec& a, const LaneVec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline LaneQuat operator*(const LaneQuat& a, const LaneQuat& b) { return quaternion_product(a, b); }
inline LaneQuat renormalized(const LaneQuat& q) { return quaternion_renormalized(q); }
// R(q) a = a + 2w (v x a) + 2 v x (v x a), as common/quat.hpp's rotate: with t = (2 v) x a (2 v
// exact, shared by the rotations with one q), each component a + w t + v x t as three fused
// multiply-adds, not a product, a cross product and two sums.
inline LaneVec rotate(const LaneQuat& q, const LaneVec& a) {
  const LaneVec& v = q.v;
  const LaneVec t = cross(v + v, a);
  return {a.x + q.w * t.x + v.y * t.z - v.z * t.y,  //
          a.y + q.w * t.y + v.z * t.x - v.x * t.z,  //
          a.z + q.w * t.z + v.x * t.y - v.y * t.x};
}
using LaneMask = decltype(Lanes{} < Lanes{});
// The lanes' square roots, each correctly rounded (as std::sqrt).
inline Lanes lane_sqrt(Lanes x) {
#if defined(__AVX512F__)
  static_assert(lanes == 8);
  return _mm512_sqrt_pd(x);  // one instruction (a loop of std::sqrt stays scalar: errno)
#else
  Lanes r;
  for (std::size_t l = 0; l < lanes; ++l) r[l] = std::sqrt(x[l]);
  return r;
#endif
}
// Eight consecutive doubles from p, at any alignment, to or from a vector: one load or store
// (a memcpy goes through the stack in halves, which a whole-vector load then waits on).
typedef Lanes UnalignedLanes __attribute__((aligned(alignof(double)), may_alias));
inline Lanes load_lanes(const double* p) { return *reinterpret_cast<const UnalignedLanes*>(p); }
inline void store_lanes(double* p, Lanes v) { *reinterpret_cast<UnalignedLanes*>(p) = v; }

// Whether every lane of m is set: the test that lets a block skip the rare lanes' loops.
inline bool every_lane(LaneMask m) {
#if defined(__AVX512F__)
  return _mm512_test_epi64_mask(__m512i(m), __m512i(m)) == 0xff;
#else
  for (std::size_t l = 0; l < lanes; ++l)
    if (!m[l]) return false;
  return true;
#endif
}
// Whether any lane of m is set.
inline bool any_lane(LaneMask m) {
#if defined(__AVX512F__)
  return _mm512_test_epi64_mask(__m512i(m), __m512i(m)) != 0;
#else
  for (std::size_t l = 0; l < lanes; ++l)
    if (m[l]) return true;
  return false;
#endif
}

// Eight quaternions (w, x, y, z) as one LaneQuat: a 4 x 8 transpose, shuffles only (pairs side
// by side, then two rounds).
static_assert(sizeof(Quat) == 4 * sizeof(double));
using Quad = double __attribute__((vector_size(4 * sizeof(double))));
inline LaneQuat transpose(const Quad (&q)[lanes]) {
  // Pairs side by side: p[k] = (q[2k], q[2k+1]) = w x y z w x y z.
  Lanes p[4];
  for (int k = 0; k < 4; ++k) p[k] = __builtin_shufflevector(q[2 * k], q[2 * k + 1], 0, 1, 2, 3, 4, 5, 6, 7);
  // Round 1: from two pairs, (w, x) and (y, z) of four quaternions.
  const Lanes wx01 = __builtin_shufflevector(p[0], p[1], 0, 1, 4, 5, 8, 9, 12, 13);
  const Lanes yz01 = __builtin_shufflevector(p[0], p[1], 2, 3, 6, 7, 10, 11, 14, 15);
  const Lanes wx23 = __builtin_shufflevector(p[2], p[3], 0, 1, 4, 5, 8, 9, 12, 13);
  const Lanes yz23 = __builtin_shufflevector(p[2], p[3], 2, 3, 6, 7, 10, 11, 14, 15);
  // Round 2: every other element.
  return {__builtin_shufflevector(wx01, wx23, 0, 2, 4, 6, 8, 10, 12, 14),
          {__builtin_shufflevector(wx01, wx23, 1, 3, 5, 7, 9, 11, 13, 15),
           __builtin_shufflevector(yz01, yz23, 0, 2, 4, 6, 8, 10, 12, 14),
           __builtin_shufflevector(yz01, yz23, 1, 3, 5, 7, 9, 11, 13, 15)}};
}

// Eight vectors loaded as (x, y, z, 0) (load_position) as one LaneVec.
inline LaneVec transpose_vectors(const Quad (&v)[lanes]) {
  const LaneQuat t = transpose(v);
  return {t.w, t.v.x, t.v.y};
}

// A position (x, y, z, 0) as one vector: a masked load, which reads nothing past z.
inline Quad load_position(const Vec3& x) {
#if defined(__AVX512F__)
  return _mm256_maskz_loadu_pd(0x7, &x.x);
#else
  return Quad{x.x, x.y, x.z, 0.0};
#endif
}

}  // namespace arlequin::dem::simd
