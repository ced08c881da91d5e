// SPDX-License-Identifier: GPL-3.0-or-later
// Breakable-yarn spring bond (law name "spring"), seed Eq. 6.
//
//   F_j = -K (|d| - L0) n,  d = x_j - x_i,  n = d / |d|,  F_i = -F_j;  energy K (|d|-L0)^2 / 2.
// Parameters (case file dem.material.bond):
//   stiffness       K [N/m]. For a yarn of n_p DEs per n_s springs, seed Eq. 8 gives
//                   K_mu = (n_s / n_p) K_M from the yarn's macroscopic stiffness K_M.
//   axial_rigidity  EA [N], instead of stiffness: each spring gets K = EA / L0 from its own rest
//                   length, a bar of that rigidity (for n_s equal springs in a chain of length
//                   L_y, K = n_s EA / L_y: seed Eq. 8 with EA = E S / n_p).
//   max_elongation  [1], optional: the spring breaks when (|d| - L0) / L0 reaches it
//                   (elastic-brittle yarn); 0 = unbreakable.
// Central force: no torque, so the DEs' rotations are untouched. Stiffness bound: K per bond
// (docs/theory.md#step).
#pragma once
#include "dem/bonds/bond_kernel_set.hpp"

namespace arlequin::dem {

class SpringBondSet final : public BondKernelSet<SpringBondSet> {
 public:
  static constexpr std::string_view name = "spring";
  static constexpr bool torques = false;
  static constexpr FailureCriterion criterion = FailureCriterion::elongation;

  SpringBondSet(double stiffness, double max_elongation = 0.0) : nominal_stiffness_(stiffness), max_elongation_(max_elongation) {}
  // Springs of axial rigidity EA (N): K = EA / L0 per spring.
  static std::unique_ptr<SpringBondSet> with_axial_rigidity(double EA, double max_elongation = 0.0) {
    auto set = std::make_unique<SpringBondSet>(0.0, max_elongation);
    set->axial_rigidity_ = EA;
    return set;
  }
  static std::unique_ptr<BondSet> make(CaseNode& section);
  static std::span<const KeyDoc> keys();  // what make() reads

  // d = x_j - x_i and its length L: the force -K (L - L0) d / L and the elongation L / L0 - 1
  // both follow from one evaluation.
  struct Evaluation {
    Vec3 d;
    double length;
    Vec3 force_on_j;
  };
  void add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) override;
  Evaluation evaluate(std::size_t b, const ParticleSet& p) const {
    const Vec3 d = p.position[second_[b]] - p.position[first_[b]];
    const double length = norm(d);
    return {d, length, d * (-stiffness_[b] * (length - rest_length_[b]) / length)};
  }
  static Vec3 force_on_j(const Evaluation& e) { return e.force_on_j; }
  double energy_of(std::size_t b, const Evaluation& e) const {
    const double stretch = e.length - rest_length_[b];
    return 0.5 * stiffness_[b] * stretch * stretch;
  }
  double failure_measure(std::size_t b, const Evaluation& e) const { return e.length / rest_length_[b] - 1.0; }
  FailureMode mode_of(std::size_t, const Evaluation&) const { return FailureMode::tension; }
  double strength() const { return max_elongation_; }
  void reorder(std::span<const std::uint32_t> order);
  void scale(std::size_t b, double factor) { stiffness_[b] *= factor; }
  double stiffness_of(std::size_t b) const { return stiffness_[b]; }  // N/m
  void add_frequency_bound(std::size_t b, const ParticleSet& p, std::span<double> translational, std::span<double>) const;

 private:
  double nominal_stiffness_;         // K of the case file, N/m
  double axial_rigidity_ = 0.0;      // EA, N; > 0: K = EA / L0 instead of the nominal K
  double max_elongation_;            // 0 = unbreakable
  std::vector<double> stiffness_;    // K per bond (weighted), N/m
  std::vector<double> rest_length_;  // L0, m
};

extern template class BondKernelSet<SpringBondSet>;

}  // namespace arlequin::dem
