// SPDX-License-Identifier: GPL-3.0-or-later
// Cohesive Euler-Bernoulli beam bond (law name "beam").
//
// Reference: D. Andre, I. Iordanoff, J.-L. Charles, J. Neauport, "Discrete element method to
// simulate continuous material by using the cohesive beam model", CMAME 213-216 (2012) 113-125.
//
// Parameters (case file dem.material.bond):
//   E_mu   [Pa]  Young's modulus of the beam
//   nu_mu  [1]   Poisson's ratio of the beam, G_mu = E_mu / (2 (1 + nu_mu))
//   r_mu   [1]   beam radius over mean DE radius: r_b = r_mu (R_i + R_j) / 2
// Section: S = pi r_b^2, I = pi r_b^4 / 4, J = 2 I; reference length L0 = |x_j - x_i| at add().
//
// Kinematics, co-rotated frame: axis n = (x_j - x_i)/L. Each DE carries a body-fixed copy
// of the reference direction d0; theta_a (theta_b) is the rotation vector turning n onto DE
// i's (j's) copy: the end rotations relative to the chord. The twist phi is the angle about
// n between the two body-fixed copies of a reference vector p0 perpendicular to d0.
// Generalised forces (linear beam element in the chord frame, stiffness from L0):
//   N   = E S (L - L0) / L0                      axial, tension > 0
//   M_a = 2 E I / L0 (2 theta_a + theta_b)       moment to hold end i
//   M_b = 2 E I / L0 (theta_a + 2 theta_b)       moment to hold end j
//   M_t = G J phi / L0                           torsion
// The shear force follows from moment balance, V_j = n x (m_i + m_j) / L (magnitude
// 6 E I (theta_a + theta_b) / L^2), so angular momentum is conserved to round-off.
// Energy: E S (L - L0)^2 / (2 L0) + 2 E I / L0 (|ta|^2 + ta.tb + |tb|^2) + G J phi^2 / (2 L0).
//
// Failure (BBF, optional parameter sigma_f [Pa]): the bond breaks when its maximal normal
// stress, sigma = N / S + r_b |M| / I at the more loaded end, reaches sigma_f. From the
// kinematics with the nominal E (Arlequin weights do not change stresses):
//   N / S = E (L - L0) / L0,   r_b |M_a| / I = 2 E r_b |2 theta_a + theta_b| / L0.
// The dominant mode recorded is the largest of |N/S|, r_b|M|/I, V/S = 1.5 E r_b^2
// |theta_a + theta_b| / L0^2 and the torsion stress G r_b |phi| / L0.
#pragma once
#include <array>

#include "dem/bonds/bond_kernel_set.hpp"

namespace arlequin::dem {

class BeamBondSet final : public BondKernelSet<BeamBondSet> {
 public:
  static constexpr std::string_view name = "beam";
  static constexpr bool torques = true;
  static constexpr FailureCriterion criterion = FailureCriterion::bbf;

  struct Parameters {
    double young = 0.0;         // E_mu, Pa
    double poisson = 0.3;       // nu_mu
    double radius_ratio = 0.5;  // r_mu
    double strength = 0.0;      // sigma_f, Pa; 0 = unbreakable
  };
  explicit BeamBondSet(const Parameters& parameters) : parameters_(parameters) {}
  static std::unique_ptr<BondSet> make(CaseNode& section);
  static std::span<const KeyDoc> keys();  // what make() reads

  void add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) override;
  // Orders the bonds by (first, second) DE (no colours) and lists each DE's bond ends.
  void finalize(std::size_t n_particles) override;
  // The gather pass: every bond's actions are computed by the SIMD block kernel (below) and
  // stored, then every DE adds those of its bonds in bond order, on the threads split as the
  // kicks: no two threads write one DE without colours, one barrier per pass instead of one per
  // colour, and sums that do not depend on the thread count. It records what BondKernelSet's
  // per-bond pass records (the virial per DE, in bond order, as accumulate_virial).
  void accumulate_forces(ParticleSet& p, const ForceScan& scan) const override;
  bool gathers() const override { return true; }
  void evaluate_share(const ParticleSet& p, const ForceScan& scan, IndexRange des) const override;
  void add_share(ParticleSet& p, const ForceScan& scan, IndexRange des) const override;

