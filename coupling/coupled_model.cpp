// SPDX-License-Identifier: GPL-3.0-or-later
#include "coupling/coupled_model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "common/error.hpp"
#include "common/parallel.hpp"
#include "dem/laguerre_cells.hpp"

namespace arlequin::coupling {

std::vector<int> group_dofs(const continuum::ContinuumSolver& continuum, const std::string& group,
                            std::array<bool, 3> components) {
  std::vector<int> dofs;
  for (int n : continuum.mesh().group(group).nodes)
    for (int c = 0; c < 3; ++c)
      if (components[c]) dofs.push_back(3 * n + c);
  return dofs;
}

namespace {

// Weights are evaluated in the reference configuration (DEM positions are swapped to their
// reference for the call), so a pre-deformed start sees the same weights as an undeformed one.
bool weight_models(dem::DemModel& dem, continuum::ContinuumSolver& continuum, const OverlapZone& zone) {
  std::vector<Vec3> current = dem.particles.position;
  dem.particles.position = dem.particles.reference;
  dem.apply_arlequin_weight([&zone](const Vec3& x) { return zone.alpha_d(x); }, zone.mass_floor());
  dem.particles.position.swap(current);
  continuum.set_weight([zone](const Vec3& x) { return zone.alpha_c(x); });
  // The first node without mass, or -1; a node mass below 1e-12 of the largest is a zero that
  // round-off kept positive.
  const auto first_massless_node = [&continuum] {
    const auto& m = continuum.lumped_mass();
    const double tiny = 1e-12 * *std::max_element(m.begin(), m.end());
    const auto it = std::find_if(m.begin(), m.end(), [tiny](double v) { return !(v > tiny); });
    return it == m.end() ? -1 : int(it - m.begin());
  };
  if (first_massless_node() < 0) return false;
  // A node with alpha_c = 0 at all its mass points (e.g. a natural-neighbour node on the
  // DEM-side edge of the overlap): its mass is floored as the DEs' are, max(alpha_c, eps), and
  // its stiffness is not, which keeps the partition of unity of the energy (docs/decisions.md#d9).
  continuum.set_weight([zone](const Vec3& x) { return zone.alpha_c(x); }, zone.mass_floor());
  if (const int n = first_massless_node(); n >= 0) {
    const Vec3& x = continuum.nodes()[n];
    std::ostringstream msg;
    msg << "continuum node " << n << " at (" << x.x << ", " << x.y << ", " << x.z
        << ") has no mass even with the floor";
    throw SettingError("mass_floor", msg.str());
  }
  return true;
}

double frobenius(const Matrix3& m) { return m.size() ? m.norm() : 0.0; }

}  // namespace

// A row of the fine mediator whose DE a DEM condition drives, where every continuum dof its
// interpolation reaches is held too, constrains nothing that moves: both sides of u_p = u_c(X_p)
// are prescribed (a clamped yarn DE on the plate's clamped face), its row of A is zero and D is
// singular there. It is untied in every component (no multiplier, as a free component of a
// partial tie), which keeps the low-rank form of A (docs/theory.md#woodbury) available.
void CoupledModel::untie_prescribed_rows() {
  if (!ops_.settings.fine_l2()) return;
  const int np = ops_.num_particles();
  for (int p = 0; p < np; ++p) {
    if (inv_mass_d_[p] != 0.0) continue;
    // A point on a held face interpolates from that face's nodes; the others' shape functions
    // there are round-off (1e-14 of the face's), which reaches nothing.
    double largest = 0.0;
    for (SparseMatrix::InnerIterator it(ops_.Gc, p); it; ++it) largest = std::max(largest, std::abs(it.value()));
    bool moves = false;
    for (SparseMatrix::InnerIterator it(ops_.Gc, p); it; ++it)
      for (int c = 0; c < 3; ++c)
        moves = moves || (std::abs(it.value()) > 1e-10 * largest && inv_mass_c_[3 * static_cast<std::size_t>(it.col()) + c] != 0.0);
    if (moves) continue;
    if (ops_.tied.size() == 0) ops_.tied.setOnes(np, 3);
    ops_.tied.row(p).setZero();
    ++prescribed_rows_;
  }
}

CoupledModel::CoupledModel(dem::DemModel& dem, continuum::ContinuumSolver& continuum, const OverlapZone& zone,
                           CoupledOptions options)
    : dem_(dem), continuum_(continuum), zone_(zone), options_(std::move(options)) {
  continuum_mass_floored_ = weight_models(dem_, continuum_, zone_);
  dem_.finalize();
  if (options_.hold_overlap_failures) {  // after finalize, which orders the bonds
    const auto& reference = dem_.particles.reference;
    dem_.hold_failures([&](std::size_t s, std::size_t b) {
      const dem::BondSet& set = *dem_.bond_sets()[s];
      return zone_.alpha_d(0.5 * (reference[set.first()[b]] + reference[set.second()[b]])) < 1.0;
    });
  }
  ops_ = CouplingOperators::build(zone_, dem_.particles, continuum_, options_.coupling);
  if (!options_.tied_components.empty()) ops_.tie_components(options_.tied_components);
  if (options_.consistent_quadrature) make_overlap_quadrature_consistent();
  continuum_.compute_forces();
  const int np = ops_.num_particles(), nn = continuum_.num_nodes();

  inv_mass_d_.resize(np);
  std::vector<char> driven(dem_.particles.size(), 0);
  for (std::uint32_t i : options_.driven_des) driven.at(i) = 1;
  for (int p = 0; p < np; ++p) {
    const std::uint32_t i = ops_.particles[p];
    inv_mass_d_[p] = driven[i] ? 0.0 : dem_.particles.inv_mass[i];
  }
  inv_mass_c_.resize(3 * static_cast<size_t>(nn));
  for (int d = 0; d < 3 * nn; ++d) inv_mass_c_[d] = 1.0 / continuum_.dof_mass()[d];
  for (int d : options_.held_continuum_dofs) inv_mass_c_.at(d) = 0.0;
  untie_prescribed_rows();
  solver_ = std::make_unique<MultiplierSolver>(ops_, inv_mass_d_, inv_mass_c_, options_.multiplier_petsc_options);
  put_state_on_constraint();

  time_steps_.dem = dem_.critical_time_step();
  time_steps_.continuum = continuum_.critical_time_step();
  if (options_.continuum_substeps == 0)  // auto (header)
    options_.continuum_substeps = std::max(1, static_cast<int>(std::floor(time_steps_.continuum / time_steps_.dem)));
  time_steps_.continuum_substeps = options_.continuum_substeps;
  time_steps_.coupled = std::min(time_steps_.dem, time_steps_.continuum / options_.continuum_substeps);
}

// The velocities onto G v = 0, and the constraint force of the present forces: the projection of
// the unconstrained accelerations (what the first half kick of the next step applies).
void CoupledModel::put_state_on_constraint() {
  const int np = ops_.num_particles(), nn = continuum_.num_nodes();
  project_velocities();
  Matrix3 ad(np, 3);
  for (int p = 0; p < np; ++p) {
    const Vec3& f = dem_.particles.force[ops_.particles[p]];
    ad.row(p) << f.x * inv_mass_d_[p], f.y * inv_mass_d_[p], f.z * inv_mass_d_[p];
  }
  Matrix3 ac = Eigen::Map<const Matrix3>(continuum_.force().data(), nn, 3).cwiseProduct(
      Eigen::Map<const Matrix3>(inv_mass_c_.data(), nn, 3));
  solver_->project(ad, ac, acc_d_, acc_c_, mu_, &constraint_force_);
}

void CoupledModel::project_velocities() {
  gather_dem_velocity(vd_);
  Matrix3 dd, dc;
  solver_->project(vd_, continuum_velocity(), dd, dc, lambda_);
  scatter_dem_velocity(vd_);
}

void CoupledModel::resume_from_set_state() {
  macro_origin_ = steps_;  // a state is set from outside between two macro steps (header)
  dem_.restart_forces();
  continuum_.compute_forces();
  put_state_on_constraint();
}

double CoupledModel::arrest(std::span<const std::uint32_t> ids) {
  if (!opens_macro_step()) throw std::logic_error("CoupledModel::arrest inside a macro step");
  const double arrested = dem_.arrest(ids);
  const auto kinetic = [this] { return dem_.kinetic_energy(ops_.particles) + continuum_kinetic_energy(); };
  const double before = kinetic();
  project_velocities();  // lambda_ is scratch between steps
  coupling_work_ += kinetic() - before;
  return arrested;
}

void CoupledModel::save_accelerations(StateArchive& archive) const {
  const auto& P = dem_.particles;
  std::vector<Vec3> translation(P.size()), rotation(P.size());
  for (std::size_t i = 0; i < P.size(); ++i)
    translation[i] = P.force[i] * P.inv_mass[i], rotation[i] = P.torque[i] * P.inv_inertia(i);
  for (int p = 0; p < ops_.num_particles(); ++p) translation[ops_.particles[p]] -= Vec3{acc_d_(p, 0), acc_d_(p, 1), acc_d_(p, 2)};
  const auto& f = continuum_.force();
  std::vector<double> nodes(f.size(), 0.0);
  for (std::size_t d = 0; d < f.size(); ++d)
    if (continuum_dof_free(d))
      nodes[d] = f[d] * inv_mass_c_[d] - acc_c_(static_cast<Eigen::Index>(d / 3), static_cast<Eigen::Index>(d % 3));
  archive.put("accelerations/dem/translation", translation);
  archive.put("accelerations/dem/rotation", rotation);
  archive.put("accelerations/continuum", nodes);
}

CoupledModel::Relaxation CoupledModel::relax(double dt, int steps, const StateArchive& target) {
  if (!opens_macro_step()) throw std::logic_error("CoupledModel::relax inside a macro step");
  auto& P = dem_.particles;
  const std::size_t n = P.size();
  // What each DE and dof is to keep unbalanced: M a_target.
  std::vector<Vec3> force_offset = target.get<Vec3>("accelerations/dem/translation"),
                    torque_offset = target.get<Vec3>("accelerations/dem/rotation");
  std::vector<double> continuum_target = target.get<double>("accelerations/continuum");
  if (force_offset.size() != n || torque_offset.size() != n || continuum_target.size() != inv_mass_c_.size())
    throw std::logic_error("CoupledModel::relax: the target's accelerations are not this model's");
  for (std::size_t i = 0; i < n; ++i) force_offset[i] *= P.mass(i), torque_offset[i] *= P.inertia(i);
  Relaxation out;
  out.free_rigid_motions = remove_free_rigid_share(force_offset, torque_offset, continuum_target);
  std::vector<char> moves(inv_mass_c_.size());
  for (std::size_t d = 0; d < moves.size(); ++d) moves[d] = continuum_dof_free(d);

  StateArchive start;
  save_state(start);
  const double fracture_before = dem_.energies().fracture;
  auto& uc = continuum_.displacement();
  auto& vc = continuum_.velocity();
  const auto stop = [&] {
    dem_.stop_motion();
    std::fill(vc.begin(), vc.end(), 0.0);
  };
  const auto kick = [&](double h) {
    dem_.relaxation_kick(h, force_offset, torque_offset);
    const auto& f = continuum_.force();
    for (std::size_t d = 0; d < vc.size(); ++d)
      if (moves[d]) vc[d] += h * (f[d] * inv_mass_c_[d] - continuum_target[d]);
    project_velocities();
  };
  const auto kinetic = [&] { return dem_.kinetic_energy() + continuum_.kinetic_energy(); };
  // sum m |P (a - a_target)|^2 = 2 T / h^2 for the velocities a kick by h from rest gives.
  const auto imbalance = [&] {
    constexpr double h = 1.0;  // the velocities are scratch: any h measures it
    stop();
    kick(h);
    const double value = 2.0 * kinetic() / (h * h);
    stop();
    return value;
  };
  out.steps = steps;
  out.imbalance_before = imbalance();
  double last = 0.0;
  for (int k = 0; k < steps; ++k) {
    kick(0.5 * dt);
    dem_.relaxation_drift(dt);
    for (std::size_t d = 0; d < uc.size(); ++d)
      if (moves[d]) uc[d] += dt * vc[d];
    continuum_.compute_forces();
    kick(0.5 * dt);
    const double now = kinetic();
    if (now < last) stop(), last = 0.0;
    else last = now;
  }
  out.imbalance_after = imbalance();

  // The relaxed displacements, and the damage of the cohesive links with what its growth
  // dissipated: their forces follow the path the relaxation took, and a link put at its relaxed
  // opening with the damage it had before would dissipate in one step more than the energy it
  // gives up (the law's dissipation assumes small steps along its envelope).
  StateArchive relaxed;
  save_state(relaxed);
  for (const auto& [name, entry] : relaxed.entries())
    if (name == "dem/particles/position" || name == "dem/particles/orientation" || name == "continuum/u" ||
        (name.starts_with("dem/bonds/") && (name.ends_with("/damage") || name.ends_with("/dissipated"))))
      start.put_entry(name, entry);
  load_state(start);
  resume_from_set_state();
  out.fracture = dem_.energies().fracture - fracture_before;
  return out;
}

// Rigid motions of both models: translations along x, y, z (modes 0-2) and turns about the
// axes through the centre of mass c (3-5; the turn scaled by the models' radius of gyration, so
// that all six have velocities of one scale). A DE or node at x moves at velocity(j, x) per unit
// of mode j, and a DE turns at spin(j).
namespace {
struct RigidModes {
  Vec3 centre{};
  double radius = 1.0;  // m
  Vec3 velocity(int j, const Vec3& x) const {
    Vec3 e{};
    e[j % 3] = 1.0;
    return j < 3 ? e : cross(e, x - centre) * (1.0 / radius);
  }
  Vec3 spin(int j) const {
    Vec3 e{};
    if (j >= 3) e[j - 3] = 1.0 / radius;
    return e;
  }
};
}  // namespace

int CoupledModel::remove_free_rigid_share(std::vector<Vec3>& force_offset, std::vector<Vec3>& torque_offset,
                                          std::vector<double>& continuum_target) const {
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  const auto& P = dem_.particles;
  const std::size_t n = P.size(), nn = static_cast<std::size_t>(continuum_.num_nodes());
  const auto& mass_c = continuum_.dof_mass();
  const auto node_position = [&](std::size_t a) {
    return continuum_.nodes()[a] + Vec3{continuum_.displacement()[3 * a], continuum_.displacement()[3 * a + 1], continuum_.displacement()[3 * a + 2]};
  };
  RigidModes modes;
  double mass = 0.0, second = 0.0;
  for (std::size_t i = 0; i < n; ++i) modes.centre += P.position[i] * P.mass(i), mass += P.mass(i);
  for (std::size_t a = 0; a < nn; ++a) modes.centre += node_position(a) * mass_c[3 * a], mass += mass_c[3 * a];
  if (!(mass > 0.0)) return 0;
  modes.centre = modes.centre * (1.0 / mass);
  for (std::size_t i = 0; i < n; ++i) second += P.mass(i) * norm2(P.position[i] - modes.centre);
  for (std::size_t a = 0; a < nn; ++a) second += mass_c[3 * a] * norm2(node_position(a) - modes.centre);
  modes.radius = std::max(std::sqrt(second / mass), 1e-300);

  // Which combinations of the six every held dof stops: the null space of sum over held dofs of
  // m m^T, m the six modes' values there.
  Matrix6 held = Matrix6::Zero();
  Vector6 value;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t imposed = dem_.imposed_motion(i);
    if (imposed == 0) continue;
    for (int k = 0; k < 3; ++k) {
      if (imposed >> k & 1) {
        for (int j = 0; j < 6; ++j) value[j] = modes.velocity(j, P.position[i])[k];
        held += value * value.transpose();
      }
      if (imposed & 8u) {
        for (int j = 0; j < 6; ++j) value[j] = modes.spin(j)[k];
        held += value * value.transpose();
      }
    }
  }
  for (std::size_t d = 0; d < 3 * nn; ++d) {
    if (continuum_dof_free(d)) continue;
    for (int j = 0; j < 6; ++j) value[j] = modes.velocity(j, node_position(d / 3))[static_cast<int>(d % 3)];
    held += value * value.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Matrix6> eigen(held);
  const double scale = std::max(eigen.eigenvalues().maxCoeff(), 1.0);
  int free = 0;
  Matrix6 basis = Matrix6::Zero();  // the free combinations, as columns
  for (int j = 0; j < 6; ++j)
    if (eigen.eigenvalues()[j] <= 1e-12 * scale) basis.col(free++) = eigen.eigenvectors().col(j);
  if (free == 0) return 0;

  // Their mass matrix and the target's net force on them: sum over the free dofs of
  // phi . M phi and phi . (f - M a_target).
  Matrix6 mode_mass = Matrix6::Zero();
  Vector6 force = Vector6::Zero();
  Eigen::Matrix<double, 3, 6> v, w;
  for (int j = 0; j < 6; ++j)
    for (int k = 0; k < 3; ++k) w(k, j) = modes.spin(j)[k];
  const Eigen::Matrix<double, 3, 6> w_free = w * basis;
  for (std::size_t i = 0; i < n; ++i) {
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 3; ++k) v(k, j) = modes.velocity(j, P.position[i])[k];
    const Eigen::Matrix<double, 3, 6> v_free = v * basis;
    const Vec3 df = P.force[i] - force_offset[i], dt = P.torque[i] - torque_offset[i];
    mode_mass += P.mass(i) * v_free.transpose() * v_free + P.inertia(i) * w_free.transpose() * w_free;
    force += v_free.transpose() * Eigen::Vector3d(df.x, df.y, df.z) + w_free.transpose() * Eigen::Vector3d(dt.x, dt.y, dt.z);
  }
  const auto& f = continuum_.force();
  for (std::size_t d = 0; d < 3 * nn; ++d) {
    if (!continuum_dof_free(d)) continue;
    Vector6 phi;
    for (int j = 0; j < 6; ++j) phi[j] = modes.velocity(j, node_position(d / 3))[static_cast<int>(d % 3)];
    const Vector6 phi_free = basis.transpose() * phi;
    mode_mass += mass_c[d] * phi_free * phi_free.transpose();
    force += phi_free * (f[d] - mass_c[d] * continuum_target[d]);
  }
  // The rigid acceleration that force gives, added to every target (the unused columns of the
  // basis are zero: a unit diagonal there keeps the 6 x 6 solve regular and leaves them zero).
  for (int j = free; j < 6; ++j) mode_mass(j, j) = 1.0;
  const Vector6 c6 = basis * mode_mass.ldlt().solve(force);
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 a{}, alpha{};
    for (int j = 0; j < 6; ++j) a += modes.velocity(j, P.position[i]) * c6[j], alpha += modes.spin(j) * c6[j];
    force_offset[i] += a * P.mass(i);
    torque_offset[i] += alpha * P.inertia(i);
  }
  for (std::size_t d = 0; d < 3 * nn; ++d) {
    if (!continuum_dof_free(d)) continue;
    double a = 0.0;
    for (int j = 0; j < 6; ++j) a += modes.velocity(j, node_position(d / 3))[static_cast<int>(d % 3)] * c6[j];
    continuum_target[d] += a;
  }
  return free;
}

