// SPDX-License-Identifier: GPL-3.0-or-later
// Natural-neighbour coordinates (Sibson and Laplace) in 3D and on a plane, computed in an order
// fixed by the node numbers, so that the same query on the same nodes gives the same bits in any
// build of the triangulation.
//
// Why not CGAL/natural_neighbor_coordinates_{2,3}.h: they accumulate over containers ordered by
// cell and vertex addresses and take circumcentres in the cells' own vertex order, both of which
// change from one build of the same triangulation to the next (the insertion order is shuffled,
// the cells land elsewhere in memory). Two nem solvers of one mesh in one process (arlequin
// compare, sweep) then differed at round-off (~1e-16 relative), and the difference grew in a run.
//
// Formulas (Q the query point, V_x^old / V_x^new the Voronoi cells without / with Q):
// - Sibson (Sibson 1980): phi_v = |S_v| / sum_u |S_u|, S_v = V_Q^new intersected with V_v^old.
//   S_v is convex and bounded by the bisector plane of (Q, v) and by the parts, closer to Q than
//   to v, of v's old Voronoi faces F_vw. Taking the cone volumes of its faces from the apex
//   (v + Q)/2, which lies on the bisector plane of (Q, v) (that face contributes nothing), and the
//   point (v + w)/2 on the plane of F_vw:
//       |S_v| = sum_w (1/3) A_vw n_vw.((v + w)/2 - (v + Q)/2) = sum_w (1/6) A_vw n_vw.(w - Q),
//   n_vw = (w - v)/|w - v| the outward normal, A_vw the area of F_vw's part closer to Q (in 2D:
//   (1/4) L_vw n_vw.(w - Q), L_vw a length). That part is F_vw cut by the bisector of (Q, v): the
//   circumcentres of the conflict cells around edge (v, w) (those whose circumsphere holds Q), in
//   turning order, closed by the circumcentre of (Q, facet) where the run of conflict cells ends.
//   One face serves S_v and S_w.
// - Laplace (Belikov et al. 1997; Sukumar, Moran, Semenov & Belikov, IJNME 50 (2001)):
//   phi_v proportional to |F_Qv^new| / |Q - v|, F_Qv^new the new Voronoi face between Q and v:
//   the polygon of the circumcentres of (Q, f) over the conflict-boundary facets f at v, in turning
//   order (in 2D a segment between the two hole edges at v).
// Canonical order: every circumcentre is taken from its vertices sorted by node; every polygon
// starts at its smallest vertex key and turns towards the smaller of its two neighbours; terms
// are summed per node in the order of the edges' node pairs, and the normalisation in node order.
#pragma once
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <utility>
#include <vector>

#include "common/vec3.hpp"

namespace arlequin::continuum::nem {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
// Scratch space of a cell for the coordinate functions: its place in the conflict region of the
// current query, -1 outside it (as every cell is between queries).
struct ConflictIndex {
  int index = -1;
};
// Vertex info: the node number.
using Dt3 = CGAL::Delaunay_triangulation_3<
    Kernel, CGAL::Triangulation_data_structure_3<
                CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>,
                CGAL::Triangulation_cell_base_with_info_3<ConflictIndex, Kernel, CGAL::Delaunay_triangulation_cell_base_3<Kernel>>>>;
using Dt2 = CGAL::Delaunay_triangulation_2<
    Kernel, CGAL::Triangulation_data_structure_2<CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>,
                                                 CGAL::Triangulation_face_base_2<Kernel>>>;
using Coords = std::vector<std::pair<int, double>>;  // (node, shape function value), by node

enum class Coordinates { sibson, laplace };

// Coordinates of q, normalised (sum 1), sorted by node. False when q lies outside the convex
// hull of the nodes or on it (there the 3D coordinates are undefined). The triangulation is
// logically const, but a call marks the cells of its conflict region (CGAL's conflict search, and
// ConflictIndex) and clears them before it returns, so no two calls on one triangulation may
// run at once.
bool natural_neighbour_coordinates(const Dt3& dt, const Vec3& q, Coordinates kind, Coords& out);
bool natural_neighbour_coordinates(const Dt2& dt, const Kernel::Point_2& q, Coordinates kind, Coords& out);

}  // namespace arlequin::continuum::nem
