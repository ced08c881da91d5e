// Breakable-yarn spring bond (law name "spring"), seed paper Eq. 6.
//
//   F_j = -K (|d| - L0) n,  d = x_j - x_i,  n = d / |d|,  F_i = -F_j;  energy K (|d|-L0)^2 / 2.
// Parameters (case file dem.material.bond):
//   stiffness  K [N/m]. For a yarn discretised with n_p DEs per n_s springs, seed Eq. 8 gives
//              K_mu = (n_s / n_p) K_M from the yarn's macroscopic stiffness K_M.
// Central force: no torque, so rotations of the DEs are untouched.
#pragma once
#include "dem/bond_set.hpp"

namespace arlequin::dem {

class SpringBondSet final : public BondSet {
 public:
  explicit SpringBondSet(double stiffness) : nominal_stiffness_(stiffness) {}
  static std::unique_ptr<BondSet> make(CaseNode& section);

  std::string_view law() const override { return "spring"; }
  void add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) override;
  void finalize(std::size_t n_particles) override;
  void accumulate_forces(ParticleSet& p) const override;
  double energy(const ParticleSet& p) const override;
  void add_frequency_bounds(const ParticleSet& p, std::span<double> translational,
                            std::span<double> rotational) const override;
  void scale_stiffness(std::span<const double> factor) override;

 private:
  double nominal_stiffness_;         // K of the case file, N/m
  std::vector<double> stiffness_;    // K per bond (weighted), N/m
  std::vector<double> rest_length_;  // L0, m
};

}  // namespace arlequin::dem