// The targets of the contract's consistent quadrature: g_a = sum_p N(p, a) h_p, h_p = sum over
// the Laguerre faces f of DE p of alpha_d(centroid_f) A_f (the weighted bond energy's gradient
// at p is -sigma h_p). Nodes with every dof held or fixed take reactions and get none.
void CoupledModel::make_overlap_quadrature_consistent() {
  const int nn = continuum_.num_nodes();
  std::vector<Vec3> target(nn, Vec3{});
  std::vector<char> held(3 * static_cast<size_t>(nn), 0), constrained(nn, 0);
  for (int d = 0; d < 3 * nn; ++d) held[d] = continuum_.is_fixed(d);
  for (int d : options_.held_continuum_dofs) held.at(d) = 1;
  for (int a = 0; a < nn; ++a) constrained[a] = !(held[3 * a] && held[3 * a + 1] && held[3 * a + 2]);
  try {
    const auto faces = dem::laguerre_faces(dem_.particles.reference, dem_.particles.radius, ops_.particles);
    for (int p = 0; p < ops_.num_particles(); ++p) {
      Vec3 h{};
      for (const auto& f : faces[p]) h += zone_.alpha_d(f.centroid) * f.area;
      for (SparseMatrix::InnerIterator it(ops_.N, p); it; ++it) target[it.col()] += it.value() * h;
    }
    quadrature_correction_ = continuum_.correct_weights(target, constrained);
  } catch (const std::runtime_error& e) {  // InputError, or RunError from the solve
    throw SettingError("quadrature", std::string("consistent: ") + e.what() +
                     " (it needs every free continuum node the overlap reaches to lie inside the coupled body: "
                     "held boundaries, no free surface through the overlap)");
  }
}

