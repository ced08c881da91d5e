// SPDX-License-Identifier: GPL-3.0-or-later
// BlockMatrix3 against a dense product: random point matrices added over overlapping node lists
// (as the stiffness assembly does), then y = K x against the dense K built from the same
// contributions; a block outside the pattern is refused; and a matrix large enough for threads
// gives the same bits on 1 and 2 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include "common/parallel.hpp"
#include "continuum/block_matrix.hpp"
#include "support/omp_threads.hpp"

namespace arlequin::continuum {
namespace {

TEST(BlockMatrix3, MultiplyEqualsTheDenseSumOfTheContributions) {
  const int n = 7;
  const std::vector<std::vector<int>> lists{{0, 1, 2}, {2, 3}, {1, 3, 4, 5}, {5, 6}, {6}, {0, 6}};
  std::vector<std::vector<int>> columns(n);
  for (const auto& l : lists)
    for (int a : l)
      for (int b : l) columns[a].push_back(b);
  for (auto& c : columns) {
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
  }
  BlockMatrix3 K(columns);
  std::vector<double> dense(9 * n * n, 0.0);  // (3n) x (3n), row-major
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (const auto& l : lists) {
    const std::size_t m = l.size();
    std::vector<double> Ke(9 * m * m);
    for (double& v : Ke) v = uni(rng);
    K.add(l, Ke.data());
    for (std::size_t a = 0; a < m; ++a)
      for (std::size_t b = 0; b < m; ++b)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) dense[(3 * l[a] + r) * 3 * n + 3 * l[b] + c] += Ke[(3 * a + r) * 3 * m + 3 * b + c];
  }
  std::vector<double> x(3 * n), y;
  for (double& v : x) v = uni(rng);
  K.multiply(x, y);
  ASSERT_EQ(y.size(), x.size());
  for (int i = 0; i < 3 * n; ++i) {
    double expected = 0.0;
    for (int j = 0; j < 3 * n; ++j) expected += dense[i * 3 * n + j] * x[j];
    EXPECT_NEAR(y[i], expected, 1e-14 * 3 * n) << i;
  }
  EXPECT_EQ(K.rows(), n);
  EXPECT_THROW(K.block(0, 4), std::logic_error);  // nodes 0 and 4 share no list
}

#ifdef _OPENMP
TEST(BlockMatrix3, MultiplyIsTheSameOnAnyThreadCount) {
  // A chain of 4000 nodes, each coupled to the next 3: ~28 000 blocks, above the threshold.
  const int n = 4000;
  std::vector<std::vector<int>> columns(n);
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - 3); j <= std::min(n - 1, i + 3); ++j) columns[i].push_back(j);
  BlockMatrix3 K(columns);
  ASSERT_GT(static_cast<long>(K.blocks()), parallel_threshold);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int i = 0; i < n; ++i)
    for (int j : columns[i])
      for (double& v : K.block(i, j)) v = uni(rng);
  std::vector<double> x(3 * n), one, two;
  for (double& v : x) v = uni(rng);
  {
    const test::OmpThreads scope(1);
    K.multiply(x, one);
  }
  {
    const test::OmpThreads scope(2);
    K.multiply(x, two);
  }
  EXPECT_EQ(one, two);
  EXPECT_THROW(K.multiply(one, one), std::invalid_argument);
  EXPECT_THROW(K.multiply(std::vector<double>(5), two), std::invalid_argument);
}
#endif

}  // namespace
}  // namespace arlequin::continuum
