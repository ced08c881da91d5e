// SPDX-License-Identifier: GPL-3.0-or-later
#include "continuum/mesh.hpp"

#include <gmsh.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "common/error.hpp"
#include "common/memory.hpp"

namespace arlequin::continuum {

namespace {

double signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return dot(b - a, cross(c - a, d - a)) / 6.0;
}

// gmsh keeps global state: one mesh at a time, with its own initialize/finalize around it.
std::mutex g_gmsh_mutex;

// General.NumThreads is applied with omp_set_num_threads, for the whole process: the scope puts
// back the thread count it found, or every OpenMP loop after a mesh load (DEM and continuum
// alike) would run on one thread.
struct GmshScope {
  GmshScope() {
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.NumThreads", 1);  // reproducible meshes
  }
  ~GmshScope() {
    gmsh::finalize();
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
  }
#ifdef _OPENMP
  int threads = omp_get_max_threads();  // initialised before the constructor's body runs
#endif
};

// gmsh's .msh reader trusts its input: a malformed file can make it write out of bounds or free
// twice and bring the program down (found by fuzz/fuzz_mesh.cpp). So a .msh is first read by
// the gmsh program in a process of its own (`gmsh FILE -0 -o /dev/null`, the same reader); if that process
// dies of a signal, the file is refused with one line instead of read here. Where the gmsh
// program cannot be started, the file is read here unchecked.
void refuse_if_gmsh_crashes_on(const std::string& path) {
  posix_spawn_file_actions_t quiet;
  posix_spawn_file_actions_init(&quiet);
  posix_spawn_file_actions_addopen(&quiet, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&quiet, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&quiet, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  // The child starts with default signal handling and none blocked (the program's handlers of
  // SIGINT and SIGTERM are not its).
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t all;
  sigfillset(&all);
  posix_spawnattr_setsigdefault(&attr, &all);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  std::string program = "gmsh", file = path, model_only = "-0", out = "-o", sink = "/dev/null", format = "-format", msh = "msh41";
  char* argv[] = {program.data(), file.data(), model_only.data(), out.data(), sink.data(), format.data(), msh.data(), nullptr};
  pid_t child = 0;
  const int spawned = posix_spawnp(&child, "gmsh", &quiet, &attr, argv, environ);
  posix_spawn_file_actions_destroy(&quiet);
  posix_spawnattr_destroy(&attr);
  if (spawned != 0) return;
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status))
    throw InputError("mesh file " + path + ": gmsh crashes reading it (" + strsignal(WTERMSIG(status)) +
                     "): a malformed or truncated .msh; write it again from gmsh");
}

// Renumbers the groups' nodes and tetrahedra (new_node / new_tet: -1 for one that is gone; nodes
// may map onto one another) and drops a group with nothing left.
void renumber_groups(const std::vector<int>& new_node, const std::vector<int>& new_tet, std::vector<PhysicalGroup>& groups) {
  std::vector<PhysicalGroup> kept_groups;
  for (PhysicalGroup& g : groups) {
    std::vector<int> group_nodes, group_tets;
    std::vector<std::array<int, 3>> triangles;
    for (int n : g.nodes)
      if (new_node[n] >= 0) group_nodes.push_back(new_node[n]);
    for (int e : g.tets)
      if (new_tet[e] >= 0) group_tets.push_back(new_tet[e]);
    for (const auto& f : g.triangles)
      if (new_node[f[0]] >= 0 && new_node[f[1]] >= 0 && new_node[f[2]] >= 0)
        triangles.push_back({new_node[f[0]], new_node[f[1]], new_node[f[2]]});
    std::sort(group_nodes.begin(), group_nodes.end());
    group_nodes.erase(std::unique(group_nodes.begin(), group_nodes.end()), group_nodes.end());
    if (group_nodes.empty() || (g.dim == 3 && group_tets.empty()) || (g.dim == 2 && triangles.empty())) continue;
    kept_groups.push_back({g.name, g.dim, std::move(group_nodes), std::move(triangles), std::move(group_tets)});
  }
  groups = std::move(kept_groups);
}

