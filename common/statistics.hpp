// SPDX-License-Identifier: GPL-3.0-or-later
// Order statistics of a few run figures (benchmarks' repeats, compare's ensemble pairs).
#pragma once
#include <algorithm>
#include <vector>

namespace arlequin {

// The median of v (not empty): the middle value, or the mean of the two middle ones.
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

}  // namespace arlequin
