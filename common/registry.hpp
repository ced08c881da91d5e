// Lookup in an explicit registry table (bond laws, contact laws, continuum solvers...): the
// case file names an entry; an unknown name is a case-file error listing the valid ones.
#pragma once
#include <algorithm>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/case_file.hpp"

namespace arlequin {

// Entry needs a member `std::string_view name`.
template <class Entry>
const Entry& choose_entry(std::span<const Entry> table, CaseNode& section, std::string_view key) {
  std::vector<std::string_view> names;
  for (const Entry& e : table) names.push_back(e.name);
  const std::string chosen = section.choice(key, names);
  return *std::ranges::find(table, chosen, &Entry::name);
}

}  // namespace arlequin
