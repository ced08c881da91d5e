// SPDX-License-Identifier: GPL-3.0-or-later
// What a run advances: the DEM alone, the continuum alone, both side by side, or both coupled
// by the Arlequin method, behind one interface that build_scene chooses once. The runner's loop is
// model.step(dt); rows read energies() and monitor(), frames write_fields().
#pragma once
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

#include "common/fields_writer.hpp"
#include "common/json.hpp"
#include "common/state_archive.hpp"
#include "dem/dem_model.hpp"

namespace arlequin::app {

class ContinuumPart;
struct OutputPlan;

// The energies of a row, J: the DEM's terms (zeros without DEs), the continuum's kinetic and
// strain energy and what its damping dissipated (0 without one) and the work of the multiplier
// forces (0 uncoupled).
struct SceneEnergies {
  dem::Energies dem;
  double continuum_kinetic = 0.0, continuum_strain = 0.0;
  double coupling_work = 0.0;
  double continuum_dissipated = 0.0;
  double total() const { return dem.total() + continuum_kinetic + continuum_strain; }
};

// The coupling's monitor after the last step (at t = 0: after the initial projection).
struct CouplingMonitorValues {
  double constraint_residual = 0.0;    // |G_d v_d + G_c v_c| / |G_d v_d|
  double velocity_mismatch_rms = 0.0;  // over the coupled DEs of |v_p - (N v_c)(x_p)|, m/s
  double velocity_mismatch_max = 0.0;  // m/s
};

// Bonds that broke where the coupling weighted them since the last look (a coupled scene only):
// one line for the user, and whether the case stops the run for it
// (coupling.on_damage_in_overlap).
struct OverlapDamageReport {
  std::string description;  // of the first such break
  std::size_t breaks = 0;   // all of them since the last look
  bool stop = true;
  bool held = false;        // the bonds were held intact, not broken
};

// What SceneModel::relax did: its steps and sum m |P (a - a_target)|^2 before and after, J/s^2.
struct RelaxationReport {
  int steps = 0;
  double imbalance_before = 0.0, imbalance_after = 0.0;
  int free_rigid_motions = 0;  // rigid motions no held dof stops, their share of the target left out
  double fracture = 0.0;  // J: dissipated by the links' damage as it relaxed (in E_fracture)
};

class SceneModel {
 public:
  virtual ~SceneModel() = default;
  virtual void step(double dt) = 0;               // one explicit step of everything it holds
  virtual double critical_time_step() const = 0;  // s; of the coupled system when coupled
  virtual SceneEnergies energies() const = 0;
  virtual std::optional<CouplingMonitorValues> monitor() const = 0;  // nullopt: nothing coupled
  virtual bool coupled() const { return false; }  // whether monitor() has values, without computing them
  virtual std::optional<OverlapDamageReport> damage_in_overlap() { return std::nullopt; }
  // The frame's fields: particles (and bonds, as the plan asks) and the continuum's.
  virtual void write_fields(FieldsWriter& fields, const OutputPlan& plan) const = 0;
  // Checkpoint (app/checkpoint.hpp): every state a step carries to the next, of every model it
  // holds; load_state on the model built again from the same case (StateMismatch if it is not).
  virtual void save_state(StateArchive& archive) const = 0;
  virtual void load_state(const StateArchive& archive) = 0;
  // A zone that moves (app/zone_move.hpp) sets the state of a model built for the new zone
  // from the one it replaces, through save_state's archive, between two steps where
  // accepts_set_state(); resume_from_set_state() then makes the forces and the coupling's
  // constraint those of that state. Only a coupled model follows a zone.
  virtual bool accepts_set_state() const { return false; }
  virtual void resume_from_set_state() { throw std::logic_error("only a coupled scene's state is set from outside"); }
  // |G_d u_d + G_c u_c| / |G_d u_d| (coupling/coupled_model.hpp), 0 uncoupled: how far a state
  // set from outside is off the displacement constraint, which the coupling keeps as it finds it.
  virtual double displacement_residual() const { return 0.0; }
  // Kinetic damping where accepts_set_state() (a moved zone's settling, app/zone_move.hpp): the
  // DEs `ids` stop and the velocities go back onto the coupling's constraint; the energy this
  // takes out is booked (coupling/coupled_model.hpp: CoupledModel::arrest). Returns the DEs' part
  // of it, J.
  virtual double arrest(std::span<const std::uint32_t> ids) { throw std::logic_error("only a coupled scene's zone settles"); }
  // Dynamic relaxation of a state set from outside toward the constrained accelerations of
  // `target` (save_accelerations' entries, rows as this model's; coupling/coupled_model.hpp:
  // CoupledModel::relax): the displacements move, the motion stays.
  virtual void save_accelerations(StateArchive& archive) const { throw std::logic_error("only a coupled scene relaxes"); }
  virtual RelaxationReport relax(double dt, int steps, const StateArchive& target) { throw std::logic_error("only a coupled scene relaxes"); }
  virtual std::string summary() const { return ""; }  // lines printed at start (the coupling's)
  virtual void describe(Json& counts) const {}       // summary.json counts of its own
};

// The DEM (its DEs, if any) and the continuum (if not null) each with its own step; the
// coupled model comes from ContinuumPart::couple.
std::unique_ptr<SceneModel> uncoupled_scene_model(dem::DemModel& dem, ContinuumPart* continuum);

// Shared by the models that hold DEs: the particles as points, the bonds as lines (plan).
void write_dem_fields(const dem::DemModel& dem, FieldsWriter& fields, const OutputPlan& plan);

}  // namespace arlequin::app
