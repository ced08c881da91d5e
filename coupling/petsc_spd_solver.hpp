// PetscSpdSolver: a sparse symmetric positive definite system solved by PETSc's KSP, the
// multiplier solver's runtime-configurable alternative to its own sparse Cholesky.
//
// Contract
//  - The matrix is copied into a sequential AIJ matrix on PETSC_COMM_SELF: every MPI rank holds
//    the whole coupled system, as it does the explicit step. PETSc must be started
//    (continuum::PetscSession).
//  - Options: a PETSc option string ("-ksp_type cg -pc_type icc -ksp_rtol 1e-14") inserted under
//    the prefix "coupling_" (so they never reach the continuum's own KSP); the defaults are
//    "-ksp_type preonly -pc_type cholesky", a direct solve factored once at construction. An
//    option PETSc does not know is left unused, as PETSc does everywhere.
//  - solve(rhs, x): x = A^-1 rhs for one column of `size()` doubles; no allocation (the
//    vectors wrap the caller's arrays). RunError if the factorisation fails (A not positive
//    definite) or an iterative solve does not converge (PETSc's reason in the message).
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
  std::string description() const;  // "preonly + cholesky", the KSP and PC types in use

 private:
  struct Handles;  // Mat, KSP, Vec: PETSc types kept out of this header
  std::unique_ptr<Handles> h_;
  int size_ = 0;
};

}  // namespace arlequin::coupling
