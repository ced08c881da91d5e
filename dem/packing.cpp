// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/packing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <variant>

#include "common/error.hpp"
#include "dem/neighbour_list.hpp"
#include "dem/samples.hpp"

namespace arlequin::dem {
namespace {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

constexpr double pi = std::numbers::pi;
double sphere_volume(double r) { return 4.0 / 3.0 * pi * r * r * r; }

// Wall layers are looser than the bulk (the first layer touches the wall at points), so the
// DEs are counted for the region eroded by a wall deficit: the solid volume is the target
// compaction times the eroded volume. First guess, in mean radii: 0.22, from the 0.20-0.23
// measured for relative_std 0.25 on boxes and cylinders of 0.8k-40k DEs; a second pass
// corrects it from the first pass's own compaction.
constexpr double first_wall_deficit = 0.22;
// Compaction error accepted without the second pass.
constexpr double compaction_slack = 0.005;
// Largest overlap accepted in a result, in mean radii. More means the packing jammed below
// the target: athermal compression jams the bulk at ~0.64 (relative_std 0.25), small samples
// earlier, so the second pass then aims this much below the compaction that jammed.
constexpr double overlap_limit = 1e-3;
constexpr double jamming_backoff = 0.01;

// Uniform and normal deviates from raw std::mt19937_64 words: the standard distributions
// are implementation-defined, and a seed must give the same sample with any library.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  // Box & Muller, Ann. Math. Stat. 29 (1958) 610; the sine half of the pair is not used.
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]: the logarithm stays finite
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * pi * u2);
  }

 private:
  std::mt19937_64 engine_;
};

// The region's geometry as far as packing needs it: bounds, erosion, volume and walls.
class Domain {
 public:
  explicit Domain(const Region& region) : shape_(region.shape()) {
    std::visit(Overloaded{
                   [&](const Box& b) { lower_ = b.lower, upper_ = b.upper; },
                   [&](const Cylinder& c) {
                     if (c.length < 0.0) throw std::invalid_argument("packing: the cylinder needs a length");
                     const Vec3 top = c.base + c.length * c.axis;
                     for (int k = 0; k < 3; ++k) {
                       const double reach = c.radius * std::sqrt(std::max(0.0, 1.0 - c.axis[k] * c.axis[k]));
                       lower_[k] = std::min(c.base[k], top[k]) - reach;
                       upper_[k] = std::max(c.base[k], top[k]) + reach;
                     }
                   },
                   [&](const Sphere& s) {
                     lower_ = s.center - Vec3{s.radius, s.radius, s.radius};
                     upper_ = s.center + Vec3{s.radius, s.radius, s.radius};
                   },
                   [&](const HalfSpace&) {
                     throw std::invalid_argument("packing: the region must be bounded (box, cylinder or sphere)");
                   },
               },
               shape_);
  }

  const Vec3& lower() const { return lower_; }
  const Vec3& upper() const { return upper_; }

  // Volume of the points at least `erosion` inside the boundary.
  double volume(double erosion) const {
    const auto positive = [](double a) { return std::max(0.0, a); };
    return std::visit(Overloaded{
                          [&](const Box& b) {
                            double v = 1.0;
                            for (int k = 0; k < 3; ++k) v *= positive(b.upper[k] - b.lower[k] - 2.0 * erosion);
                            return v;
                          },
                          [&](const Cylinder& c) {
                            const double r = positive(c.radius - erosion);
                            return pi * r * r * positive(c.length - 2.0 * erosion);
                          },
                          [&](const Sphere& s) { return sphere_volume(positive(s.radius - erosion)); },
                          [](const HalfSpace&) { return 0.0; },
                      },
                      shape_);
  }

  // Distance from x to the boundary, positive inside.
  double clearance(const Vec3& x) const {
    return std::visit(Overloaded{
                          [&](const Box& b) {
                            double c = std::numeric_limits<double>::max();
                            for (int k = 0; k < 3; ++k) c = std::min({c, x[k] - b.lower[k], b.upper[k] - x[k]});
                            return c;
                          },
                          [&](const Cylinder& c) {
                            const Vec3 d = x - c.base;
                            const double a = dot(d, c.axis);
                            return std::min({a, c.length - a, c.radius - norm(d - a * c.axis)});
                          },
                          [&](const Sphere& s) { return s.radius - norm(x - s.center); },
                          [](const HalfSpace&) { return 0.0; },
                      },
                      shape_);
  }
  bool contains(const Vec3& x, double erosion) const { return clearance(x) >= erosion; }

