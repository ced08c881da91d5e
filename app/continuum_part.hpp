// SPDX-License-Identifier: GPL-3.0-or-later
// The scene's continuum, read from the case file's `continuum:` section: the solver chosen by
// name from the registry (fe, nem), its mesh, material, boundary conditions and analysis.
// The one adapter between the application and continuum/ and coupling/: its header names no
// continuum type, so scenes without a continuum never start PETSc or read a mesh. The
// sections are read into plain settings first (continuum_part.cpp: read_continuum,
// read_coupling), then the solver and the coupling are built from them.
//
// Its keys (continuum:, coupling:) are declared beside their reader in continuum_part.cpp;
// `arlequin schema continuum` and `arlequin schema coupling` print them.
// Coupled to the DEM by the Arlequin method (coupling/) when the case has a `coupling:` section.
// The overlap also cuts both models to their domains: tetrahedra with every vertex in the
// pure-DEM zone are left out of the mesh here, and the scene does not create the sample's DEs
// beyond the overlap (in_dem_domain), so a mesh and a sample may each cover the whole body.
// Then couple() gives the model that advances both together (the coupling finalizes the DEM).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/scene_model.hpp"
#include "common/json.hpp"
#include "common/schema.hpp"
#include "common/vec3.hpp"

namespace arlequin {
class CaseNode;
namespace dem {
class DemModel;
}
class FieldsWriter;
namespace continuum {
class ContinuumSolver;
}
}  // namespace arlequin

namespace arlequin::app {

// coupling.overlap.band.follow: a DEM band that moves along its direction to keep the crack of
// the DEM's cohesive interface inside it (app/zone_move.hpp, docs/theory.md#moving-zone).
struct BandFollow {
  double margin = 0.0;  // m: it moves when the damage front comes within this of `to`
  double ahead = 0.0;   // m: the new `to` is the damage front plus this (at most `until`)
  double behind = INFINITY;  // m: the new `from` is the crack tip less this (never less than before); inf: it stays
  double until = 0.0;   // m: the furthest `to`
  int axis = 2, along = 0;                                 // the band's (0, 1, 2)
  double center = 0.0, from = 0.0, to = 0.0, width = 0.0;  // m, the band as read
  // After a move of `from`, the DEs from it to settle_length beyond it are kinetically damped
  // over settle_time (app/zone_move.hpp: BandSettling; 0 by default).
  double settle_time = 0.0;    // s
  double settle_length = 0.0;  // m
  // After a move of `from`, this many pseudo-time steps of dynamic relaxation toward the
  // accelerations before it (SceneModel::relax).
  int relax_steps = 0;
  std::string where;                         // file:line of the follow section
};

class ContinuumPart {
 public:
  // Builds the continuum, cut by the coupling's overlap when `coupling` is given; InputError for
  // any problem (also when this build has no continuum).
  static std::unique_ptr<ContinuumPart> read(CaseNode section, std::optional<CaseNode> coupling,
                                             const std::string& extra_petsc_options);
  // The keys of continuum: and coupling: (none in a build without a continuum).
  static std::span<const SchemaSection> schema();
  virtual ~ContinuumPart() = default;

  virtual continuum::ContinuumSolver& solver() = 0;
  // Where DEs may be: the pure-DEM zone and the overlap of the coupling (everywhere if uncoupled).
  virtual bool in_dem_domain(const Vec3& x) const = 0;
  // The coupling's band that follows a crack, if the case has one.
  virtual const std::optional<BandFollow>& band_follow() const = 0;
  // For a zone that moves (app/zone_move.hpp). The nodes' reference positions; per node, on
  // which side of the plane x[axis] = center its elements lie (bit 0: one below, bit 1: one
  // above, by their centroids), which tells the two faces of a slit apart; and at each reference
  // point, its shape functions' non-zero values (node, N), none where it lies outside the mesh.
  virtual const std::vector<Vec3>& node_positions() const = 0;
  virtual double dem_weight(const Vec3& x) const = 0;  // the coupling's alpha_d at x (0 uncoupled)
  // The smallest coordinate along `axis` at or beyond x of an element corner (vertex) node:
  // where a band may end so that a join from there holds whole elements (+inf: none).
  virtual double vertex_plane_from(int axis, double x) const = 0;
  virtual std::vector<std::uint8_t> node_sides(int axis, double center) const = 0;
  virtual bool prescribed(std::size_t dof) const = 0;  // whether a support or a driven strip sets this dof
  using ShapeValues = std::vector<std::vector<std::pair<int, double>>>;
  virtual ShapeValues shape_values(const std::vector<Vec3>& points) const = 0;
  // f_int(u) (3 values a node) of the continuum as weighted: K u for small strains.
  virtual void internal_force(const std::vector<double>& u, std::vector<double>& f) const = 0;
  // Per dof, the diagonal of the continuum's stiffness at the undeformed state, as weighted (N/m).
  virtual std::vector<double> stiffness_diagonal() const = 0;
  // The model that steps `dem` (built, with its boundary conditions, not finalized) and this
  // continuum together, coupled as the coupling section given to `read` says; it finalizes
  // the DEM. Its errors name their key in that section. std::invalid_argument for
  // contradictory DEM boundary conditions.
  virtual std::unique_ptr<SceneModel> couple(dem::DemModel& dem) = 0;
  virtual bool is_static() const = 0;
  virtual double critical_time_step() const = 0;  // of the continuum alone, s
  virtual void step(double dt) = 0;               // one explicit step of the continuum alone
  // Sets every node's displacement to H X (rows of H given), before coupling or stepping.
  virtual void set_affine_displacement(const std::array<Vec3, 3>& H) = 0;
  virtual void solve_static() = 0;     // equilibrium at the current time
  virtual bool has_group(const std::string& name) const = 0;
  virtual Vec3 mean_displacement(const std::string& group) const = 0;  // over the group's nodes, m
  virtual Vec3 mean_velocity(const std::string& group) const = 0;      // m/s
  // Force that supports and loads apply to the group's nodes, -(f_ext - f_int) summed, N.
  virtual Vec3 reaction_on(const std::string& group) const = 0;
  // Over the nodes: {max |u - H X|, max |H X|} (m), H by rows (patch tests).
  virtual std::array<double, 2> affine_deviation(const std::array<Vec3, 3>& H) const = 0;
  virtual double kinetic_energy() const = 0;
  virtual double strain_energy() const = 0;
  // Work of the tractions and moving supports over the steps of step(), J, and velocity
  // Verlet's shadow correction at step dt (ContinuumSolver::external_work, verlet_correction).
  virtual double external_work() const = 0;
  virtual double verlet_correction(double dt) const = 0;
  virtual double dissipated() const = 0;  // by the continuum's damping, J
  // The continuum's state alone (an uncoupled scene; a coupled one saves it with the coupling).
  virtual void save_state(StateArchive& archive) const = 0;
  virtual void load_state(const StateArchive& archive) = 0;
  virtual void write_fields(FieldsWriter& fields) const = 0;
  virtual void describe(Json& counts) const = 0;
};

}  // namespace arlequin::app
