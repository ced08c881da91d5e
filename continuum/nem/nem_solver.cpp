// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/nem/nem_solver.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

#include "common/convex_polyhedron.hpp"
#include "common/error.hpp"
#include "continuum/nem/natural_neighbours.hpp"

namespace arlequin::continuum {

namespace {

using nem::Coordinates;
using nem::Coords;
using nem::Dt2;
using nem::Dt3;
using nem::Kernel;

Kernel::Point_3 P3(const Vec3& v) { return {v.x, v.y, v.z}; }

struct Plane {
  Vec3 n;  // outward unit normal
  double d;  // n.x = d on the plane, n.x <= d inside
  Vec3 e1, e2, origin;  // in-plane frame for the 2D triangulation
  Dt2 dt;  // the plane's own nodes
  Kernel::Point_2 local(const Vec3& x) const { return {dot(x - origin, e1), dot(x - origin, e2)}; }
};

}  // namespace

// One convex piece of the domain: a body of the mesh (a connected set of tetrahedra) when it is
// convex, else one of the convex pieces the planes of its boundary faces cut it into. Pieces of
// one body share the nodes of the faces between them; bodies share no node.
struct Body {
  std::vector<int> tets;   // mesh tetrahedra
  std::vector<int> nodes;  // mesh node ids, increasing
  std::vector<int> material;  // per node of `nodes`: that of the piece's first tetrahedron holding it
  std::vector<Dt3::Vertex_handle> handle;  // per node of `nodes`, in dt
  Dt3 dt;                  // its nodes (vertex info: mesh node id)
  std::vector<Plane> planes;
  std::vector<int> neighbour;  // per plane: the piece sharing that face, -1 on the domain boundary
  std::vector<int> neighbour_plane;  // per plane: that face's plane in the neighbouring piece
  Polyhedron domain;  // its bounding box clipped by its planes (face tag -1 - k: plane k)
  std::size_t position(int node) const { return std::lower_bound(nodes.begin(), nodes.end(), node) - nodes.begin(); }
  bool shared(int plane) const { return neighbour[plane] >= 0; }
};

struct NemSolver::Geometry {
  Coordinates kind = Coordinates::sibson;
  double tol = 0;  // length: "on a plane" for nodes and points
  std::vector<Body> bodies;  // the convex pieces
  const std::vector<Vec3>* x = nullptr;

  // Natural-neighbour coordinates on domain plane k of body b (p projected onto it).
  bool on_plane(const Body& b, int k, const Vec3& p, Coords& out) const {
    return nem::natural_neighbour_coordinates(b.planes[k].dt, b.planes[k].local(p), kind, out);
  }

  // Shape functions at any point of the closed domain: those of the first piece holding it (on a
  // face two pieces of one body share, both give the 2D coordinates of the face's nodes; on a
  // face two bodies touch at, the first body's); false outside every piece.
  bool coords(const Vec3& p, Coords& out) const {
    for (const Body& b : bodies)
      if (coords(b, p, out)) return true;
    return false;
  }

  // Shape functions at a point of body b; false outside it.
  bool coords(const Body& b, const Vec3& p, Coords& out) const {
    out.clear();
    std::vector<int> on;
    for (int k = 0; k < static_cast<int>(b.planes.size()); ++k) {
      const double s = dot(b.planes[k].n, p) - b.planes[k].d;
      if (s > tol) return false;
      if (s >= -tol) on.push_back(k);
    }
    if (on.size() == 1) return on_plane(b, on[0], p, out);
    if (on.size() >= 2) return on_edge_or_corner(b, on, p, out);
    if (kind == Coordinates::sibson && nem::natural_neighbour_coordinates(b.dt, p, Coordinates::sibson, out)) {
      // Sibson volumes use the circumcentre of every conflict cell; a flat cell (four
      // cocircular nodes on a flat boundary face, common in gmsh surface meshes) spoils them.
      // Such points are caught by the linear-reproduction check and get Laplace coordinates.
      Vec3 r{};
      for (const auto& [J, value] : out) r += value * (*x)[J];
      if (norm(r - p) <= 1e-3 * tol) return true;
    }
    return nem::natural_neighbour_coordinates(b.dt, p, Coordinates::laplace, out);
  }

