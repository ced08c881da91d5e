// SPDX-License-Identifier: GPL-3.0-or-later
// The state of a run as named arrays, for checkpoints (app/checkpoint.hpp writes it to HDF5).
//
// Contract: each model puts what it needs to continue bit for bit under names of its own
// ("dem/particles/velocity", "continuum/u", ...), and gets them back into a model built again
// from the same case. An entry is `rows` tuples of `width` elements of one element kind
// (float64, int64, uint32, uint8) or a text; put() copies, get() copies out. Asking for an
// entry that is missing, of another kind or width, or (get_into) of another length throws
// StateMismatch naming the entry and both sizes: the checkpoint is not of this scene. The
// archive itself knows nothing of files, so dem/ and continuum/ use it without HDF5.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/quat.hpp"
#include "common/vec3.hpp"

namespace arlequin {

class StateMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class ElementKind : std::uint8_t { float64, int64, uint32, uint8, text };

// How a C++ value is laid out as elements: kind and count per value.
template <class T>
struct StateLayout;
template <>
struct StateLayout<double> { static constexpr ElementKind kind = ElementKind::float64; static constexpr std::size_t width = 1; };
template <>
struct StateLayout<Vec3> { static constexpr ElementKind kind = ElementKind::float64; static constexpr std::size_t width = 3; };
template <>
struct StateLayout<Quat> { static constexpr ElementKind kind = ElementKind::float64; static constexpr std::size_t width = 4; };
template <std::size_t N>
struct StateLayout<std::array<double, N>> { static constexpr ElementKind kind = ElementKind::float64; static constexpr std::size_t width = N; };
template <>
struct StateLayout<std::int64_t> { static constexpr ElementKind kind = ElementKind::int64; static constexpr std::size_t width = 1; };
template <>
struct StateLayout<std::uint32_t> { static constexpr ElementKind kind = ElementKind::uint32; static constexpr std::size_t width = 1; };
template <>
struct StateLayout<std::pair<std::uint32_t, std::uint32_t>> {
  static constexpr ElementKind kind = ElementKind::uint32;
  static constexpr std::size_t width = 2;
};
template <>
struct StateLayout<std::uint8_t> { static constexpr ElementKind kind = ElementKind::uint8; static constexpr std::size_t width = 1; };

std::size_t element_size(ElementKind kind);  // bytes
const char* name_of(ElementKind kind);      // "float64", ...

class StateArchive {
 public:
  struct Entry {
    ElementKind kind = ElementKind::float64;
    std::size_t width = 1;  // elements per row
    std::size_t rows = 0;
    std::vector<std::byte> bytes;  // rows * width elements, native byte order
  };

  template <class T>
  void put(const std::string& name, std::span<const T> values) {
    // Copied as bytes: a pair's assignment is not trivial, its bytes are the two values.
    static_assert(std::is_trivially_copy_constructible_v<T> && std::is_standard_layout_v<T> && sizeof(T) == StateLayout<T>::width * element_size_of<T>());
    Entry& e = entries_[name];
    e.kind = StateLayout<T>::kind;
    e.width = StateLayout<T>::width;
    e.rows = values.size();
    e.bytes.resize(values.size_bytes());
    if (!values.empty()) std::memcpy(e.bytes.data(), values.data(), values.size_bytes());
  }
  template <class T>
  void put(const std::string& name, const std::vector<T>& values) { put(name, std::span<const T>(values)); }
  void put(const std::string& name, double value) { put(name, std::span<const double>(&value, 1)); }
  void put(const std::string& name, std::int64_t value) { put(name, std::span<const std::int64_t>(&value, 1)); }
  void put_text(const std::string& name, const std::string& text);
  // Adds a raw entry (the checkpoint reader); the kind's element size must fit the bytes.
  void put_entry(const std::string& name, Entry entry);

  bool has(const std::string& name) const { return entries_.count(name) > 0; }
  // The values of an entry of T's kind and width, as many as it holds.
  template <class T>
  std::vector<T> get(const std::string& name) const {
    const Entry& e = entry(name, StateLayout<T>::kind, StateLayout<T>::width);
    std::vector<T> out(e.rows);
    if (e.rows > 0) std::memcpy(static_cast<void*>(out.data()), e.bytes.data(), e.bytes.size());
    return out;
  }
  // Into a span of the size the scene has (StateMismatch if the entry's differs).
  template <class T>
  void get_into(const std::string& name, std::span<T> out) const {
    const Entry& e = entry(name, StateLayout<T>::kind, StateLayout<T>::width);
    if (e.rows != out.size())
      throw StateMismatch("'" + name + "' holds " + std::to_string(e.rows) + " values, this scene has " +
                          std::to_string(out.size()));
    if (e.rows > 0) std::memcpy(static_cast<void*>(out.data()), e.bytes.data(), e.bytes.size());
  }
  template <class T>
  void get_into(const std::string& name, std::vector<T>& out) const { get_into(name, std::span<T>(out)); }
  double number(const std::string& name) const { return single<double>(name); }
  std::int64_t integer(const std::string& name) const { return single<std::int64_t>(name); }
  std::string text(const std::string& name) const;

  const std::map<std::string, Entry>& entries() const { return entries_; }
  std::size_t bytes() const;  // of all entries' values

 private:
  template <class T>
  static constexpr std::size_t element_size_of() {
    if constexpr (StateLayout<T>::kind == ElementKind::float64 || StateLayout<T>::kind == ElementKind::int64) return 8;
    else if constexpr (StateLayout<T>::kind == ElementKind::uint32) return 4;
    else return 1;
  }
  template <class T>
  T single(const std::string& name) const {
    const auto values = get<T>(name);
    if (values.size() != 1) throw StateMismatch("'" + name + "' holds " + std::to_string(values.size()) + " values, not one");
    return values[0];
  }
  const Entry& entry(const std::string& name, ElementKind kind, std::size_t width) const;

  std::map<std::string, Entry> entries_;  // ordered: the file lists them in name order
};

}  // namespace arlequin
