#include "common/png_plot.hpp"

#include <zlib.h>

#include "common/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string_view>

#include "common/atomic_file.hpp"

namespace arlequin {

namespace {

using Rgb = std::array<std::uint8_t, 3>;

// ---------------------------------------------------------------------------------------
// Bitmap font: printable ASCII 32..126, 5 columns x 9 rows per glyph. Rows 0-6 hold capitals
// and digits (row 6 is the baseline row), rows 7-8 the descenders of g, j, p, q, y and ','.
// Each glyph is written as its 9 rows of 5 pixels ('#' set, '.' clear) separated by spaces.

constexpr int kGlyphCols = 5;
constexpr int kGlyphRows = 9;
constexpr int kCellWidth = 6;  // glyph plus one column of spacing
constexpr int kCapHeight = 7;

constexpr std::array<std::string_view, 95> kFont = {
    "..... ..... ..... ..... ..... ..... ..... ..... .....",  // ' '
    "..#.. ..#.. ..#.. ..#.. ..#.. ..... ..#.. ..... .....",  // !
    ".#.#. .#.#. ..... ..... ..... ..... ..... ..... .....",  // "
    ".#.#. .#.#. ##### .#.#. ##### .#.#. .#.#. ..... .....",  // #
    "..#.. .#### #.#.. .###. ..#.# ####. ..#.. ..... .....",  // $
    "##... ##..# ...#. ..#.. .#... #..## ...## ..... .....",  // %
    ".##.. #..#. #.#.. .#... #.#.# #..#. .##.# ..... .....",  // &
    "..#.. ..#.. ..... ..... ..... ..... ..... ..... .....",  // '
    "...#. ..#.. .#... .#... .#... ..#.. ...#. ..... .....",  // (
    ".#... ..#.. ...#. ...#. ...#. ..#.. .#... ..... .....",  // )
    "..... ..#.. #.#.# .###. #.#.# ..#.. ..... ..... .....",  // *
    "..... ..#.. ..#.. ##### ..#.. ..#.. ..... ..... .....",  // +
    "..... ..... ..... ..... ..... .##.. .##.. ..#.. .#...",  // ,
    "..... ..... ..... ####. ..... ..... ..... ..... .....",  // -
    "..... ..... ..... ..... ..... .##.. .##.. ..... .....",  // .
    "....# ....# ...#. ..#.. .#... #.... #.... ..... .....",  // /
    ".###. #...# #..## #.#.# ##..# #...# .###. ..... .....",  // 0
    "..#.. .##.. ..#.. ..#.. ..#.. ..#.. .###. ..... .....",  // 1
    ".###. #...# ....# ...#. ..#.. .#... ##### ..... .....",  // 2
    "##### ...#. ..#.. ...#. ....# #...# .###. ..... .....",  // 3
    "...#. ..##. .#.#. #..#. ##### ...#. ...#. ..... .....",  // 4
    "##### #.... ####. ....# ....# #...# .###. ..... .....",  // 5
    "..##. .#... #.... ####. #...# #...# .###. ..... .....",  // 6
    "##### ....# ...#. ..#.. .#... .#... .#... ..... .....",  // 7
    ".###. #...# #...# .###. #...# #...# .###. ..... .....",  // 8
    ".###. #...# #...# .#### ....# ...#. .##.. ..... .....",  // 9
    "..... .##.. .##.. ..... .##.. .##.. ..... ..... .....",  // :
    "..... .##.. .##.. ..... .##.. .##.. ..#.. .#... .....",  // ;
    "...#. ..#.. .#... #.... .#... ..#.. ...#. ..... .....",  // <
    "..... ..... ##### ..... ##### ..... ..... ..... .....",  // =
    ".#... ..#.. ...#. ....# ...#. ..#.. .#... ..... .....",  // >
    ".###. #...# ....# ...#. ..#.. ..... ..#.. ..... .....",  // ?
    ".###. #...# #.### #.#.# #.### #.... .#### ..... .....",  // @
    ".###. #...# #...# ##### #...# #...# #...# ..... .....",  // A
    "####. #...# #...# ####. #...# #...# ####. ..... .....",  // B
    ".###. #...# #.... #.... #.... #...# .###. ..... .....",  // C
    "###.. #..#. #...# #...# #...# #..#. ###.. ..... .....",  // D
    "##### #.... #.... ####. #.... #.... ##### ..... .....",  // E
    "##### #.... #.... ####. #.... #.... #.... ..... .....",  // F
    ".###. #...# #.... #.### #...# #...# .#### ..... .....",  // G
    "#...# #...# #...# ##### #...# #...# #...# ..... .....",  // H
    ".###. ..#.. ..#.. ..#.. ..#.. ..#.. .###. ..... .....",  // I
    "..### ...#. ...#. ...#. ...#. #..#. .##.. ..... .....",  // J
    "#...# #..#. #.#.. ##... #.#.. #..#. #...# ..... .....",  // K
    "#.... #.... #.... #.... #.... #.... ##### ..... .....",  // L
    "#...# ##.## #.#.# #.#.# #...# #...# #...# ..... .....",  // M
    "#...# #...# ##..# #.#.# #..## #...# #...# ..... .....",  // N
    ".###. #...# #...# #...# #...# #...# .###. ..... .....",  // O
    "####. #...# #...# ####. #.... #.... #.... ..... .....",  // P
    ".###. #...# #...# #...# #.#.# #..#. .##.# ..... .....",  // Q
    "####. #...# #...# ####. #.#.. #..#. #...# ..... .....",  // R
    ".#### #.... #.... .###. ....# ....# ####. ..... .....",  // S
    "##### ..#.. ..#.. ..#.. ..#.. ..#.. ..#.. ..... .....",  // T
    "#...# #...# #...# #...# #...# #...# .###. ..... .....",  // U
    "#...# #...# #...# #...# #...# .#.#. ..#.. ..... .....",  // V
    "#...# #...# #...# #.#.# #.#.# #.#.# .#.#. ..... .....",  // W
    "#...# #...# .#.#. ..#.. .#.#. #...# #...# ..... .....",  // X
    "#...# #...# .#.#. ..#.. ..#.. ..#.. ..#.. ..... .....",  // Y
    "##### ....# ...#. ..#.. .#... #.... ##### ..... .....",  // Z
    ".###. .#... .#... .#... .#... .#... .###. ..... .....",  // [
    "#.... #.... .#... ..#.. ...#. ....# ....# ..... .....",  // backslash
    ".###. ...#. ...#. ...#. ...#. ...#. .###. ..... .....",  // ]
    "..#.. .#.#. #...# ..... ..... ..... ..... ..... .....",  // ^
    "..... ..... ..... ..... ..... ..... ..... ##### .....",  // _
    ".#... ..#.. ..... ..... ..... ..... ..... ..... .....",  // `
    "..... ..... .###. ....# .#### #...# .#### ..... .....",  // a
    "#.... #.... #.##. ##..# #...# #...# ####. ..... .....",  // b
    "..... ..... .###. #.... #.... #...# .###. ..... .....",  // c
    "....# ....# .##.# #..## #...# #...# .#### ..... .....",  // d
    "..... ..... .###. #...# ##### #.... .###. ..... .....",  // e
    "..##. .#..# .#... ###.. .#... .#... .#... ..... .....",  // f
    "..... ..... .#### #...# #...# #...# .#### ....# .###.",  // g
    "#.... #.... #.##. ##..# #...# #...# #...# ..... .....",  // h
    "..#.. ..... .##.. ..#.. ..#.. ..#.. .###. ..... .....",  // i
    "...#. ..... ..##. ...#. ...#. ...#. ...#. #..#. .##..",  // j
    "#.... #.... #..#. #.#.. ##... #.#.. #..#. ..... .....",  // k
    ".##.. ..#.. ..#.. ..#.. ..#.. ..#.. .###. ..... .....",  // l
    "..... ..... ##.#. #.#.# #.#.# #.#.# #.#.# ..... .....",  // m
    "..... ..... #.##. ##..# #...# #...# #...# ..... .....",  // n
    "..... ..... .###. #...# #...# #...# .###. ..... .....",  // o
    "..... ..... ####. #...# #...# #...# ####. #.... #....",  // p
    "..... ..... .#### #...# #...# #...# .#### ....# ....#",  // q
    "..... ..... #.##. ##..# #.... #.... #.... ..... .....",  // r
    "..... ..... .#### #.... .###. ....# ####. ..... .....",  // s
    ".#... .#... ###.. .#... .#... .#..# ..##. ..... .....",  // t
    "..... ..... #...# #...# #...# #..## .##.# ..... .....",  // u
    "..... ..... #...# #...# #...# .#.#. ..#.. ..... .....",  // v
    "..... ..... #...# #...# #.#.# #.#.# .#.#. ..... .....",  // w
    "..... ..... #...# .#.#. ..#.. .#.#. #...# ..... .....",  // x
    "..... ..... #...# #...# #...# #...# .#### ....# .###.",  // y
    "..... ..... ##### ...#. ..#.. .#... ##### ..... .....",  // z
    "...#. ..#.. ..#.. .#... ..#.. ..#.. ...#. ..... .....",  // {
    "..#.. ..#.. ..#.. ..#.. ..#.. ..#.. ..#.. ..#.. .....",  // |
    ".#... ..#.. ..#.. ...#. ..#.. ..#.. .#... ..... .....",  // }
    "..... ..... .#... #.#.# ...#. ..... ..... ..... .....",  // ~
};

constexpr bool font_is_well_formed() {
  for (std::string_view glyph : kFont) {
    if (glyph.size() != kGlyphRows * (kGlyphCols + 1) - 1) return false;
    for (std::size_t i = 0; i < glyph.size(); ++i) {
      const bool separator = i % (kGlyphCols + 1) == kGlyphCols;
      if (separator ? glyph[i] != ' ' : (glyph[i] != '.' && glyph[i] != '#')) return false;
    }
  }
  return true;
}
static_assert(font_is_well_formed(), "every glyph is 9 rows of 5 '.'/'#' separated by spaces");

bool glyph_pixel(int glyph, int row, int col) {
  return kFont[static_cast<std::size_t>(glyph)][static_cast<std::size_t>(row * (kGlyphCols + 1) + col)] == '#';
}

// Glyph indices of a string: printable ASCII as is, '?' for control characters and for each
// UTF-8 sequence (its continuation bytes are dropped).
std::vector<int> glyphs_of(std::string_view text) {
  std::vector<int> glyphs;
  glyphs.reserve(text.size());
  for (const char ch : text) {
    const auto byte = static_cast<unsigned char>(ch);
    if ((byte & 0xC0) == 0x80) continue;
    glyphs.push_back(byte >= 32 && byte <= 126 ? byte - 32 : '?' - 32);
  }
  return glyphs;
}

int text_width(std::string_view text, int scale) {
  const int n = static_cast<int>(glyphs_of(text).size());
  return n == 0 ? 0 : (n * kCellWidth - 1) * scale;
}

// ---------------------------------------------------------------------------------------
// Canvas and drawing.

class Canvas {
 public:
  Canvas(int width, int height)
      : width_(width), height_(height), rgb_(static_cast<std::size_t>(width) * height * 3, 255) {}

  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<std::uint8_t>& rgb() const { return rgb_; }