// MeshSource::left_out on the raw arrays; returns the number of tetrahedra dropped.
int leave_out(int npe, const std::function<bool(const std::array<Vec3, 4>&)>& left_out, std::vector<Vec3>& nodes,
              std::vector<int>& tets, std::vector<PhysicalGroup>& groups) {
  const int ntet = static_cast<int>(tets.size()) / npe;
  std::vector<int> new_tet(ntet, -1), new_node(nodes.size(), -1);
  std::vector<int> kept_tets;
  std::vector<Vec3> kept_nodes;
  for (int e = 0; e < ntet; ++e) {
    const int* t = tets.data() + static_cast<std::size_t>(e) * npe;
    if (left_out({nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]})) continue;
    new_tet[e] = static_cast<int>(kept_tets.size()) / npe;
    for (int k = 0; k < npe; ++k) {
      if (new_node[t[k]] < 0) {
        new_node[t[k]] = static_cast<int>(kept_nodes.size());
        kept_nodes.push_back(nodes[t[k]]);
      }
      kept_tets.push_back(new_node[t[k]]);
    }
  }
  const int dropped = ntet - static_cast<int>(kept_tets.size()) / npe;
  if (dropped == 0) return 0;
  renumber_groups(new_node, new_tet, groups);
  nodes = std::move(kept_nodes);
  tets = std::move(kept_tets);
  return dropped;
}

// 1e-9 of the extent of the nodes' bounding box: the distance within which two nodes are one.
double coincidence_tolerance(const std::vector<Vec3>& nodes) {
  Vec3 lo = nodes.front(), hi = nodes.front();
  for (const Vec3& x : nodes) {
    lo = {std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z)};
    hi = {std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z)};
  }
  return 1e-9 * norm(hi - lo);
}

// MeshSource::joined on the raw arrays: the nodes where it holds that lie within
// coincidence_tolerance of one another become one; a quadratic tetrahedron's edge node only with
// both of its edge's vertices (so that an element is joined along whole edges, and a join
// starting between two node planes starts at the next vertex plane). Returns how many nodes
// remain of such sets.
int join_coincident_nodes(int npe, const std::function<bool(const Vec3&)>& joined, std::vector<Vec3>& nodes,
                          std::vector<int>& tets, std::vector<PhysicalGroup>& groups) {
  const double tol = coincidence_tolerance(nodes);
  std::vector<char> in_region(nodes.size());
  for (std::size_t n = 0; n < nodes.size(); ++n) in_region[n] = joined(nodes[n]);
  std::vector<char> edge_node_apart(nodes.size(), 0);
  for (std::size_t e = 0; npe == 10 && e < tets.size() / npe; ++e) {
    const int* t = tets.data() + e * npe;
    for (std::size_t k = 0; k < kTetEdges.size(); ++k)
      if (!(in_region[t[kTetEdges[k][0]]] && in_region[t[kTetEdges[k][1]]])) edge_node_apart[t[4 + k]] = 1;
  }
  std::vector<int> candidates;
  for (int n = 0; n < static_cast<int>(nodes.size()); ++n)
    if (in_region[n] && !edge_node_apart[n]) candidates.push_back(n);
  std::sort(candidates.begin(), candidates.end(), [&](int a, int b) { return nodes[a].x < nodes[b].x; });
  // Each node's first coincident node along x (itself if none comes before it).
  std::vector<int> first(nodes.size());
  for (int n = 0; n < static_cast<int>(nodes.size()); ++n) first[n] = n;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const int a = candidates[i];
    if (first[a] != a) continue;
    for (std::size_t j = i + 1; j < candidates.size() && nodes[candidates[j]].x - nodes[a].x <= tol; ++j) {
      const int b = candidates[j];
      if (first[b] == b && norm(nodes[a] - nodes[b]) <= tol) first[b] = a;
    }
  }
  std::vector<int> new_node(nodes.size(), -1);
  std::vector<Vec3> kept_nodes;
  std::vector<char> merged;
  for (int n = 0; n < static_cast<int>(nodes.size()); ++n) {
    if (first[n] != n) continue;
    new_node[n] = static_cast<int>(kept_nodes.size());
    kept_nodes.push_back(nodes[n]);
    merged.push_back(0);
  }
  int sets = 0;
  for (int n = 0; n < static_cast<int>(nodes.size()); ++n) {
    if (first[n] == n) continue;
    new_node[n] = new_node[first[n]];
    sets += merged[new_node[n]] == 0;
    merged[new_node[n]] = 1;
  }
  if (sets == 0) return 0;
  for (int& t : tets) t = new_node[t];
  std::vector<int> same_tet(tets.size() / npe);  // no tetrahedron changes
  std::iota(same_tet.begin(), same_tet.end(), 0);
  renumber_groups(new_node, same_tet, groups);
  nodes = std::move(kept_nodes);
  return sets;
}

