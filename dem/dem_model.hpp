// SPDX-License-Identifier: GPL-3.0-or-later
// The DEM model: particles, bond batches, optional contact, boundary conditions, and the
// explicit velocity-Verlet step with rotations (docs/theory.md#step).
//
// Contract: build with add_group / add_bond_set / set_contact / add_boundary / set_damping,
// then finalize() once (checks boundary conditions, colours bonds, builds the neighbour list
// only if there is a contact law), then step(). Throws std::invalid_argument from finalize()
// for contradictory setups (the application adds the case-file location), RunError from
// check_finite() / check_energy() when the run has gone non-finite or blown up.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/step_profile.hpp"
#include "dem/bonds/bond_set.hpp"
#include "dem/boundary.hpp"
#include "dem/contacts/contact_law.hpp"
#include "dem/failure.hpp"
#include "dem/neighbour_list.hpp"
#include "dem/particles.hpp"
#include "dem/rdef.hpp"

namespace arlequin::dem {

struct Energies {
  double kinetic = 0.0;        // translational + rotational, J
  double bond = 0.0;           // elastic energy in bonds, J
  double contact = 0.0;        // elastic energy in contacts, J
  double external_work = 0.0;  // work done on the model by boundary conditions and loads, J
  double dissipated = 0.0;     // by viscous damping and contact friction, J
  double fracture = 0.0;       // elastic energy of bonds when they broke, and what cohesive
                               // links dissipated softening, J
  double total() const { return kinetic + bond + contact; }
  // Zero for an exact run: what is stored plus what was lost, less the work put in.
  double balance(double initial_total) const { return total() + dissipated + fracture - external_work - initial_total; }
};

class DemModel {
 public:
  ParticleSet particles;

  // Groups: named sets of DEs, as many as a scene needs (a weave has one per yarn), each kept
  // as its members' indices in increasing order. add_group returns the index of the group of
  // that name, made empty if new; add_members merges DEs into it (repeats are kept once).
  int add_group(const std::string& name);
  int add_group(const std::string& name, std::vector<std::uint32_t> ids);
  void add_members(int group, std::span<const std::uint32_t> ids);
  int group_index(const std::string& name) const;  // -1 if unknown
  const std::vector<std::string>& group_names() const { return group_names_; }
  const std::vector<std::uint32_t>& members(int group) const { return group_members_[group]; }

  BondSet& add_bond_set(std::unique_ptr<BondSet> set);
  const std::vector<std::unique_ptr<BondSet>>& bond_sets() const { return bond_sets_; }
  int bond_set_index(const std::string& name) const;  // -1 if unknown
  void set_contact(std::unique_ptr<ContactLaw> law, double skin);
  bool has_contact() const { return contact_ != nullptr; }
  const NeighbourList* neighbours() const { return neighbours_ ? &*neighbours_ : nullptr; }
  // Pairs that touched in the last force pass (0 without contact).
  std::size_t touching_contacts() const { return deepest_contact_.touching; }
  void add_boundary(const BoundaryCondition& bc);
  // DEs whose motion a kinematic condition imposes (valid before finalize()).
  std::vector<std::uint32_t> driven_particles() const;
  // What kinematic conditions impose on DE i (after finalize()): bits 0-2 its x, y, z velocity,
  // bit 3 its rotation (locked).
  std::uint8_t imposed_motion(std::size_t i) const { return driven_[i]; }
  // Viscous damping, force -c m v and torque -c I omega, c in 1/s (quasi-static runs).
  void set_damping(double coefficient) { damping_ = coefficient; }
  // A uniform body force m g on every DE (m/s^2), on the components no kinematic condition
  // imposes; its work is the drop of the potential, sum of m g . (x - x_reference).
  void set_gravity(const Vec3& g) { gravity_ = g; }
  // Reaction forces of this group are recorded every step (for force sensors); before finalize().
  void watch_reaction(int group);

  // Arlequin weighting (docs/theory.md#weighted-models): every DE's mass (and so its inertia) is
  // multiplied by max(alpha(x_i), mass_floor), every bond's stiffness by alpha at its
  // midpoint, every contact's force and energy by the smaller alpha of its two DEs (alpha at
  // the DEs' present positions here, i.e. the reference: a constant per pair, so contacts stay
  // conservative). Call once, after the bonds are added and before finalize().
  void apply_arlequin_weight(const std::function<double(const Vec3&)>& alpha, double mass_floor);

  // RDEF (dem/rdef.hpp) on top of the bond laws' own criteria.
  using RdefSettings = dem::RdefSettings;
  void enable_rdef(const RdefSettings& settings) { rdef_.emplace(settings); }

