// SPDX-License-Identifier: GPL-3.0-or-later
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

// The schema section of the keys that entry `name` adds to a section of kind `kind` (the last
// part of its path, "bond"): "bond (law: beam)". Shared by the readers and the schema's list.
inline std::string entry_schema_section(std::string_view kind, std::string_view key, std::string_view name) {
  return std::string(kind) + " (" + std::string(key) + ": " + std::string(name) + ")";
}

// Entry needs a member `std::string_view name`. The chosen entry's own keys are then declared
// in the schema section entry_schema_section(kind, key, name).
template <class Entry>
const Entry& choose_entry(std::span<const Entry> table, CaseNode& section, std::string_view key, std::string_view kind) {
  std::vector<std::string_view> names;
  for (const Entry& e : table) names.push_back(e.name);
  const std::string chosen = section.choice(key, names);
  section.add_schema_section(entry_schema_section(kind, key, chosen));
  return *std::ranges::find(table, chosen, &Entry::name);
}

}  // namespace arlequin
