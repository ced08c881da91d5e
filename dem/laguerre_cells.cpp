// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/laguerre_cells.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>

#include "common/convex_polyhedron.hpp"
#include "common/error.hpp"
#include "common/parallel.hpp"
#include "dem/neighbour_list.hpp"

namespace arlequin::dem {

namespace {

// The spheres no larger than `large` by bin of a uniform grid of bins `size` wide over the box
// [lo, hi]; a centre outside the box counts in the nearest bin.
struct SphereGrid {
  Vec3 lo;
  double size;
  int dims[3];
  std::vector<std::vector<std::size_t>> bins;

  SphereGrid(const Vec3& lo_, const Vec3& hi, double size_, const std::vector<Vec3>& c, const std::vector<double>& r, double large)
      : lo(lo_), size(size_) {
    for (int k = 0; k < 3; ++k) dims[k] = std::max(1, static_cast<int>(std::ceil((hi[k] - lo[k]) / size)));
    bins.resize(static_cast<std::size_t>(dims[0]) * dims[1] * dims[2]);
    for (std::size_t i = 0; i < c.size(); ++i)
      if (r[i] <= large) bins[index(coordinate(c[i], 0), coordinate(c[i], 1), coordinate(c[i], 2))].push_back(i);
  }
  int coordinate(const Vec3& x, int k) const { return std::clamp(static_cast<int>((x[k] - lo[k]) / size), 0, dims[k] - 1); }
  std::size_t index(int x, int y, int z) const { return (static_cast<std::size_t>(z) * dims[1] + y) * dims[0] + x; }
  const std::vector<std::size_t>& bin(int x, int y, int z) const { return bins[index(x, y, z)]; }
};

// Calls on_cell(k, cell) with the Laguerre cell of sphere cells[k], each face tagged with the
// neighbour whose radical plane made it (-1: the box).
template <class OnCell>
void for_each_cell(const std::vector<Vec3>& c, const std::vector<double>& r, const std::vector<std::uint32_t>& cells,
                   const Box* within, OnCell&& on_cell) {
  const std::size_t n = c.size();
  if (n == 0) return;
  Vec3 lo = c[0], hi = c[0];
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], c[i][k] - r[i]), hi[k] = std::max(hi[k], c[i][k] + r[i]);
  const double tol = 1e-12 * norm(hi - lo);
  // A bound on the relative round-off of a plane's test of a vertex (a dot product and the
  // offset, a few ulps): the tests that pass over planes leave this much to clip's own.
  constexpr double round_off = 1e-14;
  if (within)
    for (int k = 0; k < 3; ++k) lo[k] = std::max(lo[k], within->lower[k]), hi[k] = std::min(hi[k], within->upper[k]);
  // Spheres far larger than the median (an impactor among yarn DEs) are a neighbour of every
  // cell rather than binned: binned, they would set the bins' size to theirs.
  std::vector<double> scratch;
  const double large = NeighbourList::large_radius(r, scratch);
  std::vector<std::size_t> large_ones;
  double r_max = 0.0;  // of the binned spheres
  for (std::size_t i = 0; i < n; ++i) {
    if (r[i] > large)
      large_ones.push_back(i);
    else
      r_max = std::max(r_max, r[i]);
  }
  // Candidates from two uniform grids of the binned spheres: bins of `cell` for the spheres near
  // a cell's centre, taken nearest first, and bins four times as wide for the search farther out,
  // where a cell that faces a gap (a coupling's overlap facing the continuum's side) reaches far
  // across empty bins.
  const double cell = 2.0 * r_max;
  const SphereGrid fine(lo, hi, cell, c, r, large), coarse(lo, hi, 4.0 * cell, c, r, large);
  const int* dims = fine.dims;

