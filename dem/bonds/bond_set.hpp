// SPDX-License-Identifier: GPL-3.0-or-later
// A batch of bonds of one law and one material: the unit of work for bond forces.
//
// Contract: add() records a bond in the current configuration, which becomes its stress-free
// reference; both DEs must still have their reference (identity) orientation, because laws
// store reference directions once per bond instead of once per end. finalize() is called
// once after the last add() and before the first force evaluation. accumulate_forces() adds
// (never overwrites) forces and torques: one virtual call per batch, none per bond. With a
// ForceScan it also records, from the same per-bond kinematics, what the failure check of
// that configuration needs and each bond's energy, so a breakable step, or a step that ends on
// an output row, evaluates each bond once, not twice or three times.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/parallel.hpp"
#include "common/state_archive.hpp"
#include "common/schema.hpp"
#include "dem/failure.hpp"
#include "dem/particles.hpp"

namespace arlequin {
class CaseNode;
}

namespace arlequin::dem {

// Bonds are split into colours so that no two bonds of a colour share a DE: each colour is
// a parallel loop that scatters forces without atomics, and the summation order per DE is the
// same for any thread count (results do not depend on OMP_NUM_THREADS).
struct BondColouring {
  std::vector<std::uint32_t> offsets;  // colour k holds bonds [offsets[k], offsets[k+1])
  // The colours run on threads: more than parallel_threshold_bonds bonds per colour on
  // average, in a scene of more than parallel_threshold_bond_particles DEs (set by build).
  bool threaded = false;
  static bool worth_threads(std::size_t bonds, std::size_t colours, std::size_t n_particles) {
    return long(bonds) > long(colours) * parallel_threshold_bonds && long(n_particles) > parallel_threshold_bond_particles;
  }

