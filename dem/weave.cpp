// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/weave.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

#include "dem/bonds/spring_bond.hpp"
#include "dem/samples.hpp"

namespace arlequin::dem {
namespace {

constexpr double pi = std::numbers::pi;

// A yarn's centre line: u runs along the yarn's axis (x for a weft, y for a warp) from 0 to
// `length`; the centre is u e_axis + offset e_across + z(u) e_z.
struct YarnPath {
  int axis;       // 0: along x (weft), 1: along y (warp)
  double length;  // extent of u, m
  double offset;  // coordinate across (y for a weft, x for a warp), m
  std::function<double(double)> z, dz;  // height and its slope along u
};

Vec3 along(int axis, double u, double across, double z) {
  return axis == 0 ? Vec3{u, across, z} : Vec3{across, u, z};
}

// The centre of the chain at (across, through) offsets, at u: through along the path's normal
// in the (axis, z) plane.
Vec3 chain_point(const YarnPath& path, double u, double across, double through) {
  const double slope = path.dz(u);
  const double inv = 1.0 / std::sqrt(1.0 + slope * slope);
  return along(path.axis, u - through * slope * inv, path.offset + across, path.z(u) + through * inv);
}

// Fine polyline samples per DE spacing: the arc length and the DEs' places on a curve of the
// weave's curvature are then exact to far below the overlap tolerance.
constexpr int samples_per_spacing = 32;

// A chain's curve as a fine polyline: its points and their arc lengths from the start.
struct Polyline {
  std::vector<Vec3> x;
  std::vector<double> s;
};
Polyline polyline(const YarnPath& path, double across, double through, double spacing) {
  const int fine = std::max(64, int(std::ceil(samples_per_spacing * path.length / spacing)));
  Polyline line{std::vector<Vec3>(fine + 1), std::vector<double>(fine + 1, 0.0)};
  for (int k = 0; k <= fine; ++k) {
    line.x[k] = chain_point(path, path.length * k / fine, across, through);
    if (k > 0) line.s[k] = line.s[k - 1] + norm(line.x[k] - line.x[k - 1]);
  }
  return line;
}

// The DEs of one chain: the curve split into floor(L_c / spacing) arcs of equal length, a DE at
// every arc's ends. Returns the centres in order.
std::vector<Vec3> sample_chain(const YarnPath& path, double across, double through, double spacing) {
  const auto [x, s] = polyline(path, across, through, spacing);
  const int fine = int(x.size()) - 1;
  const int arcs = std::max(1, int(std::floor(s[fine] / spacing * (1.0 + 1e-12))));
  std::vector<Vec3> des(arcs + 1);
  int k = 0;
  for (int n = 0; n <= arcs; ++n) {
    const double target = s[fine] * n / arcs;
    while (k + 1 < fine && s[k + 1] < target) ++k;
    const double f = s[k + 1] > s[k] ? std::clamp((target - s[k]) / (s[k + 1] - s[k]), 0.0, 1.0) : 0.0;
    des[n] = x[k] + (x[k + 1] - x[k]) * f;
  }
  return des;
}

double centre_length(const YarnPath& path, double spacing) { return polyline(path, 0.0, 0.0, spacing).s.back(); }

struct Geometry {
  const WeaveSpec& spec;
  double R, pitch_across;
  int columns_y, columns_x;  // N_y weft columns, N_x stuffer columns

  double z_mid() const { return (spec.weft_layers - 1) * spec.yarn_thickness; }
  double first_column_y() const { return 0.5 * spec.weft_spacing; }

  YarnPath weft(int layer, int j) const {
    const double z = 2.0 * layer * spec.yarn_thickness;
    return {0, spec.length_x, (j + 0.5) * spec.weft_spacing, [z](double) { return z; }, [](double) { return 0.0; }};
  }
  YarnPath stuffer(int layer, int i) const {
    const double z = (2.0 * layer + 1.0) * spec.yarn_thickness;
    return {1, spec.length_y, (i + 0.5) * spec.warp_spacing, [z](double) { return z; }, [](double) { return 0.0; }};
  }
  YarnPath binder(int i, double amplitude) const {
    const double zm = z_mid(), y0 = first_column_y(), k = pi / spec.weft_spacing, phase = i * pi;
    return {1, spec.length_y, (i + 1.0) * spec.warp_spacing,
            [=](double y) { return zm + amplitude * std::cos(k * (y - y0) + phase); },
            [=](double y) { return -amplitude * k * std::sin(k * (y - y0) + phase); }};
  }

