// SPDX-License-Identifier: GPL-3.0-or-later
#include "coupling/multiplier_solver.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "common/error.hpp"
#include "common/parallel.hpp"

namespace arlequin::coupling {

namespace {

// X = A^-1 X for a factor of A = P^T L D L^T P and X of `width` columns, row-major (the
// components that share A solved together: L is read once for all of them); scratch of X's
// size. The triangular solves spelled out over L's columns (Eigen's solve takes one column at a
// time, and applies the inverse permutation in place, which allocates a mask each call).
template <int width>
void solve_with_factor(const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& f, const Eigen::VectorXd& D, double* x,
                       std::vector<double>& scratch) {
  const auto& L = f.matrixL().nestedExpression();  // strictly lower part used: L's diagonal is 1
  const Eigen::Index n = L.cols();
  const int* perm = f.permutationP().indices().data();
  const int* outer = L.outerIndexPtr();
  const int* inner = L.innerIndexPtr();
  const double* value = L.valuePtr();
  scratch.resize(static_cast<std::size_t>(n * width));
  double* y = scratch.data();
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < width; ++c) y[perm[i] * width + c] = x[i * width + c];
  for (Eigen::Index j = 0; j < n; ++j)  // L y' = y
    for (int p = outer[j]; p < outer[j + 1]; ++p)
      if (inner[p] > j)
        for (int c = 0; c < width; ++c) y[inner[p] * width + c] -= value[p] * y[j * width + c];
  for (Eigen::Index j = 0; j < n; ++j)
    for (int c = 0; c < width; ++c) y[j * width + c] /= D[j];
  for (Eigen::Index j = n - 1; j >= 0; --j)  // L^T y'' = y'
    for (int p = outer[j]; p < outer[j + 1]; ++p)
      if (inner[p] > j)
        for (int c = 0; c < width; ++c) y[j * width + c] -= value[p] * y[inner[p] * width + c];
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < width; ++c) x[i * width + c] = y[perm[i] * width + c];
}

// out = A x for a row-major A and x of `width` columns whose rows lie `stride` apart (a Matrix3,
// or a vector for width 1); out += A x with `add`. Each row's sum in the order of its entries,
// rows split over the threads when A has enough entries: the same bits on any thread count.
template <int width>
void multiply(const Eigen::SparseMatrix<double, Eigen::RowMajor>& A, const double* x, Eigen::Index stride, double* out,
              bool add = false) {
  for_each_index(A.rows(), A.nonZeros() > parallel_threshold, [&](long r) {
    double sum[width];
    for (int c = 0; c < width; ++c) sum[c] = add ? out[r * width + c] : 0.0;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(A, r); it; ++it)
      for (int c = 0; c < width; ++c) sum[c] += it.value() * x[it.col() * stride + c];
    for (int c = 0; c < width; ++c) out[r * width + c] = sum[c];
  });
}

bool is_diagonal(const SparseMatrix& G) {
  if (G.rows() != G.cols()) return false;
  for (int r = 0; r < G.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(G, r); it; ++it)
      if (it.col() != r) return false;
  return true;
}

}  // namespace

std::unique_ptr<MultiplierSolver::LowRank> MultiplierSolver::low_rank_form(const Eigen::VectorXd& md, const Eigen::VectorXd& mc,
                                                                            int component) const {
  const CouplingOperators& ops = *ops_;
  if (!ops.settings.fine_l2() || !is_diagonal(ops.Gd)) return nullptr;
  const int rows = ops.rows();
  auto a = std::make_unique<LowRank>();
  a->inv_D.resize(rows);
  const Eigen::VectorXd g = ops.Gd.diagonal();
  for (int r = 0; r < rows; ++r) {
    const double d = g[r] * g[r] * md[r];
    if (!(d > 0.0)) return nullptr;  // a driven DE: D is singular
    a->inv_D[r] = 1.0 / d;
  }
  // The continuum dofs G_c reaches that can move, renumbered 0..k-1.
  std::vector<int> reduced(static_cast<std::size_t>(ops.Gc.cols()), -1);
  int k = 0;
  std::vector<Eigen::Triplet<double>> t;
  std::vector<double> masses;
  for (int r = 0; r < rows; ++r) {
    if (!is_tied(r, component)) continue;  // a free row's U row is empty: its multiplier stays 0
    for (SparseMatrix::InnerIterator it(ops.Gc, r); it; ++it) {
      const auto j = static_cast<std::size_t>(it.col());
      if (mc[it.col()] == 0.0) continue;
      if (reduced[j] < 0) {
        reduced[j] = k++;
        masses.push_back(1.0 / mc[it.col()]);
      }
      t.emplace_back(r, reduced[j], it.value());
    }
  }
  a->U.resize(rows, k);
  a->U.setFromTriplets(t.begin(), t.end());
  a->Ut = RowMajorMatrix(a->U.transpose());
  Eigen::SparseMatrix<double> K = Eigen::SparseMatrix<double>(a->Ut) * a->inv_D.asDiagonal() * a->U;
  for (int j = 0; j < k; ++j) K.coeffRef(j, j) += masses[static_cast<std::size_t>(j)];
  a->K = std::make_unique<Factor>();
  a->K->compute(K);
  if (a->K->info() != Eigen::Success || !(a->K->vectorD().minCoeff() > 0.0)) return nullptr;
  a->K_diagonal = a->K->vectorD();
  // The set-up check: A y = r to 1e-10 for y solved from a fixed r (A applied matrix-free).
  Eigen::VectorXd r(rows), y(rows);
  for (int i = 0; i < rows; ++i) r[i] = 1.0 + 0.5 * std::sin(1.0 + i);
  y = r;
  solve_low_rank<1>(*a, y.data());
  Eigen::VectorXd Ay = y.cwiseQuotient(a->inv_D);
  const Eigen::VectorXd Uty = a->Ut * y;
  Eigen::VectorXd CUty(k);
  for (int j = 0; j < k; ++j) CUty[j] = Uty[j] / masses[static_cast<std::size_t>(j)];
  Ay += a->U * CUty;
  if (!((Ay - r).norm() <= 1e-10 * r.norm())) return nullptr;
  return a;
}

