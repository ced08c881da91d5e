// SPDX-License-Identifier: GPL-3.0-or-later
// MultiplierSolver: the Lagrange-multiplier system of the velocity constraint, factored once.
//
// Contract
//  - A = G_d M_d^-1 G_d^T + G_c M_c^-1 G_c^T (Xiao & Belytschko, CMAME 193 (2004) Eq. 37;
//    Jebahi et al., CMAME 255 (2013) section 3.3), per displacement component, with M the
//    weighted lumped masses. A zero inverse mass marks a held dof (essential BC): it takes no
//    correction. A row whose dofs are all held (a mediator node on a held face whose DEs are
//    held too) is empty: its multiplier is 0. A is otherwise sparse SPD while the overlap and
//    the masses do not change; it is factored once (Eigen SimplicialLDLT, fill-reducing AMD
//    ordering) in the constructor and reused. When the three components have the same inverse
//    masses one factor serves all three.
//  - project(vd, vc) solves A lambda = G_d vd + G_c vc and corrects
//      vd -= M_d^-1 G_d^T lambda,  vc -= M_c^-1 G_c^T lambda,
//    the M-orthogonal projection onto ker G (after it G_d vd + G_c vc = 0 to round-off).
//    vd: coupled DEs x 3 (order of CouplingOperators::particles); vc: continuum nodes x 3.
//    The corrections (M^-1 G^T lambda) are returned in dd, dc.
//  - No allocation per call once the outputs have their sizes (rows x 3, DEs x 3, nodes x 3):
//    the explicit step calls these every step; scratch lives in the solver (one solver per
//    coupled model, not shared between threads). A call runs its loops and the independent
//    parts of its triangular solves (ForestFactor) on the OpenMP threads, with the same bits
//    on any thread count; not to be called inside a parallel region.
//  - Partial ties (CouplingOperators::tied): a row's free components are left out of that
//    component's system (an empty row of A, a zero row of U) and of the residual, so their
//    multipliers are 0 and those velocities are not corrected. Components with the same masses
//    and the same ties share a system.
//  - RunError if A is not positive definite (e.g. a coarse mediator with too few DEs per
//    element to fix every mediator node; the message suggests the fine mediator).
//  - With the fine mediator and L2 coupling G_d = W is diagonal and G_c = -W N, so
//    A = D + U C U^T with D = W M_d^-1 W diagonal (positive while no coupled DE is driven),
//    U = G_c restricted to the continuum dofs it reaches with a non-zero inverse mass, C their
//    inverse masses. Then A, whose LDL^T fills in wherever two DEs share an element (rows of
//    thousands of entries for a yarn-dense overlap), is solved exactly by the
//    Sherman-Morrison-Woodbury identity (docs/references.md#golub2013): A^-1 r = D^-1 r - D^-1 U K^-1 U^T D^-1 r with K = C^-1 + U^T D^-1 U, a
//    matrix over those continuum nodes only, SPD, factored once (LDL^T). A step then costs
//    O(non-zeros of N): U is stored once for the three components (a component's U keeps its
//    tied rows and the nodes it can move: masks, not copies) and read once for all three; each
//    system has its own K. The continuum's correction needs no product with G_c^T: with
//    w = K^-1 U^T D^-1 r, U^T lambda = U^T D^-1 r - (K - C^-1) w = C^-1 w, so C U^T lambda = w.
//    The subtraction is benign when the continuum's nodes outweigh the DEs they carry (C small
//    against D^-1's scale: the case of a coupling); it is checked at set-up
//    on a residual of A, matrix-free, and the general LDL^T above is used when the check fails
//    (or with PETSc, or with H1 coupling, whose S is not diagonal). backend() says which.
//    project() reads the same form from the velocities, not from the residual: with h the held
//    dofs' share of G_c v_c and T the ties, the projected continuum velocities on U's columns are
//    v_c' = v_c - w = K^-1 (C^-1 v_c - U^T D^-1 T (W v_d + h)), the tied DE components meet
//    their constraint, v_d' = -(U v_c' + h) / W, and lambda = (v_d - v_d') / (W M_d^-1): the
//    mass-weighted mean of the two models' motion, in two passes over U (the residual's pass
//    over G_c is not needed), whose constraint holds to the round-off of one product.
//  - Backend: our sparse LDL^T above, or PETSc's KSP when `petsc` is set (PetscSpdSolver, on
//    the same Jacobi-scaled A, with the case's options: PETSc's way of choosing a solver at run
//    time, e.g. an iterative one for a large overlap; the application's default, preonly +
//    cholesky). Either way A is factored once by our LDL^T to check that it is positive
//    definite (the RunError above), which PETSc's Cholesky (absolute zero-pivot test) or an
//    iterative solve would not always tell. The two cost the same per step on the wave bar
//    within the VM's noise (cases/wave_bar_coupled/README.md).
#pragma once
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <array>
#include <memory>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "coupling/coupling_operators.hpp"
#include "coupling/petsc_spd_solver.hpp"

