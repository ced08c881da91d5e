// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/block_matrix.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/parallel.hpp"

namespace arlequin::continuum {

BlockMatrix3::BlockMatrix3(const std::vector<std::vector<int>>& columns) {
  offset_.reserve(columns.size() + 1);
  for (const auto& row : columns) {
    column_.insert(column_.end(), row.begin(), row.end());
    offset_.push_back(static_cast<int>(column_.size()));
  }
  block_.assign(column_.size(), Block{});
}

BlockMatrix3::Block& BlockMatrix3::block(int row, int column) {
  return const_cast<Block&>(std::as_const(*this).block(row, column));
}

const BlockMatrix3::Block& BlockMatrix3::block(int row, int column) const {
  const auto first = column_.begin() + offset_[row], last = column_.begin() + offset_[row + 1];
  const auto it = std::lower_bound(first, last, column);
  if (it == last || *it != column)
    throw std::logic_error("BlockMatrix3: block (" + std::to_string(row) + ", " + std::to_string(column) + ") is not in the pattern");
  return block_[static_cast<std::size_t>(it - column_.begin())];
}

void BlockMatrix3::add(const std::vector<int>& nodes, const double* dense) {
  const std::size_t m = nodes.size(), stride = 3 * m;
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b < m; ++b) {
      Block& k = block(nodes[a], nodes[b]);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) k[3 * r + c] += dense[(3 * a + r) * stride + 3 * b + c];
    }
}

void BlockMatrix3::multiply(const std::vector<double>& x, std::vector<double>& y) const {
  if (x.size() != 3 * static_cast<std::size_t>(rows())) throw std::invalid_argument("BlockMatrix3::multiply: x needs 3 values per row");
  if (&x == &y) throw std::invalid_argument("BlockMatrix3::multiply: x and y must differ");
  y.resize(x.size());
  const long n = rows();
  for_each_index(n, static_cast<long>(column_.size()) > parallel_threshold, [&](long i) {
    double y0 = 0.0, y1 = 0.0, y2 = 0.0;
    for (int k = offset_[i]; k < offset_[i + 1]; ++k) {
      const Block& b = block_[k];
      const double* xj = &x[3 * static_cast<std::size_t>(column_[k])];
      y0 += b[0] * xj[0] + b[1] * xj[1] + b[2] * xj[2];
      y1 += b[3] * xj[0] + b[4] * xj[1] + b[5] * xj[2];
      y2 += b[6] * xj[0] + b[7] * xj[1] + b[8] * xj[2];
    }
    y[3 * i] = y0;
    y[3 * i + 1] = y1;
    y[3 * i + 2] = y2;
  });
}

}  // namespace arlequin::continuum
