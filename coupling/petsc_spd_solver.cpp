#include "coupling/petsc_spd_solver.hpp"

#include <petscksp.h>

#include <string>
#include <vector>

#include "common/error.hpp"
#include "continuum/petsc_session.hpp"

namespace arlequin::coupling {

namespace {
void check(PetscErrorCode code, const char* what) { continuum::petsc_check(static_cast<int>(code), what); }
constexpr const char* kPrefix = "coupling_";
}  // namespace

struct PetscSpdSolver::Handles {
  Mat A = nullptr;
  KSP ksp = nullptr;
  Vec b = nullptr, x = nullptr;
};

PetscSpdSolver::PetscSpdSolver(const Eigen::SparseMatrix<double>& A, const std::string& options)
    : h_(std::make_unique<Handles>()), size_(static_cast<int>(A.rows())) {
  continuum::PetscSession::ensure();
  // The case's options under our prefix, after the defaults so that they win.
  check(PetscOptionsPrefixPush(nullptr, kPrefix), "PetscOptionsPrefixPush");
  const std::string all = "-ksp_type preonly -pc_type cholesky " + options;
  const PetscErrorCode inserted = PetscOptionsInsertString(nullptr, all.c_str());
  check(PetscOptionsPrefixPop(nullptr), "PetscOptionsPrefixPop");
  check(inserted, "coupling PETSc options");

  // Row-compressed copy: PETSc's AIJ wants per-row counts, columns and values.
  const Eigen::SparseMatrix<double, Eigen::RowMajor> R(A);
  std::vector<PetscInt> counts(size_);
  for (int r = 0; r < size_; ++r) counts[r] = static_cast<PetscInt>(R.outerIndexPtr()[r + 1] - R.outerIndexPtr()[r]);
  check(MatCreateSeqAIJ(PETSC_COMM_SELF, size_, size_, 0, counts.data(), &h_->A), "MatCreateSeqAIJ");
  for (int r = 0; r < size_; ++r) {
    const PetscInt row = r;
    std::vector<PetscInt> cols(R.innerIndexPtr() + R.outerIndexPtr()[r], R.innerIndexPtr() + R.outerIndexPtr()[r + 1]);
    check(MatSetValues(h_->A, 1, &row, counts[r], cols.data(), R.valuePtr() + R.outerIndexPtr()[r], INSERT_VALUES),
          "MatSetValues");
  }
  check(MatAssemblyBegin(h_->A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(h_->A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  check(MatSetOption(h_->A, MAT_SPD, PETSC_TRUE), "MatSetOption");

  check(KSPCreate(PETSC_COMM_SELF, &h_->ksp), "KSPCreate");
  check(KSPSetOperators(h_->ksp, h_->A, h_->A), "KSPSetOperators");
  check(KSPSetOptionsPrefix(h_->ksp, kPrefix), "KSPSetOptionsPrefix");
  check(KSPSetFromOptions(h_->ksp), "KSPSetFromOptions");
  check(KSPSetUp(h_->ksp), "KSPSetUp");
  PC pc;
  check(KSPGetPC(h_->ksp, &pc), "KSPGetPC");
  PCFailedReason failed;
  check(PCGetFailedReason(pc, &failed), "PCGetFailedReason");
  if (failed != PC_NOERROR)
    throw RunError(std::string("coupling: PETSc could not set up the multiplier solve (") + PCFailedReasons[failed] +
                   "): A is not positive definite for " + description());
  // Vectors without storage of their own: solve() places the caller's arrays in them.
  check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, size_, nullptr, &h_->b), "VecCreateSeqWithArray");
  check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, size_, nullptr, &h_->x), "VecCreateSeqWithArray");
}

PetscSpdSolver::~PetscSpdSolver() {
  if (!continuum::PetscSession::started()) return;  // PETSc already finalised at exit
  VecDestroy(&h_->b);
  VecDestroy(&h_->x);
  KSPDestroy(&h_->ksp);
  MatDestroy(&h_->A);
}

void PetscSpdSolver::solve(const double* rhs, double* x) const {
  check(VecPlaceArray(h_->b, const_cast<double*>(rhs)), "VecPlaceArray");  // read only by KSPSolve
  check(VecPlaceArray(h_->x, x), "VecPlaceArray");
  const PetscErrorCode solved = KSPSolve(h_->ksp, h_->b, h_->x);
  check(VecResetArray(h_->b), "VecResetArray");
  check(VecResetArray(h_->x), "VecResetArray");
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