namespace arlequin::coupling {

using Matrix3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  // one row per DE / node

class MultiplierSolver {
 public:
  // inv_mass_d: per coupled DE; inv_mass_c: per continuum dof (3 per node, node-major).
  // petsc: nullopt for our LDL^T, else PETSc with these options (empty: its defaults).
  MultiplierSolver(const CouplingOperators& ops, const std::vector<double>& inv_mass_d,
                   const std::vector<double>& inv_mass_c, const std::optional<std::string>& petsc);

  // A lambda = rhs per component (rhs, lambda: rows x 3).
  void solve(const Matrix3& rhs, Matrix3& lambda) const;
  // out = G_d vd + G_c vc (rows x 3), 0 in the components a row leaves free.
  void residual(const Matrix3& vd, const Eigen::Ref<const Matrix3>& vc, Matrix3& out) const;
  // Projects (vd, vc) onto ker G; lambda and the corrections dd, dc = M^-1 G^T lambda. dc is set
  // to 0 when it is resized and is not 0 only on corrected_nodes(): the general solve writes every
  // row, the Woodbury form only U's columns (0 in a component a node is held in). A
  // caller that keeps dc between calls (and changes it only on corrected_nodes()) reads the
  // whole correction in it. With `impulse`, also the multipliers' impulses G_d^T lambda (DEs x 3)
  // and G_c^T lambda (nodes x 3, set to 0 when resized and written on corrected_nodes() only),
  // held DEs and dofs included: what the work of the multiplier forces needs. dd, dc, lambda and
  // the impulses come multiplied by `rate` (a step's half kick passes 2/dt and gets them per unit
  // time: accelerations, multipliers, forces); vd and vc are the projected velocities whatever it
  // is. The Woodbury form scales each entry as it computes it, in the same pass (the same bits as
  // scaling afterwards but for the impulse on a held continuum component: a sum of scaled
  // multipliers).
  struct Impulse {
    Matrix3 dem, continuum;
  };
  void project(Matrix3& vd, Eigen::Ref<Matrix3> vc, Matrix3& dd, Matrix3& dc, Matrix3& lambda,
               Impulse* impulse = nullptr, double rate = 1.0) const;
  // The continuum nodes a projection can correct (those G_c reaches), in increasing order.
  const std::vector<int>& corrected_nodes() const { return corrected_nodes_; }

  // Distinct systems (one per distinct column of ties and reached inverse masses; the others reuse one).
  int systems() const { return systems_; }
  // "LDL^T", "diagonal + low rank (Woodbury), LDL^T of <k> continuum nodes a system ..." or "PETSc <ksp> + <pc>".
  std::string backend() const;
  int rows() const { return ops_->rows(); }
  // Non-zeros of what a solve reads: the scaled A (its factor fills in more), or U for the
  // low-rank form.
  long nonzeros() const { return nonzeros_; }

