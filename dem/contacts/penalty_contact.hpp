// Linear penalty contact (law name "penalty"), seed paper Eq. 9.
//
//   overlap delta = R_i + R_j - |x_j - x_i| > 0,  n = (x_j - x_i)/|x_j - x_i|
//   F_j = K delta n,  F_i = -F_j,  energy K delta^2 / 2
// Parameters (case file dem.contact):
//   stiffness  K [N/m]
// Frictionless and central: no torque. Elastic, so a head-on impact conserves energy.
#pragma once
#include "dem/contacts/contact_law.hpp"

namespace arlequin::dem {

class PenaltyContact final : public ContactLaw {
 public:
  explicit PenaltyContact(double stiffness) : stiffness_(stiffness) {}
  static std::unique_ptr<ContactLaw> make(CaseNode& section);
  static std::span<const KeyDoc> keys();  // what make() reads

  std::string_view law() const override { return "penalty"; }
  void accumulate_forces(const NeighbourList& list, ParticleSet& p) const override;
  double energy(const NeighbourList& list, const ParticleSet& p) const override;
  double stiffness() const override { return stiffness_; }

 private:
  double stiffness_;  // K, N/m
};

}  // namespace arlequin::dem
