// SPDX-License-Identifier: GPL-3.0-or-later
// ContinuumSolver: one elastic continuum on a gmsh mesh, discretised by a named method (see
// registry.hpp). Everything the coupling and the application use is here; a method only
// supplies its integration points, its lumped mass and its interpolation.
//
// Contract
//  - Unknowns: one displacement vector per node of `nodes()`; fields (`Field`) hold 3 values per
//    node, node-major (x0, y0, z0, x1, ...).
//  - Weight alpha(x) (Arlequin, default 1) multiplies every volume integrand: the lumped mass,
//    the internal force, the stiffness and the strain energy. The caller applies any mass floor.
//  - Kinematics (docs/theory.md#finite-kinematics): forces and energies are sums over points,
//    w_q = alpha(x_q) |cell_q|, with H_q = sum_a u_a (x) grad_q N_a the displacement gradient at q.
//      small:  eps_q = sym(H_q) = B_q u, f_int = sum_q w_q B_q^T C_q B_q u = K u,
//              E_strain = 1/2 sum_q w_q eps_q.C_q eps_q = 1/2 u.K u. K is assembled once per
//              weight (a BlockMatrix3), so a step and an energy cost one pass over K's blocks.
//      finite: total Lagrangian St Venant-Kirchhoff: F = I + H_q, Green-Lagrange
//              E_q = (H + H^T + H^T H) / 2, S_q = C_q E_q, f_int,a = sum_q w_q F_q S_q grad_q N_a,
//              E_strain = 1/2 sum_q w_q E_q.C_q E_q. A rigid rotation of any size strains nothing,
//              as a DEM's bonds see it; the material law is meant for small strains.
//    critical_time_step() and solve_static() use K (the tangent at the undeformed state).
//  - `interpolation(points)` returns the sparse operator N (rows: points, columns: nodes) with
//    u(point_p) = sum_I N(p, I) u_I per component; points outside the body are an InputError.
//  - Essential BCs act on named physical groups and fix chosen components to g(X, t); loads are
//    tractions on named boundary groups, integrated with the method's own shape functions and
//    surface rule (`surface_rule`).
//  - Explicit central difference = velocity Verlet: kick(dt/2), drift(dt), compute_forces(),
//    kick(dt/2) (`step`). The coupled step (docs/theory.md#coupled-step) calls the three parts itself.
//    Stable for dt < critical_time_step() = 2 / omega_max of M^-1 K (Lanczos).
//  - `solve_static` assembles K into a PETSc Mat distributed over PETSC_COMM_WORLD (each rank
//    adds its share of the integration points; one rank when run without mpirun) and solves
//    K u = f with KSP; the PETSc option string (e.g. "-ksp_type cg -pc_type gamg") overrides the
//    defaults "cg + gamg, rtol 1e-12". The solution is gathered on every rank: everything else
//    (explicit steps, interpolation) is replicated, so every rank must make the same calls.
//  - Mesh and input problems are InputError; failed solves and non-finite states are RunError.
#pragma once
#include <Eigen/Sparse>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "common/state_archive.hpp"
#include "common/vec3.hpp"
#include "continuum/block_matrix.hpp"
#include "continuum/finite_strain_force.hpp"
#include "continuum/material.hpp"
#include "continuum/mesh.hpp"

namespace arlequin::continuum {

using Field = std::vector<double>;
using InterpolationOperator = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using ScalarFunction = std::function<double(const Vec3& x)>;
using VectorFunction = std::function<Vec3(const Vec3& x, double t)>;

struct RegionMaterial {
  std::string region;  // name of a 3D physical group; empty = the whole mesh
  Material material;
};

// The strain measure (contract above).
enum class Kinematics { small, finite };
Kinematics kinematics_from_name(const std::string& name);  // "small" or "finite"; InputError otherwise

struct ContinuumSettings {
  MeshSource mesh;
  Kinematics kinematics = Kinematics::small;
  std::vector<RegionMaterial> materials;
  std::string petsc_options;              // given to PetscSession on the first continuum built
  std::string shape_functions = "sibson";  // nem only: "sibson" or "laplace"
  double nem_stabilization = 1.0;          // nem only: MSCNI's a (nem_solver.hpp), > 0
};

class ContinuumSolver {
 public:
  virtual ~ContinuumSolver();
  ContinuumSolver(const ContinuumSolver&) = delete;
  ContinuumSolver& operator=(const ContinuumSolver&) = delete;