// Where `joined` holds for all three vertices of two boundary triangles that lie in one plane,
// face each other and overlap, two bodies touch there without sharing nodes: their surface meshes
// differ. Returns a point of the first such pair, or nothing.
std::optional<Vec3> unjoined_contact(const Mesh& mesh, const std::function<bool(const Vec3&)>& joined) {
  struct Face {
    Vec3 a, b, c, centroid, normal;
  };
  std::vector<Face> faces;
  for (const auto& t : mesh.boundary_triangles()) {
    const Vec3 &a = mesh.nodes()[t[0]], &b = mesh.nodes()[t[1]], &c = mesh.nodes()[t[2]];
    if (!(joined(a) && joined(b) && joined(c))) continue;
    const Vec3 n = cross(b - a, c - a);
    faces.push_back({a, b, c, (a + b + c) / 3.0, n / norm(n)});
  }
  const double tol = coincidence_tolerance(mesh.nodes());
  // Whether p, in the triangle's plane, lies inside it (its edges included, to the tolerance).
  const auto inside = [tol](const Face& f, const Vec3& p) {
    const Vec3* v[3] = {&f.a, &f.b, &f.c};
    for (int k = 0; k < 3; ++k) {
      const Vec3 edge = *v[(k + 1) % 3] - *v[k];
      if (dot(cross(edge, p - *v[k]), f.normal) < -tol * norm(edge)) return false;
    }
    return true;
  };
  // Two overlapping triangles have centroids closer than the longest edge: a sweep along x.
  double longest = 0.0;
  for (const Face& f : faces) longest = std::max({longest, norm(f.b - f.a), norm(f.c - f.b), norm(f.a - f.c)});
  std::sort(faces.begin(), faces.end(), [](const Face& f, const Face& g) { return f.centroid.x < g.centroid.x; });
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (std::size_t j = i + 1; j < faces.size() && faces[j].centroid.x - faces[i].centroid.x <= longest; ++j) {
      const Face &f = faces[i], &g = faces[j];
      if (dot(f.normal, g.normal) > -1.0 + 1e-9 || std::abs(dot(f.normal, g.centroid - f.centroid)) > tol) continue;
      if (inside(f, g.centroid) || inside(g, f.centroid)) return f.centroid;
    }
  return std::nullopt;
}

}  // namespace

