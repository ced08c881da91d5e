// SPDX-License-Identifier: GPL-3.0-or-later
// PetscSpdSolver: a sparse symmetric positive definite system solved by PETSc's KSP, chosen and
// tuned at run time by an option string (the coupling's multiplier system; MultiplierSolver).
//
// Contract
//  - The matrix is copied into a sequential AIJ matrix on PETSC_COMM_SELF: every MPI rank holds
//    the whole coupled system, as it does the explicit step. PETSc is started if it was not.
//  - Options: a PETSc option string ("-ksp_type cg -pc_type icc"), read in a database of its
//    own (continuum::ScopedPetscOptions), so it reaches this solver only. Defaults, which the
//    options override: KSP preonly, PC cholesky (a direct solve, factored once here), relative
//    tolerance 1e-12 for an iterative choice (the coupling's monitor shows the residual).
//    InputError, its message starting "petsc_options: ", if PETSc refuses the options or leaves
//    one unused (misspelt, or for a solver type not chosen).
//  - solve(rhs, x): x = A^-1 rhs for one column of `size()` doubles; no allocation of ours (the
//    vectors wrap the caller's arrays). RunError if the set-up fails (e.g. a zero pivot) or an
//    iterative solve does not converge (PETSc's reason in the message).
#pragma once
#include <Eigen/Sparse>
#include <memory>
#include <string>

namespace arlequin::coupling {

class PetscSpdSolver {
 public:
  PetscSpdSolver(const Eigen::SparseMatrix<double>& A, const std::string& options);
  ~PetscSpdSolver();
  PetscSpdSolver(const PetscSpdSolver&) = delete;
  PetscSpdSolver& operator=(const PetscSpdSolver&) = delete;

  void solve(const double* rhs, double* x) const;
  int size() const { return size_; }
  std::string description() const;  // "preonly + cholesky": the KSP and PC types in use

 private:
  struct Handles;  // Mat, KSP, Vec: PETSc types kept out of this header; destroyed with it
  std::unique_ptr<Handles> h_;
  int size_ = 0;
};

}  // namespace arlequin::coupling
