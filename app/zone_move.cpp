// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/zone_move.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <tuple>
#include <unordered_map>

#include "common/error.hpp"
#include "dem/crack_front.hpp"

namespace arlequin::app {
namespace {

using Key = std::tuple<double, double, double>;
Key key_of(const Vec3& x) { return {x.x, x.y, x.z}; }

std::string exact(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

// The DEM's cohesive interface, the bond set a following band measures its crack on (-1: none).
int interface_set(const dem::DemModel& dem) { return dem.bond_set_index("interface"); }

const BandFollow& follow_of(const Scene& scene) { return *scene.continuum->band_follow(); }

dem::CrackFront crack_of(const Scene& scene) {
  const BandFollow& f = follow_of(scene);
  Vec3 along{}, across{};
  along[f.along] = 1.0;
  across[3 - f.axis - f.along] = 1.0;
  return dem::measure_crack(*scene.dem.bond_sets()[interface_set(scene.dem)], scene.dem.particles, along, across, 8);
}

// What the case's own band gives the interface: its area (0: none given) and the join's box.
struct CaseShares {
  double area = 0.0;
  std::optional<Box> join;
  double lower = -INFINITY, upper = INFINITY;  // the packing region's extent along the band, m
};

CaseShares case_shares(const Scene& first) {
  CaseShares out;
  const BandFollow& f = follow_of(first);
  const YAML::Node root = YAML::Load(first.resolved_case);
  if (const YAML::Node area = root["dem"]["interface"]["bond"]["area"]) out.area = area.as<double>();
  if (const YAML::Node join = root["continuum"]["mesh"]["join"]) {
    const YAML::Node box = join["box"];
    if (!box || join.size() != 1)
      throw InputError(f.where + ": a following band moves the continuum's join with its end: expected continuum.mesh.join: "
                                 "{box: [[x0, y0, z0], [x1, y1, z1]]}");
    const auto corner = [&box](int k) { return Vec3{box[k][0].as<double>(), box[k][1].as<double>(), box[k][2].as<double>()}; };
    out.join = Box{corner(0), corner(1)};
  }
  if (first.sample)
    if (const auto* region = std::get_if<Box>(&first.sample->spec.region.shape()))
      out.lower = region->lower[f.along], out.upper = region->upper[f.along];
  return out;
}

double length_inside(double from, double to, const CaseShares& c) { return std::min(to, c.upper) - std::max(from, c.lower); }

// `out` with its row r replaced by row map[r] of `src` where map[r] >= 0 (same layout).
StateArchive::Entry rows_from(const StateArchive::Entry& src, const std::vector<long>& map, StateArchive::Entry out,
                              const std::string& name) {
  if (src.kind != out.kind || src.width != out.width || out.rows != map.size())
    throw std::logic_error("zone move: '" + name + "' differs in layout between the two scenes");
  const std::size_t row = out.width * element_size(out.kind);
  for (std::size_t r = 0; r < map.size(); ++r)
    if (map[r] >= 0) std::memcpy(out.bytes.data() + r * row, src.bytes.data() + static_cast<std::size_t>(map[r]) * row, row);
  return out;
}

// Row r of `to`'s entry `name` becomes row map[r] of `from`'s where map[r] >= 0.
void carry_rows(const StateArchive& from, StateArchive& to, const std::string& name, const std::vector<long>& map) {
  to.put_entry(name, rows_from(from.entries().at(name), map, to.entries().at(name), name));
}

void carry_entry(const StateArchive& from, StateArchive& to, const std::string& name) { to.put_entry(name, from.entries().at(name)); }

// Row r of `archive`'s entry `name` to zero where zero[r].
void zero_rows(StateArchive& archive, const std::string& name, const std::vector<char>& zero) {
  StateArchive::Entry entry = archive.entries().at(name);
  const std::size_t row = entry.width * element_size(entry.kind);
  for (std::size_t r = 0; r < zero.size(); ++r)
    if (zero[r]) std::memset(entry.bytes.data() + r * row, 0, row);
  archive.put_entry(name, std::move(entry));
}

// The break records under `prefix` of the bonds both scenes have, renumbered; their count.
std::size_t carry_events(const StateArchive& from, StateArchive& to, const std::string& prefix,
                         const std::vector<std::vector<long>>& new_bond_of_old) {
  const auto set = from.get<std::uint32_t>(prefix + "set"), bond = from.get<std::uint32_t>(prefix + "bond");
  std::vector<long> kept;
  std::vector<std::uint32_t> renumbered;
  for (std::size_t k = 0; k < set.size(); ++k)
    if (const long b = new_bond_of_old[set[k]][bond[k]]; b >= 0) kept.push_back(static_cast<long>(k)), renumbered.push_back(static_cast<std::uint32_t>(b));
  for (const char* column : {"time", "stress", "energy", "mode_mix", "set", "criterion", "mode"}) {
    const StateArchive::Entry& src = from.entries().at(prefix + column);
    StateArchive::Entry out{src.kind, src.width, kept.size(), std::vector<std::byte>(kept.size() * src.width * element_size(src.kind))};
    to.put_entry(prefix + column, rows_from(src, kept, std::move(out), prefix + column));
  }
  to.put(prefix + "bond", renumbered);
  return kept.size();
}

// The rotation of F (polar decomposition) as a quaternion, and the spin of dF/dt F^-1.
std::pair<Quat, Vec3> rotation_and_spin(const Eigen::Matrix3d& F, const Eigen::Matrix3d& F_dot) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  const Eigen::AngleAxisd turn(R);
  const Eigen::Vector3d phi = turn.angle() * turn.axis();
  const Eigen::Matrix3d L = F_dot * F.inverse();
  const Eigen::Matrix3d W = 0.5 * (L - L.transpose());
  return {from_rotation_vector({phi.x(), phi.y(), phi.z()}), Vec3{W(2, 1), W(0, 2), W(1, 0)}};
}

// sum over a of N_a(x_p) f_a for each point's shape values (f: 3 values a node).
std::vector<Vec3> interpolate(const ContinuumPart::ShapeValues& rows, const std::vector<double>& f) {
  std::vector<Vec3> out(rows.size());
  for (std::size_t p = 0; p < rows.size(); ++p)
    for (const auto& [a, N] : rows[p]) out[p] += N * Vec3{f[3 * a], f[3 * a + 1], f[3 * a + 2]};
  return out;
}

// The new DEs' motion from the continuum before (its u and v) at their reference positions.
void take_motion_from_continuum(const ContinuumPart& continuum, const std::vector<double>& u_nodes, const std::vector<double>& v_nodes,
                                dem::ParticleSet& p, const std::vector<long>& old_of_new) {
  constexpr double h = 1e-6;  // m, the central differences' half step
  std::vector<std::uint32_t> added;
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < old_of_new.size(); ++i) {
    if (old_of_new[i] >= 0) continue;
    added.push_back(static_cast<std::uint32_t>(i));
    const Vec3& X = p.reference[i];
    points.push_back(X);
    for (int k = 0; k < 3; ++k)
      for (const double sign : {1.0, -1.0}) {
        Vec3 Y = X;
        Y[k] += sign * h;
        points.push_back(Y);
      }
  }
  if (added.empty()) return;
  const auto rows = continuum.shape_values(points);
  const std::vector<Vec3> u = interpolate(rows, u_nodes), v = interpolate(rows, v_nodes);
  for (std::size_t a = 0; a < added.size(); ++a) {
    const std::size_t i = added[a], at = 7 * a;
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity(), F_dot = Eigen::Matrix3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const Vec3 du = (u[at + 1 + 2 * k] - u[at + 2 + 2 * k]) / (2.0 * h), dv = (v[at + 1 + 2 * k] - v[at + 2 + 2 * k]) / (2.0 * h);
      for (int c = 0; c < 3; ++c) F(c, k) += du[c], F_dot(c, k) = dv[c];
    }
    const auto [q, spin] = rotation_and_spin(F, F_dot);
    p.position[i] = p.reference[i] + u[at];
    p.velocity[i] = v[at];
    p.orientation[i] = q;
    p.angular_velocity[i] = spin;
  }
}

