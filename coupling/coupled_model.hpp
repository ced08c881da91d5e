// SPDX-License-Identifier: GPL-3.0-or-later
// CoupledModel: a DEM model and a continuum coupled by the Arlequin method with velocity
// multipliers, advanced by one explicit velocity-Verlet step (docs/theory.md#coupled-step).
//
// Contract
//  - Construction takes a DemModel that is built (DEs, bonds, boundary conditions) but NOT
//    finalized, and a ContinuumSolver whose weight is untouched; both are borrowed and must
//    outlive the CoupledModel. It weights them (DEM: masses by max(alpha_d, eps), bonds by
//    alpha_d at the midpoint; continuum: mass and stiffness integrands by alpha_c), finalizes
//    the DEM, builds G_d, G_c, factors A once, and puts the initial state on the constraint:
//    velocities are projected onto G v = 0. Initial displacements must satisfy G u = 0 (e.g.
//    both at rest, or both on one affine field); displacement_residual() reports it.
//  - Weights are evaluated in the reference configuration. If some continuum node has no weighted
//    mass (alpha_c = 0 at all its mass points, e.g. natural-neighbour nodes on the DEM-side edge
//    of the overlap), the continuum's mass weight becomes max(alpha_c, eps), as the DEs' is; its
//    stiffness keeps alpha_c (no stiffness where the DEM alone carries the load); summary() says
//    so. DEs beyond the overlap on the continuum side must not exist.
//  - Consistent overlap quadrature (options.consistent_quadrature; "coupling.quadrature:
//    consistent"). Under a uniform stress sigma carried by both models, the gradient of the
//    weighted bond energy at DE p is r_d = -sigma h_p, h_p = sum over its Laguerre faces f of
//    alpha_d(centroid_f) times the face's area vector A_f; this holds for a lattice whose bonds
//    cross the faces at their centroids and carry sigma A_f (the simple-cubic lattice under
//    normal stresses, the patch test's case; a random packing has no uniform static state to
//    begin with). That of the weighted continuum energy at node a is r_c = sigma g_a, g_a =
//    sum_q w_q grad_q N_a. Static equilibrium with either mediator needs r_c = -N^T r_d, i.e.
//    g_a = sum_p N(p, a) h_p at every node with a free dof (a sufficient condition where the
//    overlap holds driven DEs: their h_p is counted as for free ones). P1 with constant or
//    linear weights meets it on a mesh matched to the lattice (and with the fine mediator on
//    coarser ones); cubic weights and natural neighbours (whose shape functions reach past the
//    next node plane) do not, which is a ghost force of O(eps E A) at the overlap. With the
//    option, the continuum's overlap point weights are corrected to meet it
//    (ContinuumSolver::correct_weights: the least change in relative entropy, so they stay
//    positive and K positive semi-definite; the mass is not touched). The correction depends
//    neither on sigma nor on time and keeps K symmetric, so the energy and the critical step
//    keep their meaning (the step is estimated after it). In the spirit of variationally
//    consistent integration (Chen, Hillman & Rueter, IJNME 95 (2013)), which corrects a
//    meshfree quadrature to pass the patch test; here the weights, not the test gradients, are
//    corrected, and the reference is the DE cloud's divergence. The targets must be reachable:
//    every free node the overlap reaches must lie inside the coupled body (a free surface
//    through the overlap has each model's own surface flux, and they differ; InputError).
//  - Dofs with essential conditions that lie in the coupling support must be declared
//    (held_continuum_dofs, driven_des): they get no correction (zero inverse mass in A).
//  - step(dt), with the constraint acting on accelerations, split over the two half kicks
//    (RATTLE-like: Andersen, J. Comput. Phys. 52 (1983); for a linear constraint it is velocity
//    Verlet on the constrained subspace, so G u = 0 and G v = 0 are kept to round-off and the
//    multiplier forces do no work):
//      1. constraint_half_kick: v -= dt/2 M^-1 G^T mu(n)          (both models)
//      2. advance_models: DEM kick dt/2, drift, forces (weighted); continuum likewise
//      3. kick_to_trial: both kick dt/2 -> trial velocities v*
//      4. solve_multipliers: A lambda = G_d v_d* + G_c v_c*
//      5. correct_velocities: v = v* - M^-1 G^T lambda; mu(n+1) = 2 lambda / dt, and the work
//         of the multiplier forces over the drift, G^T (mu(n) + mu(n+1)) dt/2 . v(n+1/2) (the
//         drift velocities of step 2; MultiplierSolver::project gives G^T lambda)
//    Steps 3-5 are the constrained velocity-Verlet correction; step 1 is the same constraint force applied
//    in the first half kick, which keeps v(n+1/2) (the drift velocity) on the constraint.
//  - options.continuum_substeps = m > 1 (multiple time stepping; "coupling.continuum_substeps"):
//    the continuum's internal force is computed once every m steps and applied as two impulses,
//    m dt/2 M^-1 f at the first step of each macro step of m steps and at its last (r-RESPA's
//    impulse form: Tuckerman, Berne & Martyna, J. Chem. Phys. 97 (1992); still time-reversible
//    and symplectic); the continuum drifts and the constraint is solved every step. m = 1 is
//    step 2 and 3 above.
//    m = 0 (auto) takes m = floor(continuum / DEM critical step), at least 1 (time_steps() says).
//  - critical_time_step() = min(DEM, continuum / m): the constrained system's highest frequency
//    is at most the larger of the two (Rayleigh quotient over a subspace), and the continuum's
//    macro step m dt must stay below its own.
//  - energies(): DEM kinetic + bond + contact and continuum kinetic + strain (both weighted),
//    DEM external work and dissipation, the work of the multiplier forces, and the O(dt^2)
//    difference to velocity Verlet's invariant (shadow_total(), conserved to round-off for linear
//    bonds and no loads; total() oscillates by O((omega dt)^2) around it). Balance:
//    total - total(0) = dem external work - dissipated + coupling work (continuum external
//    work of tractions or moving held dofs is not counted).
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "continuum/continuum_solver.hpp"
#include "coupling/coupling_operators.hpp"
#include "coupling/multiplier_solver.hpp"
#include "coupling/overlap_zone.hpp"
#include "dem/dem_model.hpp"

