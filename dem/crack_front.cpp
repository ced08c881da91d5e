// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/crack_front.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace arlequin::dem {

CrackFront measure_crack(const BondSet& set, const ParticleSet& p, const Vec3& axis, const Vec3& across, int bins) {
  const auto damage = set.damage_values();
  const auto broken = set.broken();
  const auto damage_of = [&](std::size_t b) { return damage.empty() ? double(broken[b]) : damage[b]; };
  const auto midpoint = [&](std::size_t b) { return 0.5 * (p.reference[set.first()[b]] + p.reference[set.second()[b]]); };
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (std::size_t b = 0; b < set.size(); ++b) {
    const double w = dot(midpoint(b), across);
    low = std::min(low, w), high = std::max(high, w);
  }
  const double none = -std::numeric_limits<double>::infinity();
  std::vector<double> tip(bins, none), front(bins, none);
  for (std::size_t b = 0; b < set.size(); ++b) {
    const double d = damage_of(b);
    if (d <= 0.0) continue;
    const Vec3 x = midpoint(b);
    const double share = high > low ? (dot(x, across) - low) / (high - low) : 0.0;
    const int k = std::clamp(int(share * bins), 0, bins - 1);
    const double along = dot(x, axis);
    front[k] = std::max(front[k], along);
    if (d >= 1.0 || broken[b]) tip[k] = std::max(tip[k], along);
  }
  const auto mean = [&](const std::vector<double>& v) {
    double sum = 0.0;
    int count = 0;
    for (double x : v)
      if (x != none) sum += x, ++count;
    return count ? sum / count : std::numeric_limits<double>::quiet_NaN();
  };
  CrackFront c{mean(tip), mean(front), 0.0};
  for (double e : set.dissipated_values()) c.dissipated += e;
  return c;
}

}  // namespace arlequin::dem
