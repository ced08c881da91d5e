// Small ordered JSON value: run summaries are written with it and read back when runs are
// compared. Object keys keep insertion order so summaries diff cleanly between runs.
#pragma once
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace arlequin {

class Json {
 public:
  using Array = std::vector<Json>;
  using Object = std::vector<std::pair<std::string, Json>>;
  enum class Type { Null, Bool, Integer, Number, String, Array, Object };

  Json() = default;  // null
  Json(std::nullptr_t) {}
  Json(bool value) : value_(value) {}
  Json(double value) : value_(value) {}
  // Every integer type (int, int64_t, size_t, ...) is kept exact as int64; unsigned values
  // beyond int64 fall back to a number, as any JSON reader would read them anyway.
  template <std::integral T>
    requires(!std::same_as<T, bool>)
  Json(T value) {
    if constexpr (std::is_unsigned_v<T> && sizeof(T) >= sizeof(std::int64_t)) {
      if (value > static_cast<T>(std::numeric_limits<std::int64_t>::max())) {
        value_ = static_cast<double>(value);
        return;
      }
    }
    value_ = static_cast<std::int64_t>(value);
  }
  Json(const char* value) : value_(std::string(value)) {}
  Json(std::string_view value) : value_(std::string(value)) {}
  Json(std::string value) : value_(std::move(value)) {}

  static Json object() { return Json(Object{}); }
  static Json array() { return Json(Array{}); }

  // Object member, created (null) if missing; a null value first becomes an empty object.
  // std::logic_error on other types.
  Json& operator[](std::string_view key);
  // Appends to an array; a null value first becomes an empty array. std::logic_error otherwise.
  void push_back(Json value);

  Type type() const { return static_cast<Type>(value_.index()); }
  bool is_null() const { return type() == Type::Null; }
  // Typed reads; InputError naming the expected and the actual type when they differ
  // (a mismatch means the file read back is not what was expected).
  bool as_bool() const;
  std::int64_t as_integer() const;
  double as_number() const;  // Integer or Number
  const std::string& as_string() const;
  const Array& as_array() const;
  const Object& as_object() const;
  // Object member or nullptr (also when this is not an object).
  const Json* find(std::string_view key) const;
  // Object member; InputError naming the key when missing.
  const Json& at(std::string_view key) const;

  // indent >= 0: one value per line, nested levels indented by `indent` spaces;
  // indent < 0: everything on one line. Non-finite numbers are written as null since JSON
  // has no representation for them.
  std::string dump(int indent = 2) const;
  // Parses a complete document (RFC 8259). InputError with the byte offset on bad input.
  static Json parse(std::string_view text);

  bool operator==(const Json&) const = default;

 private:
  explicit Json(Object value) : value_(std::move(value)) {}
  explicit Json(Array value) : value_(std::move(value)) {}
  void dump_to(std::string& out, int indent, int depth) const;

  // Alternative order matches Type.
  std::variant<std::nullptr_t, bool, std::int64_t, double, std::string, Array, Object> value_;
};

// write_file_atomically(path, json.dump() + '\n').
void write_json_atomically(const std::filesystem::path& path, const Json& json);

}  // namespace arlequin
