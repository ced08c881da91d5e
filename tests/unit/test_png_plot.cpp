// PNG plots: tick choice, and written files parsed back (chunks, CRCs, zlib stream, pixels).
#include <gtest/gtest.h>

#include "support/scratch_dir.hpp"
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.hpp"
#include "common/png_plot.hpp"

#include <zlib.h>

namespace arlequin {
namespace {

namespace fs = std::filesystem;

class PngPlot : public test::ScratchDirTest {};

// --- An independent reader for the subset of PNG the writer produces -------------------

std::uint32_t reference_crc32(const std::uint8_t* data, std::size_t size) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, 3 bytes a pixel

  std::array<std::uint8_t, 3> at(int x, int y) const {
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

// Parses an 8-bit RGB, non-interlaced PNG; every check failure is a gtest failure (and an
// empty image).
Image read_png(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string file = buffer.str();
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(file.data());
  Image image;

  const std::string signature = "\x89PNG\r\n\x1a\n";
  EXPECT_EQ(file.substr(0, 8), signature);
  if (file.substr(0, 8) != signature) return {};

  std::vector<std::uint8_t> idat;
  std::vector<std::string> types;
  std::size_t pos = 8;
  while (pos + 12 <= file.size()) {
    const std::uint32_t length = be32(bytes + pos);
    EXPECT_LE(pos + 12 + length, file.size());
    if (pos + 12 + length > file.size()) return {};
    const std::string type = file.substr(pos + 4, 4);
    const std::uint8_t* data = bytes + pos + 8;
    EXPECT_EQ(be32(data + length), reference_crc32(bytes + pos + 4, length + 4)) << "CRC of chunk " << type;
    types.push_back(type);
    if (type == "IHDR") {
      EXPECT_EQ(length, 13u);
      image.width = static_cast<int>(be32(data));
      image.height = static_cast<int>(be32(data + 4));
      EXPECT_EQ(data[8], 8);   // bit depth
      EXPECT_EQ(data[9], 2);   // RGB
      EXPECT_EQ(data[10], 0);  // deflate
      EXPECT_EQ(data[11], 0);  // filter method
      EXPECT_EQ(data[12], 0);  // no interlace
    } else if (type == "IDAT") {
      idat.insert(idat.end(), data, data + length);
    }
    pos += 12 + length;
  }
  EXPECT_EQ(pos, file.size());
  EXPECT_FALSE(types.empty());
  if (types.empty()) return {};
  EXPECT_EQ(types.front(), "IHDR");
  EXPECT_EQ(types.back(), "IEND");

  // The zlib stream (header and Adler-32 checked by zlib itself) inflates to the scanlines.
  const std::size_t stride = 1 + 3 * static_cast<std::size_t>(image.width);
  std::vector<std::uint8_t> raw(image.height * stride + 1);
  uLongf size = static_cast<uLongf>(raw.size());
  EXPECT_EQ(uncompress(raw.data(), &size, idat.data(), static_cast<uLong>(idat.size())), Z_OK);
  raw.resize(size);
  EXPECT_EQ(raw.size(), image.height * stride);
  if (raw.size() != image.height * stride) return {};
  for (int y = 0; y < image.height; ++y) {
    EXPECT_EQ(raw[y * stride], 0) << "filter type of row " << y;
    image.rgb.insert(image.rgb.end(), raw.begin() + static_cast<std::ptrdiff_t>(y * stride + 1),
                     raw.begin() + static_cast<std::ptrdiff_t>((y + 1) * stride));
  }
  return image;
}

struct ColourStats {
  int count = 0;
  int y_min = std::numeric_limits<int>::max(), y_max = -1;
};

ColourStats find_colour(const Image& image, std::array<std::uint8_t, 3> colour) {
  ColourStats stats;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (image.at(x, y) == colour) ++stats.count, stats.y_min = std::min(stats.y_min, y), stats.y_max = std::max(stats.y_max, y);
  return stats;
}

// --- Ticks --------------------------------------------------------------------------------

void expect_ticks(const std::vector<double>& actual, const std::vector<double>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_NEAR(actual[i], expected[i], 1e-12 * std::max(1.0, std::abs(expected[i]))) << "tick " << i;
}

TEST_F(PngPlot, NiceTicksUseOneTwoFiveSteps) {
  expect_ticks(nice_ticks(0, 0.93), {0, 0.2, 0.4, 0.6, 0.8});
  expect_ticks(nice_ticks(0, 1), {0, 0.2, 0.4, 0.6, 0.8, 1.0});
  expect_ticks(nice_ticks(-3.7, 12.2), {0, 5, 10});
  expect_ticks(nice_ticks(12.2, -3.7, 8), {-2, 0, 2, 4, 6, 8, 10, 12});  // either order
  expect_ticks(nice_ticks(1e6, 3.4e6, 4), {1e6, 2e6, 3e6});
  expect_ticks(nice_ticks(0.0012, 0.0031), {0.0015, 0.002, 0.0025, 0.003});
  expect_ticks(nice_ticks(2.5, 2.5), {2.5});
  EXPECT_TRUE(nice_ticks(0, std::numeric_limits<double>::quiet_NaN()).empty());
  EXPECT_TRUE(nice_ticks(-1e308, 1e308).empty());
  EXPECT_TRUE(nice_ticks(0, 5e-324).empty());
  for (double hi : {0.013, 7.0, 55.0, 1234.5}) {
    const std::vector<double> ticks = nice_ticks(0, hi, 6);
    EXPECT_GE(ticks.size(), 3u);
    EXPECT_LE(ticks.size(), 6u);
  }
}

TEST_F(PngPlot, LogTicksAreDecades) {
  expect_ticks(log_ticks(1e-3, 1e2), {1e-3, 1e-2, 1e-1, 1, 10, 100});
  expect_ticks(log_ticks(2e-3, 5e2), {1e-2, 1e-1, 1, 10, 100});
  expect_ticks(log_ticks(1e-12, 1e3, 8), {1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-2, 1, 100});  // every 2nd decade
  EXPECT_TRUE(log_ticks(0, 10).empty());
  EXPECT_TRUE(log_ticks(-1, 10).empty());
}

// --- Files ----------------------------------------------------------------------------------

TEST_F(PngPlot, TwoAxesPlotIsValidPngWithBothColours) {
  PlotSpec spec;
  spec.title = "Bond failure under tension";
  spec.x_label = "strain";
  spec.y_label = "broken bond fraction";
  spec.y2_label = "stress [MPa]";
  PlotSeries broken{"broken bonds", {}, {}, PlotSeries::Style::line, false};
  PlotSeries stress{"stress", {}, {}, PlotSeries::Style::line_points, true};
  for (int i = 0; i <= 40; ++i) {
    const double strain = 0.0005 * i;
    broken.x.push_back(strain);
    broken.y.push_back(1 / (1 + std::exp(-(strain - 0.012) * 900)));
    stress.x.push_back(strain);
    stress.y.push_back(1800 * strain * std::exp(-strain * 80) + 1000);
  }
  spec.series = {broken, stress};
  const fs::path path = dir_ / "two_axes.png";
  write_png_plot(path, spec);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp." + std::to_string(::getpid())));

  const Image image = read_png(path);
  ASSERT_EQ(image.width, spec.width);
  ASSERT_EQ(image.height, spec.height);
  const ColourStats first = find_colour(image, plot_series_colour(0));
  const ColourStats second = find_colour(image, plot_series_colour(1));
  EXPECT_GT(first.count, 300);
  EXPECT_GT(second.count, 300);
  // Each series spans a good part of the height: the stress (values around 1000) is on its
  // own axis, else the fraction (0 to 1) would be a flat line at the bottom.
  EXPECT_GT(first.y_max - first.y_min, spec.height / 2);
  EXPECT_GT(second.y_max - second.y_min, spec.height / 4);
  EXPECT_NE(plot_series_colour(0), plot_series_colour(1));
  EXPECT_EQ(image.at(0, 0), (std::array<std::uint8_t, 3>{255, 255, 255}));
}

TEST_F(PngPlot, LogPlotSkipsUnusableValues) {
  PlotSpec spec;
  spec.title = "Error against run time";
  spec.x_label = "wall time [s]";
  spec.y_label = "relative error";
  spec.log_x = spec.log_y = true;
  spec.width = 640;
  spec.height = 420;
  PlotSeries dem{"DEM", {0.5, 2, 8, 30, 120, 500}, {0.3, 0.1, 0.04, 0.012, 0.004, 0.0011}, PlotSeries::Style::line_points};
  PlotSeries coupled{"coupled", {0.2, -1, 1.5, std::numeric_limits<double>::quiet_NaN(), 20, 90},
                     {0.5, 0.2, 0.06, 0.02, 0, 0.002}, PlotSeries::Style::points};
  spec.series = {dem, coupled};
  const fs::path path = dir_ / "log.png";
  write_png_plot(path, spec);

  const Image image = read_png(path);
  ASSERT_EQ(image.width, 640);
  ASSERT_EQ(image.height, 420);
  EXPECT_GT(find_colour(image, plot_series_colour(0)).count, 200);
  EXPECT_GT(find_colour(image, plot_series_colour(1)).count, 40);
}

TEST_F(PngPlot, DegenerateSeriesDoNotCrash) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  PlotSpec spec;
  spec.series = {PlotSeries{"empty", {}, {}},
                 PlotSeries{"constant", {1, 2, 3}, {5, 5, 5}},
                 PlotSeries{"not finite", {nan, 1, inf}, {1, nan, 2}, PlotSeries::Style::points, true},
                 PlotSeries{"single", {2}, {4}},
                 PlotSeries{"huge", {1, 2, 3}, {1e308, -1e308, 1}}};
  write_png_plot(dir_ / "degenerate.png", spec);
  EXPECT_EQ(read_png(dir_ / "degenerate.png").width, 900);
  EXPECT_GT(find_colour(read_png(dir_ / "degenerate.png"), plot_series_colour(1)).count, 100);

  PlotSpec nothing;  // no series at all, log axes without data
  nothing.log_x = nothing.log_y = true;
  write_png_plot(dir_ / "nothing.png", nothing);
  EXPECT_EQ(read_png(dir_ / "nothing.png").height, 560);

  PlotSpec zero;  // a constant zero series
  zero.series = {PlotSeries{"zero", {0, 0}, {0, 0}, PlotSeries::Style::points}};
  write_png_plot(dir_ / "zero.png", zero);
  EXPECT_GT(find_colour(read_png(dir_ / "zero.png"), plot_series_colour(0)).count, 20);
}

TEST_F(PngPlot, RejectsBadInputAndReportsIoErrors) {
  PlotSpec spec;
  spec.series = {PlotSeries{"mismatch", {1, 2}, {1}}};
  EXPECT_THROW(write_png_plot(dir_ / "bad.png", spec), std::invalid_argument);
  spec.series.clear();
  spec.width = 10;
  EXPECT_THROW(write_png_plot(dir_ / "small.png", spec), std::invalid_argument);
  spec.width = 900;
  std::ofstream(dir_ / "file") << "x";
  EXPECT_THROW(write_png_plot(dir_ / "file" / "plot.png", spec), RunError);
}

}  // namespace
}  // namespace arlequin