Mesh Mesh::load(const MeshSource& source) {
  namespace fs = std::filesystem;
  if (!fs::exists(source.path)) throw InputError("mesh file not found: " + source.path);
  const std::string ext = fs::path(source.path).extension().string();
  if (ext != ".geo" && ext != ".msh") throw InputError("mesh file must be .geo or .msh: " + source.path);
  if (source.order != 1 && source.order != 2) throw InputError("mesh order must be 1 or 2, got " + std::to_string(source.order));

  if (ext == ".msh") refuse_if_gmsh_crashes_on(source.path);
  std::lock_guard<std::mutex> lock(g_gmsh_mutex);
  GmshScope scope;
  try {
    gmsh::open(source.path);
    if (ext == ".geo") {
      if (source.size > 0.0) {
        // Meshing a body at a size far below its extent would run for hours and then fail to
        // allocate: refuse it first. About one node per h^3 of the bounding box, and at least
        // 1 kB per node for gmsh's mesh and the solver's rows.
        double lo[3], hi[3];
        gmsh::model::getBoundingBox(-1, -1, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
        const double nodes = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) / std::pow(source.size, 3);
        if (const std::string beyond = beyond_memory(nodes * 1e3, "about 1 kB per node"); !beyond.empty()) {
          char text[64];
          std::snprintf(text, sizeof text, " at size %g m makes about %.3g nodes, ", source.size, nodes);
          throw InputError("meshing " + source.path + text + beyond);
        }
        gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
        gmsh::option::setNumber("Mesh.MeshSizeMin", source.size);
        gmsh::option::setNumber("Mesh.MeshSizeMax", source.size);
      }
      // Straight-sided P2 (edge nodes at midpoints): the solvers use affine geometry.
      gmsh::option::setNumber("Mesh.SecondOrderLinear", 1);
      gmsh::model::mesh::generate(3);
      if (source.order == 2) gmsh::model::mesh::setOrder(2);
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError("gmsh could not mesh/read " + source.path + ": " + e.what());
  } catch (const std::string& message) {  // gmsh 4.8 throws its error message as a std::string
    throw InputError("gmsh could not mesh/read " + source.path + ": " + message);
  }

  std::vector<std::size_t> node_tags;
  std::vector<double> coords, param;
  gmsh::model::mesh::getNodes(node_tags, coords, param);
  std::unordered_map<std::size_t, Vec3> tag_xyz;
  for (size_t i = 0; i < node_tags.size(); ++i) tag_xyz[node_tags[i]] = {coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]};

  std::vector<int> types;
  std::vector<std::vector<std::size_t>> elem_tags, elem_nodes;
  gmsh::model::mesh::getElements(types, elem_tags, elem_nodes, 3);
  int order = 0, npe = 0;
  std::vector<std::size_t> tet_tags, tet_node_tags;
  for (size_t k = 0; k < types.size(); ++k) {
    if (types[k] != 4 && types[k] != 11)
      throw InputError(source.path + ": only tetrahedra are supported (gmsh element type " + std::to_string(types[k]) + ")");
    order = types[k] == 4 ? 1 : 2;
    npe = types[k] == 4 ? 4 : 10;
    tet_tags = elem_tags[k];
    tet_node_tags = elem_nodes[k];
  }
  if (types.size() > 1) throw InputError(source.path + ": mixed linear and quadratic tetrahedra");
  if (tet_tags.empty()) throw InputError(source.path + ": the mesh has no tetrahedra (is there a volume?)");

  // Compact numbering of the nodes used by tetrahedra.
  std::unordered_map<std::size_t, int> node_index;
  std::vector<Vec3> nodes;
  std::vector<int> tets;
  tets.reserve(tet_node_tags.size());
  for (std::size_t t : tet_node_tags) {
    auto [it, fresh] = node_index.try_emplace(t, static_cast<int>(nodes.size()));
    if (fresh) {
      const auto xyz = tag_xyz.find(t);
      if (xyz == tag_xyz.end())
        throw InputError(source.path + ": a tetrahedron names node " + std::to_string(t) + ", which the file does not define");
      nodes.push_back(xyz->second);
    }
    tets.push_back(it->second);
  }
  std::unordered_map<std::size_t, int> tet_index;
  for (size_t e = 0; e < tet_tags.size(); ++e) tet_index[tet_tags[e]] = static_cast<int>(e);

  std::vector<PhysicalGroup> groups;
  gmsh::vectorpair dim_tags;
  gmsh::model::getPhysicalGroups(dim_tags);
  for (auto [dim, tag] : dim_tags) {
    if (dim != 2 && dim != 3) continue;
    PhysicalGroup g;
    g.dim = dim;
    gmsh::model::getPhysicalName(dim, tag, g.name);
    if (g.name.empty()) g.name = std::to_string(tag);
    std::vector<std::size_t> gtags;
    std::vector<double> gcoords;
    gmsh::model::mesh::getNodesForPhysicalGroup(dim, tag, gtags, gcoords);
    for (std::size_t t : gtags) {
      auto it = node_index.find(t);
      if (it != node_index.end()) g.nodes.push_back(it->second);
    }
    std::sort(g.nodes.begin(), g.nodes.end());
    g.nodes.erase(std::unique(g.nodes.begin(), g.nodes.end()), g.nodes.end());
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    for (int ent : entities) {
      std::vector<int> etypes;
      std::vector<std::vector<std::size_t>> etags, enodes;
      gmsh::model::mesh::getElements(etypes, etags, enodes, dim, ent);
      for (size_t k = 0; k < etypes.size(); ++k) {
        if (dim == 3) {
          for (std::size_t t : etags[k]) {
            const auto tet = tet_index.find(t);
            if (tet == tet_index.end())
              throw InputError(source.path + ": physical group '" + g.name + "' holds element " + std::to_string(t) +
                               ", which is not one of the mesh's tetrahedra");
            g.tets.push_back(tet->second);
          }
        } else {
          if (etypes[k] != 2 && etypes[k] != 9)
            throw InputError(source.path + ": physical group '" + g.name + "' holds surface elements of gmsh type " +
                             std::to_string(etypes[k]) + " (expected triangles, types 2 and 9)");
          const size_t per = etypes[k] == 2 ? 3 : 6;
          auto volume_node = [&](std::size_t t) {
            const auto node = node_index.find(t);
            if (node == node_index.end())
              throw InputError(source.path + ": physical group '" + g.name + "' has a triangle on node " +
                               std::to_string(t) + ", which no tetrahedron uses");
            return node->second;
          };
          for (size_t f = 0; f < etags[k].size(); ++f)
            g.triangles.push_back({volume_node(enodes[k][per * f]), volume_node(enodes[k][per * f + 1]),
                                   volume_node(enodes[k][per * f + 2])});
        }
      }
    }
    groups.push_back(std::move(g));
  }

  // gmsh's P2 edge order differs from kTetEdges: place each edge node by its position.
  if (order == 2) {
    const int ntet = static_cast<int>(tets.size()) / npe;
    for (int e = 0; e < ntet; ++e) {
      int* t = tets.data() + static_cast<size_t>(e) * npe;
      std::array<int, 6> edge{-1, -1, -1, -1, -1, -1};
      const double h = norm(nodes[t[1]] - nodes[t[0]]) + norm(nodes[t[2]] - nodes[t[0]]) + norm(nodes[t[3]] - nodes[t[0]]);
      for (int m = 4; m < 10; ++m)
        for (int k = 0; k < 6; ++k) {
          const Vec3 mid = 0.5 * (nodes[t[kTetEdges[k][0]]] + nodes[t[kTetEdges[k][1]]]);
          if (norm(nodes[t[m]] - mid) <= 1e-9 * h) edge[k] = t[m];
        }
      if (std::find(edge.begin(), edge.end(), -1) != edge.end())
        throw InputError(source.path + ": quadratic tetrahedron " + std::to_string(e) +
                         " has an edge node away from its edge midpoint (curved elements are not supported)");
      std::copy(edge.begin(), edge.end(), t + 4);
    }
  }
  int dropped = 0;
  if (source.left_out) {
    dropped = leave_out(npe, source.left_out, nodes, tets, groups);
    if (tets.empty()) throw InputError(source.path + ": every tetrahedron lies in " + source.left_out_name);
  }
  const int joined = source.joined ? join_coincident_nodes(npe, source.joined, nodes, tets, groups) : 0;
  Mesh mesh(order, std::move(nodes), std::move(tets), std::move(groups));
  mesh.tets_left_out_ = dropped;
  mesh.nodes_joined_ = joined;
  // Joined bodies share every node of the face between them, which is then inside the mesh. Two
  // faces still touching there have different surface meshes, and would be joined at points only.
  if (source.joined)
    if (const std::optional<Vec3> x = unjoined_contact(mesh, source.joined)) {
      std::ostringstream msg;
      msg << source.path << ": two bodies touch at (" << x->x << ", " << x->y << ", " << x->z << "), in "
          << source.joined_name << ", without nodes to join: their surface meshes differ there (joining needs the "
          << "same surface mesh on both, e.g. transfinite)";
      throw InputError(msg.str());
    }
  return mesh;
}

