// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/case_file.hpp"
#include "common/schema.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>

#include "common/error.hpp"

namespace arlequin {

namespace detail {

// One node of the resolved document. Map records also carry the schema bookkeeping of the
// document mapping they mirror (which keys were asked for), because both are keyed by the
// same path and a section read twice must see the same record.
struct CaseRecord {
  enum class Kind { Map, List, Plain, Text } kind = Kind::Map;  // Text may need quotes
  std::string text;                                              // Plain/Text leaves
  std::vector<std::pair<std::string, std::unique_ptr<CaseRecord>>> entries;  // Map
  std::vector<std::unique_ptr<CaseRecord>> items;                            // List
  std::vector<std::string> known;  // keys asked for by accessors: the valid keys
  std::vector<std::string> named;  // user-chosen names read by child_named
  bool any_keys = false;

  // The record of `key`, replaced by a fresh one of `kind` unless it already is one
  // (keeps a section's place and bookkeeping when it is read again).
  CaseRecord& slot(std::string_view key, Kind k) {
    auto it = std::find_if(entries.begin(), entries.end(), [&](auto& e) { return e.first == key; });
    if (it == entries.end()) it = entries.insert(entries.end(), {std::string(key), nullptr});
    if (!it->second || it->second->kind != k || k == Kind::List) {
      it->second = std::make_unique<CaseRecord>();
      it->second->kind = k;
    }
    return *it->second;
  }
  void put(std::string_view key, Kind k, std::string value) { slot(key, k).text = std::move(value); }
  void put_list(std::string_view key, Kind k, const std::vector<std::string>& values) {
    CaseRecord& list = slot(key, Kind::List);
    for (const auto& v : values) {
      list.items.push_back(std::make_unique<CaseRecord>());
      list.items.back()->kind = k;
      list.items.back()->text = v;
    }
  }
};

// "file:line", or the file alone when the line is unknown (0).
inline std::string file_line(const std::string& file, int line) {
  return file + (line > 0 ? ":" + std::to_string(line) : "");
}

// "path.key", or the key alone at the top.
inline std::string child_path(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

struct CaseState {
  std::filesystem::path file;    // as given by the user: messages show it like that
  std::filesystem::path folder;  // absolute; relative paths in the case are resolved here
  YAML::Node doc;
  // Views refer to their mapping by index: assigning a YAML::Node rebinds the node it
  // shares data with, so views never hold one themselves (that makes CaseNode assignable).
  std::vector<YAML::Node> nodes;
  // Where the entries under a key path came from, in the order they were put there: a base case
  // (`extends`) and the files over it, whose lines the entries carry, then the "--set ..."
  // overrides, which have none. The empty path stands for every entry.
  struct Origin {
    std::string prefix;
    std::string where;  // a file as given, or the override's text
    bool has_lines;
  };
  std::vector<Origin> origins;
  CaseRecord resolved;
  const Schema* schema = nullptr;  // checks every key read, when given

  // "--set ..." if an override provided `path` (or a mapping above it), else "file:line" of the
  // file that provided it (the case's own file unless it extends another).
  std::string location(std::string_view path, int line) const {
    const Origin* best = nullptr;
    std::size_t best_len = 0;
    for (const Origin& o : origins) {
      const std::string_view prefix = o.prefix;
      const bool covers = prefix.empty() || (path.starts_with(prefix) &&
                                             (path.size() == prefix.size() || path[prefix.size()] == '.' ||
                                              path[prefix.size()] == '['));
      if (covers && prefix.size() >= best_len) best = &o, best_len = prefix.size();
    }
    if (best && !best->has_lines) return best->where;
    return file_line(best ? best->where : file.string(), line);
  }
};

}  // namespace detail

using detail::CaseRecord;
using detail::child_path;
using detail::file_line;
using Kind = CaseRecord::Kind;

namespace {

// The one place that formats input errors: "<where>: <key path>: <message>".
[[noreturn]] void raise(std::string_view where, std::string_view path, std::string_view message) {
  std::string text(where);
  if (!path.empty()) (text += ": ") += path;
  (text += ": ") += message;
  throw InputError(text);
}

std::string format_number(double v) {
  char buf[32];
  return {buf, std::to_chars(buf, buf + sizeof buf, v).ptr};
}

std::string unit_text(std::string_view unit) {
  return unit.empty() || unit == "1" ? "" : " [" + std::string(unit) + "]";
}

// "a number > 0 [m]", "an integer >= 1", "a list of 3 numbers [m]".
std::string number_text(std::string_view noun, Range range, std::string_view unit) {
  std::string r = range.describe();
  return std::string(noun) + (r.empty() ? "" : " " + r) + unit_text(unit);
}

// A finite number written as a plain YAML scalar; `used` tells how much text a number
// prefix covered, so "1 mm" can be told apart from "abc".
std::optional<double> parse_number(std::string_view s, std::size_t* used = nullptr) {
  if (s.starts_with('+')) s.remove_prefix(1);
  double v = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (used) *used = ec == std::errc() ? std::size_t(end - s.data()) : 0;
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<double> parse_number(const YAML::Node& n) {
  return n.IsScalar() ? parse_number(n.Scalar()) : std::nullopt;
}

// What a value is, for "got ..." (kept to one short line).
std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsMap()) return "a mapping";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size()) + " items";
  if (parse_number(n)) return n.Scalar();
  std::string s = n.Scalar();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  std::replace(s.begin(), s.end(), '\n', ' ');
  return "'" + s + "'";
}

std::string joined(const auto& words, std::string_view separator = ", ") {
  std::string out;
  for (const auto& w : words) (out += out.empty() ? "" : separator) += w;
  return out;
}

// Strings that a YAML reader would take for another type are quoted in resolved output.
bool looks_typed(const std::string& s) {
  static constexpr std::string_view words[] = {"true", "false", "True", "False", "TRUE", "FALSE",
                                               "null", "Null", "NULL", "~", "auto", ""};
  return parse_number(s) || std::find(std::begin(words), std::end(words), s) != std::end(words);
}

void emit(YAML::Emitter& out, const CaseRecord& r) {
  switch (r.kind) {
    case Kind::Plain: out << r.text; break;
    case Kind::Text:
      if (looks_typed(r.text)) out << YAML::DoubleQuoted;
      out << r.text;
      break;
    case Kind::Map:
      out << YAML::BeginMap;
      for (const auto& [key, value] : r.entries) {
        out << YAML::Key << key << YAML::Value;
        emit(out, *value);
      }
      out << YAML::EndMap;
      break;
    case Kind::List: {
      // Lists of scalars (vectors, field names) read best on one line.
      const bool flat = std::all_of(r.items.begin(), r.items.end(),
                                    [](auto& i) { return i->kind != Kind::Map; });
      if (flat) out << YAML::Flow;
      out << YAML::BeginSeq;
      for (const auto& item : r.items) emit(out, *item);
      out << YAML::EndSeq;
      break;
    }
  }
}

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

std::string read_text(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    raise(file.string(), "", "cannot open case file (" + std::string(std::strerror(EISDIR)) + ")");
  std::ifstream in(file);
  if (!in) raise(file.string(), "", "cannot open case file (" + std::string(std::strerror(errno)) + ")");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Applies one "a.b.c=value" override: replaces or creates the key, creating mappings on the way.
// A generated value as a YAML node: scalars are plain text (a number in its exact form), as a
// case file would give them.
YAML::Node to_yaml(const CaseValue& v) {
  switch (v.kind()) {
    case CaseValue::Kind::number:
    case CaseValue::Kind::text: return YAML::Node(v.text());
    case CaseValue::Kind::list: {
      YAML::Node list(YAML::NodeType::Sequence);
      for (const CaseValue& item : v.items()) list.push_back(to_yaml(item));
      return list;
    }
    case CaseValue::Kind::map: break;
  }
  YAML::Node map(YAML::NodeType::Map);
  for (const auto& [key, value] : v.entries()) map[key] = to_yaml(value);
  return map;
}

void apply_override(detail::CaseState& s, const Override& o) {
  const std::string& text = o.text;
  const std::string where = o.where();
  const auto eq = text.find('=');
  if (eq == std::string::npos) raise(where, "", "expected key.path=value");
  std::vector<std::string> keys;
  std::string path = text.substr(0, eq);
  std::erase_if(path, [](char c) { return std::isspace(static_cast<unsigned char>(c)); });
  for (std::size_t start = 0;;) {
    const auto dot = path.find('.', start);
    keys.push_back(path.substr(start, dot - start));
    if (keys.back().empty()) raise(where, "", "empty key in '" + path + "'");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  const YAML::Node value = [&] {
    if (o.value) return to_yaml(*o.value);
    try {
      return YAML::Load(text.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      raise(where, "", "YAML syntax error in value: " + e.msg);
    }
  }();

  if (s.doc.IsNull()) s.doc.reset(YAML::Node(YAML::NodeType::Map));
  YAML::Node map;
  map.reset(s.doc);
  std::string at;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    at += (i ? "." : "") + keys[i];
    if (i + 1 == keys.size()) break;
    const YAML::Node next = map[keys[i]];
    if (!next.IsDefined() || next.IsNull()) {
      map[keys[i]] = YAML::Node(YAML::NodeType::Map);
      s.origins.push_back({at, where, false});  // the new mapping and everything in it came from here
    } else if (!next.IsMap()) {
      raise(where, "", "'" + at + "' is " + describe(next) + ", not a mapping");
    }
    const YAML::Node inner = map[keys[i]];
    map.reset(inner);
  }
  map[keys.back()] = value;
  s.origins.push_back({at, where, false});
}

// The keys of a mapping in order, each checked to be a plain name given once: yaml-cpp accepts
// duplicate keys and silently keeps the first. `where(key path, line)` places a message.
template <class Where>
std::vector<std::string> checked_keys(const YAML::Node& map, const std::string& path, const Where& where) {
  std::vector<std::string> keys;
  std::vector<int> lines;
  if (!map.IsMap()) return keys;
  for (const auto& kv : map) {
    const int line = line_of(kv.first);
    if (!kv.first.IsScalar()) raise(where(path, line), path, "keys must be plain names");
    const std::string& key = kv.first.Scalar();
    const std::string at = child_path(path, key);
    const auto seen = std::find(keys.begin(), keys.end(), key);
    if (seen != keys.end())
      raise(where(at, line), at, "duplicate key (first given at line " + std::to_string(lines[seen - keys.begin()]) + ")");
    keys.push_back(key);
    lines.push_back(line);
  }
  return keys;
}

// The mapping `over` (a case that extends another, read from `file`) laid over `base`: mappings
// present in both are merged key by key, any other value replaces the base's, and a key given
// no value removes the base's entry (its default then applies). The keys keep the base's order
// (a region's materials are looked up in order), the new ones after them, and every key its own
// file's node, so that its line is that file's; where each value laid over came from is recorded.
YAML::Node laid_over(detail::CaseState& s, const YAML::Node& base, const YAML::Node& over, const std::string& path,
                     const std::string& file) {
  const auto in_file = [&file](const std::string&, int line) { return file_line(file, line); };
  const std::vector<std::string> keys = checked_keys(over, path, in_file);
  std::vector<YAML::Node> key_nodes;
  for (const auto& kv : over) key_nodes.push_back(kv.first);
  std::vector<bool> placed(keys.size(), false);
  YAML::Node out(YAML::NodeType::Map);
  const auto put = [&](std::size_t k) {
    const YAML::Node value = over[keys[k]];
    placed[k] = true;
    if (!value.IsDefined() || value.IsNull()) return;  // removed
    out.force_insert(key_nodes[k], value);
    s.origins.push_back({child_path(path, keys[k]), file, true});
  };
  for (const auto& kv : base) {
    const auto k = static_cast<std::size_t>(std::find(keys.begin(), keys.end(), kv.first.Scalar()) - keys.begin());
    if (k == keys.size()) {
      out.force_insert(kv.first, kv.second);
    } else if (const YAML::Node value = over[keys[k]]; value.IsMap() && kv.second.IsMap()) {
      placed[k] = true;
      out.force_insert(kv.first, laid_over(s, kv.second, value, child_path(path, keys[k]), file));
    } else {
      put(k);
    }
  }
  for (std::size_t k = 0; k < keys.size(); ++k)
    if (!placed[k]) put(k);
  return out;
}

// Parses a case file; when it names a base case (`extends: base.yaml`, in the same folder, so
// that relative paths in both are read from one place), reads that first (itself possibly
// extending another) and lays this file's entries over it. `chain`: the files that extend this
// one, to refuse a cycle.
YAML::Node read_document(detail::CaseState& s, const std::filesystem::path& file, std::vector<std::filesystem::path>& chain) {
  const std::string text = read_text(file);
  YAML::Node doc;
  try {
    doc.reset(YAML::Load(text));
  } catch (const YAML::Exception& e) {
    raise(file_line(file.string(), e.mark.is_null() ? 0 : e.mark.line + 1), "", "YAML syntax error: " + e.msg);
  }
  if (!doc.IsMap() && !doc.IsNull())
    raise(file_line(file.string(), line_of(doc)), "", "expected a mapping of sections at the top level, got " + describe(doc));
  const YAML::Node base_name = doc.IsMap() ? std::as_const(doc)["extends"] : YAML::Node();
  if (!base_name.IsDefined()) {
    if (!chain.empty()) s.origins.push_back({"", file.string(), true});  // a base: its entries carry its lines
    return doc;
  }
  const std::string where = file_line(file.string(), line_of(base_name));
  const std::filesystem::path name = base_name.IsScalar() ? std::filesystem::path(base_name.Scalar()) : std::filesystem::path();
  if (name.empty() || name.has_parent_path())
    raise(where, "extends", "expected the file name of a case in this case's folder (relative paths in both are read from it), got " +
                                describe(base_name));
  const std::filesystem::path base = file.parent_path() / name;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(base, ec)) raise(where, "extends", "no case file " + base.string());
  chain.push_back(file);
  for (const auto& f : chain)
    if (std::filesystem::equivalent(f, base, ec)) {
      std::string cycle;
      for (const auto& g : chain) cycle += g.filename().string() + " -> ";
      raise(where, "extends", "the cases extend one another: " + cycle + name.string());
    }
  const YAML::Node below = read_document(s, base, chain);
  chain.pop_back();
  doc.remove("extends");
  return laid_over(s, below, doc, "", file.string());
}

}  // namespace

// ---- CaseValue ------------------------------------------------------------------------

CaseValue::CaseValue(double number) : kind_(Kind::number), text_(format_number(number)) {}

CaseValue::CaseValue(const Vec3& v) : kind_(Kind::list), items_{CaseValue(v.x), CaseValue(v.y), CaseValue(v.z)} {}

CaseValue CaseValue::list(std::vector<CaseValue> items) {
  CaseValue v(Kind::list);
  v.items_ = std::move(items);
  return v;
}

CaseValue CaseValue::map(std::vector<std::pair<std::string, CaseValue>> entries) {
  CaseValue v(Kind::map);
  v.entries_ = std::move(entries);
  return v;
}

std::string CaseValue::yaml() const {
  YAML::Emitter out;
  out.SetSeqFormat(YAML::Flow);
  out.SetMapFormat(YAML::Flow);
  out << to_yaml(*this);
  return out.c_str();
}

// ---- Range, edit distance --------------------------------------------------------------

bool Range::contains(double v) const {
  return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
}

std::string Range::describe() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return std::string("in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
           (hi_open ? ")" : "]");
  if (has_lo) return (lo_open ? "> " : ">= ") + format_number(lo);
  if (has_hi) return (hi_open ? "< " : "<= ") + format_number(hi);
  return "";
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);  // distances from a[0..i) to every prefix of b
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::optional<std::string_view> closest_match(std::string_view word,
                                              std::span<const std::string_view> candidates) {
  std::optional<std::string_view> best;
  std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (auto c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_distance) best = c, best_distance = d;
  }
  return best;
}

