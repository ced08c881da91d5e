// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/case_schema.hpp"

#include <deque>
#include <string>

#include "app/continuum_part.hpp"
#include "app/scene.hpp"
#include "common/region.hpp"
#include "common/registry.hpp"
#include "dem/bonds/bond_set.hpp"
#include "dem/contacts/contact_law.hpp"

namespace arlequin::app {
namespace {

// The sections of every registry entry's own keys, "bond (law: beam)" ...; `paths` keeps the
// section names the sections refer to.
template <class Entry>
void add_entries(std::vector<SchemaSection>& sections, std::deque<std::string>& paths, std::span<const Entry> table,
                 std::string_view kind, std::string_view help) {
  for (const Entry& e : table) {
    paths.push_back(entry_schema_section(kind, "law", e.name));
    sections.push_back({paths.back(), help, e.keys()});
  }
}

Schema build_case_schema() {
  static std::deque<std::string> paths;
  std::vector<SchemaSection> sections;
  for (const auto& s : scene_schema()) sections.push_back(s);
  add_entries(sections, paths, dem::bond_laws(), "bond", "the keys of a bond law, beside law: in a bond section");
  add_entries(sections, paths, dem::contact_laws(), "contact", "the keys of a contact law, beside law: in dem.contact");
  for (const auto& s : Region::schema()) sections.push_back(s);
  for (const auto& s : ContinuumPart::schema()) sections.push_back(s);
  return Schema(std::move(sections));
}

}  // namespace

const Schema& case_schema() {
  static const Schema schema = build_case_schema();
  return schema;
}

}  // namespace arlequin::app
