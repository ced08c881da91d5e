// SPDX-License-Identifier: GPL-3.0-or-later
// The step profile's table and its comparison of two thread counts (common/step_profile.hpp):
// shares of the step, the serial share, and the Karp-Flatt serial fraction
// e = (1/S - 1/T) / (1 - 1/T) against its closed form.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "common/step_profile.hpp"

namespace arlequin {
namespace {

// The words of the table's row of `name` (empty if there is none).
std::vector<std::string> row(const std::string& text, const std::string& name) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind(name + " ", 0) == 0) {
      std::istringstream words(line);
      std::vector<std::string> out;
      for (std::string w; words >> w;) out.push_back(w);
      return out;
    }
  return {};
}
using Row = std::vector<std::string>;

// Two phases over 10 steps: bonds 3 s on threads, boundary 1 s serial.
StepProfile profile(double bonds, double boundary) {
  StepProfile p;
  const int b = p.phase("bonds"), c = p.phase("boundary");
  EXPECT_EQ(p.phase("bonds"), b);  // a name is one phase
  p.add(b, bonds, true);
  p.add(c, boundary, false);
  for (int s = 0; s < 10; ++s) p.count_step();
  return p;
}

TEST(StepProfile, TableGivesSharesOfTheStep) {
  const StepProfile p = profile(3.0, 1.0);
  EXPECT_EQ(p.seconds(), 4.0);
  EXPECT_EQ(p.serial_seconds(), 1.0);
  const std::string table = p.table();
  // ms per step, share, serial share.
  EXPECT_EQ(row(table, "bonds"), (Row{"bonds", "300.0000", "75.0%", "0.0%"})) << table;
  EXPECT_EQ(row(table, "boundary"), (Row{"boundary", "100.0000", "25.0%", "25.0%"})) << table;
  EXPECT_EQ(row(table, "step"), (Row{"step", "400.0000", "100.0%", "25.0%"})) << table;
}

TEST(StepProfile, ComparisonGivesTheKarpFlattFraction) {
  // On T = 4 threads bonds take 1 s (S = 3, e = (1/3 - 1/4) / (3/4) = 1/9 = 11.1 %) and the
  // boundary 1 s (S = 1, e = 100 %); the step 2 s (S = 2, e = (1/2 - 1/4) / (3/4) = 33.3 %), of
  // which 1 s serial by design (50.0 %).
  const std::string text = StepProfile::comparison(profile(3.0, 1.0), profile(1.0, 1.0), 4);
  EXPECT_EQ(row(text, "bonds"), (Row{"bonds", "300.0000", "100.0000", "3.00x", "11.1%", "0.0%"})) << text;
  EXPECT_EQ(row(text, "boundary"), (Row{"boundary", "100.0000", "100.0000", "1.00x", "100.0%", "50.0%"})) << text;
  EXPECT_EQ(row(text, "step"), (Row{"step", "400.0000", "200.0000", "2.00x", "33.3%", "50.0%"})) << text;
}

}  // namespace
}  // namespace arlequin
