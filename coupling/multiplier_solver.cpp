// SPDX-License-Identifier: GPL-3.0-or-later
#include "coupling/multiplier_solver.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>

#include "common/error.hpp"
#include "common/parallel.hpp"

namespace arlequin::coupling {

namespace {

// A row of the solve's scratch: a vector of 2 or 4 doubles, at a double's alignment (the
// vector's own may exceed the allocation's). Spelled per size: GCC drops a vector_size that
// depends on a template parameter.
template <int size>
struct SolveRow;
template <>
struct SolveRow<2> {
  typedef double type __attribute__((vector_size(2 * sizeof(double)), aligned(alignof(double)), may_alias));
};
template <>
struct SolveRow<4> {
  typedef double type __attribute__((vector_size(4 * sizeof(double)), aligned(alignof(double)), may_alias));
};

// X = A^-1 X for a factor of A = P^T L D L^T P and X of `width` columns, row-major (the
// components that share A solved together: L is read once for all of them), in three parts:
// load_permuted puts X into the scratch y = P X, solve_columns runs the triangular solves over
// one task's columns (MultiplierSolver::ForestFactor: trees of the elimination forest, which
// read and write only their own rows of y; within a tree, supernodes of columns that share
// their rows), store_permuted puts y back, X = P^T y. The solves
// are spelled out over L's columns (Eigen's solve takes one column at a time, and applies the
// inverse permutation in place, which allocates a mask each call). A row of the scratch is one
// small vector (width 3 padded to 4, 1 to 2), so an entry of L costs one vector multiply-add for
// all the components, each component's arithmetic that of a loop over them. A row's updates come
// from the same columns in the same order whichever tasks run and on which thread: the bits of
// one serial pass over all the columns.
template <int width>
using RowOf = typename SolveRow<std::max(2, static_cast<int>(std::bit_ceil(static_cast<unsigned>(width))))>::type;

template <int width>
void load_permuted(const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& f, const double* x, std::vector<double>& scratch) {
  using Row = RowOf<width>;
  const Eigen::Index n = f.matrixL().nestedExpression().cols();
  const int* perm = f.permutationP().indices().data();
  scratch.resize(static_cast<std::size_t>(n) * sizeof(Row) / sizeof(double));
  Row* y = reinterpret_cast<Row*>(scratch.data());
  for_each_index(n, n > parallel_threshold_rows, [&](long i) {
    Row row{};
    for (int c = 0; c < width; ++c) row[c] = x[i * width + c];
    y[perm[i]] = row;
  });
}

// One supernode's part of the forward solve L y' = y: its K columns j0 .. j0 + K - 1 hold, below
// their triangle, the same rows (MultiplierSolver::ForestFactor). The triangle first, column by
// column; then each shared row's K updates at once, its row of y read and written once, not K
// times. Each row takes its updates from the columns in increasing order, as a column-by-column
// pass gives them: the same bits.
template <int K, int width>
void forward_supernode(const int* outer, const int* inner, const double* value, int j0, double* scratch) {
  using Row = RowOf<width>;  // named here: as a template argument the type would lose its alignment
  Row* y = reinterpret_cast<Row*>(scratch);
  for (int c = 0; c < K; ++c) {  // the triangle: column j0 + c's first K - 1 - c rows are j0 + c + 1 ...
    const Row yc = y[j0 + c];
    for (int p = outer[j0 + c]; p < outer[j0 + c] + (K - 1 - c); ++p) y[inner[p]] -= value[p] * yc;
  }
  Row yk[K];
  const double* column[K];  // column j0 + c from its entry in the first shared row
  for (int c = 0; c < K; ++c) {
    yk[c] = y[j0 + c];
    column[c] = value + outer[j0 + c] + (K - 1 - c);
  }
  const int* rows = inner + outer[j0 + K - 1];
  const int shared = outer[j0 + K] - outer[j0 + K - 1];
  for (int q = 0; q < shared; ++q) {
    Row acc = y[rows[q]];
    for (int c = 0; c < K; ++c) acc -= column[c][q] * yk[c];
    y[rows[q]] = acc;
  }
}

// One supernode's part of the backward solve L^T y'' = y' (columns in decreasing order, each a dot
// product over its rows): the shared rows' sums of all K columns at once, each row of y read once;
// then each column's triangle, from the last column down (its rows' y final by then), and y[j] -=
// shared sum + triangle sum. The sums are split into partial sums (one sum would wait on each add
// in turn: the solve's critical path): four for a single column, two a column below four columns.
template <int K, int width>
void backward_supernode(const int* outer, const int* inner, const double* value, int j0, double* scratch) {
  using Row = RowOf<width>;
  Row* y = reinterpret_cast<Row*>(scratch);
  constexpr int sums = K == 1 ? 4 : K < 4 ? 2 : 1;
  const int* rows = inner + outer[j0 + K - 1];
  const int shared = outer[j0 + K] - outer[j0 + K - 1];
  const double* column[K];  // column j0 + c from its entry in the first shared row
  for (int c = 0; c < K; ++c) column[c] = value + outer[j0 + c] + (K - 1 - c);
  Row sum[sums][K] = {};
  int q = 0;
  for (; q + sums <= shared; q += sums)
    for (int u = 0; u < sums; ++u) {
      const Row yq = y[rows[q + u]];
      for (int c = 0; c < K; ++c) sum[u][c] += column[c][q + u] * yq;
    }
  for (; q < shared; ++q)
    for (int c = 0; c < K; ++c) sum[0][c] += column[c][q] * y[rows[q]];
  for (int c = K - 1; c >= 0; --c) {
    Row total = sums == 4 ? (sum[0][c] + sum[1][c]) + (sum[2][c] + sum[3][c]) : sums == 2 ? sum[0][c] + sum[1][c] : sum[0][c];
    for (int p = outer[j0 + c]; p < outer[j0 + c] + (K - 1 - c); ++p) total += value[p] * y[inner[p]];
    y[j0 + c] -= total;
  }
}

// The most columns a supernode takes (a longer run of nested columns is cut into supernodes of
// this size): the kernels above keep a row of y for each column in registers.
constexpr int max_supernode = 8;

// f(std::integral_constant<int, k>{}) for a supernode of k = 1 ... max_supernode columns.
template <class F>
void with_supernode_size(int k, F&& f) {
  static_assert(max_supernode == 8);
  switch (k) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 5: return f(std::integral_constant<int, 5>{});
    case 6: return f(std::integral_constant<int, 6>{});
    case 7: return f(std::integral_constant<int, 7>{});
    default: return f(std::integral_constant<int, 8>{});
  }
}

// The triangular solves over one task's supernodes [first, last) (positions in `columns` at
// supernode_start[s]), L y' = y, y' /= D, L^T y'' = y'. A row's updates come from the same
// columns in the same order whichever tasks run and on which thread: the bits of one serial pass.
template <int width>
void solve_columns(const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& f, const Eigen::VectorXd& D, const int* columns,
                   const int* supernode_start, int first, int last, std::vector<double>& scratch) {
  using Row = RowOf<width>;
  // L by columns, each holding only its rows below the diagonal (an LDL^T stores no unit diagonal)
  const auto& L = f.matrixL().nestedExpression();
  const int* outer = L.outerIndexPtr();
  const int* inner = L.innerIndexPtr();
  const double* value = L.valuePtr();
  Row* y = reinterpret_cast<Row*>(scratch.data());
  for (int s = first; s < last; ++s) {
    const int j0 = columns[supernode_start[s]];
    with_supernode_size(supernode_start[s + 1] - supernode_start[s], [&](auto size) {
      forward_supernode<decltype(size)::value, width>(outer, inner, value, j0, scratch.data());
    });
  }
  for (int q = supernode_start[first]; q < supernode_start[last]; ++q) y[columns[q]] /= D[columns[q]];
  for (int s = last - 1; s >= first; --s) {
    const int j0 = columns[supernode_start[s]];
    with_supernode_size(supernode_start[s + 1] - supernode_start[s], [&](auto size) {
      backward_supernode<decltype(size)::value, width>(outer, inner, value, j0, scratch.data());
    });
  }
}

template <int width>
void store_permuted(const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& f, const std::vector<double>& scratch, double* x) {
  using Row = RowOf<width>;
  const Eigen::Index n = f.matrixL().nestedExpression().cols();
  const int* perm = f.permutationP().indices().data();
  const Row* y = reinterpret_cast<const Row*>(scratch.data());
  for_each_index(n, n > parallel_threshold_rows, [&](long i) {
    for (int c = 0; c < width; ++c) x[i * width + c] = y[perm[i]][c];
  });
}

// f(std::integral_constant<int, w>) for w = width, 1, 2 or 3: the templates above from a run-time width.
template <class F>
void with_width(int width, F&& f) {
  if (width == 3) f(std::integral_constant<int, 3>{});
  else if (width == 2) f(std::integral_constant<int, 2>{});
  else f(std::integral_constant<int, 1>{});
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

std::unique_ptr<MultiplierSolver::LowRank> MultiplierSolver::low_rank_form() const {
  const CouplingOperators& ops = *ops_;
  if (!ops.settings.fine_l2() || !is_diagonal(ops.Gd)) return nullptr;
  const int rows = ops.rows();
  auto a = std::make_unique<LowRank>();
  a->inv_D.resize(rows);
  a->tied.resize(rows, 3);
  a->g = ops.Gd.diagonal();
  const Eigen::VectorXd& g = a->g;
  a->inv_g.setZero(rows);
  a->mass_over_g.setZero(rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 3; ++c) a->tied(r, c) = is_tied(r, c) ? 1.0 : 0.0;
    const double d = g[r] * g[r] * inv_d_(r, 0);  // a DE's inverse mass is the same in x, y and z
    if (a->tied.row(r).any()) {
      if (!(d > 0.0)) return nullptr;  // a driven DE, tied: D is singular
      a->inv_D[r] = 1.0 / d;
      a->inv_g[r] = 1.0 / g[r];
      a->mass_over_g[r] = 1.0 / (g[r] * inv_d_(r, 0));
    } else {
      a->inv_D[r] = 1.0;  // no multiplier in any component: the pivot only keeps D invertible
    }
  }
  // U's columns: the continuum nodes G_c reaches from a row tied in a component the node can move in.
  std::vector<int> column(static_cast<std::size_t>(ops.Gc.cols()), -1);
  int k = 0;
  for (int r = 0; r < rows; ++r)
    for (SparseMatrix::InnerIterator it(ops.Gc, r); it; ++it)
      for (int c = 0; c < 3; ++c)
        if (is_tied(r, c) && inv_c_(it.col(), c) != 0.0 && column[static_cast<std::size_t>(it.col())] < 0) {
          column[static_cast<std::size_t>(it.col())] = k++;
          a->node.push_back(it.col());
        }
  a->movable.resize(k, 3);
  a->mass.resize(k, 3);
  for (int j = 0; j < k; ++j)
    for (int c = 0; c < 3; ++c) {
      const double inv = inv_c_(a->node[static_cast<std::size_t>(j)], c);
      a->movable(j, c) = inv != 0.0 ? 1.0 : 0.0;
      a->mass(j, c) = inv != 0.0 ? 1.0 / inv : 0.0;
    }
  std::vector<Eigen::Triplet<double>> held;
  for (int r = 0; r < rows; ++r)
    for (SparseMatrix::InnerIterator it(ops.Gc, r); it; ++it)
      if ((inv_c_.row(it.col()).array() == 0.0).any()) held.emplace_back(r, static_cast<int>(it.col()), it.value());
  a->held.resize(rows, ops.Gc.cols());
  a->held.setFromTriplets(held.begin(), held.end());
  a->heldT = RowMajorMatrix(a->held.transpose());
  std::vector<Eigen::Triplet<double>> t;
  for (int r = 0; r < rows; ++r)
    for (SparseMatrix::InnerIterator it(ops.Gc, r); it; ++it)
      if (const int j = column[static_cast<std::size_t>(it.col())]; j >= 0) t.emplace_back(r, j, it.value());
  a->U.resize(rows, k);
  a->U.setFromTriplets(t.begin(), t.end());
  a->Ut = RowMajorMatrix(a->U.transpose());
  // Each system's K over all of U's columns: U_c = T_c U H_c (its tied rows, its movable
  // columns); a column the component holds gets a unit pivot and, its right-hand side masked
  // to 0, a zero solution.
  for (int c = 0; c < 3; ++c) {
    if (factor_of_[c] < static_cast<int>(a->K.size())) continue;  // served by an earlier component's
    std::vector<Eigen::Triplet<double>> tc;
    for (const auto& e : t)
      if (a->tied(e.row(), c) != 0.0 && a->movable(e.col(), c) != 0.0) tc.push_back(e);
    RowMajorMatrix Uc(rows, k);
    Uc.setFromTriplets(tc.begin(), tc.end());
    Eigen::SparseMatrix<double> K = Eigen::SparseMatrix<double>(Uc.transpose()) * a->inv_D.asDiagonal() * Uc;
    for (int j = 0; j < k; ++j)
      K.coeffRef(j, j) += a->movable(j, c) != 0.0 ? 1.0 / inv_c_(a->node[static_cast<std::size_t>(j)], c) : 1.0;
    auto f = std::make_unique<Factor>();
    f->compute(K);
    if (f->info() != Eigen::Success || !(f->vectorD().minCoeff() > 0.0)) return nullptr;
    a->K.push_back(forest_of(std::move(f)));
  }
  // The set-up check: A y = r to 1e-10 for y solved from a fixed r (A applied matrix-free,
  // D y + T U H C H U^T y per component).
  Matrix3 r(rows, 3), y;
  for (int i = 0; i < rows; ++i)
    for (int c = 0; c < 3; ++c) r(i, c) = a->tied(i, c) * (1.0 + 0.5 * std::sin(1.0 + i + 7.0 * c));
  solve_low_rank(*a, r, y);
  Matrix3 q = a->Ut * y, Ay(rows, 3);
  for (int j = 0; j < k; ++j)
    for (int c = 0; c < 3; ++c) q(j, c) = a->movable(j, c) != 0.0 ? q(j, c) * inv_c_(a->node[static_cast<std::size_t>(j)], c) : 0.0;
  Ay = a->U * q;
  for (int i = 0; i < rows; ++i)
    for (int c = 0; c < 3; ++c) Ay(i, c) = y(i, c) / a->inv_D[i] + a->tied(i, c) * Ay(i, c);
  if (!((Ay - r).norm() <= 1e-10 * r.norm())) return nullptr;
  return a;
}

// The components each system serves, in order (served[0..width)), and their count.
std::pair<std::array<int, 3>, int> MultiplierSolver::served_by(int k) const {
  std::array<int, 3> served{};
  int width = 0;
  for (int c = 0; c < 3; ++c)
    if (factor_of_[c] == k) served[static_cast<std::size_t>(width++)] = c;
  return {served, width};
}

void MultiplierSolver::solve_low_rank(const LowRank& a, const Matrix3& rhs, Matrix3& lambda) const {
  const Eigen::Index rows = rhs.rows(), k = a.U.cols();
  y_.resize(rows, 3);
  for_each_index(rows, rows > parallel_threshold_rows, [&](long r) {  // y = D^-1 rhs, 0 in the free components
    for (int c = 0; c < 3; ++c) y_(r, c) = a.tied(r, c) * (a.inv_D[r] * rhs(r, c));
  });
  w_.resize(k, 3);
  multiply<3>(a.Ut, y_.data(), 3, w_.data());  // U^T y, then w = K^-1 U^T y, every system at once
  w_.array() *= a.movable.array();
  solve_systems(a.K, w_, w_, nullptr);
  lambda.resize(rows, 3);
  multiply<3>(a.U, w_.data(), 3, lambda.data());  // U w
  for_each_index(rows, rows > parallel_threshold_rows, [&](long r) {  // lambda = y - D^-1 U w
    for (int c = 0; c < 3; ++c) lambda(r, c) = a.tied(r, c) * (y_(r, c) - a.inv_D[r] * lambda(r, c));
  });
}

// A depends on the continuum's inverse masses only at the nodes G_c reaches: a node held in one
// component far from the overlap (a load strip) leaves the components' systems the same.
int MultiplierSolver::system_of_earlier_component(int c) const {
  const auto& tied = ops_->tied;
  const auto same_reached_masses = [&](int b) {
    for (int r = 0; r < ops_->Gc.outerSize(); ++r)
      for (SparseMatrix::InnerIterator it(ops_->Gc, r); it; ++it)
        if (inv_c_(it.col(), b) != inv_c_(it.col(), c)) return false;
    return true;
  };
  for (int b = 0; b < c; ++b)
    if ((tied.size() == 0 || tied.col(b) == tied.col(c)) && same_reached_masses(b)) return factor_of_[b];
  return -1;
}

MultiplierSolver::MultiplierSolver(const CouplingOperators& ops, const std::vector<double>& inv_mass_d,
                                   const std::vector<double>& inv_mass_c, const std::optional<std::string>& petsc)
    : ops_(&ops), GdT_(ops.Gd.transpose()), GcT_(ops.Gc.transpose()) {
  for (int n = 0; n < GcT_.outerSize(); ++n)
    if (GcT_.outerIndexPtr()[n + 1] > GcT_.outerIndexPtr()[n]) corrected_nodes_.push_back(n);
  const int np = ops.num_particles(), nn = static_cast<int>(ops.Gc.cols());
  if (static_cast<int>(inv_mass_d.size()) != np || static_cast<int>(inv_mass_c.size()) != 3 * nn)
    throw std::invalid_argument("MultiplierSolver: inverse mass sizes do not match the operators");
  inv_d_.resize(np, 3);
  for (int p = 0; p < np; ++p) inv_d_.row(p).setConstant(inv_mass_d[p]);
  inv_c_ = Eigen::Map<const Matrix3>(inv_mass_c.data(), nn, 3);

  // The systems: a component shares an earlier one's when its masses and ties are the same.
  for (int c = 0; c < 3; ++c) {
    const int same = system_of_earlier_component(c);
    factor_of_[c] = same >= 0 ? same : systems_++;
  }
  // The low-rank form when it applies; else the general factor.
  if (!petsc) {
    low_rank_ = low_rank_form();
    if (low_rank_) {
      nonzeros_ = low_rank_->U.nonZeros();
      return;
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (system_of_earlier_component(c) >= 0) continue;
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
    scales_.push_back(scale);
    if (petsc) {
      petsc_.push_back(std::make_unique<PetscSpdSolver>(Acol, *petsc));
      continue;
    }
    factors_.push_back(forest_of(std::move(f)));
  }
}

// Per system, the components it serves solved together (columns of one row-major block): the
// low-rank form, PETSc's KSP (a column at a time), or our factor of the Jacobi-scaled A,
// S P^T L D L^T P S lambda = rhs.
void MultiplierSolver::solve(const Matrix3& rhs, Matrix3& lambda) const {
  if (low_rank_) return solve_low_rank(*low_rank_, rhs, lambda);
  lambda.resize(rhs.rows(), 3);
  const Eigen::Index rows = rhs.rows();
  if (!petsc_.empty()) {
    // Each solve starts from zero, whatever -ksp_initial_guess_nonzero says: a guess carried over
    // from another component or step would make the multipliers depend on the run's history,
    // which a restart (docs/restart.md) could not reproduce.
    for (int k = 0; k < systems_; ++k) {
      const auto [served, width] = served_by(k);
      for (int s = 0; s < width; ++s) {
        const int c = served[static_cast<std::size_t>(s)];
        column_ = rhs.col(c).cwiseProduct(scales_[k]);
        solution_.assign(static_cast<std::size_t>(rows), 0.0);
        petsc_[k]->solve(column_.data(), solution_.data());
        lambda.col(c) = Eigen::Map<const Eigen::VectorXd>(solution_.data(), rows).cwiseProduct(scales_[k]);
      }
    }
    return;
  }
  solve_systems(factors_, rhs, lambda, &scales_);
}

MultiplierSolver::ForestFactor MultiplierSolver::forest_of(std::unique_ptr<Factor> factor) {
  ForestFactor f;
  const auto& L = factor->matrixL().nestedExpression();
  const int n = static_cast<int>(L.cols());
  const int* outer = L.outerIndexPtr();
  const int* inner = L.innerIndexPtr();
  // Each column's tree, from the last column down: a parent's index is larger than its child's.
  std::vector<int> tree(static_cast<std::size_t>(n)), start(1, 0);
  for (int j = n - 1; j >= 0; --j) {
    int parent = n;
    for (int p = outer[j]; p < outer[j + 1]; ++p) parent = std::min(parent, inner[p]);
    if (parent == n) start.push_back(0);  // a root: a new tree
    tree[static_cast<std::size_t>(j)] = parent == n ? static_cast<int>(start.size()) - 2 : tree[static_cast<std::size_t>(parent)];
  }
  // The columns tree by tree, each tree's in increasing order (a counting sort by tree).
  for (int t : tree) ++start[static_cast<std::size_t>(t) + 1];
  for (std::size_t t = 1; t < start.size(); ++t) start[t] += start[t - 1];
  f.columns.resize(static_cast<std::size_t>(n));
  std::vector<int> next(start.begin(), start.end() - 1);
  for (int j = 0; j < n; ++j) f.columns[static_cast<std::size_t>(next[static_cast<std::size_t>(tree[static_cast<std::size_t>(j)])]++)] = j;
  // Supernodes: column b = a + 1 continues a's supernode when a's rows are b and then b's rows (b is
  // a's parent, in a's tree), up to max_supernode columns.
  const auto continues = [&](int a, int b) {
    const int rows = outer[a + 1] - outer[a];
    return b == a + 1 && rows == outer[b + 1] - outer[b] + 1 && inner[outer[a]] == b &&
           std::equal(inner + outer[a] + 1, inner + outer[a + 1], inner + outer[b]);
  };
  for (int q = 0; q < n; ++q) {
    const auto z = static_cast<std::size_t>(q);
    if (q == 0 || !continues(f.columns[z - 1], f.columns[z]) || q - f.supernode_start.back() == max_supernode)
      f.supernode_start.push_back(q);
  }
  f.supernode_start.push_back(n);
  // Whole trees, in order, into tasks of at least task_columns columns (the last may have fewer);
  // a tree starts a supernode, found among the starts by its first column's position.
  const auto supernode_at = [&](int position) {
    return static_cast<int>(std::lower_bound(f.supernode_start.begin(), f.supernode_start.end(), position) -
                            f.supernode_start.begin());
  };
  f.task_start.push_back(0);
  for (std::size_t t = 1; t < start.size(); ++t)
    if (start[t] - f.supernode_start[static_cast<std::size_t>(f.task_start.back())] >= task_columns || t + 1 == start.size())
      f.task_start.push_back(supernode_at(start[t]));
  f.D = factor->vectorD();
  f.factor = std::move(factor);
  return f;
}

void MultiplierSolver::solve_systems(const std::vector<ForestFactor>& factors, const Matrix3& in, Matrix3& out,
                                     const std::vector<Eigen::VectorXd>* scales) const {
  const auto systems = static_cast<int>(factors.size());
  const Eigen::Index rows = in.rows();
  // Each system's components of `in` (scaled) into its block, row-major.
  blocks_.resize(factors.size());
  for (int s = 0; s < systems; ++s) {
    const auto [served, width] = served_by(s);
    std::vector<double>& block = blocks_[static_cast<std::size_t>(s)];
    block.resize(static_cast<std::size_t>(rows * width));
    const double* scale = scales ? (*scales)[static_cast<std::size_t>(s)].data() : nullptr;
    for (Eigen::Index r = 0; r < rows; ++r)
      for (int m = 0; m < width; ++m) {
        const double v = in(r, served[static_cast<std::size_t>(m)]);
        block[static_cast<std::size_t>(r * width + m)] = scale ? v * scale[r] : v;
      }
  }
  block_scratch_.resize(factors.size());
  std::array<long, 4> first_task{};  // system s's tasks are [first_task[s], first_task[s + 1]) of all
  long nonzeros = 0;
  for (int s = 0; s < systems; ++s) {
    const auto z = static_cast<std::size_t>(s);
    const Factor& factor = *factors[z].factor;
    with_width(served_by(s).second, [&](auto width) {
      load_permuted<decltype(width)::value>(factor, blocks_[z].data(), block_scratch_[z]);
    });
    first_task[z + 1] = first_task[z] + static_cast<long>(factors[z].task_start.size()) - 1;
    nonzeros += factor.matrixL().nestedExpression().nonZeros();
  }
  const long tasks = first_task[static_cast<std::size_t>(systems)];
  // The tasks are independent and each does the same arithmetic on any thread: the same bits on
  // any thread count. Sizes differ (a tree of a few columns, one of thousands): dynamic.
  run_threaded_if(tasks > 1 && nonzeros > parallel_threshold, [&] {
#pragma omp for schedule(dynamic, 1)
    for (long i = 0; i < tasks; ++i) {
      std::size_t s = 0;
      while (i >= first_task[s + 1]) ++s;
      const ForestFactor& f = factors[s];
      const auto t = static_cast<std::size_t>(i - first_task[s]);
      with_width(served_by(static_cast<int>(s)).second, [&](auto width) {
        solve_columns<decltype(width)::value>(*f.factor, f.D, f.columns.data(), f.supernode_start.data(), f.task_start[t],
                                              f.task_start[t + 1], block_scratch_[s]);
      });
    }
  });
  // The solutions back, each system's into its components of `out` (scaled).
  out.resize(rows, 3);
  for (int s = 0; s < systems; ++s) {
    const auto z = static_cast<std::size_t>(s);
    const auto [served, width] = served_by(s);
    with_width(width, [&](auto w) { store_permuted<decltype(w)::value>(*factors[z].factor, block_scratch_[z], blocks_[z].data()); });
    const double* scale = scales ? (*scales)[z].data() : nullptr;
    for (Eigen::Index r = 0; r < rows; ++r)
      for (int m = 0; m < width; ++m) {
        const double v = blocks_[z][static_cast<std::size_t>(r * width + m)];
        out(r, served[static_cast<std::size_t>(m)]) = scale ? v * scale[r] : v;
      }
  }
}

std::string MultiplierSolver::backend() const {
  if (low_rank_) {
    long largest = 0;
    std::size_t parts = 0, supernodes = 0;
    int widest = 0;
    for (const auto& K : low_rank_->K) {
      const long nonzeros = K.factor->matrixL().nestedExpression().nonZeros();
      if (nonzeros > largest) {
        largest = nonzeros;
        supernodes = K.supernode_start.size() - 1;
      }
      parts += K.task_start.size() - 1;
      for (std::size_t s = 0; s + 1 < K.supernode_start.size(); ++s)
        widest = std::max(widest, K.supernode_start[s + 1] - K.supernode_start[s]);
    }
    return "diagonal + low rank (Woodbury), LDL^T of " + std::to_string(low_rank_->U.cols()) + " continuum nodes a system (" +
           std::to_string(largest) + " non-zeros in the largest factor, its columns in " + std::to_string(supernodes) +
           " supernodes, the widest of all " + std::to_string(widest) + " columns; the systems' solves in " +
           std::to_string(parts) + " independent parts)";
  }
  return petsc_.empty() ? "LDL^T" : "PETSc " + petsc_.front()->description();
}

void MultiplierSolver::residual(const Matrix3& vd, const Eigen::Ref<const Matrix3>& vc, Matrix3& out) const {
  out.resize(ops_->rows(), 3);
  multiply<3>(ops_->Gd, vd.data(), 3, out.data());
  multiply<3>(ops_->Gc, vc.data(), vc.outerStride(), out.data(), true);
  if (ops_->tied.size()) out.array() *= ops_->tied.array();
}

void MultiplierSolver::project_low_rank(const LowRank& a, Matrix3& vd, Eigen::Ref<Matrix3> vc, Matrix3& dd, Matrix3& dc,
                                        Matrix3& lambda, Impulse* impulse, double rate) const {
  const long rows = ops_->rows(), k = a.U.cols();
  const bool rows_threaded = rows > parallel_threshold_rows;
  // h, the held dofs' share of G_c vc (the other components of their nodes are U's).
  const bool any_held = a.held.nonZeros() > 0;
  if (any_held) {
    held_share_.setZero(rows, 3);
    for_each_index(rows, rows_threaded, [&](long r) {
      for (RowMajorMatrix::InnerIterator it(a.held, r); it; ++it)
        for (int c = 0; c < 3; ++c)
          if (inv_c_(it.col(), c) == 0.0) held_share_(r, c) += it.value() * vc(it.col(), c);
    });
  }
  const auto held_share = [&](long r, int c) { return any_held ? held_share_(r, c) : 0.0; };
  // K v_c' = C^-1 v_c - U^T y on U's columns, y = D^-1 T (W vd + h); 0 where a node is held.
  y_.resize(rows, 3);
  for_each_index(rows, rows_threaded, [&](long r) {
    for (int c = 0; c < 3; ++c) y_(r, c) = a.tied(r, c) * (a.inv_D[r] * (a.g[r] * vd(r, c) + held_share(r, c)));
  });
  w_.resize(k, 3);
  multiply<3>(a.Ut, y_.data(), 3, w_.data());
  for_each_index(k, k > parallel_threshold_rows, [&](long j) {
    const int n = a.node[static_cast<std::size_t>(j)];
    for (int c = 0; c < 3; ++c) w_(j, c) = a.mass(j, c) * vc(n, c) - a.movable(j, c) * w_(j, c);
  });
  solve_systems(a.K, w_, w_, nullptr);
  // The tied components meet their rows, W vd' + U v_c' + h = 0; the others keep their velocity.
  // The same pass scales by the rate and gives the impulse G_d^T lambda = g lambda.
  lambda.resize(rows, 3);
  dd.resize(rows, 3);
  if (impulse) impulse->dem.resize(rows, 3);
  const int* outer = a.U.outerIndexPtr();
  const int* column = a.U.innerIndexPtr();
  const double* value = a.U.valuePtr();
  for_each_index(rows, a.U.nonZeros() > parallel_threshold, [&](long r) {
    double uv[3] = {0.0, 0.0, 0.0};  // row r of U v_c'
    for (int e = outer[r]; e < outer[r + 1]; ++e)
      for (int c = 0; c < 3; ++c) uv[c] += value[e] * w_(column[e], c);
    for (int c = 0; c < 3; ++c) {
      double correction = 0.0, multiplier = 0.0;
      if (a.tied(r, c) != 0.0) {
        const double projected = -(uv[c] + held_share(r, c)) * a.inv_g[r];
        correction = vd(r, c) - projected;
        multiplier = correction * a.mass_over_g[r];
        vd(r, c) = projected;
      }
      dd(r, c) = correction * rate;
      lambda(r, c) = multiplier * rate;
      if (impulse) impulse->dem(r, c) = a.g[r] * multiplier * rate;
    }
  });
  Matrix3* fc = impulse ? &impulse->continuum : nullptr;
  if (fc && fc->rows() != GcT_.rows()) fc->setZero(GcT_.rows(), 3);
  for_each_index(k, k > parallel_threshold_rows, [&](long j) {
    const int n = a.node[static_cast<std::size_t>(j)];
    for (int c = 0; c < 3; ++c)
      if (a.movable(j, c) != 0.0) {
        const double correction = vc(n, c) - w_(j, c);
        vc(n, c) = w_(j, c);
        dc(n, c) = correction * rate;
        if (fc) (*fc)(n, c) = a.mass(j, c) * correction * rate;  // C^-1 dc = G_c^T lambda where the node moves
      } else if (fc) {
        (*fc)(n, c) = 0.0;
      }
  });
  if (!fc || !any_held) return;
  for (int n = 0; n < a.heldT.outerSize(); ++n) {  // and the held components' from their entries
    double sum[3] = {0.0, 0.0, 0.0};
    for (RowMajorMatrix::InnerIterator it(a.heldT, n); it; ++it)
      for (int c = 0; c < 3; ++c) sum[c] += it.value() * lambda(it.col(), c);
    for (int c = 0; c < 3; ++c)
      if (inv_c_(n, c) == 0.0) (*fc)(n, c) = sum[c];
  }
}

void MultiplierSolver::project(Matrix3& vd, Eigen::Ref<Matrix3> vc, Matrix3& dd, Matrix3& dc, Matrix3& lambda,
                               Impulse* impulse, double rate) const {
  if (dc.rows() != GcT_.rows()) dc.setZero(GcT_.rows(), 3);
  if (low_rank_) return project_low_rank(*low_rank_, vd, vc, dd, dc, lambda, impulse, rate);
  residual(vd, vc, rhs_);
  solve(rhs_, lambda);
  const long rows = GdT_.rows(), nodes = static_cast<long>(corrected_nodes_.size());
  dd.resize(rows, 3);
  multiply<3>(GcT_, lambda.data(), 3, dc.data());
  multiply<3>(GdT_, lambda.data(), 3, dd.data());
  if (impulse) {
    impulse->dem = dd;
    if (impulse->continuum.rows() != GcT_.rows()) impulse->continuum.setZero(GcT_.rows(), 3);
    for (int n : corrected_nodes_) impulse->continuum.row(n) = dc.row(n);
  }
  dc.array() *= inv_c_.array();
  for_each_index(rows, rows > parallel_threshold_rows, [&](long r) {
    dd.row(r).array() *= inv_d_.row(r).array();
    vd.row(r) -= dd.row(r);
  });
  for_each_index(nodes, nodes > parallel_threshold_rows, [&](long k) {
    const int n = corrected_nodes_[static_cast<std::size_t>(k)];
    vc.row(n) -= dc.row(n);
  });
  if (rate == 1.0) return;
  dd *= rate;
  lambda *= rate;
  for (int n : corrected_nodes_) dc.row(n) *= rate;
  if (!impulse) return;
  impulse->dem *= rate;
  for (int n : corrected_nodes_) impulse->continuum.row(n) *= rate;
}

}  // namespace arlequin::coupling
