// Linear penalty contact (law name "penalty"), seed Eq. 9.
//
//   overlap delta = R_i + R_j - |x_j - x_i| > 0,  n = (x_j - x_i)/|x_j - x_i|
//   F_j = K delta n,  F_i = -F_j,  energy K delta^2 / 2
// Parameters (case file dem.contact): stiffness K [N/m].
// Frictionless and central: no torque. Elastic, so a head-on impact conserves energy.
#pragma once
#include "dem/contacts/contact_kernel.hpp"

namespace arlequin::dem {

class PenaltyContact final : public ContactKernelLaw<PenaltyContact> {
 public:
  static constexpr std::string_view name = "penalty";
  explicit PenaltyContact(double stiffness) : stiffness_(stiffness) {}
  static std::unique_ptr<ContactLaw> make(CaseNode& section);
  static std::span<const KeyDoc> keys();  // what make() reads

  Vec3 force_on_j(const Vec3& d, double distance, double reach) const { return d * (stiffness_ * (reach - distance) / distance); }
  double energy_of(double overlap) const { return 0.5 * stiffness_ * overlap * overlap; }
  double stiffness() const override { return stiffness_; }

 private:
  double stiffness_;  // K, N/m
};

}  // namespace arlequin::dem