std::string CoupledModel::summary() const {
  std::ostringstream s;
  const auto& w = zone_.weighting();
  s << "coupling overlap: " << zone_.description() << "\n"
    << "coupling weights: " << weight_shape_name(w.shape) << ", mass floor " << w.mass_floor;
  if (continuum_mass_floored_) s << " (continuum: on mass too, some nodes had alpha_c = 0)";
  s << "\n"
    << "coupling operators: mediator " << mediator_name(ops_.settings.mediator) << ", "
    << coupling_type_name(ops_.settings.type);
  if (ops_.settings.type == CouplingType::h1) s << " (length " << ops_.settings.length << " m)";
  if (options_.consistent_quadrature)
    s << "; consistent quadrature: " << quadrature_correction_.points << " overlap points weighted for "
      << quadrature_correction_.nodes << " free nodes (largest change " << quadrature_correction_.largest_change
      << ", smallest weight " << quadrature_correction_.smallest_weight << " of a point's volume)";
  s << "; " << ops_.num_particles() << " coupled DEs, " << ops_.rows() << " multipliers per component";
  if (prescribed_rows_ > 0) s << " (" << prescribed_rows_ << " of them untied: driven DEs where the continuum is held)";
  s << "\n"
    << "coupling matrix A: " << solver_->backend() << ", " << solver_->nonzeros() << " non-zeros stored, "
    << solver_->systems() << " system(s) set up once\n"
    << "critical time step: DEM " << time_steps_.dem << " s, continuum " << time_steps_.continuum << " s";
  if (options_.continuum_substeps > 1)
    s << " (its internal force once every " << options_.continuum_substeps << " steps: "
      << time_steps_.continuum / options_.continuum_substeps << " s a step)";
  s << ", coupled " << time_steps_.coupled << " s\n";
  return s.str();
}

