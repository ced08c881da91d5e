// SPDX-License-Identifier: GPL-3.0-or-later
// Runs the `arlequin` executable as a user would and captures what it prints.
#pragma once
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace arlequin::test {

struct CliResult {
  int exit_code = -1;
  std::string output;  // stdout or stderr, as asked
};

// args are appended to the executable path; stream: "stdout" or "stderr".
inline CliResult run_arlequin(const std::string& args, const std::string& stream = "stderr") {
  const std::string exe = std::string(ARLEQUIN_BINARY_DIR) + "/app/arlequin";
  const std::string redirect = stream == "stderr" ? " 2>&1 >/dev/null" : " 2>/dev/null";
  FILE* pipe = popen((exe + " " + args + redirect).c_str(), "r");
  CliResult r;
  std::array<char, 4096> buffer;
  while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe)) r.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A fresh scratch folder under the system temp directory.
inline std::filesystem::path scratch_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("arlequin_test_" + name);
}
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = scratch_path(name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Rows of a CSV file as maps column -> text.
inline std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& path) {
  std::istringstream in(read_text(path));
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> header;
  for (std::stringstream s(line); std::getline(s, cell, ',');) header.push_back(cell);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    auto& row = rows.emplace_back();
    std::size_t k = 0;
    for (std::stringstream s(line); std::getline(s, cell, ',') && k < header.size();) row[header[k++]] = cell;
  }
  return rows;
}
inline double number(const std::map<std::string, std::string>& row, const std::string& column) {
  return std::stod(row.at(column));
}

// `column` of CSV rows where the column `along` (increasing down the rows) equals x, linear between
// rows, held beyond the first and last rows.
inline double value_at(const std::vector<std::map<std::string, std::string>>& rows, const std::string& along, double x,
                       const std::string& column) {
  std::size_t k = 1;
  while (k + 1 < rows.size() && number(rows[k], along) < x) ++k;
  const double x0 = number(rows[k - 1], along), x1 = number(rows[k], along);
  const double s = std::clamp((x - x0) / (x1 - x0), 0.0, 1.0);
  return (1 - s) * number(rows[k - 1], column) + s * number(rows[k], column);
}

}  // namespace arlequin::test
