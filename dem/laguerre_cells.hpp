// Laguerre (power) cells of a set of spheres: cell i holds the points x with
//   |x - c_i|^2 - R_i^2 <= |x - c_j|^2 - R_j^2   for every j,
// bounded by the radical planes 2 (c_j - c_i).x = |c_j|^2 - |c_i|^2 - R_j^2 + R_i^2, and here by
// the spheres' bounding box. They tile the box (sum of volumes = box volume) and, unlike
// sphere volume / compaction, a small sphere among large ones gets the room its neighbours
// leave it: the volume share of a DE's virial stress (RDEF, failure.hpp; Aurenhammer, SIAM J.
// Comput. 16 (1987) for power diagrams).
#pragma once
#include <vector>

#include "common/vec3.hpp"

namespace arlequin::dem {

// Volume of every sphere's Laguerre cell within the box [min(c - R), max(c + R)] (m^3).
std::vector<double> laguerre_volumes(const std::vector<Vec3>& centres, const std::vector<double>& radii);

}  // namespace arlequin::dem
