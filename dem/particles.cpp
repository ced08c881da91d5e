#include "dem/particles.hpp"

#include <algorithm>
#include <numbers>

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
  groups.push_back(0);
  return size() - 1;
}

void ParticleSet::clear_forces() {
  std::fill(force.begin(), force.end(), Vec3{});
  std::fill(torque.begin(), torque.end(), Vec3{});
}

void ParticleSet::move_entry(std::size_t from, std::size_t to) {
  if (from == to) return;
  position[to] = position[from];
  reference[to] = reference[from];
  velocity[to] = velocity[from];
  orientation[to] = orientation[from];
  angular_velocity[to] = angular_velocity[from];
  force[to] = force[from];
  torque[to] = torque[from];
  radius[to] = radius[from];
  inv_mass[to] = inv_mass[from];
  groups[to] = groups[from];
}

void ParticleSet::resize(std::size_t n) {
  position.resize(n);
  reference.resize(n);
  velocity.resize(n);
  orientation.resize(n);
  angular_velocity.resize(n);
  force.resize(n);
  torque.resize(n);
  radius.resize(n);
  inv_mass.resize(n);
  groups.resize(n);
}

void ParticleSet::reserve(std::size_t n) {
  position.reserve(n);
  reference.reserve(n);
  velocity.reserve(n);
  orientation.reserve(n);
  angular_velocity.reserve(n);
  force.reserve(n);
  torque.reserve(n);
  radius.reserve(n);
  inv_mass.reserve(n);
  groups.reserve(n);
}

}  // namespace arlequin::dem
