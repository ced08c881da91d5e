// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/bonds/beam_bond.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "common/case_file.hpp"
#include "dem/lanes.hpp"

namespace arlequin::dem {

template class BondKernelSet<BeamBondSet>;
namespace {

// The kinematics of BeamBondSet::block bonds at once, one bond per lane (dem/lanes.hpp). Every
// bond, alone or in a block, goes through this one kernel, so a bond's actions do not depend on
// the bonds it is evaluated with.
using namespace simd;
static_assert(BeamBondSet::block == lanes);

// 1 / x and 1 / sqrt(x) without a division. A division's result comes some 20 cycles after its
// operand, and the kernel's chain (length, axis, the two end rotations, the twist) waited on
// four of them in turn; the AVX-512 estimates (relative error below 2^-14) take a few cycles,
// and two Newton steps, r (2 - x r) and y (3/2 - x y^2 / 2), each square the error, to within
// rounding: a relative error below 3e-16 (about an ulp) over all normal x. A zero x gives NaN
// where the division gave infinity: a cosine c <= 0 is a lane the kernel takes again beyond its
// series, and a zero length gave NaN before too (the axis, 0 times infinity).
inline Lanes reciprocal(Lanes x) {
#if defined(__AVX512F__)
  Lanes r = _mm512_rcp14_pd(x);
  for (int step = 0; step < 2; ++step) r = r + r * (1.0 - x * r);
  return r;
#else
  return 1.0 / x;
#endif
}
inline Lanes inverse_sqrt(Lanes x) {
#if defined(__AVX512F__)
  Lanes y = _mm512_rsqrt14_pd(x);
  const Lanes half_x = 0.5 * x;
  for (int step = 0; step < 2; ++step) y = y * (1.5 - half_x * (y * y));
  return y;
#else
  return 1.0 / lane_sqrt(x);
#endif
}

// The series of atan(x)/x = 1 - x^2/3 + x^4/5 - x^6/7 in x2 = x^2: below x = 0.05
// (2.9 degrees, where bonds live) it is exact to 5e-12 relative and costs a tenth of libm's
// atan2, which otherwise dominates the bond loop (and has no vector form here).
constexpr double series_limit = 0.05;
inline Lanes atan_over_x(Lanes x2) { return 1.0 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 * (1.0 / 7.0))); }

// atan2(s, c), the twist angle.
inline Lanes bond_angle(Lanes s, Lanes c) {
  const Lanes x = s * reciprocal(c);
  Lanes angle = x * atan_over_x(x * x);
  const auto series = (c > 0.0) & ((s < 0.0 ? -s : s) < series_limit * c);
  if (every_lane(series)) return angle;
  for (std::size_t l = 0; l < lanes; ++l)
    if (!series[l]) angle[l] = std::atan2(s[l], c[l]);  // a lane beyond the series (rare)
  return angle;
}

// Rotation vector turning unit vector a onto unit vector b (exact for any angle, no loss near
// 0 or pi/2); zero where a and b are parallel to the last bit. With s = |a x b| and c = a.b it
// is (a x b) atan2(s, c) / s; in the series' range atan(s/c)/s = atan_over_x(s^2/c^2) / c, so
// neither s nor s/c is needed: one reciprocal, no square root.
inline LaneVec rotation_between(const LaneVec& a, const LaneVec& b) {
  const LaneVec axis = cross(a, b);
  const Lanes s2 = dot(axis, axis), c = dot(a, b), inverse_c = reciprocal(c);
  Lanes scale = inverse_c * atan_over_x(s2 * inverse_c * inverse_c);
  const auto series = (c > 0.0) & (s2 < (series_limit * series_limit) * (c * c));
  if (every_lane(series)) return axis * scale;
  for (std::size_t l = 0; l < lanes; ++l)
    if (!series[l]) {  // beyond the series (rare)
      const double s = std::sqrt(s2[l]);
      scale[l] = s < 1e-300 ? 0.0 : std::atan2(s, c[l]) / s;
    }
  return axis * scale;
}

// A unit vector perpendicular to d, chosen from the coordinate axis least aligned with d.
inline Vec3 perpendicular_to(const Vec3& d) {
  const Vec3 ax{std::abs(d.x), std::abs(d.y), std::abs(d.z)};
  const Vec3 e = (ax.x <= ax.y && ax.x <= ax.z) ? Vec3{1, 0, 0}
                 : (ax.y <= ax.z)               ? Vec3{0, 1, 0}
                                                : Vec3{0, 0, 1};
  return normalized(cross(d, e));
}

}  // namespace

