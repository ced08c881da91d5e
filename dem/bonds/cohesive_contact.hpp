// SPDX-License-Identifier: GPL-3.0-or-later
// Bilinear cohesive contact (law name "cohesive_bilinear"): the seed's contact softening model
// (its Eq. 2) between DEs across an interface, with mixed mode after Camanho and Davila.
// Equations, derivations and references: docs/theory.md#cohesive-contact.
//
// A link joins two DEs that were neighbours across the interface when the scene was built; it
// is a pair with history (its damage), so it lives in a fixed pair list like the bonds, and
// when it has failed it leaves the list and the pair is left to the contact law, as a broken
// bond's pair is (docs/decisions.md#d25).
//
// Kinematics: each DE carries a body-fixed copy of the offset from its centre to the contact
// point, r_i = R_i d0 / (R_i + R_j) and r_j = -R_j d0 / (R_i + R_j) at creation (d0 = x_j - x_i),
// so the opening u = (x_j + Q_j r_j) - (x_i + Q_i r_i) is zero at creation and unchanged by a
// rigid motion of the pair. With n = (x_j - x_i)/|x_j - x_i|: u_n = u.n, u_s = u - u_n n.
// Section S = pi R^2, R = (R_i + R_j)/2 (seed Eq. 2), times an optional factor that makes the
// links' sections add up to the interface's nominal area; link stiffness K = k S.
// Per unit area, with <x> = max(x, 0), lambda = sqrt(<u_n>^2 + |u_s|^2), beta = |u_s| / u_n:
//   onset      delta_n0 = sigma_n / k, delta_s0 = sigma_s / k; quadratic initiation
//              (<t_n>/sigma_n)^2 + (t_s/sigma_s)^2 = 1 gives lambda_0(beta);
//   failure    delta_nf = 2 G_I / sigma_n, delta_sf = 2 G_II / sigma_s (seed Eq. 2); the
//              Benzeggagh-Kenane energy G_c = G_I + (G_II - G_I) B^eta, B = |u_s|^2 / lambda^2,
//              gives lambda_f = 2 G_c / (k lambda_0);
//   damage     d = max over history of lambda_f (lambda - lambda_0) / (lambda (lambda_f - lambda_0)),
//              clipped to [0, 1]: linear softening, unloading to the origin;
//   force on j F_j = -K [(1 - d) u_s + (1 - d) <u_n> n - <-u_n> n]  (compression undamaged);
//   torques    on i Q_i r_i x (-F_j), on j Q_j r_j x F_j.
// Energy: elastic K [(1 - d) lambda^2 + <-u_n>^2] / 2; dissipated, per link, G_c S times the
// fraction (lambda(d) - lambda_0) / (lambda_f - lambda_0) reached, accumulated as d grows: G_c S
// exactly when the link fails along a fixed mode mix.
// Parameters (case file dem....bond with law: cohesive_bilinear): sigma_max, sigma_max_shear
// [Pa], G_I, G_II [J/m^2], stiffness k [Pa/m], bk_exponent eta, precrack (a region holding the
// contact points of the links that start failed), area [m^2].
#pragma once
#include <optional>

#include "common/region.hpp"
#include "dem/bonds/bond_kernel_set.hpp"

namespace arlequin::dem {

class CohesiveContactSet final : public BondKernelSet<CohesiveContactSet> {
 public:
  static constexpr std::string_view name = "cohesive_bilinear";
  static constexpr bool torques = true;
  static constexpr FailureCriterion criterion = FailureCriterion::cohesive;

  struct Parameters {
    double strength_normal = 0.0;   // sigma_max^n, Pa
    double strength_shear = 0.0;    // sigma_max^s, Pa
    double toughness_I = 0.0;       // G_I, J/m^2
    double toughness_II = 0.0;      // G_II, J/m^2
    double stiffness = 0.0;         // k, traction per opening, Pa/m
    double bk_exponent = 2.0;       // eta of Benzeggagh-Kenane
    std::optional<Region> precrack;  // links whose contact point lies here at creation start failed
    double area = 0.0;              // m^2; > 0: the sections are scaled to add up to it
  };
  // Throws std::invalid_argument naming the parameter when the law is not well posed (a
  // strength, toughness or stiffness not positive; u_p not beyond the elastic opening).
  explicit CohesiveContactSet(const Parameters& parameters);
  static std::unique_ptr<BondSet> make(CaseNode& section);
  static std::span<const KeyDoc> keys();  // what make() reads