  const Mesh& mesh() const { return mesh_; }
  const std::vector<Vec3>& nodes() const { return mesh_.nodes(); }
  int num_nodes() const { return mesh_.num_nodes(); }

  // Arlequin weight; recomputes the lumped mass and the point weights. The stiffness (point
  // weights) takes alpha; the mass max(alpha, mass_floor), so that a node whose points all have
  // alpha = 0 keeps a mass without the material gaining stiffness where it has no weight (the
  // DEM's masses are floored alike, docs/decisions.md#d9).
  void set_weight(ScalarFunction alpha, double mass_floor = 0.0);
  const std::vector<double>& lumped_mass() const { return mass_; }  // per node, weighted
  // Per dof: the node's lumped mass times the material's inertia share along the dof's axis;
  // the mass the dynamics use (kicks, kinetic energy, critical step, coupling).
  const std::vector<double>& dof_mass() const { return dof_mass_; }

  // Consistency of a weighted quadrature (the Arlequin overlap's consistent quadrature,
  // coupling/coupled_model.hpp). Under a uniform stress sigma the weighted internal force of
  // node a is sigma g_a, with
  //   g_a = sum_q w_q grad_q N_a   (m^2).
  // This changes the weights w_q of the points where alpha(x_q) < 1 (the overlap) to
  // w_q exp((A^T y)_q), the closest to the old ones in relative entropy (for small changes:
  // the least sum_q delta_q^2 / w_q), such that g_a = target[a] at every node with
  // constrained[a] that those points reach (the others cannot change, and their targets are
  // not looked at). The weights stay positive; the lumped mass is not changed. Targets that
  // cannot be met (e.g. contradicting a free surface's own flux) are an InputError, and then
  // nothing has changed. Call after set_weight.
  struct WeightCorrection {
    int points = 0;                // points allowed to change (alpha < 1)
    int nodes = 0;                 // constrained nodes they reach
    double largest_change = 0.0;   // max |delta_q| / |cell_q|
    double smallest_weight = 0.0;  // min w_q / |cell_q| over those points after the change
  };
  WeightCorrection correct_weights(const std::vector<Vec3>& target, const std::vector<char>& constrained);
  bool is_fixed(int dof) const { return is_fixed_[dof] != 0; }

  virtual InterpolationOperator interpolation(const std::vector<Vec3>& points) const = 0;

  // Fixes `components` of every node of `group` to u0 + g(X, t) (applied now and at every
  // drift), u0 the initial displacement (0 unless set_initial_displacement). Without g (or with
  // an empty one) the support is still: its dofs stay at u0 with zero velocity, and the steps
  // skip them (their support work is zero), so whoever writes velocity() or displacement() must
  // leave held dofs as they are (the coupling's corrections and relaxation write free dofs only).
  void fix(const std::string& group, std::array<bool, 3> components, VectorFunction g = {});
  // Starts from u0 (one value per dof): a pre-strained state. Essential conditions, set before
  // or after, prescribe their g on top of it, as the DEM's boundary conditions move DEs from
  // where they start.
  void set_initial_displacement(const Field& u0);
  // Traction (force per area, function of position and time) on a 2D physical group.
  void add_traction(const std::string& group, VectorFunction traction);

  Field& displacement() { return u_; }
  Field& velocity() { return v_; }
  const Field& displacement() const { return u_; }
  const Field& velocity() const { return v_; }
  const Field& force() const { return f_; }  // f_ext(t) - f_int(u) - damping from the last compute_forces
  double time() const { return t_; }