constexpr KeyDoc beam_keys[] = {
    {"E_mu", KeyType::number, "Pa", Range::positive(), "", "the beam's Young's modulus (calibrated: arlequin calibrate)"},
    {"nu_mu", KeyType::number, "1", Range::open_between(-1, 0.5), "0.3", "the beam's Poisson's ratio (its shear modulus)"},
    {"r_mu", KeyType::number, "1", Range::open_between(0, 2), "", "beam radius over the two DEs' mean radius"},
    {"sigma_f", KeyType::number, "Pa", Range::non_negative(), "0", "BBF strength: the bond breaks at this normal stress; 0: never"},
};
std::span<const KeyDoc> BeamBondSet::keys() { return beam_keys; }

std::unique_ptr<BondSet> BeamBondSet::make(CaseNode& section) {
  Parameters prm;
  prm.young = section.number("E_mu", Range::positive(), "Pa");
  prm.poisson = section.number_or("nu_mu", 0.3, Range::open_between(-1.0, 0.5), "1");
  prm.radius_ratio = section.number("r_mu", Range::open_between(0.0, 2.0), "1");
  prm.strength = section.number_or("sigma_f", 0.0, Range::non_negative(), "Pa");
  return std::make_unique<BeamBondSet>(prm);
}

void BeamBondSet::add(std::uint32_t i, std::uint32_t j, const ParticleSet& p) {
  const Quat identity{};
  if (!(p.orientation[i].w == identity.w && p.orientation[i].v == identity.v &&
        p.orientation[j].w == identity.w && p.orientation[j].v == identity.v))
    throw std::logic_error("BeamBondSet::add: DEs must have their reference orientation");
  const Vec3 d = p.position[j] - p.position[i];
  const double L0 = norm(d);
  const double rb = parameters_.radius_ratio * 0.5 * (p.radius[i] + p.radius[j]);
  const double S = std::numbers::pi * rb * rb;
  const double I = 0.25 * std::numbers::pi * rb * rb * rb * rb;
  const double J = 2.0 * I;
  const double G = parameters_.young / (2.0 * (1.0 + parameters_.poisson));
  add_pair(i, j);
  rest_length_.push_back(L0);
  beam_radius_.push_back(rb);
  axial_.push_back(parameters_.young * S / L0);
  bending_.push_back(2.0 * parameters_.young * I / L0);
  torsion_.push_back(G * J / L0);
  const Vec3 direction = d / L0, normal = perpendicular_to(direction);
  for (int k = 0; k < 3; ++k) direction_[k].push_back(direction[k]), normal_[k].push_back(normal[k]);
}

void BeamBondSet::reorder(std::span<const std::uint32_t> order) {
  apply_order(rest_length_, order);
  apply_order(beam_radius_, order);
  apply_order(axial_, order);
  apply_order(bending_, order);
  apply_order(torsion_, order);
  for (int k = 0; k < 3; ++k) apply_order(direction_[k], order), apply_order(normal_[k], order);
}

BeamBondSet::Actions BeamBondSet::actions(std::size_t b, const ParticleSet& p) const {
  ActionsBlock a;
  actions(b, 1, p, a, true);
  return a[0];
}

