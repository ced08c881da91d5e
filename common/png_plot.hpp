// Small line/scatter plots written as PNG files, with no plotting library: calibration
// curves, broken-bond fractions against strain next to the stress-strain curve, error
// against run time. Axes get 1-2-5 ticks (decades on log axes), labels, a title, an
// optional second y axis on the right and a legend; text uses a built-in bitmap font.
// The PNG is 8-bit RGB, stored without compression (a 900x560 plot is about 1.5 MB).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace arlequin {

struct PlotSeries {
  enum class Style { line, points, line_points };

  std::string label;  // legend text; series with an empty label are left out of the legend
  std::vector<double> x, y;  // same length (std::invalid_argument otherwise)
  Style style = Style::line;
  bool right_axis = false;  // plotted against the right y axis
};

struct PlotSpec {
  std::string title, x_label, y_label, y2_label;  // printable ASCII; other bytes show as '?'
  std::vector<PlotSeries> series;
  bool log_x = false, log_y = false, log_y2 = false;  // log_y: left axis, log_y2: right axis
  int width = 900, height = 560;                      // pixels, each within [200, 8000]
};

// Draws `spec` and writes it to `path` as a PNG through "<path>.tmp" and a rename, so a
// reader never sees a partial image. Points with a non-finite coordinate (or one beyond
// 1e300 in size, or one below 1e-300 on a log axis, non-positive ones included) are
// skipped and break the line there. Axis ranges come from the data, widened to whole
// ticks; an empty or constant range is padded. Colours follow plot_series_colour(index in
// spec.series). Throws std::invalid_argument for a bad size or mismatched x/y lengths,
// RunError when the file cannot be written.
void write_png_plot(const std::filesystem::path& path, const PlotSpec& spec);

// The colour of series `index` (a fixed palette of 10 that repeats), as {r, g, b}.
std::array<std::uint8_t, 3> plot_series_colour(std::size_t index);

// Tick values for a linear axis from `lo` to `hi`: the multiples within [lo, hi] of the
// smallest step of the form {1, 2, 5} x 10^k that gives at most `max_ticks` of them
// (max_ticks >= 2). The bounds may come in either order; {lo} if lo == hi; empty if a
// bound is not finite or the range is too wide or too narrow for doubles (span below 1e-12
// of the bounds).
std::vector<double> nice_ticks(double lo, double hi, int max_ticks = 7);

// Tick values for a log axis from `lo` to `hi` (both > 0, else empty): the powers of ten
// within [lo, hi], every decade or every 2nd, 3rd, 5th, 10th, ... decade so that there are
// at most `max_ticks` (>= 2) of them.
std::vector<double> log_ticks(double lo, double hi, int max_ticks = 8);

}  // namespace arlequin
