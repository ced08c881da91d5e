// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/csv_series.hpp"

#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "common/atomic_file.hpp"

namespace arlequin {

namespace {

constexpr auto flush_interval = std::chrono::seconds(2);

}  // namespace

CsvSeries::CsvSeries(std::filesystem::path path, std::vector<std::string> columns)
    : path_(std::move(path)), columns_(std::move(columns)), last_flush_(std::chrono::steady_clock::now()) {
  if (columns_.empty()) throw std::logic_error("CsvSeries '" + path_.string() + "': no columns");
  for (const std::string& name : columns_) {
    if (name.empty() || name.find_first_of(",\"\r\n") != std::string::npos)
      throw std::logic_error("CsvSeries '" + path_.string() + "': bad column name '" + name + "'");
  }
}

CsvSeries::~CsvSeries() {
  try {
    flush();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arlequin: %s\n", e.what());
  }
}

void CsvSeries::append(std::span<const double> row) {
  if (row.size() != columns_.size())
    throw std::logic_error("CsvSeries '" + path_.string() + "': row of " + std::to_string(row.size()) +
                           " values for " + std::to_string(columns_.size()) + " columns");
  values_.insert(values_.end(), row.begin(), row.end());
  dirty_ = true;
  if (std::chrono::steady_clock::now() - last_flush_ > flush_interval) flush();
}

std::span<const double> CsvSeries::row(std::size_t i) const {
  if (i >= rows())
    throw std::out_of_range("CsvSeries '" + path_.string() + "': row " + std::to_string(i) + " of " +
                            std::to_string(rows()));
  return std::span<const double>(values_).subspan(i * columns_.size(), columns_.size());
}

void CsvSeries::flush() {
  if (!dirty_) return;
  std::string text;
  // Each value takes at most 19 characters in %.12g ("-1.23456789012e-308") plus separator.
  text.reserve(values_.size() * 20 + columns_.size() * 16);
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (c > 0) text += ',';
    text += columns_[c];
  }
  text += '\n';
  const std::size_t width = columns_.size();
  for (std::size_t i = 0; i < values_.size(); ++i) {
    // to_chars with precision 12 is printf's %.12g in the C locale, whatever the global locale.
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, values_[i], std::chars_format::general, 12);
    text.append(buffer, result.ptr);
    text += (i + 1) % width == 0 ? '\n' : ',';
  }
  write_file_atomically(path_, text);
  dirty_ = false;
  last_flush_ = std::chrono::steady_clock::now();
}

}  // namespace arlequin