// Never inlined: one compiled copy serves the gather (which the OpenMP region and the calling
// thread each compile) and single bonds, so FMA contraction cannot differ between them (the bits
// of a bond's actions do not depend on who asks).
[[gnu::noinline]] void BeamBondSet::actions(std::size_t first, std::size_t count, const ParticleSet& p,
                                            ActionsBlock& out, bool with_stresses) const {
  assert(count >= 1 && count <= lanes);
  // Lane l holds bond first + l; lanes past count repeat the last bond (out holds it there
  // again). The DEs' positions (as x, y, z, 0) and orientations are loaded whole, one vector a
  // DE, and transposed; the bonds' own data, stored per component, are consecutive in a full
  // block and load as whole vectors.
  const auto bond_of_lane = [first, count](std::size_t l) { return first + std::min(l, count - 1); };
  std::uint32_t first_de[lanes], second_de[lanes];
  if (count == lanes) {
    std::memcpy(first_de, first_.data() + first, sizeof first_de);
    std::memcpy(second_de, second_.data() + first, sizeof second_de);
  } else
    for (std::size_t l = 0; l < lanes; ++l) first_de[l] = first_[bond_of_lane(l)], second_de[l] = second_[bond_of_lane(l)];
  // Raw pointers: the stores to the local arrays below cannot move them, and the compiler then
  // keeps them in registers.
  const Vec3* position = p.position.data();
  const Quat* orientation = p.orientation.data();
  Quad qa[lanes], qb[lanes], da[lanes];
  for (std::size_t l = 0; l < lanes; ++l) {
    da[l] = load_position(position[second_de[l]]) - load_position(position[first_de[l]]);
    std::memcpy(&qa[l], &orientation[first_de[l]], sizeof(Quad));
    std::memcpy(&qb[l], &orientation[second_de[l]], sizeof(Quad));
  }
  const LaneQuat qi = transpose(qa), qj = transpose(qb);
  const LaneVec d = transpose_vectors(da);
  const auto load = [&](const std::vector<double>& data) {
    Lanes v;
    if (count == lanes) std::memcpy(&v, data.data() + first, sizeof v);
    else
      for (std::size_t l = 0; l < lanes; ++l) v[l] = data[bond_of_lane(l)];
    return v;
  };
  const LaneVec direction{load(direction_[0]), load(direction_[1]), load(direction_[2])};
  const LaneVec normal{load(normal_[0]), load(normal_[1]), load(normal_[2])};
  const Lanes rest_length = load(rest_length_), axial = load(axial_), bending = load(bending_), torsion = load(torsion_);
  // The length and its inverse from the squared length side by side, not one after the other.
  const Lanes length2 = dot(d, d), length = lane_sqrt(length2), inverse_length = inverse_sqrt(length2);
  const LaneVec axis = d * inverse_length;
  const LaneVec theta_a = rotation_between(axis, rotate(qi, direction));
  const LaneVec theta_b = rotation_between(axis, rotate(qj, direction));
  // Twist about the axis between the two body-fixed copies of p0; the components of p
  // along the axis drop out of the triple product, only the cosine term needs them.
  const LaneVec pi = rotate(qi, normal), pj = rotate(qj, normal);
  const Lanes twist = bond_angle(dot(axis, cross(pi, pj)), dot(pi, pj) - dot(pi, axis) * dot(pj, axis));

  const Lanes axial_force = axial * (length - rest_length);
  const Lanes torsion_moment = torsion * twist;
  const LaneVec torque_on_i = -bending * (2.0 * theta_a + theta_b) + torsion_moment * axis;
  const LaneVec torque_on_j = -bending * (theta_a + 2.0 * theta_b) - torsion_moment * axis;
  const LaneVec force_on_j = -axial_force * axis + cross(axis, torque_on_i + torque_on_j) * inverse_length;
  const auto store = [](ActionsBlock::Lane& to, const Lanes& from) { std::memcpy(to, &from, sizeof from); };
  const auto store_vec = [&store](ActionsBlock::Lane* to, const LaneVec& from) {
    store(to[0], from.x), store(to[1], from.y), store(to[2], from.z);
  };
  store(out.length, length), store(out.axial_force, axial_force), store(out.twist, twist);
  store_vec(out.axis, axis), store_vec(out.theta_a, theta_a), store_vec(out.theta_b, theta_b);
  store_vec(out.force_on_j, force_on_j), store_vec(out.torque_on_i, torque_on_i), store_vec(out.torque_on_j, torque_on_j);
  if (!with_stresses) {
    const Lanes nan = Lanes{} + std::numeric_limits<double>::quiet_NaN();
    store(out.axial_stress, nan), store(out.bending_stress, nan);
    return;
  }
  // BBF (header): N / S = E (L - L0) / L0 and r_b |M| / I = 2 E r_b / L0 max(|2 theta_a + theta_b|,
  // |theta_a + 2 theta_b|), with the nominal E.
  const double young = parameters_.young;
  const auto lane_norm = [](const LaneVec& v) { return lane_sqrt(dot(v, v)); };
  const Lanes end_a = lane_norm(2.0 * theta_a + theta_b), end_b = lane_norm(theta_a + 2.0 * theta_b);
  store(out.axial_stress, young * (length - rest_length) / rest_length);
  store(out.bending_stress, 2.0 * young * load(beam_radius_) / rest_length * (end_a < end_b ? end_b : end_a));
}

