// Breakable-yarn spring bond (law name "spring"), seed paper Eq. 6.
//
//   F_j = -K (|d| - L0) n,  d = x_j - x_i,  n = d / |d|,  F_i = -F_j;  energy K (|d|-L0)^2 / 2.
// Parameters (case file dem.material.bond):
//   stiffness  K [N/m]. For a yarn discretised with n_p DEs per n_s springs, seed Eq. 8 gives
//              K_mu = (n_s / n_p) K_M from the yarn's macroscopic stiffness K_M.
// Central force: no torque, so rotations of the DEs are untouched.
// Failure (optional parameter max_elongation [1]): the spring breaks when (|d| - L0) / L0
// reaches it (elastic-brittle yarn).
#pragma once
#include "dem/bond_set.hpp"

namespace arlequin::dem {

class SpringBondSet final : public BondSet {
 public:
  SpringBondSet(double stiffness, double max_elongation = 0.0)
      : nominal_stiffness_(stiffness), max_elongation_(max_elongation) {}
  static std::unique_ptr<BondSet> make(CaseNode& section);

  std::string_view law() const override { return "spring"; }
  void add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) override;
  void finalize(std::size_t n_particles) override;
  void accumulate_forces(ParticleSet& p, const ForceScan& scan) const override;
  double energy(const ParticleSet& p) const override;
  void record_energies(const ParticleSet& p) const override;
  void add_frequency_bounds(const ParticleSet& p, std::span<double> translational,
                            std::span<double> rotational) const override;
  void scale_stiffness(std::span<const double> factor) override;
  bool has_strength() const override { return max_elongation_ > 0.0; }
  void find_failures(const ParticleSet& p, std::uint32_t set_index, double time,
                     std::vector<BreakEvent>& events) const override;
  void accumulate_virial(const ParticleSet& p, VirialBranch branch, std::span<Sym3> virial) const override;
  double bond_energy(std::size_t b, const ParticleSet& p) const override;

 private:
  void zero_stiffness(std::size_t b) override { stiffness_[b] = 0.0; }
  // d = x_j - x_i and its length L: the force -K (L - L0) d / L and the elongation L / L0 - 1
  // both follow from one evaluation.
  struct Stretch {
    Vec3 d;
    double length;
  };
  Stretch stretch(std::size_t b, const ParticleSet& p) const;
  Vec3 force_on_j(std::size_t b, const Stretch& s) const;
  Vec3 force_on_j(std::size_t b, const ParticleSet& p) const;
  double energy_of(std::size_t b, const Stretch& s) const;

  double nominal_stiffness_;         // K of the case file, N/m
  double max_elongation_;            // 0 = unbreakable
  std::vector<double> stiffness_;    // K per bond (weighted), N/m
  std::vector<double> rest_length_;  // L0, m
  // Elongation per bond from the last force pass with ForceScan::criterion (scratch sized
  // by finalize; one writer per bond).
  mutable std::vector<double> elongation_;
};

}  // namespace arlequin::dem
