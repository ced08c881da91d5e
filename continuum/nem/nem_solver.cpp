// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/nem/nem_solver.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

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

// One body of the mesh: a connected set of tetrahedra, convex, sharing no node with another.
struct Body {
  std::vector<int> nodes;  // mesh node ids
  Dt3 dt;                  // its nodes (vertex info: mesh node id)
  std::vector<Plane> planes;
  Polyhedron domain;  // its bounding box clipped by its planes (face tag -1 - k: plane k)
};

struct NemSolver::Geometry {
  Coordinates kind = Coordinates::sibson;
  double tol = 0;  // length: "on a plane" for nodes and points
  std::vector<Body> bodies;
  const std::vector<Vec3>* x = nullptr;

  // Natural-neighbour coordinates on domain plane k of body b (p projected onto it).
  bool on_plane(const Body& b, int k, const Vec3& p, Coords& out) const {
    return nem::natural_neighbour_coordinates(b.planes[k].dt, b.planes[k].local(p), kind, out);
  }

  // Shape functions at any point of the closed domain: those of the first body holding it (the
  // bodies share no node, so a point on a face two bodies share takes one body's); false
  // outside every body.
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

// The bodies of the mesh: its tetrahedra joined through shared nodes (union-find); each body's
// nodes in increasing order, bodies by their first node.
std::vector<std::vector<int>> mesh_bodies(const Mesh& mesh) {
  std::vector<int> parent(mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) parent[i] = i;
  const auto root = [&parent](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (int e = 0; e < mesh.num_tets(); ++e)
    for (int a = 1; a < mesh.nodes_per_tet(); ++a) {
      const int r0 = root(mesh.tet(e)[0]), r1 = root(mesh.tet(e)[a]);
      if (r0 != r1) parent[std::max(r0, r1)] = std::min(r0, r1);
    }
  std::map<int, std::vector<int>> by_root;
  for (int i = 0; i < mesh.num_nodes(); ++i) by_root[root(i)].push_back(i);
  std::vector<std::vector<int>> bodies;
  for (auto& [r, nodes] : by_root) bodies.push_back(std::move(nodes));
  return bodies;
}

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

  // Bodies, and per body its domain planes (the distinct planes of its boundary triangles), its
  // tessellations and its domain as a polyhedron.
  const std::vector<std::vector<int>> body_nodes = mesh_bodies(mesh_);
  std::vector<int> body_of(n);
  g.bodies.resize(body_nodes.size());
  for (size_t k = 0; k < body_nodes.size(); ++k) {
    g.bodies[k].nodes = body_nodes[k];
    for (int i : body_nodes[k]) body_of[i] = static_cast<int>(k);
  }
  const std::string several = g.bodies.size() > 1 ? " of body " : "";
  for (const auto& tri : mesh_.boundary_triangles()) {
    Body& body = g.bodies[body_of[tri[0]]];
    const Vec3 nn = normalized(cross(X[tri[1]] - X[tri[0]], X[tri[2]] - X[tri[0]]));
    const double d = dot(nn, X[tri[0]]);
    const bool known = std::any_of(body.planes.begin(), body.planes.end(),
                                   [&](const Plane& p) { return norm(p.n - nn) < 1e-9 && std::abs(p.d - d) < g.tol; });
    if (!known) {
      Plane p;
      p.n = nn;
      p.d = d;
      body.planes.push_back(std::move(p));
    }
  }
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
                           " lies outside the plane of a boundary face); only convex bodies are supported");
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
    const Vec3 a = blo - 0.01 * L * Vec3{1, 1, 1}, b = bhi + 0.01 * L * Vec3{1, 1, 1};
    body.domain = box_polyhedron(a, b, -1000000);
    for (int m = 0; m < static_cast<int>(body.planes.size()); ++m)
      clip(body.domain, body.planes[m].n, body.planes[m].d, -1 - m, 1e-12 * L);
    for (const PolyFace& f : body.domain)
      if (f.tag == -1000000) throw InputError("nem: the mesh boundary does not close a convex domain" + which);
  }

  // Node materials: that of the first tetrahedron holding the node.
  std::vector<int> node_material(n, -1);
  for (int e = 0; e < mesh_.num_tets(); ++e)
    for (int a = 0; a < mesh_.nodes_per_tet(); ++a)
      if (node_material[mesh_.tet(e)[a]] < 0) node_material[mesh_.tet(e)[a]] = tet_material_[e];
  node_density_.resize(n);
  for (int i = 0; i < n; ++i) node_density_[i] = materials_[node_material[i]].density;

  // Integration (see the header): per node i its clipped Voronoi cell V_i, cut into one
  // sub-cell per cell vertex v: the union of the tetrahedra (x_i, face centre, edge midpoint, v).
  // One integration point per sub-cell, b_J = (int phi_J n dS over its surface) / volume.
  using Flux = std::vector<std::pair<int, Vec3>>;  // (J, int phi_J n dS)
  std::vector<Dt3::Vertex_handle> vh(n);
  for (const Body& body : g.bodies)
    for (auto v = body.dt.finite_vertices_begin(); v != body.dt.finite_vertices_end(); ++v) vh[v->info()] = v;
  Coords phi;
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
  std::map<std::pair<int, int>, FaceParts> shared;
  struct SubCell {
    double volume = 0;
    Vec3 moment{};
    Flux flux;
  };
  cell_volume_.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    const Body& body = g.bodies[body_of[i]];
    Polyhedron cell = body.domain;
    std::vector<Dt3::Vertex_handle> adj;
    body.dt.finite_adjacent_vertices(vh[i], std::back_inserter(adj));
    for (const auto& v : adj) {
      const int j = v->info();
      const Vec3 nn = normalized(X[j] - X[i]);
      clip(cell, nn, dot(nn, 0.5 * (X[i] + X[j])), j, 1e-12 * L);
    }
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
      const auto from = f.tag >= 0 && f.tag < i ? shared.find({f.tag, i}) : shared.end();
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
        for (size_t m = 0; m < k; ++m) {
          const auto [before, after] = midpoints(m);
          const Vec3& p = f.pts[m];
          add_flux(body, c, before, p, 0.5 * norm(cross(before - c, p - c)) * f.n, plane, parts.flux[m]);
          add_flux(body, c, p, after, 0.5 * norm(cross(p - c, after - c)) * f.n, plane, parts.flux[m]);
        }
        if (f.tag > i) shared[{i, f.tag}] = parts;
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
    double volume = 0;
    for (const SubCell& sk : sub) volume += sk.volume;
    if (!(volume > 0)) throw RunError("nem: empty Voronoi cell at node " + std::to_string(i));
    cell_volume_[i] = volume;
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
      points_.material.push_back(node_material[i]);
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
