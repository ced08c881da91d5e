// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/dem_model.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "common/damped_step.hpp"
#include "common/error.hpp"

namespace arlequin::dem {

int DemModel::add_group(const std::string& name) {
  if (const int g = group_index(name); g >= 0) return g;
  group_names_.push_back(name);
  group_members_.emplace_back();
  reaction_.emplace_back();
  return static_cast<int>(group_names_.size()) - 1;
}

int DemModel::add_group(const std::string& name, std::vector<std::uint32_t> ids) {
  const int g = add_group(name);
  add_members(g, ids);
  return g;
}

void DemModel::add_members(int group, std::span<const std::uint32_t> ids) {
  std::vector<std::uint32_t>& m = group_members_[group];
  const auto old_end = m.insert(m.end(), ids.begin(), ids.end());  // the first inserted
  if (!std::is_sorted(old_end, m.end())) std::sort(old_end, m.end());
  std::inplace_merge(m.begin(), old_end, m.end());
  m.erase(std::unique(m.begin(), m.end()), m.end());
}

void DemModel::watch_reaction(int group) {
  const auto at = std::lower_bound(watched_.begin(), watched_.end(), group);
  if (at == watched_.end() || *at != group) watched_.insert(at, group);
}

int DemModel::group_index(const std::string& name) const {
  const auto it = std::find(group_names_.begin(), group_names_.end(), name);
  return it == group_names_.end() ? -1 : static_cast<int>(it - group_names_.begin());
}

int DemModel::bond_set_index(const std::string& name) const {
  const auto it = std::find_if(bond_sets_.begin(), bond_sets_.end(), [&name](const auto& set) { return set->name == name; });
  return it == bond_sets_.end() ? -1 : static_cast<int>(it - bond_sets_.begin());
}

BondSet& DemModel::add_bond_set(std::unique_ptr<BondSet> set) {
  bond_sets_.push_back(std::move(set));
  return *bond_sets_.back();
}

void DemModel::set_contact(std::unique_ptr<ContactLaw> law, double skin) {
  contact_ = std::move(law);
  neighbours_.emplace(skin);
}

void DemModel::add_boundary(const BoundaryCondition& bc) { boundaries_.push_back(bc); }

std::vector<std::uint32_t> DemModel::driven_particles() const {
  std::vector<std::uint32_t> out;
  for (const BoundaryCondition& bc : boundaries_) {
    const int g = group_index(bc.group);
    if (!bc.kinematic() || g < 0) continue;
    for (std::uint32_t i : members(g)) out.push_back(i);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void DemModel::finalize() {
  // Boundary conditions: each component of a DE's motion has at most one owner (a load or a
  // free declaration owns all three); a contradiction names both conditions.
  std::vector<std::array<int, 3>> owner(particles.size(), {-1, -1, -1});
  for (std::size_t c = 0; c < boundaries_.size(); ++c) {
    const BoundaryCondition& bc = boundaries_[c];
    const int g = group_index(bc.group);
    if (g < 0) throw std::invalid_argument("unknown group '" + bc.group + "'");
    const auto ids = members(g);
    if (ids.empty()) throw std::invalid_argument("group '" + bc.group + "' has no DE");
    for (std::uint32_t i : ids) {
      for (int k = 0; k < 3; ++k) {
        if (bc.kinematic() && !bc.components[k]) continue;
        if (owner[i][k] >= 0) {
          std::ostringstream msg;
          msg << "DE " << i << " is in group '" << boundaries_[owner[i][k]].group << "' (boundary[" << owner[i][k]
              << "]) and group '" << bc.group << "' (boundary[" << c << "]), which both set its "
              << "xyz"[k] << " motion: a component can take only one boundary condition";
          throw std::invalid_argument(msg.str());
        }
        owner[i][k] = static_cast<int>(c);
      }
      if (bc.kinematic())
        constraints_.push_back({i, static_cast<std::uint32_t>(c), particles.mass(i),
                                static_cast<std::uint8_t>(bc.components[0] | bc.components[1] << 1 | bc.components[2] << 2 |
                                                          bc.lock_rotation << 3)});
      if (bc.kind == BoundaryKind::force) {
        loaded_.push_back({i, static_cast<std::uint32_t>(c), particles.mass(i), 0});
        load_per_particle_.push_back(bc.value / static_cast<double>(ids.size()));
      }
    }
  }
  constraint_reaction_.assign(constraints_.size(), Vec3{});
  moving_constraints_.clear();
  still_constraints_.clear();
  for (std::size_t k = 0; k < constraints_.size(); ++k)
    (boundaries_[constraints_[k].condition].still() ? still_constraints_ : moving_constraints_).push_back(static_cast<std::uint32_t>(k));
  // A still condition's DEs start at rest along what it imposes (the first step would stop them):
  // from here on their kinetic energy there is 0, so driven_kinetic_energy and the work of
  // their reactions skip them.
  for (const std::uint32_t k : still_constraints_) impose(constraints_[k], Vec3{});
  condition_velocity_.assign(boundaries_.size(), Vec3{});
  watched_members_.clear();
  for (const int g : watched_)
    for (const std::uint32_t i : group_members_[g]) watched_members_.push_back({i, static_cast<std::uint32_t>(g)});
  // In DE order (then group): the sums read the forces in memory order.
  std::sort(watched_members_.begin(), watched_members_.end());
  driven_.assign(particles.size(), 0);
  for (const Constraint& c : constraints_) driven_[c.particle] |= c.imposed;
  if (damping_ > 0.0) {
    damping_force_.assign(particles.size(), Vec3{});
    damping_torque_.assign(particles.size(), Vec3{});
  }
  for (auto& set : bond_sets_) set->finalize(particles.size());
  set_pointers_.clear();
  pass_sets_.assign(bond_sets_.size(), 1);
  for (std::size_t s = 0, first = 0; s < bond_sets_.size(); ++s) {
    set_pointers_.push_back(bond_sets_[s].get());
    if (s > 0 && bond_sets_[s]->gathers() && bond_sets_[s - 1]->gathers()) ++pass_sets_[first], pass_sets_[s] = 0;
    else first = s;
  }
  if (neighbours_) {
    neighbours_->set_exclusions(intact_bonded_pairs());
    neighbours_->build(particles);
  }
  if (contact_) {
    // check_contact_resolution's critical step of the contacts a DE has now: its bonds' row
    // of the bound (set-up values: a break only lowers it) plus its touching contacts'.
    const std::size_t n = particles.size();
    bond_frequency_bound_.assign(n, 0.0);
    std::vector<double> rot(n, 0.0);
    for (const auto& set : bond_sets_) set->add_frequency_bounds(particles, bond_frequency_bound_, rot);
    inv_mass_max_ = 0.0;
    for (std::size_t i = 0; i < n; ++i) inv_mass_max_ = std::max(inv_mass_max_, contact_inv_mass(i));
    contact_bound_each_.resize(n);
    for (std::size_t i = 0; i < n; ++i) contact_bound_each_[i] = contact_frequency_bound(i, 1);
    touching_.assign(n, 0);
  }
  if (rdef_) rdef_->prepare(particles, group_members_);
  failure_on_ = rdef_.has_value() ||
                std::any_of(bond_sets_.begin(), bond_sets_.end(), [](const auto& set) { return set->has_strength(); });
  restart_forces();
}

void DemModel::restart_forces() {
  energy_record_step_ = -1;  // bond energies recorded before are another state's
  compute_forces();
  record_reactions();
  apply_loads_and_damping();
}

double DemModel::contact_inv_mass(std::size_t i) const {
  return contact_weight_.empty() ? particles.inv_mass[i] : contact_weight_[i] * particles.inv_mass[i];
}

double DemModel::contact_frequency_bound(std::size_t i, std::uint32_t contacts) const {
  const double inv_m = contact_inv_mass(i);
  return contact_->stiffness() * contacts * (inv_m + std::sqrt(inv_m * inv_mass_max_));
}

double DemModel::critical_time_step() const {
  const std::size_t n = particles.size();
  std::vector<double> trans(n, 0.0), rot(n, 0.0);
  for (const auto& set : bond_sets_) set->add_frequency_bounds(particles, trans, rot);
  if (contact_ && n > 0) {
    std::vector<std::uint32_t> count(n, 0);
    if (neighbours_)
      for (auto [i, j] : neighbours_->pairs()) ++count[i], ++count[j];
    for (std::size_t i = 0; i < n; ++i) trans[i] += contact_frequency_bound(i, std::max(1u, count[i]));
  }
  double omega2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) omega2 = std::max({omega2, trans[i], rot[i]});
  // Viscous damping is applied from the half-step velocity (apply_loads_and_damping).
  double dt_c = damped_critical_step(omega2, damping_);
  // With contact, a DE that moves more than its radius in a step can pass through another
  // unseen: the step is also bounded by R_i / |v_i| at the present speeds (check_finite stops a
  // run whose DEs later move faster than that).
  if (contact_)
    for (std::size_t i = 0; i < n; ++i)
      if (const double speed = norm(particles.velocity[i]); speed > 0.0) dt_c = std::min(dt_c, particles.radius[i] / speed);
  return dt_c;
}

void DemModel::set_profile(StepProfile* profile) {
  if (profile && pass_sets_.size() != bond_sets_.size()) throw std::logic_error("DemModel: set_profile before finalize()");
  profile_ = profile;
  if (!profile) return;
  phase_.kick = profile->phase("kicks");
  phase_.drift = profile->phase("drift and clear forces");
  phase_.boundary = profile->phase("boundary conditions");
  if (neighbours_) phase_.neighbours = profile->phase("neighbour list");
  phase_.bonds.assign(bond_sets_.size(), 0);
  for (std::size_t s = 0; s < bond_sets_.size(); ++s) {
    if (pass_sets_[s] == 0) continue;  // in an earlier set's pass
    const BondSet& set = *bond_sets_[s];
    std::string names = set.name;
    for (std::size_t k = 1; k < pass_sets_[s]; ++k) names += ", " + bond_sets_[s + k]->name;
    const std::string pass = set.colours() > 0 ? std::to_string(set.colours()) + " colours"
                             : pass_sets_[s] > 1 ? "gather, one pass" : "gather";
    phase_.bonds[s] = profile->phase("bonds " + names + " (" + std::string(set.law()) + ", " + pass + ")");
  }
  if (contact_) phase_.contacts = profile->phase("contacts");
  if (failure_on_) phase_.failure = profile->phase("failure scan and breaks");
  if (!watched_.empty()) phase_.reactions = profile->phase("group reactions");
  phase_.loads = profile->phase("loads and damping");
  phase_.finite = profile->phase("finite check");
}

void DemModel::step(double dt) {
  advance_to_forces(dt);
  finish_step(dt);
}

void DemModel::advance_to_forces(double dt) {
  last_dt_ = dt;
  const bool particles_threaded = particle_loops_threaded();
  {
    // Work of kinematic conditions = the driven DEs' kinetic energy change (here and at the
    // end of the step) + the work of their reactions (record_reactions).
    const PhaseTimer timer(profile_, phase_.boundary, false);
    external_work_ -= driven_kinetic_energy();
  }
  {
    const PhaseTimer timer(profile_, phase_.kick, particles_threaded);
    kick(0.5 * dt);                   // v(n+1/2) = v(n) + dt/2 a(n)
  }
  {
    const PhaseTimer timer(profile_, phase_.boundary, false);
    impose_motion(time_, true, dt);   // driven DEs move exactly by u(t+dt) - u(t)
  }
  {
    const PhaseTimer timer(profile_, phase_.drift, particles_threaded);
    drift(dt);                        // x(n+1) = x(n) + dt v(n+1/2); q(n+1) = exp(dt w) q(n); f = 0
  }
  time_ += dt;
  {
    const PhaseTimer timer(profile_, phase_.neighbours, particles_threaded);
    update_neighbours();              // only with contact, once two DEs may have closed the skin
  }
  // Bonds, contacts -> f(n+1); breakable: also each bond's failure measure or virial; before
  // an output row: also each bond's energy.
  ForceScan scan = failure_on_ ? failure_scan() : ForceScan{};
  scan.energy = std::exchange(energy_record_requested_, false);
  // Friction's power at the half-step velocities, over the step (as the damping's work).
  dissipated_ += dt * compute_forces(scan, true);
  if (failure_on_) apply_failures(scan.energy);  // BBF / RDEF: break bonds, forces again if any broke
  energy_record_step_ = scan.energy ? steps_ + 1 : -1;
  record_reactions();                 // for sensors, and the work of driven DEs
  {
    const PhaseTimer timer(profile_, phase_.loads, particles_threaded && damping_ > 0.0);
    apply_loads_and_damping();        // dead loads, viscous damping
  }
}

void DemModel::finish_step(double dt) {
  {
    const PhaseTimer timer(profile_, phase_.kick, particle_loops_threaded());
    kick(0.5 * dt);                   // v(n+1) = v(n+1/2) + dt/2 a(n+1)
  }
  const PhaseTimer timer(profile_, phase_.boundary, false);
  impose_motion(time_, false, dt);    // driven DEs: v = du/dt(t(n+1))
  external_work_ += driven_kinetic_energy();
  ++steps_;
}

void DemModel::apply_arlequin_weight(const std::function<double(const Vec3&)>& alpha, double mass_floor) {
  ParticleSet& p = particles;
  contact_weight_.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    contact_weight_[i] = alpha(p.position[i]);
    p.inv_mass[i] /= std::max(contact_weight_[i], mass_floor);
  }
  std::vector<double> factor;
  for (auto& set : bond_sets_) {
    factor.resize(set->size());
    for (std::size_t b = 0; b < set->size(); ++b)
      factor[b] = alpha(0.5 * (p.position[set->first()[b]] + p.position[set->second()[b]]));
    set->scale_stiffness(factor);
  }
}

void DemModel::hold_failures(const std::function<bool(std::size_t, std::size_t)>& held) {
  held_.resize(bond_sets_.size());
  for (std::size_t s = 0; s < bond_sets_.size(); ++s) {
    held_[s].assign(bond_sets_[s]->size(), 0);
    for (std::size_t b = 0; b < held_[s].size(); ++b) held_[s][b] = held(s, b) ? 1 : 0;
  }
}

void DemModel::kick(double half_dt) {
  ParticleSet& p = particles;
  const long n = static_cast<long>(p.size());
  const auto kick_one = [&p, half_dt](long i) {
    p.velocity[i] += p.force[i] * (half_dt * p.inv_mass[i]);
    p.angular_velocity[i] += p.torque[i] * (half_dt * p.inv_inertia(i));
  };
  if (!(damping_ > 0.0)) {  // no damping work to account for: a plain loop
    for_each_index(n, n > parallel_threshold, kick_one);
    return;
  }
  // A half kick changes a DE's kinetic energy by h F . (v + v')/2 exactly; the damping
  // force's share of that is the energy it dissipated.
  dissipated_ += fixed_order_sum(n, parallel_threshold, kick_partial_, [&](long i) {
    const Vec3 v = p.velocity[i], w = p.angular_velocity[i];
    kick_one(i);
    return -half_dt * (dot(damping_force_[i], 0.5 * (v + p.velocity[i])) +
                       dot(damping_torque_[i], 0.5 * (w + p.angular_velocity[i])));
  });
}

void DemModel::impose_motion(double t, bool half_step, double dt) {
  // Each condition's velocity once, then its DEs'.
  for (std::size_t k = 0; k < boundaries_.size(); ++k) {
    const BoundaryCondition& bc = boundaries_[k];
    if (bc.kinematic())
      condition_velocity_[k] = half_step ? (bc.displacement_at(t + dt) - bc.displacement_at(t)) / dt : bc.velocity_at(t);
  }
  for (const std::uint32_t k : moving_constraints_) impose(constraints_[k], condition_velocity_[constraints_[k].condition]);
  for (const std::uint32_t k : still_constraints_) impose(constraints_[k], Vec3{});
}

void DemModel::impose(const Constraint& c, const Vec3& v) {
  for (int k = 0; k < 3; ++k)
    if (c.imposed >> k & 1) particles.velocity[c.particle][k] = v[k];
  if (c.imposed & 8) particles.angular_velocity[c.particle] = {};
}

double DemModel::driven_kinetic_energy() const {
  // Still conditions' DEs are at rest along their imposed components: no term.
  double e = 0.0;
  for (const std::uint32_t index : moving_constraints_) {
    const Constraint& c = constraints_[index];
    const Vec3& v = particles.velocity[c.particle];
    for (int k = 0; k < 3; ++k)
      if (c.imposed >> k & 1) e += 0.5 * c.mass * v[k] * v[k];
  }
  return e;
}

void DemModel::drift(double dt) {
  ParticleSet& p = particles;
  const long n = static_cast<long>(p.size());
  // Each thread its share, in vector lanes: a DE's bits do not depend on the DEs that share its
  // lanes (ParticleSet::drift), so not on the thread count.
  run_threaded_if(n > parallel_threshold, [&p, n, dt] {
    const IndexRange share = thread_share(n);
    p.drift(share.begin, share.end, dt);
  });
  // For the force pass, in a pass of its own: inside the loop above, its stores took most of the
  // drift's time (docs/performance.md#clearing-forces).
  p.clear_forces();
}

void DemModel::update_neighbours() {
  if (neighbours_ && neighbours_->needs_rebuild(particles)) neighbours_->build(particles);
}

double DemModel::compute_forces(const ForceScan& scan, bool cleared) {
  if (pass_sets_.size() != bond_sets_.size()) throw std::logic_error("DemModel: a force pass before finalize()");
  if (!cleared) particles.clear_forces();
  for (std::size_t s = 0; s < bond_sets_.size(); s += pass_sets_[s]) {
    const std::span<const BondSet* const> pass(&set_pointers_[s], pass_sets_[s]);
    const bool together = pass.size() > 1;
    const bool threaded = together ? gathered_pass_threaded(pass, particles.size()) : bond_sets_[s]->runs_on_threads();
    const PhaseTimer timer(profile_, profile_ ? phase_.bonds[s] : 0, runs_threaded(threaded));
    if (together) accumulate_gathered_forces(pass, particles, scan);
    else bond_sets_[s]->accumulate_forces(particles, scan);
  }
  if (!contact_) return 0.0;
  const PhaseTimer timer(profile_, phase_.contacts, false);
  std::fill(touching_.begin(), touching_.end(), 0u);
  deepest_contact_ = contact_->accumulate_forces(*neighbours_, particles, touching_, contact_weight_);
  return deepest_contact_.friction_power;
}

ForceScan DemModel::failure_scan() {
  ForceScan scan;
  scan.criterion = true;
  if (rdef_) rdef_->scan_into(scan);
  return scan;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> DemModel::intact_bonded_pairs() const {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (const auto& set : bond_sets_)
    for (std::size_t b = 0; b < set->size(); ++b)
      if (!set->broken()[b]) pairs.emplace_back(set->first()[b], set->second()[b]);
  return pairs;
}

void DemModel::apply_failures(bool record_energy) {
  {
    const PhaseTimer timer(profile_, phase_.failure, false);
    if (!break_failed_bonds()) return;
  }
  ForceScan scan;
  scan.energy = record_energy;
  compute_forces(scan);
}

bool DemModel::break_failed_bonds() {
  new_breaks_.clear();
  for (std::size_t s = 0; s < bond_sets_.size(); ++s)
    bond_sets_[s]->find_failures(particles, static_cast<std::uint32_t>(s), time_, new_breaks_);
  if (rdef_) rdef_->find_failures(particles, bond_sets_, time_, new_breaks_);
  if (new_breaks_.empty()) return false;
  bool broke = false;
  for (const BreakEvent& e : new_breaks_) {
    BondSet& set = *bond_sets_[e.set];
    if (set.broken()[e.bond]) continue;  // reported twice (BBF and RDEF): break once
    if (!held_.empty() && held_[e.set][e.bond] != 0) {
      if (held_[e.set][e.bond] == 1) held_failures_.push_back(e);
      held_[e.set][e.bond] = 2;
      continue;
    }
    set.break_bond(e.bond);
    fracture_ += e.energy;
    breaks_.push_back(e);
    broke = true;
  }
  if (!broke) return false;
  // Former partners now meet by contact; the step's forces (and the energy record) are
  // recomputed without the bonds.
  if (neighbours_) {
    neighbours_->set_exclusions(intact_bonded_pairs());
    neighbours_->build(particles);
  }
  return true;
}

std::vector<Sym3> DemModel::virial_stress(double compaction) const {
  // sigma_i = 1/(2 Omega_i) sum_j sym(r_ij (x) f_ij) (failure.hpp, seed Eq. 1), r_ij / 2 the branch.
  std::vector<Sym3> sigma(particles.size(), Sym3{});
  for (const auto& set : bond_sets_) set->accumulate_virial(particles, VirialBranch::half, sigma);
  divide_by_volumes(sphere_volume_shares(particles, compaction), sigma);
  return sigma;
}

std::vector<double> DemModel::damage() const {
  std::vector<double> bonds(particles.size(), 0.0), broken(particles.size(), 0.0);
  for (const auto& set : bond_sets_)
    for (std::size_t b = 0; b < set->size(); ++b)
      for (std::uint32_t i : {set->first()[b], set->second()[b]}) {
        bonds[i] += 1.0;
        broken[i] += set->broken()[b];
      }
  for (std::size_t i = 0; i < bonds.size(); ++i) broken[i] = bonds[i] > 0.0 ? broken[i] / bonds[i] : 0.0;
  return broken;
}

void DemModel::record_reactions() {
  const ParticleSet& p = particles;
  if (!watched_.empty()) {
    const PhaseTimer timer(profile_, phase_.reactions, false);
    for (const int g : watched_) reaction_[g] = {};
    for (const auto& [i, group] : watched_members_) reaction_[group] -= p.force[i];
  }
  const PhaseTimer timer(profile_, phase_.boundary, false);
  // Reaction R = -(bond + contact forces) on each driven DE; over the drift it did the
  // trapezoidal work (R(n) + R(n+1))/2 . dt v(n+1/2).
  // Only the imposed components: forces along free ones move the DE like any other. A still
  // condition's reactions do no work: its DEs do not move along them.
  for (const std::uint32_t k : moving_constraints_) {
    const std::uint32_t i = constraints_[k].particle;
    Vec3 reaction{};
    for (int d = 0; d < 3; ++d)
      if (constraints_[k].imposed >> d & 1) reaction[d] = -p.force[i][d];
    external_work_ += dot(0.5 * (reaction + constraint_reaction_[k]), p.velocity[i]) * last_dt_;
    constraint_reaction_[k] = reaction;
  }
}

void DemModel::apply_loads_and_damping() {
  ParticleSet& p = particles;
  for (std::size_t k = 0; k < loaded_.size(); ++k) {
    const std::uint32_t i = loaded_[k].particle;
    p.force[i] += load_per_particle_[k];
    external_work_ += dot(load_per_particle_[k], p.velocity[i]) * last_dt_;
  }
  if (gravity_ != Vec3{}) {
    const long n = static_cast<long>(p.size());
    for_each_index(n, n > parallel_threshold, [&](long i) {
      for (int k = 0; k < 3; ++k)
        if (!imposes(i, k)) p.force[i][k] += p.mass(i) * gravity_[k];
    });
  }
  if (damping_ > 0.0) {
    // Viscous damping from the half-step velocity, none on imposed components; split over the
    // threads as the kicks.
    const long n = static_cast<long>(p.size());
    for_each_index(n, n > parallel_threshold, [&](long i) {
      damping_force_[i] = p.velocity[i] * (-damping_ * p.mass(i));
      for (int k = 0; k < 3; ++k)
        if (imposes(i, k)) damping_force_[i][k] = 0.0;
      damping_torque_[i] = (driven_[i] & 8) ? Vec3{} : p.angular_velocity[i] * (-damping_ * p.inertia(i));
      p.force[i] += damping_force_[i];
      p.torque[i] += damping_torque_[i];
    });
  }
}

void DemModel::use_energy_record() const {
  if (energy_record_step_ == steps_) return;  // the last step's force pass recorded them
  for (const auto& set : bond_sets_) set->record_energies(particles);
}

double DemModel::particle_kinetic_energy(std::size_t i) const {
  const ParticleSet& p = particles;
  return 0.5 * (p.mass(i) * norm2(p.velocity[i]) + p.inertia(i) * norm2(p.angular_velocity[i]));
}

double DemModel::kinetic_energy() const {
  double e = 0.0;
  for (std::size_t i = 0; i < particles.size(); ++i) e += particle_kinetic_energy(i);
  return e;
}

double DemModel::kinetic_energy(std::span<const std::uint32_t> ids) const {
  double e = 0.0;
  for (const std::uint32_t i : ids) e += particle_kinetic_energy(i);
  return e;
}

double DemModel::arrest(std::span<const std::uint32_t> ids) {
  const double before = kinetic_energy(ids);
  for (const std::uint32_t i : ids) {
    for (int k = 0; k < 3; ++k)
      if (!imposes(i, k)) particles.velocity[i][k] = 0.0;
    if (!(driven_[i] & 8u)) particles.angular_velocity[i] = Vec3{};
  }
  const double removed = before - kinetic_energy(ids);
  dissipated_ += removed;
  return removed;
}

void DemModel::relaxation_kick(double h, std::span<const Vec3> force_offset, std::span<const Vec3> torque_offset) {
  ParticleSet& p = particles;
  const long n = static_cast<long>(p.size());
  for_each_index(n, n > parallel_threshold, [&](long i) {
    p.velocity[i] += (p.force[i] - force_offset[i]) * (h * p.inv_mass[i]);
    p.angular_velocity[i] += (p.torque[i] - torque_offset[i]) * (h * p.inv_inertia(i));
    for (int k = 0; k < 3; ++k)
      if (imposes(i, k)) p.velocity[i][k] = 0.0;
    if (driven_[i] & 8u) p.angular_velocity[i] = Vec3{};
  });
}

void DemModel::relaxation_drift(double dt) {
  drift(dt);
  update_neighbours();
  compute_forces({}, true);
  apply_loads_and_damping();
}

void DemModel::stop_motion() {
  std::fill(particles.velocity.begin(), particles.velocity.end(), Vec3{});
  std::fill(particles.angular_velocity.begin(), particles.angular_velocity.end(), Vec3{});
}

double DemModel::round_off_kinetic_energy(double time) const {
  double extent = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const Vec3& x = particles.position[i];
    extent = std::max({extent, std::abs(x.x), std::abs(x.y), std::abs(x.z)});
    mass += particles.mass(i);
  }
  const double speed = std::numeric_limits<double>::epsilon() * extent / time;
  return 0.5 * mass * speed * speed;
}

Energies DemModel::energies() const {
  Energies e;
  e.kinetic = kinetic_energy();
  use_energy_record();
  for (const auto& set : bond_sets_) e.bond += set->recorded_energy();
  if (contact_) e.contact = contact_->energy(*neighbours_, particles, contact_weight_);
  e.external_work = external_work_;
  // Gravity is conservative: its work is the drop of m g . x, exact whatever the path (driven
  // components excluded: gravity does not act on them).
  if (gravity_ != Vec3{})
    for (std::size_t i = 0; i < particles.size(); ++i)
      for (int k = 0; k < 3; ++k)
        if (!imposes(i, k))
          e.external_work += particles.mass(i) * gravity_[k] * (particles.position[i][k] - particles.reference[i][k]);
  e.dissipated = dissipated_;
  e.fracture = fracture_;
  // Cohesive links still intact have dissipated part of their toughness; a failed link's share
  // is in fracture_ already (its break event).
  for (const auto& set : bond_sets_) {
    const auto dissipated = set->dissipated_values();
    const auto broken = set->broken();
    for (std::size_t b = 0; b < dissipated.size(); ++b)
      if (!broken[b]) e.fracture += dissipated[b];
  }
  return e;
}

template <class Value>
Vec3 DemModel::group_mean(int group, Value value) const {
  Vec3 sum{};
  const auto& ids = group_members_[group];
  for (const std::uint32_t i : ids) sum += value(i);
  return ids.empty() ? Vec3{} : sum / static_cast<double>(ids.size());
}

Vec3 DemModel::mean_displacement(int group) const {
  return group_mean(group, [&](std::size_t i) { return particles.position[i] - particles.reference[i]; });
}

double DemModel::group_energy(int group) const {
  use_energy_record();
  bond_energy_share_.assign(particles.size(), 0.0);
  for (const auto& set : bond_sets_) set->add_recorded_energy_per_particle(bond_energy_share_);
  double e = 0.0;
  for (const std::uint32_t i : group_members_[group]) e += bond_energy_share_[i] + particle_kinetic_energy(i);
  return e;
}

Vec3 DemModel::mean_velocity(int group) const {
  return group_mean(group, [&](std::size_t i) { return particles.velocity[i]; });
}

namespace {
// A DE's row of the frequency bound with the contacts touching it now (its bonds' row plus each
// contact's), 1/s^2; 0 for a DE that touches none (its bonds alone were checked at set-up). A
// select, not a branch: whether a DE touches another is a coin toss in a packing.
inline double crowding_bound(double bonds, double per_contact, std::uint32_t touching) {
  return touching > 0 ? bonds + per_contact * touching : 0.0;
}
}  // namespace

void DemModel::check_finite() const {
  const ParticleSet& p = particles;
  const long n = static_cast<long>(p.size());
  const PhaseTimer timer(profile_, phase_.finite, particle_loops_threaded());
  // Each thread's share of the DEs (split as the kicks) in a vectorised pass that only finds
  // whether a velocity is not finite (x - x is 0 for a finite x, NaN otherwise; a sum of them is
  // NaN if any is) and, with contact, the largest |v|^2 / R^2 and frequency bound: maxima and
  // that test do not depend on the order of the terms. Only when the step fails a check does
  // diagnose() take the DEs again, in order, to name them.
  const Vec3* v = p.velocity.data();
  const Vec3* w = p.angular_velocity.data();
  const double* radius = p.radius.data();
  const std::uint32_t* touching = touching_.data();
  const double* bond_bound = bond_frequency_bound_.data();
  const double* contact_bound = contact_bound_each_.data();
  const bool contact = contact_ != nullptr;
  const auto probe_of = [v, w](long i) {
    return ((v[i].x - v[i].x) + (v[i].y - v[i].y) + (v[i].z - v[i].z)) + ((w[i].x - w[i].x) + (w[i].y - w[i].y) + (w[i].z - w[i].z));
  };
  const long shares = scan_thread_shares(n, parallel_threshold, finite_shares_, [&](long begin, long end) {
    double probe = 0.0, reach2 = 0.0, omega2 = 0.0;
    if (contact) {
#pragma omp simd reduction(+ : probe) reduction(max : reach2, omega2)
      for (long i = begin; i < end; ++i) {
        probe += probe_of(i);
        reach2 = std::max(reach2, norm2(v[i]) / (radius[i] * radius[i]));
        omega2 = std::max(omega2, crowding_bound(bond_bound[i], contact_bound[i], touching[i]));
      }
    } else {
#pragma omp simd reduction(+ : probe)
      for (long i = begin; i < end; ++i) probe += probe_of(i);
    }
    return FiniteScan{!(probe == 0.0), reach2, omega2};
  });
  FiniteScan all;
  for (long t = 0; t < shares; ++t) {
    const FiniteScan& scan = finite_shares_[static_cast<std::size_t>(t)];
    all.bad = all.bad || scan.bad;
    all.reach2 = std::max(all.reach2, scan.reach2);
    all.omega2 = std::max(all.omega2, scan.omega2);
  }
  if (all.bad || (contact && fails_contact_resolution(std::sqrt(all.reach2) * last_dt_, all.omega2))) diagnose();
}

bool DemModel::fails_contact_resolution(double reach, double omega2) const {
  const double dt = last_dt_;
  return reach > 1.0 || deepest_contact_.deepest > 1.0 || omega2 * dt * dt + 2.0 * damping_ * dt >= 4.0;
}

void DemModel::diagnose() const {
  const ParticleSet& p = particles;
  std::size_t bad = 0, first = 0;
  ContactResolution worst;  // with contact: the fastest and the most crowded DE, the first of equals
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!is_finite(p.velocity[i]) || !is_finite(p.angular_velocity[i])) {
      if (bad++ == 0) first = i;
    }
    if (!contact_) continue;
    if (const double r = norm(p.velocity[i]) * last_dt_ / p.radius[i]; r > worst.reach) worst.reach = r, worst.fastest = i;
    if (const double row = crowding_bound(bond_frequency_bound_[i], contact_bound_each_[i], touching_[i]); row > worst.omega2)
      worst.omega2 = row, worst.crowded = i;
  }
  if (bad == 0 && contact_) check_contact_resolution(worst);
  if (bad == 0) return;
  std::ostringstream msg;
  msg << "step " << steps_ << " (t = " << time_ << " s): " << bad << " DE(s) have a non-finite velocity, "
      << "the first is DE " << first << " at (" << p.reference[first].x << ", " << p.reference[first].y << ", "
      << p.reference[first].z << ") m; likely cause: a time step above the stability limit, or an initial "
         "overlap far too deep for the contact stiffness";
  throw RunError(msg.str());
}