  // The cells on the threads: each is built on its own, in the same order of planes on any
  // thread count (the same bits), and a cell at a gap of the packing, whose search reaches far,
  // costs a thousand times one deep inside it, so the threads take them a few at a time. An
  // exception must not leave the parallel region: the failure of the lowest k is kept and thrown
  // after it, as a serial loop would have thrown it.
  const long count = static_cast<long>(cells.size());
  long failed_at = count;
  std::exception_ptr failure;
  run_threaded_if(count > 64, [&] {
    std::vector<std::pair<double, std::size_t>> near;
    std::vector<std::size_t> large_left;
#pragma omp for schedule(dynamic, 4)
    for (long k = 0; k < count; ++k) try {
      const std::size_t i = cells[static_cast<std::size_t>(k)];
      // The distance from c_i of sphere j's radical plane (R_i^2 - R_j^2 moves it from d / 2); for a
      // binned sphere at distance D it is at least (D^2 - r_max^2) / (2 D) (R_i^2 >= 0, R_j <= r_max).
      const auto plane_distance = [&](double d2, std::size_t j) { return (d2 + r[i] * r[i] - r[j] * r[j]) / (2.0 * std::sqrt(d2)); };
      const int ci[3] = {fine.coordinate(c[i], 0), fine.coordinate(c[i], 1), fine.coordinate(c[i], 2)};
      Polyhedron poly = box_polyhedron(lo, hi, -1);
      // The cell's extent (its farthest vertex from c_i), its bounding box, and `clear`: a binned
      // sphere farther than that from c_i has its plane beyond the extent (with clip's tolerance
      // and the tests' round-off): (D^2 - r_max^2) / (2 D) > margin for D > clear.
      double margin = 0.0, clear2 = 0.0;
      Vec3 bounds_lo, bounds_hi;
      const auto measure_cell = [&] {  // of a cell not empty
        double extent = 0.0;
        bounds_lo = bounds_hi = poly.front().pts.front();
        for (const PolyFace& f : poly)
          for (const Vec3& p : f.pts) {
            extent = std::max(extent, norm(p - c[i]));
            for (int a = 0; a < 3; ++a) bounds_lo[a] = std::min(bounds_lo[a], p[a]), bounds_hi[a] = std::max(bounds_hi[a], p[a]);
          }
        margin = extent + tol + round_off * (norm(c[i]) + extent);
        const double clear = margin + std::sqrt(margin * margin + r_max * r_max);
        clear2 = clear * clear;
      };
      measure_cell();
      // Cuts the cell by sphere j's radical plane; false once the cell is empty (a small sphere's
      // cell inside its neighbours' power). A plane that cuts nothing leaves the cell as it is
      // (clip), and one clear of the cell's bounding box cuts nothing: such planes are passed over
      // without looking at the cell's vertices.
      const auto cut = [&](std::size_t j, double d2) {
        if (!(d2 > 0.0)) throw InputError("laguerre cells: spheres " + std::to_string(i) + " and " + std::to_string(j) + " share a centre");
        const Vec3 e = c[j] - c[i];
        const double d = std::sqrt(d2);
        // The radical plane, as (e/d).x <= offset.
        const Vec3 normal = e / d;
        const double offset = (norm2(c[j]) - norm2(c[i]) - r[j] * r[j] + r[i] * r[i]) / (2.0 * d);
        // Clear of the bounding box's corner farthest along the normal by more than clip's
        // tolerance less a bound on the round-off of the two dot products.
        Vec3 farthest;
        for (int a = 0; a < 3; ++a) farthest[a] = normal[a] > 0.0 ? bounds_hi[a] : bounds_lo[a];
        const double reach_of_box = dot(normal, farthest);
        if (reach_of_box - offset + round_off * (std::abs(reach_of_box) + std::abs(offset)) <= tol) return true;
        if (!clip(poly, normal, offset, static_cast<int>(j), tol)) return true;
        if (poly.empty()) return false;
        measure_cell();
        return true;
      };
      // First every sphere within two bins and every large one, nearest first (so later planes
      // rarely cut), until no plane left can cut the cell: a binned sphere at distance D >= that of
      // the nearest left is looked at through `clear`, a large one on its own.
      near.clear();
      for (int z = std::max(0, ci[2] - 2); z <= std::min(dims[2] - 1, ci[2] + 2); ++z)
        for (int y = std::max(0, ci[1] - 2); y <= std::min(dims[1] - 1, ci[1] + 2); ++y)
          for (int x = std::max(0, ci[0] - 2); x <= std::min(dims[0] - 1, ci[0] + 2); ++x)
            for (std::size_t j : fine.bin(x, y, z))
              if (j != i) near.emplace_back(norm2(c[j] - c[i]), j);
      large_left.clear();
      for (std::size_t j : large_ones)
        if (j != i) near.emplace_back(norm2(c[j] - c[i]), j), large_left.push_back(j);
      std::sort(near.begin(), near.end());
      bool empty = false;
      for (const auto& [d2, j] : near) {
        if (d2 > clear2 && std::all_of(large_left.begin(), large_left.end(),
                                       [&](std::size_t l) { return plane_distance(norm2(c[l] - c[i]), l) > margin; }))
          break;
        if (r[j] > large) large_left.erase(std::find(large_left.begin(), large_left.end(), j));
        if (!cut(j, d2)) {
          empty = true;
          break;
        }
      }
      // Then the wide bins k = 0, 1, ... bins from c_i's (a shell of that grid at a time), each
      // sphere not among the first whose plane can still reach the cell, until the bins left are
      // clear of it: a binned sphere k wide bins away is at least k - 1 of their widths from c_i,
      // and one not among the first at least two narrow bins' widths. Large spheres left were
      // clear of the cell when last looked at, and the cell has only shrunk since.
      const auto among_first = [&](std::size_t j) {
        for (int a = 0; a < 3; ++a)
          if (std::abs(fine.coordinate(c[j], a) - ci[a]) > 2) return false;
        return true;
      };
      const auto cut_by_bin = [&](int x, int y, int z) {
        for (std::size_t j : coarse.bin(x, y, z))
          if (const double d2 = norm2(c[j] - c[i]); d2 <= clear2 && !among_first(j) && !cut(j, d2)) return false;
        return true;
      };
      const int* wide = coarse.dims;
      const int cw[3] = {coarse.coordinate(c[i], 0), coarse.coordinate(c[i], 1), coarse.coordinate(c[i], 2)};
      const int last_shell = std::max({cw[0], wide[0] - 1 - cw[0], cw[1], wide[1] - 1 - cw[1], cw[2], wide[2] - 1 - cw[2]});
      const auto beyond = [&](double distance) { return distance > 0.0 && distance * distance > clear2; };
      for (int shell = 0; !empty && !beyond(2.0 * cell) && shell <= last_shell && !beyond((shell - 1) * coarse.size); ++shell)
        for (int z = std::max(0, cw[2] - shell); !empty && z <= std::min(wide[2] - 1, cw[2] + shell); ++z)
          for (int y = std::max(0, cw[1] - shell); !empty && y <= std::min(wide[1] - 1, cw[1] + shell); ++y) {
            if (std::abs(z - cw[2]) < shell && std::abs(y - cw[1]) < shell) {  // a row through the shell: its two ends
              for (const int x : {cw[0] - shell, cw[0] + shell})
                if (!empty && x >= 0 && x < wide[0]) empty = !cut_by_bin(x, y, z);
              continue;
            }
            for (int x = std::max(0, cw[0] - shell); !empty && x <= std::min(wide[0] - 1, cw[0] + shell); ++x) empty = !cut_by_bin(x, y, z);
          }
      on_cell(static_cast<std::size_t>(k), poly);
    } catch (...) {
#pragma omp critical(laguerre_failure)
      if (k < failed_at) failed_at = k, failure = std::current_exception();
    }
  });
  if (failure) std::rethrow_exception(failure);
}

}  // namespace