  // Greedy edge colouring of (first, second) in a scene of n_particles DEs; returns the
  // permutation that sorts bonds by (colour, first), fills offsets and sets threaded. At most
  // 2 d - 1 colours, d the largest number of bonds at one DE.
  std::vector<std::uint32_t> build(std::span<const std::uint32_t> first,
                                   std::span<const std::uint32_t> second, std::size_t n_particles);
};

// Reorders v so that v_new[k] = v_old[order[k]].
template <class T>
void apply_order(std::vector<T>& v, std::span<const std::uint32_t> order) {
  std::vector<T> sorted(v.size());
  for (std::size_t k = 0; k < order.size(); ++k) sorted[k] = v[order[k]];
  v.swap(sorted);
}

// Runs body(first, last) over blocks of at most `block` consecutive bonds [first, last) of one
// colour, colour by colour, each colour's blocks split over threads if colouring.threaded. One
// team of threads serves all colours, with a barrier between colours, rather than a team
// started per colour.
template <class Body>
void for_each_bond_block(const BondColouring& colouring, long block, Body&& body) {
  const long colours = static_cast<long>(colouring.offsets.size()) - 1;
  run_threaded_if(colouring.threaded, [&] {
    for (long c = 0; c < colours; ++c) {
      const long begin = colouring.offsets[c], end = colouring.offsets[c + 1];
#pragma omp for schedule(static)
      for (long k = begin; k < end; k += block)
        body(static_cast<std::size_t>(k), static_cast<std::size_t>(std::min(end, k + block)));
    }
  });
}

// Runs body(b) for every bond, as for_each_bond_block.
template <class Body>
void for_each_bond(const BondColouring& colouring, Body&& body) {
  for_each_bond_block(colouring, 1, [&](std::size_t b, std::size_t) { body(b); });
}

// Adds the virial of a bond between DEs i and j, f_i the force on i, to both DEs. Per DE it is
// sym(b (x) f) with b the branch vector from the DE's centre to the boundary of its cell on
// the centre line, scaled by 2 to go with the 1 / (2 Omega) of seed Eq. 1: at the mid-point
// (half), b = r_ij / 2 for both; on the radical plane (radical, the face of the Laguerre
// cells), b_i = d_i r_ij / d with d_i = (d^2 + R_i^2 - R_j^2) / 2d, d_j = d - d_i, so that each
// DE's virial is that of its own cell, and both add up to sym(r_ij (x) f) as before.
// Out of line on purpose: the force pass's record and accumulate_virial() call this one compiled
// routine, so their virials agree to the bit whatever each caller's inlining would contract
// into fused multiply-adds.
void add_bond_virial(const ParticleSet& p, std::uint32_t i, std::uint32_t j, const Vec3& f_i, VirialBranch branch,
                     std::span<Sym3> virial);
// The same bond's term of one end's DE only (end 0: i, 1: j), added to `virial` (that DE's):
// add_bond_virial is this for both ends, so a pass that sums per DE gets the same bits.
void add_bond_end_virial(const ParticleSet& p, std::uint32_t i, std::uint32_t j, const Vec3& f_i, VirialBranch branch,
                         int end, Sym3& virial);

// What a force pass records besides forces, for the failure check of the same configuration
// (DemModel::apply_failures) and for the energies of an output row.
struct ForceScan {
  bool criterion = false;  // each bond's failure measure, read by find_failures()
  std::span<Sym3> virial;  // if not empty: every intact bond's virial added, as accumulate_virial()
  VirialBranch branch = VirialBranch::half;
  bool energy = false;  // each bond's elastic energy, read by recorded_energies()
};

class BondSet {
 public:
  virtual ~BondSet() = default;
  virtual std::string_view law() const = 0;
  virtual void add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) = 0;
  virtual void finalize(std::size_t n_particles) = 0;
  virtual void accumulate_forces(ParticleSet& p, const ForceScan& scan) const = 0;
  // A gather pass (BeamBondSet) is two halves with one barrier between them, each thread on the
  // DEs `des` it owns (thread_share): the actions of the bonds whose first DE is one of them,
  // computed and stored; then those DEs' sums of their bonds' actions. Consecutive gather sets
  // run as one pass (accumulate_gathered_forces). The other laws' passes are not split.
  virtual bool gathers() const { return false; }
  virtual void evaluate_share(const ParticleSet&, const ForceScan&, IndexRange) const { not_a_gather_pass(); }
  virtual void add_share(ParticleSet&, const ForceScan&, IndexRange) const { not_a_gather_pass(); }
  // Elastic energy stored in the batch in configuration p, J (leaves the record alone).
  virtual double energy(const ParticleSet& p) const = 0;
  // Each bond's elastic energy in configuration p into the record that a force pass with
  // ForceScan::energy also fills (for when no such pass has seen p).
  virtual void record_energies(const ParticleSet& p) const = 0;
  // Each bond's elastic energy (J) of the configuration of the last accumulate_forces() with
  // scan.energy or record_energies(); a broken bond's is 0. Their sum in a fixed order (the
  // same bits on any thread count), and half of each added to both its DEs' entries (where the
  // energy is, for energy sensors over a group).
  std::span<const double> recorded_energies() const { return energy_record_; }
  double recorded_energy() const;
  void add_recorded_energy_per_particle(std::span<double> energy) const;
  // Adds to every DE's row the block-Gershgorin bound of omega^2 (rad^2/s^2) coming from this
  // batch, for its translational and rotational rows of M^-1/2 K M^-1/2 (Feingold-Varga:
  // lambda_max <= max_i sum_j ||A_ij||_2).
  virtual void add_frequency_bounds(const ParticleSet& p, std::span<double> translational,
                                    std::span<double> rotational) const = 0;
  // Multiplies bond b's stiffness (all its modes) by factor[b] (Arlequin weighting): once at
  // set-up, so the force loop pays nothing for it.
  virtual void scale_stiffness(std::span<const double> factor) = 0;

  // Failure. has_strength(): the law was given a strength, so find_failures() can report
  // events (BBF for beams, maximum elongation for springs) for the configuration of the last
  // accumulate_forces() with scan.criterion (the measures it recorded). accumulate_virial()
  // adds every intact bond's sym(b (x) f) to both its DEs (RDEF, see failure.hpp;
  // add_bond_virial).
  virtual bool has_strength() const = 0;
  virtual void find_failures(const ParticleSet& p, std::uint32_t set_index, double time,
                             std::vector<BreakEvent>& events) const = 0;
  virtual void accumulate_virial(const ParticleSet& p, VirialBranch branch, std::span<Sym3> virial) const = 0;
  virtual double bond_energy(std::size_t b, const ParticleSet& p) const = 0;
  // Laws with a damage variable (cohesive links): each bond's damage in [0, 1] and the energy
  // its softening has dissipated so far, J (a failed bond's included). Empty for the others,
  // whose bonds are intact or broken (broken()).
  virtual std::span<const double> damage_values() const { return {}; }
  virtual std::span<const double> dissipated_values() const { return {}; }
  // A line about the set beyond its size, for the scene's facts (empty: nothing to add).
  virtual std::string describe() const { return {}; }
  // A broken bond keeps its place but its stiffness is zero: it carries no force from the
  // next force evaluation on, and the force loop needs no branch for it.
  void break_bond(std::size_t b) {
    broken_[b] = 1;
    zero_stiffness(b);
    energy_record_[b] = 0.0;
  }
  std::span<const std::uint8_t> broken() const { return broken_; }
  // Checkpoint: the pairs (to recognise the set), the broken flags, the energy record and the
  // law's own history (save_law_state) under `prefix`. load_state on the set built again from the
  // same case (finalized, weighted) breaks again the bonds that were broken; StateMismatch if the
  // pairs differ.
  void save_state(StateArchive& archive, const std::string& prefix) const;
  void load_state(const StateArchive& archive, const std::string& prefix);

