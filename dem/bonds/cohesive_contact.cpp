// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/bonds/cohesive_contact.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <stdexcept>

#include "common/case_file.hpp"
#include "common/quat.hpp"
#include "dem/lanes.hpp"

namespace arlequin::dem {

template class BondKernelSet<CohesiveContactSet>;

constexpr KeyDoc cohesive_keys[] = {
    {"sigma_max", KeyType::number, "Pa", Range::positive(), "", "normal strength sigma_max^n (seed Eq. 2)"},
    {"sigma_max_shear", KeyType::number, "Pa", Range::positive(), "(sigma_max)", "shear strength sigma_max^s"},
    {"G_I", KeyType::number, "J/m^2", Range::positive(), "", "mode I toughness: u_p^n = 2 G_I / sigma_max (seed Eq. 2)"},
    {"G_II", KeyType::number, "J/m^2", Range::positive(), "(G_I)", "mode II toughness: u_p^s = 2 G_II / sigma_max_shear"},
    {"stiffness", KeyType::number, "Pa/m", Range::positive(), "", "traction per opening before damage, both directions"},
    {"bk_exponent", KeyType::number, "1", Range::positive(), "2", "Benzeggagh-Kenane exponent eta of the mixed-mode toughness"},
    {"precrack", KeyType::section, "", {}, "(none)", "a region: links whose mid-point lies in it start failed"},
    {"area", KeyType::number, "m^2", Range::positive(), "(none)", "nominal interface area the links' sections are scaled to add up to: where there are DEs, within 10 % of what the links cover"},
};
std::span<const KeyDoc> CohesiveContactSet::keys() { return cohesive_keys; }

CohesiveContactSet::CohesiveContactSet(const Parameters& parameters) : parameters_(parameters) {
  const Parameters& q = parameters_;
  const auto require_positive = [](double value, const char* key) {
    if (!(value > 0.0) || !std::isfinite(value)) throw std::invalid_argument(std::string(key) + ": expected a positive number");
  };
  require_positive(q.strength_normal, "sigma_max");
  require_positive(q.strength_shear, "sigma_max_shear");
  require_positive(q.toughness_I, "G_I");
  require_positive(q.toughness_II, "G_II");
  require_positive(q.stiffness, "stiffness");
  require_positive(q.bk_exponent, "bk_exponent");
  // Softening needs the failure opening u_p = 2 G / sigma beyond the elastic one sigma / k.
  const auto check_mode = [&](double strength, double toughness, const char* key) {
    const double elastic = strength / q.stiffness, failure = 2.0 * toughness / strength;
    if (!(failure > elastic)) {
      char msg[256];
      std::snprintf(msg, sizeof msg,
                    "u_p = 2 G / sigma = %.4g m is not beyond the elastic opening sigma / stiffness = %.4g m; "
                    "raise the stiffness above %.4g Pa/m or the toughness",
                    failure, elastic, strength * strength / (2.0 * toughness));
      throw std::invalid_argument(std::string(key) + ": " + msg);
    }
  };
  check_mode(q.strength_normal, q.toughness_I, "G_I");
  check_mode(q.strength_shear, q.toughness_II, "G_II");
}

std::unique_ptr<BondSet> CohesiveContactSet::make(CaseNode& section) {
  Parameters q;
  q.strength_normal = section.number("sigma_max", Range::positive(), "Pa");
  q.strength_shear = section.number_or("sigma_max_shear", q.strength_normal, Range::positive(), "Pa");
  q.toughness_I = section.number("G_I", Range::positive(), "J/m^2");
  q.toughness_II = section.number_or("G_II", q.toughness_I, Range::positive(), "J/m^2");
  q.stiffness = section.number("stiffness", Range::positive(), "Pa/m");
  q.bk_exponent = section.number_or("bk_exponent", 2.0, Range::positive(), "1");
  if (auto region = section.child_if("precrack")) {
    q.precrack = Region::read(*region);
    region->finish();
  }
  if (section.has("area")) q.area = section.number("area", Range::positive(), "m^2");
  try {
    return std::make_unique<CohesiveContactSet>(q);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    const auto colon = what.find(": ");
    section.fail(what.substr(0, colon), what.substr(colon + 2));
  }
}

void CohesiveContactSet::add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) {
  const Quat identity{};
  if (!(p.orientation[i].w == identity.w && p.orientation[i].v == identity.v && p.orientation[j].w == identity.w &&
        p.orientation[j].v == identity.v))
    throw std::logic_error("CohesiveContactSet::add: DEs must have their reference orientation");
  add_pair(i, j);
  const Vec3 d0 = p.position[j] - p.position[i];
  const double Ri = p.radius[i], Rj = p.radius[j];
  offset_i_.push_back(d0 * (Ri / (Ri + Rj)));
  offset_j_.push_back(d0 * (-Rj / (Ri + Rj)));
  const double R = 0.5 * (Ri + Rj);
  section_.push_back(std::numbers::pi * R * R);
  stiffness_.push_back(parameters_.stiffness * section_.back());
  damage_.push_back(0.0);
  dissipated_.push_back(0.0);
  if (parameters_.precrack && parameters_.precrack->contains(p.position[i] + offset_i_.back())) {
    broken_.back() = 1;
    damage_.back() = 1.0;
    stiffness_.back() = 0.0;
  }
}

