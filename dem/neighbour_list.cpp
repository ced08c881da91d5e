// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/neighbour_list.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.hpp"
#include "common/parallel.hpp"

namespace arlequin::dem {
namespace {

constexpr std::uint64_t key_of(std::uint32_t i, std::uint32_t j) {
  return (std::uint64_t{i} << 32) | j;
}

}  // namespace

void NeighbourList::set_exclusions(std::vector<std::pair<std::uint32_t, std::uint32_t>> excluded) {
  excluded_.clear();
  for (auto [i, j] : excluded) excluded_.push_back(key_of(std::min(i, j), std::max(i, j)));
  std::sort(excluded_.begin(), excluded_.end());
  excluded_start_.clear();  // set again by the next build, which knows the DE count
}

void NeighbourList::build(const ParticleSet& p) {
  const std::size_t n = p.size();
  pairs_.clear();
  position_at_build_ = p.position;
  ++builds_;
  if (n < 2) return;
  // Each DE's excluded partners after it: excluded_'s keys i * 2^32 + j from excluded_start_[i]
  // on (a few per DE, scanned; a search of all the keys took a third of the build).
  if (excluded_start_.size() != n + 1) {
    excluded_start_.assign(n + 1, 0);
    for (const std::uint64_t key : excluded_)
      if (const std::uint64_t i = key >> 32; i < n) ++excluded_start_[i + 1];
    for (std::size_t i = 0; i < n; ++i) excluded_start_[i + 1] += excluded_start_[i];
  }
  Vec3 lo = p.position[0], hi = p.position[0];
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p.position[i][k]);
      hi[k] = std::max(hi[k], p.position[i][k]);
    }
  // A DE far larger than the median (an impactor among yarn DEs) would make every cell its
  // size and each cell hold hundreds of DEs: such DEs stay out of the cells and are tested
  // against every DE instead, O(n) each.
  const double large = large_radius(p.radius, scratch_radius_);
  double r_max = 0.0;
  large_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (p.radius[i] > large) large_.push_back(static_cast<std::uint32_t>(i));
    else r_max = std::max(r_max, p.radius[i]);
  // Cell edge >= the largest interaction distance, so only the 27 surrounding cells matter;
  // grown if the box would hold more than eight cells per DE (a sparse scene), so the grid's
  // memory stays that of the DEs.
  const Vec3 extent = hi - lo;
  const double largest = std::max({extent.x, extent.y, extent.z});
  if (!std::isfinite(largest))
    throw RunError("contact search: the DEs lie farther apart than a double can measure (beyond 1e308 m); nothing can be binned");
  const double cap = 8.0 * double(n) + 1024.0;
  double h = std::max(2.0 * r_max + skin_, largest / cap);  // no axis beyond the cap: counts stay small
  const auto cells_along = [&](int k) { return std::floor(extent[k] / h) + 1.0; };
  while (cells_along(0) * cells_along(1) * cells_along(2) > cap) h *= 1.25;
  const auto nx = static_cast<std::int64_t>(cells_along(0)), ny = static_cast<std::int64_t>(cells_along(1)),
             nz = static_cast<std::int64_t>(cells_along(2));
  const auto cell_of = [&](const Vec3& x) {
    const auto c = [&](int k, std::int64_t count) { return std::min(static_cast<std::int64_t>((x[k] - lo[k]) / h), count - 1); };
    return static_cast<std::uint32_t>((c(0, nx) * ny + c(1, ny)) * nz + c(2, nz));
  };
  // The DEs by cell (a counting sort; within a cell, by index).
  cell_start_.assign(static_cast<std::size_t>(nx * ny * nz) + 1, 0);
  cell_of_de_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (p.radius[i] > large) continue;
    cell_of_de_[i] = cell_of(p.position[i]);
    ++cell_start_[cell_of_de_[i] + 1];
  }
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  cell_des_.resize(cell_start_.back());
  scratch_next_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    if (p.radius[i] <= large) cell_des_[scratch_next_[cell_of_de_[i]]++] = static_cast<std::uint32_t>(i);
  // The binned DEs' positions and radii in cell order: a cell's candidates are read as runs of
  // consecutive entries, not one cache line each through the DE index.
  binned_position_.resize(cell_des_.size());
  binned_radius_.resize(cell_des_.size());
  for (std::size_t k = 0; k < cell_des_.size(); ++k) {
    binned_position_[k] = p.position[cell_des_[k]];
    binned_radius_[k] = p.radius[cell_des_[k]];
  }
  using PairList = std::vector<std::pair<std::uint32_t, std::uint32_t>>;
  // The pair (a, b) of DEs, as (i, j) with i < j, unless excluded.
  const auto add_unless_excluded = [&](std::uint32_t a, std::uint32_t b, PairList& out) {
    const std::uint32_t i = std::min(a, b), j = std::max(a, b);
    for (std::uint32_t k = excluded_start_[i]; k < excluded_start_[i + 1]; ++k)
      if (static_cast<std::uint32_t>(excluded_[k]) == j) return;
    out.emplace_back(i, j);
  };
  // Whether two spheres' surfaces are closer than the skin.
  const auto within_reach = [this](const Vec3& xa, double ra, const Vec3& xb, double rb) {
    const double reach = ra + rb + skin_;
    return norm2(xb - xa) < reach * reach;
  };
  // The pair (a, b) if within reach and not excluded.
  const auto consider = [&](std::uint32_t a, std::uint32_t b, PairList& out) {
    if (within_reach(p.position[a], p.radius[a], p.position[b], p.radius[b])) add_unless_excluded(a, b, out);
  };
  // Binned entry a against the binned entries [from, to).
  const auto consider_run = [&](std::uint32_t a, std::uint32_t from, std::uint32_t to, PairList& out) {
    const Vec3 xa = binned_position_[a];
    const double ra = binned_radius_[a];
    for (std::uint32_t b = from; b < to; ++b)
      if (within_reach(xa, ra, binned_position_[b], binned_radius_[b])) add_unless_excluded(cell_des_[a], cell_des_[b], out);
  };
  // Each cell against itself and the 13 neighbours after it in cell order (every pair of cells
  // once): the next cell along z, and four columns of up to three cells, each column's cells
  // consecutive in cell order, so its DEs one run. On threads each collects its own pairs, in an
  // order that depends on the threads.
  const std::int64_t cells = nx * ny * nz;
  const bool threaded = static_cast<long>(n) > parallel_threshold;
  const auto teams = static_cast<std::size_t>(runs_threaded(threaded) ? max_threads() : 1);
  if (found_.size() < teams) found_.resize(teams);
  for (auto& list : found_) list.clear();
  for (const std::uint32_t i : large_)
    for (std::uint32_t j = 0; j < n; ++j)
      if (p.radius[j] <= large || j > i) consider(i, j, found_[0]);
  run_threaded_if(threaded, [&] {
    PairList& out = found_[static_cast<std::size_t>(thread_index())];
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t c = 0; c < cells; ++c) {
      const std::uint32_t begin = cell_start_[c], end = cell_start_[c + 1];
      if (begin == end) continue;  // most cells of a sparse scene
      const std::int64_t cx = c / (ny * nz), cy = c / nz % ny, cz = c % nz;
      // The runs of binned entries this cell's DEs meet: the next cell along z, then the columns
      // (cx, cy + 1), (cx + 1, cy - 1 ... cy + 1), each from cz - 1 to cz + 1.
      std::uint32_t run_from[5], run_to[5];
      int runs = 0;
      if (cz + 1 < nz) run_from[runs] = end, run_to[runs++] = cell_start_[c + 2];
      const std::int64_t z0 = std::max<std::int64_t>(cz - 1, 0), z1 = std::min<std::int64_t>(cz + 1, nz - 1);
      for (const auto& [dx, dy] : {std::pair{0, 1}, std::pair{1, -1}, std::pair{1, 0}, std::pair{1, 1}}) {
        const std::int64_t ox = cx + dx, oy = cy + dy;
        if (ox >= nx || oy < 0 || oy >= ny) continue;
        const std::int64_t column = (ox * ny + oy) * nz;
        run_from[runs] = cell_start_[column + z0], run_to[runs++] = cell_start_[column + z1 + 1];
      }
      for (std::uint32_t a = begin; a != end; ++a) {
        consider_run(a, a + 1, end, out);
        for (int r = 0; r < runs; ++r) consider_run(a, run_from[r], run_to[r], out);
      }
    }
  });
  // The list sorted by (i, j), so the same whatever thread found a pair: a counting sort by i,
  // then each DE's few partners in order (a comparison sort of the whole list took as long as
  // the search).
  first_start_.assign(n + 1, 0);
  for (std::size_t t = 0; t < teams; ++t)
    for (const auto& [i, j] : found_[t]) ++first_start_[i + 1];
  for (std::size_t i = 0; i < n; ++i) first_start_[i + 1] += first_start_[i];
  pairs_.resize(first_start_[n]);
  scratch_next_.assign(first_start_.begin(), first_start_.end() - 1);
  for (std::size_t t = 0; t < teams; ++t)
    for (const auto& pair : found_[t]) pairs_[scratch_next_[pair.first]++] = pair;
  for (std::size_t i = 0; i < n; ++i)
    if (first_start_[i + 1] - first_start_[i] > 1) std::sort(pairs_.begin() + first_start_[i], pairs_.begin() + first_start_[i + 1]);
}

