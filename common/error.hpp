// SPDX-License-Identifier: GPL-3.0-or-later
// Errors the user can act on. A message names where the problem is (file, line, key) and
// what was expected; the application turns them into one line on stderr and a non-zero exit.
#pragma once
#include <stdexcept>
#include <string>
#include <utility>

namespace arlequin {

// Bad input: case file, command line, mesh or sample file.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bad input found by a library that knows which of its settings is at fault (`key`, e.g.
// "quadrature") but not where that setting sits in a case file: the reader that passed the
// settings in catches it and names the place (file:line: section.key: message).
class SettingError : public InputError {
 public:
  SettingError(std::string key, const std::string& message)
      : InputError(key + ": " + message), key_(std::move(key)), message_(message) {}
  const std::string& key() const { return key_; }
  const std::string& message() const { return message_; }

 private:
  std::string key_, message_;
};

// The simulation itself went wrong (NaN, blow-up, solver failure); outputs so far are kept.
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace arlequin
