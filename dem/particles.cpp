// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/particles.hpp"

#include <algorithm>
#include <cstring>
#include <numbers>

#include "common/parallel.hpp"
#include "dem/lanes.hpp"

namespace arlequin::dem {

namespace {

using namespace simd;

// The drift of eight DEs, the entries from x, v, omega and q: x += dt v, and q = exp(dt omega) q
// renormalised where omega != 0.
//  - The positions as their 24 doubles (x0 y0 z0 x1 ...) in three vectors, the layout they have
//    in memory: component by component, no transpose.
//  - The turn one DE a lane (dem/lanes.hpp), so a DE's bits do not depend on the block (a loop
//    DE by DE, in scalar code, could contract a product and a sum into a fused multiply-add
//    where the lanes do not), and only when one of the eight turns (none does in a block in
//    pure tension). A DE turning beyond the rotation vector's series (quat.hpp: 1e-2 rad in a
//    step) takes the exact rotation, by itself.
void drift_eight(Vec3* x, const Vec3* v, const Vec3* omega, Quat* q, double dt) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double) && sizeof(Quat) == 4 * sizeof(double));
  LaneMask turning{};
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t at = k * lanes;
    store_lanes(&x->x + at, load_lanes(&x->x + at) + load_lanes(&v->x + at) * dt);
    turning |= load_lanes(&omega->x + at) != 0.0;
  }
  if (!any_lane(turning)) return;

  Quad wq[lanes], qq[lanes];
  for (std::size_t l = 0; l < lanes; ++l) wq[l] = load_position(omega[l]), std::memcpy(&qq[l], &q[l], sizeof qq[l]);
  const LaneQuat wt = transpose(wq), qt = transpose(qq);
  const LaneVec w{wt.w, wt.v.x, wt.v.y};
  // exp(phi) q, phi = dt omega, renormalized, as from_rotation_vector below the series' limit
  const LaneVec phi = dt * w;
  const Lanes a2 = dot(phi, phi);
  const HalfAngle<Lanes> h = half_angle_series(a2);
  const LaneQuat r = renormalized(LaneQuat{h.cos_half, phi * h.sin_half_over_angle} * qt);
  const Lanes w2 = dot(w, w);
  for (std::size_t l = 0; l < lanes; ++l) {
    if (!(w2[l] > 0.0)) continue;  // not turning: q stays as it is
    if (a2[l] < 1e-4) q[l] = {r.w[l], {r.v.x[l], r.v.y[l], r.v.z[l]}};
    else q[l] = renormalized(from_rotation_vector(omega[l] * dt) * q[l]);
  }
}

}  // namespace

std::size_t ParticleSet::add(const Vec3& x, double r, double density) {
  const double m = density * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  position.push_back(x);
  reference.push_back(x);
  velocity.push_back({});
  orientation.push_back({});
  angular_velocity.push_back({});
  force.push_back({});
  torque.push_back({});
  radius.push_back(r);
  inv_mass.push_back(1.0 / m);
  return size() - 1;
}

void ParticleSet::clear_forces() {
  // On the threads, split as the kicks and the drift, so each thread clears the DEs it updates.
  const long n = static_cast<long>(size());
  // Two plain stores: `force[i] = torque[i] = Vec3{}` read the cleared force back to copy it.
  for_each_index(n, n > parallel_threshold, [f = force.data(), t = torque.data()](long i) {
    f[i] = Vec3{};
    t[i] = Vec3{};
  });
}

void ParticleSet::move_entry(std::size_t from, std::size_t to) {
  if (from != to) for_each_array([&](auto& array) { array[to] = array[from]; });
}

void ParticleSet::resize(std::size_t n) {
  for_each_array([n](auto& array) { array.resize(n); });
}

void ParticleSet::reserve(std::size_t n) {
  for_each_array([n](auto& array) { array.reserve(n); });
}

void ParticleSet::drift(long begin, long end, double dt) {
  long i = begin;
  for (; i + static_cast<long>(lanes) <= end; i += static_cast<long>(lanes))
    drift_eight(&position[i], &velocity[i], &angular_velocity[i], &orientation[i], dt);
  if (i == end) return;
  // The last DEs with DEs at rest in the lanes past them, through the same code.
  Vec3 x[lanes], v[lanes], omega[lanes];
  Quat q[lanes];
  const auto from = static_cast<std::ptrdiff_t>(i), count = static_cast<std::ptrdiff_t>(end - i);
  std::copy_n(position.begin() + from, count, x), std::copy_n(velocity.begin() + from, count, v);
  std::copy_n(angular_velocity.begin() + from, count, omega), std::copy_n(orientation.begin() + from, count, q);
  drift_eight(x, v, omega, q, dt);
  std::copy_n(x, count, position.begin() + from), std::copy_n(q, count, orientation.begin() + from);
}

}  // namespace arlequin::dem