// A continuum node whose motion the DEs give (one the band leaves, one new to the continuum, one
// the new start overlap reaches): the motion of the DEs around it on its side of the mid-plane,
// the value at X of the affine field fitted to the 16 nearest by least squares (displacement and
// velocity).
std::pair<Vec3, Vec3> motion_from_des(const dem::ParticleSet& p, const Vec3& X, std::uint8_t side, int axis, double center) {
  constexpr std::size_t nearest = 16;
  std::vector<std::pair<double, std::uint32_t>> found;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool below = p.reference[i][axis] < center;
    if ((below && !(side & 1)) || (!below && !(side & 2))) continue;
    found.emplace_back(norm2(p.reference[i] - X), static_cast<std::uint32_t>(i));
  }
  const std::size_t k = std::min(nearest, found.size());
  if (k < 4) throw RunError("a moved zone's new continuum node has fewer than 4 DEs on its side to take its motion from");
  std::partial_sort(found.begin(), found.begin() + static_cast<long>(k), found.end());
  // The normal equations, fixed-size: no dynamic Eigen matrix is instantiated here, whose
  // alignment would differ from the one a shared library built apart (gmsh) expects of its own.
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Matrix<double, 4, 6> rhs = Eigen::Matrix<double, 4, 6>::Zero();
  for (std::size_t r = 0; r < k; ++r) {
    const std::uint32_t i = found[r].second;
    const Vec3 d = p.reference[i] - X, u = p.position[i] - p.reference[i];
    const Eigen::Vector4d a(1.0, d.x, d.y, d.z);
    Eigen::Matrix<double, 1, 6> b;
    b << u.x, u.y, u.z, p.velocity[i].x, p.velocity[i].y, p.velocity[i].z;
    normal += a * a.transpose();
    rhs += a * b;
  }
  const Eigen::Matrix<double, 4, 6> fit = normal.colPivHouseholderQr().solve(rhs);
  return {Vec3{fit(0, 0), fit(0, 1), fit(0, 2)}, Vec3{fit(0, 3), fit(0, 4), fit(0, 5)}};
}