  void finalize();
  // The forces and torques of the present state, as finalize() puts them before the first step
  // (bonds, contacts, reactions, loads, damping): what the next step's first kick reads, after
  // the state was set from outside between two steps (a zone moved, app/zone_move.hpp).
  void restart_forces();

  // Critical time step 2 / omega_max, omega_max^2 from the block-Gershgorin bound over
  // bonds and contacts, lowered by damping (docs/theory.md#critical-step). Contacts count as
  // many per DE as it has neighbours at setup (at least one), with the stiffness of the contact
  // law; with contact, no DE may move more than its radius in a step at its present speed.
  // check_finite stops a run whose DEs come to touch more DEs than that allows.
  double critical_time_step() const;

  // One velocity-Verlet step of size dt (s): the phases, in order. step() is
  // advance_to_forces() then finish_step(); a coupled step runs the two halves itself and
  // corrects velocities after finish_step().
  void step(double dt);
  void advance_to_forces(double dt);  // kick dt/2, drift dt, forces at t + dt
  void finish_step(double dt);        // kick dt/2 to the velocities at t + dt
  // Times the step's phases into `profile` from now on (nullptr: stops); after finalize().
  void set_profile(StepProfile* profile);
  double time() const { return time_; }
  long steps_done() const { return steps_; }
  double last_dt() const { return last_dt_; }  // s, the last step's size (0 before the first; checkpointed)

  // Every break so far, in order; broken bonds' energy is in Energies::fracture.
  const std::vector<BreakEvent>& breaks() const { return breaks_; }
  // Bonds whose failure criterion is held in abeyance (a coupling overlap, where the continuum
  // cannot break: coupling.on_damage_in_overlap: hold): held(set, bond) true keeps the bond intact
  // when its criterion is met; each such bond is listed once in held_failures(), as the break it
  // would have been. After finalize() (which orders the bonds), before the first step; a
  // checkpoint keeps the list (and load_state needs the same bonds held).
  void hold_failures(const std::function<bool(std::size_t set, std::size_t bond)>& held);
  const std::vector<BreakEvent>& held_failures() const { return held_failures_; }
  bool failure_enabled() const { return failure_on_; }
  // Virial stress of every DE over its intact bonds (failure.hpp, seed Eq. 1), Pa, with the
  // volume share Omega_i = sphere volume / compaction.
  std::vector<Sym3> virial_stress(double compaction) const;
  // Fraction of each DE's bonds that are broken (0 for a DE without bonds).
  std::vector<double> damage() const;

  // Output rows: the next step's force pass also records every bond's energy, so that
  // energies() and group_energy() after that step read it instead of evaluating every bond
  // again (without the request they evaluate the bonds themselves). They trust the record until
  // the next step starts, so DEs moved between a recorded step and these calls are not seen.
  void record_energies_in_next_step() { energy_record_requested_ = true; }
  Energies energies() const;
  double kinetic_energy() const;  // Energies::kinetic alone (no bond pass), J
  double kinetic_energy(std::span<const std::uint32_t> ids) const;  // of these DEs, J
  // Kinetic damping (dynamic relaxation, docs/references.md#barnes1999): the DEs `ids` stop,
  // velocity and spin zero, but for the components a kinematic condition imposes; the kinetic
  // energy they had goes to Energies::dissipated. Between two steps. Returns that energy, J.
  double arrest(std::span<const std::uint32_t> ids);
  // Pseudo-time steps of dynamic relaxation (CoupledModel::relax), which seeks a state's
  // equilibrium, not its motion: the time stands still, so imposed components do not move
  // (their velocity is held at 0), no bond fails, and the forces are those of the bonds,
  // contacts, loads and damping less `offset` (force and torque per DE: what each DE is to keep
  // unbalanced). relaxation_kick: v += h M^-1 (f - offset), w likewise; relaxation_drift: the
  // drift by dt and those forces. Running sums (work, dissipation) may change: the caller keeps
  // the state it started from (save_state) and takes only the positions from the relaxation.
  void relaxation_kick(double h, std::span<const Vec3> force_offset, std::span<const Vec3> torque_offset);
  void relaxation_drift(double dt);
  void stop_motion();  // every velocity and spin to 0 (kinetic damping at a peak)
  double external_work() const { return external_work_; }  // J, cheap (no energy sums)
  // Force that boundary and loads apply to the group, -(bond + contact forces on it), N.
  Vec3 reaction_on(int group) const { return reaction_[group]; }
  Vec3 mean_displacement(int group) const;  // m
  Vec3 mean_velocity(int group) const;      // m/s
  // Kinetic energy of the group's DEs plus half the energy of each of their bonds, J.
  double group_energy(int group) const;
  // Both throw RunError naming the step, the DE and the likely cause. check_finite (cheap,
  // meant for every step): any non-finite velocity; with contact, also a DE that moved more
  // than its radius in the last step (it can pass through another) or a contact deeper than
  // the pair's smaller radius (a penalty too soft for the impact). check_energy: kinetic
  // energy above energy_limit (J), a blow-up.
  void check_finite() const;
  void check_energy(double energy_limit) const;
  // The kinetic energy of every DE moving at eps X / time (eps: machine epsilon; X: the largest
  // coordinate of any DE, so eps X is a rounding error of position), J. With time the critical
  // step dt_c it is the scale of round-off motion (app/runner.cpp).
  double round_off_kinetic_energy(double time) const;