void DemModel::check_contact_resolution(const ContactResolution& worst) const {
  // Moving more than its radius in a step, a DE can cross a contact without the contact ever
  // seeing it; the penalty holds an impact only if the overlap stays inside the spheres; and a
  // DE that touches more DEs than at set-up (an impact packing them together) raises the
  // highest frequency above the one the step was set for (the bound of critical_time_step
  // with its contacts now: stable while omega^2 dt^2 + 2 c dt < 4).
  const ContactPass& c = deepest_contact_;
  const double dt = last_dt_;
  if (!fails_contact_resolution(worst.reach, worst.omega2)) return;
  const ParticleSet& p = particles;
  const auto at = [&p](std::size_t i) {
    std::ostringstream where;
    where << "DE " << i << " at (" << p.position[i].x << ", " << p.position[i].y << ", " << p.position[i].z << ") m";
    return where.str();
  };
  std::ostringstream msg;
  msg << "step " << steps_ << " (t = " << time_ << " s): ";
  if (worst.reach > 1.0) {
    const std::size_t i = worst.fastest;
    msg << at(i) << " moves " << worst.reach << " of its radius per step (" << norm(p.velocity[i])
        << " m/s): a contact can be crossed unseen; lower the time step (time.safety or time.dt) below "
        << p.radius[i] / norm(p.velocity[i]) << " s";
  } else if (c.deepest > 1.0) {
    msg << "the contact of DEs " << c.first << " and " << c.second << " overlaps " << c.deepest
        << " of the smaller radius: the contact stiffness (" << contact_->stiffness()
        << " N/m) is too soft to stop this impact within the spheres (an impact of energy E needs about "
           "K >= 2 E / R^2); raise dem.contact.stiffness";
  } else {
    const double limit = damped_critical_step(worst.omega2, damping_);
    msg << at(worst.crowded) << " touches " << touching_[worst.crowded] << " DEs at once: with its bonds and "
        << contact_->stiffness() << " N/m per contact its critical step is " << limit << " s, below the step " << dt
        << " s set for the contacts at set-up (likely cause: an impact packing DEs together); lower the time step "
           "(time.safety or time.dt) below " << limit << " s";
  }
  throw RunError(msg.str());
}