double NeighbourList::large_radius(std::span<const double> radii, std::vector<double>& scratch) {
  scratch.assign(radii.begin(), radii.end());
  const auto middle = scratch.begin() + static_cast<std::ptrdiff_t>(scratch.size() / 2);
  std::nth_element(scratch.begin(), middle, scratch.end());
  return large_radius_ratio * *middle;
}

bool NeighbourList::needs_rebuild(const ParticleSet& p) const {
  if (position_at_build_.size() != p.size()) return true;
  // A pair left out had a gap of at least the skin at the build; since then it closed by at most
  // the sum of the two DEs' displacements, so at most the sum of the two largest. Each thread's
  // share of the DEs on the threads; the two largest of all do not depend on the order they are
  // met in.
  using Largest = std::pair<double, double>;  // the two largest squared displacements
  const auto add = [](Largest& top, double d2) {
    if (d2 > top.first) {
      top.second = top.first;
      top.first = d2;
    } else if (d2 > top.second) {
      top.second = d2;
    }
  };
  const long shares = scan_thread_shares(static_cast<long>(p.size()), parallel_threshold, largest_moves_, [&](long begin, long end) {
    Largest top{0.0, 0.0};
    for (long i = begin; i < end; ++i) add(top, norm2(p.position[static_cast<std::size_t>(i)] - position_at_build_[static_cast<std::size_t>(i)]));
    return top;
  });
  Largest top{0.0, 0.0};
  for (long t = 0; t < shares; ++t) {
    add(top, largest_moves_[static_cast<std::size_t>(t)].first);
    add(top, largest_moves_[static_cast<std::size_t>(t)].second);
  }
  return std::sqrt(top.first) + std::sqrt(top.second) > skin_;
}

void NeighbourList::save_state(StateArchive& archive, const std::string& prefix) const {
  archive.put(prefix + "pairs", pairs_);
  archive.put(prefix + "position_at_build", position_at_build_);
  archive.put(prefix + "builds", static_cast<std::int64_t>(builds_));
}

void NeighbourList::load_state(const StateArchive& archive, const std::string& prefix, std::size_t n_particles) {
  pairs_ = archive.get<std::pair<std::uint32_t, std::uint32_t>>(prefix + "pairs");
  for (const auto& [i, j] : pairs_)
    if (!(i < j && j < n_particles)) throw StateMismatch("its contact pairs name DEs beyond this scene's");
  position_at_build_ = archive.get<Vec3>(prefix + "position_at_build");
  if (position_at_build_.size() != n_particles)
    throw StateMismatch("its contact search was built for " + std::to_string(position_at_build_.size()) + " DEs, this scene has " +
                        std::to_string(n_particles));
  builds_ = static_cast<std::size_t>(archive.integer(prefix + "builds"));
}

}  // namespace arlequin::dem