  struct Evaluation {
    Vec3 force_on_j, torque_on_i, torque_on_j;
    double damage;       // d after this configuration (history included)
    double mode_mix;     // B = |u_s|^2 / lambda^2, the shear share (0 in pure opening)
    double elastic;      // J
    double dissipation;  // J: dissipated by the growth of d from the stored value to this one
  };
  void add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) override;
  // Scales the sections to the nominal area (if given), then colours as every bond set.
  void finalize(std::size_t n_particles) override;
  Evaluation evaluate(std::size_t b, const ParticleSet& p) const;
  // Links first .. first + count - 1 (1 <= count <= 8) at once, one a lane (dem/lanes.hpp), into
  // out[0 .. count). Every evaluation, alone (evaluate) or in the force pass's blocks, goes
  // through this one kernel, so a link's result does not depend on the links it shares a block
  // with.
  void evaluate_block(std::size_t first, std::size_t count, const ParticleSet& p, Evaluation* out) const;
  // The force pass in blocks of eight links of a colour (BondKernelSet's records and history).
  void accumulate_forces(ParticleSet& p, const ForceScan& scan) const override;
  // The force pass keeps the damage (irreversible) and the dissipated energy.
  void commit(std::size_t b, const Evaluation& e) const {
    damage_[b] = e.damage;
    dissipated_[b] += e.dissipation;
  }
  static Vec3 force_on_j(const Evaluation& e) { return e.force_on_j; }
  static Vec3 torque_on_i(const Evaluation& e) { return e.torque_on_i; }
  static Vec3 torque_on_j(const Evaluation& e) { return e.torque_on_j; }
  double energy_of(std::size_t, const Evaluation& e) const { return e.elastic; }
  // A failed link's event carries what it dissipated, and the elastic energy it still held.
  double event_energy(std::size_t b, const Evaluation& e) const { return dissipated_[b] + e.dissipation + e.elastic; }
  double event_mode_mix(std::size_t, const Evaluation& e) const { return e.mode_mix; }
  double failure_measure(std::size_t, const Evaluation& e) const { return e.damage; }
  FailureMode mode_of(std::size_t, const Evaluation& e) const { return e.mode_mix > 0.5 ? FailureMode::shear : FailureMode::tension; }
  double strength() const { return 1.0; }  // a link fails when d reaches 1
  void reorder(std::span<const std::uint32_t> order);
  // Weights (and failure, with 0) scale the section, so forces, strengths and toughness alike.
  void scale(std::size_t b, double factor) {
    section_[b] *= factor;
    stiffness_[b] *= factor;
  }
  void add_frequency_bound(std::size_t b, const ParticleSet& p, std::span<double> translational,
                           std::span<double> rotational) const;

  std::span<const double> damage_values() const override { return damage_; }
  std::span<const double> dissipated_values() const override { return dissipated_; }
  std::string describe() const override;

  const Parameters& parameters() const { return parameters_; }
  double section(std::size_t b) const { return section_[b]; }  // S of link b, m^2
  // The area of the interface the links cover, m^2, from their contact points as built (DEs in
  // their reference places): the convex hull of the points in the plane normal to the links'
  // mean direction, widened by half the links' spacing delta = sqrt(hull / links) / 2 all round
  // (A + P delta + pi delta^2). What `area` should be, to a few per cent on a plane interface
  // (the outermost contact points lie about a radius inside its edges); 0 when the points do
  // not lie in one plane (spread along the normal over a tenth of the hull's size) or are
  // fewer than three.
  double covered_area(const ParticleSet& p) const;

 private:
  void save_law_state(StateArchive& archive, const std::string& prefix) const override;
  void load_law_state(const StateArchive& archive, const std::string& prefix) override;

  Parameters parameters_;
  double section_scale_ = 1.0;         // nominal area / sum of pi R^2 (1 without an area)
  std::vector<double> section_;        // S, m^2
  std::vector<double> stiffness_;      // K = k S (weighted; 0 once failed), N/m
  std::vector<Vec3> offset_i_, offset_j_;  // contact point from each centre, body frames, m
  mutable std::vector<double> damage_;      // d, advanced only by the force pass (commit)
  mutable std::vector<double> dissipated_;  // J per link, likewise
};

extern template class BondKernelSet<CohesiveContactSet>;

}  // namespace arlequin::dem
