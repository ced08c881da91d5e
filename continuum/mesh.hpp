// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh: a tetrahedral mesh with named physical groups, read or generated through the gmsh C++ API.
// Contract:
//  - `Mesh::load` meshes a .geo file in-process (element size `size`, order 1 or 2) or reads a
//    ready .msh (its own order). Only tetrahedra are kept; nodes not used by a tetrahedron drop.
//  - Tetrahedra are stored with positive volume, vertices first; quadratic tetrahedra are
//    renumbered to the fixed edge order of `kTetEdges` (gmsh's own order is not assumed: every
//    edge node is matched to the midpoint of its two vertices, which also rejects curved P2).
//  - `MeshSource::left_out` (optional) drops every tetrahedron it holds for, given its four
//    vertices (an Arlequin coupling's pure-DEM zone: whether the tetrahedron lies in it, which for
//    a convex zone is whether its vertices do), then the nodes only those used; physical groups
//    keep what remains of them, and a group with nothing left is dropped.
//  - `MeshSource::joined` (optional, a convex region) joins bodies meshed apart: nodes it holds
//    for that coincide (within 1e-9 of the mesh's extent) become one node, after left_out (a P2
//    edge node only if it holds for both of the edge's vertices: whole edges are joined). Two
//    arms meshed as separate volumes become one body there (the uncracked part of a specimen).
//    Two bodies whose boundary faces still touch inside it (in one plane, facing each other,
//    overlapping) have different surface meshes there and would be held at points only: an
//    InputError (joining needs the same surface mesh on both, e.g. transfinite).
//  - Problems are InputError: unreadable file, no tetrahedra, inverted or flat tetrahedron,
//    empty physical group, unknown group name (the message lists the known ones).
#pragma once
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "common/vec3.hpp"

namespace arlequin::continuum {

struct MeshSource {
  std::string path;   // .geo (meshed here) or .msh
  double size = 0.0;  // target element size for .geo; 0 keeps the sizes written in the file
  int order = 1;      // 1 or 2, for .geo
  std::function<bool(const std::array<Vec3, 4>&)> left_out;  // optional, on a tetrahedron's vertices: see the contract
  std::string left_out_name = "the left-out region";  // for the error when it holds everything
  std::function<bool(const Vec3&)> joined{};  // optional, on a node's position: see the contract
  std::string joined_name = "the joined region";  // for the error when the bodies' faces differ there
};

// Edge k of a tetrahedron joins vertices kTetEdges[k]; node 4+k of a P2 tetrahedron sits on it.
inline constexpr std::array<std::array<int, 2>, 6> kTetEdges{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
// Face k of a tetrahedron is the triangle of vertices kTetFaces[k], turning counter-clockwise
// about its outward normal when the tetrahedron's volume is positive (as Mesh stores them).
inline constexpr std::array<std::array<int, 3>, 4> kTetFaces{{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

struct PhysicalGroup {
  std::string name;
  int dim = 0;                                 // 2: boundary part, 3: region
  std::vector<int> nodes;                      // sorted, all nodes of its entities (P2 included)
  std::vector<std::array<int, 3>> triangles;   // dim 2: vertex triples
  std::vector<int> tets;                       // dim 3: tetrahedron indices
};

class Mesh {
 public:
  static Mesh load(const MeshSource& source);
  // Builds from arrays (tests, generated meshes); checks orientation like `load`.
  Mesh(int order, std::vector<Vec3> nodes, std::vector<int> tets, std::vector<PhysicalGroup> groups);

  int order() const { return order_; }
  int nodes_per_tet() const { return order_ == 1 ? 4 : 10; }
  int num_nodes() const { return static_cast<int>(nodes_.size()); }
  int num_tets() const { return static_cast<int>(tets_.size()) / nodes_per_tet(); }
  const std::vector<Vec3>& nodes() const { return nodes_; }
  const int* tet(int e) const { return tets_.data() + static_cast<size_t>(e) * nodes_per_tet(); }
  double tet_volume(int e) const;
  double volume() const;

  const std::vector<PhysicalGroup>& groups() const { return groups_; }
  bool has_group(const std::string& name) const;
  const PhysicalGroup& group(const std::string& name) const;  // InputError if unknown
  // Triangles (vertex triples) on the outer boundary: faces owned by one tetrahedron only.
  std::vector<std::array<int, 3>> boundary_triangles() const;
  int tets_left_out() const { return tets_left_out_; }  // by MeshSource::left_out
  int nodes_joined() const { return nodes_joined_; }      // by MeshSource::joined: nodes that were two or more

 private:
  int order_;
  std::vector<Vec3> nodes_;
  std::vector<int> tets_;
  std::vector<PhysicalGroup> groups_;
  int tets_left_out_ = 0;
  int nodes_joined_ = 0;
};

}  // namespace arlequin::continuum