namespace {

// True when `typed` is `meant` with one character dropped, one added, two neighbours swapped, or
// only the letter case changed: the slips that make a key. A missing key is only compared with
// such near misses, as any other present key may be a valid one not read yet (r_mu is one
// substitution from E_mu).
bool is_slip_of(std::string_view typed, std::string_view meant) {
  const auto lower = [](std::string_view s) {
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  };
  if (typed == meant) return false;
  if (lower(typed) == lower(meant)) return true;
  if (typed.size() + 1 == meant.size() || meant.size() + 1 == typed.size()) {
    const std::string_view longer = typed.size() > meant.size() ? typed : meant, shorter = typed.size() > meant.size() ? meant : typed;
    for (std::size_t k = 0; k < longer.size(); ++k)
      if (std::string(longer.substr(0, k)) + std::string(longer.substr(k + 1)) == shorter) return true;
    return false;
  }
  if (typed.size() != meant.size()) return false;
  for (std::size_t k = 0; k + 1 < typed.size(); ++k) {
    std::string swapped(typed);
    std::swap(swapped[k], swapped[k + 1]);
    if (swapped == meant) return true;
  }
  return false;
}

}  // namespace

// ---- CaseNode ------------------------------------------------------------------------

struct CaseNode::Entry {
  YAML::Node value;  // undefined when the key is absent
  std::string path;  // "dem.sample.radius", "dem.gravity[2]"
  int line = 0;      // 1-based line of the key or list item; 0 if unknown
  bool present() const { return value.IsDefined(); }
};