  // Sum over the walls a sphere (x, r) crosses of overlap times the inward normal: the
  // wall force at unit stiffness. Raises max_overlap to the largest overlap.
  Vec3 wall_push(const Vec3& x, double r, double& max_overlap) const {
    Vec3 push{};
    const auto wall = [&](double overlap, const Vec3& inward) {
      if (overlap <= 0.0) return;
      push += overlap * inward;
      max_overlap = std::max(max_overlap, overlap);
    };
    std::visit(Overloaded{
                   [&](const Box& b) {
                     for (int k = 0; k < 3; ++k) {
                       Vec3 e{};
                       e[k] = 1.0;
                       wall(r - (x[k] - b.lower[k]), e);
                       wall(r - (b.upper[k] - x[k]), -e);
                     }
                   },
                   [&](const Cylinder& c) {
                     const Vec3 d = x - c.base;
                     const double a = dot(d, c.axis);
                     wall(r - a, c.axis);
                     wall(r - (c.length - a), -c.axis);
                     const Vec3 radial = d - a * c.axis;
                     const double rho = norm(radial);
                     if (rho > 0.0) wall(r - (c.radius - rho), radial / -rho);
                   },
                   [&](const Sphere& s) {
                     const Vec3 d = x - s.center;
                     const double rho = norm(d);
                     if (rho > 0.0) wall(r - (s.radius - rho), d / -rho);
                   },
                   [](const HalfSpace&) {},
               },
               shape_);
    return push;
  }

 private:
  Region::Shape shape_;
  Vec3 lower_, upper_;
};

void check(const PackingSpec& s) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("packing: ") + what);
  };
  require(s.mean_radius > 0.0, "mean_radius must be positive");
  require(s.relative_std >= 0.0, "relative_std must not be negative");
  require(s.relative_std == 0.0 || s.truncation > 0.0, "truncation must be positive");
  require(s.relative_std * s.truncation < 1.0, "relative_std x truncation must be below 1 (positive radii)");
  require(s.target_compaction > 0.0 && s.target_compaction < 0.7, "target_compaction must be in (0, 0.7)");
  require(s.min_coordination >= 0.0, "min_coordination must not be negative");
  require(s.bond_tolerance > 0.0 && s.bond_tolerance < 0.5, "bond_tolerance must be in (0, 0.5)");
}

// Radii mean (1 + std z), z standard normal redrawn while |z| > truncation, until their
// spheres' volume reaches solid_volume.
std::vector<double> draw_radii(const PackingSpec& spec, double solid_volume, Random& random) {
  std::vector<double> radii;
  for (double volume = 0.0; volume < solid_volume;) {
    double z = 0.0;
    if (spec.relative_std > 0.0) {
      do z = random.normal();
      while (std::abs(z) > spec.truncation);
    }
    radii.push_back(spec.mean_radius * (1.0 + spec.relative_std * z));
    volume += sphere_volume(radii.back());
  }
  return radii;
}

// Uniform cell grid over the domain's bounding box, cells of edge >= h.
class Grid {
 public:
  Grid(const Domain& domain, double h) : lower_(domain.lower()), h_(h) {
    for (int k = 0; k < 3; ++k) n_[k] = std::max(1L, static_cast<long>((domain.upper()[k] - lower_[k]) / h));
  }
  std::array<long, 3> cell(const Vec3& x) const {
    std::array<long, 3> c;
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(static_cast<long>((x[k] - lower_[k]) / h_), 0L, n_[k] - 1);
    return c;
  }
  long index(const std::array<long, 3>& c) const { return (c[2] * n_[1] + c[1]) * n_[0] + c[0]; }
  long cells() const { return n_[0] * n_[1] * n_[2]; }
  // Calls f(cell index) for the cells around c (itself included).
  template <class F>
  void around(const std::array<long, 3>& c, F&& f) const {
    for (long z = std::max(0L, c[2] - 1); z <= std::min(n_[2] - 1, c[2] + 1); ++z)
      for (long y = std::max(0L, c[1] - 1); y <= std::min(n_[1] - 1, c[1] + 1); ++y)
        for (long x = std::max(0L, c[0] - 1); x <= std::min(n_[0] - 1, c[0] + 1); ++x) f(index({x, y, z}));
  }

 private:
  Vec3 lower_;
  double h_;
  std::array<long, 3> n_{};
};