  // Mixes `colour` into pixel (x, y) with opacity `alpha` in [0, 1]; outside pixels ignored.
  void blend(int x, int y, Rgb colour, double alpha) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_ || alpha <= 0) return;
    std::uint8_t* p = &rgb_[(static_cast<std::size_t>(y) * width_ + x) * 3];
    if (alpha >= 1) {
      p[0] = colour[0], p[1] = colour[1], p[2] = colour[2];
      return;
    }
    for (int c = 0; c < 3; ++c) p[c] = static_cast<std::uint8_t>(std::lround(p[c] + alpha * (colour[c] - p[c])));
  }

  // Pixels x0 <= x <= x1, y0 <= y <= y1 (bounds in either order).
  void fill(int x0, int y0, int x1, int y1, Rgb colour, double alpha = 1) {
    if (x0 > x1) std::swap(x0, x1);
    if (y0 > y1) std::swap(y0, y1);
    for (int y = std::max(y0, 0); y <= std::min(y1, height_ - 1); ++y)
      for (int x = std::max(x0, 0); x <= std::min(x1, width_ - 1); ++x) blend(x, y, colour, alpha);
  }

 private:
  int width_, height_;
  std::vector<std::uint8_t> rgb_;
};

struct Rect {
  int x0, y0, x1, y1;  // inclusive pixel bounds
  bool contains(int x, int y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

// Draws `text` with its top-left corner at (x, y), each font pixel a scale x scale block.
// Vertical text reads bottom to top (rotated a quarter turn counter-clockwise): (x, y) is
// then its bottom-left corner, and the tops of the letters face left.
void draw_text(Canvas& canvas, int x, int y, std::string_view text, int scale, Rgb colour,
               bool vertical = false) {
  const std::vector<int> glyphs = glyphs_of(text);
  for (std::size_t i = 0; i < glyphs.size(); ++i) {
    for (int row = 0; row < kGlyphRows; ++row) {
      for (int col = 0; col < kGlyphCols; ++col) {
        if (!glyph_pixel(glyphs[i], row, col)) continue;
        const int along = (static_cast<int>(i) * kCellWidth + col) * scale;
        const int across = row * scale;
        if (vertical)
          canvas.fill(x + across, y - along - scale, x + across + scale - 1, y - along - 1, colour);
        else
          canvas.fill(x + along, y + across, x + along + scale - 1, y + across + scale - 1, colour);
      }
    }
  }
}

enum class Align { left, centre, right };

void draw_text_aligned(Canvas& canvas, int x, int y, std::string_view text, int scale, Rgb colour, Align align) {
  const int w = text_width(text, scale);
  const int left = align == Align::left ? x : align == Align::centre ? x - w / 2 : x - w;
  draw_text(canvas, left, y, text, scale, colour);
}

// Anti-aliased shapes are first rendered as per-pixel coverage (the maximum over all the
// shapes of one series, so overlapping segments and joints are not darkened twice), then
// mixed into the canvas in one colour.
class Coverage {
 public:
  Coverage(int width, int height, Rect clip)
      : width_(width), clip_(clip), value_(static_cast<std::size_t>(width) * height, 0.0f) {}

  const Rect& clip() const { return clip_; }
  float at(int x, int y) const { return value_[static_cast<std::size_t>(y) * width_ + x]; }

  void cover(int x, int y, double amount) {
    if (!clip_.contains(x, y)) return;
    float& v = value_[static_cast<std::size_t>(y) * width_ + x];
    v = std::max(v, static_cast<float>(std::min(amount, 1.0)));
  }

  // A disc of radius r centred at (cx, cy); pixel centres are at integer + 0.5.
  void disc(double cx, double cy, double r) {
    for (int y = static_cast<int>(std::floor(cy - r - 1)); y <= static_cast<int>(std::floor(cy + r + 1)); ++y)
      for (int x = static_cast<int>(std::floor(cx - r - 1)); x <= static_cast<int>(std::floor(cx + r + 1)); ++x)
        cover(x, y, r + 0.5 - std::hypot(x + 0.5 - cx, y + 0.5 - cy));
  }

  // A stroke of half width hw from a to b with round ends.
  void segment(double ax, double ay, double bx, double by, double hw) {
    const double reach = hw + 1.5;
    if (!clip_segment(ax, ay, bx, by, reach)) return;
    const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    auto cover_pixel = [&](int x, int y) {
      const double cx = x + 0.5, cy = y + 0.5;
      const double t = len2 > 0 ? std::clamp(((cx - ax) * dx + (cy - ay) * dy) / len2, 0.0, 1.0) : 0.0;
      cover(x, y, hw + 0.5 - std::hypot(ax + t * dx - cx, ay + t * dy - cy));
    };
    // Walk the long direction one pixel at a time; across it the stroke spans at most
    // hw * sqrt(2) plus half a pixel of slope on each side of the centre line.
    const bool steep = std::abs(dy) > std::abs(dx);
    const double a_major = steep ? ay : ax, b_major = steep ? by : bx;
    const double a_minor = steep ? ax : ay, d_major = steep ? dy : dx, d_minor = steep ? dx : dy;
    const int m0 = static_cast<int>(std::floor(std::min(a_major, b_major) - reach));
    const int m1 = static_cast<int>(std::floor(std::max(a_major, b_major) + reach));
    const double half_span = hw * 1.5 + 2;
    for (int m = m0; m <= m1; ++m) {
      const double t = d_major != 0 ? std::clamp((m + 0.5 - a_major) / d_major, 0.0, 1.0) : 0.0;
      const double centre = a_minor + t * d_minor;
      for (int n = static_cast<int>(std::floor(centre - half_span)); n <= static_cast<int>(std::floor(centre + half_span));
           ++n)
        steep ? cover_pixel(n, m) : cover_pixel(m, n);
    }
  }

  // Mixes the covered pixels into `canvas` in `colour`; marks them in `occupied` if given.
  void paint(Canvas& canvas, Rgb colour, std::vector<std::uint8_t>* occupied = nullptr) const {
    for (int y = clip_.y0; y <= clip_.y1; ++y) {
      for (int x = clip_.x0; x <= clip_.x1; ++x) {
        const float a = at(x, y);
        if (a <= 0) continue;
        canvas.blend(x, y, colour, a);
        if (occupied != nullptr) (*occupied)[static_cast<std::size_t>(y) * width_ + x] = 1;
      }
    }
  }

 private:
  // Liang-Barsky: cuts the segment to the clip rectangle grown by `margin`, so that huge
  // coordinates never turn into long pixel walks. False if nothing is left.
  bool clip_segment(double& ax, double& ay, double& bx, double& by, double margin) const {
    const double xmin = clip_.x0 - margin, xmax = clip_.x1 + 1 + margin;
    const double ymin = clip_.y0 - margin, ymax = clip_.y1 + 1 + margin;
    const double dx = bx - ax, dy = by - ay;
    double t0 = 0, t1 = 1;
    const double p[4] = {-dx, dx, -dy, dy};
    const double q[4] = {ax - xmin, xmax - ax, ay - ymin, ymax - ay};
    for (int i = 0; i < 4; ++i) {
      if (p[i] == 0) {
        if (q[i] < 0) return false;
        continue;
      }
      const double r = q[i] / p[i];
      if (p[i] < 0) t0 = std::max(t0, r);
      else t1 = std::min(t1, r);
      if (t0 > t1) return false;
    }
    const double x0 = ax + t0 * dx, y0 = ay + t0 * dy;
    bx = ax + t1 * dx, by = ay + t1 * dy;
    ax = x0, ay = y0;
    return true;
  }

  int width_;
  Rect clip_;
  std::vector<float> value_;
};

// ---------------------------------------------------------------------------------------
// Axes.

constexpr double kTickEps = 1e-9;

// Steps 1, 2, 5, 10, 20, ... x 10^k starting from the largest one not above `minimum`.
class StepSequence {
 public:
  explicit StepSequence(double minimum) : magnitude_(std::pow(10.0, std::floor(std::log10(minimum)))) {}
  double next() {
    static constexpr double mantissas[3] = {1, 2, 5};
    const double step = mantissas[index_] * magnitude_;
    if (++index_ == 3) index_ = 0, magnitude_ *= 10;
    return step;
  }

 private:
  double magnitude_;
  int index_ = 0;
};

struct Axis {
  bool log = false;
  double lo = 0, hi = 1;  // data range covered (lo < hi; > 0 on a log axis)
  std::vector<double> major, minor;
  std::vector<std::string> labels;  // one per major tick
  double p_lo = 0, p_hi = 1;        // pixel coordinates of lo and hi

  // Beyond 1e300 (below 1e-300 on a log axis) range arithmetic could overflow or
  // underflow: such values are skipped like NaN.
  bool usable(double v) const { return std::abs(v) <= 1e300 && (!log || v >= 1e-300); }
  double map(double v) const {
    const double t = log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo);
    return p_lo + t * (p_hi - p_lo);
  }
  int max_label_width(int scale) const {
    int w = 0;
    for (const std::string& label : labels) w = std::max(w, text_width(label, scale));
    return w;
  }
};

std::string format_linear_tick(double v, double step) {
  char buffer[64];
  if (std::abs(v) < step * kTickEps) return "0";
  const double biggest = std::max(std::abs(v), step);
  if (biggest >= 1e5 || biggest < 1e-4) {
    // Scientific, with as many mantissa digits as the step needs: "2.5e-5", "3e6".
    const int digits = std::clamp(static_cast<int>(std::floor(std::log10(std::abs(v)) + kTickEps) -
                                                   std::floor(std::log10(step) + kTickEps)),
                                  0, 12);
    std::snprintf(buffer, sizeof buffer, "%.*e", digits, v);
    char* e = std::strchr(buffer, 'e');  // "-2.50e-05" -> "-2.5e-5", "1.0e+06" -> "1e6"
    const int exponent = std::atoi(e + 1);
    *e = '\0';
    if (std::strchr(buffer, '.') != nullptr) {
      while (e[-1] == '0') *--e = '\0';
      if (e[-1] == '.') e[-1] = '\0';
    }
    char text[80];
    std::snprintf(text, sizeof text, "%se%d", buffer, exponent);
    return text;
  }
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + kTickEps)));
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