void DemModel::check_energy(double energy_limit) const {
  const ParticleSet& p = particles;
  std::size_t fastest = 0;
  double fastest_energy = -1.0, kinetic = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double e = particle_kinetic_energy(i);
    kinetic += e;
    if (e > fastest_energy) fastest_energy = e, fastest = i;
  }
  if (kinetic <= energy_limit) return;
  std::ostringstream msg;
  msg << "step " << steps_ << " (t = " << time_ << " s): kinetic energy " << kinetic
      << " J exceeds the blow-up limit " << energy_limit << " J (fastest DE: " << fastest << " at ("
      << p.position[fastest].x << ", " << p.position[fastest].y << ", " << p.position[fastest].z
      << ") m); likely cause: a time step too close to the stability limit for the stiffest bond or "
         "contact";
  if (damping_ > 0.0) msg << " or for the viscous damping (c dt = " << damping_ * last_dt_ << ", stable below 2)";
  msg << ", or energy injected by boundary conditions";
  throw RunError(msg.str());
}

void DemModel::save_events(StateArchive& archive, const std::string& prefix, const std::vector<BreakEvent>& events) {
  std::vector<double> time, stress, energy, mode_mix;
  std::vector<std::uint32_t> set, bond, criterion, mode;
  for (const BreakEvent& e : events) {
    time.push_back(e.time), stress.push_back(e.stress), energy.push_back(e.energy), mode_mix.push_back(e.mode_mix);
    set.push_back(e.set), bond.push_back(e.bond);
    criterion.push_back(static_cast<std::uint32_t>(e.criterion)), mode.push_back(static_cast<std::uint32_t>(e.mode));
  }
  for (const auto& [name, values] : {std::pair{"time", &time}, {"stress", &stress}, {"energy", &energy}, {"mode_mix", &mode_mix}})
    archive.put(prefix + name, *values);
  for (const auto& [name, values] : {std::pair{"set", &set}, {"bond", &bond}, {"criterion", &criterion}, {"mode", &mode}})
    archive.put(prefix + name, *values);
}