  std::size_t size() const { return first_.size(); }
  std::span<const std::uint32_t> first() const { return first_; }
  std::span<const std::uint32_t> second() const { return second_; }
  // The force pass runs the colours on the OpenMP threads there are (BondColouring::threaded).
  bool runs_on_threads() const { return colouring_.threaded; }
  std::size_t colours() const { return colouring_.offsets.empty() ? 0 : colouring_.offsets.size() - 1; }
  std::string name;  // the bonds' group (e.g. fibre, matrix, interface), for records and output

 protected:
  void add_pair(std::uint32_t i, std::uint32_t j) {
    first_.push_back(i);
    second_.push_back(j);
    broken_.push_back(0);
    energy_record_.push_back(0.0);
  }
  // Colours the pairs and reorders first/second/broken/the energy record; returns the order
  // for the law's arrays.
  std::vector<std::uint32_t> order_pairs(std::size_t n_particles) {
    auto order = colouring_.build(first_, second_, n_particles);
    apply_pair_order(order);
    return order;
  }
  // For a law that gathers instead (BeamBondSet): no colours; the pairs sorted by (first,
  // second), so that a DE's bonds, and those of its neighbours in numbering, lie together.
  // colouring_.threaded by the same scene-size rule, with all bonds as one colour.
  std::vector<std::uint32_t> order_pairs_by_first(std::size_t n_particles);
  // record_energies(): energy_record_[b] = bond_energy(b) for every bond (finalized or not:
  // each bond writes only its own entry, so no colouring is needed; on threads when the force
  // pass is, by the same scene-size rule).
  template <class BondEnergy>
  void record_each(BondEnergy&& bond_energy) const {
    for_each_index(static_cast<long>(size()), colouring_.threaded,
                   [&](long b) { energy_record_[b] = bond_energy(static_cast<std::size_t>(b)); });
  }
  void apply_pair_order(std::span<const std::uint32_t> order) {
    apply_order(first_, order);
    apply_order(second_, order);
    apply_order(broken_, order);
    apply_order(energy_record_, order);
  }
  virtual void zero_stiffness(std::size_t b) = 0;
  [[noreturn]] static void not_a_gather_pass();
  // What the law's bonds remember beyond broken or intact (a cohesive link's damage): none by
  // default.
  virtual void save_law_state(StateArchive&, const std::string& /*prefix*/) const {}
  virtual void load_law_state(const StateArchive&, const std::string& /*prefix*/) {}

  std::vector<std::uint32_t> first_, second_;
  std::vector<std::uint8_t> broken_;
  BondColouring colouring_;
  // Scratch written by const passes (one writer per bond): the energy record, and the chunk
  // sums of fixed_order_sum.
  mutable std::vector<double> energy_record_;
  mutable std::vector<double> sum_partial_;
};

// The force passes of the gather sets `sets` (BondSet::gathers) as one, in one team of threads
// with one barrier: each thread evaluates every set's bonds at the DEs it owns, then adds every
// set's actions to those DEs, set after set in the order of `sets`, so that each DE's sums are
// those of the sets' passes one after the other (the same bits). A set whose bonds lie in a
// part of the scene (one material of several) has them all at the DEs of a few threads: a pass
// of its own would leave the other threads waiting at its barrier.
void accumulate_gathered_forces(std::span<const BondSet* const> sets, ParticleSet& p, const ForceScan& scan);
// Whether that pass runs on the threads: all its bonds as one colour (BondColouring::worth_threads).
bool gathered_pass_threaded(std::span<const BondSet* const> sets, std::size_t n_particles);

// Registry of bond laws, keyed by the case-file name (dem.material.bond.law).
// A law's own keys are declared by keys() beside its make() (schema section "bond (law: name)").
struct BondLawEntry {
  std::string_view name;
  std::string_view summary;
  std::unique_ptr<BondSet> (*make)(CaseNode& parameters);
  std::span<const KeyDoc> (*keys)();
};
std::span<const BondLawEntry> bond_laws();
std::unique_ptr<BondSet> make_bond_set(CaseNode& bond_section);

}  // namespace arlequin::dem