std::vector<double> laguerre_cell_measures(const std::vector<Vec3>& c, const std::vector<double>& r,
                                           const std::vector<std::uint32_t>& cells,
                                           const std::function<double(const Polyhedron&)>& measure, const Box* within) {
  std::vector<double> values(cells.size(), 0.0);
  for_each_cell(c, r, cells, within, [&](std::size_t k, const Polyhedron& poly) { values[k] = measure(poly); });
  return values;
}

std::vector<double> laguerre_volumes(const std::vector<Vec3>& c, const std::vector<double>& r) {
  std::vector<std::uint32_t> all(c.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  return laguerre_cell_measures(c, r, all, [](const Polyhedron& poly) { return volume(poly); });
}

std::vector<std::vector<LaguerreFace>> laguerre_faces(const std::vector<Vec3>& c, const std::vector<double>& r,
                                                      const std::vector<std::uint32_t>& cells) {
  std::vector<std::vector<LaguerreFace>> faces(cells.size());
  for_each_cell(c, r, cells, nullptr, [&](std::size_t k, const Polyhedron& poly) {
    for (const PolyFace& f : poly) {
      if (f.tag < 0) continue;
      // Area and centroid by a fan of triangles from the vertex centre (their signed areas share
      // the sign of the vertex order).
      const Vec3 o = vertex_centre(f);
      double area = 0.0;
      Vec3 moment{};
      for (std::size_t v = 0; v < f.pts.size(); ++v) {
        const Vec3& p = f.pts[v];
        const Vec3& q = f.pts[(v + 1) % f.pts.size()];
        const double t = 0.5 * dot(cross(p - o, q - o), f.n);
        area += t;
        moment += t * (o + p + q) / 3.0;
      }
      if (area != 0.0) faces[k].push_back({static_cast<std::uint32_t>(f.tag), std::abs(area) * f.n, moment / area});
    }
  });
  return faces;
}

}  // namespace arlequin::dem