CaseNode::CaseNode(std::shared_ptr<detail::CaseState> state, std::size_t index, std::string path,
                   int line, detail::CaseRecord* record)
    : state_(std::move(state)), index_(index), path_(std::move(path)), line_(line), record_(record) {}

// A view on a mapping value; an empty value counts as an empty mapping. Keys are checked
// here once: yaml-cpp accepts duplicate keys and would silently use the first.
CaseNode CaseNode::open(const std::shared_ptr<detail::CaseState>& state, const Entry& e,
                        detail::CaseRecord& record) {
  CaseNode node(state, state->nodes.size(), e.path, e.line, &record);
  if (!e.value.IsMap() && !e.value.IsNull()) node.mismatch(e, "a mapping");
  state->nodes.push_back(e.value);
  checked_keys(e.value, e.path, [&state](const std::string& at, int line) { return state->location(at, line); });
  return node;
}

CaseNode::Entry CaseNode::find(std::string_view key) const {
  const YAML::Node& map = state_->nodes[index_];
  if (map.IsMap())
    for (const auto& kv : map)
      if (kv.first.Scalar() == key) return {kv.second, key_path(key), line_of(kv.first)};
  return {YAML::Node(YAML::NodeType::Undefined), key_path(key), 0};
}

CaseNode::Entry CaseNode::lookup(std::string_view key) {
  auto& known = record_->known;
  if (std::find(known.begin(), known.end(), key) == known.end()) known.emplace_back(key);
  return find(key);
}