namespace arlequin::coupling {

struct CoupledOptions {
  CouplingSettings coupling;
  // Consistent overlap quadrature (above; cases/patch_coupled/README.md): the continuum's
  // overlap weights are corrected so that its weighted residual of a uniform stress is the DE
  // cloud's, seen through N.
  bool consistent_quadrature = false;
  // The multiplier solve: PETSc's KSP with these options (default: none, i.e. preonly +
  // cholesky), or nullopt for our own sparse LDL^T (MultiplierSolver; case keys
  // "coupling.solver: petsc | direct", "coupling.petsc_options").
  std::optional<std::string> multiplier_petsc_options = std::string();
  std::vector<int> held_continuum_dofs;     // 3 * node + component
  std::vector<std::uint32_t> driven_des;    // DEs with kinematic boundary conditions
  // Bonds of the overlap (alpha_d < 1 at their midpoint) do not break when their criterion is
  // met: the continuum they share the load with cannot (coupling.on_damage_in_overlap: hold).
  bool hold_overlap_failures = false;
  // The continuum's internal force evaluated every this many steps (coupling.continuum_substeps);
  // 0: auto, the largest m whose macro step m dt_DEM stays within the continuum's critical step
  // (floor(dt_continuum / dt_DEM), at least 1), so that the continuum never sets the step.
  int continuum_substeps = 1;
  // Per DE of the scene, the components its coupling holds (coupling.ties); empty: all three.
  std::vector<std::array<bool, 3>> tied_components;
};

// The dofs of a continuum physical group (for held_continuum_dofs).
std::vector<int> group_dofs(const continuum::ContinuumSolver& continuum, const std::string& group,
                            std::array<bool, 3> components);

struct TimeSteps {
  double dem = 0.0;        // s, DEM critical step (weighted masses and bonds)
  double continuum = 0.0;  // s, continuum critical step (weighted)
  double coupled = 0.0;    // s, min of the DEM's and the continuum's / m
  int continuum_substeps = 1;  // m: the continuum's internal force once every m steps
};

struct CoupledEnergies {
  dem::Energies dem;
  double continuum_kinetic = 0.0;  // J
  double continuum_strain = 0.0;   // J
  double coupling_work = 0.0;      // J, work of the multiplier forces on both models
  // a.M a over each model, a = constrained accelerations at this time (rotations included), J/s^2.
  double dem_acceleration_norm = 0.0;
  double continuum_acceleration_norm = 0.0;
  double total() const { return dem.total() + continuum_kinetic + continuum_strain; }
  // Velocity Verlet's own invariant, which differs from total() by O((omega dt)^2): for a linear
  // system it conserves exactly total() - dt^2/8 a.M a (one oscillator:
  // 1/2 v^2 + 1/2 w^2 u^2 (1 - (w dt)^2 / 4)). J.
  double shadow_total(double dt) const { return dem_shadow(dt) + continuum_shadow(dt); }
  double dem_shadow(double dt) const { return dem.total() - dt * dt / 8.0 * dem_acceleration_norm; }
  double continuum_shadow(double dt) const {
    return continuum_kinetic + continuum_strain - dt * dt / 8.0 * continuum_acceleration_norm;
  }
};

struct CouplingMonitor {
  double constraint_residual = 0.0;    // |G_d v_d + G_c v_c| / |G_d v_d| after the last correction
  double velocity_mismatch = 0.0;      // rms over coupled DEs of |v_p - (N v_c)(x_p)| (held components), m/s
  double max_velocity_mismatch = 0.0;  // max of the same, m/s
};

// Bonds that broke where the coupling weighted them (their set-up midpoint in the overlap, the
// DEM's weight there below 1): the coupling's operators assume that material intact.
struct OverlapDamage {
  std::size_t breaks = 0;  // such breaks (or held failures) since the last look
  dem::BreakEvent first;   // the first of them
  double weight = 1.0;     // alpha_d at its bond's midpoint
  bool held = false;       // the bonds were held intact (options.hold_overlap_failures)
};

class CoupledModel {
 public:
  CoupledModel(dem::DemModel& dem, continuum::ContinuumSolver& continuum, const OverlapZone& zone,
               CoupledOptions options = {});
  CoupledModel(const CoupledModel&) = delete;
  CoupledModel& operator=(const CoupledModel&) = delete;