// The per-DE and per-node loops of the coupled step run on the threads (common/parallel.hpp):
// each entry's arithmetic is its own, so the bits do not depend on the thread count.
void CoupledModel::gather_dem_velocity(Matrix3& v) const {
  const long np = ops_.num_particles();
  v.resize(np, 3);
  for_each_index(np, np > parallel_threshold_rows, [&](long p) {
    const Vec3& u = dem_.particles.velocity[ops_.particles[p]];
    v.row(p) << u.x, u.y, u.z;
  });
}

void CoupledModel::scatter_dem_velocity(const Matrix3& v) {
  const long np = ops_.num_particles();
  for_each_index(np, np > parallel_threshold_rows,
                 [&](long p) { dem_.particles.velocity[ops_.particles[p]] = {v(p, 0), v(p, 1), v(p, 2)}; });
}

Eigen::Map<Matrix3> CoupledModel::continuum_velocity() {
  return Eigen::Map<Matrix3>(continuum_.velocity().data(), continuum_.num_nodes(), 3);
}

void CoupledModel::step(double dt) {
  continuum_.begin_step_work();  // its moving supports and tractions (held dofs: no correction)
  constraint_half_kick(dt);
  advance_models(dt);
  kick_to_trial(dt);
  solve_and_correct(dt);
  continuum_.end_step_work();
  time_ += dt;
  ++steps_;
}

