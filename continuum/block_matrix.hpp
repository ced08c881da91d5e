// SPDX-License-Identifier: GPL-3.0-or-later
// BlockMatrix3: a sparse matrix of 3x3 blocks in compressed block rows (one block row per node,
// one block per pair of coupled nodes): the assembled stiffness K of the explicit solvers.
//
// Why: a linear-elastic step needs f_int = K u. Summed over the integration points it costs two
// passes over their entries (strain B_q u, then B_q^T s_q); nem's sub-cell points each couple a
// whole Voronoi cell's nodes, so the points hold many more entries than K has blocks (the
// coupled 3D bar of cases/wave_bar_coupled: see continuum/README.md). One pass over K is also
// what the energy 1/2 u.K u needs.
//
// Contract: the pattern is fixed at construction (sorted column lists per row, each with the
// diagonal); add() accumulates into an existing block (std::logic_error for a block outside the
// pattern); multiply() writes y = K x (x of 3 values per row, y a different vector, resized),
// each row summed in column order, on threads for large matrices, with the same bits on any
// thread count (std::invalid_argument for a wrong size or y aliasing x).
#pragma once
#include <array>
#include <vector>

namespace arlequin::continuum {

class BlockMatrix3 {
 public:
  using Block = std::array<double, 9>;  // row-major
  BlockMatrix3() = default;
  // columns[i]: the sorted block columns of row i.
  explicit BlockMatrix3(const std::vector<std::vector<int>>& columns);

  int rows() const { return static_cast<int>(offset_.size()) - 1; }
  std::size_t blocks() const { return column_.size(); }
  Block& block(int row, int column);  // must be in the pattern
  const Block& block(int row, int column) const;
  // Adds the 3x3 block at (3 a, 3 b) of the row-major (3 m) x (3 m) matrix `dense` to block
  // (nodes[a], nodes[b]) for every a, b < m.
  void add(const std::vector<int>& nodes, const double* dense);
  void multiply(const std::vector<double>& x, std::vector<double>& y) const;

 private:
  std::vector<int> offset_{0};
  std::vector<int> column_;
  std::vector<Block> block_;
};

}  // namespace arlequin::continuum