template <int width>
void MultiplierSolver::solve_low_rank(const LowRank& a, double* x) const {
  const Eigen::Index rows = a.U.rows();
  for (Eigen::Index r = 0; r < rows; ++r)  // y = D^-1 r
    for (int c = 0; c < width; ++c) x[r * width + c] *= a.inv_D[r];
  reduced_.resize(static_cast<std::size_t>(a.U.cols() * width));
  multiply<width>(a.Ut, x, width, reduced_.data());  // U^T y
  solve_with_factor<width>(*a.K, a.K_diagonal, reduced_.data(), reduced_scratch_);
  solution_.resize(static_cast<std::size_t>(rows * width));
  multiply<width>(a.U, reduced_.data(), width, solution_.data());  // U K^-1 U^T y
  for (Eigen::Index r = 0; r < rows; ++r)
    for (int c = 0; c < width; ++c) x[r * width + c] -= a.inv_D[r] * solution_[static_cast<std::size_t>(r * width + c)];
}

int MultiplierSolver::system_of_earlier_component(int c) const {
  const auto& tied = ops_->tied;
  for (int b = 0; b < c; ++b)
    if (inv_c_.col(b) == inv_c_.col(c) && (tied.size() == 0 || tied.col(b) == tied.col(c))) return factor_of_[b];
  return -1;
}

