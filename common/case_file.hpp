// SPDX-License-Identifier: GPL-3.0-or-later
// Case files: the user's YAML description of a simulation, read through a strict schema.
//
// Readers pull values through CaseNode accessors that state the type, allowed range and unit
// of each key; loaded with a Schema (common/schema.hpp), every read is checked against the
// key's declaration beside its reader, so the printed schema is the one the code reads. Every
// accessor records the key as known; finish() then rejects any key the reader never asked for,
// which catches typos that would otherwise silently fall back to defaults. Every error is
// one line naming where (file:line, or the --set text that provided the value), the key
// path and what was expected. Everything read, defaults included, is mirrored into a
// resolved document that `arlequin check` prints.
#pragma once
#include <cstddef>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/vec3.hpp"

namespace arlequin {

class Schema;
enum class KeyType;

// Allowed values of a number, with a text for messages ("> 0", "in [0, 1]").
struct Range {
  static constexpr double inf = std::numeric_limits<double>::infinity();
  double lo = -inf, hi = inf;
  bool lo_open = false, hi_open = false;

  static constexpr Range any() { return {}; }
  static constexpr Range positive() { return {0.0, inf, true, false}; }
  static constexpr Range non_negative() { return at_least(0.0); }
  static constexpr Range at_least(double lo) { return {lo, inf, false, false}; }
  static constexpr Range between(double lo, double hi) { return {lo, hi, false, false}; }
  static constexpr Range open_between(double lo, double hi) { return {lo, hi, true, true}; }
  bool operator==(const Range&) const = default;

  bool contains(double v) const;
  std::string describe() const;  // "" for any()
};

// Levenshtein distance (insertions, deletions, substitutions).
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate closest to `word` if it is close enough to be a likely typo
// (distance <= max(2, word.size() / 3)); used for "did you mean ...?" hints.
std::optional<std::string_view> closest_match(std::string_view word,
                                              std::span<const std::string_view> candidates);

namespace detail {
struct CaseState;
struct CaseRecord;
}  // namespace detail

// A value built in code for an override, so that generated sections are data, not YAML text:
// a number (every bit kept), a word, [x, y, z], a list or a mapping.
class CaseValue {
 public:
  CaseValue(double number);
  CaseValue(int number) : CaseValue(static_cast<double>(number)) {}
  CaseValue(const char* text) : CaseValue(std::string(text)) {}
  CaseValue(std::string text) : kind_(Kind::text), text_(std::move(text)) {}
  CaseValue(const Vec3& v);
  static CaseValue list(std::vector<CaseValue> items);
  static CaseValue map(std::vector<std::pair<std::string, CaseValue>> entries);

  enum class Kind { number, text, list, map };
  Kind kind() const { return kind_; }
  const std::string& text() const { return text_; }  // number (shortest exact form) or text
  const std::vector<CaseValue>& items() const { return items_; }
  const std::vector<std::pair<std::string, CaseValue>>& entries() const { return entries_; }
  std::string yaml() const;  // in YAML flow style, for messages

 private:
  CaseValue(Kind kind) : kind_(kind) {}
  Kind kind_;
  std::string text_;
  std::vector<CaseValue> items_;
  std::vector<std::pair<std::string, CaseValue>> entries_;
};

// One "a.b.c=value" override of a case (the value is parsed as YAML, or given as a CaseValue)
// and where it was given: "--set" (the command line, the default), "--over", a spec file's line
// and key, e.g. "spec.yaml:14: samples[1].set", or the code that generated it. Messages about
// what it set name that origin.
struct Override {
  std::string text;  // "key.path=value" as given, or as the value's YAML
  std::string origin = "--set";
  std::shared_ptr<const CaseValue> value;  // the value as data (then not parsed from text)
  Override(std::string text_, std::string origin_ = "--set") : text(std::move(text_)), origin(std::move(origin_)) {}
  Override(const char* text_) : text(text_) {}
  Override(const std::string& key_path, CaseValue value_, std::string origin_)
      : text(key_path + "=" + value_.yaml()), origin(std::move(origin_)), value(std::make_shared<const CaseValue>(std::move(value_))) {}
  std::string where() const { return origin.starts_with("--") ? origin + " " + text : origin + ": " + text; }
};

// A view on one mapping of a case document (a section, or an item of a list of mappings).
// Cheap to copy; all views of one CaseFile share its state.
class CaseNode {
 public:
  // Numbers are plain SI values; `unit` is only shown in messages ("m" -> "[m]";
  // "" or "1" for dimensionless shows nothing).
  double number(std::string_view key, Range range, std::string_view unit);
  double number_or(std::string_view key, double fallback, Range range, std::string_view unit);
  // A number or the word `auto` (nullopt); a missing key means auto.
  std::optional<double> number_or_auto(std::string_view key, Range range, std::string_view unit);
  long long integer(std::string_view key, Range range);
  long long integer_or(std::string_view key, long long fallback, Range range);
  // An integer or the word `auto` (nullopt); a missing key means the fallback.
  std::optional<long long> integer_or_auto(std::string_view key, long long fallback, Range range);
  bool boolean(std::string_view key);
  bool boolean_or(std::string_view key, bool fallback);
  std::string string(std::string_view key);
  std::string string_or(std::string_view key, std::string_view fallback);
  std::string choice(std::string_view key, std::span<const std::string_view> allowed);
  std::string choice_or(std::string_view key, std::string_view fallback,
                        std::span<const std::string_view> allowed);
  Vec3 vec3(std::string_view key, Range each, std::string_view unit);
  Vec3 vec3_or(std::string_view key, Vec3 fallback, Range each, std::string_view unit);
  std::vector<double> numbers(std::string_view key, Range each, std::string_view unit);
  // A list of [x, y, z] triples, e.g. box corners [[x0,y0,z0],[x1,y1,z1]].
  std::vector<Vec3> vec3_list(std::string_view key, Range each, std::string_view unit);
  std::vector<std::string> strings(std::string_view key);
  std::vector<std::string> strings_or(std::string_view key, const std::vector<std::string>& fallback);
  // A path relative to the case file's folder (or absolute) that must name an existing file.
  std::filesystem::path existing_file(std::string_view key);

