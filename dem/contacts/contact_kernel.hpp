// SPDX-License-Identifier: GPL-3.0-or-later
// The pair loop every contact law shares, written once: a law is a kernel that gives the force
// and the energy of two touching spheres, and ContactKernelLaw<Law> turns it into a ContactLaw.
//
// A law derives from ContactKernelLaw<Law> (CRTP: inlined per pair, no virtual call per
// contact) and supplies:
//   static constexpr std::string_view name;   its case-file name (dem.contact.law)
//   Vec3 force_on_j(const Vec3& d, double distance, double reach) const;
//       the force on DE j of a pair with d = x_j - x_i, |d| = distance < reach = R_i + R_j, N
//   double energy_of(double overlap) const;    elastic energy at overlap = reach - distance > 0, J
//   double stiffness() const override;        the largest normal stiffness, N/m (time step)
//   double friction() const;                  Coulomb coefficient mu (0: frictionless)
//   double slip_velocity() const;             regularisation of the friction, m/s
// Friction (docs/theory.md#contact-friction): the tangential force on j opposes the sliding
// velocity v_t of the contact point, F_t = -mu |F_n| v_t / max(|v_t|, v_slip): Coulomb while
// sliding faster than v_slip, viscous below it (no history, so the neighbour list can be
// rebuilt freely); it acts at the contact point, hence torques. Its power is returned.
#pragma once
#include <algorithm>
#include <cmath>

#include "dem/contacts/contact_law.hpp"

namespace arlequin::dem {

template <class Law>
class ContactKernelLaw : public ContactLaw {
 public:
  std::string_view law() const override { return Law::name; }

  ContactPass accumulate_forces(const NeighbourList& list, ParticleSet& p, std::span<std::uint32_t> touching = {},
                                std::span<const double> weight = {}) const override {
    const double mu = self().friction();
    const bool count = !touching.empty(), weighted = !weight.empty();
    ContactPass pass;
    for (auto [i, j] : list.pairs()) {
      const Vec3 d = p.position[j] - p.position[i];
      const double reach = p.radius[i] + p.radius[j];
      const double dist2 = norm2(d);
      if (dist2 >= reach * reach) continue;  // a listed pair that does not touch
      const double distance = std::sqrt(dist2);
      Vec3 f_j = self().force_on_j(d, distance, reach);
      const double w = weighted ? std::min(weight[i], weight[j]) : 1.0;
      if (weighted) f_j *= w;
      p.force[i] -= f_j;
      p.force[j] += f_j;
      if (count) ++touching[i], ++touching[j];
      if (mu > 0.0) pass.friction_power += add_friction(i, j, d / distance, 0.5 * (reach - distance), norm(f_j), mu, p);
      ++pass.touching;
      // The deepest contact is watched where the DEM alone holds the pair (weight 1): in a
      // coupling overlap the continuum carries the share the weighted contact does not.
      const double depth = w < 1.0 ? 0.0 : (reach - distance) / std::min(p.radius[i], p.radius[j]);
      if (depth > pass.deepest) pass = {pass.friction_power, depth, i, j, pass.touching};
    }
    return pass;
  }

  double energy(const NeighbourList& list, const ParticleSet& p, std::span<const double> weight = {}) const override {
    double e = 0.0;
    for (auto [i, j] : list.pairs()) {
      const double overlap = p.radius[i] + p.radius[j] - norm(p.position[j] - p.position[i]);
      if (overlap > 0.0) e += self().energy_of(overlap) * (weight.empty() ? 1.0 : std::min(weight[i], weight[j]));
    }
    return e;
  }

 private:
  const Law& self() const { return static_cast<const Law&>(*this); }

  // Friction of the pair (i, j) touching along n with normal force magnitude f_n: added to both
  // DEs at the contact point, half the overlap inside each sphere (so the two arms add up to the
  // centre distance and the pair's angular momentum is kept); returns its dissipated power, W.
  double add_friction(std::uint32_t i, std::uint32_t j, const Vec3& n, double half_overlap, double f_n, double mu,
                      ParticleSet& p) const {
    const Vec3 arm_i = n * (p.radius[i] - half_overlap), arm_j = n * (half_overlap - p.radius[j]);  // centre -> contact
    const Vec3 v = (p.velocity[j] + cross(p.angular_velocity[j], arm_j)) - (p.velocity[i] + cross(p.angular_velocity[i], arm_i));
    const Vec3 v_t = v - n * dot(v, n);
    const double speed = norm(v_t);
    if (speed == 0.0) return 0.0;
    const Vec3 f_t = v_t * (-mu * f_n / std::max(speed, self().slip_velocity()));
    p.force[j] += f_t;
    p.force[i] -= f_t;
    p.torque[j] += cross(arm_j, f_t);
    p.torque[i] += cross(arm_i, -f_t);
    return -dot(f_t, v_t);
  }
};

}  // namespace arlequin::dem