// Random sequential addition: each sphere (radius scale * R_i, in order) at the first of
// uniformly drawn points where it is inside the domain and overlaps no earlier sphere.
std::vector<Vec3> insert_randomly(const Domain& domain, const std::vector<double>& radii, double scale,
                                  Random& random) {
  const double r_max = *std::max_element(radii.begin(), radii.end());
  const Grid grid(domain, 2.0 * scale * r_max);
  std::vector<std::vector<std::uint32_t>> members(grid.cells());
  std::vector<Vec3> x(radii.size());
  const Vec3 lo = domain.lower(), size = domain.upper() - domain.lower();
  constexpr int max_attempts = 1'000'000;
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double r = scale * radii[i];
    int attempt = 0;
    for (;; ++attempt) {
      if (attempt == max_attempts)
        throw RunError("packing: no room to insert DE " + std::to_string(i) + " of " + std::to_string(radii.size()));
      const Vec3 trial = lo + Vec3{random.uniform() * size.x, random.uniform() * size.y, random.uniform() * size.z};
      if (!domain.contains(trial, r)) continue;
      bool free = true;
      grid.around(grid.cell(trial), [&](long c) {
        for (const std::uint32_t j : members[c]) {
          const double reach = r + scale * radii[j];
          if (norm2(x[j] - trial) < reach * reach) free = false;
        }
      });
      if (!free) continue;
      x[i] = trial;
      members[grid.index(grid.cell(trial))].push_back(static_cast<std::uint32_t>(i));
      break;
    }
  }
  return x;
}

// The DEs being packed, at radii scale * R_i, and their relaxation: the minimum of the
// soft-sphere energy U = sum k/2 overlap^2 over DE pairs and DE-wall contacts (k = 1, unit
// masses) by FIRE (Bitzek et al., PRL 97 (2006) 170201, with the semi-implicit Euler step and
// back-step of Guénolé et al., Comput. Mater. Sci. 175 (2020) 109584). Only the minimum
// matters, so the time unit is sqrt(m/k) = 1.
class Packer {
 public:
  Packer(const Domain& domain, const std::vector<Vec3>& x, std::vector<double> radii, double mean_radius)
      : domain_(domain), radii_(std::move(radii)), mean_radius_(mean_radius),
        r_max_(*std::max_element(radii_.begin(), radii_.end())), list_(skin_factor * mean_radius) {
    for (std::size_t i = 0; i < x.size(); ++i) work_.add(x[i], radii_[i], 1.0);
  }

  void set_scale(double scale) {
    scale_ = scale;
    for (std::size_t i = 0; i < radii_.size(); ++i) work_.radius[i] = scale * radii_[i];
  }
  const ParticleSet& particles() const { return work_; }
  // Largest overlap at the last force evaluation / mean radius.
  double max_overlap() const { return max_overlap_ / mean_radius_; }