void CoupledModel::constraint_half_kick(double dt) {
  const double h = 0.5 * dt;
  const long np = ops_.num_particles();
  for_each_index(np, np > parallel_threshold_rows, [&](long p) {
    dem_.particles.velocity[ops_.particles[p]] -= Vec3{acc_d_(p, 0), acc_d_(p, 1), acc_d_(p, 2)} * h;
  });
  // acc_c_ is 0 but on the nodes the projection corrects
  const std::vector<int>& nodes = solver_->corrected_nodes();
  Eigen::Map<Matrix3> vc = continuum_velocity();
  for_each_index(static_cast<long>(nodes.size()), static_cast<long>(nodes.size()) > parallel_threshold_rows, [&](long k) {
    const int n = nodes[static_cast<std::size_t>(k)];
    vc.row(n) -= h * acc_c_.row(n);
  });
}

void CoupledModel::advance_models(double dt) {
  dem_.advance_to_forces(dt);
  // The continuum's forces as two impulses a macro step of m steps apart (theory.md#continuum-substeps):
  // the first half kick opens the macro step, the forces and the second close it.
  if (opens_macro_step()) continuum_.kick(0.5 * options_.continuum_substeps * dt);
  continuum_.drift(dt);
  if (closes_macro_step()) continuum_.compute_forces();
  // The drift velocities v(n+1/2) where the multipliers act, for their work (solve_and_correct).
  gather_dem_velocity(vd_drift_);
  const std::vector<int>& nodes = solver_->corrected_nodes();
  const Eigen::Map<Matrix3> vc = continuum_velocity();
  vc_drift_.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for_each_index(vc_drift_.rows(), vc_drift_.rows() > parallel_threshold_rows,
                 [&](long k) { vc_drift_.row(k) = vc.row(nodes[static_cast<std::size_t>(k)]); });
}

