// SPDX-License-Identifier: GPL-3.0-or-later
// Small text helpers shared by the app's tools (calibrate, virtual tests): a number printed
// with a printf pattern, the names of the coordinate axes as case files spell them, broken
// fractions per bond set.
#pragma once
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/case_file.hpp"

namespace arlequin::app {

inline constexpr std::string_view axis_names[] = {"x", "y", "z"};

// The axis 0, 1, 2 that `text` names; otherwise the case node's error for `key`.
inline int axis_index(CaseNode& node, std::string_view key, const std::string& text) {
  for (int k = 0; k < 3; ++k)
    if (text == axis_names[k]) return k;
  node.fail(key, "expected an axis x, y or z, got '" + text + "'");
}

// One number formatted by a printf pattern with a single double conversion.
inline std::string format(const char* pattern, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, pattern, value);
  return buffer;
}

// Broken fractions per bond set as "fibre 4.1, matrix 40, ..." (percent); `separator` "; "
// keeps a CSV cell free of commas.
inline std::string broken_text(const std::vector<std::pair<std::string, double>>& fractions, const char* separator = ", ") {
  std::string text;
  for (const auto& [name, f] : fractions) text += (text.empty() ? "" : separator) + name + format(" %.3g", 100.0 * f);
  return text;
}

}  // namespace arlequin::app
