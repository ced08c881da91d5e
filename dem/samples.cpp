// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/samples.hpp"

#include <algorithm>

#include "dem/neighbour_list.hpp"

namespace arlequin::dem {

void build_lattice(ParticleSet& p, const Vec3& origin, std::array<int, 3> counts, double spacing,
                   double radius, double density) {
  p.reserve(p.size() + static_cast<std::size_t>(counts[0]) * counts[1] * counts[2]);
  for (int k = 0; k < counts[2]; ++k)
    for (int j = 0; j < counts[1]; ++j)
      for (int i = 0; i < counts[0]; ++i)
        p.add(origin + Vec3{i * spacing, j * spacing, k * spacing}, radius, density);
}

void build_chain(ParticleSet& p, const Vec3& start, const Vec3& direction, int count,
                 double spacing, double radius, double density) {
  for (int k = 0; k < count; ++k) p.add(start + direction * (k * spacing), radius, density);
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> close_pairs(const ParticleSet& p, double tolerance) {
  // The neighbour list finds pairs within R_i + R_j + skin; the skin is the largest reach
  // the tolerance can give, then each pair is tested with its own radii.
  const double r_max = p.size() ? *std::max_element(p.radius.begin(), p.radius.end()) : 0.0;
  NeighbourList list(2.0 * r_max * tolerance);
  list.build(p);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  for (auto [i, j] : list.pairs()) {
    const double reach = (p.radius[i] + p.radius[j]) * (1.0 + tolerance);
    if (norm2(p.position[j] - p.position[i]) < reach * reach) out.emplace_back(i, j);
  }
  return out;
}

}  // namespace arlequin::dem