// The displacement of the nodes `refit` in equilibrium with the others held (and the dofs a
// support or driven strip sets): the least strain energy of the continuum as the new scene
// weighs it. One Newton step from u: its linear system by conjugate gradients on those nodes'
// dofs, K times a direction by central differences of f_int, preconditioned by the diagonal of
// the stiffness at the undeformed state (Jacobi: the dofs' stiffnesses span the weights and the
// elements' shapes, a P2 vertex's and a mid-edge node's differ); stopped when the residual is
// 1e-8 of the start's. Dofs no weighted element stiffens stay as they were.
void relax_nodes(const ContinuumPart& continuum, const std::vector<char>& refit, std::vector<double>& u) {
  std::vector<std::size_t> dofs;
  for (std::size_t a = 0; a < refit.size(); ++a)
    if (refit[a])
      for (std::size_t c = 0; c < 3; ++c)
        if (!continuum.prescribed(3 * a + c)) dofs.push_back(3 * a + c);
  if (dofs.empty()) return;
  const std::size_t n = dofs.size();
  const auto dot = [n](const std::vector<double>& a, const std::vector<double>& b) {
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) sum += a[k] * b[k];
    return sum;
  };
  std::vector<double> inverse_diagonal(n);
  {
    const std::vector<double> diagonal = continuum.stiffness_diagonal();
    for (std::size_t k = 0; k < n; ++k) inverse_diagonal[k] = diagonal[dofs[k]] > 0.0 ? 1.0 / diagonal[dofs[k]] : 0.0;
  }
  std::vector<double> f(u.size()), plus(u.size()), minus(u.size()), shifted(u.size());
  // K p on the dofs, by central differences of f_int over 1e-7 m along p's largest component.
  const auto stiffness_times = [&](const std::vector<double>& p, std::vector<double>& out) {
    double largest = 0.0;
    for (double x : p) largest = std::max(largest, std::abs(x));
    const double h = 1e-7 / std::max(largest, 1e-300);
    for (const double sign : {1.0, -1.0}) {
      shifted = u;
      for (std::size_t k = 0; k < n; ++k) shifted[dofs[k]] += sign * h * p[k];
      continuum.internal_force(shifted, sign > 0.0 ? plus : minus);
    }
    for (std::size_t k = 0; k < n; ++k) out[k] = (plus[dofs[k]] - minus[dofs[k]]) / (2.0 * h);
  };
  continuum.internal_force(u, f);
  std::vector<double> x(n, 0.0), r(n), z(n), p(n), Ap(n);
  for (std::size_t k = 0; k < n; ++k) r[k] = -f[dofs[k]], z[k] = inverse_diagonal[k] * r[k];
  p = z;
  double rz = dot(r, z);
  const double stop = 1e-16 * dot(r, r);
  for (std::size_t it = 0; it < 2 * n && dot(r, r) > stop; ++it) {
    stiffness_times(p, Ap);
    const double pAp = dot(p, Ap);
    if (!(pAp > 0.0)) break;  // a direction nothing stiffens
    const double alpha = rz / pAp;
    for (std::size_t k = 0; k < n; ++k) x[k] += alpha * p[k], r[k] -= alpha * Ap[k], z[k] = inverse_diagonal[k] * r[k];
    const double rz_next = dot(r, z);
    for (std::size_t k = 0; k < n; ++k) p[k] = z[k] + (rz_next / rz) * p[k];
    rz = rz_next;
  }
  for (std::size_t k = 0; k < n; ++k) u[dofs[k]] += x[k];
}

}  // namespace