 private:
  using Factor = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>;
  // One system's factor P^T L D L^T P and the independent parts of its solve: the trees of L's
  // elimination forest (a column's parent is its first row below the diagonal, and every entry of
  // a column lies in the column's own tree), so that a tree's triangular solves read and write only
  // its own rows. Trees are grouped, in order, into tasks of at least `task_columns` columns.
  // Within a tree, runs of consecutive columns j, j + 1, ... each of whose rows are the next
  // column and then that column's rows (j + 1 the parent of j) make a supernode: below their
  // triangle the same rows, which the solves read and write once for all its columns.
  struct ForestFactor {
    std::unique_ptr<Factor> factor;
    Eigen::VectorXd D;
    std::vector<int> columns;          // L's columns tree by tree, each tree's in increasing order
    std::vector<int> supernode_start;  // supernode s: columns[supernode_start[s] .. supernode_start[s + 1])
    std::vector<int> task_start;       // task t: supernodes task_start[t] .. task_start[t + 1] - 1
  };
  static constexpr int task_columns = 256;
  // The forest of a computed factor.
  static ForestFactor forest_of(std::unique_ptr<Factor> factor);
  // The Woodbury form of one component's A (above).
  using RowMajorMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  struct LowRank {
    Eigen::VectorXd g;                // G_d's diagonal
    Eigen::VectorXd inv_g;            // 1 / g per row, 0 where a row is free in every component
    Eigen::VectorXd mass_over_g;      // m_d / g: a row's multiplier per unit of its DE's correction; 0 likewise
    Eigen::VectorXd inv_D;            // per row
    Matrix3 tied;                     // per row and component: 1 held, 0 free (CouplingOperators::tied)
    RowMajorMatrix U, Ut;             // rows x the nodes G_c reaches that can move (all components'), its transpose
    std::vector<int> node;            // the continuum node of each of U's columns
    Matrix3 movable;                  // per column and component: 1 where the node can move, 0 where held
    Matrix3 mass;                     // per column and component: the continuum mass (1 / inverse mass), 0 where held
    // G_c's entries at nodes held in some component (the other components' products mask
    // them), rows x nodes, and its transpose: the held dofs' share of the residual and of
    // G_c^T lambda. Empty where no row reaches a held dof.
    RowMajorMatrix held, heldT;
    std::vector<ForestFactor> K;      // per system, over all of U's columns
  };
  // The low-rank form of A, or nullptr when it does not apply or its set-up residual check fails.
  std::unique_ptr<LowRank> low_rank_form() const;
  // Whether the constraint holds row r's component c (CouplingOperators::tied).
  bool is_tied(int r, int c) const { return ops_->tied.size() == 0 || ops_->tied(r, c) != 0.0; }
  // lambda = A^-1 rhs, every system at once: the products with U and U^T read U once for the
  // three components.
  void solve_low_rank(const LowRank& a, const Matrix3& rhs, Matrix3& lambda) const;
  // project() in the low-rank form, from the velocities (the header's direct form).
  void project_low_rank(const LowRank& a, Matrix3& vd, Eigen::Ref<Matrix3> vc, Matrix3& dd, Matrix3& dc,
                        Matrix3& lambda, Impulse* impulse, double rate) const;
  // out = A_s^-1 in in the components each system s serves, A_s = factors[s], every system at
  // once (the tasks of all of them on the threads); with `scales`, A_s is the scaled S A S and
  // in and out are scaled by S (scales[s] per row). out may be in.
  void solve_systems(const std::vector<ForestFactor>& factors, const Matrix3& in, Matrix3& out,
                     const std::vector<Eigen::VectorXd>* scales) const;
  // The components system k serves (the first `width` entries) and their number.
  std::pair<std::array<int, 3>, int> served_by(int k) const;
  // The system of an earlier component with the same ties and the same continuum inverse masses
  // at the nodes G_c reaches (the DEs' masses are the same for all three components), or -1.
  int system_of_earlier_component(int c) const;

  const CouplingOperators* ops_;
  RowMajorMatrix GdT_, GcT_;                   // the transposes, for row-wise products
  std::vector<int> corrected_nodes_;           // GcT_'s rows with an entry
  std::unique_ptr<LowRank> low_rank_;          // the low-rank form, or null
  Matrix3 inv_d_, inv_c_;                      // inverse masses, per row and component
  std::vector<ForestFactor> factors_;          // our LDL^T, or
  std::vector<std::unique_ptr<PetscSpdSolver>> petsc_;  // PETSc's solve
  std::vector<Eigen::VectorXd> scales_;        // Jacobi scaling diag(A)^-1/2 of each factor
  std::array<int, 3> factor_of_{0, 0, 0};      // component -> system
  int systems_ = 0;
  long nonzeros_ = 0;
  mutable Matrix3 rhs_;                        // scratch: the residual to project
  mutable Eigen::VectorXd column_;              // scratch: one component (PETSc)
  mutable std::vector<double> solution_;       // scratch: a component (PETSc)
  mutable std::vector<std::vector<double>> blocks_, block_scratch_;  // scratch: each system's components
  mutable Matrix3 y_, w_;                      // scratch: the low-rank form's D^-1 rhs and K^-1 U^T y
  mutable Matrix3 held_share_;                 // scratch: the held dofs' share of G_c vc, per row
};

}  // namespace arlequin::coupling