void BeamBondSet::finalize(std::size_t n_particles) {
  reorder(order_pairs_by_first(n_particles));
  measure_.assign(size(), 0.0);
  // Bond ends per DE (counting sort by DE, bonds in order), then only the DEs that have any.
  std::vector<std::uint32_t> offsets(n_particles + 1, 0);
  for (std::size_t b = 0; b < size(); ++b) ++offsets[first_[b] + 1], ++offsets[second_[b] + 1];
  for (std::size_t i = 0; i < n_particles; ++i) offsets[i + 1] += offsets[i];
  end_bonds_.resize(2 * size());
  std::vector<std::uint32_t> next(offsets.begin(), offsets.end() - 1);
  for (std::size_t b = 0; b < size(); ++b) {
    end_bonds_[next[first_[b]]++] = static_cast<std::uint32_t>(2 * b);
    end_bonds_[next[second_[b]]++] = static_cast<std::uint32_t>(2 * b + 1);
  }
  bonded_.clear();
  end_offsets_.assign(1, 0);
  for (std::size_t i = 0; i < n_particles; ++i)
    if (offsets[i + 1] > offsets[i]) bonded_.push_back(static_cast<std::uint32_t>(i)), end_offsets_.push_back(offsets[i + 1]);
  for (auto& component : bond_actions_) component.assign((size() + block - 1) / block * block, 0.0);
}

void BeamBondSet::accumulate_forces(ParticleSet& p, const ForceScan& scan) const {
  if (end_offsets_.empty()) throw std::logic_error("BeamBondSet: a force pass before finalize()");
  const BondSet* self = this;
  accumulate_gathered_forces({&self, 1}, p, scan);
}

namespace {
// Where DE i's entries begin in a list sorted by DE (first_, bonded_).
long entries_from(const std::vector<std::uint32_t>& by_de, long i) {
  return static_cast<long>(std::lower_bound(by_de.begin(), by_de.end(), static_cast<std::uint32_t>(i)) - by_de.begin());
}
}  // namespace

void BeamBondSet::evaluate_share(const ParticleSet& p, const ForceScan& scan, IndexRange des) const {
  const Records r = records(scan);
  const long bonds = static_cast<long>(size()), n_particles = static_cast<long>(p.size());
  // The bonds whose first DE is one of `des`, the boundaries rounded down to whole blocks.
  const long bond_begin = entries_from(first_, des.begin) / long(block) * long(block);
  const long bond_end = des.end == n_particles ? bonds : entries_from(first_, des.end) / long(block) * long(block);
  // Every bond's actions (and its failure measure or energy), a block at a time, stored whole.
  for (long first = bond_begin; first < bond_end; first += long(block)) {
    ActionsBlock a;
    const std::size_t count = std::min<std::size_t>(block, std::size_t(bonds - first));
    actions(std::size_t(first), count, p, a, r.criterion);
    const double* from[9] = {a.force_on_j[0],  a.force_on_j[1],  a.force_on_j[2],  a.torque_on_i[0], a.torque_on_i[1],
                             a.torque_on_i[2], a.torque_on_j[0], a.torque_on_j[1], a.torque_on_j[2]};
    for (int c = 0; c < 9; ++c) std::memcpy(bond_actions_[c].data() + first, from[c], sizeof(ActionsBlock::Lane));
    if (r.criterion) {  // failure_measure, lane by lane; the lanes at the strength one by one (rare)
      Lanes axial_stress, bending_stress;
      std::memcpy(&axial_stress, a.axial_stress, sizeof axial_stress);
      std::memcpy(&bending_stress, a.bending_stress, sizeof bending_stress);
      const Lanes measure = axial_stress + bending_stress;
      std::memcpy(measure_.data() + first, &measure, count * sizeof(double));
      if (!every_lane(measure < strength()))
        for (std::size_t l = 0; l < count; ++l) note_measure(first + l, measure[l]);
    }
    if (r.energy)
      for (std::size_t l = 0; l < count; ++l) energy_record_[first + l] = energy_of(first + l, a[l]);
  }
}