std::string CaseNode::where() const { return state_->location(path_, line_); }
std::string CaseNode::where(const Entry& e) const { return state_->location(e.path, e.line); }

std::string CaseNode::key_path(std::string_view key) const {
  return child_path(path_, key);
}

void CaseNode::fail(std::string_view key, std::string_view message) const { raise(where(key), key_path(key), message); }

std::string CaseNode::misspelling_hint(std::string_view key) const {
  for (const auto& present : keys())
    if (!recognised(present) && is_slip_of(present, key)) {
      const Entry e = find(present);
      return "; is '" + present + "' (" + (e.line > 0 ? "line " + std::to_string(e.line) : where(e)) + ") a misspelling of '" +
             std::string(key) + "'?";
    }
  return "";
}

void CaseNode::missing(std::string_view key, std::string_view expected) const {
  // A slip of the pen is the likely cause: name a key not read so far that is one.
  raise(where(), path_, "missing required key '" + std::string(key) + "' (" + std::string(expected) + ")" + misspelling_hint(key));
}

void CaseNode::mismatch(const Entry& e, std::string_view expected) const {
  raise(where(e), e.path, "expected " + std::string(expected) + ", got " + describe(e.value));
}

double CaseNode::to_number(const Entry& e, Range range, std::string_view unit, bool integer) const {
  std::string expected = number_text(integer ? "an integer" : "a number", range, unit);
  std::size_t used = 0;
  const auto v = e.value.IsScalar() ? parse_number(e.value.Scalar(), &used) : std::nullopt;
  if (!v && used > 0) expected += " (SI units, no unit suffix)";  // "1 mm", "200GPa"
  // Integers beyond 2^53 cannot be told apart from their neighbours as doubles.
  if (!v || !range.contains(*v) || (integer && (std::trunc(*v) != *v || std::abs(*v) > 0x1p53)))
    mismatch(e, expected);
  return *v;
}

