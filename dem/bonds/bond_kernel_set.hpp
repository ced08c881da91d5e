// SPDX-License-Identifier: GPL-3.0-or-later
// The bookkeeping every bond law shares, written once: a law is a kernel that evaluates one
// bond, and BondKernelSet<Law> turns it into a BondSet (force pass with its failure, energy and
// virial records, energies, virial, failure events, stiffness scaling and bounds, colouring).
//
// A law derives from BondKernelSet<Law> (CRTP: the per-bond calls are inlined, no virtual call
// per bond) and supplies:
//   static constexpr std::string_view name;            its case-file name (dem.material.bond.law)
//   static constexpr bool torques;                      whether it applies torques
//   static constexpr FailureCriterion criterion;        what its failure measure is
//   struct Evaluation;                                  what one evaluation of a bond yields
//   void add(i, j, p);                                  add_pair(i, j) and the law's own arrays
//   Evaluation evaluate(b, p) const;                    bond b in configuration p
//   static Vec3 force_on_j(const Evaluation&);          force of the bond on its second DE, N
//   static Vec3 torque_on_i / torque_on_j(const Evaluation&)   (only with torques), N m
//   double energy_of(b, const Evaluation&) const;       elastic energy, J
//   double failure_measure(b, const Evaluation&) const; compared with strength(), the law's unit
//   FailureMode mode_of(b, const Evaluation&) const;    the mode recorded when it breaks
//   double strength() const;                            0: unbreakable
//   void reorder(order);                                apply_order to each per-bond array
//   void scale(b, factor);                              every stiffness of bond b times factor
//   void add_frequency_bound(b, p, translational, rotational) const;   see BondSet
// A law with history (a damage variable) may also supply
//   void commit(b, const Evaluation&) const;            keep what the force pass evaluated
//   double event_energy(b, const Evaluation&) const;    a failure's dissipated energy (else energy_of)
//   double event_mode_mix(b, const Evaluation&) const;  a failure's mode mix (else none)
// commit is called by the force pass only, after each evaluation, so evaluate() stays a pure
// function of the configuration and the stored history.
// A law with a faster pass of its own (the beam's SIMD blocks and gather) overrides
// accumulate_forces and records what record_scan records (the virial through add_bond_end_virial,
// in bond order per DE, so that it has accumulate_virial's bits).
#pragma once
#include <atomic>
#include <stdexcept>
#include <string>

#include "dem/bonds/bond_set.hpp"

namespace arlequin::dem {

template <class Law>
class BondKernelSet : public BondSet {
 public:
  std::string_view law() const override { return Law::name; }
  bool has_strength() const override { return self().strength() > 0.0; }
  // The overrides are defined below the class, not in it: a law's explicit instantiation (in
  // its .cpp, with that file's compile options) is then the only copy the program links,
  // where an inline copy from another file could be picked instead.
  void finalize(std::size_t n_particles) override;
  void scale_stiffness(std::span<const double> factor) override;
  void accumulate_forces(ParticleSet& p, const ForceScan& scan) const override;
  double bond_energy(std::size_t b, const ParticleSet& p) const override;
  double energy(const ParticleSet& p) const override;
  void record_energies(const ParticleSet& p) const override;
  void accumulate_virial(const ParticleSet& p, VirialBranch branch, std::span<Sym3> virial) const override;
  // Events for the intact bonds whose measure, recorded by the last force pass with
  // scan.criterion, reaches the strength. A failing bond (rare) is evaluated again for its
  // mode and energy.
  void find_failures(const ParticleSet& p, std::uint32_t set_index, double time,
                     std::vector<BreakEvent>& events) const override;
  void add_frequency_bounds(const ParticleSet& p, std::span<double> translational,
                            std::span<double> rotational) const override;

 protected:
  // What a scanning pass records besides the forces.
  struct Records {
    bool criterion, virial, energy;
    bool any() const { return criterion || virial || energy; }
  };
  Records records(const ForceScan& scan) const { return {scan.criterion && has_strength(), !scan.virial.empty(), scan.energy}; }

  // Adds bond b's force (and torques) to its two DEs.
  // (Evaluation is Law::Evaluation, a template parameter since Law is incomplete here.)
  template <class Evaluation>
  static void apply_actions(std::uint32_t i, std::uint32_t j, const Evaluation& e, ParticleSet& p) {
    const Vec3 f_j = Law::force_on_j(e);
    p.force[i] -= f_j;
    p.force[j] += f_j;
    if constexpr (Law::torques) {
      p.torque[i] += Law::torque_on_i(e);
      p.torque[j] += Law::torque_on_j(e);
    }
  }
  template <class Evaluation>
  void apply(std::size_t b, const Evaluation& e, ParticleSet& p) const {
    apply_actions(first_[b], second_[b], e, p);
  }