  // On an edge of body b (two or more planes): the 1D linear interpolant between the nearest
  // nodes of the edge on either side; at a corner, the corner node.
  bool on_edge_or_corner(const Body& b, const std::vector<int>& on, const Vec3& p, Coords& out) const {
    const Vec3 t = cross(b.planes[on[0]].n, b.planes[on[1]].n);
    const auto nearest = b.dt.nearest_vertex(P3(p));
    if (on.size() >= 3 || norm(t) < 1e-12) {
      if (norm((*x)[nearest->info()] - p) > tol) return false;
      out.push_back({nearest->info(), 1.0});
      return true;
    }
    const Vec3 dir = normalized(t);
    int lo = -1, hi = -1;
    double slo = -1e300, shi = 1e300;
    for (int i : b.nodes) {
      const Vec3& xi = (*x)[i];
      if (std::abs(dot(b.planes[on[0]].n, xi) - b.planes[on[0]].d) > tol ||
          std::abs(dot(b.planes[on[1]].n, xi) - b.planes[on[1]].d) > tol)
        continue;
      const double s = dot(xi - p, dir);
      if (s <= 0 && s > slo) slo = s, lo = i;
      if (s >= 0 && s < shi) shi = s, hi = i;
    }
    if (lo < 0 || hi < 0) return false;
    if (lo == hi || shi - slo <= tol) {
      out.push_back({lo, 1.0});
      return true;
    }
    out.push_back({lo, shi / (shi - slo)});
    out.push_back({hi, -slo / (shi - slo)});
    return true;
  }
};

namespace {

using Face = std::array<int, 3>;

Face sorted(Face f) {
  std::sort(f.begin(), f.end());
  return f;
}

// The plane of triangle t of nodes X: outward unit normal (t turns counter-clockwise about it).
std::pair<Vec3, double> plane_of(const Face& t, const std::vector<Vec3>& X) {
  const Vec3 n = normalized(cross(X[t[1]] - X[t[0]], X[t[2]] - X[t[0]]));
  return {n, dot(n, X[t[0]])};
}

// Adds the plane n.x = d (n unit) to `planes` unless one there is the same (within tol).
int find_or_add_plane(std::vector<Plane>& planes, const Vec3& n, double d, double tol) {
  for (std::size_t k = 0; k < planes.size(); ++k)
    if (norm(planes[k].n - n) < 1e-9 && std::abs(planes[k].d - d) < tol) return static_cast<int>(k);
  Plane p;
  p.n = n;
  p.d = d;
  planes.push_back(std::move(p));
  return static_cast<int>(planes.size()) - 1;
}
// The same for the plane of triangle t of nodes X, oriented as plane_of.
int find_or_add_plane(std::vector<Plane>& planes, const Face& t, const std::vector<Vec3>& X, double tol) {
  const auto [n, d] = plane_of(t, X);
  return find_or_add_plane(planes, n, d, tol);
}

// The planes that cut a non-convex body into convex pieces: those of its boundary faces
// (`planes`) and, where a plane holds both boundary faces of the body and faces inside it (two
// bodies meshed apart and joined over part of their common face, continuum/mesh.hpp: a slit
// that ends inside the body), the plane through each edge where the two kinds meet,
// perpendicular to that plane. Without these the pieces on either side of the slit's plane
// would meet on part of a face only.
std::vector<Plane> planes_with_slit_ends(const Mesh& mesh, const std::map<Face, std::vector<std::pair<int, Face>>>& faces,
                                         const std::vector<int>& body_tets, const std::vector<Plane>& planes, double tol) {
  const std::vector<Vec3>& X = mesh.nodes();
  std::vector<char> in_body(mesh.num_tets(), 0);
  for (int e : body_tets) in_body[e] = 1;
  const auto on_plane = [&](const Face& f, const Plane& p) {
    return std::all_of(f.begin(), f.end(), [&](int v) { return std::abs(dot(p.n, X[v]) - p.d) <= tol; });
  };
  std::vector<Plane> cuts = planes;
  for (const Plane& p : planes) {
    // The edges of the body's faces on p, each marked 1 if a boundary face has it, 2 if an inner
    // face has it: 3 where the slit ends.
    std::map<std::pair<int, int>, int> edge_kinds;
    for (const auto& [key, holders] : faces) {
      if (!in_body[holders[0].first] || !on_plane(key, p)) continue;
      for (int k = 0; k < 3; ++k) {
        const int a = key[k], c = key[(k + 1) % 3];
        int& kinds = edge_kinds[{std::min(a, c), std::max(a, c)}];
        kinds |= holders.size() == 1 ? 1 : 2;
      }
    }
    for (const auto& [edge, kinds] : edge_kinds) {
      if (kinds != 3) continue;
      // A cut's side does not matter: its normal's largest component is made positive, so that
      // the slit's two faces (opposite normals) give it once.
      const Vec3 a = X[edge.first];
      Vec3 n = normalized(cross(p.n, X[edge.second] - a));
      const int largest = std::abs(n.x) >= std::max(std::abs(n.y), std::abs(n.z)) ? 0 : std::abs(n.y) >= std::abs(n.z) ? 1 : 2;
      if (n[largest] < 0.0) n = -1.0 * n;
      find_or_add_plane(cuts, n, dot(n, a), tol);
    }
  }
  return cuts;
}

// The convex pieces of the mesh (see Body): its bodies (tetrahedra joined through shared nodes,
// union-find), by their first node; a body that is not convex is cut by the planes of its
// boundary faces (and across the ends of a slit, planes_with_slit_ends), each tetrahedron going
// to the piece on its side of every one of them (a cell of the planes' arrangement, convex; two
// cells meet on a whole face of each). Each piece's planes are those of its boundary faces in
// the order of their sorted vertex triples (as Mesh::boundary_triangles), each with the piece
// across it.
std::vector<Body> mesh_pieces(const Mesh& mesh, double tol) {
  const std::vector<Vec3>& X = mesh.nodes();
  const int n = mesh.num_nodes(), tets = mesh.num_tets();
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  const auto root = [&parent](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (int e = 0; e < tets; ++e)
    for (int a = 1; a < mesh.nodes_per_tet(); ++a) {
      const int r0 = root(mesh.tet(e)[0]), r1 = root(mesh.tet(e)[a]);
      if (r0 != r1) parent[std::max(r0, r1)] = std::min(r0, r1);
    }
  // A root is its body's smallest node: numbering the roots in node order orders the bodies.
  std::vector<int> body_of_root(n, -1);
  int bodies = 0;
  for (int i = 0; i < n; ++i)
    if (root(i) == i) body_of_root[i] = bodies++;
  std::vector<std::vector<int>> body_tets(bodies), body_nodes(bodies);
  for (int e = 0; e < tets; ++e) body_tets[body_of_root[root(mesh.tet(e)[0])]].push_back(e);
  for (int i = 0; i < n; ++i) body_nodes[body_of_root[root(i)]].push_back(i);

  // Every face: the tetrahedra holding it (one on the boundary, two inside), each with the face's
  // vertices turning about the normal out of that tetrahedron.
  std::map<Face, std::vector<std::pair<int, Face>>> faces;
  for (int e = 0; e < tets; ++e)
    for (const auto& f : kTetFaces) {
      const Face t{mesh.tet(e)[f[0]], mesh.tet(e)[f[1]], mesh.tet(e)[f[2]]};
      faces[sorted(t)].push_back({e, t});
    }
  std::vector<std::vector<Plane>> body_planes(bodies);
  for (const auto& [key, holders] : faces)
    if (holders.size() == 1) find_or_add_plane(body_planes[body_of_root[root(key[0])]], holders[0].second, X, tol);

  std::vector<Body> pieces;
  std::vector<int> piece_of_tet(tets, -1);
  for (int b = 0; b < bodies; ++b) {
    if (body_tets[b].empty())  // Mesh drops such nodes; a mesh built otherwise must too
      throw InputError("nem: node " + std::to_string(body_nodes[b][0]) + " belongs to no tetrahedron");
    const std::vector<Plane>& planes = body_planes[b];
    const bool convex = std::all_of(body_nodes[b].begin(), body_nodes[b].end(), [&](int i) {
      return std::all_of(planes.begin(), planes.end(), [&](const Plane& p) { return dot(p.n, X[i]) - p.d <= tol; });
    });
    if (convex) {
      for (int e : body_tets[b]) piece_of_tet[e] = static_cast<int>(pieces.size());
      pieces.emplace_back().tets = body_tets[b];
      continue;
    }
    const std::vector<Plane> cuts = planes_with_slit_ends(mesh, faces, body_tets[b], planes, tol);
    std::map<std::vector<char>, int> piece_of_side;  // which side of each plane -> piece
    for (int e : body_tets[b]) {
      std::vector<char> side(cuts.size());
      for (std::size_t k = 0; k < cuts.size(); ++k) {
        double lo = 1e300, hi = -1e300;
        for (int a = 0; a < 4; ++a) {
          const double s = dot(cuts[k].n, X[mesh.tet(e)[a]]) - cuts[k].d;
          lo = std::min(lo, s), hi = std::max(hi, s);
        }
        if (lo < -tol && hi > tol)
          throw InputError("nem: the domain" + (bodies > 1 ? " of body " + std::to_string(b) : std::string()) +
                           " is not convex and the plane of one of its boundary faces cuts tetrahedron " +
                           std::to_string(e) + " (node " + std::to_string(mesh.tet(e)[0]) +
                           "): a non-convex body is taken as the convex pieces the planes of its faces cut it "
                           "into, so its mesh needs faces on those planes where they cross it (gmsh: fragments)");
        side[k] = hi > tol;
      }
      const auto [at, added] = piece_of_side.try_emplace(side, static_cast<int>(pieces.size()));
      if (added) pieces.emplace_back();
      pieces[at->second].tets.push_back(e);
      piece_of_tet[e] = at->second;
    }
  }
  for (Body& piece : pieces) {
    for (int e : piece.tets) piece.nodes.insert(piece.nodes.end(), mesh.tet(e), mesh.tet(e) + mesh.nodes_per_tet());
    std::sort(piece.nodes.begin(), piece.nodes.end());
    piece.nodes.erase(std::unique(piece.nodes.begin(), piece.nodes.end()), piece.nodes.end());
  }
  // Each piece's planes, with the piece across each: -1 on a boundary face of the mesh.
  const auto add = [&](int piece, const Face& t, int across) {
    Body& body = pieces[piece];
    const int k = find_or_add_plane(body.planes, t, X, tol);
    if (k == static_cast<int>(body.neighbour.size())) body.neighbour.push_back(across), body.neighbour_plane.push_back(-1);
    if (body.neighbour[k] != across)
      throw InputError("nem: a face of the domain's convex piece " + std::to_string(piece) + " (node " +
                       std::to_string(body.nodes[0]) + ") is shared with more than one other piece or partly on the "
                       "domain boundary; cut the body so that its pieces meet on whole faces");
    return k;
  };
  for (const auto& [key, holders] : faces) {
    if (holders.size() == 1) add(piece_of_tet[holders[0].first], holders[0].second, -1);
    const int a = piece_of_tet[holders[0].first], b = holders.size() == 2 ? piece_of_tet[holders[1].first] : a;
    if (a != b) {
      const int ka = add(a, holders[0].second, b), kb = add(b, holders[1].second, a);
      pieces[a].neighbour_plane[ka] = kb;
      pieces[b].neighbour_plane[kb] = ka;
    }
  }
  return pieces;
}

using Flux = std::vector<std::pair<int, Vec3>>;  // (J, int phi_J n dS)
using Point2 = std::array<double, 2>;

double cross2(const Point2& o, const Point2& a, const Point2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// The part of convex polygon `poly` on the left of the line from a to b (Sutherland-Hodgman).
std::vector<Point2> left_of(const std::vector<Point2>& poly, const Point2& a, const Point2& b) {
  std::vector<Point2> out;
  for (std::size_t m = 0; m < poly.size(); ++m) {
    const Point2 &p = poly[m], &q = poly[(m + 1) % poly.size()];
    const double sp = cross2(a, b, p), sq = cross2(a, b, q);
    if (sp >= 0) out.push_back(p);
    if ((sp >= 0) != (sq >= 0)) {
      const double t = sp / (sp - sq);
      out.push_back({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])});
    }
  }
  return out;
}

double signed_area(const std::vector<Point2>& poly) {
  double a = 0;
  for (std::size_t m = 0; m < poly.size(); ++m) a += 0.5 * cross2({0, 0}, poly[m], poly[(m + 1) % poly.size()]);
  return a;
}

// The fluxes through the faces two pieces of a body share (Body). On such a face each piece's
// cells give their own triangles (their Voronoi cells there differ where a node off the face is
// nearer to it than the face's nodes), and midpoint rules on two different triangulations would
// integrate the face's shape functions differently: the fluxes would not cancel between the
// pieces and the patch test would fail at the interface. So both sides are integrated on the
// overlay of the two triangulations: every part of a triangle of one piece over a triangle of the
// other, fanned from its vertex centre, one point per fan triangle (exact for linear fields: each
// triangle's sum still integrates them exactly), its flux added to both triangles with opposite
// normals. Each triangle is then the sum of its parts, and the two pieces' fluxes through the
// face cancel to round-off.
class SharedFaceFluxes {
 public:
  // voronoi_cell(piece, node) gives a node's cell in a piece (a Body) and corner_triangles(face, visit)
  // its face's triangles, as the integration visits them (the same calls give the same bits).
  template <class VoronoiCell, class CornerTriangles>
  SharedFaceFluxes(const std::vector<Body>& pieces, Coordinates kind, double tol, const VoronoiCell& voronoi_cell,
                   const CornerTriangles& corner_triangles)
      : triangles_(pieces.size()), first_(pieces.size()), flux_(pieces.size()) {
    for (std::size_t p = 0; p < pieces.size(); ++p) {
      const Body& body = pieces[p];
      if (std::none_of(body.neighbour.begin(), body.neighbour.end(), [](int q) { return q >= 0; })) continue;
      first_[p].resize(body.nodes.size() + 1);
      for (std::size_t k = 0; k < body.nodes.size(); ++k) {
        first_[p][k] = triangles_[p].size();
        for (const PolyFace& f : voronoi_cell(body, body.nodes[k])) {
          if (f.tag >= 0 || !body.shared(-1 - f.tag)) continue;
          corner_triangles(f, [&](std::size_t, const Vec3& a, const Vec3& b, const Vec3& c) {
            triangles_[p].push_back({a, b, c, -1 - f.tag});
          });
        }
      }
      first_[p].back() = triangles_[p].size();
      flux_[p].resize(triangles_[p].size());
    }
    for (std::size_t p = 0; p < pieces.size(); ++p)
      for (std::size_t k = 0; k < pieces[p].planes.size(); ++k) {
        const int q = pieces[p].neighbour[k];
        if (q <= static_cast<int>(p)) continue;
        overlay(pieces[p], static_cast<int>(p), static_cast<int>(k), q, pieces[p].neighbour_plane[k], kind, tol);
      }
  }