  // FIRE until every net force is below force_tolerance mean radii (a k = 1 overlap) or
  // after max_iterations.
  void relax(double force_tolerance, long max_iterations) {
    // Bitzek et al.'s parameters; steps in units of sqrt(m/k) = 1, dt_max below the explicit
    // stability limit 2/omega_max ~ 2/sqrt(2 x 14 contacts).
    constexpr double dt_max = 0.3, dt_min = 0.002, f_inc = 1.1, f_dec = 0.5, alpha_start = 0.1, f_alpha = 0.99;
    constexpr int delay = 5;
    double dt = 0.1, alpha = alpha_start;
    int positive_steps = 0;
    auto& x = work_.position;
    auto& v = work_.velocity;
    auto& f = work_.force;
    std::fill(v.begin(), v.end(), Vec3{});
    compute_forces();
    for (long it = 0; it < max_iterations && max_force_ >= force_tolerance * mean_radius_; ++it) {
      double power = 0.0;
      for (std::size_t i = 0; i < x.size(); ++i) power += dot(f[i], v[i]);
      if (power > 0.0) {
        if (++positive_steps > delay) {
          dt = std::min(dt * f_inc, dt_max);
          alpha *= f_alpha;
        }
      } else {
        positive_steps = 0;
        dt = std::max(dt * f_dec, dt_min);
        alpha = alpha_start;
        for (std::size_t i = 0; i < x.size(); ++i) x[i] -= 0.5 * dt * v[i];
        std::fill(v.begin(), v.end(), Vec3{});
      }
      double v2 = 0.0, f2 = 0.0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        v[i] += dt * f[i];
        v2 += norm2(v[i]);
        f2 += norm2(f[i]);
      }
      const double mix = f2 > 0.0 ? alpha * std::sqrt(v2 / f2) : 0.0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        v[i] = (1.0 - alpha) * v[i] + mix * f[i];
        x[i] += dt * v[i];
      }
      compute_forces();
    }
  }

 private:
  static constexpr double skin_factor = 0.4;  // list skin / mean radius

  // The list holds pairs within R_i + R_j + skin at the build; it stays complete while twice
  // the largest displacement plus the growth of the largest pair of radii fits in the skin.
  void update_neighbours() {
    if (built_) {
      double moved2 = 0.0;
      for (std::size_t i = 0; i < work_.size(); ++i)
        moved2 = std::max(moved2, norm2(work_.position[i] - at_build_[i]));
      if (2.0 * std::sqrt(moved2) + 2.0 * (scale_ - scale_at_build_) * r_max_ < list_.skin()) return;
    }
    list_.build(work_);
    at_build_ = work_.position;
    scale_at_build_ = scale_;
    built_ = true;
  }

  void compute_forces() {
    update_neighbours();
    auto& x = work_.position;
    auto& f = work_.force;
    const auto& r = work_.radius;
    std::fill(f.begin(), f.end(), Vec3{});
    max_overlap_ = 0.0;
    for (const auto& [i, j] : list_.pairs()) {
      const Vec3 d = x[j] - x[i];
      const double reach = r[i] + r[j], d2 = norm2(d);
      if (d2 >= reach * reach || d2 == 0.0) continue;
      const double distance = std::sqrt(d2), overlap = reach - distance;
      const Vec3 push = (overlap / distance) * d;
      f[j] += push;
      f[i] -= push;
      max_overlap_ = std::max(max_overlap_, overlap);
    }
    max_force_ = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      f[i] += domain_.wall_push(x[i], r[i], max_overlap_);
      max_force_ = std::max(max_force_, norm2(f[i]));
    }
    max_force_ = std::sqrt(max_force_);
  }

  const Domain& domain_;
  std::vector<double> radii_;  // final radii R_i
  double mean_radius_, r_max_;
  double scale_ = 1.0;
  ParticleSet work_;  // positions, velocities, forces, radii scale * R_i
  NeighbourList list_;
  std::vector<Vec3> at_build_;
  double scale_at_build_ = 0.0;
  bool built_ = false;
  double max_overlap_ = 0.0, max_force_ = 0.0;
};

// Eigenvalues of a symmetric 3x3 matrix, ascending (trigonometric solution of the
// characteristic cubic; Smith, Commun. ACM 4 (1961) 168).
std::array<double, 3> symmetric_eigenvalues(const std::array<std::array<double, 3>, 3>& a) {
  const double q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
  const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
  const double p2 = (a[0][0] - q) * (a[0][0] - q) + (a[1][1] - q) * (a[1][1] - q) + (a[2][2] - q) * (a[2][2] - q) +
                    2.0 * off;
  if (p2 == 0.0) return {q, q, q};
  const double p = std::sqrt(p2 / 6.0);
  std::array<std::array<double, 3>, 3> b;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) b[i][j] = (a[i][j] - (i == j ? q : 0.0)) / p;
  const double det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
                     b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
                     b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
  const double angle = std::acos(std::clamp(det / 2.0, -1.0, 1.0)) / 3.0;
  const double largest = q + 2.0 * p * std::cos(angle);
  const double smallest = q + 2.0 * p * std::cos(angle + 2.0 * pi / 3.0);
  return {smallest, 3.0 * q - largest - smallest, largest};
}