std::string CaseNode::to_string(const Entry& e) const {
  if (!e.value.IsScalar()) mismatch(e, "a string");
  return e.value.Scalar();
}

std::vector<CaseNode::Entry> CaseNode::elements(const Entry& list, std::string_view expected) const {
  if (list.value.IsNull()) return {};
  if (!list.value.IsSequence()) mismatch(list, expected);
  std::vector<Entry> out;
  for (const auto& item : list.value)
    out.push_back({item, list.path + "[" + std::to_string(out.size()) + "]", line_of(item)});
  return out;
}

double CaseNode::number(std::string_view key, Range range, std::string_view unit) {
  check_schema(key, KeyType::number, &range, unit);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, number_text("a number", range, unit));
  const double v = to_number(e, range, unit, false);
  record_->put(key, Kind::Plain, format_number(v));
  return v;
}

double CaseNode::number_or(std::string_view key, double fallback, Range range, std::string_view unit) {
  const std::string fallback_text = format_number(fallback);
  check_schema(key, KeyType::number, &range, unit, &fallback_text);
  if (!find(key).present()) {
    lookup(key);
    record_->put(key, Kind::Plain, format_number(fallback));
    return fallback;
  }
  return number(key, range, unit);
}

std::optional<double> CaseNode::number_or_auto(std::string_view key, Range range, std::string_view unit) {
  const std::string fallback_text = "auto";
  check_schema(key, KeyType::number_or_auto, &range, unit, &fallback_text);
  const Entry e = lookup(key);
  if (!e.present() || (e.value.IsScalar() && e.value.Scalar() == "auto")) {
    record_->put(key, Kind::Plain, "auto");
    return std::nullopt;
  }
  if (!parse_number(e.value)) mismatch(e, number_text("a number", range, unit) + " or 'auto'");
  return number(key, range, unit);
}

long long CaseNode::integer(std::string_view key, Range range) {
  check_schema(key, KeyType::integer, &range);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, number_text("an integer", range, ""));
  const auto v = static_cast<long long>(to_number(e, range, "", true));
  record_->put(key, Kind::Plain, std::to_string(v));
  return v;
}

long long CaseNode::integer_or(std::string_view key, long long fallback, Range range) {
  const std::string fallback_text = std::to_string(fallback);
  check_schema(key, KeyType::integer, &range, {}, &fallback_text);
  if (!find(key).present()) {
    lookup(key);
    record_->put(key, Kind::Plain, std::to_string(fallback));
    return fallback;
  }
  return integer(key, range);
}

std::optional<long long> CaseNode::integer_or_auto(std::string_view key, long long fallback, Range range) {
  const std::string fallback_text = std::to_string(fallback);
  check_schema(key, KeyType::integer_or_auto, &range, {}, &fallback_text);
  const Entry e = lookup(key);
  if (!e.present()) {
    record_->put(key, Kind::Plain, fallback_text);
    return fallback;
  }
  if (e.value.IsScalar() && e.value.Scalar() == "auto") {
    record_->put(key, Kind::Plain, "auto");
    return std::nullopt;
  }
  if (!parse_number(e.value)) mismatch(e, number_text("an integer", range, "") + " or 'auto'");
  return integer(key, range);
}

