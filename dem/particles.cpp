// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/particles.hpp"

#include <algorithm>
#include <numbers>

#include "common/parallel.hpp"

namespace arlequin::dem {

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

}  // namespace arlequin::dem