void check_band_follow(const Scene& scene) {
  const BandFollow& f = follow_of(scene);
  if (interface_set(scene.dem) < 0)
    throw InputError(f.where + ": a band follows the crack of the DEM's interface, and this case has none (dem.interface)");
  if (!scene.dem.bond_sets()[interface_set(scene.dem)]->has_strength())
    throw InputError(f.where + ": the DEM's interface cannot fail, so there is no crack to follow");
  if (scene.output.checkpoint_every > 0.0)
    throw InputError(f.where + ": a band that follows a crack is built again as it moves, and its run is not checkpointed: "
                               "remove output.checkpoint_every");
  case_shares(scene);  // refuses a join it cannot move
}

std::optional<BandPlace> band_place(const Scene& scene) {
  const BandFollow& f = follow_of(scene);
  if (f.to >= f.until) return std::nullopt;
  const dem::CrackFront crack = crack_of(scene);
  if (!(crack.damage_front > f.to - f.margin)) return std::nullopt;  // also NaN: no damage yet
  // Its end on a plane of element vertices, where a join that moves with it holds whole elements
  // (a slit between the band's end and the join would be a crack ahead of the DEM's).
  BandPlace place{f.from, std::min(scene.continuum->vertex_plane_from(f.along, crack.damage_front + f.ahead), f.until)};
  // The band keeps its two end overlaps and a core between them (OverlapZone::band).
  if (std::isfinite(crack.tip) && crack.tip - f.behind > f.from) place.from = std::min(crack.tip - f.behind, place.to - 4.0 * f.width);
  place.from = std::max(place.from, f.from);
  return place;
}

void BandSettling::pick(const Scene& moved) {
  const BandFollow& f = follow_of(moved);
  const dem::ParticleSet& p = moved.dem.particles;
  ids_.clear();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.reference[i][f.along] <= f.from + f.settle_length) ids_.push_back(static_cast<std::uint32_t>(i));
  last_kinetic_ = moved.dem.kinetic_energy(ids_);
}

void BandSettling::start(const Scene& moved) {
  const BandFollow& f = follow_of(moved);
  steps_left_ = static_cast<long>(std::ceil(f.settle_time / moved.dt - 1e-9));
  steps_done_ = 0;
  dissipated_ = 0.0;
  pick(moved);
}

void BandSettling::carry_to(const Scene& moved) {
  if (active()) pick(moved);
}