MultiplierSolver::MultiplierSolver(const CouplingOperators& ops, const std::vector<double>& inv_mass_d,
                                   const std::vector<double>& inv_mass_c, const std::optional<std::string>& petsc)
    : ops_(&ops), GdT_(ops.Gd.transpose()), GcT_(ops.Gc.transpose()) {
  const int np = ops.num_particles(), nn = static_cast<int>(ops.Gc.cols());
  if (static_cast<int>(inv_mass_d.size()) != np || static_cast<int>(inv_mass_c.size()) != 3 * nn)
    throw std::invalid_argument("MultiplierSolver: inverse mass sizes do not match the operators");
  inv_d_.resize(np, 3);
  for (int p = 0; p < np; ++p) inv_d_.row(p).setConstant(inv_mass_d[p]);
  inv_c_ = Eigen::Map<const Matrix3>(inv_mass_c.data(), nn, 3);

  // The low-rank form when every distinct component has it; else the general factor.
  if (!petsc) {
    for (int c = 0; c < 3; ++c) {
      if (const int same = system_of_earlier_component(c); same >= 0) {
        factor_of_[c] = same;
        continue;
      }
      auto a = low_rank_form(inv_d_.col(c), inv_c_.col(c), c);
      if (!a) {
        low_rank_.clear();
        break;
      }
      factor_of_[c] = static_cast<int>(low_rank_.size());
      nonzeros_ = a->U.nonZeros();
      low_rank_.push_back(std::move(a));
    }
    if (!low_rank_.empty()) return;
  }
  for (int c = 0; c < 3; ++c) {
    if (const int same = system_of_earlier_component(c); same >= 0) {
      factor_of_[c] = same;
      continue;
    }
    const Eigen::VectorXd md = inv_d_.col(c), mc = inv_c_.col(c);
    Eigen::VectorXd tie = Eigen::VectorXd::Ones(ops.rows());  // free rows empty: their multipliers 0 (below)
    for (int r = 0; r < ops.rows(); ++r) tie[r] = is_tied(r, c) ? 1.0 : 0.0;
    const SparseMatrix A = tie.asDiagonal() *
                           SparseMatrix(ops.Gd * md.asDiagonal() * SparseMatrix(ops.Gd.transpose()) +
                                        ops.Gc * mc.asDiagonal() * SparseMatrix(ops.Gc.transpose())) *
                           tie.asDiagonal();
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

// Per system, the components it serves solved together (columns of one row-major block): the
// low-rank form, PETSc's KSP (a column at a time), or our factor of the Jacobi-scaled A,
// S P^T L D L^T P S lambda = rhs.
void MultiplierSolver::solve(const Matrix3& rhs, Matrix3& lambda) const {
  lambda.resize(rhs.rows(), 3);
  const Eigen::Index rows = rhs.rows();
  for (int k = 0; k < systems(); ++k) {
    std::array<int, 3> served{};
    int width = 0;
    for (int c = 0; c < 3; ++c)
      if (factor_of_[c] == k) served[static_cast<std::size_t>(width++)] = c;
    if (!petsc_.empty()) {
      // Each solve starts from zero, whatever -ksp_initial_guess_nonzero says: a guess carried over
      // from another component or step would make the multipliers depend on the run's history,
      // which a restart (docs/restart.md) could not reproduce.
      for (int s = 0; s < width; ++s) {
        const int c = served[static_cast<std::size_t>(s)];
        column_ = rhs.col(c).cwiseProduct(scales_[k]);
        solution_.assign(static_cast<std::size_t>(rows), 0.0);
        petsc_[k]->solve(column_.data(), solution_.data());
        lambda.col(c) = Eigen::Map<const Eigen::VectorXd>(solution_.data(), rows).cwiseProduct(scales_[k]);
      }
      continue;
    }
    block_.resize(static_cast<std::size_t>(rows * width));
    const double* scale = low_rank_.empty() ? scales_[k].data() : nullptr;
    for (Eigen::Index r = 0; r < rows; ++r)
      for (int s = 0; s < width; ++s)
        block_[static_cast<std::size_t>(r * width + s)] = rhs(r, served[static_cast<std::size_t>(s)]) * (scale ? scale[r] : 1.0);
    const auto solve_block = [&]<int w>() {
      if (low_rank_.empty()) solve_with_factor<w>(*factors_[k], diagonals_[k], block_.data(), block_scratch_);
      else solve_low_rank<w>(*low_rank_[k], block_.data());
    };
    if (width == 3) solve_block.template operator()<3>();
    else if (width == 2) solve_block.template operator()<2>();
    else solve_block.template operator()<1>();
    for (Eigen::Index r = 0; r < rows; ++r)
      for (int s = 0; s < width; ++s)
        lambda(r, served[static_cast<std::size_t>(s)]) = block_[static_cast<std::size_t>(r * width + s)] * (scale ? scale[r] : 1.0);
  }
}

std::string MultiplierSolver::backend() const {
  if (!low_rank_.empty())
    return "diagonal + low rank (Woodbury), LDL^T of " + std::to_string(low_rank_.front()->U.cols()) + " continuum dofs (" +
           std::to_string(low_rank_.front()->K->matrixL().nestedExpression().nonZeros()) + " non-zeros in its factor)";
  return petsc_.empty() ? "LDL^T" : "PETSc " + petsc_.front()->description();
}

void MultiplierSolver::residual(const Matrix3& vd, const Eigen::Ref<const Matrix3>& vc, Matrix3& out) const {
  out.resize(ops_->rows(), 3);
  multiply<3>(ops_->Gd, vd.data(), 3, out.data());
  multiply<3>(ops_->Gc, vc.data(), vc.outerStride(), out.data(), true);
  if (ops_->tied.size()) out.array() *= ops_->tied.array();
}

void MultiplierSolver::project(Matrix3& vd, Eigen::Ref<Matrix3> vc, Matrix3& dd, Matrix3& dc, Matrix3& lambda) const {
  residual(vd, vc, rhs_);
  solve(rhs_, lambda);
  dd.resize(GdT_.rows(), 3);
  multiply<3>(GdT_, lambda.data(), 3, dd.data());
  dd.array() *= inv_d_.array();
  dc.resize(GcT_.rows(), 3);
  multiply<3>(GcT_, lambda.data(), 3, dc.data());
  dc.array() *= inv_c_.array();
  vd -= dd;
  vc -= dc;
}

}  // namespace arlequin::coupling