Mesh::Mesh(int order, std::vector<Vec3> nodes, std::vector<int> tets, std::vector<PhysicalGroup> groups)
    : order_(order), nodes_(std::move(nodes)), tets_(std::move(tets)), groups_(std::move(groups)) {
  if (num_tets() == 0) throw InputError("mesh has no tetrahedra");
  double lmax = 0.0;
  for (int e = 0; e < num_tets(); ++e) lmax = std::max(lmax, norm(nodes_[tet(e)[1]] - nodes_[tet(e)[0]]));
  for (int e = 0; e < num_tets(); ++e) {
    const double v = tet_volume(e);
    if (v <= 1e-12 * lmax * lmax * lmax) {
      std::ostringstream msg;
      const Vec3& c = nodes_[tet(e)[0]];
      msg << (v < 0 ? "inverted" : "flat") << " tetrahedron " << e << " (volume " << v << ") at (" << c.x << ", "
          << c.y << ", " << c.z << ")";
      throw InputError(msg.str());
    }
  }
  for (const auto& g : groups_) {
    if (g.nodes.empty() || (g.dim == 3 && g.tets.empty()) || (g.dim == 2 && g.triangles.empty()))
      throw InputError("physical group '" + g.name + "' is empty");
  }
}

double Mesh::tet_volume(int e) const {
  const int* t = tet(e);
  return signed_volume(nodes_[t[0]], nodes_[t[1]], nodes_[t[2]], nodes_[t[3]]);
}

