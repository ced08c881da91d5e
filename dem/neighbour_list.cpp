// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/neighbour_list.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace arlequin::dem {
namespace {

constexpr std::uint64_t key_of(std::uint32_t i, std::uint32_t j) {
  return (std::uint64_t{i} << 32) | j;
}
// Cells are addressed by three 21-bit coordinates packed in one 64-bit key.
constexpr std::uint64_t cell_key(std::int64_t cx, std::int64_t cy, std::int64_t cz) {
  return (static_cast<std::uint64_t>(cx) << 42) | (static_cast<std::uint64_t>(cy) << 21) |
         static_cast<std::uint64_t>(cz);
}

}  // namespace

void NeighbourList::set_exclusions(std::vector<std::pair<std::uint32_t, std::uint32_t>> excluded) {
  excluded_.clear();
  for (auto [i, j] : excluded) excluded_.push_back(key_of(std::min(i, j), std::max(i, j)));
  std::sort(excluded_.begin(), excluded_.end());
}

void NeighbourList::build(const ParticleSet& p) {
  const std::size_t n = p.size();
  pairs_.clear();
  position_at_build_ = p.position;
  ++builds_;
  if (n < 2) return;
  Vec3 lo = p.position[0], hi = p.position[0];
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p.position[i][k]);
      hi[k] = std::max(hi[k], p.position[i][k]);
    }
  // A DE far larger than the median (an impactor among yarn DEs) would make every cell its
  // size and each cell hold hundreds of DEs: such DEs stay out of the cells and are tested
  // against every DE instead, O(n) each.
  std::vector<double>& radii = scratch_radius_;
  radii.assign(p.radius.begin(), p.radius.end());
  std::nth_element(radii.begin(), radii.begin() + n / 2, radii.end());
  const double large = large_radius_ratio * radii[n / 2];
  double r_max = 0.0;
  large_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (p.radius[i] > large) large_.push_back(static_cast<std::uint32_t>(i));
    else r_max = std::max(r_max, p.radius[i]);
  // Cell edge >= the largest interaction distance, so only the 27 surrounding cells matter;
  // grown if needed to keep coordinates within 21 bits (very sparse scenes).
  double h = 2.0 * r_max + skin_;
  for (int k = 0; k < 3; ++k) h = std::max(h, (hi[k] - lo[k]) / 2.0e6);
  cells_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (p.radius[i] > large) continue;
    const Vec3& x = p.position[i];
    cells_.push_back({cell_key(static_cast<std::int64_t>((x.x - lo.x) / h) + 1, static_cast<std::int64_t>((x.y - lo.y) / h) + 1,
                               static_cast<std::int64_t>((x.z - lo.z) / h) + 1),
                      static_cast<std::uint32_t>(i)});
  }
  std::sort(cells_.begin(), cells_.end());
  const auto consider = [&](std::uint32_t i, std::uint32_t j) {
    const double reach = p.radius[i] + p.radius[j] + skin_;
    if (norm2(p.position[j] - p.position[i]) >= reach * reach) return;
    const std::uint32_t lo_id = std::min(i, j), hi_id = std::max(i, j);
    if (std::binary_search(excluded_.begin(), excluded_.end(), key_of(lo_id, hi_id))) return;
    pairs_.emplace_back(lo_id, hi_id);
  };
  for (std::size_t a = 0; a < large_.size(); ++a)
    for (std::uint32_t j = 0; j < n; ++j)
      if (p.radius[j] <= large || j > large_[a]) consider(large_[a], j);
  constexpr std::uint64_t mask = (std::uint64_t{1} << 21) - 1;
  for (std::size_t a = 0; a < cells_.size(); ++a) {
    const auto [key, i] = cells_[a];
    const std::int64_t cx = key >> 42, cy = (key >> 21) & mask, cz = key & mask;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const std::uint64_t other = cell_key(cx + dx, cy + dy, cz + dz);
          if (other < key) continue;  // each cell pair once (own cell handled below)
          auto it = std::lower_bound(cells_.begin(), cells_.end(),
                                     std::pair<std::uint64_t, std::uint32_t>{other, 0});
          for (; it != cells_.end() && it->first == other; ++it) {
            const std::uint32_t j = it->second;
            if (other == key && j <= i) continue;
            consider(i, j);
          }
        }
  }
  std::sort(pairs_.begin(), pairs_.end());
}

bool NeighbourList::needs_rebuild(const ParticleSet& p) const {
  if (position_at_build_.size() != p.size()) return true;
  const double limit = 0.25 * skin_ * skin_;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (norm2(p.position[i] - position_at_build_[i]) > limit) return true;
  return false;
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