// Ticks at whole steps covering [dmin, dmax]; the axis ends on the first and last tick.
// At least 3 ticks are allowed: a range across zero may need -step, 0 and step.
Axis make_linear_axis(double dmin, double dmax, int max_ticks) {
  Axis axis;
  max_ticks = std::max(max_ticks, 3);
  if (!(dmin <= dmax)) dmin = 0, dmax = 1;  // no data
  const double magnitude = std::max(std::abs(dmin), std::abs(dmax));
  if (dmax - dmin <= 1e-9 * magnitude || dmax - dmin < std::numeric_limits<double>::min()) {
    const double pad = magnitude > 0 ? 0.1 * magnitude : 1.0;
    dmin -= pad, dmax += pad;
  }
  StepSequence steps((dmax - dmin) / std::max(max_ticks - 1, 1));
  double step = steps.next();
  long long k0 = 0, k1 = 0;
  for (;;) {
    k0 = static_cast<long long>(std::floor(dmin / step + kTickEps));
    k1 = static_cast<long long>(std::ceil(dmax / step - kTickEps));
    if (k1 - k0 + 1 <= max_ticks) break;
    step = steps.next();
  }
  axis.lo = static_cast<double>(k0) * step;
  axis.hi = static_cast<double>(k1) * step;
  for (long long k = k0; k <= k1; ++k) {
    axis.major.push_back(static_cast<double>(k) * step);
    axis.labels.push_back(format_linear_tick(axis.major.back(), step));
  }
  return axis;
}