bool CaseNode::boolean(std::string_view key) {
  check_schema(key, KeyType::boolean);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, "true or false");
  // Only true/false: YAML 1.1 also reads yes/no/on/off, a common source of surprises.
  static constexpr std::string_view yes[] = {"true", "True", "TRUE"}, no[] = {"false", "False", "FALSE"};
  const std::string s = e.value.IsScalar() ? e.value.Scalar() : "";
  const bool t = std::find(std::begin(yes), std::end(yes), s) != std::end(yes);
  if (!t && std::find(std::begin(no), std::end(no), s) == std::end(no)) mismatch(e, "true or false");
  record_->put(key, Kind::Plain, t ? "true" : "false");
  return t;
}

bool CaseNode::boolean_or(std::string_view key, bool fallback) {
  const std::string fallback_text = fallback ? "true" : "false";
  check_schema(key, KeyType::boolean, nullptr, {}, &fallback_text);
  if (!find(key).present()) {
    lookup(key);
    record_->put(key, Kind::Plain, fallback ? "true" : "false");
    return fallback;
  }
  return boolean(key);
}

std::string CaseNode::string(std::string_view key) {
  check_schema(key, KeyType::string);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, "a string");
  std::string s = to_string(e);
  record_->put(key, Kind::Text, s);
  return s;
}

std::string CaseNode::string_or(std::string_view key, std::string_view fallback) {
  const std::string fallback_text(fallback);
  check_schema(key, KeyType::string, nullptr, {}, &fallback_text);
  if (!find(key).present()) {
    lookup(key);
    record_->put(key, Kind::Text, std::string(fallback));
    return std::string(fallback);
  }
  return string(key);
}

std::string CaseNode::choice(std::string_view key, std::span<const std::string_view> allowed) {
  check_schema(key, KeyType::choice, nullptr, {}, nullptr, joined(allowed, " | "));
  const std::string expected = "one of " + joined(allowed);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, expected);
  if (!e.value.IsScalar()) mismatch(e, expected);
  const std::string s = e.value.Scalar();
  if (std::find(allowed.begin(), allowed.end(), s) == allowed.end()) {
    const auto hint = closest_match(s, allowed);
    raise(where(e), e.path,
          "expected " + expected + ", got " + describe(e.value) +
              (hint ? "; did you mean '" + std::string(*hint) + "'?" : ""));
  }
  record_->put(key, Kind::Text, s);
  return s;
}

std::string CaseNode::choice_or(std::string_view key, std::string_view fallback,
                                std::span<const std::string_view> allowed) {
  const std::string fallback_text(fallback);
  check_schema(key, KeyType::choice, nullptr, {}, &fallback_text, joined(allowed, " | "));
  if (!find(key).present()) {
    lookup(key);
    record_->put(key, Kind::Text, std::string(fallback));
    return std::string(fallback);
  }
  return choice(key, allowed);
}

Vec3 CaseNode::vec3(std::string_view key, Range each, std::string_view unit) {
  check_schema(key, KeyType::vec3, &each, unit);
  const std::string expected = number_text("a list of 3 numbers", each, unit);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, expected);
  const auto items = elements(e, expected);
  if (items.size() != 3) mismatch(e, expected);
  Vec3 v;
  for (int k = 0; k < 3; ++k) v[k] = to_number(items[k], each, unit, false);
  record_->put_list(key, Kind::Plain, {format_number(v.x), format_number(v.y), format_number(v.z)});
  return v;
}

Vec3 CaseNode::vec3_or(std::string_view key, Vec3 fallback, Range each, std::string_view unit) {
  const std::string fallback_text = "[" + format_number(fallback.x) + ", " + format_number(fallback.y) + ", " + format_number(fallback.z) + "]";
  check_schema(key, KeyType::vec3, &each, unit, &fallback_text);
  if (!find(key).present()) {
    lookup(key);
    record_->put_list(key, Kind::Plain,
                      {format_number(fallback.x), format_number(fallback.y), format_number(fallback.z)});
    return fallback;
  }
  return vec3(key, each, unit);
}

std::vector<double> CaseNode::numbers(std::string_view key, Range each, std::string_view unit) {
  check_schema(key, KeyType::numbers, &each, unit);
  const std::string expected = number_text("a list of numbers", each, unit);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, expected);
  std::vector<double> out;
  std::vector<std::string> texts;
  for (const auto& item : elements(e, expected)) {
    out.push_back(to_number(item, each, unit, false));
    texts.push_back(format_number(out.back()));
  }
  record_->put_list(key, Kind::Plain, texts);
  return out;
}