  const TimeSteps& time_steps() const { return time_steps_; }
  double critical_time_step() const { return time_steps_.coupled; }
  // One line per item: overlap, weights, mediator, counts, A, time steps (printed at start).
  std::string summary() const;

  void step(double dt);
  double time() const { return time_; }
  long steps_done() const { return steps_; }

  CoupledEnergies energies() const;
  // The continuum's kinetic energy, J: at velocities in step with its forces when they act every
  // few steps (options.continuum_substeps), else 1/2 v.M v.
  double continuum_kinetic_energy() const;
  double coupling_work() const { return coupling_work_; }  // J, as in energies(), without the sums
  // From the state after the last step, on demand: a step computes neither this nor the
  // acceleration norms of energies(), which only output rows and tests read.
  CouplingMonitor monitor() const;
  // |G_d u_d + G_c u_c| / |G_d u_d| for the current displacements.
  double displacement_residual() const;

  // The breaks since the last call whose bonds lie where the DEM's weight is below 1 (count and
  // first; nullopt if none): each break of the DEM is looked at once. With
  // hold_overlap_failures, the bonds held intact there instead (held).
  std::optional<OverlapDamage> damage_in_overlap();

  // Checkpoint (docs/restart.md): both models' states (DemModel::save_state,
  // ContinuumSolver::save_state under "continuum/") and the coupling's own under "coupling/": the
  // multipliers and constraint accelerations the next step's first half kick applies, their
  // forces G^T mu, the multiplier work, time, step and the breaks already looked at. load_state
  // on the coupled model built again from the same case continues bit for bit.
  void save_state(StateArchive& archive) const;
  void load_state(const StateArchive& archive);
  // After both models' states were set from outside between two steps (a zone that moved,
  // app/zone_move.hpp: DEs and nodes carried over from another scene, the new ones interpolated):
  // their forces again, the velocities onto the constraint and its force, as at construction;
  // a macro step of the continuum's substeps opens at the next step, whatever the step count.
  void resume_from_set_state();
  // Kinetic damping between two macro steps (opens_macro_step(), where the continuum's
  // velocities are in step with its forces): the DEs `ids` stop (DemModel::arrest, their kinetic
  // energy booked as the DEM's dissipation), then the velocities of both models go back onto
  // G v = 0 by the same mass-weighted projection as a step's correction. That projection is an
  // impulse of the multipliers; the kinetic energy it changes is their work, booked in
  // coupling_work(). Returns what the DEs lost, J.
  double arrest(std::span<const std::uint32_t> ids);
  // Dynamic relaxation of a state set from outside (after resume_from_set_state, where
  // opens_macro_step()): it moves the displacements, not the motion, toward the state whose
  // constrained accelerations are `target`'s (save_accelerations' entries, e.g. those each DE
  // and node had before a zone moved, so that the move leaves no force it did not find).
  // `steps` pseudo-time steps of dt with the time standing still (DemModel::relaxation_kick:
  // imposed components and held dofs still, no failure): both models kicked by
  // M^-1 (f - M a_target), their velocities onto G v = 0 after each kick, and all velocities
  // zeroed where the kinetic energy fell (kinetic damping at its peaks,
  // docs/references.md#barnes1999). Then the state it started from takes the relaxed DE
  // positions, orientations and continuum displacements, and the cohesive links' damage and
  // dissipation, which grow along the relaxation's path as along a step's (velocities, time
  // and the other running sums as they were), and resumes (resume_from_set_state); G u keeps
  // what it found.
  // A net force on a rigid motion that no held dof stops (for the DCB held at its load lines
  // along z only: along x and y, and turns about z and about the load line) has no static state:
  // pseudo-time would carry the whole away at constant acceleration, the kinetic energy would
  // never fall and nothing would be damped. The target's share on those motions, what the state
  // set changed of the total momentum, is left to the run: the targets are shifted by the rigid
  // acceleration that cancels it (M-weighted, rotations about the centre of mass).
  // The relaxation changes the total energy, which the caller books as the move's. Returned:
  // sum m |P (a - a_target)|^2 over both models, P the projection onto G a = 0, before and after.
  struct Relaxation {
    int steps = 0;
    double imbalance_before = 0.0, imbalance_after = 0.0;  // W/s = J/s^2
    int free_rigid_motions = 0;  // whose share of the target was taken out
    double fracture = 0.0;  // J: what the growth of the links' damage dissipated (kept, in E_fracture)
  };
  // The constrained accelerations of the present state under "accelerations/": per DE
  // (translation m/s^2, rotation rad/s^2) and per continuum dof (0 on held ones).
  void save_accelerations(StateArchive& archive) const;
  Relaxation relax(double dt, int steps, const StateArchive& target);
  // Whether the next step opens a macro step of options.continuum_substeps (its continuum force
  // is then that of the present state): where a state may be set from outside.
  bool opens_macro_step() const { return macro_phase() == 0; }