// Decade stride 1, 2, 3, 5, 10, 20, 30, 50, ...
int decade_stride(int index) {
  static constexpr int base[4] = {1, 2, 3, 5};
  int stride = base[index % 4];
  for (int i = 0; i < index / 4; ++i) stride *= 10;
  return stride;
}

int floor_multiple(int v, int m) { return (v >= 0 ? v / m : -((-v + m - 1) / m)) * m; }
int ceil_multiple(int v, int m) { return -floor_multiple(-v, m); }

Axis make_log_axis(double dmin, double dmax, int max_ticks) {
  Axis axis;
  axis.log = true;
  if (!(dmin <= dmax)) dmin = 1, dmax = 10;
  int e0 = static_cast<int>(std::floor(std::log10(dmin) + kTickEps));
  int e1 = static_cast<int>(std::ceil(std::log10(dmax) - kTickEps));
  if (e1 <= e0) --e0, ++e1;
  int stride = 1;
  for (int i = 0;; ++i) {
    stride = decade_stride(i);
    if ((ceil_multiple(e1, stride) - floor_multiple(e0, stride)) / stride + 1 <= max_ticks) break;
  }
  // Whole strides, but within 1e-300 ... 1e300 where the data are.
  e0 = std::max(floor_multiple(e0, stride), -300), e1 = std::min(ceil_multiple(e1, stride), 300);
  axis.lo = std::pow(10.0, e0);
  axis.hi = std::pow(10.0, e1);
  const bool plain = e0 >= -3 && e1 <= 4;  // 0.001 ... 10000 as decimals, else 1e-4 style
  for (int e = ceil_multiple(e0, stride); e <= e1; e += stride) {
    axis.major.push_back(std::pow(10.0, e));
    char buffer[32];
    if (plain) std::snprintf(buffer, sizeof buffer, "%.*f", std::max(0, -e), axis.major.back());
    else std::snprintf(buffer, sizeof buffer, "1e%d", e);
    axis.labels.emplace_back(buffer);
  }
  if (stride == 1 && e1 - e0 <= 8) {
    for (int e = e0; e < e1; ++e)
      for (int m = 2; m <= 9; ++m) axis.minor.push_back(m * std::pow(10.0, e));
  } else if (stride > 1 && (e1 - e0) / stride <= 40) {
    for (int e = e0; e < e1; ++e)
      if (e % stride != 0) axis.minor.push_back(std::pow(10.0, e));
  }
  return axis;
}

