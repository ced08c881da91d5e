// SPDX-License-Identifier: GPL-3.0-or-later
// Spherical discrete elements in structure-of-arrays form.
//
// Contract: every array has size(); index i is one DE for the whole run (once bonds or groups
// refer to DEs they are never reordered or removed, so those indices stay valid; `keep_only`
// is for a sample being built). Orientation q maps body to
// world frame; angular velocity omega is in the world frame. Inertia is the sphere's
// I = 2/5 m R^2, isotropic, so Euler's equations reduce to d(omega)/dt = torque / I.
#pragma once
#include <cstdint>
#include <vector>

#include "common/quat.hpp"
#include "common/vec3.hpp"

namespace arlequin::dem {

struct ParticleSet {
  std::vector<Vec3> position;         // m
  std::vector<Vec3> reference;        // m, position at t = 0 (for displacements)
  std::vector<Vec3> velocity;         // m/s
  std::vector<Quat> orientation;      // body -> world
  std::vector<Vec3> angular_velocity; // rad/s, world frame
  std::vector<Vec3> force;            // N, accumulated each step
  std::vector<Vec3> torque;           // N m, accumulated each step
  std::vector<double> radius;         // m
  std::vector<double> inv_mass;       // 1/kg

  std::size_t size() const { return position.size(); }

  // Appends a DE at rest with identity orientation; returns its index.
  std::size_t add(const Vec3& x, double r, double density);

  double mass(std::size_t i) const { return 1.0 / inv_mass[i]; }
  // Derived from the mass (I = 2/5 m R^2) rather than stored: 8 B less per DE, and any
  // weighting of the mass carries over to the inertia.
  double inv_inertia(std::size_t i) const { return inv_mass[i] / (0.4 * radius[i] * radius[i]); }
  double inertia(std::size_t i) const { return 1.0 / inv_inertia(i); }
  void clear_forces();
  // The drift of DEs [begin, end) over dt: x += dt v, and q = exp(dt omega) q renormalised
  // (omega is constant over the drift of a sphere, so the rotation is exact). Eight DEs at a
  // time, one a vector lane: a DE's new position and orientation have the same bits whichever
  // DEs share its block (so on any thread count, and alone).
  void drift(long begin, long end, double dt);
  void reserve(std::size_t n);
  // Drops every DE i with keep(i) false, keeping the order of the others; returns how many
  // were dropped. Only before bonds, groups or boundary conditions refer to DE indices.
  template <class Keep>
  std::size_t keep_only(Keep keep);

 private:
  // Applies f to every per-DE array: one list of the arrays for reserve, resize and moves.
  template <class F>
  void for_each_array(F f) {
    f(position), f(reference), f(velocity), f(orientation), f(angular_velocity);
    f(force), f(torque), f(radius), f(inv_mass);
  }
  void move_entry(std::size_t from, std::size_t to);
  void resize(std::size_t n);
};

template <class Keep>
std::size_t ParticleSet::keep_only(Keep keep) {
  const std::size_t n = size();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (keep(i)) move_entry(i, kept++);
  resize(kept);
  return n - kept;
}

}  // namespace arlequin::dem
