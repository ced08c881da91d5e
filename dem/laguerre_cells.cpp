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
  // Candidates from a uniform grid of cells of size `cell`; a search reaches `reach` cells out.
  const double cell = 2.0 * r_max;
  int dims[3];
  for (int k = 0; k < 3; ++k) dims[k] = std::max(1, static_cast<int>(std::ceil((hi[k] - lo[k]) / cell)));
  auto cell_of = [&](const Vec3& x, int k) { return std::clamp(static_cast<int>((x[k] - lo[k]) / cell), 0, dims[k] - 1); };
  std::vector<std::vector<std::size_t>> bins(static_cast<std::size_t>(dims[0]) * dims[1] * dims[2]);
  for (std::size_t i = 0; i < n; ++i)
    if (r[i] <= large)
      bins[(static_cast<std::size_t>(cell_of(c[i], 2)) * dims[1] + cell_of(c[i], 1)) * dims[0] + cell_of(c[i], 0)].push_back(i);

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
      // The distance from c_i of sphere j's radical plane (R_i^2 - R_j^2 moves it from d / 2), and
      // the least of it for a binned sphere at distance D (R_i^2 >= 0, R_j <= r_max).
      const auto plane_distance = [&](double d2, std::size_t j) { return (d2 + r[i] * r[i] - r[j] * r[j]) / (2.0 * std::sqrt(d2)); };
      const auto binned_plane_distance = [r_max](double D) { return (D * D - r_max * r_max) / (2.0 * D); };
      for (int reach = 2;; reach *= 2) {
        // Every sphere within `reach` cells and every large one.
        near.clear();
        const int ci[3] = {cell_of(c[i], 0), cell_of(c[i], 1), cell_of(c[i], 2)};
        for (int z = std::max(0, ci[2] - reach); z <= std::min(dims[2] - 1, ci[2] + reach); ++z)
          for (int y = std::max(0, ci[1] - reach); y <= std::min(dims[1] - 1, ci[1] + reach); ++y)
            for (int x = std::max(0, ci[0] - reach); x <= std::min(dims[0] - 1, ci[0] + reach); ++x)
              for (std::size_t j : bins[(static_cast<std::size_t>(z) * dims[1] + y) * dims[0] + x])
                if (j != i) near.emplace_back(norm2(c[j] - c[i]), j);
        large_left.clear();
        for (std::size_t j : large_ones)
          if (j != i) near.emplace_back(norm2(c[j] - c[i]), j), large_left.push_back(j);
        // Their planes cut the box nearest first (so later planes rarely cut), until no plane left
        // can cut the cell: a binned sphere at distance D >= that of the nearest left has its plane
        // at least binned_plane_distance(D) from c_i, a large one is looked at on its own. A plane
        // that cuts nothing leaves the cell as it is (clip), and one clear of the cell's bounding
        // box cuts nothing: such planes are passed over without looking at the cell's vertices.
        // The cell is then the one every plane of the search in turn would give, to the bit.
        std::sort(near.begin(), near.end());
        Polyhedron poly = box_polyhedron(lo, hi, -1);
        double extent = 0.0;
        Vec3 bounds_lo, bounds_hi;
        const auto measure_cell = [&] {  // of a cell not empty
          extent = 0.0;
          bounds_lo = bounds_hi = poly.front().pts.front();
          for (const PolyFace& f : poly)
            for (const Vec3& p : f.pts) {
              extent = std::max(extent, norm(p - c[i]));
              for (int a = 0; a < 3; ++a) bounds_lo[a] = std::min(bounds_lo[a], p[a]), bounds_hi[a] = std::max(bounds_hi[a], p[a]);
            }
        };
        measure_cell();
        for (const auto& [d2, j] : near) {
          const double margin = extent + tol + round_off * (norm(c[i]) + extent);
          if (d2 > 0.0 && binned_plane_distance(std::sqrt(d2)) > margin &&
              std::all_of(large_left.begin(), large_left.end(),
                          [&](std::size_t l) { return plane_distance(norm2(c[l] - c[i]), l) > margin; }))
            break;
          if (r[j] > large) large_left.erase(std::find(large_left.begin(), large_left.end(), j));
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
          if (reach_of_box - offset + round_off * (std::abs(reach_of_box) + std::abs(offset)) <= tol) continue;
          if (!clip(poly, normal, offset, static_cast<int>(j), tol)) continue;
          if (poly.empty()) {  // a small sphere's cell inside its neighbours' power (no plane cuts it further)
            extent = 0.0;
            break;
          }
          measure_cell();
        }
        // Complete if no sphere beyond the search can cut the cell: every sphere outside the
        // searched cells is a binned one at least `reach` cells away.
        const bool everything = reach >= std::max({dims[0], dims[1], dims[2]});
        if (everything || binned_plane_distance(reach * cell) > extent) {
          on_cell(static_cast<std::size_t>(k), poly);
          break;
        }
      }
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