// Solid fraction of the region eroded by `margin`: the share of the points of a cubic
// lattice (spacing a quarter mean radius, coarser beyond 3e7 points) in it that lie in a
// sphere. Counting whole spheres by their centres instead follows the layering of the
// centres near walls: with a 2-radius margin it reads 0.003 low (measured on 10k and 40k DEs).
double solid_fraction(const ParticleSet& p, const Domain& domain, double margin, double mean_radius) {
  const Vec3 lo = domain.lower() + Vec3{margin, margin, margin};
  const Vec3 size = domain.upper() - domain.lower() - Vec3{2.0 * margin, 2.0 * margin, 2.0 * margin};
  constexpr double max_points = 3e7;
  const double a = std::max(0.25 * mean_radius, std::cbrt(size.x * size.y * size.z / max_points));
  std::array<long, 3> n;
  for (int k = 0; k < 3; ++k) n[k] = std::max(1L, static_cast<long>(size[k] / a));
  const auto point = [&](long i, long j, long k) { return lo + a * Vec3{i + 0.5, j + 0.5, k + 0.5}; };
  std::vector<char> solid(static_cast<std::size_t>(n[0] * n[1] * n[2]), 0);
  for (std::size_t d = 0; d < p.size(); ++d) {
    const Vec3& x = p.position[d];
    const double r = p.radius[d];
    std::array<long, 3> first, last;
    for (int k = 0; k < 3; ++k) {
      first[k] = std::max(0L, static_cast<long>(std::ceil((x[k] - r - lo[k]) / a - 0.5)));
      last[k] = std::min(n[k] - 1, static_cast<long>(std::floor((x[k] + r - lo[k]) / a - 0.5)));
    }
    for (long k = first[2]; k <= last[2]; ++k)
      for (long j = first[1]; j <= last[1]; ++j)
        for (long i = first[0]; i <= last[0]; ++i)
          if (norm2(point(i, j, k) - x) <= r * r) solid[(k * n[1] + j) * n[0] + i] = 1;
  }
  std::size_t inside = 0, filled = 0;
  for (long k = 0; k < n[2]; ++k)
    for (long j = 0; j < n[1]; ++j)
      for (long i = 0; i < n[0]; ++i) {
        if (!domain.contains(point(i, j, k), margin)) continue;
        ++inside;
        filled += solid[(k * n[1] + j) * n[0] + i];
      }
  return inside > 0 ? static_cast<double>(filled) / inside : 0.0;
}

// Compaction, coordination and fabric of the DEs; a region too small to have an interior
// counts as all interior.
void measure(const ParticleSet& p, const Domain& domain, const PackingSpec& spec, PackingReport& out) {
  double margin = interior_margin * spec.mean_radius;
  if (domain.volume(margin) <= 0.0) margin = 0.0;
  std::vector<char> interior(p.size());
  std::size_t inner = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    interior[i] = domain.contains(p.position[i], margin);
    inner += interior[i];
  }
  out.compaction = solid_fraction(p, domain, margin, spec.mean_radius);
  const auto bonds = close_pairs(p, spec.bond_tolerance);
  std::size_t inner_ends = 0, inner_pairs = 0;
  std::array<std::array<double, 3>, 3> fabric{};
  for (const auto& [i, j] : bonds) {
    inner_ends += interior[i] + interior[j];
    if (!interior[i] || !interior[j]) continue;
    ++inner_pairs;
    const Vec3 n = normalized(p.position[j] - p.position[i]);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) fabric[a][b] += n[a] * n[b];
  }
  for (auto& row : fabric)
    for (double& value : row) value /= std::max<std::size_t>(inner_pairs, 1);
  out.mean_coordination = 2.0 * bonds.size() / std::max<std::size_t>(p.size(), 1);
  out.interior_coordination = static_cast<double>(inner_ends) / std::max<std::size_t>(inner, 1);
  out.fabric_eigenvalues = symmetric_eigenvalues(fabric);
}

std::vector<std::pair<double, std::size_t>> histogram(const std::vector<double>& radii, const PackingSpec& spec) {
  constexpr int bins = 20;
  const double half_width = spec.mean_radius * spec.relative_std * spec.truncation;
  const double lo = spec.mean_radius - half_width, width = 2.0 * half_width / bins;
  std::vector<std::pair<double, std::size_t>> out;
  if (width == 0.0) {
    out.emplace_back(spec.mean_radius, radii.size());
    return out;
  }
  for (int b = 0; b < bins; ++b) out.emplace_back(lo + (b + 0.5) * width, 0);
  for (const double r : radii) ++out[std::clamp(static_cast<int>((r - lo) / width), 0, bins - 1)].second;
  return out;
}

// Orders DEs by cell of a coarse grid (z, then y, then x) so that neighbours are near in
// memory, for the relaxation here and the runs on the sample.
void sort_spatially(const Domain& domain, double h, std::vector<Vec3>& x, std::vector<double>& radii) {
  const Grid grid(domain, h);
  std::vector<std::pair<long, std::uint32_t>> order(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) order[i] = {grid.index(grid.cell(x[i])), static_cast<std::uint32_t>(i)};
  std::sort(order.begin(), order.end());
  std::vector<Vec3> x_sorted(x.size());
  std::vector<double> r_sorted(x.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    x_sorted[k] = x[order[k].second];
    r_sorted[k] = radii[order[k].second];
  }
  x.swap(x_sorted);
  radii.swap(r_sorted);
}