void CoupledModel::kick_to_trial(double dt) {
  dem_.finish_step(dt);
  if (closes_macro_step()) continuum_.kick(0.5 * options_.continuum_substeps * dt);
}

std::optional<OverlapDamage> CoupledModel::damage_in_overlap() {
  const auto& reference = dem_.particles.reference;
  std::optional<OverlapDamage> damage;
  const auto look = [&](const std::vector<dem::BreakEvent>& events, std::size_t& looked_at, bool held) {
    for (; looked_at < events.size(); ++looked_at) {
      const dem::BreakEvent& e = events[looked_at];
      const dem::BondSet& set = *dem_.bond_sets()[e.set];
      const double weight = zone_.alpha_d(0.5 * (reference[set.first()[e.bond]] + reference[set.second()[e.bond]]));
      if (!(weight < 1.0)) continue;
      if (!damage) damage = OverlapDamage{0, e, weight, held};
      ++damage->breaks;
    }
  };
  look(dem_.breaks(), breaks_looked_at_, false);
  look(dem_.held_failures(), held_looked_at_, true);
  return damage;
}

void CoupledModel::solve_and_correct(double dt) {
  gather_dem_velocity(vd_);
  // The corrections and multipliers of the half step dt/2, per unit time: acc_d_, acc_c_, mu(n+1)
  // and the constraint forces.
  solver_->project(vd_, continuum_velocity(), acc_d_, acc_c_, lambda_, &constraint_force_next_, 2.0 / dt);
  scatter_dem_velocity(vd_);
  const std::vector<int>& nodes = solver_->corrected_nodes();
  // Work of F = -G^T mu over the drift, trapezoidal in time: -dt (mu(n) + mu(n+1))/2 . G v(n+1/2),
  // as G^T (mu(n) + mu(n+1)) . v(n+1/2) over the coupled DEs and the nodes G reaches.
  double power = (constraint_force_.dem + constraint_force_next_.dem).cwiseProduct(vd_drift_).sum();
  Matrix3& fc = constraint_force_next_.continuum;
  const Matrix3& fc_before = constraint_force_.continuum;
  for (std::size_t k = 0; k < nodes.size(); ++k) {  // 0 elsewhere (MultiplierSolver::project)
    const int n = nodes[k];
    for (int c = 0; c < 3; ++c) power += (fc_before(n, c) + fc(n, c)) * vc_drift_(static_cast<Eigen::Index>(k), c);
  }
  coupling_work_ -= 0.5 * dt * power;
  mu_.swap(lambda_);
  std::swap(constraint_force_, constraint_force_next_);
}