  // Index of the first shared-face triangle of the cell of the piece's node at `position`.
  std::size_t first(int piece, std::size_t position) const { return first_[piece].empty() ? 0 : first_[piece][position]; }

  // The flux of the piece's triangle `index`, which must be the triangle (a, b, c).
  const Flux& flux(int piece, std::size_t index, const Vec3& a, const Vec3& b, const Vec3& c) const {
    const Triangle& t = triangles_[piece].at(index);
    if (!(t.a == a && t.b == b && t.c == c)) throw std::logic_error("nem: a shared face's triangles visited out of order");
    return flux_[piece][index];
  }

 private:
  struct Triangle {
    Vec3 a, b, c;
    int plane;
  };

  // The overlay of piece p's triangles on its plane k with piece q's on its plane kq (the same
  // face, opposite normals); shape functions from p's plane (the same nodes as q's).
  void overlay(const Body& body, int p, int k, int q, int kq, Coordinates kind, double tol) {
    const Plane& plane = body.planes[k];
    const auto flat = [&](const Triangle& t) {  // counter-clockwise in the plane's frame
      const auto at = [&](const Vec3& x) {
        const auto l = plane.local(x);
        return Point2{l.x(), l.y()};
      };
      std::vector<Point2> poly{at(t.a), at(t.b), at(t.c)};
      if (signed_area(poly) < 0) std::swap(poly[1], poly[2]);
      return poly;
    };
    std::vector<std::size_t> mine, theirs;
    for (std::size_t t = 0; t < triangles_[p].size(); ++t)
      if (triangles_[p][t].plane == k) mine.push_back(t);
    for (std::size_t t = 0; t < triangles_[q].size(); ++t)
      if (triangles_[q][t].plane == kq) theirs.push_back(t);
    // q's triangles binned on a grid of about one triangle per bin.
    std::vector<std::vector<Point2>> their_poly;
    Point2 lo{1e300, 1e300}, hi{-1e300, -1e300};
    double area = 0;
    for (std::size_t t : theirs) {
      their_poly.push_back(flat(triangles_[q][t]));
      area += signed_area(their_poly.back());
      for (const Point2& v : their_poly.back())
        for (int c = 0; c < 2; ++c) lo[c] = std::min(lo[c], v[c]), hi[c] = std::max(hi[c], v[c]);
    }
    if (theirs.empty()) {  // nothing covers p's triangles: refused below, unless they have no area
      for (std::size_t t : mine) check_cover(0.0, flat(triangles_[p][t]), p, q, tol);
      return;
    }
    const double bin = std::sqrt(area / static_cast<double>(theirs.size()));
    const auto bins_along = [&](int c) { return static_cast<int>(std::clamp((hi[c] - lo[c]) / bin, 0.0, 4095.0)) + 1; };
    const int nx = bins_along(0), ny = bins_along(1);
    const auto cell = [&](double v, int c) {
      const int count = c == 0 ? nx : ny;
      return std::clamp(static_cast<int>((v - lo[c]) / (hi[c] - lo[c] + 1e-300) * count), 0, count - 1);
    };
    std::vector<std::vector<std::size_t>> bins(static_cast<std::size_t>(nx) * ny);
    const auto box = [&](const std::vector<Point2>& poly) {
      std::array<int, 4> b{cell(poly[0][0], 0), cell(poly[0][0], 0), cell(poly[0][1], 1), cell(poly[0][1], 1)};
      for (const Point2& v : poly) {
        b[0] = std::min(b[0], cell(v[0], 0)), b[1] = std::max(b[1], cell(v[0], 0));
        b[2] = std::min(b[2], cell(v[1], 1)), b[3] = std::max(b[3], cell(v[1], 1));
      }
      return b;
    };
    for (std::size_t u = 0; u < theirs.size(); ++u) {
      const auto b = box(their_poly[u]);
      for (int x = b[0]; x <= b[1]; ++x)
        for (int y = b[2]; y <= b[3]; ++y) bins[static_cast<std::size_t>(x) * ny + y].push_back(u);
    }
    std::vector<double> their_cover(theirs.size(), 0.0);
    std::vector<std::size_t> seen(theirs.size(), SIZE_MAX);
    Coords phi;
    for (std::size_t t : mine) {
      const std::vector<Point2> poly = flat(triangles_[p][t]);
      const double own = signed_area(poly);
      double cover = 0;
      const auto b = box(poly);
      for (int x = b[0]; x <= b[1]; ++x)
        for (int y = b[2]; y <= b[3]; ++y)
          for (std::size_t u : bins[static_cast<std::size_t>(x) * ny + y]) {
            if (seen[u] == t) continue;
            seen[u] = t;
            std::vector<Point2> part = poly;
            const auto& other = their_poly[u];
            for (std::size_t e = 0; e < 3 && part.size() >= 3; ++e) part = left_of(part, other[e], other[(e + 1) % 3]);
            if (part.size() < 3) continue;
            const double a = signed_area(part);
            if (!(a > 1e-12 * std::min(own, signed_area(other)))) continue;
            cover += a;
            their_cover[u] += a;
            Point2 centre{0, 0};
            for (const Point2& v : part) centre[0] += v[0] / part.size(), centre[1] += v[1] / part.size();
            for (std::size_t m = 0; m < part.size(); ++m) {
              const Point2 &v = part[m], &w = part[(m + 1) % part.size()];
              const double fan = 0.5 * cross2(centre, v, w);
              if (!(fan > 0)) continue;
              const Vec3 point = plane.origin + ((centre[0] + v[0] + w[0]) / 3.0) * plane.e1 + ((centre[1] + v[1] + w[1]) / 3.0) * plane.e2;
              if (!nem::natural_neighbour_coordinates(plane.dt, plane.local(point), kind, phi))
                throw RunError("nem: natural-neighbour coordinates failed on a face two convex pieces share");
              for (const auto& [J, value] : phi) {
                flux_[p][t].push_back({J, (value * fan) * plane.n});
                flux_[q][theirs[u]].push_back({J, -(value * fan) * plane.n});
              }
            }
          }
      check_cover(cover, poly, p, q, tol);
    }
    for (std::size_t u = 0; u < theirs.size(); ++u) check_cover(their_cover[u], their_poly[u], p, q, tol);
  }

