// SPDX-License-Identifier: GPL-3.0-or-later
// What a case would need against what the machine has: a case far beyond the memory is refused
// before anything is allocated (a bad_alloc mid-build, or minutes of meshing, says nothing useful).
#pragma once
#include <unistd.h>

#include <cstdio>
#include <string>

namespace arlequin {

// Physical memory of this machine, bytes (0 if the system does not say).
inline double physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? double(pages) * double(page) : 0.0;
}

// "12.3 GB" (decimal units).
inline std::string gigabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g GB", bytes / 1e9);
  return text;
}

// A budget below the machine's memory, bytes (0: none). The fuzz targets set one, so that an
// input asking for gigabytes is refused as it would be on a small machine, not built.
inline double& memory_budget_bytes() {
  static double budget = 0.0;
  return budget;
}

// Empty if `bytes` fits in the physical memory (or it is unknown) and the budget; else the
// sentence to add to an error: "which needs at least X (WHY); this machine has Y" (or "the
// memory budget is Y" where the budget is the smaller).
inline std::string beyond_memory(double bytes, const std::string& why) {
  const double budget = memory_budget_bytes(), have = physical_memory_bytes();
  const bool budgeted = budget > 0.0 && (have <= 0.0 || budget < have);
  const double limit = budgeted ? budget : have;
  if (limit <= 0.0 || bytes <= limit) return {};
  return "which needs at least " + gigabytes(bytes) + " (" + why + "); " +
         (budgeted ? "the memory budget is " : "this machine has ") + gigabytes(limit);
}

}  // namespace arlequin
