// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include "convergence_util.hpp"

using namespace arlequin::continuum;
using namespace arlequin::continuum::testing;

TEST(ContinuumFeStatic, ConvergenceP1) {
  const double rate = convergence_rate("fe", 1, 0.15, 0.075);
  std::cout << "P1 L2 rate " << rate << "\n";
  EXPECT_GE(rate, 1.8);
}

TEST(ContinuumFeStatic, ConvergenceP2) {
  const double rate = convergence_rate("fe", 2, 0.3, 0.15);
  std::cout << "P2 L2 rate " << rate << "\n";
  EXPECT_GE(rate, 2.8);
}

TEST(ContinuumFeStatic, CantileverTipDeflectionP2) {
  const double ratio = cantilever_tip_ratio("fe", 2, 0.25);
  std::cout << "P2 cantilever tip / Timoshenko " << ratio << "\n";
  EXPECT_NEAR(ratio, 1.0, 0.02);
}