  // The generalised forces of bond b in the current configuration (for tests, sensors and
  // failure criteria): forces and torques exerted by the bond on its two DEs.
  struct Actions {
    double length, axial_force, twist;
    Vec3 axis, theta_a, theta_b;
    Vec3 force_on_j, torque_on_i, torque_on_j;  // force on i is -force_on_j
    double axial_stress, bending_stress;        // BBF's N / S and r_b |M| / I at the more loaded end, Pa
  };
  Actions actions(std::size_t b, const ParticleSet& p) const;
  // Bonds are evaluated `block` at a time (one per SIMD lane), their actions kept as the
  // kernel computes them, one array per quantity and component (stored whole, not lane by
  // lane); out[l] is the Actions of the block's bond l.
  static constexpr std::size_t block = 8;
  struct ActionsBlock {
    using Lane = double[block];
    Lane length, axial_force, twist;
    Lane axis[3], theta_a[3], theta_b[3], force_on_j[3], torque_on_i[3], torque_on_j[3];
    Lane axial_stress, bending_stress;
    static Vec3 at(const Lane (&v)[3], std::size_t l) { return {v[0][l], v[1][l], v[2][l]}; }
    Actions operator[](std::size_t l) const {
      return {length[l],         axial_force[l],       twist[l],
              at(axis, l),       at(theta_a, l),       at(theta_b, l),
              at(force_on_j, l), at(torque_on_i, l),   at(torque_on_j, l),
              axial_stress[l],   bending_stress[l]};
    }
  };
  // The actions of bonds [first, first + count), count in [1, block], into lanes [0, count)
  // of out (the lanes past count hold the last bond's again); BBF's stresses only `with_stresses`
  // (NaN otherwise: the force pass of an unbreakable set does not pay for them).
  void actions(std::size_t first, std::size_t count, const ParticleSet& p, ActionsBlock& out, bool with_stresses) const;
  const Parameters& parameters() const { return parameters_; }

  // The law's kernel (BondKernelSet).
  using Evaluation = Actions;
  Evaluation evaluate(std::size_t b, const ParticleSet& p) const { return actions(b, p); }
  static Vec3 force_on_j(const Actions& a) { return a.force_on_j; }
  static Vec3 torque_on_i(const Actions& a) { return a.torque_on_i; }
  static Vec3 torque_on_j(const Actions& a) { return a.torque_on_j; }
  double energy_of(std::size_t b, const Actions& a) const;
  double failure_measure(std::size_t, const Actions& a) const { return a.axial_stress + a.bending_stress; }
  FailureMode mode_of(std::size_t b, const Actions& a) const;
  double strength() const { return parameters_.strength; }
  void reorder(std::span<const std::uint32_t> order);
  void scale(std::size_t b, double factor) {
    axial_[b] *= factor;
    bending_[b] *= factor;
    torsion_[b] *= factor;
  }
  void add_frequency_bound(std::size_t b, const ParticleSet& p, std::span<double> translational, std::span<double> rotational) const;

 private:
  Parameters parameters_;
  std::vector<double> rest_length_;   // L0, m
  std::vector<double> beam_radius_;   // r_b, m
  std::vector<double> axial_;         // E S / L0, N/m
  std::vector<double> bending_;       // 2 E I / L0, N m
  std::vector<double> torsion_;       // G J / L0, N m
  // d0 (reference axis) and p0 (perpendicular to d0), unit: one array per component, so that
  // a block of consecutive bonds loads each component as one vector, like the scalars above.
  std::array<std::vector<double>, 3> direction_;
  std::array<std::vector<double>, 3> normal_;
  // The gather pass: bonded_ lists the DEs with a bond of the set, in order; bonded_[k]'s bond
  // ends are end_bonds_[end_offsets_[k] .. end_offsets_[k + 1]), each 2 b + 0 where it is bond
  // b's first DE, 2 b + 1 where it is its second, in bond order.
  std::vector<std::uint32_t> bonded_, end_offsets_, end_bonds_;
  // Scratch of the gather pass, one array per component of the force on j, the torque on i and
  // the torque on j (9 arrays, one writer per bond), sized to whole blocks.
  mutable std::array<std::vector<double>, 9> bond_actions_;
};

extern template class BondKernelSet<BeamBondSet>;

}  // namespace arlequin::dem
