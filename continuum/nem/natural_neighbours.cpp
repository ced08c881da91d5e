// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/nem/natural_neighbours.hpp"

#include <algorithm>
#include <array>

namespace arlequin::continuum::nem {

namespace {

// A polygon corner's name: the nodes of the circumsphere it is the centre of, sorted; a corner
// that also passes through Q has -1 first.
using Key = std::array<int, 4>;
struct Corner {
  Key key;
  Vec3 x;
};

Vec3 to_vec(const Kernel::Point_3& p) { return {p.x(), p.y(), p.z()}; }
Vec3 to_vec(const Kernel::Point_2& p) { return {p.x(), p.y(), 0.0}; }

template <class Handle>
void sort_by_node(Handle* v, int n) {
  std::sort(v, v + n, [](const Handle& a, const Handle& b) { return a->info() < b->info(); });
}

// Circumcentres, each from its vertices in node order: of a cell, of (facet, Q), of a face,
// of (edge, q).
Corner cell_corner(Dt3::Cell_handle c) {
  std::array<Dt3::Vertex_handle, 4> v{c->vertex(0), c->vertex(1), c->vertex(2), c->vertex(3)};
  sort_by_node(v.data(), 4);
  return {{v[0]->info(), v[1]->info(), v[2]->info(), v[3]->info()},
          to_vec(CGAL::circumcenter(v[0]->point(), v[1]->point(), v[2]->point(), v[3]->point()))};
}
Corner facet_corner(std::array<Dt3::Vertex_handle, 3> v, const Kernel::Point_3& q) {
  sort_by_node(v.data(), 3);
  return {{-1, v[0]->info(), v[1]->info(), v[2]->info()}, to_vec(CGAL::circumcenter(v[0]->point(), v[1]->point(), v[2]->point(), q))};
}
// In 2D only distances between circumcentres are taken, so no names are needed.
Vec3 face_centre(Dt2::Face_handle f) {
  std::array<Dt2::Vertex_handle, 3> v{f->vertex(0), f->vertex(1), f->vertex(2)};
  sort_by_node(v.data(), 3);
  return to_vec(CGAL::circumcenter(v[0]->point(), v[1]->point(), v[2]->point()));
}
Vec3 edge_centre(std::array<Dt2::Vertex_handle, 2> v, const Kernel::Point_2& q) {
  sort_by_node(v.data(), 2);
  return to_vec(CGAL::circumcenter(v[0]->point(), v[1]->point(), q));
}

// Area of a planar convex polygon whose corners are in turning order (either sense), as a fan
// from its smallest corner key, turning towards the smaller neighbour.
double polygon_area(const std::vector<Corner>& poly) {
  const size_t m = poly.size();
  if (m < 3) return 0.0;
  size_t s = 0;
  for (size_t k = 1; k < m; ++k)
    if (poly[k].key < poly[s].key) s = k;
  const bool forward = poly[(s + 1) % m].key < poly[(s + m - 1) % m].key;
  const auto at = [&](size_t k) -> const Vec3& { return poly[forward ? (s + k) % m : (s + m - k) % m].x; };
  Vec3 twice{};
  for (size_t k = 1; k + 1 < m; ++k) twice += cross(at(k) - at(0), at(k + 1) - at(0));
  return 0.5 * norm(twice);
}

// The terms (node, value), summed per node in the order given, normalised in node order.
bool normalise(std::vector<std::pair<int, double>>& terms, Coords& out) {
  std::stable_sort(terms.begin(), terms.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  out.clear();
  for (const auto& [J, value] : terms) {
    if (out.empty() || out.back().first != J)
      out.push_back({J, value});
    else
      out.back().second += value;
  }
  double sum = 0;
  for (const auto& [J, value] : out) sum += value;
  if (!(sum > 0)) return false;
  for (auto& [J, value] : out) value /= sum;
  return true;
}

// The edges (node pairs) of the given simplices, one representative each, in node-pair order.
template <class Handle>
struct EdgeOf {
  int a, b;  // nodes, a < b
  Handle simplex;
  int i, j;  // local vertex indices
};
template <int N, class Handle>
std::vector<EdgeOf<Handle>> edges_of(const std::vector<Handle>& simplices) {
  std::vector<EdgeOf<Handle>> edges;
  for (const Handle& c : simplices)
    for (int i = 0; i < N; ++i)
      for (int j = i + 1; j < N; ++j) {
        const int a = c->vertex(i)->info(), b = c->vertex(j)->info();
        edges.push_back({std::min(a, b), std::max(a, b), c, i, j});
      }
  const auto pair_less = [](const auto& x, const auto& y) { return std::pair{x.a, x.b} < std::pair{y.a, y.b}; };
  std::sort(edges.begin(), edges.end(), pair_less);
  edges.erase(std::unique(edges.begin(), edges.end(), [](const auto& x, const auto& y) { return x.a == y.a && x.b == y.b; }),
              edges.end());
  return edges;
}

bool contains(const std::vector<Dt2::Face_handle>& sorted, const Dt2::Face_handle& f) {
  return std::binary_search(sorted.begin(), sorted.end(), f);
}

// Numbers the conflict cells of one query in their cells' ConflictIndex, and clears them again.
class ConflictNumbering {
 public:
  explicit ConflictNumbering(const std::vector<Dt3::Cell_handle>& cells) : cells_(cells) {
    for (size_t k = 0; k < cells_.size(); ++k) cells_[k]->info().index = static_cast<int>(k);
  }
  ~ConflictNumbering() {
    for (const auto& c : cells_) c->info().index = -1;
  }
  ConflictNumbering(const ConflictNumbering&) = delete;
  ConflictNumbering& operator=(const ConflictNumbering&) = delete;

 private:
  const std::vector<Dt3::Cell_handle>& cells_;
};

// Sibson's term of the face on the bisector of (v, w) for S_v, of area (3D) or length (2D)
// `measure`: (1/(2 d)) measure n_vw.(w - Q), d the dimension (header).
double sibson_term(double measure, int dim, const Vec3& v, const Vec3& w, const Vec3& q) {
  return measure / (2.0 * dim) * dot(normalized(w - v), w - q);
}

}  // namespace

bool natural_neighbour_coordinates(const Dt3& dt, const Vec3& q, Coordinates kind, Coords& out) {
  out.clear();
  const Kernel::Point_3 Q(q.x, q.y, q.z);
  Dt3::Locate_type lt;
  int li, lj;
  const Dt3::Cell_handle start = dt.locate(Q, lt, li, lj);
  if (lt == Dt3::VERTEX) {
    out.push_back({start->vertex(li)->info(), 1.0});
    return true;
  }
  if (dt.dimension() != 3 || dt.is_infinite(start)) return false;
  std::vector<Dt3::Facet> boundary;
  std::vector<Dt3::Cell_handle> conflict;
  dt.find_conflicts(Q, start, std::back_inserter(boundary), std::back_inserter(conflict));
  for (const auto& c : conflict)
    if (dt.is_infinite(c)) return false;  // Q on the hull or outside it
  std::vector<std::pair<int, double>> terms;
  std::vector<Corner> poly;

  if (kind == Coordinates::laplace) {
    // Per boundary facet: its nodes and the circumcentre of (facet, Q).
    struct BoundaryFacet {
      std::array<Dt3::Vertex_handle, 3> v;
      Corner corner;
    };
    std::vector<BoundaryFacet> facets;
    std::vector<Dt3::Vertex_handle> neighbours;
    for (const auto& [c, i] : boundary) {
      const std::array<Dt3::Vertex_handle, 3> v{c->vertex((i + 1) & 3), c->vertex((i + 2) & 3), c->vertex((i + 3) & 3)};
      facets.push_back({v, facet_corner(v, Q)});
      neighbours.insert(neighbours.end(), v.begin(), v.end());
    }
    sort_by_node(neighbours.data(), static_cast<int>(neighbours.size()));
    neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
    for (const auto& v : neighbours) {
      // The facets at v in turning order: each next one shares the edge (v, x) left by the last.
      std::vector<const BoundaryFacet*> ring;
      for (const auto& f : facets)
        if (std::find(f.v.begin(), f.v.end(), v) != f.v.end()) ring.push_back(&f);
      poly.clear();
      Dt3::Vertex_handle exit{};
      for (size_t k = 0; k < ring.size(); ++k) {
        if (k > 0) {
          const auto next = std::find_if(ring.begin() + k, ring.end(), [&](const BoundaryFacet* f) {
            return std::find(f->v.begin(), f->v.end(), exit) != f->v.end();
          });
          if (next == ring.end()) return false;
          std::swap(ring[k], *next);
        }
        poly.push_back(ring[k]->corner);
        for (const auto& x : ring[k]->v)
          if (x != v && x != exit) {
            exit = x;
            break;
          }
      }
      terms.push_back({v->info(), polygon_area(poly) / norm(to_vec(v->point()) - q)});
    }
    return normalise(terms, out);
  }

  // Sibson: the faces F_vw over the edges of the conflict cells. Per conflict cell its
  // circumcentre, and per boundary facet (cell, i) the circumcentre of (facet, Q).
  const ConflictNumbering numbering(conflict);
  std::vector<Corner> corner(conflict.size());
  for (size_t k = 0; k < conflict.size(); ++k) corner[k] = cell_corner(conflict[k]);
  std::vector<std::array<Corner, 4>> facet(conflict.size());
  for (const auto& [c, i] : boundary)
    facet[c->info().index][i] = facet_corner({c->vertex((i + 1) & 3), c->vertex((i + 2) & 3), c->vertex((i + 3) & 3)}, Q);
  std::vector<Dt3::Cell_handle> ring;
  for (const auto& e : edges_of<4>(conflict)) {
    const Dt3::Vertex_handle v = e.simplex->vertex(e.i), w = e.simplex->vertex(e.j);
    ring.clear();
    Dt3::Cell_circulator cc = dt.incident_cells(e.simplex, e.i, e.j), done = cc;
    do ring.push_back(cc);
    while (++cc != done);
    ring.push_back(ring.front());
    poly.clear();
    for (size_t k = 0; k + 1 < ring.size(); ++k) {
      const int here = ring[k]->info().index, next = ring[k + 1]->info().index;
      if (here >= 0) poly.push_back(corner[here]);
      // The run of conflict cells starts or ends at the boundary facet between here and next.
      if (here >= 0 && next < 0) poly.push_back(facet[here][ring[k]->index(ring[k + 1])]);
      if (here < 0 && next >= 0) poly.push_back(facet[next][ring[k + 1]->index(ring[k])]);
    }
    const double area = polygon_area(poly);
    const Vec3 xv = to_vec(v->point()), xw = to_vec(w->point());
    terms.push_back({v->info(), sibson_term(area, 3, xv, xw, q)});
    terms.push_back({w->info(), sibson_term(area, 3, xw, xv, q)});
  }
  return normalise(terms, out);
}

bool natural_neighbour_coordinates(const Dt2& dt, const Kernel::Point_2& q, Coordinates kind, Coords& out) {
  out.clear();
  Dt2::Locate_type lt;
  int li;
  const Dt2::Face_handle start = dt.locate(q, lt, li);
  if (lt == Dt2::VERTEX) {
    out.push_back({start->vertex(li)->info(), 1.0});
    return true;
  }
  if (dt.dimension() != 2 || lt == Dt2::OUTSIDE_CONVEX_HULL || lt == Dt2::OUTSIDE_AFFINE_HULL) return false;
  std::vector<Dt2::Face_handle> conflict;
  std::vector<Dt2::Edge> boundary;
  dt.get_conflicts_and_boundary(q, std::back_inserter(conflict), std::back_inserter(boundary), start);
  for (const auto& f : conflict)
    if (dt.is_infinite(f)) return false;  // q on the hull
  const Vec3 x_q = to_vec(q);
  std::vector<std::pair<int, double>> terms;

  if (kind == Coordinates::laplace) {
    // Each neighbour v lies on two hole edges; its new Voronoi edge joins their circumcentres with q.
    std::vector<std::pair<Dt2::Vertex_handle, Vec3>> ends;  // (v, circumcentre of a hole edge at v)
    for (const auto& [f, i] : boundary) {
      const Dt2::Vertex_handle a = f->vertex(Dt2::cw(i)), b = f->vertex(Dt2::ccw(i));
      const Vec3 c = edge_centre({a, b}, q);
      ends.push_back({a, c});
      ends.push_back({b, c});
    }
    std::sort(ends.begin(), ends.end(), [](const auto& x, const auto& y) { return x.first->info() < y.first->info(); });
    for (size_t k = 0; k < ends.size(); k += 2) {
      if (k + 1 == ends.size() || ends[k + 1].first != ends[k].first || (k + 2 < ends.size() && ends[k + 2].first == ends[k].first))
        return false;
      const Dt2::Vertex_handle v = ends[k].first;
      terms.push_back({v->info(), norm(ends[k].second - ends[k + 1].second) / norm(to_vec(v->point()) - x_q)});
    }
    return normalise(terms, out);
  }

  // Sibson: the Voronoi edges of the conflict faces' edges, cut where the conflict run ends.
  std::sort(conflict.begin(), conflict.end());
  for (const auto& e : edges_of<3>(conflict)) {
    const int opposite = 3 - e.i - e.j;
    const Dt2::Face_handle other = e.simplex->neighbor(opposite);
    const Dt2::Vertex_handle v = e.simplex->vertex(e.i), w = e.simplex->vertex(e.j);
    const Vec3 end = contains(conflict, other) ? face_centre(other) : edge_centre({v, w}, q);
    const double length = norm(face_centre(e.simplex) - end);
    const Vec3 xv = to_vec(v->point()), xw = to_vec(w->point());
    terms.push_back({v->info(), sibson_term(length, 2, xv, xw, x_q)});
    terms.push_back({w->info(), sibson_term(length, 2, xw, xv, x_q)});
  }
  return normalise(terms, out);
}

}  // namespace arlequin::continuum::nem
