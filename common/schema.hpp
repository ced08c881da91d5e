// SPDX-License-Identifier: GPL-3.0-or-later
// The case-file schema: every key a reader asks for, declared once beside that reader (name,
// type, unit, range, default, help), and checked on every read.
//
// A reader declares its section's keys in a table of KeyDoc (a SchemaSection) next to the code
// that reads them; app/case_schema.cpp lists the tables of a case file. CaseFile::load with a
// schema makes every CaseNode accessor check its key against it: an undeclared key, or one
// declared with another type, unit, range, choice list or default than the accessor states, is
// a logic error (a bug in the program, found by any test or run that reads the key). The
// schema remembers the keys read, so a test can find declared keys that no reader asks for.
// `arlequin schema [section]` prints it.
#pragma once
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/case_file.hpp"

namespace arlequin {

enum class KeyType {
  number,          // number / number_or
  number_or_auto,  // a number or the word auto
  integer,
  integer_or_auto,  // an integer or the word auto
  boolean,
  string,
  choice,  // one of `values`
  vec3,    // [x, y, z]
  numbers,
  vec3_list,  // [[x, y, z], ...]
  strings,
  file,       // a path relative to the case file
  section,    // a mapping (its keys are a section of their own)
  list,       // a list of mappings (each item is the section "<key>[]")
  names,      // a mapping of user-chosen names (each one the section "<key>.<name>")
};
std::string_view name_of(KeyType type);

struct KeyDoc {
  std::string_view key;
  KeyType type = KeyType::number;
  std::string_view unit = "";      // SI unit as the reader states it ("" or "1": none)
  Range range = {};                // allowed numbers (numbers, integers and each number of a list)
  std::string_view fallback = "";  // the default as a case would write it; "" when there is none;
                                   // "(...)" for a default computed from other keys
  std::string_view help = "";
  std::string_view values = "";  // choice: the allowed words, "a | b | c"
};

// The keys of one mapping. `path` is where it sits in a case ("dem.sample"; "sensors[]" for the
// items of a list, "dem.materials.<name>" for a mapping under a user-chosen name), or, for the
// keys a registry entry adds to its section, "<section> (<key>: <entry>)" ("bond (law: beam)").
struct SchemaSection {
  std::string_view path;
  std::string_view help;
  std::span<const KeyDoc> keys;
};

class Schema {
 public:
  explicit Schema(std::vector<SchemaSection> sections) : sections_(std::move(sections)) {}

  const std::vector<SchemaSection>& sections() const { return sections_; }
  const KeyDoc* find(std::string_view section, std::string_view key) const;
  // Every key read so far through a CaseFile loaded with this schema, as "section|key".
  const std::set<std::string>& read() const { return read_; }
  void note_read(std::string_view section, std::string_view key) const;

  // The sections whose path starts with `prefix` ("" for all) as text: one block per section,
  // one line per key: key, type, unit, range or values, default, help.
  std::string describe(std::string_view prefix = "") const;

 private:
  std::vector<SchemaSection> sections_;
  mutable std::set<std::string> read_;
};

}  // namespace arlequin