Axis make_axis(double dmin, double dmax, bool log, int max_ticks) {
  return log ? make_log_axis(dmin, dmax, max_ticks) : make_linear_axis(dmin, dmax, max_ticks);
}

// ---------------------------------------------------------------------------------------
// PNG encoding: 8-bit RGB, filter 0 on every row, one zlib stream.

std::uint32_t crc32_update(std::uint32_t crc, const std::uint8_t* data, std::size_t size) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

void put_u32(std::string& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<char>((v >> shift) & 0xFF));
}

void put_chunk(std::string& out, const char type[4], const std::string& data) {
  put_u32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.append(type, 4);
  out += data;
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(out.data()) + start;
  put_u32(out, crc32_update(0, bytes, out.size() - start));
}

std::string encode_png(const Canvas& canvas) {
  const int w = canvas.width(), h = canvas.height();
  const std::size_t row_bytes = static_cast<std::size_t>(w) * 3;
  std::string raw;  // scanlines, each led by its filter type (0: none)
  raw.reserve(h * (row_bytes + 1));
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);
    raw.append(reinterpret_cast<const char*>(canvas.rgb().data()) + y * row_bytes, row_bytes);
  }

  // zlib (deflate, default level): plots are mostly flat colour, so they shrink ~50-fold.
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string zlib(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(zlib.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                static_cast<uLong>(raw.size()), Z_DEFAULT_COMPRESSION) != Z_OK)
    throw arlequin::RunError("PNG encoding: zlib could not compress the image");
  zlib.resize(size);

  std::string header;
  put_u32(header, static_cast<std::uint32_t>(w));
  put_u32(header, static_cast<std::uint32_t>(h));
  header += std::string{'\x08', '\x02', '\x00', '\x00', '\x00'};  // 8 bit RGB, deflate, no interlace

  std::string png = "\x89PNG\r\n\x1a\n";
  put_chunk(png, "IHDR", header);
  put_chunk(png, "IDAT", zlib);
  put_chunk(png, "IEND", std::string());
  return png;
}

