// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/schema.hpp"

#include <algorithm>
#include <cstdio>

namespace arlequin {

std::string_view name_of(KeyType type) {
  switch (type) {
    case KeyType::number: return "number";
    case KeyType::number_or_auto: return "number or auto";
    case KeyType::integer: return "integer";
    case KeyType::integer_or_auto: return "integer or auto";
    case KeyType::boolean: return "true | false";
    case KeyType::string: return "string";
    case KeyType::choice: return "choice";
    case KeyType::vec3: return "[x, y, z]";
    case KeyType::numbers: return "list of numbers";
    case KeyType::vec3_list: return "list of [x, y, z]";
    case KeyType::strings: return "list of strings";
    case KeyType::file: return "file";
    case KeyType::section: return "section";
    case KeyType::list: return "list of sections";
    case KeyType::names: return "named sections";
  }
  return "";
}

const KeyDoc* Schema::find(std::string_view section, std::string_view key) const {
  for (const SchemaSection& s : sections_)
    if (s.path == section)
      for (const KeyDoc& k : s.keys)
        if (k.key == key) return &k;
  return nullptr;
}

void Schema::note_read(std::string_view section, std::string_view key) const {
  read_.insert(std::string(section) + "|" + std::string(key));
}

std::string Schema::describe(std::string_view prefix) const {
  std::string out;
  for (const SchemaSection& s : sections_) {
    if (!s.path.starts_with(prefix)) continue;
    if (!out.empty()) out += '\n';
    out.append(s.path).append(": ").append(s.help).append("\n");
    for (const KeyDoc& k : s.keys) {
      std::string type(name_of(k.type));
      if (k.type == KeyType::choice) type = std::string(k.values);
      const std::string range = k.range.describe();
      if (!range.empty()) type += " " + range;
      std::string_view unit = k.unit;  // "(...)": a unit the reader states per case; shown without the marks
      if (unit.starts_with("(") && unit.ends_with(")")) unit = unit.substr(1, unit.size() - 2);
      if (!unit.empty() && unit != "1") type.append(" [").append(unit).append("]");
      std::string line = "  " + std::string(k.key);
      line.resize(std::max<std::size_t>(line.size() + 1, 22), ' ');
      line += type;
      line.resize(std::max<std::size_t>(line.size() + 1, 52), ' ');
      line += k.fallback.empty() ? std::string("(required)") : "default " + std::string(k.fallback);
      out += line + "\n      " + std::string(k.help) + "\n";
    }
  }
  return out;
}

}  // namespace arlequin
