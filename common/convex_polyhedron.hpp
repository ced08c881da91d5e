// SPDX-License-Identifier: GPL-3.0-or-later
// Convex polyhedra by their faces, clipped by half-spaces: Voronoi cells (continuum/nem) and
// Laguerre (power) cells (dem RDEF volume shares) are a box cut by one plane per neighbour.
#pragma once
#include <vector>

#include "common/vec3.hpp"

namespace arlequin {

// Convex polygon face: vertices in order around it, outward unit normal, and a tag telling
// the caller which plane made it (the tag given to `clip`, or the box's).
struct PolyFace {
  std::vector<Vec3> pts;
  Vec3 n;
  int tag = 0;
};
using Polyhedron = std::vector<PolyFace>;

// The box [lo, hi] with every face tagged `tag`.
Polyhedron box_polyhedron(const Vec3& lo, const Vec3& hi, int tag);

// Keeps the part of `poly` with n.x <= d (Sutherland-Hodgman per face, plus the cap polygon,
// tagged `tag`). Vertices within `tol` (length) of the plane count as on it; a plane that cuts
// no vertex by more than tol leaves poly unchanged. Polygon vertices within tol of their
// predecessor are dropped (a vertex cut from two faces is computed twice). Returns whether the
// plane cut poly.
bool clip(Polyhedron& poly, const Vec3& n, double d, int tag, double tol);

// Centre of a face's vertices (not its area centroid).
Vec3 vertex_centre(const PolyFace& f);

// Volume, by pyramids from the centre of all the vertices (inside a convex polyhedron).
double volume(const Polyhedron& poly);

}  // namespace arlequin