// ---------------------------------------------------------------------------------------
// Plot layout and drawing.

constexpr Rgb kInk{25, 25, 25};
constexpr Rgb kFrame{70, 70, 70};
constexpr Rgb kGrid{226, 226, 226};
constexpr Rgb kMinorGrid{242, 242, 242};
constexpr Rgb kLegendBorder{170, 170, 170};
constexpr Rgb kWhite{255, 255, 255};

constexpr int kTickLength = 5;
constexpr int kMinorTickLength = 3;
constexpr int kInset = 8;  // pixels between the frame and the ends of the axis ranges
constexpr double kLineHalfWidth = 1.1;
constexpr double kPointRadius = 3.2;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
};

bool draws_lines(PlotSeries::Style s) { return s != PlotSeries::Style::points; }
bool draws_points(PlotSeries::Style s) { return s != PlotSeries::Style::line; }

}  // namespace

std::array<std::uint8_t, 3> plot_series_colour(std::size_t index) {
  static constexpr std::array<Rgb, 10> palette = {{
      {0, 94, 184},    // blue
      {232, 112, 0},   // orange
      {24, 150, 64},   // green
      {204, 32, 44},   // red
      {124, 72, 180},  // purple
      {0, 160, 176},   // teal
      {146, 90, 44},   // brown
      {222, 64, 160},  // magenta
      {96, 96, 96},    // grey
      {160, 156, 0},   // olive
  }};
  return palette[index % palette.size()];
}

std::vector<double> nice_ticks(double lo, double hi, int max_ticks) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {};
  if (lo > hi) std::swap(lo, hi);
  if (lo == hi) return {lo};
  max_ticks = std::max(max_ticks, 2);
  const double span = hi - lo;
  if (!std::isfinite(span) || span < 1e-12 * std::max(std::abs(lo), std::abs(hi)) ||
      span / max_ticks < std::numeric_limits<double>::min())
    return {};
  StepSequence steps(span / max_ticks);
  for (;;) {
    const double step = steps.next();
    if (!std::isfinite(step)) return {};
    const auto k0 = static_cast<long long>(std::ceil(lo / step - kTickEps));
    const auto k1 = static_cast<long long>(std::floor(hi / step + kTickEps));
    if (k1 - k0 + 1 > max_ticks) continue;
    std::vector<double> ticks;
    for (long long k = k0; k <= k1; ++k) ticks.push_back(static_cast<double>(k) * step);
    return ticks;
  }
}

std::vector<double> log_ticks(double lo, double hi, int max_ticks) {
  if (!(lo > 0) || !(hi > 0) || !std::isfinite(lo) || !std::isfinite(hi)) return {};
  if (lo > hi) std::swap(lo, hi);
  max_ticks = std::max(max_ticks, 2);
  const int e0 = static_cast<int>(std::ceil(std::log10(lo) - kTickEps));
  const int e1 = static_cast<int>(std::floor(std::log10(hi) + kTickEps));
  std::vector<double> ticks;
  for (int i = 0;; ++i) {
    const int stride = decade_stride(i);
    const int first = ceil_multiple(e0, stride), last = floor_multiple(e1, stride);
    if (last >= first && (last - first) / stride + 1 > max_ticks) continue;
    for (int e = first; e <= last; e += stride) ticks.push_back(std::pow(10.0, e));
    return ticks;
  }
}