std::vector<Vec3> CaseNode::vec3_list(std::string_view key, Range each, std::string_view unit) {
  check_schema(key, KeyType::vec3_list, &each, unit);
  const std::string expected = number_text("a list of [x, y, z] triples", each, unit);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, expected);
  std::vector<Vec3> out;
  CaseRecord& list = record_->slot(key, Kind::List);  // a list of [x, y, z] lists
  for (const auto& item : elements(e, expected)) {
    const auto xyz = elements(item, expected);
    if (xyz.size() != 3) mismatch(item, expected);
    Vec3 v;
    for (int k = 0; k < 3; ++k) v[k] = to_number(xyz[k], each, unit, false);
    out.push_back(v);
    auto& triple = *list.items.emplace_back(std::make_unique<CaseRecord>());
    triple.kind = Kind::List;
    for (int k = 0; k < 3; ++k) {
      triple.items.push_back(std::make_unique<CaseRecord>());
      triple.items.back()->kind = Kind::Plain;
      triple.items.back()->text = format_number(v[k]);
    }
  }
  return out;
}

std::vector<std::string> CaseNode::strings(std::string_view key) {
  check_schema(key, KeyType::strings);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, "a list of strings");
  std::vector<std::string> out;
  for (const auto& item : elements(e, "a list of strings")) out.push_back(to_string(item));
  record_->put_list(key, Kind::Text, out);
  return out;
}

std::string CaseNode::where(std::string_view key) const {
  const Entry e = find(key);
  return e.present() ? where(e) : where();
}

std::vector<Override> CaseNode::overrides(std::string_view key) {
  const std::string origin = where(key) + ": " + key_path(key);
  std::vector<Override> out;
  for (std::string& text : strings(key)) out.emplace_back(std::move(text), origin);
  return out;
}

std::vector<Override> CaseNode::overrides_or_empty(std::string_view key) {
  if (!find(key).present()) {
    strings_or(key, {});  // records the (empty) default
    return {};
  }
  return overrides(key);
}

std::vector<std::string> CaseNode::strings_or(std::string_view key, const std::vector<std::string>& fallback) {
  const std::string fallback_text = "[" + joined(fallback) + "]";
  check_schema(key, KeyType::strings, nullptr, {}, &fallback_text);
  if (!find(key).present()) {
    lookup(key);
    record_->put_list(key, Kind::Text, fallback);
    return fallback;
  }
  return strings(key);
}

std::filesystem::path CaseNode::existing_file(std::string_view key) {
  check_schema(key, KeyType::file);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, "a file path");
  const std::string text = to_string(e);
  const std::filesystem::path given(text);
  const auto file = (given.is_absolute() ? given : state_->folder / given).lexically_normal();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    raise(where(e), e.path,
          "file '" + text + "' not found (looked in " + file.parent_path().string() + ")");
  if (std::filesystem::is_directory(file, ec)) raise(where(e), e.path, "'" + text + "' is a folder, expected a file");
  record_->put(key, Kind::Text, file.string());
  return file;
}

CaseNode CaseNode::child(std::string_view key) {
  std::string section = check_schema(key, KeyType::section);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, "a mapping");
  return opened(e, record_->slot(key, Kind::Map), std::move(section));
}

std::optional<CaseNode> CaseNode::child_if(std::string_view key) {
  check_schema(key, KeyType::section);
  if (!lookup(key).present()) return std::nullopt;
  return child(key);
}

bool CaseNode::has(std::string_view key) {
  check_schema(key, KeyType::section);  // any declared type: see check_schema
  return lookup(key).present();
}

CaseNode CaseNode::child_named(std::string_view name) {
  const Entry e = find(name);
  if (!e.present()) missing(name, "a mapping");
  if (std::find(record_->named.begin(), record_->named.end(), name) == record_->named.end())
    record_->named.emplace_back(name);
  return opened(e, record_->slot(name, Kind::Map), check_schema("<name>", KeyType::section));
}

std::vector<CaseNode> CaseNode::items(const Entry& list, std::string_view key, const std::string& section) {
  const auto entries = elements(list, "a list of mappings");
  CaseRecord& out = record_->slot(key, Kind::List);
  std::vector<CaseNode> nodes;
  for (const auto& item : entries) {
    out.items.push_back(std::make_unique<CaseRecord>());
    nodes.push_back(opened(item, *out.items.back(), section + "[]"));
  }
  return nodes;
}

std::vector<CaseNode> CaseNode::list(std::string_view key) {
  const std::string section = check_schema(key, KeyType::list);
  const Entry e = lookup(key);
  if (!e.present()) missing(key, "a list of mappings");
  return items(e, key, section);
}

std::vector<CaseNode> CaseNode::list_or_empty(std::string_view key) {
  const std::string section = check_schema(key, KeyType::list);
  const Entry e = lookup(key);
  return items(e.present() ? e : Entry{YAML::Node(YAML::NodeType::Null), e.path, 0}, key, section);
}

std::vector<std::string> CaseNode::keys() const {
  std::vector<std::string> out;
  const YAML::Node& map = state_->nodes[index_];
  if (map.IsMap())
    for (const auto& kv : map) out.push_back(kv.first.Scalar());
  return out;
}