std::vector<BreakEvent> DemModel::load_events(const StateArchive& archive, const std::string& prefix,
                                              const std::function<bool(const BreakEvent&)>& consistent, const char* what) const {
  const auto time = archive.get<double>(prefix + "time"), stress = archive.get<double>(prefix + "stress"),
             energy = archive.get<double>(prefix + "energy"), mode_mix = archive.get<double>(prefix + "mode_mix");
  const auto set = archive.get<std::uint32_t>(prefix + "set"), bond = archive.get<std::uint32_t>(prefix + "bond"),
             criterion = archive.get<std::uint32_t>(prefix + "criterion"), mode = archive.get<std::uint32_t>(prefix + "mode");
  const std::size_t n = time.size();
  for (const std::size_t size : {stress.size(), energy.size(), mode_mix.size(), set.size(), bond.size(), criterion.size(), mode.size()})
    if (size != n) throw StateMismatch("its break records have columns of different lengths");
  std::vector<BreakEvent> events;
  for (std::size_t k = 0; k < n; ++k) {
    const BreakEvent e{time[k], set[k], bond[k], static_cast<FailureCriterion>(criterion[k]), static_cast<FailureMode>(mode[k]),
                       stress[k], energy[k], mode_mix[k]};
    if (set[k] >= bond_sets_.size() || bond[k] >= bond_sets_[set[k]]->size() || !consistent(e) ||
        criterion[k] > static_cast<std::uint32_t>(FailureCriterion::cohesive) || mode[k] > static_cast<std::uint32_t>(FailureMode::torsion))
      throw StateMismatch("its break record " + std::to_string(k) + " names a bond this scene does not have " + what);
    events.push_back(e);
  }
  return events;
}