void write_png_plot(const std::filesystem::path& path, const PlotSpec& spec) {
  const int W = spec.width, H = spec.height;
  if (W < 200 || H < 200 || W > 8000 || H > 8000)
    throw std::invalid_argument("plot '" + path.string() + "': size " + std::to_string(W) + "x" +
                                std::to_string(H) + " outside 200..8000 pixels");
  for (const PlotSeries& s : spec.series)
    if (s.x.size() != s.y.size())
      throw std::invalid_argument("plot '" + path.string() + "': series '" + s.label + "' has " +
                                  std::to_string(s.x.size()) + " x and " + std::to_string(s.y.size()) +
                                  " y values");

  const int scale = std::max(1, std::min(W, H) / 480);  // tick labels, legend, axis labels
  const int title_scale = 2 * scale;
  const int cap = kCapHeight * scale;
  const double line_hw = kLineHalfWidth * scale, point_r = kPointRadius * scale;
  const bool has_y2 = std::any_of(spec.series.begin(), spec.series.end(), [](const PlotSeries& s) { return s.right_axis; });
  const bool has_y1 = std::any_of(spec.series.begin(), spec.series.end(), [](const PlotSeries& s) { return !s.right_axis; });

  // Data ranges: only points drawable on both of their axes count.
  Axis probe_x, probe_y1, probe_y2;
  probe_x.log = spec.log_x, probe_y1.log = spec.log_y, probe_y2.log = spec.log_y2;
  Range rx, ry1, ry2;
  for (const PlotSeries& s : spec.series) {
    const Axis& probe_y = s.right_axis ? probe_y2 : probe_y1;
    Range& ry = s.right_axis ? ry2 : ry1;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!probe_x.usable(s.x[i]) || !probe_y.usable(s.y[i])) continue;
      rx.add(s.x[i]);
      ry.add(s.y[i]);
    }
  }

  // Vertical layout first: it fixes the y ticks, whose labels set the side margins.
  const int top = 12 + (spec.title.empty() ? cap / 2 : kGlyphRows * title_scale + 10);
  const int bottom_margin = kTickLength + 5 + cap + 12 + (spec.x_label.empty() ? 0 : kGlyphRows * scale + 8);
  const int plot_h = H - top - bottom_margin;
  const int max_y_ticks = std::clamp(plot_h / (cap * 5), 3, 11);
  Axis y1 = make_axis(ry1.lo, ry1.hi, spec.log_y, max_y_ticks);
  Axis y2 = make_axis(ry2.lo, ry2.hi, spec.log_y2, max_y_ticks);

  const int label_band = kGlyphRows * scale + 10;  // room for a vertical axis label
  const int left = 10 + (spec.y_label.empty() ? 0 : label_band) + y1.max_label_width(scale) + 5 + kTickLength;
  const int right_margin = has_y2 ? 10 + (spec.y2_label.empty() ? 0 : label_band) + y2.max_label_width(scale) + 5 + kTickLength
                                  : 24;
  const Rect frame{left, top, W - 1 - right_margin, H - 1 - bottom_margin};
  if (frame.x1 - frame.x0 < 4 * kInset || frame.y1 - frame.y0 < 4 * kInset)
    throw std::invalid_argument("plot '" + path.string() + "': labels leave no room for the plot");

  // As many x ticks as fit without their labels running into each other.
  Axis x;
  for (int n = 11; n >= 3; --n) {
    x = make_axis(rx.lo, rx.hi, spec.log_x, n);
    const double spacing = static_cast<double>(frame.x1 - frame.x0 - 2 * kInset) / std::max<std::size_t>(x.major.size() - 1, 1);
    if (spacing >= x.max_label_width(scale) + 4 * scale * kCellWidth / 2) break;
  }
  x.p_lo = frame.x0 + kInset + 0.5, x.p_hi = frame.x1 - kInset + 0.5;
  for (Axis* y : {&y1, &y2}) y->p_lo = frame.y1 - kInset + 0.5, y->p_hi = frame.y0 + kInset + 0.5;

  Canvas canvas(W, H);
  const Rect inside{frame.x0 + 1, frame.y0 + 1, frame.x1 - 1, frame.y1 - 1};
  auto column = [](double p) { return static_cast<int>(std::floor(p)); };

  // Grid: x ticks, and the ticks of the left axis (of the right one if it is alone).
  const Axis& grid_y = has_y2 && !has_y1 ? y2 : y1;
  for (double v : x.minor) canvas.fill(column(x.map(v)), inside.y0, column(x.map(v)), inside.y1, kMinorGrid);
  for (double v : grid_y.minor) canvas.fill(inside.x0, column(grid_y.map(v)), inside.x1, column(grid_y.map(v)), kMinorGrid);
  for (double v : x.major) canvas.fill(column(x.map(v)), inside.y0, column(x.map(v)), inside.y1, kGrid);
  for (double v : grid_y.major) canvas.fill(inside.x0, column(grid_y.map(v)), inside.x1, column(grid_y.map(v)), kGrid);

  // Series, each in its palette colour; gaps in the data break the line.
  std::vector<std::uint8_t> occupied(static_cast<std::size_t>(W) * H, 0);
  for (std::size_t si = 0; si < spec.series.size(); ++si) {
    const PlotSeries& s = spec.series[si];
    const Axis& y = s.right_axis ? y2 : y1;
    Coverage cov(W, H, inside);
    const std::size_t n = s.x.size();
    auto ok = [&](std::size_t i) { return x.usable(s.x[i]) && y.usable(s.y[i]); };
    for (std::size_t i = 0; i < n; ++i) {
      if (!ok(i)) continue;
      const double px = x.map(s.x[i]), py = y.map(s.y[i]);
      const bool next = i + 1 < n && ok(i + 1);
      const bool prev = i > 0 && ok(i - 1);
      if (draws_lines(s.style) && next) cov.segment(px, py, x.map(s.x[i + 1]), y.map(s.y[i + 1]), line_hw);
      if (draws_points(s.style)) cov.disc(px, py, point_r);
      else if (!next && !prev) cov.disc(px, py, 0.75 * point_r);  // a lone point of a line
    }
    cov.paint(canvas, plot_series_colour(si), &occupied);
  }

  // Frame, ticks and tick labels.
  canvas.fill(frame.x0, frame.y0, frame.x1, frame.y0, kFrame);
  canvas.fill(frame.x0, frame.y1, frame.x1, frame.y1, kFrame);
  canvas.fill(frame.x0, frame.y0, frame.x0, frame.y1, kFrame);
  canvas.fill(frame.x1, frame.y0, frame.x1, frame.y1, kFrame);
  for (double v : x.minor) canvas.fill(column(x.map(v)), frame.y1 + 1, column(x.map(v)), frame.y1 + kMinorTickLength, kFrame);
  for (std::size_t i = 0; i < x.major.size(); ++i) {
    const int px = column(x.map(x.major[i]));
    canvas.fill(px, frame.y1 + 1, px, frame.y1 + kTickLength, kFrame);
    draw_text_aligned(canvas, px, frame.y1 + kTickLength + 5, x.labels[i], scale, kInk, Align::centre);
  }
  auto y_ticks = [&](const Axis& y, bool on_right) {
    const int edge = on_right ? frame.x1 : frame.x0;
    const int dir = on_right ? 1 : -1;
    for (double v : y.minor) canvas.fill(edge + dir, column(y.map(v)), edge + dir * kMinorTickLength, column(y.map(v)), kFrame);
    for (std::size_t i = 0; i < y.major.size(); ++i) {
      const int py = column(y.map(y.major[i]));
      canvas.fill(edge + dir, py, edge + dir * kTickLength, py, kFrame);
      draw_text_aligned(canvas, edge + dir * (kTickLength + 5), py - cap / 2, y.labels[i], scale, kInk,
                        on_right ? Align::left : Align::right);
    }
  };
  if (has_y1 || !has_y2) y_ticks(y1, false);
  if (has_y2) y_ticks(y2, true);

  // Title and axis labels.
  const int centre_x = (frame.x0 + frame.x1) / 2, centre_y = (frame.y0 + frame.y1) / 2;
  if (!spec.title.empty()) {
    // Smaller when too wide, then cut with "..." if still too wide.
    const int room = W - 20;
    const int title_size = text_width(spec.title, title_scale) <= room ? title_scale : scale;
    std::string title = spec.title;
    if (text_width(title, title_size) > room) {
      const auto fits = static_cast<std::size_t>(std::max(room / (kCellWidth * title_size) - 3, 0));
      const std::vector<int> glyphs = glyphs_of(title);
      title.clear();
      for (std::size_t i = 0; i < std::min(fits, glyphs.size()); ++i) title.push_back(static_cast<char>(glyphs[i] + 32));
      title += "...";
    }
    draw_text_aligned(canvas, W / 2, 10 + (title_scale - title_size) * kCapHeight / 2, title, title_size, kInk, Align::centre);
  }
  if (!spec.x_label.empty())
    draw_text_aligned(canvas, centre_x, frame.y1 + kTickLength + 5 + cap + 12, spec.x_label, scale, kInk, Align::centre);
  if (!spec.y_label.empty())
    draw_text(canvas, 10, centre_y + text_width(spec.y_label, scale) / 2, spec.y_label, scale, kInk, true);
  if (!spec.y2_label.empty() && has_y2)
    draw_text(canvas, W - 10 - kGlyphRows * scale, centre_y + text_width(spec.y2_label, scale) / 2, spec.y2_label,
              scale, kInk, true);

  // Legend, in the corner of the plot where it hides the fewest drawn data pixels.
  std::vector<std::pair<std::size_t, std::string>> entries;
  for (std::size_t si = 0; si < spec.series.size(); ++si) {
    const PlotSeries& s = spec.series[si];
    if (s.label.empty()) continue;
    entries.emplace_back(si, s.right_axis && has_y1 ? s.label + " (right)" : s.label);
  }
  if (!entries.empty()) {
    const int pad = 6 * scale, sample = 24 * scale, row_h = std::max(11 * scale, static_cast<int>(2 * point_r) + 4);
    int text_w = 0;
    for (const auto& entry : entries) text_w = std::max(text_w, text_width(entry.second, scale));
    const int box_w = pad + sample + pad + text_w + pad;
    const int box_h = pad * 2 + static_cast<int>(entries.size()) * row_h - (row_h - cap);
    const int gap = kInset + 2;
    const int xs[3] = {inside.x1 - gap - box_w + 1, inside.x0 + gap, (inside.x0 + inside.x1 - box_w) / 2};
    const int ys[2] = {inside.y0 + gap, inside.y1 - gap - box_h + 1};
    const std::pair<int, int> candidates[6] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 0}, {2, 1}};
    Rect box{xs[0], ys[0], xs[0] + box_w - 1, ys[0] + box_h - 1};
    long best = std::numeric_limits<long>::max();
    for (const auto& [cx, cy] : candidates) {
      const Rect r{xs[cx], ys[cy], xs[cx] + box_w - 1, ys[cy] + box_h - 1};
      long hidden = 0;
      for (int yy = std::max(r.y0, 0); yy <= std::min(r.y1, H - 1); ++yy)
        for (int xx = std::max(r.x0, 0); xx <= std::min(r.x1, W - 1); ++xx)
          hidden += occupied[static_cast<std::size_t>(yy) * W + xx];
      if (hidden < best) best = hidden, box = r;
    }
    canvas.fill(box.x0, box.y0, box.x1, box.y1, kWhite, 0.88);
    canvas.fill(box.x0, box.y0, box.x1, box.y0, kLegendBorder);
    canvas.fill(box.x0, box.y1, box.x1, box.y1, kLegendBorder);
    canvas.fill(box.x0, box.y0, box.x0, box.y1, kLegendBorder);
    canvas.fill(box.x1, box.y0, box.x1, box.y1, kLegendBorder);
    for (std::size_t k = 0; k < entries.size(); ++k) {
      const PlotSeries& s = spec.series[entries[k].first];
      const int text_top = box.y0 + pad + static_cast<int>(k) * row_h;
      const double mid_y = text_top + cap / 2.0;
      const double x0 = box.x0 + pad, x1 = x0 + sample;
      Coverage cov(W, H, box);
      if (draws_lines(s.style)) cov.segment(x0 + 1, mid_y, x1 - 1, mid_y, line_hw);
      if (draws_points(s.style)) cov.disc((x0 + x1) / 2, mid_y, point_r);
      cov.paint(canvas, plot_series_colour(entries[k].first));
      draw_text(canvas, static_cast<int>(x1) + pad, text_top, entries[k].second, scale, kInk);
    }
  }

  write_file_atomically(path, encode_png(canvas));
}

}  // namespace arlequin