  const OverlapZone& zone() const { return zone_; }
  const CouplingOperators& operators() const { return ops_; }
  const MultiplierSolver& multipliers() const { return *solver_; }
  dem::DemModel& dem() { return dem_; }
  continuum::ContinuumSolver& continuum() { return continuum_; }

 private:
  void untie_prescribed_rows();
  // The constructor's and resume_from_set_state's last part: the velocities onto G v = 0, the
  // constraint force of the present forces.
  void put_state_on_constraint();
  // Both models' velocities onto G v = 0 (the mass-weighted projection); lambda_ as scratch.
  void project_velocities();
  // Whether continuum dof d moves on its own: neither fixed nor held for the coupling.
  bool continuum_dof_free(std::size_t d) const { return inv_mass_c_[d] != 0.0 && !continuum_.is_fixed(static_cast<int>(d)); }
  // relax's targets (M a_target, per DE force and torque; per continuum dof the acceleration)
  // less their share on the rigid motions that no held dof stops (see relax).
  // Returns how many independent rigid motions were free.
  int remove_free_rigid_share(std::vector<Vec3>& force_offset, std::vector<Vec3>& torque_offset,
                              std::vector<double>& continuum_target) const;
  // The phases of step(), in order (see the contract above).
  void constraint_half_kick(double dt);
  void advance_models(double dt);
  void kick_to_trial(double dt);
  // Whether the step in progress is the last of a macro step of the continuum's substeps (during
  // a step, opens_macro_step() says whether it is the first; both when there is one substep).
  bool closes_macro_step() const { return macro_phase() + 1 == options_.continuum_substeps; }
  // The steps of the present macro step done so far, counted from macro_origin_.
  int macro_phase() const { return static_cast<int>((steps_ - macro_origin_) % options_.continuum_substeps); }
  void solve_and_correct(double dt);  // solve_multipliers + correct_velocities