  // Viscous (mass-proportional) damping, force -c m v on every free dof, c in 1/s, from the
  // velocity at compute_forces() (the half-step velocity in a step), as the DEM's
  // (DemModel::set_damping): quasi-static runs, and the same arms as a damped DEM in a coupled
  // scene. It lowers critical_time_step() (common/damped_step.hpp); dissipated() is its work.
  void set_damping(double coefficient);
  double dissipated() const { return dissipated_; }  // J, >= 0
  void compute_forces();
  void kick(double dt);   // v += dt M^-1 f on free components (and the damping's work)
  void drift(double dt);  // u += dt v on free components; t += dt; fixed ones follow g
  // One velocity-Verlet step; it also adds the step's external work (external_work()).
  void step(double dt);
  // The external work of one step, for a step made of the parts above (a coupled step):
  // begin_step_work() before its first kick, end_step_work() after its last (step() calls both).
  void begin_step_work();
  void end_step_work();
  double critical_time_step() const;

  // Work done on the continuum by its tractions and its moving supports over the steps between
  // begin_step_work() and end_step_work() (step(), a coupled step), J: per step, the prescribed dofs' kinetic
  // energy change + 1/2 (f_ext + f_ext').du - 1/2 (f + f')_prescribed.du_prescribed, which with
  // verlet_correction() makes the discrete energy balance exact for linear elasticity
  // (docs/theory.md#energy).
  double external_work() const { return external_work_; }
  // (dt^2 / 8) sum over the free dofs of f^2 / m, J: velocity Verlet conserves, without external
  // work, kinetic + strain energy minus this (the step's shadow energy of a linear system).
  double verlet_correction(double dt) const;

  // Checkpoint (docs/restart.md): u, v, f, time and the external work under `prefix`, with the
  // lumped mass to recognise the discretisation; load_state on the solver built again from the
  // same case (weighted alike) continues bit for bit, StateMismatch if the mass differs.
  void save_state(StateArchive& archive, const std::string& prefix) const;
  void load_state(const StateArchive& archive, const std::string& prefix);
  // Static equilibrium at the current time; leaves u solved, v untouched, forces updated.
  void solve_static(const std::string& petsc_options = "");
  // SettingError at "petsc_options" when PETSc refuses the static solve's options or leaves one
  // unread (checked on a 1 x 1 system, so a case is refused before its run; starts PETSc).
  static void check_static_solver_options(const std::string& petsc_options);

  // f_int(u) of the solver's kinematics; K u for small ones.
  void internal_force(const Field& u, Field& f_int) const;
  // Small kinematics: 1/2 u.K u, one pass over K. A rigid part of u cancels to round-off
  // eps |K| |u|^2 (the point sum's was second order in eps); far below the energies of these
  // cases, but a state with a rigid motion 1e6 times its strains would see it. Finite: the
  // point sum of the contract.
  double strain_energy() const;
  // Per dof, K's diagonal (K the tangent at the undeformed state, as weighted), N/m: the scale
  // of each dof's stiffness, for preconditioning a solve with the tangent of either kinematics.
  std::vector<double> stiffness_diagonal() const;
  // 1/2 v.M v; with `kick` (s): that of the velocities a kick by it with the present forces
  // would give, the state unchanged (a multiple-time-step caller's synchronised velocities).
  double kinetic_energy(double kick = 0.0) const;

  // Integration points, for output and checks: positions and strain / stress (Voigt): small
  // strain and Cauchy stress, or (finite) Green-Lagrange strain and second Piola-Kirchhoff stress.
  const std::vector<Vec3>& point_positions() const { return points_.x; }
  const std::vector<double>& point_weights() const { return point_weight_; }  // alpha(x_q) |cell_q|, m^3
  std::vector<Voigt> point_strain() const;
  std::vector<Voigt> point_stress() const;

 protected:
  explicit ContinuumSolver(const ContinuumSettings& settings);

  // Integration points in compressed rows: point q couples nodes node[offset[q] .. offset[q+1])
  // with (smoothed) shape-function gradients grad[...] and has measure volume[q].
  struct Points {
    std::vector<Vec3> x;
    std::vector<double> volume;
    std::vector<int> material;
    std::vector<int> offset{0};
    std::vector<int> node;
    std::vector<Vec3> grad;
    // Optional (empty if the method has none): grad[e] = sum_b coef[e]_b basis[q][b], the same
    // combinations at the same point of every element (FiniteStrainForce then reads these, not
    // grad).
    std::vector<std::array<Vec3, 3>> basis;
    std::vector<Vec3> coef;
  };
  // Derived constructors fill points_ and then call finish_setup().
  void finish_setup();
  virtual std::vector<double> weighted_lumped_mass(const ScalarFunction& alpha) const = 0;