  // Offsets of a yarn's chains in its cross-section: across, then through.
  std::vector<std::pair<double, double>> chain_offsets() const {
    std::vector<std::pair<double, double>> out;
    for (int b = 0; b < spec.chains_through; ++b)
      for (int a = 0; a < spec.chains_across; ++a)
        out.emplace_back((a - 0.5 * (spec.chains_across - 1)) * pitch_across, (b - 0.5 * (spec.chains_through - 1)) * 2.0 * R);
    return out;
  }
};

// DEs being built: positions and, per DE, its chain (a chain's DEs are consecutive, so two DEs
// share a spring exactly when they are neighbours in one chain).
struct Draft {
  std::vector<Vec3> x;
  std::vector<std::uint32_t> chain;
  std::uint32_t chains = 0;

  void add_yarn(const Geometry& g, const YarnPath& path) {
    for (const auto& [across, through] : g.chain_offsets()) {
      for (const Vec3& p : sample_chain(path, across, through, 2.0 * g.R)) {
        x.push_back(p);
        chain.push_back(chains);
      }
      ++chains;
    }
  }
};

// The deepest interpenetration, over 2R, of two DEs of `draft` that share no spring.
double deepest_overlap(const Draft& draft, double R) {
  ParticleSet p;
  p.reserve(draft.x.size());
  for (const Vec3& x : draft.x) p.add(x, R, 1.0);
  double deepest = 0.0;
  for (const auto& [i, j] : close_pairs(p, 0.0)) {
    if (draft.chain[i] == draft.chain[j] && j == i + 1) continue;
    deepest = std::max(deepest, (2.0 * R - norm(draft.x[j] - draft.x[i])) / (2.0 * R));
  }
  return deepest;
}

// Overlap of the binders with the weft columns they cross, at amplitude A (the stuffers lie
// beside the binders, clear of them by check_geometry). Every binder: the weft DEs sit at a
// different place along x under each one.
double binder_overlap(const Geometry& g, const Draft& wefts, double amplitude) {
  Draft draft;
  for (int i = 0; i + 1 < g.columns_x; ++i) draft.add_yarn(g, g.binder(i, amplitude));
  for (std::size_t n = 0; n < wefts.x.size(); ++n) {
    draft.x.push_back(wefts.x[n]);
    draft.chain.push_back(draft.chains + wefts.chain[n]);
  }
  return deepest_overlap(draft, g.R);
}

double binder_crimp(const Geometry& g, double amplitude) {
  return centre_length(g.binder(0, amplitude), 2.0 * g.R) / g.spec.length_y - 1.0;
}

// The smallest amplitude at which the binders clear the weft columns, to 0.1 %, by bisection
// from the one that just passes over the top weft (K t) to four times that; 0 if even that
// does not clear them.
double clearing_amplitude(const Geometry& g, const Draft& wefts) {
  const auto clears = [&](double A) { return binder_overlap(g, wefts, A) <= weave_overlap_tolerance; };
  double lo = g.spec.weft_layers * g.spec.yarn_thickness, hi = 4.0 * lo;
  if (clears(lo)) return lo;
  if (!clears(hi)) return 0.0;
  while (hi - lo > 1e-3 * lo) (clears(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
  return hi;
}

Draft all_wefts(const Geometry& g) {
  Draft wefts;
  for (int k = 0; k < g.spec.weft_layers; ++k)
    for (int j = 0; j < g.columns_y; ++j) wefts.add_yarn(g, g.weft(k, j));
  return wefts;
}

std::string mm(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g mm", metres * 1e3);
  return text;
}

Geometry check_geometry(const WeaveSpec& s) {
  Geometry g{s, s.yarn_thickness / (2.0 * s.chains_through), s.yarn_width / s.chains_across, 0, 0};
  if (g.pitch_across < 2.0 * g.R * (1.0 - weave_overlap_tolerance))
    throw WeaveError("chains_across", "a yarn " + mm(s.yarn_width) + " wide holds at most " +
                                          std::to_string(int(s.yarn_width / (2.0 * g.R) + 1e-9)) + " chains of DEs of radius " +
                                          mm(g.R) + " (yarn_thickness / (2 chains_through)) side by side");
  g.columns_y = int(std::floor(s.length_y / s.weft_spacing + 1e-9));
  g.columns_x = int(std::floor(s.length_x / s.warp_spacing + 1e-9));
  if (g.columns_y < 2)
    throw WeaveError("weft_spacing", "the fabric, " + mm(s.length_y) + " along y, holds fewer than two weft columns " +
                                         mm(s.weft_spacing) + " apart");
  if (g.columns_x < 2)
    throw WeaveError("warp_spacing", "the fabric, " + mm(s.length_x) + " along x, holds fewer than two stuffer columns " +
                                         mm(s.warp_spacing) + " apart (a binder runs between two)");
  // A yarn's half-extent across: its outer chains' centres plus R.
  const double half_extent = 0.5 * (s.chains_across - 1) * g.pitch_across + g.R;
  if (s.weft_spacing < 2.0 * half_extent * (1.0 - weave_overlap_tolerance))
    throw WeaveError("weft_spacing", "weft columns " + mm(s.weft_spacing) + " apart interpenetrate: each is " +
                                         mm(2.0 * half_extent) + " wide");
  if (0.5 * s.warp_spacing < 2.0 * half_extent * (1.0 - weave_overlap_tolerance))
    throw WeaveError("warp_spacing", "a binder midway between stuffers " + mm(s.warp_spacing) + " apart cuts them: the spacing must be at least " +
                                         mm(4.0 * half_extent) + " (two yarn widths)");
  return g;
}

}  // namespace

WeaveReport build_weave(DemModel& model, const WeaveSpec& s, const std::function<bool(const Vec3&)>& keep) {
  const Geometry g = check_geometry(s);
  WeaveReport report;
  report.radius = g.R;

  // The binders' amplitude: from the crimp asked for, or the smallest that clears the weft.
  const Draft wefts = all_wefts(g);
  const double clearing = clearing_amplitude(g, wefts);
  if (clearing == 0.0)
    throw WeaveError("weft_spacing", "binders cannot pass between weft columns " + mm(s.weft_spacing) +
                                         " apart at any amplitude up to four weft layers: widen the spacing");
  double A = clearing;
  if (s.crimp > 0.0) {
    double lo = 0.0, hi = 8.0 * clearing;
    if (binder_crimp(g, hi) < s.crimp) throw WeaveError("crimp", "a binder crimp this large needs an amplitude beyond eight fabric thicknesses");
    for (int it = 0; it < 60; ++it) ((binder_crimp(g, 0.5 * (lo + hi)) < s.crimp) ? lo : hi) = 0.5 * (lo + hi);
    A = 0.5 * (lo + hi);
    if (binder_overlap(g, wefts, A) > weave_overlap_tolerance) {
      char why[200];
      std::snprintf(why, sizeof why,
                    "at crimp %.4g the binders (amplitude %s) cut through the weft columns; the smallest crimp that clears "
                    "them is %.4g",
                    s.crimp, mm(A).c_str(), binder_crimp(g, clearing));
      throw WeaveError("crimp", why);
    }
  }
  report.amplitude = A;
  report.crimp = binder_crimp(g, A);

  // Every yarn, family by family; each yarn's DEs and centre-line length.
  Draft draft;
  struct Yarn {
    std::string name;
    int family;  // 0 weft, 1 stuffer, 2 binder
    std::size_t first, end;
    double length;
  };
  std::vector<Yarn> yarns;
  const auto add = [&](std::string name, int family, const YarnPath& path) {
    const std::size_t first = draft.x.size();
    draft.add_yarn(g, path);
    yarns.push_back({std::move(name), family, first, draft.x.size(), centre_length(path, 2.0 * g.R)});
  };
  for (int k = 0; k < s.weft_layers; ++k)
    for (int j = 0; j < g.columns_y; ++j) add("weft_" + std::to_string(k) + "_" + std::to_string(j), 0, g.weft(k, j));
  for (int k = 0; k + 1 < s.weft_layers; ++k)
    for (int i = 0; i < g.columns_x; ++i) add("stuffer_" + std::to_string(k) + "_" + std::to_string(i), 1, g.stuffer(k, i));
  for (int i = 0; i + 1 < g.columns_x; ++i) add("binder_" + std::to_string(i), 2, g.binder(i, A));
  report.deepest_overlap = deepest_overlap(draft, g.R);

  // DEs: each yarn's mass rho S L_y shared equally by its DEs (those kept are created).
  ParticleSet& p = model.particles;
  constexpr std::uint32_t not_kept = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> id(draft.x.size(), not_kept);
  p.reserve(p.size() + draft.x.size());
  const double de_volume = 4.0 / 3.0 * pi * g.R * g.R * g.R;
  for (const Yarn& y : yarns) {
    const double yarn_mass = s.density * s.section * y.length;
    const double de_mass = yarn_mass / double(y.end - y.first);
    for (std::size_t n = y.first; n < y.end; ++n)
      if (!keep || keep(draft.x[n])) {
        id[n] = static_cast<std::uint32_t>(p.add(draft.x[n], g.R, de_mass / de_volume));
        p.inv_mass[id[n]] = 1.0 / de_mass;
      }
    report.mass += yarn_mass;
    report.family_mass[y.family] += yarn_mass;
  }

  // Springs along every chain, one set per family.
  static constexpr const char* families[] = {"weft", "stuffer", "binder"};
  const double EA = s.modulus * s.section / (s.chains_across * s.chains_through);
  BondSet* sets[3];
  for (int f = 0; f < 3; ++f) {
    sets[f] = &model.add_bond_set(SpringBondSet::with_axial_rigidity(EA, s.failure_strain));
    sets[f]->name = families[f];
  }
  for (const Yarn& y : yarns)
    for (std::size_t n = y.first; n + 1 < y.end; ++n)
      if (draft.chain[n] == draft.chain[n + 1] && id[n] != not_kept && id[n + 1] != not_kept) {
        sets[y.family]->add(id[n], id[n + 1], p);
        ++report.springs;
      }

  // Groups: families, yarns (those with DEs kept), the clamped edges.
  std::vector<std::uint32_t> family_members[3];
  for (const Yarn& y : yarns) {
    std::vector<std::uint32_t> ids;
    for (std::size_t n = y.first; n < y.end; ++n)
      if (id[n] != not_kept) ids.push_back(id[n]);
    if (ids.empty()) continue;
    family_members[y.family].insert(family_members[y.family].end(), ids.begin(), ids.end());
    model.add_group(y.name, std::move(ids));
  }
  for (int f = 0; f < 3; ++f) model.add_group(families[f], std::move(family_members[f]));
  std::vector<std::uint32_t> edges;
  for (std::size_t n = 0; n < draft.x.size(); ++n) {
    const Vec3& x = draft.x[n];
    if (id[n] != not_kept && std::min({x.x, s.length_x - x.x, x.y, s.length_y - x.y}) < s.clamp_width) edges.push_back(id[n]);
  }
  model.add_group("edges", std::move(edges));

  double total_length = 0.0;
  for (const Yarn& y : yarns) {
    ++(y.family == 0 ? report.wefts : y.family == 1 ? report.stuffers : report.binders);
    (y.family == 0 ? report.weft_length : y.family == 1 ? report.stuffer_length : report.binder_length) = y.length;
    total_length += y.length;
  }
  report.thickness = 2.0 * A + s.yarn_thickness;
  report.areal_density = report.mass / (s.length_x * s.length_y);
  report.fibre_volume_fraction = s.section * total_length / (s.length_x * s.length_y * report.thickness);
  report.spring_stiffness = EA / (2.0 * g.R);
  report.rule_of_mixtures_x = s.modulus * s.section * s.weft_layers / (s.weft_spacing * report.thickness);
  report.rule_of_mixtures_y = s.modulus * s.section * (s.weft_layers - 1) / (s.warp_spacing * report.thickness);
  report.des = std::size_t(std::count_if(id.begin(), id.end(), [](std::uint32_t i) { return i != not_kept; }));
  report.des_not_kept = draft.x.size() - report.des;
  return report;
}

}  // namespace arlequin::dem
