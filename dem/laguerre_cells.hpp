// SPDX-License-Identifier: GPL-3.0-or-later
// Laguerre (power) cells of a set of spheres: cell i holds the points x with
//   |x - c_i|^2 - R_i^2 <= |x - c_j|^2 - R_j^2   for every j,
// bounded by the radical planes 2 (c_j - c_i).x = |c_j|^2 - |c_i|^2 - R_j^2 + R_i^2, and here by
// the spheres' bounding box. They tile the box (sum of volumes = box volume) and, unlike
// sphere volume / compaction, a small sphere among large ones gets the room its neighbours
// leave it: the volume share of a DE's virial stress (RDEF, failure.hpp; Aurenhammer, SIAM J.
// Comput. 16 (1987) for power diagrams). Their faces between neighbours are the DE cloud's
// discrete divergence (the Arlequin overlap's consistent quadrature, coupling/coupled_model.hpp).
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "common/convex_polyhedron.hpp"
#include "common/region.hpp"
#include "common/vec3.hpp"

namespace arlequin::dem {

// Volume of every sphere's Laguerre cell within the box [min(c - R), max(c + R)] (m^3).
std::vector<double> laguerre_volumes(const std::vector<Vec3>& centres, const std::vector<double>& radii);

// measure(cell) for the Laguerre cell of each sphere in `cells` (indices into centres), in that
// order; all spheres take part in the tessellation. E.g. the part of a cell inside a region
// (the Arlequin overlap's share of a coupled DE, coupling/coupling_operators.hpp). within
// (optional): the cells are cut to this box too (it must hold the cells' centres), which
// spares the tessellation the parts of cells a measure inside it does not see.
std::vector<double> laguerre_cell_measures(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                           const std::vector<std::uint32_t>& cells,
                                           const std::function<double(const Polyhedron&)>& measure,
                                           const Box* within = nullptr);

// A face between a cell and a neighbour's: area vector (area times the unit normal pointing out
// of the cell, m^2) and area centroid (m). Faces on the box are not listed.
struct LaguerreFace {
  std::uint32_t neighbour;
  Vec3 area;
  Vec3 centroid;
};
// The neighbour faces of the cells of spheres `cells` (indices into centres), in that order;
// all spheres take part in the tessellation.
std::vector<std::vector<LaguerreFace>> laguerre_faces(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                                      const std::vector<std::uint32_t>& cells);

}  // namespace arlequin::dem
