// SPDX-License-Identifier: GPL-3.0-or-later
// Plots of a run's results: the program says what to draw (plots.json in the results folder),
// the Python package python/arlequin draws it with matplotlib (`python3 -m arlequin.plot DIR`,
// usable on its own). Curves either name columns of a CSV file in that folder (series.csv,
// curve.csv: no data is copied) or carry their points inline. python/README.md holds the
// plots.json format; this file writes exactly that.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace arlequin {

struct PlotCurve {
  enum class Style { line, points, line_points, dashed };

  std::string label;  // legend text; empty: left out of the legend
  Style style = Style::line;
  bool right_axis = false;
  int colour = -1;  // the default colour cycle's entry to draw in; -1: the next one
  // Either columns of a CSV file in the results folder, multiplied by the scales...
  std::string csv{}, x_column{}, y_column{};
  double x_scale = 1.0, y_scale = 1.0;
  // ...or the points themselves (used when csv is empty; same length).
  std::vector<double> x{}, y{};
};

struct Plot {
  std::string file;  // in the results folder; its extension is the default format (.png)
  std::string title, x_label, y_label, y2_label;
  bool log_x = false, log_y = false, log_y2 = false;
  std::vector<PlotCurve> curves;
};

// Writes `plots` to dir/plots.json (atomically, replacing any earlier list), then draws them
// with the Python package. Drawing is best effort: the run's results are already written, so
// a missing Python, matplotlib or a failed plot is said in one line on stderr ("plots skipped
// (files): why") and never fails the command. The interpreter is the one found at configure
// time (Debian's python3, where python3-matplotlib installs), or $ARLEQUIN_PYTHON.
void write_plots(const std::filesystem::path& dir, const std::vector<Plot>& plots);

}  // namespace arlequin
