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
#pragma once
#include <cmath>

#include "dem/contacts/contact_law.hpp"

namespace arlequin::dem {

template <class Law>
class ContactKernelLaw : public ContactLaw {
 public:
  std::string_view law() const override { return Law::name; }

  void accumulate_forces(const NeighbourList& list, ParticleSet& p) const override {
    for (auto [i, j] : list.pairs()) {
      const Vec3 d = p.position[j] - p.position[i];
      const double reach = p.radius[i] + p.radius[j];
      const double dist2 = norm2(d);
      if (dist2 >= reach * reach) continue;  // a listed pair that does not touch
      const Vec3 f_j = self().force_on_j(d, std::sqrt(dist2), reach);
      p.force[i] -= f_j;
      p.force[j] += f_j;
    }
  }

  double energy(const NeighbourList& list, const ParticleSet& p) const override {
    double e = 0.0;
    for (auto [i, j] : list.pairs()) {
      const double overlap = p.radius[i] + p.radius[j] - norm(p.position[j] - p.position[i]);
      if (overlap > 0.0) e += self().energy_of(overlap);
    }
    return e;
  }

 private:
  const Law& self() const { return static_cast<const Law&>(*this); }
};

}  // namespace arlequin::dem
