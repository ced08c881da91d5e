// SPDX-License-Identifier: GPL-3.0-or-later
// Time series table (one row per output step) written as CSV. Rows stay in memory and the
// whole file is rewritten atomically, so the file on disk is always a complete table that
// plotting scripts can read while the run goes on.
#pragma once
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace arlequin {

class CsvSeries {
 public:
  // Column names must be non-empty and free of ',', '"' and line breaks (std::logic_error).
  CsvSeries(std::filesystem::path path, std::vector<std::string> columns);
  // Not copyable or movable: the destructor writes the file, a copy would write it twice.
  CsvSeries(const CsvSeries&) = delete;
  CsvSeries& operator=(const CsvSeries&) = delete;
  // Flushes; errors are reported on stderr since a destructor cannot throw.
  ~CsvSeries();

  // Appends one row (row.size() must equal columns().size(), else std::logic_error).
  // Flushes when more than 2 s of wall time passed since the last flush, which bounds both
  // the data lost in a crash and the cost of rewriting long tables.
  void append(std::span<const double> row);
  // Rewrites the file (header + all rows, values as "%.12g"). Throws RunError.
  void flush();

  std::size_t rows() const { return values_.size() / columns_.size(); }
  std::span<const double> row(std::size_t i) const;  // std::out_of_range if i >= rows()
  const std::vector<std::string>& columns() const { return columns_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::vector<std::string> columns_;
  std::vector<double> values_;  // row-major, rows() x columns().size()
  bool dirty_ = true;           // true until the file matches values_ (header-only included)
  std::chrono::steady_clock::time_point last_flush_;
};

}  // namespace arlequin