  // Checkpoint (docs/restart.md): everything the next step reads of what the earlier ones left,
  // under "dem/": the DEs' motion and last forces, each bond set's history, the neighbour list,
  // the break records, the running energy sums, time and step. load_state() on the model built
  // again from the same case and finalized continues bit for bit; StateMismatch when the
  // checkpoint's DEs (radius, mass, reference position) or bonds are not this model's.
  void save_state(StateArchive& archive) const;
  void load_state(const StateArchive& archive);

 private:
  template <class Value>
  Vec3 group_mean(int group, Value value) const;
  void kick(double half_dt);
  void impose_motion(double t, bool half_step, double dt);
  void drift(double dt);
  void update_neighbours();
  // Forces of the current configuration (cleared first unless `cleared`: the drift does it);
  // returns the friction's power, W.
  double compute_forces(const ForceScan& scan = {}, bool cleared = false);
  // check_finite's contact part, given what its pass over the DEs found.
  struct ContactResolution {
    double reach = 0.0;           // the largest distance a DE moved in the last step, over its radius
    std::size_t fastest = 0;      // that DE
    double omega2 = 0.0;          // the largest frequency bound (1/s^2) with the contacts touching now
    std::size_t crowded = 0;      // that DE
  };
  void check_contact_resolution(const ContactResolution& worst) const;
  // Whether a step whose fastest DE moved `reach` radii and whose largest frequency bound is
  // omega2 (1/s^2) fails check_contact_resolution.
  bool fails_contact_resolution(double reach, double omega2) const;
  // check_finite's slow path, for a step that fails it: the DEs in order, the error naming them.
  void diagnose() const;
  // Break records under `prefix` of a checkpoint (breaks, held failures); load_events checks each
  // against this scene (StateMismatch naming `what` the bond should be, unless consistent(e)).
  static void save_events(StateArchive& archive, const std::string& prefix, const std::vector<BreakEvent>& events);
  std::vector<BreakEvent> load_events(const StateArchive& archive, const std::string& prefix,
                                      const std::function<bool(const BreakEvent&)>& consistent, const char* what) const;
  // DE i's row of the frequency bound (1/s^2) from `contacts` contacts (critical_time_step).
  double contact_frequency_bound(std::size_t i, std::uint32_t contacts) const;
  // alpha_i / m_i: a weighted contact's stiffness over a DE's weighted mass is at most
  // K alpha_i / m_i (its pairs weigh min(alpha_i, alpha_j)), never above the unweighted K / m.
  double contact_inv_mass(std::size_t i) const;
  // The scan that records, in the step's force pass, what apply_failures() needs.
  ForceScan failure_scan();
  void record_reactions();
  void apply_failures(bool record_energy);  // record_energy: the forces' recomputation records too
  bool break_failed_bonds();                // apply_failures' breaks; false: none failed
  // Whether the loops over every DE (kicks, drift, damping, the finite check) run on threads.
  bool particle_loops_threaded() const { return runs_threaded(static_cast<long>(particles.size()) > parallel_threshold); }
  // Makes the bond sets' energy records those of the current configuration (a pass over the
  // bonds unless the last step's force pass recorded them).
  void use_energy_record() const;
  double particle_kinetic_energy(std::size_t i) const;  // DE i's, translation and rotation, J
  std::vector<std::pair<std::uint32_t, std::uint32_t>> intact_bonded_pairs() const;
  double driven_kinetic_energy() const;
  void apply_loads_and_damping();