  // Sub-mappings. An empty value (`output:` with nothing after it) is an empty mapping/list.
  CaseNode child(std::string_view key);
  std::optional<CaseNode> child_if(std::string_view key);
  bool has(std::string_view key);  // also records the key as known
  std::vector<CaseNode> list(std::string_view key);  // items get paths like "loads[2]"
  std::vector<CaseNode> list_or_empty(std::string_view key);

  // Mappings whose keys are user-chosen names (materials: {fibre: ..., matrix: ...}).
  std::vector<std::string> keys() const;  // in file order
  CaseNode child_named(std::string_view name);  // known, but never offered as a suggestion
  void accept_any_keys();

  std::string where() const;  // "case.yaml:12" or "--set a.b=1"
  std::string where(std::string_view key) const;  // of that key if present, else of this mapping
  const std::string& path() const { return path_; }  // "dem.sample"; "" for the top level
  std::string key_path(std::string_view key) const;
  // Throws InputError "<where of key>: <path.key>: <message>" (semantic checks by callers).
  [[noreturn]] void fail(std::string_view key, std::string_view message) const;

  // Rejects keys present in this mapping that no accessor asked for.
  void finish() const;

  // Keys of this mapping are also looked up in the schema section `section` (a registry
  // entry's own keys, "bond (law: beam)"), as well as in the one of its place.
  void add_schema_section(std::string_view section);

  // A list of "key=value" overrides, each with this key's place as its origin ("spec.yaml:14:
  // samples[1].set"); required, or empty when absent.
  std::vector<Override> overrides(std::string_view key);
  std::vector<Override> overrides_or_empty(std::string_view key);

  // "; is 'E_m' (line 6) a misspelling of 'E_mu'?" when a key not asked for so far is a slip of
  // `key` (one letter dropped, added or swapped with its neighbour, or another case), else "".
  std::string misspelling_hint(std::string_view key) const;

 private:
  friend class CaseFile;
  struct Entry;  // a value with its key path and line; defined in case_file.cpp

  CaseNode(std::shared_ptr<detail::CaseState> state, std::size_t index, std::string path, int line,
           detail::CaseRecord* record);
  static CaseNode open(const std::shared_ptr<detail::CaseState>& state, const Entry& entry,
                       detail::CaseRecord& record);

  Entry find(std::string_view key) const;
  Entry lookup(std::string_view key);  // find + record the key as known
  std::vector<Entry> elements(const Entry& list, std::string_view expected) const;
  std::vector<CaseNode> items(const Entry& list, std::string_view key, const std::string& section);
  double to_number(const Entry& e, Range range, std::string_view unit, bool integer) const;
  std::string to_string(const Entry& e) const;
  std::string where(const Entry& e) const;
  bool recognised(std::string_view key) const;  // asked for by an accessor so far
  [[noreturn]] void missing(std::string_view key, std::string_view expected) const;
  [[noreturn]] void mismatch(const Entry& e, std::string_view expected) const;
  // With a schema: `key` must be declared in one of this mapping's sections as `type`, with
  // this unit and range, these values (choice) and, for an accessor with a default, that
  // default as text (fallback); std::logic_error otherwise. Records the key as read and returns
  // the schema section of its value ("<declaring section>.<key>"; by place without a schema).
  std::string check_schema(std::string_view key, KeyType type, const Range* range = nullptr, std::string_view unit = {},
                    const std::string* fallback = nullptr, std::string_view values = {}) const;
  CaseNode opened(const Entry& e, detail::CaseRecord& record, std::string section) const;

  std::shared_ptr<detail::CaseState> state_;
  std::size_t index_;  // this mapping in the state's node table
  std::string path_;
  int line_;  // 1-based line of this mapping's key (0 if unknown)
  detail::CaseRecord* record_;  // this mapping's part of the resolved document
  // Its schema sections: where it sits ("dem.sample", "sensors[]"), then any added.
  std::vector<std::string> sections_{std::string()};
};

// A loaded case document with its overrides applied.
class CaseFile {
 public:
  // With a schema, every key read is checked against it (see common/schema.hpp).
  static CaseFile load(const std::filesystem::path& file, const std::vector<Override>& overrides = {},
                       const Schema* schema = nullptr);

  CaseNode root();
  // YAML of every value read so far (defaults included), in read order.
  std::string resolved_yaml() const;
  const std::filesystem::path& path() const;

 private:
  explicit CaseFile(std::shared_ptr<detail::CaseState> state) : state_(std::move(state)) {}
  std::shared_ptr<detail::CaseState> state_;
};

}  // namespace arlequin