  // Each triangle is the sum of its overlay parts, to round-off and to the slivers the cells'
  // clipping tolerance (1e-12 of the domain, 1e-3 of tol) leaves along their edges.
  static void check_cover(double cover, const std::vector<Point2>& triangle, int p, int q, double tol) {
    double perimeter = 0;
    for (std::size_t m = 0; m < 3; ++m) perimeter += std::hypot(triangle[(m + 1) % 3][0] - triangle[m][0], triangle[(m + 1) % 3][1] - triangle[m][1]);
    const double area = signed_area(triangle);
    if (std::abs(cover - area) > 1e-8 * area + 1e-2 * tol * perimeter)
      throw RunError("nem: the cells of convex pieces " + std::to_string(p) + " and " + std::to_string(q) +
                     " do not cover their shared face alike");
  }

  std::vector<std::vector<Triangle>> triangles_;  // per piece, in the order its cells visit them
  std::vector<std::vector<std::size_t>> first_;   // per piece: per node position, its cell's first
  std::vector<std::vector<Flux>> flux_;
};

}  // namespace

std::unique_ptr<ContinuumSolver> NemSolver::create(const ContinuumSettings& settings) {
  return std::make_unique<NemSolver>(settings);
}

NemSolver::~NemSolver() = default;

NemSolver::NemSolver(const ContinuumSettings& settings) : ContinuumSolver(settings), geo_(std::make_unique<Geometry>()) {
  if (settings.shape_functions != "sibson" && settings.shape_functions != "laplace")
    throw InputError("nem: shape_functions must be 'sibson' or 'laplace', got '" + settings.shape_functions + "'");
  Geometry& g = *geo_;
  g.kind = settings.shape_functions == "laplace" ? Coordinates::laplace : Coordinates::sibson;
  if (!(settings.nem_stabilization > 0.0))
    throw InputError("nem: stabilization must be > 0 (MSCNI's a; 1 integrates each sub-cell), got " +
                     std::to_string(settings.nem_stabilization));
  const double root_a = std::sqrt(settings.nem_stabilization);
  const std::vector<Vec3>& X = nodes();
  const int n = num_nodes();
  g.x = &X;
  Vec3 lo = X[0], hi = X[0];
  for (const Vec3& p : X)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const double L = norm(hi - lo);
  g.tol = 1e-9 * L;

  // The convex pieces, and per piece its domain planes (the distinct planes of its boundary
  // faces), its tessellations and its domain as a polyhedron.
  g.bodies = mesh_pieces(mesh_, g.tol);
  std::vector<std::vector<int>> pieces_of(n);  // the pieces holding each node, in order
  for (size_t k = 0; k < g.bodies.size(); ++k)
    for (int i : g.bodies[k].nodes) pieces_of[i].push_back(static_cast<int>(k));
  const std::string several = g.bodies.size() > 1 ? " of convex piece " : "";
  for (size_t k = 0; k < g.bodies.size(); ++k) {
    Body& body = g.bodies[k];
    const std::string which = several.empty() ? "" : several + std::to_string(k) + " (node " + std::to_string(body.nodes[0]) + ")";
    for (Plane& p : body.planes) {
      p.e1 = normalized(std::abs(p.n.x) < 0.9 ? cross(p.n, Vec3{1, 0, 0}) : cross(p.n, Vec3{0, 1, 0}));
      p.e2 = cross(p.n, p.e1);
      p.origin = p.d * p.n;
      std::vector<std::pair<Kernel::Point_2, int>> pts;
      for (int i : body.nodes) {
        const double s = dot(p.n, X[i]) - p.d;
        if (s > g.tol)
          throw InputError("nem: the domain" + which + " is not convex (node " + std::to_string(i) +
                           " lies outside the plane of one of its faces)");
        if (s >= -g.tol) pts.push_back({p.local(X[i]), i});
      }
      p.dt.insert(pts.begin(), pts.end());
    }
    std::vector<std::pair<Kernel::Point_3, int>> pts;
    Vec3 blo = X[body.nodes[0]], bhi = blo;
    for (int i : body.nodes) {
      pts.push_back({P3(X[i]), i});
      for (int c = 0; c < 3; ++c) blo[c] = std::min(blo[c], X[i][c]), bhi[c] = std::max(bhi[c], X[i][c]);
    }
    body.dt.insert(pts.begin(), pts.end());
    if (body.dt.number_of_vertices() != body.nodes.size()) throw InputError("nem: duplicate nodes in the mesh" + which);
    body.handle.resize(body.nodes.size());
    for (auto v = body.dt.finite_vertices_begin(); v != body.dt.finite_vertices_end(); ++v) body.handle[body.position(v->info())] = v;
    const Vec3 a = blo - 0.01 * L * Vec3{1, 1, 1}, b = bhi + 0.01 * L * Vec3{1, 1, 1};
    body.domain = box_polyhedron(a, b, -1000000);
    for (int m = 0; m < static_cast<int>(body.planes.size()); ++m)
      clip(body.domain, body.planes[m].n, body.planes[m].d, -1 - m, 1e-12 * L);
    for (const PolyFace& f : body.domain)
      if (f.tag == -1000000) throw InputError("nem: the mesh boundary does not close a convex domain" + which);
  }

  // A node's material in a piece: that of the piece's first tetrahedron holding it.
  for (Body& body : g.bodies) {
    body.material.assign(body.nodes.size(), -1);
    for (int e : body.tets)
      for (int a = 0; a < mesh_.nodes_per_tet(); ++a) {
        int& m = body.material[body.position(mesh_.tet(e)[a])];
        if (m < 0) m = tet_material_[e];
      }
  }

  // Integration (see the header): per node i its clipped Voronoi cell V_i, cut into one
  // sub-cell per cell vertex v: the union of the tetrahedra (x_i, face centre, edge midpoint, v).
  // One integration point per sub-cell, b_J = (int phi_J n dS over its surface) / volume.
  Coords phi;
  // Node i's Voronoi cell in a piece: the piece's domain clipped by the bisecting plane of each
  // Delaunay neighbour (face tag: the neighbour's node id).
  const auto voronoi_cell = [&](const Body& body, int i) {
    Polyhedron cell = body.domain;
    std::vector<Dt3::Vertex_handle> adj;
    body.dt.finite_adjacent_vertices(body.handle[body.position(i)], std::back_inserter(adj));
    for (const auto& v : adj) {
      const int j = v->info();
      const Vec3 nn = normalized(X[j] - X[i]);
      clip(cell, nn, dot(nn, 0.5 * (X[i] + X[j])), j, 1e-12 * L);
    }
    return cell;
  };
  // The 2k triangles of a k-gon face around its corners, in order: corner m's part is
  // (c, mid(m-1, m), p_m) and (c, p_m, mid(m, m+1)), c the face's vertex centre.
  const auto corner_triangles = [](const PolyFace& f, const auto& visit) {
    const Vec3 c = vertex_centre(f);
    const size_t k = f.pts.size();
    for (size_t m = 0; m < k; ++m) {
      const Vec3 &p = f.pts[m], before = 0.5 * (f.pts[(m + k - 1) % k] + p), after = 0.5 * (p + f.pts[(m + 1) % k]);
      visit(m, c, before, p);
      visit(m, c, p, after);
    }
  };
  const SharedFaceFluxes shared_faces(g.bodies, g.kind, g.tol, voronoi_cell, corner_triangles);
  // Midpoint rule on triangle (a, b, c) with area vector an (area times unit normal); plane >= 0:
  // the triangle lies on that domain plane, its point then also joins the boundary rule for
  // tractions (so loads and gradients satisfy the same integration constraint).
  std::vector<Eigen::Triplet<double>> boundary_phi;
  auto add_flux = [&](const Body& body, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& an, int plane, Flux& out) {
    const double area = norm(an);
    if (!(area > 0)) return;
    const Vec3 q = (a + b + c) / 3.0;
    if (!(plane >= 0 ? g.on_plane(body, plane, q, phi) : g.coords(body, q, phi)))
      throw RunError("nem: natural-neighbour coordinates failed at a Voronoi cell point");
    for (const auto& [J, value] : phi) out.push_back({J, value * an});
    if (plane >= 0) {
      for (const auto& [J, value] : phi) boundary_phi.emplace_back(static_cast<int>(boundary_.x.size()), J, value);
      boundary_.x.push_back(q);
      boundary_.w.push_back(area);
    }
  };
  // Face between cells i < j: its polygon and the flux through the part of it around each of its
  // vertices, from cell i, kept until cell j takes them reversed. Clipping the two cells gives
  // polygons equal only to the clipping tolerance; sharing one keeps every sub-cell closed (grad x
  // = I to round-off) and makes the fluxes cancel exactly between the cells. A face too small to
  // survive clipping on one side is integrated on the other alone.
  struct FaceParts {
    std::vector<Vec3> pts;
    std::vector<Flux> flux;  // per polygon vertex
  };
  std::map<std::tuple<int, int, int>, FaceParts> shared;  // (piece, i, j)
  struct SubCell {
    double volume = 0;
    Vec3 moment{};
    Flux flux;
  };
  cell_volume_.assign(n, 0.0);
  node_density_.assign(n, 0.0);
  for (int i = 0; i < n; ++i)
    for (const int piece : pieces_of[i]) {
      const Body& body = g.bodies[piece];
      Polyhedron cell = voronoi_cell(body, i);
      std::size_t next_shared = shared_faces.first(piece, body.position(i));
      // The cell's vertices, each polygon corner mapped to one (corners within the tolerance are
      // one vertex).
      std::vector<Vec3> vertex;
      auto vertex_id = [&](const Vec3& p) {
        for (size_t k = 0; k < vertex.size(); ++k)
          if (norm(vertex[k] - p) <= g.tol) return static_cast<int>(k);
        vertex.push_back(p);
        return static_cast<int>(vertex.size()) - 1;
      };
      std::vector<SubCell> sub;
      for (PolyFace& f : cell) {
        // The part around corner m: triangles (c, mid(m-1, m), p_m) and (c, p_m, mid(m, m+1)).
        FaceParts parts;
        const auto from = f.tag >= 0 && f.tag < i ? shared.find({piece, f.tag, i}) : shared.end();
        const bool taken = from != shared.end();
        if (taken) {
          parts = std::move(from->second);
          for (Flux& flux : parts.flux)
            for (auto& [J, v] : flux) v = -v;
          shared.erase(from);
          f.pts = parts.pts;
        }
        const Vec3 c = vertex_centre(f);
        const size_t k = f.pts.size();
        const auto midpoints = [&](size_t m) {  // of the edges before and after corner m
          return std::pair{0.5 * (f.pts[(m + k - 1) % k] + f.pts[m]), 0.5 * (f.pts[m] + f.pts[(m + 1) % k])};
        };
        if (!taken) {
          parts.pts = f.pts;
          parts.flux.resize(k);
          const int plane = f.tag >= 0 ? -1 : -1 - f.tag;
          if (plane >= 0 && body.shared(plane))
            corner_triangles(f, [&](size_t m, const Vec3& a, const Vec3& b, const Vec3& t) {
              const Flux& flux = shared_faces.flux(piece, next_shared++, a, b, t);
              parts.flux[m].insert(parts.flux[m].end(), flux.begin(), flux.end());
            });
          else
            corner_triangles(f, [&](size_t m, const Vec3& a, const Vec3& b, const Vec3& t) {
              add_flux(body, a, b, t, 0.5 * norm(cross(b - a, t - a)) * f.n, plane, parts.flux[m]);
            });
          if (f.tag > i) shared[{piece, i, f.tag}] = parts;
        }
        const double height = dot(c - X[i], f.n);  // of x_i over the face plane (>= 0)
        // The polygon's turning sense about the outward normal: +1 counter-clockwise.
        Vec3 turning{};
        for (size_t m = 0; m < k; ++m) turning += cross(f.pts[m] - c, f.pts[(m + 1) % k] - c);
        const double sense = dot(turning, f.n) >= 0 ? 1.0 : -1.0;
        std::vector<int> id(k);
        for (size_t m = 0; m < k; ++m) id[m] = vertex_id(f.pts[m]);
        if (sub.size() < vertex.size()) sub.resize(vertex.size());
        for (size_t m = 0; m < k; ++m) {
          const auto [before, after] = midpoints(m);
          const Vec3& p = f.pts[m];
          SubCell& s_m = sub[id[m]];
          s_m.flux.insert(s_m.flux.end(), parts.flux[m].begin(), parts.flux[m].end());
          for (const auto& [a, b] : {std::pair{before, p}, std::pair{p, after}}) {
            const double v = 0.5 * norm(cross(a - c, b - c)) * height / 3.0;
            s_m.volume += v;
            s_m.moment += (0.25 * v) * (X[i] + c + a + b);
          }
          // Triangle (x_i, c, mid(m, m+1)) between the sub-cells of corners m and m + 1.
          const int next = id[(m + 1) % k];
          if (next == id[m]) continue;
          // Out of corner m's part, as a side of the tetrahedron (x_i, c, p_m, after) whose base
          // is outward: signed, so it holds when x_i lies on the face (flat tetrahedra) too.
          const Vec3 an = 0.5 * sense * cross(c - X[i], after - X[i]);
          Flux flux;
          add_flux(body, X[i], c, after, an, -1, flux);
          s_m.flux.insert(s_m.flux.end(), flux.begin(), flux.end());
          for (auto& [J, value] : flux) sub[next].flux.push_back({J, -value});
        }
      }
      if (next_shared != shared_faces.first(piece, body.position(i) + 1))
        throw std::logic_error("nem: a cell took another number of shared-face triangles than it recorded");
      double volume = 0;
      for (const SubCell& sk : sub) volume += sk.volume;
      if (!(volume > 0)) throw RunError("nem: empty Voronoi cell at node " + std::to_string(i));
      cell_volume_[i] += volume;
      const double density = materials_[body.material[body.position(i)]].density;
      // A node's density: its pieces' (the same bits as one piece's where they agree), else their
      // mean weighted by its cell in each.
      node_density_[i] = piece == pieces_of[i][0] || density == node_density_[i]
                             ? density
                             : (node_density_[i] * (cell_volume_[i] - volume) + density * volume) / cell_volume_[i];
      // A thin sub-cell (|V_K| < 1e-2 |V_i|: a short cell edge, many left by nearly cospherical
      // nodes; or a corner where the node itself sits) has a surface-to-volume ratio that amplifies
      // round-off in its gradients (seen: 2e-11 in grad x at |V_K| ~ 1e-6 |V_i|), so it is merged
      // into the cell's largest sub-cell; a union of closed smoothing domains is one.
      size_t largest = 0;
      for (size_t k = 0; k < sub.size(); ++k)
        if (sub[k].volume > sub[largest].volume) largest = k;
      const auto merged = [&](size_t k) { return k != largest && sub[k].volume < 1e-2 * volume; };
      for (size_t k = 0; k < sub.size(); ++k) {
        if (!merged(k)) continue;
        SubCell& into = sub[largest];
        into.volume += sub[k].volume;
        into.moment += sub[k].moment;
        into.flux.insert(into.flux.end(), sub[k].flux.begin(), sub[k].flux.end());
      }
      // MSCNI's a (header): point K's gradients g_K' = g_L + sqrt(a) (g_K - g_L), g_L the cell's,
      // so that sum_K |V_LK| e'_K.C e'_K is the header's energy (the cross terms vanish, as
      // sum_K |V_LK| (g_K - g_L) = 0). With a = 1 (g_K' = g_K) a point couples its own nodes only.
      std::map<int, Vec3> cell_flux;
      for (size_t k = 0; k < sub.size(); ++k)
        if (!merged(k))
          for (const auto& [J, value] : sub[k].flux) cell_flux[J] += value;
      for (size_t k = 0; k < sub.size(); ++k) {
        if (merged(k)) continue;
        const SubCell& sk = sub[k];
        std::map<int, Vec3> own_flux;
        for (const auto& [J, value] : sk.flux) own_flux[J] += value;
        points_.x.push_back(sk.moment / sk.volume);
        points_.volume.push_back(sk.volume);
        points_.material.push_back(body.material[body.position(i)]);
        for (const auto& [J, flux] : cell_flux) {
          const auto own = own_flux.find(J);
          if (root_a == 1.0 && own == own_flux.end()) continue;
          const Vec3 g_sub = own == own_flux.end() ? Vec3{} : own->second / sk.volume;
          const Vec3 g_cell = flux / volume;
          points_.node.push_back(J);
          points_.grad.push_back(root_a == 1.0 ? g_sub : g_cell + root_a * (g_sub - g_cell));
        }
        points_.offset.push_back(static_cast<int>(points_.node.size()));
      }
    }

  // Boundary rule for tractions: the owner of each point is the nearest boundary triangle.
  boundary_.N.resize(static_cast<int>(boundary_.x.size()), n);
  boundary_.N.setFromTriplets(boundary_phi.begin(), boundary_phi.end());
  {
    using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CGAL::AABB_triangle_primitive<Kernel, std::vector<Kernel::Triangle_3>::const_iterator>>>;
    const auto triangles = mesh_.boundary_triangles();
    std::vector<Kernel::Triangle_3> tri;
    for (const auto& t : triangles) tri.emplace_back(P3(X[t[0]]), P3(X[t[1]]), P3(X[t[2]]));
    const Tree tree(tri.begin(), tri.end());
    for (const Vec3& q : boundary_.x) {
      auto owner = triangles[tree.closest_point_and_primitive(P3(q)).second - tri.cbegin()];
      std::sort(owner.begin(), owner.end());
      boundary_owner_.push_back(owner);
    }
  }
  finish_setup();
}

InterpolationOperator NemSolver::interpolation(const std::vector<Vec3>& points) const {
  std::vector<Eigen::Triplet<double>> trip;
  Coords phi;
  for (size_t p = 0; p < points.size(); ++p) {
    if (!geo_->coords(points[p], phi))
      throw InputError("interpolation point (" + std::to_string(points[p].x) + ", " + std::to_string(points[p].y) + ", " +
                       std::to_string(points[p].z) + ") lies outside the natural-neighbour domain");
    for (const auto& [J, value] : phi) trip.emplace_back(static_cast<int>(p), J, value);
  }
  InterpolationOperator op(static_cast<int>(points.size()), num_nodes());
  op.setFromTriplets(trip.begin(), trip.end());
  return op;
}

ContinuumSolver::SurfaceRule NemSolver::surface_rule(const std::vector<std::array<int, 3>>& triangles) const {
  std::set<std::array<int, 3>> wanted;
  for (auto t : triangles) {
    std::sort(t.begin(), t.end());
    wanted.insert(t);
  }
  SurfaceRule rule;
  std::vector<Eigen::Triplet<double>> trip;
  for (int p = 0; p < static_cast<int>(boundary_.x.size()); ++p) {
    if (!wanted.count(boundary_owner_[p])) continue;
    const int row = static_cast<int>(rule.x.size());
    for (InterpolationOperator::InnerIterator it(boundary_.N, p); it; ++it) trip.emplace_back(row, static_cast<int>(it.col()), it.value());
    rule.x.push_back(boundary_.x[p]);
    rule.w.push_back(boundary_.w[p]);
  }
  if (rule.x.empty()) throw InputError("nem: a traction group has no triangle on the boundary of the domain");
  rule.N.resize(static_cast<int>(rule.x.size()), num_nodes());
  rule.N.setFromTriplets(trip.begin(), trip.end());
  return rule;
}

std::vector<double> NemSolver::weighted_lumped_mass(const ScalarFunction& alpha) const {
  std::vector<double> m(num_nodes());
  for (int i = 0; i < num_nodes(); ++i) m[i] = alpha(nodes()[i]) * node_density_[i] * cell_volume_[i];
  return m;
}

}  // namespace arlequin::continuum