// sum m |a|^2 with a the constrained accelerations (rotations included).
std::array<double, 2> CoupledModel::acceleration_norm() const {
  const auto& P = dem_.particles;
  double sum = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i)
    sum += norm2(P.force[i]) * P.inv_mass[i] + norm2(P.torque[i]) * P.inv_inertia(i);
  // Coupled DEs: replace m|f/m|^2 by m|f/m - a_con|^2 (no per-step scratch array).
  for (int p = 0; p < ops_.num_particles(); ++p) {
    const std::uint32_t i = ops_.particles[p];
    const Vec3 a = P.force[i] * P.inv_mass[i];
    const Vec3 constrained = a - Vec3{acc_d_(p, 0), acc_d_(p, 1), acc_d_(p, 2)};
    sum += (norm2(constrained) - norm2(a)) / P.inv_mass[i];
  }
  double sum_c = 0.0;
  const auto& f = continuum_.force();
  for (std::size_t d = 0; d < f.size(); ++d) {
    if (inv_mass_c_[d] == 0.0) continue;
    const double a = f[d] * inv_mass_c_[d] - acc_c_(static_cast<Eigen::Index>(d / 3), static_cast<Eigen::Index>(d % 3));
    sum_c += a * a / inv_mass_c_[d];
  }
  return {sum, sum_c};
}

double CoupledModel::continuum_kinetic_energy() const {
  // Inside a macro step of the continuum's substeps (theory.md#continuum-substeps) its velocities
  // carry the opening impulse m dt/2 M^-1 f whole; j steps in, the force's share so far is j dt,
  // so the energy is taken at v - (m/2 - j) dt M^-1 f, as if the force acted evenly.
  const int m = options_.continuum_substeps, j = macro_phase();
  return continuum_.kinetic_energy(j == 0 ? 0.0 : -(0.5 * m - j) * dem_.last_dt());
}

