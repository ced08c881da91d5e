// SPDX-License-Identifier: GPL-3.0-or-later
// Linear penalty contact (law name "penalty"), seed Eq. 9.
//
//   overlap delta = R_i + R_j - |x_j - x_i| > 0,  n = (x_j - x_i)/|x_j - x_i|
//   F_j = K delta n,  F_i = -F_j,  energy K delta^2 / 2
// Parameters (case file dem.contact): stiffness K [N/m] (a weave's: its springs' K_mu, seed); friction mu [1] (0: frictionless,
// central, no torque; a head-on impact then conserves energy) and slip_velocity [m/s], the
// regularisation of the Coulomb friction (contact_kernel.hpp).
#pragma once
#include "dem/contacts/contact_kernel.hpp"

namespace arlequin::dem {

class PenaltyContact final : public ContactKernelLaw<PenaltyContact> {
 public:
  static constexpr std::string_view name = "penalty";
  explicit PenaltyContact(double stiffness, double friction = 0.0, double slip_velocity = 1e-3)
      : stiffness_(stiffness), friction_(friction), slip_velocity_(slip_velocity) {}
  static std::unique_ptr<ContactLaw> make(CaseNode& section, const ContactDefaults& defaults);
  static std::span<const KeyDoc> keys();  // what make() reads

  Vec3 force_on_j(const Vec3& d, double distance, double reach) const { return d * (stiffness_ * (reach - distance) / distance); }
  double energy_of(double overlap) const { return 0.5 * stiffness_ * overlap * overlap; }
  double stiffness() const override { return stiffness_; }
  double friction() const { return friction_; }
  double slip_velocity() const { return slip_velocity_; }

 private:
  double stiffness_;      // K, N/m
  double friction_;       // mu
  double slip_velocity_;  // m/s
};

}  // namespace arlequin::dem