namespace {

struct Point2 {
  double x, y;
};
double turn(const Point2& o, const Point2& a, const Point2& b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

// Area and perimeter of the convex hull of `points` (Andrew's monotone chain; reorders them).
std::pair<double, double> hull_area_and_perimeter(std::vector<Point2>& points) {
  std::sort(points.begin(), points.end(), [](const Point2& a, const Point2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  std::vector<Point2> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);  // the last point is the first
  double area = 0.0, perimeter = 0.0;
  for (std::size_t m = 0; m < hull.size(); ++m) {
    const Point2 &a = hull[m], &b = hull[(m + 1) % hull.size()];
    area += 0.5 * (a.x * b.y - b.x * a.y);
    perimeter += std::hypot(b.x - a.x, b.y - a.y);
  }
  return {area, perimeter};
}

}  // namespace

double CohesiveContactSet::covered_area(const ParticleSet& p) const {
  const std::size_t n = size();
  if (n < 3) return 0.0;
  Vec3 normal{};
  for (std::size_t b = 0; b < n; ++b) {
    const Vec3 d = p.position[second()[b]] - p.position[first()[b]];
    normal += dot(d, normal) < 0.0 ? -1.0 * (d / norm(d)) : d / norm(d);
  }
  normal = normal / norm(normal);
  const Vec3 e1 = normalized(cross(normal, std::abs(normal.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
  const Vec3 e2 = cross(normal, e1);
  std::vector<Point2> points(n);
  double lowest = INFINITY, highest = -INFINITY;
  for (std::size_t b = 0; b < n; ++b) {
    const Vec3 c = p.position[first()[b]] + offset_i_[b];
    points[b] = {dot(c, e1), dot(c, e2)};
    lowest = std::min(lowest, dot(c, normal));
    highest = std::max(highest, dot(c, normal));
  }
  const auto [area, perimeter] = hull_area_and_perimeter(points);
  if (!(area > 0.0) || highest - lowest > 0.1 * std::sqrt(area)) return 0.0;
  const double delta = 0.5 * std::sqrt(area / static_cast<double>(n));
  return area + perimeter * delta + std::numbers::pi * delta * delta;
}

void CohesiveContactSet::finalize(std::size_t n_particles) {
  if (parameters_.area > 0.0 && size() > 0) {
    double total = 0.0;
    for (double s : section_) total += s;
    section_scale_ = parameters_.area / total;
    for (std::size_t b = 0; b < size(); ++b) {
      section_[b] *= section_scale_;
      stiffness_[b] *= section_scale_;
    }
  }
  BondKernelSet<CohesiveContactSet>::finalize(n_particles);
}

CohesiveContactSet::Evaluation CohesiveContactSet::evaluate(std::size_t b, const ParticleSet& p) const {
  Evaluation e;
  evaluate_block(b, 1, p, &e);
  return e;
}

// Never inlined: one compiled copy serves the force pass and single links, so FMA contraction
// cannot differ between them.
[[gnu::noinline]] void CohesiveContactSet::evaluate_block(std::size_t first, std::size_t count, const ParticleSet& p,
                                                          Evaluation* out) const {
  using namespace simd;
  assert(count >= 1 && count <= lanes);
  // Lane l holds link first + l; lanes past count repeat the last link (not written out).
  // Positions, orientations and contact offsets are loaded one vector each and transposed.
  Quad xa[lanes], xb[lanes], qa[lanes], qb[lanes], oa[lanes], ob[lanes];
  Lanes K, stored, section;
  for (std::size_t l = 0; l < lanes; ++l) {
    const std::size_t b = first + std::min(l, count - 1);
    xa[l] = load_position(p.position[first_[b]]);
    xb[l] = load_position(p.position[second_[b]]);
    std::memcpy(&qa[l], &p.orientation[first_[b]], sizeof(Quad));
    std::memcpy(&qb[l], &p.orientation[second_[b]], sizeof(Quad));
    oa[l] = load_position(offset_i_[b]);
    ob[l] = load_position(offset_j_[b]);
    K[l] = stiffness_[b], stored[l] = damage_[b], section[l] = section_[b];
  }
  const LaneVec xi = transpose_vectors(xa), xj = transpose_vectors(xb);
  const LaneVec arm_i = rotate(transpose(qa), transpose_vectors(oa)), arm_j = rotate(transpose(qb), transpose_vectors(ob));
  const LaneVec d = xj - xi;
  const LaneVec n = d * (1.0 / lane_sqrt(dot(d, d)));
  const LaneVec u = (xj + arm_j) - (xi + arm_i);
  const Lanes un = dot(u, n);
  const LaneVec us = u - n * un;
  const Lanes s2 = dot(us, us), zero{};
  const Lanes opening = un < zero ? zero : un, closing = -un < zero ? zero : -un;  // std::max(., 0)
  const Lanes lambda2 = opening * opening + s2;
  const Lanes lambda = lane_sqrt(lambda2);

  // Onset and failure openings along the present mode mix (docs/theory.md#cohesive-contact).
  const Parameters& q = parameters_;
  const double k = q.stiffness;
  const double dn0 = q.strength_normal / k, ds0 = q.strength_shear / k;
  const LaneMask mixed = lambda2 > zero;
  const Lanes mix = mixed ? s2 / lambda2 : zero;  // B
  const Lanes lambda0 =
      mixed ? dn0 * ds0 * lane_sqrt(lambda2 / (ds0 * ds0 * opening * opening + dn0 * dn0 * s2)) : zero + dn0;
  Lanes damage = stored, dissipation = zero;
  // Below the onset opening the damage stays as it is and nothing is dissipated: the mixed-mode
  // toughness (a pow) and the failure opening are needed only beyond it, in the process zone.
  if (const LaneMask softening = lambda > lambda0; any_lane(softening)) {
    Lanes share = zero;  // B^eta, on the softening lanes only
    for (std::size_t l = 0; l < lanes; ++l)
      if (softening[l]) share[l] = std::pow(mix[l], q.bk_exponent);
    const Lanes toughness = q.toughness_I + (q.toughness_II - q.toughness_I) * share;
    const Lanes failure = 2.0 * toughness / (k * lambda0), least = lambda0 * (1.0 + 1e-12);
    const Lanes lambda_f = failure < least ? least : failure;  // std::max
    const Lanes trial = lambda >= lambda_f ? zero + 1.0 : lambda_f * (lambda - lambda0) / (lambda * (lambda_f - lambda0));
    damage = softening ? (stored < trial ? trial : stored) : stored;
    // Fraction of G_c S dissipated once the damage is d, along this mix.
    const auto dissipated_fraction = [&](Lanes dmg) {
      const Lanes reached = lambda0 * lambda_f / (lambda_f - dmg * (lambda_f - lambda0));
      return (reached - lambda0) / (lambda_f - lambda0);
    };
    const LaneMask dissipating = softening & (damage > stored) & (K > zero);
    dissipation = dissipating ? toughness * section * (dissipated_fraction(damage) - dissipated_fraction(stored)) : zero;
  }
  const LaneVec force_on_j = (us + n * opening) * (-K * (1.0 - damage)) + n * (K * closing);
  const LaneVec torque_on_i = cross(arm_i, LaneVec{-force_on_j.x, -force_on_j.y, -force_on_j.z});
  const LaneVec torque_on_j = cross(arm_j, force_on_j);
  const Lanes elastic = 0.5 * K * ((1.0 - damage) * lambda2 + closing * closing);
  for (std::size_t l = 0; l < count; ++l) {
    Evaluation& e = out[l];
    e.force_on_j = {force_on_j.x[l], force_on_j.y[l], force_on_j.z[l]};
    e.torque_on_i = {torque_on_i.x[l], torque_on_i.y[l], torque_on_i.z[l]};
    e.torque_on_j = {torque_on_j.x[l], torque_on_j.y[l], torque_on_j.z[l]};
    e.damage = damage[l];
    e.mode_mix = mix[l];
    e.elastic = elastic[l];
    e.dissipation = dissipation[l];
  }
}

void CohesiveContactSet::accumulate_forces(ParticleSet& p, const ForceScan& scan) const {
  const Records r = records(scan);
  const std::uint8_t* broken = broken_.data();
  for_each_bond_block(colouring_, static_cast<long>(simd::lanes), [&](std::size_t first, std::size_t end) {
    // A block of failed links is skipped: each would carry no force, keep its damage (1) and
    // dissipate nothing more, and its scan records need no update (break_bond set its energy to 0,
    // find_failures passes failed links by, the virial leaves them out).
    if (std::all_of(broken + first, broken + end, [](std::uint8_t failed) { return failed != 0; })) return;
    Evaluation e[simd::lanes];
    evaluate_block(first, end - first, p, e);
    for (std::size_t b = first; b < end; ++b) {
      apply(b, e[b - first], p);
      commit(b, e[b - first]);
      if (r.any()) record_scan(b, e[b - first], p, scan, r);
    }
  });
}

void CohesiveContactSet::reorder(std::span<const std::uint32_t> order) {
  apply_order(section_, order);
  apply_order(stiffness_, order);
  apply_order(offset_i_, order);
  apply_order(offset_j_, order);
  apply_order(damage_, order);
  apply_order(dissipated_, order);
}

// Block-Gershgorin rows of a link of stiffness K whose contact point sits at a_i, a_j from the
// centres: translational K, rotational K a_i^2 (own) and K a_i a_j (other), coupling K a.
void CohesiveContactSet::add_frequency_bound(std::size_t b, const ParticleSet& p, std::span<double> translational,
                                             std::span<double> rotational) const {
  const double K = stiffness_[b];
  const double a[2] = {norm(offset_i_[b]), norm(offset_j_[b])};
  for (int end = 0; end < 2; ++end) {
    const std::uint32_t i = end == 0 ? first_[b] : second_[b];
    const std::uint32_t j = end == 0 ? second_[b] : first_[b];
    const double ai = a[end], aj = a[1 - end];
    const double mi = p.inv_mass[i], mj = p.inv_mass[j];
    const double Ii = p.inv_inertia(i), Ij = p.inv_inertia(j);
    translational[i] += K * (mi + std::sqrt(mi * mj) + ai * std::sqrt(mi * Ii) + aj * std::sqrt(mi * Ij));
    rotational[i] += K * (ai * ai * Ii + ai * aj * std::sqrt(Ii * Ij) + ai * (std::sqrt(Ii * mi) + std::sqrt(Ii * mj)));
  }
}

void CohesiveContactSet::save_law_state(StateArchive& archive, const std::string& prefix) const {
  archive.put(prefix + "damage", damage_);
  archive.put(prefix + "dissipated", dissipated_);
}

void CohesiveContactSet::load_law_state(const StateArchive& archive, const std::string& prefix) {
  archive.get_into(prefix + "damage", damage_);
  archive.get_into(prefix + "dissipated", dissipated_);
}

std::string CohesiveContactSet::describe() const {
  std::size_t failed = 0;
  for (auto f : broken_) failed += f;
  char text[256];
  std::snprintf(text, sizeof text, "%zu links (%zu start failed), u_p^n = %.4g m, sections x %.4f", size(), failed,
                2.0 * parameters_.toughness_I / parameters_.strength_normal, section_scale_);
  return text;
}

}  // namespace arlequin::dem
