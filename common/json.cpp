#include "common/json.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <system_error>

#include "common/atomic_file.hpp"
#include "common/error.hpp"

namespace arlequin {

namespace {

constexpr const char* type_names[] = {"null", "bool", "integer", "number", "string", "array", "object"};

const char* type_name(Json::Type type) { return type_names[static_cast<int>(type)]; }

void append_escaped(std::string& out, std::string_view text) {
  out += '"';
  for (const char ch : text) {
    switch (ch) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) {
          char buffer[8];
          std::snprintf(buffer, sizeof buffer, "\\u%04x", static_cast<unsigned>(ch));
          out += buffer;
        } else {
          out += ch;  // UTF-8 passes through unchanged
        }
    }
  }
  out += '"';
}

void append_number(std::string& out, double value) {
  if (!std::isfinite(value)) {
    out += "null";
    return;
  }
  char buffer[32];
  // Shortest text that reads back to the same double, independent of the locale.
  const char* end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  const std::string_view text(buffer, end - buffer);
  out += text;
  // Keep the value a number (not an integer) when read back: 3.0 is written "3.0".
  if (text.find_first_of(".e") == std::string_view::npos) out += ".0";
}

void append_newline(std::string& out, int indent, int depth) {
  if (indent < 0) return;
  out += '\n';
  out.append(static_cast<std::size_t>(indent) * depth, ' ');
}

class Parser {
 public:
  explicit Parser(std::string_view text) : text_(text) {}

  Json document() {
    Json value = parse_value(0);
    skip_space();
    if (pos_ != text_.size()) fail("unexpected text after the value");
    return value;
  }

 private:
  // Deep enough for any summary, shallow enough that hostile input cannot blow the stack.
  static constexpr int max_depth = 256;

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError("JSON: " + what + " at offset " + std::to_string(pos_));
  }

  void skip_space() {
    while (pos_ < text_.size() &&
           (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\n' || text_[pos_] == '\r'))
      ++pos_;
  }
  bool consume(char ch) {
    skip_space();
    if (pos_ < text_.size() && text_[pos_] == ch) {
      ++pos_;
      return true;
    }
    return false;
  }
  void expect(char ch) {
    if (!consume(ch)) fail(std::string("expected '") + ch + "'");
  }
  bool consume_word(std::string_view word) {
    if (text_.substr(pos_, word.size()) != word) return false;
    pos_ += word.size();
    return true;
  }

  Json parse_value(int depth) {
    if (depth > max_depth) fail("nesting too deep");
    skip_space();
    if (pos_ == text_.size()) fail("unexpected end of input");
    const char ch = text_[pos_];
    if (ch == '{') return parse_object(depth);
    if (ch == '[') return parse_array(depth);
    if (ch == '"') return Json(parse_string());
    if (ch == '-' || (ch >= '0' && ch <= '9')) return parse_number();
    if (consume_word("true")) return Json(true);
    if (consume_word("false")) return Json(false);
    if (consume_word("null")) return Json();
    fail("unexpected character");
  }

  Json parse_object(int depth) {
    ++pos_;  // '{'
    Json object = Json::object();
    if (consume('}')) return object;
    do {
      skip_space();
      if (pos_ == text_.size() || text_[pos_] != '"') fail("expected a key string");
      const std::size_t key_pos = pos_;
      std::string key = parse_string();
      if (object.find(key) != nullptr) {
        pos_ = key_pos;
        fail("duplicate key '" + key + "'");
      }
      expect(':');
      object[key] = parse_value(depth + 1);
    } while (consume(','));
    expect('}');
    return object;
  }

  Json parse_array(int depth) {
    ++pos_;  // '['
    Json array = Json::array();
    if (consume(']')) return array;
    do {
      array.push_back(parse_value(depth + 1));
    } while (consume(','));
    expect(']');
    return array;
  }

  unsigned parse_hex4() {
    unsigned value = 0;
    const auto [end, ec] = std::from_chars(text_.data() + pos_, text_.data() + std::min(pos_ + 4, text_.size()), value, 16);
    if (ec != std::errc() || end != text_.data() + pos_ + 4) fail("bad \\u escape");
    pos_ += 4;
    return value;
  }

  static void append_utf8(std::string& out, unsigned code) {
    if (code < 0x80) {
      out += static_cast<char>(code);
    } else if (code < 0x800) {
      out += static_cast<char>(0xC0 | (code >> 6));
      out += static_cast<char>(0x80 | (code & 0x3F));
    } else if (code < 0x10000) {
      out += static_cast<char>(0xE0 | (code >> 12));
      out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (code & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (code >> 18));
      out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (code & 0x3F));
    }
  }

  std::string parse_string() {
    ++pos_;  // opening quote
    std::string out;
    while (true) {
      if (pos_ == text_.size()) fail("unterminated string");
      const char ch = text_[pos_++];
      if (ch == '"') return out;
      if (static_cast<unsigned char>(ch) < 0x20) fail("control character in string");
      if (ch != '\\') {
        out += ch;
        continue;
      }
      if (pos_ == text_.size()) fail("unterminated string");
      switch (text_[pos_++]) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          unsigned code = parse_hex4();
          // Characters beyond the BMP come as a UTF-16 surrogate pair.
          if (code >= 0xD800 && code < 0xDC00) {
            if (!consume_word("\\u")) fail("unpaired surrogate");
            const unsigned low = parse_hex4();
            if (low < 0xDC00 || low >= 0xE000) fail("unpaired surrogate");
            code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
          } else if (code >= 0xDC00 && code < 0xE000) {
            fail("unpaired surrogate");
          }
          append_utf8(out, code);
          break;
        }
        default:
          --pos_;
          fail("bad escape");
      }
    }
  }

  Json parse_number() {
    const std::size_t start = pos_;
    const auto digits = [&] {
      const std::size_t first = pos_;
      while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') ++pos_;
      if (pos_ == first) fail("expected a digit");
    };
    if (text_[pos_] == '-') ++pos_;
    if (pos_ < text_.size() && text_[pos_] == '0') {
      ++pos_;  // JSON forbids leading zeros
    } else {
      digits();
    }
    bool integral = true;
    if (pos_ < text_.size() && text_[pos_] == '.') {
      ++pos_;
      digits();
      integral = false;
    }
    if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < text_.size() && (text_[pos_] == '+' || text_[pos_] == '-')) ++pos_;
      digits();
      integral = false;
    }
    const char* first = text_.data() + start;
    const char* last = text_.data() + pos_;
    if (integral) {
      std::int64_t value = 0;
      // Integers beyond int64 are still valid JSON: they are read as numbers below.
      if (std::from_chars(first, last, value).ec == std::errc()) return Json(value);
    }
    double value = 0.0;
    const auto result = std::from_chars(first, last, value);
    if (result.ec != std::errc() || result.ptr != last) {
      pos_ = start;
      fail("number out of range");
    }
    return Json(value);
  }

  std::string_view text_;
  std::size_t pos_ = 0;
};

}  // namespace