CouplingMonitor CoupledModel::monitor() const {
  Matrix3 vd, residual;
  gather_dem_velocity(vd);
  const Eigen::Map<const Matrix3> vc(continuum_.velocity().data(), continuum_.num_nodes(), 3);
  solver_->residual(vd, vc, residual);
  const double scale = frobenius(ops_.Gd * vd);  // |G_d vd|, the scale of both residuals
  const auto relative = [scale](const Matrix3& r) { return scale > 0 ? frobenius(r) / scale : frobenius(r); };
  CouplingMonitor m;
  m.constraint_residual = relative(residual);
  Matrix3 mismatch = ops_.N * vc - vd;
  if (ops_.tied.size()) mismatch.array() *= ops_.tied.array();  // free components may differ
  const Eigen::Index n = mismatch.rows();
  double sum = 0.0, largest = 0.0;
  for (Eigen::Index p = 0; p < n; ++p) {
    const double m2 = mismatch.row(p).squaredNorm();
    sum += m2;
    largest = std::max(largest, m2);
  }
  m.velocity_mismatch = n ? std::sqrt(sum / double(n)) : 0.0;
  m.max_velocity_mismatch = std::sqrt(largest);
  return m;
}

CoupledEnergies CoupledModel::energies() const {
  CoupledEnergies e;
  e.dem = dem_.energies();
  e.continuum_kinetic = continuum_kinetic_energy();
  e.continuum_strain = continuum_.strain_energy();
  e.coupling_work = coupling_work_;
  const auto [dem_norm, continuum_norm] = acceleration_norm();
  e.dem_acceleration_norm = dem_norm;
  e.continuum_acceleration_norm = continuum_norm;
  return e;
}

double CoupledModel::displacement_residual() const {
  Matrix3 ud(ops_.num_particles(), 3);
  for (int p = 0; p < ops_.num_particles(); ++p) {
    const std::uint32_t i = ops_.particles[p];
    const Vec3 u = dem_.particles.position[i] - dem_.particles.reference[i];
    ud.row(p) << u.x, u.y, u.z;
  }
  const Eigen::Map<const Matrix3> uc(continuum_.displacement().data(), continuum_.num_nodes(), 3);
  const double scale = frobenius(ops_.Gd * ud);
  Matrix3 r_matrix;
  solver_->residual(ud, uc, r_matrix);
  const double r = frobenius(r_matrix);
  return scale > 0 ? r / scale : r;
}

namespace {
// Rows of a Matrix3 (one per DE or node, row-major) as 3-vectors, for the checkpoint.
std::span<const Vec3> rows_of(const Matrix3& m) { return {reinterpret_cast<const Vec3*>(m.data()), static_cast<std::size_t>(m.rows())}; }
std::span<Vec3> rows_of(Matrix3& m) { return {reinterpret_cast<Vec3*>(m.data()), static_cast<std::size_t>(m.rows())}; }
}  // namespace

void CoupledModel::save_state(StateArchive& archive) const {
  dem_.save_state(archive);
  continuum_.save_state(archive, "continuum/");
  archive.put("coupling/mu", rows_of(mu_));
  archive.put("coupling/acceleration_dem", rows_of(acc_d_));
  archive.put("coupling/acceleration_continuum", rows_of(acc_c_));
  archive.put("coupling/force_dem", rows_of(constraint_force_.dem));
  archive.put("coupling/force_continuum", rows_of(constraint_force_.continuum));
  archive.put("coupling/work", coupling_work_);
  archive.put("coupling/time", time_);
  archive.put("coupling/steps", std::int64_t{steps_});
  archive.put("coupling/macro_origin", std::int64_t{macro_origin_});
  archive.put("coupling/breaks_looked_at", static_cast<std::int64_t>(breaks_looked_at_));
  archive.put("coupling/held_looked_at", static_cast<std::int64_t>(held_looked_at_));
}

void CoupledModel::load_state(const StateArchive& archive) {
  dem_.load_state(archive);
  continuum_.load_state(archive, "continuum/");
  archive.get_into("coupling/mu", rows_of(mu_));
  archive.get_into("coupling/acceleration_dem", rows_of(acc_d_));
  archive.get_into("coupling/acceleration_continuum", rows_of(acc_c_));
  archive.get_into("coupling/force_dem", rows_of(constraint_force_.dem));
  archive.get_into("coupling/force_continuum", rows_of(constraint_force_.continuum));
  coupling_work_ = archive.number("coupling/work");
  time_ = archive.number("coupling/time");
  steps_ = archive.integer("coupling/steps");
  macro_origin_ = archive.has("coupling/macro_origin") ? archive.integer("coupling/macro_origin") : 0;  // 0 before it was kept
  breaks_looked_at_ = static_cast<std::size_t>(archive.integer("coupling/breaks_looked_at"));
  held_looked_at_ = static_cast<std::size_t>(archive.integer("coupling/held_looked_at"));
}

}  // namespace arlequin::coupling