// One packing, its DEs counted for compaction `aim` in the region eroded by `deficit` (m).
// The report has no count, histogram or time yet.
struct Packing {
  std::vector<Vec3> position;
  std::vector<double> radius;
  PackingReport report;
};

Packing pack(const PackingSpec& spec, const Domain& domain, double deficit, double aim) {
  Random random(spec.seed);
  Packing out;
  out.radius = draw_radii(spec, aim * domain.volume(deficit), random);
  if (out.radius.empty()) throw std::invalid_argument("packing: the region has no volume");

  // Insertion at compaction 0.2, where random addition is quick (its own jamming limit is
  // 0.38, less near walls).
  constexpr double insertion_compaction = 0.2;
  double scale = std::cbrt(insertion_compaction / aim);
  std::vector<Vec3> x = insert_randomly(domain, out.radius, scale, random);
  const double r_max = *std::max_element(out.radius.begin(), out.radius.end());
  sort_spatially(domain, 2.0 * r_max, x, out.radius);

  // Grow the radii in steps to their final size, relaxing overlaps after each: an athermal
  // compression (O'Hern et al., PRE 68 (2003) 011306) that stops just below jamming, where
  // contacts have opened by little and near-contacts are many.
  constexpr double growth_step = 0.01;
  // Net-force tolerances (mean radii); the final one leaves overlaps of ~1e-5 mean radii.
  constexpr double growth_force_tolerance = 1e-3, final_force_tolerance = 1e-6;
  constexpr long max_iterations = 20000;
  Packer packer(domain, x, out.radius, spec.mean_radius);
  for (; scale < 1.0; scale = std::min(1.0, scale + growth_step)) {
    packer.set_scale(scale);
    packer.relax(growth_force_tolerance, max_iterations);
  }
  packer.set_scale(1.0);
  packer.relax(final_force_tolerance, max_iterations);
  measure(packer.particles(), domain, spec, out.report);
  out.report.max_overlap = packer.max_overlap();
  out.position = packer.particles().position;
  return out;
}

// The wall deficit (m) for which the DEs' volume is the packing's compaction times the
// volume of the eroded region (bisection: the volume decreases with the erosion).
double implied_wall_deficit(const Domain& domain, const Packing& packing, double mean_radius) {
  double solid = 0.0;
  for (const double r : packing.radius) solid += sphere_volume(r);
  const double envelope = solid / packing.report.compaction;
  double lo = -5.0 * mean_radius, hi = 5.0 * mean_radius;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (domain.volume(mid) > envelope)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double estimated_count(const PackingSpec& spec) {
  check(spec);
  const double s = spec.relative_std;
  return spec.target_compaction * Domain(spec.region).volume(0.0) / (sphere_volume(spec.mean_radius) * (1.0 + 3.0 * s * s));
}

PackingReport build_packing(ParticleSet& p, const PackingSpec& spec, double density) {
  const auto start = std::chrono::steady_clock::now();
  check(spec);
  const Domain domain(spec.region);
  const double target = spec.target_compaction;
  Packing packing = pack(spec, domain, first_wall_deficit * spec.mean_radius, target);
  const bool jammed = packing.report.max_overlap > overlap_limit;
  if (jammed || std::abs(packing.report.compaction - target) > compaction_slack) {
    const double aim = jammed ? std::min(target, packing.report.compaction - jamming_backoff) : target;
    packing = pack(spec, domain, implied_wall_deficit(domain, packing, spec.mean_radius), aim);
  }
  if (packing.report.max_overlap > overlap_limit)
    throw RunError("packing: overlaps of " + std::to_string(packing.report.max_overlap) +
                   " mean radii remain: target compaction " + std::to_string(spec.target_compaction) +
                    " is above what this radius distribution reaches in this region; lower it or widen the distribution");
  if (packing.report.interior_coordination < spec.min_coordination)
    throw RunError("packing: mean coordination " + std::to_string(packing.report.interior_coordination) +
                   " is below " + std::to_string(spec.min_coordination) + " at bond tolerance " +
                   std::to_string(spec.bond_tolerance) + ": raise the bond tolerance");

  p.reserve(p.size() + packing.position.size());
  for (std::size_t i = 0; i < packing.position.size(); ++i) p.add(packing.position[i], packing.radius[i], density);
  PackingReport report = std::move(packing.report);
  report.count = packing.position.size();
  report.radius_histogram = histogram(packing.radius, spec);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace arlequin::dem
