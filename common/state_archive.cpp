// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/state_archive.hpp"

namespace arlequin {

std::size_t element_size(ElementKind kind) {
  switch (kind) {
    case ElementKind::float64:
    case ElementKind::int64: return 8;
    case ElementKind::uint32: return 4;
    case ElementKind::uint8:
    case ElementKind::text: return 1;
  }
  return 1;
}

const char* name_of(ElementKind kind) {
  switch (kind) {
    case ElementKind::float64: return "float64";
    case ElementKind::int64: return "int64";
    case ElementKind::uint32: return "uint32";
    case ElementKind::uint8: return "uint8";
    case ElementKind::text: return "text";
  }
  return "?";
}

void StateArchive::put_text(const std::string& name, const std::string& text) {
  Entry& e = entries_[name];
  e.kind = ElementKind::text;
  e.width = 1;
  e.rows = text.size();
  e.bytes.resize(text.size());
  if (!text.empty()) std::memcpy(e.bytes.data(), text.data(), text.size());
}

void StateArchive::put_entry(const std::string& name, Entry entry) {
  if (entry.bytes.size() != entry.rows * entry.width * element_size(entry.kind))
    throw StateMismatch("'" + name + "': " + std::to_string(entry.bytes.size()) + " bytes for " +
                        std::to_string(entry.rows) + " rows of " + std::to_string(entry.width) + " " + name_of(entry.kind));
  entries_[name] = std::move(entry);
}

std::string StateArchive::text(const std::string& name) const {
  const Entry& e = entry(name, ElementKind::text, 1);
  return std::string(reinterpret_cast<const char*>(e.bytes.data()), e.bytes.size());
}

std::size_t StateArchive::bytes() const {
  std::size_t n = 0;
  for (const auto& [name, e] : entries_) n += e.bytes.size();
  return n;
}

const StateArchive::Entry& StateArchive::entry(const std::string& name, ElementKind kind, std::size_t width) const {
  const auto it = entries_.find(name);
  if (it == entries_.end()) throw StateMismatch("it has no '" + name + "'");
  const Entry& e = it->second;
  if (e.kind != kind || e.width != width)
    throw StateMismatch("'" + name + "' holds " + std::string(name_of(e.kind)) + " x " + std::to_string(e.width) +
                        ", this scene expects " + name_of(kind) + " x " + std::to_string(width));
  return e;
}

}  // namespace arlequin