void DemModel::save_state(StateArchive& archive) const {
  const ParticleSet& p = particles;
  for (const auto& [name, values] : {std::pair{"reference", &p.reference}, {"position", &p.position}, {"velocity", &p.velocity},
                                     {"angular_velocity", &p.angular_velocity}, {"force", &p.force}, {"torque", &p.torque}})
    archive.put("dem/particles/" + std::string(name), *values);
  archive.put("dem/particles/orientation", p.orientation);
  archive.put("dem/particles/radius", p.radius);
  archive.put("dem/particles/inv_mass", p.inv_mass);
  for (std::size_t s = 0; s < bond_sets_.size(); ++s) bond_sets_[s]->save_state(archive, "dem/bonds/" + std::to_string(s) + "/");
  if (neighbours_) neighbours_->save_state(archive, "dem/neighbours/");
  save_events(archive, "dem/breaks/", breaks_);
  if (!held_.empty()) save_events(archive, "dem/held_failures/", held_failures_);
  archive.put("dem/constraint_reaction", constraint_reaction_);
  archive.put("dem/damping_force", damping_force_);
  archive.put("dem/damping_torque", damping_torque_);
  archive.put("dem/reaction", std::span<const Vec3>(reaction_));
  archive.put("dem/time", time_);
  archive.put("dem/last_dt", last_dt_);
  archive.put("dem/steps", std::int64_t{steps_});
  archive.put("dem/external_work", external_work_);
  archive.put("dem/dissipated", dissipated_);
  archive.put("dem/fracture", fracture_);
  archive.put("dem/energy_record_requested", std::int64_t{energy_record_requested_});
  archive.put("dem/energy_record_step", std::int64_t{energy_record_step_});
}