  // Quadrature of surface integrals over boundary triangles (vertex triples of the mesh): points,
  // weights (areas) and the interpolation operator at the points. Default: Dunavant degree 4 on
  // every triangle.
  struct SurfaceRule {
    std::vector<Vec3> x;
    std::vector<double> w;
    InterpolationOperator N;
  };
  virtual SurfaceRule surface_rule(const std::vector<std::array<int, 3>>& triangles) const;

  Mesh mesh_;
  std::vector<Material> materials_;
  std::vector<int> tet_material_;  // per tetrahedron, index into materials_
  Points points_;

 private:
  struct Traction {
    SurfaceRule rule;
    VectorFunction fn;
  };
  struct Fixed {
    int dof;
    VectorFunction g;    // empty: a still support
    double start = 0.0;  // the initial displacement of the dof, m
  };
  // H_q = sum_a u_a (x) grad_q N_a (row: displacement component, column: derivative).
  Eigen::Matrix3d displacement_gradient(int q, const Field& u) const;
  Voigt strain_at(int q, const Field& u) const;  // the kinematics' strain, engineering shears
  void add_external_force(Field& f) const;
  double prescribed(const Fixed& f, double t) const;

  // For every node in [node0, node1), the sorted nodes it shares an integration point with
  // (itself included): K's block pattern (the explicit K and the static solve's local rows).
  std::vector<std::vector<int>> coupled_nodes(int node0, int node1) const;
  // Point q's w_q B_q^T C_q B_q over its nodes (`nodes`, m of them): (3 m) x (3 m), row-major,
  // i.e. m x m blocks of 3 x 3 (PETSc's blocked layout).
  void point_stiffness(int q, std::vector<int>& nodes, std::vector<double>& Ke) const;
  // K = sum_q w_q B_q^T C_q B_q, assembled on first use after the weight was set.
  const BlockMatrix3& stiffness() const;
  // correct_weights' solve: the new weights of `points`, whose weights now are w0 (row[a]: the
  // row block of constrained node a, or -1; `rows` blocks).
  Eigen::VectorXd weights_meeting_targets(const std::vector<int>& points, const Eigen::VectorXd& w0,
                                          const std::vector<int>& row, int rows, const std::vector<Vec3>& target) const;

  Kinematics kinematics_;
  FiniteStrainForce finite_force_;  // finite kinematics' force (built by finish_setup)
  ScalarFunction alpha_;
  std::vector<double> point_weight_;  // alpha(x_q) volume_q
  // stiffness()'s K and whether it is that of the current weights; strain_energy()'s K u. Kept
  // between calls so that nothing is allocated per step (one caller at a time per solver, as
  // for every other state).
  mutable BlockMatrix3 stiffness_;
  mutable bool stiffness_current_ = false;
  mutable Field ku_;
  std::vector<double> mass_;
  std::vector<double> dof_mass_;
  std::vector<Fixed> fixed_;
  std::vector<int> moving_fixed_;  // fixed_'s entries with a g: the ones a step imposes and whose work it sums
  Field initial_u_;  // set_initial_displacement's u0 (empty: zero)
  std::vector<char> is_fixed_;  // per dof
  std::vector<double> kick_inverse_mass_;  // per dof: 1 / dof_mass_, 0 where fixed (what a kick multiplies f by)
  void update_kick_inverse_mass();
  std::vector<Traction> tractions_;
  Field u_, v_, f_;
  double t_ = 0.0;
  double external_work_ = 0.0;
  double damping_ = 0.0;         // 1/s
  Field damping_force_;          // N per dof, of the last compute_forces (both half kicks use it)
  double dissipated_ = 0.0;      // J
  std::vector<double> kick_partial_;  // the damped kick's work, per chunk of dofs (fixed_order_sum)
  // A step's work so far and its scratch: with tractions, u and f_ext at the step's start and f_ext
  // at its end; the prescribed dofs' u and f at the step's start.
  double step_work_ = 0.0;
  Field step_u_, step_f_ext_, step_f_ext_new_, step_fixed_u_, step_f_fixed_;
};

}  // namespace arlequin::continuum