  void make_overlap_quadrature_consistent();
  void gather_dem_velocity(Matrix3& v) const;
  void scatter_dem_velocity(const Matrix3& v);
  std::array<double, 2> acceleration_norm() const;  // DEM, continuum, for energies()
  Eigen::Map<Matrix3> continuum_velocity();

  dem::DemModel& dem_;
  continuum::ContinuumSolver& continuum_;
  OverlapZone zone_;
  std::size_t breaks_looked_at_ = 0;  // damage_in_overlap()
  std::size_t held_looked_at_ = 0;    // damage_in_overlap()
  CoupledOptions options_;
  CouplingOperators ops_;
  std::unique_ptr<MultiplierSolver> solver_;
  std::vector<double> inv_mass_d_, inv_mass_c_;
  Matrix3 acc_d_, acc_c_;  // constraint accelerations M^-1 G^T mu(n) (subtracted)
  Matrix3 mu_;             // multipliers of the constraint force at t(n)
  MultiplierSolver::Impulse constraint_force_;  // G^T mu(n) on the coupled DEs and the continuum's nodes, N
  // Scratch of the step (sized once; no allocation per step): coupled DE velocities, those of
  // the drift and the corrected nodes' (for the multipliers' work), multipliers and their impulse.
  Matrix3 vd_, vd_drift_, vc_drift_, lambda_;
  MultiplierSolver::Impulse constraint_force_next_;
  TimeSteps time_steps_;
  bool continuum_mass_floored_ = false;
  int prescribed_rows_ = 0;  // rows untied by untie_prescribed_rows
  continuum::ContinuumSolver::WeightCorrection quadrature_correction_;
  double coupling_work_ = 0.0;
  double time_ = 0.0;
  long steps_ = 0;
  // The step the macro steps count from: 0, or the one a state was set from outside at
  // (resume_from_set_state). A following band's moved scene may take another number of substeps
  // than the scene its state came from (continuum_substeps: auto), and the run's step count
  // need not be a multiple of it.
  long macro_origin_ = 0;
};

}  // namespace arlequin::coupling