void DemModel::load_state(const StateArchive& archive) {
  ParticleSet& p = particles;
  // The scene must be the one the checkpoint left: same DEs, to the bit.
  for (const auto& [name, values] : {std::pair{"radius", &p.radius}, {"inv_mass", &p.inv_mass}})
    if (archive.get<double>("dem/particles/" + std::string(name)) != *values)
      throw StateMismatch("its DEs' " + std::string(name) + " differ from this scene's");
  if (archive.get<Vec3>("dem/particles/reference") != p.reference)
    throw StateMismatch("its DEs' reference positions differ from this scene's");
  for (const auto& [name, values] : {std::pair{"position", &p.position}, {"velocity", &p.velocity},
                                     {"angular_velocity", &p.angular_velocity}, {"force", &p.force}, {"torque", &p.torque}})
    archive.get_into("dem/particles/" + std::string(name), *values);
  archive.get_into("dem/particles/orientation", p.orientation);
  for (std::size_t s = 0; s < bond_sets_.size(); ++s) bond_sets_[s]->load_state(archive, "dem/bonds/" + std::to_string(s) + "/");
  if (archive.has("dem/bonds/" + std::to_string(bond_sets_.size()) + "/first"))
    throw StateMismatch("it has more bond sets than this scene's " + std::to_string(bond_sets_.size()));
  if (neighbours_) {
    neighbours_->set_exclusions(intact_bonded_pairs());
    neighbours_->load_state(archive, "dem/neighbours/", p.size());
  }
  breaks_ = load_events(archive, "dem/breaks/", [this](const BreakEvent& e) { return bond_sets_[e.set]->broken()[e.bond] != 0; },
                        "broken");
  if (!held_.empty()) {
    held_failures_ = load_events(archive, "dem/held_failures/",
                                 [this](const BreakEvent& e) { return !bond_sets_[e.set]->broken()[e.bond] && held_[e.set][e.bond] != 0; },
                                 "held");
    for (const BreakEvent& e : held_failures_) held_[e.set][e.bond] = 2;
  }
  archive.get_into("dem/constraint_reaction", constraint_reaction_);
  archive.get_into("dem/damping_force", damping_force_);
  archive.get_into("dem/damping_torque", damping_torque_);
  archive.get_into("dem/reaction", std::span<Vec3>(reaction_));
  time_ = archive.number("dem/time");
  last_dt_ = archive.number("dem/last_dt");
  steps_ = archive.integer("dem/steps");
  external_work_ = archive.number("dem/external_work");
  dissipated_ = archive.number("dem/dissipated");
  fracture_ = archive.number("dem/fracture");
  energy_record_requested_ = archive.integer("dem/energy_record_requested") != 0;
  energy_record_step_ = archive.integer("dem/energy_record_step");
}

}  // namespace arlequin::dem