double Mesh::volume() const {
  double v = 0.0;
  for (int e = 0; e < num_tets(); ++e) v += tet_volume(e);
  return v;
}

bool Mesh::has_group(const std::string& name) const {
  return std::any_of(groups_.begin(), groups_.end(), [&](const PhysicalGroup& g) { return g.name == name; });
}

const PhysicalGroup& Mesh::group(const std::string& name) const {
  for (const auto& g : groups_)
    if (g.name == name) return g;
  std::string known;
  for (const auto& g : groups_) known += (known.empty() ? "" : ", ") + g.name;
  throw InputError("mesh has no physical group '" + name + "' (known: " + (known.empty() ? "none" : known) + ")");
}

std::vector<std::array<int, 3>> Mesh::boundary_triangles() const {
  std::map<std::array<int, 3>, std::pair<std::array<int, 3>, int>> count;
  for (int e = 0; e < num_tets(); ++e)
    for (const auto& f : kTetFaces) {
      std::array<int, 3> tri{tet(e)[f[0]], tet(e)[f[1]], tet(e)[f[2]]};
      std::array<int, 3> key = tri;
      std::sort(key.begin(), key.end());
      auto& entry = count[key];
      entry.first = tri;
      ++entry.second;
    }
  std::vector<std::array<int, 3>> out;
  for (const auto& [key, entry] : count)
    if (entry.second == 1) out.push_back(entry.first);
  return out;
}

}  // namespace arlequin::continuum
