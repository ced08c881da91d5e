// BlockMatrix3 against a dense product: random point matrices added over overlapping node lists
// (as the stiffness assembly does), then y = K x against the dense K built from the same
// contributions; a block outside the pattern is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include "continuum/block_matrix.hpp"

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

}  // namespace
}  // namespace arlequin::continuum