void CaseNode::accept_any_keys() { record_->any_keys = true; }

void CaseNode::add_schema_section(std::string_view section) { sections_.emplace_back(section); }

CaseNode CaseNode::opened(const Entry& e, detail::CaseRecord& record, std::string section) const {
  CaseNode node = open(state_, e, record);
  node.sections_ = {std::move(section)};
  return node;
}

std::string CaseNode::check_schema(std::string_view key, KeyType type, const Range* range, std::string_view unit,
                                   const std::string* fallback, std::string_view values) const {
  const std::string by_place = sections_.front().empty() ? std::string(key) : sections_.front() + "." + std::string(key);
  const Schema* schema = state_->schema;
  if (!schema) return by_place;
  const KeyDoc* doc = nullptr;
  std::string_view section;
  for (const std::string& s : sections_)
    if ((doc = schema->find(s, key)) || (doc = schema->find(s, "<name>"))) {  // "<name>": any user-chosen key
      section = s;
      break;
    }
  const std::string where = "schema: " + (sections_.front().empty() ? std::string("(top)") : sections_.front()) + "." + std::string(key);
  if (!doc) throw std::logic_error(where + ": read but not declared");
  schema->note_read(section, doc->key);
  const std::string declared_at = section.empty() ? std::string(doc->key) : std::string(section) + "." + std::string(doc->key);
  const bool presence_test = type == KeyType::section && doc->type != KeyType::section && doc->type != KeyType::names;
  if (presence_test) return declared_at;  // has(key): a test of presence, whatever the key's type
  const bool mapping = doc->type == KeyType::names && type == KeyType::section;
  const bool number_part = (doc->type == KeyType::number_or_auto && type == KeyType::number) ||
                           (doc->type == KeyType::integer_or_auto && type == KeyType::integer);  // ..._or_auto read via number / integer
  if (doc->type != type && !mapping && !number_part) throw std::logic_error(where + ": read as " + std::string(name_of(type)) + ", declared " + std::string(name_of(doc->type)));
  const bool unit_varies = doc->unit.starts_with("(");  // "(by type)": the reader states it per case
  if (range && !unit_varies && !(doc->range == *range)) throw std::logic_error(where + ": read with range '" + range->describe() + "', declared '" + doc->range.describe() + "'");
  if (range && !unit_varies && doc->unit != unit) throw std::logic_error(where + ": read in [" + std::string(unit) + "], declared [" + std::string(doc->unit) + "]");
  if (!doc->values.starts_with("(") && doc->values != values) throw std::logic_error(where + ": read as one of '" + std::string(values) + "', declared '" + std::string(doc->values) + "'");
  const bool computed = doc->fallback.starts_with("(");
  if (fallback && !computed && doc->fallback != *fallback)
    throw std::logic_error(where + ": read with default '" + *fallback + "', declared '" + std::string(doc->fallback) + "'");
  return declared_at;
}

bool CaseNode::recognised(std::string_view key) const {
  const auto& known = record_->known;
  const auto& named = record_->named;
  return std::find(known.begin(), known.end(), key) != known.end() || std::find(named.begin(), named.end(), key) != named.end();
}

void CaseNode::finish() const {
  if (record_->any_keys) return;
  const auto& known = record_->known;
  for (const auto& key : keys()) {
    if (recognised(key)) continue;
    const std::vector<std::string_view> valid(known.begin(), known.end());
    const auto hint = closest_match(key, valid);
    raise(where(find(key)), key_path(key),
          hint         ? "unknown key; did you mean '" + std::string(*hint) + "'?"
          : valid.empty() ? std::string("unknown key; no keys are expected here")
                          : "unknown key; valid keys: " + joined(valid));
  }
}

// ---- CaseFile ------------------------------------------------------------------------

CaseFile CaseFile::load(const std::filesystem::path& file, const std::vector<Override>& overrides, const Schema* schema) {
  auto state = std::make_shared<detail::CaseState>();
  state->schema = schema;
  state->file = file;
  state->folder = std::filesystem::absolute(file).lexically_normal().parent_path();
  std::vector<std::filesystem::path> chain;
  state->doc.reset(read_document(*state, file, chain));
  for (const auto& o : overrides) apply_override(*state, o);
  return CaseFile(std::move(state));
}

CaseNode CaseFile::root() {
  CaseNode node = CaseNode::open(state_, CaseNode::Entry{state_->doc, "", 1}, state_->resolved);
  node.sections_ = {""};
  return node;
}

std::string CaseFile::resolved_yaml() const {
  YAML::Emitter out;
  out.SetIndent(2);
  emit(out, state_->resolved);
  return std::string(out.c_str()) + "\n";
}

const std::filesystem::path& CaseFile::path() const { return state_->file; }

}  // namespace arlequin
