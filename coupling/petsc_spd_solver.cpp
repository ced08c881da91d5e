// SPDX-License-Identifier: GPL-3.0-or-later
#include "coupling/petsc_spd_solver.hpp"

#include <petscksp.h>

#include <string>
#include <vector>

#include "common/error.hpp"
#include "continuum/petsc_session.hpp"

namespace arlequin::coupling {

namespace {
void check(PetscErrorCode code, const char* what) { continuum::petsc_check(static_cast<int>(code), what); }
}  // namespace

struct PetscSpdSolver::Handles {
  Mat A = nullptr;
  KSP ksp = nullptr;
  Vec b = nullptr, x = nullptr;
  ~Handles() {
    if (!continuum::PetscSession::started()) return;  // PETSc already finalised at exit
    VecDestroy(&b);
    VecDestroy(&x);
    KSPDestroy(&ksp);
    MatDestroy(&A);
  }
};

PetscSpdSolver::PetscSpdSolver(const Eigen::SparseMatrix<double>& A, const std::string& options)
    : h_(std::make_unique<Handles>()), size_(static_cast<int>(A.rows())) {
  continuum::PetscSession::ensure();
  // Row-compressed copy: PETSc's AIJ takes a row's columns and values at once.
  const Eigen::SparseMatrix<double, Eigen::RowMajor> R(A);
  const int* start = R.outerIndexPtr();
  std::vector<PetscInt> counts(size_), columns(R.innerIndexPtr(), R.innerIndexPtr() + R.nonZeros());
  for (int r = 0; r < size_; ++r) counts[r] = start[r + 1] - start[r];
  check(MatCreateSeqAIJ(PETSC_COMM_SELF, size_, size_, 0, counts.data(), &h_->A), "MatCreateSeqAIJ");
  for (PetscInt r = 0; r < size_; ++r)
    check(MatSetValues(h_->A, 1, &r, counts[r], columns.data() + start[r], R.valuePtr() + start[r], INSERT_VALUES),
          "MatSetValues");
  check(MatAssemblyBegin(h_->A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(h_->A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  check(MatSetOption(h_->A, MAT_SPD, PETSC_TRUE), "MatSetOption");

  check(KSPCreate(PETSC_COMM_SELF, &h_->ksp), "KSPCreate");
  check(KSPSetOperators(h_->ksp, h_->A, h_->A), "KSPSetOperators");
  // The defaults, set before the options so that the options win and only theirs are checked
  // for use: a direct solve, and a tight tolerance for an iterative choice.
  PC pc;
  check(KSPGetPC(h_->ksp, &pc), "KSPGetPC");
  check(KSPSetType(h_->ksp, KSPPREONLY), "KSPSetType");
  check(PCSetType(pc, PCCHOLESKY), "PCSetType");
  check(KSPSetTolerances(h_->ksp, 1e-12, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT), "KSPSetTolerances");
  {
    // Options and set-up (the factorisation of a direct solve) under the options' own database.
    const continuum::ScopedPetscOptions scope(options);
    // Quietly: a refused option is the case's error, reported once by us, not PETSc's trace.
    PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
    const PetscErrorCode read = KSPSetFromOptions(h_->ksp);
    PetscPopErrorHandler();
    if (read != 0) throw SettingError("petsc_options", "PETSc refused '" + options + "' (an unknown KSP or PC type?)");
    check(KSPSetUp(h_->ksp), "KSPSetUp");
    if (const std::string unused = scope.unused(); !unused.empty())
      throw SettingError("petsc_options", "PETSc did not use '" + unused + "' (misspelt, or for a solver type not chosen)");
  }
  check(KSPGetPC(h_->ksp, &pc), "KSPGetPC");  // the options may have replaced it
  PCFailedReason failed;
  check(PCGetFailedReason(pc, &failed), "PCGetFailedReason");
  if (failed != PC_NOERROR)
    throw RunError(std::string("coupling: PETSc could not set up the multiplier solve (") + PCFailedReasons[failed] +
                   ", " + description() + ")");
  // Vectors without storage of their own: solve() places the caller's arrays in them.
  check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, size_, nullptr, &h_->b), "VecCreateSeqWithArray");
  check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, size_, nullptr, &h_->x), "VecCreateSeqWithArray");
}

PetscSpdSolver::~PetscSpdSolver() = default;

void PetscSpdSolver::solve(const double* rhs, double* x) const {
  // KSPSolve may scale b in place (-ksp_diagonal_scale): the caller's rhs is its scratch.
  check(VecPlaceArray(h_->b, const_cast<double*>(rhs)), "VecPlaceArray");
  const PetscErrorCode placed = VecPlaceArray(h_->x, x);
  const PetscErrorCode solved = placed == 0 ? KSPSolve(h_->ksp, h_->b, h_->x) : placed;
  // Reset whatever happened, so that the next call can place its arrays again.
  VecResetArray(h_->b);
  if (placed == 0) VecResetArray(h_->x);
  check(solved, "KSPSolve (coupling multipliers)");
  KSPConvergedReason reason;
  check(KSPGetConvergedReason(h_->ksp, &reason), "KSPGetConvergedReason");
  if (reason < 0)
    throw RunError(std::string("coupling: the multiplier solve did not converge (") + KSPConvergedReasons[reason] + ", " +
                   description() + "); tighten or change coupling.petsc_options");
}

std::string PetscSpdSolver::description() const {
  KSPType ksp_type;
  PCType pc_type;
  PC pc;
  check(KSPGetType(h_->ksp, &ksp_type), "KSPGetType");
  check(KSPGetPC(h_->ksp, &pc), "KSPGetPC");
  check(PCGetType(pc, &pc_type), "PCGetType");
  return std::string(ksp_type ? ksp_type : "?") + " + " + (pc_type ? pc_type : "?");
}

}  // namespace arlequin::coupling
