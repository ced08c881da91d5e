// Errors the user can act on. A message names where the problem is (file, line, key) and
// what was expected; the application turns them into one line on stderr and a non-zero exit.
#pragma once
#include <stdexcept>
#include <string>

namespace arlequin {

// Bad input: case file, command line, mesh or sample file.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The simulation itself went wrong (NaN, blow-up, solver failure); outputs so far are kept.
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace arlequin