Json& Json::operator[](std::string_view key) {
  if (is_null()) value_ = Object{};
  auto* members = std::get_if<Object>(&value_);
  if (members == nullptr)
    throw std::logic_error(std::string("Json: operator[] on a ") + type_name(type()) + " value");
  for (auto& [name, value] : *members) {
    if (name == key) return value;
  }
  return members->emplace_back(std::string(key), Json()).second;
}

void Json::push_back(Json value) {
  if (is_null()) value_ = Array{};
  auto* elements = std::get_if<Array>(&value_);
  if (elements == nullptr) throw std::logic_error(std::string("Json: push_back on a ") + type_name(type()) + " value");
  elements->push_back(std::move(value));
}

namespace {

template <class T>
const T& get_as(const auto& variant, Json::Type actual, Json::Type expected) {
  const T* value = std::get_if<T>(&variant);
  if (value == nullptr)
    throw InputError(std::string("JSON: expected ") + type_name(expected) + ", found " + type_name(actual));
  return *value;
}

}  // namespace

bool Json::as_bool() const { return get_as<bool>(value_, type(), Type::Bool); }
std::int64_t Json::as_integer() const { return get_as<std::int64_t>(value_, type(), Type::Integer); }
const std::string& Json::as_string() const { return get_as<std::string>(value_, type(), Type::String); }
const Json::Array& Json::as_array() const { return get_as<Array>(value_, type(), Type::Array); }
const Json::Object& Json::as_object() const { return get_as<Object>(value_, type(), Type::Object); }

double Json::as_number() const {
  if (const auto* integer = std::get_if<std::int64_t>(&value_)) return static_cast<double>(*integer);
  return get_as<double>(value_, type(), Type::Number);
}

const Json* Json::find(std::string_view key) const {
  if (const auto* members = std::get_if<Object>(&value_)) {
    for (const auto& [name, value] : *members) {
      if (name == key) return &value;
    }
  }
  return nullptr;
}

const Json& Json::at(std::string_view key) const {
  const Json* value = find(key);
  if (value == nullptr) throw InputError("JSON: missing key '" + std::string(key) + "'");
  return *value;
}

std::string Json::dump(int indent) const {
  std::string out;
  dump_to(out, indent, 0);
  return out;
}

void Json::dump_to(std::string& out, int indent, int depth) const {
  switch (type()) {
    case Type::Null: out += "null"; break;
    case Type::Bool: out += std::get<bool>(value_) ? "true" : "false"; break;
    case Type::Integer: out += std::to_string(std::get<std::int64_t>(value_)); break;
    case Type::Number: append_number(out, std::get<double>(value_)); break;
    case Type::String: append_escaped(out, std::get<std::string>(value_)); break;
    case Type::Array: {
      const Array& elements = std::get<Array>(value_);
      out += '[';
      for (std::size_t i = 0; i < elements.size(); ++i) {
        if (i > 0) out += ',';
        append_newline(out, indent, depth + 1);
        elements[i].dump_to(out, indent, depth + 1);
      }
      if (!elements.empty()) append_newline(out, indent, depth);
      out += ']';
      break;
    }
    case Type::Object: {
      const Object& members = std::get<Object>(value_);
      out += '{';
      for (std::size_t i = 0; i < members.size(); ++i) {
        if (i > 0) out += ',';
        append_newline(out, indent, depth + 1);
        append_escaped(out, members[i].first);
        out += indent < 0 ? ":" : ": ";
        members[i].second.dump_to(out, indent, depth + 1);
      }
      if (!members.empty()) append_newline(out, indent, depth);
      out += '}';
      break;
    }
  }
}

Json Json::parse(std::string_view text) { return Parser(text).document(); }

void write_json_atomically(const std::filesystem::path& path, const Json& json) {
  write_file_atomically(path, json.dump() + '\n');
}

}  // namespace arlequin