void BeamBondSet::add_share(ParticleSet& p, const ForceScan& scan, IndexRange des) const {
  const Records r = records(scan);
  // Every bonded DE of `des` adds its bonds' actions in bond order (-f on a first DE, +f on a
  // second). Raw pointers: nothing in the loop can move the arrays, and the compiler keeps them
  // in registers.
  const double *fx = bond_actions_[0].data(), *fy = bond_actions_[1].data(), *fz = bond_actions_[2].data();
  const double *tix = bond_actions_[3].data(), *tiy = bond_actions_[4].data(), *tiz = bond_actions_[5].data();
  const double *tjx = bond_actions_[6].data(), *tjy = bond_actions_[7].data(), *tjz = bond_actions_[8].data();
  const std::uint32_t *bonded = bonded_.data(), *offsets = end_offsets_.data(), *ends = end_bonds_.data();
  Vec3 *force = p.force.data(), *torque = p.torque.data();
  const long k_begin = entries_from(bonded_, des.begin), k_end = entries_from(bonded_, des.end);
  for (long k = k_begin; k < k_end; ++k) {
    Vec3 f{}, t{};
    for (std::uint32_t e = offsets[k]; e < offsets[k + 1]; ++e) {
      const std::uint32_t b = ends[e] >> 1;
      if (ends[e] & 1u) {
        f += Vec3{fx[b], fy[b], fz[b]};
        t += Vec3{tjx[b], tjy[b], tjz[b]};
      } else {
        f -= Vec3{fx[b], fy[b], fz[b]};
        t += Vec3{tix[b], tiy[b], tiz[b]};
      }
    }
    force[bonded[k]] += f;
    torque[bonded[k]] += t;
  }
  if (!r.virial) return;
  // Recording the virial (RDEF): each DE's intact bonds' terms, in bond order, as accumulate_virial.
  for (long k = k_begin; k < k_end; ++k)
    for (std::uint32_t e = offsets[k]; e < offsets[k + 1]; ++e) {
      const std::uint32_t b = ends[e] >> 1;
      if (!broken_[b])
        add_bond_end_virial(p, first_[b], second_[b], -Vec3{fx[b], fy[b], fz[b]}, scan.branch, static_cast<int>(ends[e] & 1u),
                            scan.virial[bonded[k]]);
    }
}

double BeamBondSet::energy_of(std::size_t b, const Actions& a) const {
  const double stretch = a.length - rest_length_[b];
  return 0.5 * axial_[b] * stretch * stretch +
         bending_[b] * (norm2(a.theta_a) + dot(a.theta_a, a.theta_b) + norm2(a.theta_b)) +
         0.5 * torsion_[b] * a.twist * a.twist;
}

// The dominant stress of a failing bond: the largest of |N/S|, r_b|M|/I, the shear stress
// V/S = 1.5 E r_b^2 |theta_a + theta_b| / L0^2 and the torsion stress G r_b |phi| / L0.
FailureMode BeamBondSet::mode_of(std::size_t b, const Actions& a) const {
  const double E = parameters_.young, G = E / (2.0 * (1.0 + parameters_.poisson));
  const double L0 = rest_length_[b], rb = beam_radius_[b];
  const double axial = a.axial_stress, bending = a.bending_stress;
  const double shear = 1.5 * E * rb * rb * norm(a.theta_a + a.theta_b) / (L0 * L0);
  const double torsion = G * rb * std::abs(a.twist) / L0;
  FailureMode mode = axial >= 0.0 ? FailureMode::tension : FailureMode::compression;
  double dominant = std::abs(axial);
  for (auto [value, m] : {std::pair{bending, FailureMode::bending}, std::pair{shear, FailureMode::shear},
                          std::pair{torsion, FailureMode::torsion}})
    if (value > dominant) dominant = value, mode = m;
  return mode;
}

void BeamBondSet::add_frequency_bound(std::size_t b, const ParticleSet& p, std::span<double> translational,
                                      std::span<double> rotational) const {
  const double L0 = rest_length_[b], kb = bending_[b], kt = torsion_[b];
  const double k_trans = std::max(axial_[b], 6.0 * kb / (L0 * L0));  // E S/L, 12 E I/L^3
  const double k_cross = 3.0 * kb / L0;                               // 6 E I / L^2
  const double k_rot_own = std::max(2.0 * kb, kt);                    // 4 E I / L, G J / L
  const double k_rot_other = std::max(kb, kt);                        // 2 E I / L, G J / L
  for (int end = 0; end < 2; ++end) {
    const std::uint32_t i = end == 0 ? first_[b] : second_[b];
    const std::uint32_t j = end == 0 ? second_[b] : first_[b];
    const double mi = p.inv_mass[i], mj = p.inv_mass[j];
    const double Ii = p.inv_inertia(i), Ij = p.inv_inertia(j);
    translational[i] += k_trans * (mi + std::sqrt(mi * mj)) +
                        k_cross * (std::sqrt(mi * Ii) + std::sqrt(mi * Ij));
    rotational[i] += k_rot_own * Ii + k_rot_other * std::sqrt(Ii * Ij) +
                     k_cross * (std::sqrt(Ii * mi) + std::sqrt(Ii * mj));
  }
}

}  // namespace arlequin::dem