void BandSettling::after_step(const dem::DemModel& dem, SceneModel& model) {
  --steps_left_;
  ++steps_done_;
  // Between two macro steps only, where the continuum's velocities are in step with its forces
  // and the projection's work is the change of the kinetic energies the balance books.
  if (!model.accepts_set_state()) return;
  const double kinetic = dem.kinetic_energy(ids_);
  if (kinetic < last_kinetic_) {
    dissipated_ += model.arrest(ids_);
    last_kinetic_ = dem.kinetic_energy(ids_);  // what imposed motion leaves
  } else {
    last_kinetic_ = kinetic;
  }
}

std::unique_ptr<Scene> move_zone(const Scene& first, Scene& current, BandPlace place, ZoneMove& report) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!current.model->accepts_set_state()) throw std::logic_error("move_zone between the substeps of a macro step");
  const BandFollow& f0 = follow_of(first);
  const CaseShares shares = case_shares(first);
  report = ZoneMove{};
  report.energy_before = current.model->energies().total();

  // The case again, the band moved.
  SceneOptions options = current.built_with;
  options.check_output_dir = false;
  options.write_sample_cache = false;
  const std::string origin = "the band following the crack (" + f0.where + ")";
  const auto set = [&](const std::string& key, const std::string& value) { options.overrides.emplace_back(key + "=" + value, origin); };
  set("coupling.overlap.band.from", exact(place.from));
  set("coupling.overlap.band.to", exact(place.to));
  if (shares.area > 0.0)
    set("dem.interface.bond.area", exact(shares.area * length_inside(place.from, place.to, shares) / length_inside(f0.from, f0.to, shares)));
  if (shares.join) {
    Box join = *shares.join;
    join.lower[f0.along] += place.to - f0.to;
    char box[200];
    std::snprintf(box, sizeof box, "{box: [[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g]]}", join.lower.x, join.lower.y, join.lower.z,
                  join.upper.x, join.upper.y, join.upper.z);
    set("continuum.mesh.join", box);
  }
  set("time.dt", exact(current.dt));
  options.crack_initial_tips.clear();
  for (const Sensor& s : first.sensors) options.crack_initial_tips.push_back(s.crack.initial_tip);
  // Built in place: its model refers to its own DEM and continuum.
  std::unique_ptr<Scene> next(new Scene(build_scene(first.case_file, options)));
  next->output = current.output;
  next->steps = current.steps;

  // Who is who: DEs by reference position, bonds by their DEs, nodes by position and side.
  const dem::ParticleSet &po = current.dem.particles, &pn = next->dem.particles;
  std::map<Key, long> old_de;
  for (std::size_t i = 0; i < po.size(); ++i) old_de.emplace(key_of(po.reference[i]), static_cast<long>(i));
  std::vector<long> old_of_new(pn.size(), -1);
  for (std::size_t i = 0; i < pn.size(); ++i)
    if (const auto it = old_de.find(key_of(pn.reference[i])); it != old_de.end()) old_of_new[i] = it->second, ++report.des_kept;
  report.des = pn.size();
  report.des_added = pn.size() - report.des_kept;
  report.des_dropped = po.size() - report.des_kept;

  const auto& sets_old = current.dem.bond_sets();
  const auto& sets_new = next->dem.bond_sets();
  if (sets_old.size() != sets_new.size()) throw std::logic_error("zone move: the scenes have different bond sets");
  std::vector<std::vector<long>> bond_old_of_new(sets_new.size()), bond_new_of_old(sets_old.size());
  for (std::size_t s = 0; s < sets_new.size(); ++s) {
    const dem::BondSet &o = *sets_old[s], &n = *sets_new[s];
    const auto pair_key = [&po](std::uint32_t i, std::uint32_t j) { return std::uint64_t{std::min(i, j)} * po.size() + std::max(i, j); };
    std::unordered_map<std::uint64_t, long> old_bond;
    for (std::size_t b = 0; b < o.size(); ++b) old_bond.emplace(pair_key(o.first()[b], o.second()[b]), static_cast<long>(b));
    bond_old_of_new[s].assign(n.size(), -1);
    bond_new_of_old[s].assign(o.size(), -1);
    for (std::size_t b = 0; b < n.size(); ++b) {
      const long i = old_of_new[n.first()[b]], j = old_of_new[n.second()[b]];
      if (i < 0 || j < 0) continue;
      if (const auto it = old_bond.find(pair_key(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j))); it != old_bond.end())
        bond_old_of_new[s][b] = it->second, bond_new_of_old[s][it->second] = static_cast<long>(b);
    }
    for (std::size_t b = 0; b < o.size(); ++b) report.links_dropped_broken += bond_new_of_old[s][b] < 0 && o.broken()[b];
  }

  const ContinuumPart &co = *current.continuum, &cn = *next->continuum;
  const auto& xo = co.node_positions();
  const auto& xn = cn.node_positions();
  const auto side_old = co.node_sides(f0.axis, f0.center), side_new = cn.node_sides(f0.axis, f0.center);
  std::map<std::tuple<double, double, double, int>, long> old_node;
  for (std::size_t a = 0; a < xo.size(); ++a) old_node.emplace(std::tuple{xo[a].x, xo[a].y, xo[a].z, int{side_old[a]}}, static_cast<long>(a));
  std::vector<long> old_dof_of_new(3 * xn.size(), -1);
  for (std::size_t a = 0; a < xn.size(); ++a) {
    auto it = old_node.find(std::tuple{xn[a].x, xn[a].y, xn[a].z, int{side_new[a]}});
    if (it == old_node.end()) it = old_node.find(std::tuple{xn[a].x, xn[a].y, xn[a].z, 3});  // joined before, apart now
    if (it == old_node.end()) {
      ++report.nodes_added;  // of the pure-DEM zone before
      continue;
    }
    for (int c = 0; c < 3; ++c) old_dof_of_new[3 * a + c] = 3 * it->second + c;
  }

  // The state, through the checkpoint archives: the new scene's own, overwritten by the old's.
  StateArchive before, after;
  current.model->save_state(before);
  next->model->save_state(after);
  for (const char* name : {"position", "velocity", "angular_velocity", "orientation"})
    carry_rows(before, after, "dem/particles/" + std::string(name), old_of_new);
  for (std::size_t s = 0; s < sets_new.size(); ++s) {
    const std::string prefix = "dem/bonds/" + std::to_string(s) + "/";
    for (const char* name : {"broken", "energy_record", "damage", "dissipated"})
      if (after.has(prefix + name)) carry_rows(before, after, prefix + name, bond_old_of_new[s]);
  }
  const std::size_t breaks = carry_events(before, after, "dem/breaks/", bond_new_of_old);
  const std::size_t held = after.has("dem/held_failures/time") ? carry_events(before, after, "dem/held_failures/", bond_new_of_old) : 0;
  for (const char* name : {"dem/time", "dem/last_dt", "dem/steps", "dem/external_work", "dem/dissipated", "dem/fracture",
                           "dem/energy_record_requested", "dem/energy_record_step", "continuum/time", "continuum/external_work",
                           "continuum/dissipated", "coupling/work", "coupling/time", "coupling/steps"})
    carry_entry(before, after, name);
  for (const char* name : {"continuum/u", "continuum/v"}) carry_rows(before, after, name, old_dof_of_new);
  const bool start_moved = place.from > follow_of(current).from;
  {
    // Where the DEM's weight falls (the zone left it) and where the continuum is new: the DEs'
    // motion for the share the DEM carried, then the displacement relaxed to the continuum's
    // equilibrium with the nodes around held. Also the nodes of the elements the band's new start
    // overlap reaches that lay in the DEM-only zone: the continuum weighed them as nothing, so
    // their field is no continuum's own, and the overlap now weighs it.
    auto u = after.get<double>("continuum/u"), v = after.get<double>("continuum/v");
    const double start_reach = cn.vertex_plane_from(f0.along, place.from + f0.width);
    std::vector<char> relaxed(xn.size(), 0);
    for (std::size_t a = 0; a < xn.size(); ++a) {
      const bool added = old_dof_of_new[3 * a] < 0;
      const double dem_share = added ? 1.0 : co.dem_weight(xn[a]);
      const bool reached = start_moved && dem_share >= 1.0 && xn[a][f0.along] <= start_reach;
      if (!added && !reached && !(dem_share > cn.dem_weight(xn[a]))) continue;
      relaxed[a] = 1;
      const auto [ua, va] = motion_from_des(po, xn[a], side_new[a], f0.axis, f0.center);
      for (int c = 0; c < 3; ++c) {
        u[3 * a + c] = dem_share * ua[c] + (1.0 - dem_share) * u[3 * a + c];
        v[3 * a + c] = dem_share * va[c] + (1.0 - dem_share) * v[3 * a + c];
      }
      ++report.nodes_from_des;
    }
    // A move of the start also relaxes every other node no coupled DE's field reaches (with the
    // nodes the coupled DEs' field reaches and the driven strips held): where the DEM's weight
    // was a fraction, the continuum's field carried only its share of the stress, and handed over
    // as it stands it stores more than the DEM did (docs/decisions.md#d56).
    if (start_moved) {
      std::vector<Vec3> coupled;
      for (std::size_t i = 0; i < pn.size(); ++i)
        if (cn.dem_weight(pn.reference[i]) < 1.0) coupled.push_back(pn.reference[i]);
      std::vector<char> tied(xn.size(), 0);
      for (const auto& row : cn.shape_values(coupled))
        for (const auto& [a, N] : row) tied[a] = 1;
      for (std::size_t a = 0; a < xn.size(); ++a) relaxed[a] |= !tied[a];
    }
    relax_nodes(cn, relaxed, u);
    after.put("continuum/u", u);
    after.put("continuum/v", v);
    // The coupled DEs stay where they are: the coupling ties velocities and keeps G u as it finds
    // it, the DEs' offset from the continuum's field included (SceneModel::displacement_residual).
    // Put onto that field, they would lose their own fluctuation about it at the cost of their
    // bonds' energy (docs/decisions.md#d56).
  }
  after.put("coupling/breaks_looked_at", static_cast<std::int64_t>(breaks));
  after.put("coupling/held_looked_at", static_cast<std::int64_t>(held));
  next->model->load_state(after);
  take_motion_from_continuum(co, before.get<double>("continuum/u"), before.get<double>("continuum/v"), next->dem.particles, old_of_new);
  next->model->resume_from_set_state();
  // A move of the start hands the wake's stress to the continuum in one step: the state is then
  // relaxed to its equilibrium at the present load, every DE both scenes have and every continuum
  // node toward rest, the DEs new to the zone toward their own accelerations as set (they took the
  // continuum's motion; what their packing's forces make of it is not the move's). Not toward the
  // accelerations before: where the move dropped or reweighted the DEs a node or DE was tied to,
  // those carried the coupling's force from DEs that are gone, a force the arms then balanced at
  // the load strips (docs/decisions.md#d56).
  if (const int steps = follow_of(*next).relax_steps; start_moved && steps > 0) {
    StateArchive target;
    next->model->save_accelerations(target);
    std::vector<char> kept(pn.size());  // the DEs both scenes have
    for (std::size_t i = 0; i < pn.size(); ++i) kept[i] = old_of_new[i] >= 0;
    zero_rows(target, "accelerations/dem/translation", kept);
    zero_rows(target, "accelerations/dem/rotation", kept);
    target.put("accelerations/continuum", std::vector<double>(target.get<double>("accelerations/continuum").size(), 0.0));
    report.relaxation = next->model->relax(current.dt, steps, target);
  }

  // The crack sensors go on from the run's pre-crack tip, and count what the links left behind
  // dissipated.
  for (std::size_t k = 0; k < next->sensors.size(); ++k) {
    const Sensor::Crack &was = current.sensors[k].crack;
    Sensor::Crack& is = next->sensors[k].crack;
    if (next->sensors[k].kind != Sensor::Kind::crack) continue;
    const auto dissipated = [&is](const Scene& scene) {
      return dem::measure_crack(*scene.dem.bond_sets()[is.bond_set], scene.dem.particles, is.axis, is.across, is.bins).dissipated;
    };
    is.dissipated_left = was.dissipated_left + dissipated(current) - dissipated(*next);
  }
  report.energy_after = next->model->energies().total();
  report.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return next;
}

}  // namespace arlequin::app
