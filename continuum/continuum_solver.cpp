// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/continuum_solver.hpp"

#include <petscksp.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include "common/damped_step.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"
#include "continuum/petsc_session.hpp"

namespace arlequin::continuum {

namespace {

// Dunavant degree-4 rule on a triangle (Dunavant, IJNME 21 (1985)), barycentric (a, b, b)
// permutations; weights sum to 1. Degree 4 integrates P2 traces times quadratic tractions exactly.
constexpr double kTriA[2] = {0.445948490915965, 0.091576213509771};
constexpr double kTriW[2] = {0.223381589678011, 0.109951743655322};

void check(PetscErrorCode code, const char* what) { petsc_check(static_cast<int>(code), what); }

// The static solve's defaults (CG, algebraic multigrid, relative tolerance 1e-12), set before
// the case's options so that those win and only theirs are checked; then KSPSetFromOptions
// under PETSc's quiet error handler (a refused option is the case's error, said once in one
// line, not PETSc's trace). SettingError at petsc_options when PETSc refuses an option or
// leaves one unread. `scope` holds `options`.
void set_static_solver_options(KSP ksp, const ScopedPetscOptions& scope, const std::string& options) {
  PC pc;
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  check(KSPSetType(ksp, KSPCG), "KSPSetType");
  check(PCSetType(pc, PCGAMG), "PCSetType");
  check(KSPSetTolerances(ksp, 1e-12, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT), "KSPSetTolerances");
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  const PetscErrorCode read = KSPSetFromOptions(ksp);
  PetscPopErrorHandler();
  if (read != 0) throw SettingError("petsc_options", "PETSc refused '" + options + "' (an unknown KSP or PC type?)");
  if (const std::string unused = scope.unused(); !unused.empty())
    throw SettingError("petsc_options", "PETSc did not use '" + unused + "' (misspelt, or for a solver type not chosen)");
}

}  // namespace

void ContinuumSolver::check_static_solver_options(const std::string& petsc_options) {
  PetscSession::ensure(petsc_options);
  Mat A;
  check(MatCreateSeqAIJ(PETSC_COMM_SELF, 1, 1, 1, nullptr, &A), "MatCreateSeqAIJ");
  check(MatSetValue(A, 0, 0, 1.0, INSERT_VALUES), "MatSetValue");
  check(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  KSP ksp;
  check(KSPCreate(PETSC_COMM_SELF, &ksp), "KSPCreate");
  check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
  try {
    const ScopedPetscOptions scope(petsc_options);
    set_static_solver_options(ksp, scope, petsc_options);
  } catch (...) {
    KSPDestroy(&ksp);
    MatDestroy(&A);
    throw;
  }
  KSPDestroy(&ksp);
  MatDestroy(&A);
}

Kinematics kinematics_from_name(const std::string& name) {
  if (name == "small") return Kinematics::small;
  if (name == "finite") return Kinematics::finite;
  throw InputError("unknown kinematics '" + name + "' (known: small, finite)");
}

ContinuumSolver::ContinuumSolver(const ContinuumSettings& settings)
    : mesh_(Mesh::load(settings.mesh)), kinematics_(settings.kinematics) {
  PetscSession::ensure(settings.petsc_options);
  if (settings.materials.empty()) throw InputError("continuum: no material given");
  tet_material_.assign(mesh_.num_tets(), -1);
  for (const auto& rm : settings.materials) {
    const int index = static_cast<int>(materials_.size());
    materials_.push_back(rm.material);
    if (rm.region.empty()) {
      std::fill(tet_material_.begin(), tet_material_.end(), index);
      continue;
    }
    const PhysicalGroup& g = mesh_.group(rm.region);
    if (g.dim != 3) throw InputError("material region '" + rm.region + "' is not a volume group");
    for (int e : g.tets) tet_material_[e] = index;
  }
  if (std::find(tet_material_.begin(), tet_material_.end(), -1) != tet_material_.end())
    throw InputError("continuum: some tetrahedra lie in no region with a material");
  // A node on the face between two materials would need a mix of their shares; one share for all.
  for (const Material& m : materials_)
    if (!(m.inertia == materials_.front().inertia)) throw InputError("continuum: the materials' inertia shares differ (one set for all materials)");
  const size_t ndof = 3 * static_cast<size_t>(mesh_.num_nodes());
  u_.assign(ndof, 0.0);
  v_.assign(ndof, 0.0);
  f_.assign(ndof, 0.0);
  is_fixed_.assign(ndof, 0);
}

ContinuumSolver::~ContinuumSolver() = default;

void ContinuumSolver::finish_setup() {
  set_weight([](const Vec3&) { return 1.0; });
  if (kinematics_ == Kinematics::small) return;
  std::vector<Stiffness> stiffness;
  for (const Material& m : materials_) stiffness.push_back(m.C);
  finite_force_ =
      FiniteStrainForce(points_.offset, points_.node, points_.grad, points_.material, stiffness, points_.basis, points_.coef);
}

void ContinuumSolver::set_weight(ScalarFunction alpha, double mass_floor) {
  alpha_ = std::move(alpha);
  point_weight_.resize(points_.x.size());
  for (size_t q = 0; q < points_.x.size(); ++q) point_weight_[q] = alpha_(points_.x[q]) * points_.volume[q];
  mass_ = mass_floor > 0.0 ? weighted_lumped_mass([this, mass_floor](const Vec3& x) { return std::max(alpha_(x), mass_floor); })
                           : weighted_lumped_mass(alpha_);
  const Vec3& share = materials_.front().inertia;  // the same for every material (constructor)
  dof_mass_.resize(3 * mass_.size());
  for (std::size_t d = 0; d < dof_mass_.size(); ++d) dof_mass_[d] = mass_[d / 3] * share[static_cast<int>(d % 3)];
  update_kick_inverse_mass();
  stiffness_current_ = false;
}

ContinuumSolver::WeightCorrection ContinuumSolver::correct_weights(const std::vector<Vec3>& target,
                                                                   const std::vector<char>& constrained) {
  const int nn = num_nodes(), np = static_cast<int>(points_.x.size());
  WeightCorrection result;
  // The points that may change and the constrained nodes they reach (3 rows each).
  std::vector<int> row(nn, -1), points;
  for (int q = 0; q < np; ++q)
    if (alpha_(points_.x[q]) < 1.0) {
      points.push_back(q);
      for (int k = points_.offset[q]; k < points_.offset[q + 1]; ++k) {
        const int a = points_.node[k];
        if (constrained.at(a) && row[a] < 0) row[a] = result.nodes++;
      }
    }
  result.points = static_cast<int>(points.size());
  Eigen::VectorXd w0(result.points);
  for (int j = 0; j < result.points; ++j) w0[j] = point_weight_[points[j]];
  Eigen::VectorXd w = w0;
  if (result.nodes > 0) w = weights_meeting_targets(points, w0, row, result.nodes, target);
  result.smallest_weight = result.points ? std::numeric_limits<double>::infinity() : 0.0;
  for (int j = 0; j < result.points; ++j) {
    const int q = points[j];
    result.largest_change = std::max(result.largest_change, std::abs(w[j] - w0[j]) / points_.volume[q]);
    point_weight_[q] = w[j];
    result.smallest_weight = std::min(result.smallest_weight, w[j] / points_.volume[q]);
  }
  stiffness_current_ = false;
  return result;
}

Eigen::VectorXd ContinuumSolver::weights_meeting_targets(const std::vector<int>& points, const Eigen::VectorXd& w0,
                                                         const std::vector<int>& row, int rows,
                                                         const std::vector<Vec3>& target) const {
  using Sparse = Eigen::SparseMatrix<double>;
  const int nn = num_nodes(), np = static_cast<int>(points_.x.size());
  std::vector<int> column(np, -1);
  for (std::size_t j = 0; j < points.size(); ++j) column[points[j]] = static_cast<int>(j);
  // b = target - g (current weights, all points); A(3 row(a) + k, column(q)) = grad_q N_a [k].
  Eigen::VectorXd b = Eigen::VectorXd::Zero(3 * rows);
  for (int a = 0; a < nn; ++a)
    if (row[a] >= 0)
      for (int k = 0; k < 3; ++k) b[3 * row[a] + k] = target.at(a)[k];
  std::vector<Eigen::Triplet<double>> t;
  for (int q = 0; q < np; ++q)
    for (int k = points_.offset[q]; k < points_.offset[q + 1]; ++k) {
      const int r = row[points_.node[k]];
      if (r < 0) continue;
      const Vec3& g = points_.grad[k];
      for (int c = 0; c < 3; ++c) {
        b[3 * r + c] -= point_weight_[q] * g[c];
        if (column[q] >= 0) t.emplace_back(3 * r + c, column[q], g[c]);
      }
    }
  Sparse A(3 * rows, static_cast<int>(points.size()));
  A.setFromTriplets(t.begin(), t.end());
  // The new weights w_q exp((A^T y)_q): positive whatever the correction (so K stays positive
  // semi-definite), and the closest to the old ones in relative entropy sum_q w'_q ln(w'_q /
  // w_q) - w'_q + w_q among the weights that meet the targets (y are its Lagrange multipliers;
  // for small changes it is the least sum_q delta_q^2 / w_q). Newton on A w'(y) = A w0 + b, with
  // Jacobian A diag(w') A^T. A diagonal shift of 1e-14 of each row's own diagonal keeps it
  // factorable when rows are dependent (the partition of unity makes the rows of all nodes of a
  // region sum to zero) without slowing the rows whose points are few; halving steps keep the
  // residual falling, and a step that cannot ends the iteration.
  const Eigen::VectorXd goal = A * w0 + b;
  // Gauge: a node's sum_q w_q |grad_q N_a|, the size of its weighted terms.
  const double gauge = (Sparse(A.cwiseAbs()) * w0).maxCoeff();
  const double tolerance = 1e-13 * gauge;
  Eigen::VectorXd y = Eigen::VectorXd::Zero(3 * rows), w = w0, residual = b;
  Eigen::SimplicialLDLT<Sparse> ldlt;
  bool moved = true;
  for (int iteration = 0; iteration < 60 && moved && residual.lpNorm<Eigen::Infinity>() > tolerance; ++iteration) {
    Sparse J = A * w.asDiagonal() * Sparse(A.transpose());
    const double least_diagonal = 1e-12 * J.diagonal().maxCoeff();
    for (int r = 0; r < J.rows(); ++r) J.coeffRef(r, r) += 1e-14 * std::max(J.coeffRef(r, r), least_diagonal);
    if (iteration == 0) ldlt.analyzePattern(J);
    ldlt.factorize(J);
    if (ldlt.info() != Eigen::Success) throw RunError("weight correction: factorisation failed");
    const Eigen::VectorXd dy = ldlt.solve(residual);
    moved = false;
    for (double step = 1.0; step > 1e-6 && !moved; step *= 0.5) {
      const Eigen::VectorXd y_try = y + step * dy;
      const Eigen::VectorXd w_try = w0.cwiseProduct((A.transpose() * y_try).array().exp().matrix());
      const Eigen::VectorXd r_try = goal - A * w_try;
      if (r_try.norm() < residual.norm()) y = y_try, w = w_try, residual = r_try, moved = true;
    }
  }
  if (!(residual.lpNorm<Eigen::Infinity>() <= 1e-11 * gauge)) {
    std::ostringstream msg;
    msg << "the weighted gradients cannot meet their targets (residual " << residual.lpNorm<Eigen::Infinity>()
        << " m^2 against terms of " << gauge << " m^2)";
    throw InputError(msg.str());
  }
  return w;
}

std::vector<std::vector<int>> ContinuumSolver::coupled_nodes(int node0, int node1) const {
  std::vector<std::vector<int>> adj(static_cast<size_t>(node1 - node0));
  for (size_t q = 0; q + 1 < points_.offset.size(); ++q)
    for (int a = points_.offset[q]; a < points_.offset[q + 1]; ++a) {
      const int i = points_.node[a];
      if (i < node0 || i >= node1) continue;
      for (int b = points_.offset[q]; b < points_.offset[q + 1]; ++b) adj[i - node0].push_back(points_.node[b]);
    }
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  return adj;
}

void ContinuumSolver::point_stiffness(int q, std::vector<int>& nodes, std::vector<double>& Ke) const {
  const int b0 = points_.offset[q], m = points_.offset[q + 1] - b0;
  const Stiffness C = point_weight_[q] * materials_[points_.material[q]].C;
  Eigen::Matrix<double, 6, Eigen::Dynamic> B = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, 3 * m);
  nodes.resize(m);
  for (int a = 0; a < m; ++a) {
    const Vec3& g = points_.grad[b0 + a];
    nodes[a] = points_.node[b0 + a];
    B(0, 3 * a) = g.x;
    B(1, 3 * a + 1) = g.y;
    B(2, 3 * a + 2) = g.z;
    B(3, 3 * a + 1) = g.z, B(3, 3 * a + 2) = g.y;
    B(4, 3 * a) = g.z, B(4, 3 * a + 2) = g.x;
    B(5, 3 * a) = g.y, B(5, 3 * a + 1) = g.x;
  }
  Ke.resize(static_cast<size_t>(9 * m * m));
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(Ke.data(), 3 * m, 3 * m) =
      B.transpose() * C * B;
}

const BlockMatrix3& ContinuumSolver::stiffness() const {
  if (stiffness_current_) return stiffness_;
  stiffness_ = BlockMatrix3(coupled_nodes(0, num_nodes()));
  std::vector<int> point_nodes;
  std::vector<double> Ke;
  for (int q = 0; q + 1 < static_cast<int>(points_.offset.size()); ++q) {
    point_stiffness(q, point_nodes, Ke);
    stiffness_.add(point_nodes, Ke.data());
  }
  stiffness_current_ = true;
  return stiffness_;
}

std::vector<double> ContinuumSolver::stiffness_diagonal() const {
  const BlockMatrix3& K = stiffness();
  std::vector<double> diagonal(3 * static_cast<size_t>(num_nodes()));
  for (int n = 0; n < num_nodes(); ++n)
    for (int c = 0; c < 3; ++c) diagonal[3 * static_cast<size_t>(n) + c] = K.block(n, n)[static_cast<size_t>(4 * c)];
  return diagonal;
}

void ContinuumSolver::fix(const std::string& group, std::array<bool, 3> components, VectorFunction g) {
  for (int n : mesh_.group(group).nodes)
    for (int c = 0; c < 3; ++c) {
      if (!components[c]) continue;
      const int dof = 3 * n + c;
      auto it = std::find_if(fixed_.begin(), fixed_.end(), [&](const Fixed& f) { return f.dof == dof; });
      if (it == fixed_.end())
        it = fixed_.insert(fixed_.end(), {dof, g, initial_u_.empty() ? 0.0 : initial_u_[dof]});
      else
        it->g = g;  // the later BC on a shared node wins
      is_fixed_[dof] = 1;
      kick_inverse_mass_[dof] = 0.0;
      u_[dof] = prescribed(*it, t_);
      if (!g) v_[dof] = 0.0;  // still: at rest from here on (the first drift stopped it before)
    }
  moving_fixed_.clear();
  for (std::size_t k = 0; k < fixed_.size(); ++k)
    if (fixed_[k].g) moving_fixed_.push_back(static_cast<int>(k));
}

void ContinuumSolver::set_initial_displacement(const Field& u0) {
  if (u0.size() != u_.size()) throw std::invalid_argument("set_initial_displacement: one value per dof expected");
  u_ = initial_u_ = u0;
  for (Fixed& f : fixed_) {
    f.start = u0[f.dof];
    u_[f.dof] = prescribed(f, t_);
  }
}

double ContinuumSolver::prescribed(const Fixed& f, double t) const {
  return f.g ? f.start + f.g(nodes()[f.dof / 3], t)[f.dof % 3] : f.start;
}

void ContinuumSolver::add_traction(const std::string& group, VectorFunction traction) {
  const PhysicalGroup& g = mesh_.group(group);
  if (g.dim != 2) throw InputError("traction group '" + group + "' is not a surface group");
  tractions_.push_back({surface_rule(g.triangles), std::move(traction)});
}

ContinuumSolver::SurfaceRule ContinuumSolver::surface_rule(const std::vector<std::array<int, 3>>& triangles) const {
  SurfaceRule rule;
  for (const auto& tri : triangles) {
    const Vec3 &a = nodes()[tri[0]], &b = nodes()[tri[1]], &c = nodes()[tri[2]];
    const double area = 0.5 * norm(cross(b - a, c - a));
    for (int r = 0; r < 2; ++r) {
      const double p = kTriA[r], s = 1.0 - 2.0 * p;
      const std::array<std::array<double, 3>, 3> bary{{{s, p, p}, {p, s, p}, {p, p, s}}};
      for (const auto& l : bary) {
        rule.x.push_back(l[0] * a + l[1] * b + l[2] * c);
        rule.w.push_back(kTriW[r] * area);
      }
    }
  }
  rule.N = interpolation(rule.x);
  return rule;
}

Eigen::Matrix3d ContinuumSolver::displacement_gradient(int q, const Field& u) const {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (int k = points_.offset[q]; k < points_.offset[q + 1]; ++k) {
    const Vec3& g = points_.grad[k];
    const double* uj = &u[3 * static_cast<size_t>(points_.node[k])];
    for (int i = 0; i < 3; ++i) H.row(i) += uj[i] * Eigen::RowVector3d(g.x, g.y, g.z);
  }
  return H;
}

namespace {

// A symmetric strain tensor in Voigt order (xx, yy, zz, yz, xz, xy), engineering shears.
Voigt voigt_strain(const Eigen::Matrix3d& e) {
  Voigt v;
  v << e(0, 0), e(1, 1), e(2, 2), 2.0 * e(1, 2), 2.0 * e(0, 2), 2.0 * e(0, 1);
  return v;
}

// Green-Lagrange E = (H + H^T + H^T H) / 2, or the small strain (H + H^T) / 2.
Eigen::Matrix3d strain_tensor(const Eigen::Matrix3d& H, Kinematics k) {
  const Eigen::Matrix3d linear = 0.5 * (H + H.transpose());
  return k == Kinematics::small ? linear : Eigen::Matrix3d(linear + 0.5 * H.transpose() * H);
}

}  // namespace

Voigt ContinuumSolver::strain_at(int q, const Field& u) const {
  return voigt_strain(strain_tensor(displacement_gradient(q, u), kinematics_));
}

// f_int = sum_q w_q B_q^T C_q B_q u = K u, K assembled once per weight (block_matrix.hpp says
// why); finite kinematics: the first Piola-Kirchhoff stress P = F S(E) of every point, spread
// to its nodes as w_q P grad_q N_a (the gradient of the contract's strain energy).
void ContinuumSolver::internal_force(const Field& u, Field& f_int) const {
  if (kinematics_ == Kinematics::small) {
    stiffness().multiply(u, f_int);
    return;
  }
  finite_force_.compute(u, point_weight_, f_int);
}

void ContinuumSolver::add_external_force(Field& f) const {
  for (const Traction& tr : tractions_) {
    const SurfaceRule& r = tr.rule;
    for (int p = 0; p < r.N.rows(); ++p) {
      const Vec3 t = r.w[p] * tr.fn(r.x[p], t_);
      for (InterpolationOperator::InnerIterator it(r.N, p); it; ++it) {
        double* fj = &f[3 * static_cast<size_t>(it.col())];
        fj[0] += it.value() * t.x;
        fj[1] += it.value() * t.y;
        fj[2] += it.value() * t.z;
      }
    }
  }
}

void ContinuumSolver::set_damping(double coefficient) {
  damping_ = coefficient;
  damping_force_.assign(u_.size(), 0.0);  // until the next compute_forces (the state at rest)
}

// The per-dof loops of the explicit step run on the threads (common/parallel.hpp): each dof's
// arithmetic is its own, so the bits do not depend on the thread count; the damped kick's work is
// summed by chunks in a fixed order.
void ContinuumSolver::compute_forces() {
  internal_force(u_, f_);
  const long n = static_cast<long>(f_.size());
  for_each_index(n, n > parallel_threshold, [f = f_.data()](long d) { f[d] = -f[d]; });
  add_external_force(f_);
  if (!(damping_ > 0.0)) return;
  for_each_index(n, n > parallel_threshold, [this](long d) {
    damping_force_[d] = is_fixed_[d] ? 0.0 : -damping_ * dof_mass_[d] * v_[d];
    f_[d] += damping_force_[d];
  });
}

void ContinuumSolver::update_kick_inverse_mass() {
  kick_inverse_mass_.resize(dof_mass_.size());
  for (std::size_t d = 0; d < dof_mass_.size(); ++d) kick_inverse_mass_[d] = is_fixed_[d] ? 0.0 : 1.0 / dof_mass_[d];
}

// The kick and the drift update every dof without a branch or a division, so that the drift and
// an undamped kick run in vector lanes: a held dof's kick is by 0 (kick_inverse_mass_), and its
// drift is overwritten by its prescribed value (its velocity the one that reaches that value).
void ContinuumSolver::kick(double dt) {
  const long n = static_cast<long>(v_.size());
  const auto dv = [this, dt](long d) { return dt * f_[d] * kick_inverse_mass_[d]; };
  if (!(damping_ > 0.0)) {
    for_each_index(n, n > parallel_threshold, [this, &dv](long d) { v_[d] += dv(d); });
    return;
  }
  // A kick changes a dof's kinetic energy by dt f (v + v')/2 exactly; the damping force's share
  // of that is the energy it dissipated (as DemModel::kick; 0 on held dofs, compute_forces).
  dissipated_ -= fixed_order_sum(n, parallel_threshold, kick_partial_, [this, dt, &dv](long d) {
    const double v = v_[d];
    v_[d] += dv(d);
    return dt * damping_force_[d] * 0.5 * (v + v_[d]);
  });
}

void ContinuumSolver::drift(double dt) {
  t_ += dt;
  // A still support's dofs keep u0 and zero velocity through the drift as they are.
  for (int k : moving_fixed_) {  // from u before the drift
    const Fixed& f = fixed_[static_cast<std::size_t>(k)];
    v_[f.dof] = (prescribed(f, t_) - u_[f.dof]) / dt;
  }
  const long n = static_cast<long>(u_.size());
  for_each_index(n, n > parallel_threshold, [this, dt](long d) { u_[d] += dt * v_[d]; });
  for (int k : moving_fixed_) {
    const Fixed& f = fixed_[static_cast<std::size_t>(k)];
    u_[f.dof] = prescribed(f, t_);
  }
}

void ContinuumSolver::begin_step_work() {
  // The tractions' term takes a pass over every dof and is made only when there are tractions;
  // the supports' only over the prescribed dofs.
  step_work_ = 0.0;
  if (!tractions_.empty()) {
    step_u_ = u_;
    step_f_ext_.assign(u_.size(), 0.0);
    add_external_force(step_f_ext_);
  }
  // The moving supports' work; a still support's is zero (its dofs neither move nor have speed).
  step_fixed_u_.resize(moving_fixed_.size());
  step_f_fixed_.resize(moving_fixed_.size());
  for (std::size_t k = 0; k < moving_fixed_.size(); ++k) {
    const int d = fixed_[static_cast<std::size_t>(moving_fixed_[k])].dof;
    step_work_ -= 0.5 * dof_mass_[d] * v_[d] * v_[d];
    step_fixed_u_[k] = u_[d];
    step_f_fixed_[k] = f_[d];
  }
}

void ContinuumSolver::end_step_work() {
  if (!tractions_.empty()) {
    step_f_ext_new_.assign(u_.size(), 0.0);
    add_external_force(step_f_ext_new_);
    for (std::size_t d = 0; d < u_.size(); ++d) step_work_ += 0.5 * (step_f_ext_[d] + step_f_ext_new_[d]) * (u_[d] - step_u_[d]);
  }
  for (std::size_t k = 0; k < moving_fixed_.size(); ++k) {
    const int d = fixed_[static_cast<std::size_t>(moving_fixed_[k])].dof;
    step_work_ += 0.5 * dof_mass_[d] * v_[d] * v_[d] - 0.5 * (step_f_fixed_[k] + f_[d]) * (u_[d] - step_fixed_u_[k]);
  }
  external_work_ += step_work_;
}

void ContinuumSolver::step(double dt) {
  begin_step_work();
  kick(0.5 * dt);
  drift(dt);
  compute_forces();
  kick(0.5 * dt);
  end_step_work();
  double sum = 0;
  for (double v : v_) sum += v;
  if (!std::isfinite(sum)) throw RunError("continuum: non-finite state at t = " + std::to_string(t_));
}

void ContinuumSolver::save_state(StateArchive& archive, const std::string& prefix) const {
  archive.put(prefix + "lumped_mass", dof_mass_);
  archive.put(prefix + "u", u_);
  archive.put(prefix + "v", v_);
  archive.put(prefix + "f", f_);
  archive.put(prefix + "time", t_);
  archive.put(prefix + "external_work", external_work_);
  archive.put(prefix + "damping_force", damping_force_);
  archive.put(prefix + "dissipated", dissipated_);
}

void ContinuumSolver::load_state(const StateArchive& archive, const std::string& prefix) {
  if (archive.get<double>(prefix + "lumped_mass") != dof_mass_)
    throw StateMismatch("its continuum's lumped mass differs from this scene's (another mesh, material or weight)");
  archive.get_into(prefix + "u", u_);
  archive.get_into(prefix + "v", v_);
  archive.get_into(prefix + "f", f_);
  t_ = archive.number(prefix + "time");
  external_work_ = archive.number(prefix + "external_work");
  damping_force_ = archive.get<double>(prefix + "damping_force");
  if (!damping_force_.empty() && damping_force_.size() != f_.size())
    throw StateMismatch("'" + prefix + "damping_force' holds " + std::to_string(damping_force_.size()) + " values, this scene has " +
                        std::to_string(f_.size()));
  dissipated_ = archive.number(prefix + "dissipated");
}

double ContinuumSolver::verlet_correction(double dt) const {
  double sum = 0.0;
  for (std::size_t d = 0; d < f_.size(); ++d)
    if (!is_fixed_[d]) sum += f_[d] * f_[d] / dof_mass_[d];
  return dt * dt / 8.0 * sum;
}

// omega_max^2, the largest eigenvalue of the symmetric A = M^-1/2 K M^-1/2, by the Lanczos
// process (e.g. Golub & Van Loan, Matrix Computations, section 10.1; Parlett, The Symmetric
// Eigenvalue Problem, chapter 13): k products with A build the tridiagonal T_k whose largest
// eigenvalue theta (a Ritz value) approaches the top of A's spectrum from below, much faster than
// a power iteration where the top eigenvalues cluster. ||A y - theta y|| = beta_k |s_k| for its
// Ritz vector y (s_k: the last entry of T_k's eigenvector), so an eigenvalue of A lies within that
// of theta: the process stops when it is under 1e-6 theta and returns theta + beta_k |s_k|, an
// estimate from above of that eigenvalue. The start vector is random so it has a component
// along the top modes. No reorthogonalisation: its loss only repeats converged Ritz values, the
// largest stays. dt_c = 2 / omega_max (central difference, e.g. Belytschko, Liu & Moran,
// Nonlinear Finite Elements, section 6.3).
double ContinuumSolver::critical_time_step() const {
  for (double m : dof_mass_)
    if (!(m > 0)) throw RunError("continuum: a lumped mass is not positive (weight without floor?)");
  const size_t n = u_.size();
  std::vector<double> inv_sqrt_mass(n);
  for (size_t d = 0; d < n; ++d) inv_sqrt_mass[d] = 1.0 / std::sqrt(dof_mass_[d]);
  Field q(n), q_previous(n, 0.0), w(n), scaled(n);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (double& v : q) v = uni(rng);
  const auto norm = [](const Field& v) {
    double sum = 0.0;
    for (double x : v) sum += x * x;
    return std::sqrt(sum);
  };
  const double q_norm = norm(q);
  for (double& v : q) v /= q_norm;
  constexpr double tolerance = 1e-6;
  constexpr int max_steps = 1000;
  std::vector<double> alpha, beta;  // T_k's diagonal and off-diagonal
  double estimate = 0.0, residual = INFINITY;
  for (int k = 0;; ++k) {  // ends at the last step at the latest (below)
    for (size_t d = 0; d < n; ++d) scaled[d] = q[d] * inv_sqrt_mass[d];
    stiffness().multiply(scaled, w);  // w = A q
    double a = 0.0;
    for (size_t d = 0; d < n; ++d) {
      w[d] *= inv_sqrt_mass[d];
      a += q[d] * w[d];
    }
    const double b_previous = beta.empty() ? 0.0 : beta.back();
    for (size_t d = 0; d < n; ++d) w[d] -= a * q[d] + b_previous * q_previous[d];
    const double b = norm(w);
    alpha.push_back(a);
    // The last step: out of steps, or b = 0 (T_k holds A's whole span: its eigenvalues are A's).
    const bool last = k + 1 == max_steps || k + 1 == static_cast<int>(n) || !(b > 0.0);
    if (k % 5 == 4 || last) {  // T_k's eigenproblem every fifth step (k^2 work each time)
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz;
      ritz.computeFromTridiagonal(Eigen::Map<const Eigen::VectorXd>(alpha.data(), static_cast<Eigen::Index>(alpha.size())),
                                  Eigen::Map<const Eigen::VectorXd>(beta.data(), static_cast<Eigen::Index>(beta.size())),
                                  Eigen::ComputeEigenvectors);
      const Eigen::Index top = ritz.eigenvalues().size() - 1;
      estimate = ritz.eigenvalues()(top);
      residual = b * std::abs(ritz.eigenvectors()(top, top));
      if (residual <= tolerance * estimate || last) break;
    }
    beta.push_back(b);
    q_previous.swap(q);
    for (size_t d = 0; d < n; ++d) q[d] = w[d] / b;
  }
  if (!(estimate > 0) || !(residual <= tolerance * estimate))
    throw RunError("continuum: could not estimate the highest frequency (Lanczos: largest Ritz value " + std::to_string(estimate) +
                   ", residual " + std::to_string(residual) + " after " + std::to_string(alpha.size()) + " steps)");
  return damped_critical_step(estimate + residual, damping_);
}

// Static solve on PETSC_COMM_WORLD. Rows follow PETSc's default split, by whole nodes
// (PetscSplitOwnershipBlock, block size 3); rank r assembles the integration points
// [r nq / size, (r + 1) nq / size), and entries of rows owned elsewhere travel in PETSc's stash at
// MatAssemblyBegin/End. Without mpirun there is one rank and this is a sequential solve.
void ContinuumSolver::solve_static(const std::string& petsc_options) {
  if (kinematics_ == Kinematics::finite)
    throw InputError("continuum: the static solve is linear (kinematics: small); finite kinematics are for explicit runs");
  const MPI_Comm comm = PETSC_COMM_WORLD;
  PetscMPIInt rank, size;  // MPI errors abort (MPI_ERRORS_ARE_FATAL): no codes to check
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const PetscInt nn = mesh_.num_nodes(), n = 3 * nn;
  PetscInt n_local = PETSC_DECIDE, n_global = n, row_end;
  check(PetscSplitOwnershipBlock(comm, 3, &n_local, &n_global), "PetscSplitOwnershipBlock");
  MPI_Scan(&n_local, &row_end, 1, MPIU_INT, MPI_SUM, comm);
  const int node0 = static_cast<int>((row_end - n_local) / 3), node1 = static_cast<int>(row_end / 3);

  // Block sparsity of the local rows: nodes sharing an integration point are coupled.
  const int nq = static_cast<int>(points_.x.size());
  std::vector<PetscInt> d_nnz(node1 - node0), o_nnz(node1 - node0);
  {
    const std::vector<std::vector<int>> adj = coupled_nodes(node0, node1);
    for (int i = 0; i < node1 - node0; ++i) {
      const auto& a = adj[i];
      d_nnz[i] = static_cast<PetscInt>(std::count_if(a.begin(), a.end(), [&](int j) { return j >= node0 && j < node1; }));
      o_nnz[i] = static_cast<PetscInt>(a.size()) - d_nnz[i];
    }
  }

  Mat K;
  check(MatCreate(comm, &K), "MatCreate");
  check(MatSetSizes(K, n_local, n_local, n, n), "MatSetSizes");
  check(MatSetType(K, MATAIJ), "MatSetType");
  check(MatSetBlockSize(K, 3), "MatSetBlockSize");
  check(MatXAIJSetPreallocation(K, 3, d_nnz.data(), o_nnz.data(), nullptr, nullptr), "MatXAIJSetPreallocation");
  std::vector<int> point_nodes;
  std::vector<PetscInt> idx;
  std::vector<double> Ke;
  const int q0 = static_cast<int>(static_cast<long long>(nq) * rank / size);
  const int q1 = static_cast<int>(static_cast<long long>(nq) * (rank + 1) / size);
  for (int q = q0; q < q1; ++q) {
    point_stiffness(q, point_nodes, Ke);
    idx.assign(point_nodes.begin(), point_nodes.end());
    const PetscInt m = static_cast<PetscInt>(point_nodes.size());
    check(MatSetValuesBlocked(K, m, idx.data(), m, idx.data(), Ke.data(), ADD_VALUES), "MatSetValuesBlocked");
  }
  check(MatAssemblyBegin(K, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(K, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");

  // Right-hand side, start vector with the prescribed values, and the local fixed rows.
  Field f_ext(u_.size(), 0.0);
  add_external_force(f_ext);
  Vec b, x, coords;
  check(MatCreateVecs(K, &x, &b), "MatCreateVecs");
  PetscInt lo, hi;
  check(VecGetOwnershipRange(b, &lo, &hi), "VecGetOwnershipRange");
  PetscScalar* pb;
  PetscScalar* px;
  check(VecGetArray(b, &pb), "VecGetArray");
  check(VecGetArray(x, &px), "VecGetArray");
  for (PetscInt d = lo; d < hi; ++d) {
    pb[d - lo] = f_ext[d];
    px[d - lo] = 0.0;
  }
  std::vector<PetscInt> rows;
  for (const Fixed& f : fixed_) {
    if (f.dof < lo || f.dof >= hi) continue;
    px[f.dof - lo] = prescribed(f, t_);
    rows.push_back(f.dof);
  }
  check(VecRestoreArray(b, &pb), "VecRestoreArray");
  check(VecRestoreArray(x, &px), "VecRestoreArray");
  // Eliminate fixed components symmetrically (keeps CG applicable); the unit diagonal is
  // scaled to the matrix so the conditioning does not suffer.
  Vec diag;
  check(VecDuplicate(b, &diag), "VecDuplicate");
  check(MatGetDiagonal(K, diag), "MatGetDiagonal");
  PetscReal dsum;
  check(VecSum(diag, &dsum), "VecSum");
  check(VecDestroy(&diag), "VecDestroy");
  check(MatZeroRowsColumns(K, static_cast<PetscInt>(rows.size()), rows.data(), dsum / n, x, b), "MatZeroRowsColumns");

  // Rigid-body near-null space helps algebraic multigrid on elasticity.
  check(VecDuplicate(b, &coords), "VecDuplicate");
  check(VecSetBlockSize(coords, 3), "VecSetBlockSize");
  PetscScalar* pc;
  check(VecGetArray(coords, &pc), "VecGetArray");
  for (PetscInt d = lo; d < hi; ++d) pc[d - lo] = nodes()[d / 3][static_cast<int>(d % 3)];
  check(VecRestoreArray(coords, &pc), "VecRestoreArray");
  MatNullSpace rigid;
  check(MatNullSpaceCreateRigidBody(coords, &rigid), "MatNullSpaceCreateRigidBody");
  check(MatSetNearNullSpace(K, rigid), "MatSetNearNullSpace");

  KSP ksp;
  KSPConvergedReason reason;
  {
    // The option string in a database of its own while the solver is set up and run.
    const ScopedPetscOptions options(petsc_options);
    check(KSPCreate(comm, &ksp), "KSPCreate");
    check(KSPSetOperators(ksp, K, K), "KSPSetOperators");
    set_static_solver_options(ksp, options, petsc_options);
    check(KSPSolve(ksp, b, x), "KSPSolve");
    check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
  }

  // Every rank gets the whole solution.
  VecScatter to_all;
  Vec x_all;
  check(VecScatterCreateToAll(x, &to_all, &x_all), "VecScatterCreateToAll");
  check(VecScatterBegin(to_all, x, x_all, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  check(VecScatterEnd(to_all, x, x_all, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* sol;
  check(VecGetArrayRead(x_all, &sol), "VecGetArrayRead");
  std::copy(sol, sol + n, u_.begin());
  check(VecRestoreArrayRead(x_all, &sol), "VecRestoreArrayRead");
  VecScatterDestroy(&to_all);
  VecDestroy(&x_all);
  KSPDestroy(&ksp);
  MatNullSpaceDestroy(&rigid);
  VecDestroy(&coords);
  VecDestroy(&x);
  VecDestroy(&b);
  MatDestroy(&K);
  if (reason < 0) throw RunError("continuum: static solve did not converge (KSPConvergedReason " + std::to_string(reason) + ")");
  compute_forces();
}

double ContinuumSolver::strain_energy() const {
  if (kinematics_ == Kinematics::finite) return finite_force_.energy(u_, point_weight_);
  stiffness().multiply(u_, ku_);
  double e = 0;
  for (size_t d = 0; d < u_.size(); ++d) e += u_[d] * ku_[d];
  return 0.5 * e;
}

double ContinuumSolver::kinetic_energy(double kick) const {
  double e = 0;
  for (size_t d = 0; d < v_.size(); ++d) {
    const double v = is_fixed_[d] ? v_[d] : v_[d] + kick * f_[d] / dof_mass_[d];
    e += 0.5 * dof_mass_[d] * v * v;
  }
  return e;
}

std::vector<Voigt> ContinuumSolver::point_strain() const {
  std::vector<Voigt> out(points_.x.size());
  for (size_t q = 0; q < out.size(); ++q) out[q] = strain_at(static_cast<int>(q), u_);
  return out;
}

std::vector<Voigt> ContinuumSolver::point_stress() const {
  std::vector<Voigt> out = point_strain();
  for (size_t q = 0; q < out.size(); ++q) out[q] = materials_[points_.material[q]].C * out[q];
  return out;
}

}  // namespace arlequin::continuum
