#include "coupling/multiplier_solver.hpp"

#include <string>

#include "common/error.hpp"

namespace arlequin::coupling {

MultiplierSolver::MultiplierSolver(const CouplingOperators& ops, const std::vector<double>& inv_mass_d,
                                   const std::vector<double>& inv_mass_c)
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
    Eigen::SparseMatrix<double> Acol = A;  // column-major for the Cholesky factor
    nonzeros_ = Acol.nonZeros();
    auto f = std::make_unique<Factor>();
    f->compute(Acol);
    bool ok = f->info() == Eigen::Success;
    if (ok) {
      const Eigen::VectorXd D = f->vectorD();
      const double dmax = D.cwiseAbs().maxCoeff();
      ok = D.minCoeff() > 1e-13 * dmax;
    }
    if (!ok)
      throw RunError("coupling: the multiplier matrix A (" + std::to_string(ops.rows()) +
                     " rows) is not positive definite; with the coarse mediator every continuum element "
                     "of the overlap needs enough DEs to fix its nodes (use a larger overlap, a finer DEM, "
                     "or mediator: fine)");
    factor_of_[c] = static_cast<int>(factors_.size());
    factors_.push_back(std::move(f));
  }
}

Matrix3 MultiplierSolver::solve(const Matrix3& rhs) const {
  Matrix3 lambda(rhs.rows(), 3);
  for (int c = 0; c < 3; ++c) lambda.col(c) = factors_[factor_of_[c]]->solve(Eigen::VectorXd(rhs.col(c)));
  return lambda;
}

Matrix3 MultiplierSolver::residual(const Matrix3& vd, const Eigen::Ref<const Matrix3>& vc) const {
  return ops_->Gd * vd + ops_->Gc * vc;
}

Matrix3 MultiplierSolver::project(Matrix3& vd, Eigen::Ref<Matrix3> vc, Matrix3& dd, Matrix3& dc) const {
  const Matrix3 lambda = solve(residual(vd, vc));
  dd = inv_d_.cwiseProduct(Matrix3(ops_->Gd.transpose() * lambda));
  dc = inv_c_.cwiseProduct(Matrix3(ops_->Gc.transpose() * lambda));
  vd -= dd;
  vc -= dc;
  return lambda;
}

}  // namespace arlequin::coupling
