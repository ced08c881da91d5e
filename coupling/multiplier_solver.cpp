// SPDX-License-Identifier: GPL-3.0-or-later
#include "coupling/multiplier_solver.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "common/error.hpp"

namespace arlequin::coupling {

MultiplierSolver::MultiplierSolver(const CouplingOperators& ops, const std::vector<double>& inv_mass_d,
                                   const std::vector<double>& inv_mass_c, const std::optional<std::string>& petsc)
    : ops_(&ops) {
  const int np = ops.num_particles(), nn = static_cast<int>(ops.Gc.cols());
  if (static_cast<int>(inv_mass_d.size()) != np || static_cast<int>(inv_mass_c.size()) != 3 * nn)
    throw std::invalid_argument("MultiplierSolver: inverse mass sizes do not match the operators");
  inv_d_.resize(np, 3);
  for (int p = 0; p < np; ++p) inv_d_.row(p).setConstant(inv_mass_d[p]);
  inv_c_ = Eigen::Map<const Matrix3>(inv_mass_c.data(), nn, 3);

  for (int c = 0; c < 3; ++c) {
    int same = -1;
    for (int b = 0; b < c && same < 0; ++b)
      if (inv_c_.col(b) == inv_c_.col(c)) same = factor_of_[b];
    if (same >= 0) {
      factor_of_[c] = same;
      continue;
    }
    const Eigen::VectorXd md = inv_d_.col(c), mc = inv_c_.col(c);
    const SparseMatrix A = ops.Gd * md.asDiagonal() * SparseMatrix(ops.Gd.transpose()) +
                           ops.Gc * mc.asDiagonal() * SparseMatrix(ops.Gc.transpose());
    // Jacobi scaling S A S, S = diag(A)^-1/2: rows of A differ by orders of magnitude (a
    // floored continuum mass on the overlap edge against a full one), and the pivot test below
    // is only meaningful on a unit diagonal.
    // A row whose DEs and nodes are all held (inverse masses 0) is empty: nothing can move to
    // meet it, so its multiplier is 0 (scale 0, unit pivot) rather than a singular A. Empty up
    // to the round-off of the interpolation (measured: diagonals 1e-33 of the largest and less).
    Eigen::VectorXd scale = A.diagonal();
    const double empty_row = 1e-20 * scale.maxCoeff();
    bool ok = scale.minCoeff() >= 0.0 && scale.maxCoeff() > 0.0;
    if (ok) scale = scale.unaryExpr([empty_row](double d) { return d > empty_row ? 1.0 / std::sqrt(d) : 0.0; });
    Eigen::SparseMatrix<double> Acol = scale.asDiagonal() * A * scale.asDiagonal();  // column-major for the factor
    for (Eigen::Index r = 0; r < scale.size(); ++r)
      if (scale[r] == 0.0) Acol.coeffRef(r, r) = 1.0;
    nonzeros_ = Acol.nonZeros();
    auto f = std::make_unique<Factor>();
    if (ok) f->compute(Acol);
    ok = ok && f->info() == Eigen::Success;
    double dmin = 0.0, dmax = 0.0;
    if (ok) {
      const Eigen::VectorXd D = f->vectorD();
      dmax = D.cwiseAbs().maxCoeff();
      dmin = D.minCoeff();
      ok = dmin > 1e-13 * dmax;
    }
    if (!ok) {
      std::ostringstream msg;
      msg << "coupling: the multiplier matrix A (" << ops.rows() << " rows, component " << "xyz"[c] << ", LDL^T pivots of the Jacobi-scaled A "
          << dmin << " to " << dmax << ") is not positive definite; with the coarse mediator every continuum element "
          << "of the overlap needs enough DEs to fix its nodes (use a larger overlap, a finer DEM, or mediator: fine)";
      throw RunError(msg.str());
    }
    factor_of_[c] = static_cast<int>(scales_.size());
    scales_.push_back(scale);
    if (petsc) {
      petsc_.push_back(std::make_unique<PetscSpdSolver>(Acol, *petsc));
      continue;
    }
    diagonals_.push_back(f->vectorD());
    factors_.push_back(std::move(f));
  }
}

// The factor's solve spelled out, S P^T L D L^T P S lambda = rhs with the Jacobi scaling S:
// Eigen's own applies the inverse permutation in place, which allocates a mask each call.
void MultiplierSolver::solve(const Matrix3& rhs, Matrix3& lambda) const {
  lambda.resize(rhs.rows(), 3);
  for (int c = 0; c < 3; ++c) {
    const int k = factor_of_[c];
    column_ = rhs.col(c).cwiseProduct(scales_[k]);
    if (!petsc_.empty()) {
      // Each solve starts from zero, whatever -ksp_initial_guess_nonzero says: a guess carried over
      // from another component or step would make the multipliers depend on the run's history,
      // which a restart (docs/restart.md) could not reproduce.
      solution_.setZero(column_.size());
      petsc_[k]->solve(column_.data(), solution_.data());
      lambda.col(c) = solution_.cwiseProduct(scales_[k]);
      continue;
    }
    const Factor& f = *factors_[k];
    solution_ = f.permutationP() * column_;
    f.matrixL().solveInPlace(solution_);
    solution_.array() /= diagonals_[k].array();
    f.matrixU().solveInPlace(solution_);
    column_ = f.permutationPinv() * solution_;
    lambda.col(c) = column_.cwiseProduct(scales_[k]);
  }
}

std::string MultiplierSolver::backend() const { return petsc_.empty() ? "LDL^T" : "PETSc " + petsc_.front()->description(); }

void MultiplierSolver::residual(const Matrix3& vd, const Eigen::Ref<const Matrix3>& vc, Matrix3& out) const {
  out.noalias() = ops_->Gd * vd;
  out.noalias() += ops_->Gc * vc;
}

void MultiplierSolver::project(Matrix3& vd, Eigen::Ref<Matrix3> vc, Matrix3& dd, Matrix3& dc, Matrix3& lambda) const {
  residual(vd, vc, rhs_);
  solve(rhs_, lambda);
  dd.noalias() = ops_->Gd.transpose() * lambda;
  dd.array() *= inv_d_.array();
  dc.noalias() = ops_->Gc.transpose() * lambda;
  dc.array() *= inv_c_.array();
  vd -= dd;
  vc -= dc;
}

}  // namespace arlequin::coupling