  struct Constraint {
    std::uint32_t particle;
    std::uint32_t condition;  // index into boundaries_
    double mass;              // the DE's (weighted) mass, kg, for the driven kinetic energy
    std::uint8_t imposed;     // bits 0-2: the condition imposes x, y, z; bit 3: it locks rotation
  };
  void impose(const Constraint& c, const Vec3& v);  // c's imposed components of its DE's velocity = v
  std::vector<std::string> group_names_;
  std::vector<std::vector<std::uint32_t>> group_members_;  // per group, increasing DE indices
  std::vector<std::unique_ptr<BondSet>> bond_sets_;
  // The force passes of the bond sets (finalize()): consecutive gather sets share one
  // (accumulate_gathered_forces); pass_sets_[s] the number of sets in the pass that starts at
  // set s, 0 for a set in an earlier set's pass. set_pointers_: bond_sets_'s pointers, for spans.
  std::vector<std::size_t> pass_sets_;
  std::vector<const BondSet*> set_pointers_;
  std::unique_ptr<ContactLaw> contact_;
  std::optional<NeighbourList> neighbours_;
  ContactPass deepest_contact_;  // of the last force pass
  std::vector<std::uint32_t> touching_;        // per DE: its touching contacts in the last force pass
  std::vector<double> bond_frequency_bound_;   // per DE: its bonds' translational row of the bound, 1/s^2
  double inv_mass_max_ = 0.0;                  // 1/kg, the largest contact_inv_mass
  std::vector<double> contact_bound_each_;     // per DE: contact_frequency_bound(i, 1), 1/s^2 (check_finite)
  std::vector<double> contact_weight_;         // per DE: its Arlequin weight alpha (empty: none)
  std::vector<std::vector<std::uint8_t>> held_;  // per set and bond: 1 held, 2 held and its criterion met
  std::vector<BreakEvent> held_failures_;
  std::vector<BoundaryCondition> boundaries_;
  std::vector<Constraint> constraints_;  // kinematic, one per constrained DE
  // Indices into constraints_: those of moving conditions (the imposed velocity, the driven
  // kinetic energy and the reactions' work), and of still ones (only held at rest, impose_motion).
  std::vector<std::uint32_t> moving_constraints_, still_constraints_;
  std::vector<Vec3> constraint_reaction_;  // last reaction per constraint (for its work)
  std::vector<Vec3> condition_velocity_;   // scratch of impose_motion: per boundary condition, m/s
  // (DE, group) for every DE of a watched group, in DE order: record_reactions' sums.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> watched_members_;
  std::vector<Constraint> loaded_;       // force loads, one entry per (DE, load)
  std::vector<Vec3> load_per_particle_;  // N, per entry of loaded_
  std::optional<RdefCriterion> rdef_;
  bool failure_on_ = false;              // a law has a strength, or RDEF is on
  std::vector<BreakEvent> breaks_;
  std::vector<BreakEvent> new_breaks_;   // scratch, this step's candidates
  std::vector<double> kick_partial_;     // scratch: kick's chunk sums of the damping work
  struct FiniteScan {  // check_finite's pass over a thread's DEs
    bool bad = false;     // a non-finite velocity
    double reach2 = 0.0;  // the largest |v|^2 / R^2, 1/s^2
    double omega2 = 0.0;  // the largest frequency bound with the contacts touching now, 1/s^2
  };
  mutable std::vector<FiniteScan> finite_shares_;  // scratch: check_finite's, one per thread
  bool energy_record_requested_ = false;  // record_energies_in_next_step()
  long energy_record_step_ = -1;          // the step whose force pass recorded the bonds' energies
  mutable std::vector<double> bond_energy_share_;  // scratch of group_energy(), J per DE
  std::vector<int> watched_;      // the groups whose reactions are recorded, increasing
  std::vector<Vec3> reaction_;   // per group (zero for those not watched), N
  double damping_ = 0.0;
  Vec3 gravity_{};  // m/s^2
  std::vector<Vec3> damping_force_, damping_torque_;  // this step's, kept for both half kicks
  // The step's phases in profile_ (set_profile), one per force pass of the bond sets in bonds
  // (at its first set's index).
  StepProfile* profile_ = nullptr;
  struct ProfilePhases {
    int kick, drift, boundary, neighbours, contacts, failure, reactions, loads, finite;
    std::vector<int> bonds;
  } phase_{};
  std::vector<std::uint8_t> driven_;  // per DE: bits 0-2 imposed x, y, z; bit 3 rotation locked
  // Whether a kinematic condition imposes component k (0-2) of DE i's motion.
  bool imposes(std::size_t i, int k) const { return driven_[i] & (1u << k); }
  double time_ = 0.0;
  double last_dt_ = 0.0;  // s, step size of the step in progress (0 before the first)
  long steps_ = 0;
  double external_work_ = 0.0;
  double dissipated_ = 0.0;
  double fracture_ = 0.0;
};

}  // namespace arlequin::dem