  // Bond b's records from its evaluation. A colour holds no two bonds of a DE, so the virial
  // scatters without races, in accumulate_virial's order; the bond pulls i with -force_on_j.
  template <class Evaluation>
  void record_scan(std::size_t b, const Evaluation& e, ParticleSet& p, const ForceScan& scan, const Records& r) const {
    if (r.criterion) note_measure(b, self().failure_measure(b, e));
    if (r.energy) energy_record_[b] = self().energy_of(b, e);
    if (r.virial && !broken_[b]) add_bond_virial(p, first_[b], second_[b], -Law::force_on_j(e), scan.branch, scan.virial);
  }

  void zero_stiffness(std::size_t b) override;

  // Records bond b's failure measure; an intact bond at its strength raises failing_, so that
  // find_failures scans the bonds only after a pass where one may fail.
  void note_measure(std::size_t b, double measure) const {
    measure_[b] = measure;
    if (measure >= self().strength() && !broken_[b]) failing_.store(true, std::memory_order_relaxed);
  }
  // Each bond's failure measure from the last force pass with ForceScan::criterion (scratch
  // sized by finalize; one writer per bond).
  mutable std::vector<double> measure_;
  mutable std::atomic<bool> failing_{false};

 private:
  const Law& self() const { return static_cast<const Law&>(*this); }
  static constexpr bool has_history =
      requires(const Law& law, std::size_t b, const typename Law::Evaluation& e) { law.commit(b, e); };
  Law& mutable_self() { return static_cast<Law&>(*this); }
};

template <class Law>
void BondKernelSet<Law>::finalize(std::size_t n_particles) {
  const auto order = order_pairs(n_particles);
  mutable_self().reorder(order);
  measure_.assign(size(), 0.0);
}

template <class Law>
void BondKernelSet<Law>::scale_stiffness(std::span<const double> factor) {
  for (std::size_t b = 0; b < size(); ++b) mutable_self().scale(b, factor[b]);
}

template <class Law>
void BondKernelSet<Law>::zero_stiffness(std::size_t b) {
  mutable_self().scale(b, 0.0);
}

template <class Law>
void BondKernelSet<Law>::accumulate_forces(ParticleSet& p, const ForceScan& scan) const {
  const Records r = records(scan);
  if (!r.any()) {  // the plain pass: no test per bond
    for_each_bond(colouring_, [&](std::size_t b) {
      const auto e = self().evaluate(b, p);
      apply(b, e, p);
      if constexpr (has_history) self().commit(b, e);
    });
    return;
  }
  for_each_bond(colouring_, [&](std::size_t b) {
    const auto e = self().evaluate(b, p);
    apply(b, e, p);
    if constexpr (has_history) self().commit(b, e);
    record_scan(b, e, p, scan, r);
  });
}

template <class Law>
double BondKernelSet<Law>::bond_energy(std::size_t b, const ParticleSet& p) const {
  return self().energy_of(b, self().evaluate(b, p));
}

template <class Law>
double BondKernelSet<Law>::energy(const ParticleSet& p) const {
  return fixed_order_sum(static_cast<long>(size()), parallel_threshold, sum_partial_,
                         [&](long b) { return bond_energy(static_cast<std::size_t>(b), p); });
}

template <class Law>
void BondKernelSet<Law>::record_energies(const ParticleSet& p) const {
  record_each([&](std::size_t b) { return bond_energy(b, p); });
}

template <class Law>
void BondKernelSet<Law>::accumulate_virial(const ParticleSet& p, VirialBranch branch, std::span<Sym3> virial) const {
  for (std::size_t b = 0; b < size(); ++b)
    if (!broken_[b]) add_bond_virial(p, first_[b], second_[b], -Law::force_on_j(self().evaluate(b, p)), branch, virial);
}

template <class Law>
void BondKernelSet<Law>::find_failures(const ParticleSet& p, std::uint32_t set_index, double time,
                                       std::vector<BreakEvent>& events) const {
  if (!has_strength()) return;
  if (measure_.size() != size()) throw std::logic_error(std::string(Law::name) + " bonds: added after finalize()");
  if (!failing_.exchange(false, std::memory_order_relaxed)) return;
  const double strength = self().strength();
  for (std::size_t b = 0; b < size(); ++b) {
    if (broken_[b] || measure_[b] < strength) continue;
    const auto e = self().evaluate(b, p);
    BreakEvent event{time, set_index, static_cast<std::uint32_t>(b), Law::criterion, self().mode_of(b, e), measure_[b],
                     self().energy_of(b, e)};
    if constexpr (requires { self().event_energy(b, e); }) event.energy = self().event_energy(b, e);
    if constexpr (requires { self().event_mode_mix(b, e); }) event.mode_mix = self().event_mode_mix(b, e);
    events.push_back(event);
  }
}

template <class Law>
void BondKernelSet<Law>::add_frequency_bounds(const ParticleSet& p, std::span<double> translational,
                                              std::span<double> rotational) const {
  for (std::size_t b = 0; b < size(); ++b) self().add_frequency_bound(b, p, translational, rotational);
}

}  // namespace arlequin::dem
