// SPDX-License-Identifier: GPL-3.0-or-later
// build_scene: a case file read section by section (scene_readers.hpp), then the time step.
#include "app/scene.hpp"
#include "app/zone_move.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "app/case_schema.hpp"
#include "app/scene_readers.hpp"
#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/schema.hpp"

namespace arlequin::app {
namespace {

// ---- The top-level keys and time (common/schema.hpp) ----

constexpr KeyDoc top_keys[] = {
    {"name", KeyType::string, "", {}, "(the case folder's name)", "the case's name, used for the default output folder"},
    {"units", KeyType::choice, "", {}, "SI", "unit system of every number in the case", "SI"},
    {"time", KeyType::section, "", {}, "", "the time span and step"},
    {"dem", KeyType::section, "", {}, "(none)", "the discrete elements: sample, bonds, contact, damping, failure"},
    {"continuum", KeyType::section, "", {}, "(none)", "a continuum model (see continuum)"},
    {"coupling", KeyType::section, "", {}, "(none)", "Arlequin coupling of the DEM zone and the continuum (see coupling)"},
    {"groups", KeyType::list, "", {}, "(none)", "named sets of DEs, by region or by index"},
    {"boundary", KeyType::list, "", {}, "(none)", "DEM boundary conditions, one per group"},
    {"initial", KeyType::list, "", {}, "(none)", "initial velocities of groups of DEs"},
    {"initial_strain", KeyType::section, "", {}, "(none)", "a uniform initial displacement gradient of both models"},
    {"pulse", KeyType::section, "", {}, "(none)", "an initial velocity pulse travelling along a direction"},
    {"sensors", KeyType::list, "", {}, "(none)", "series.csv columns: forces, displacements, velocities, energies of groups"},
    {"checks", KeyType::list, "", {}, "(none)", "acceptance checks of series columns against references"},
    {"output", KeyType::section, "", {}, "(defaults)", "where and how often results are written"},
};
constexpr KeyDoc time_keys[] = {
    {"end", KeyType::number, "s", Range::positive(), "", "simulated time at which the run ends"},
    {"dt", KeyType::number_or_auto, "s", Range::positive(), "auto", "time step; auto: safety x the critical step, a larger one is refused"},
    {"safety", KeyType::number, "1", Range::open_between(0, 1), "0.3", "fraction of the critical time step taken by dt: auto"},
};
constexpr SchemaSection top_sections[] = {
    {"", "a case file's top-level sections", top_keys},
    {"time", "time span and step", time_keys},
};

// Finalizes the DEM and chooses the scene's model: coupled when the case couples the DEM to the
// continuum (the coupling finalizes the DEM), else each with its own step. A contradiction
// between boundary conditions is reported at the boundary section.
void finalize_models(CaseNode root, Scene& scene, bool coupled) {
  if (coupled && scene.dem.particles.size() == 0)
    root.fail("coupling", "no DE of the sample lies in the DEM domain (the pure-DEM zone and the overlap)");
  try {
    if (coupled) {
      scene.model = scene.continuum->couple(scene.dem);
    } else {
      scene.dem.finalize();
      scene.model = uncoupled_scene_model(scene.dem, scene.continuum.get());
    }
  } catch (const std::invalid_argument& e) {
    if (root.has("boundary")) root.fail("boundary", e.what());
    throw InputError(root.where() + ": " + e.what());
  }
}

}  // namespace

std::span<const SchemaSection> scene_schema() {
  static const std::vector<SchemaSection> sections = [] {
    std::vector<SchemaSection> all(std::begin(top_sections), std::end(top_sections));
    for (auto part : {dem_schema(), loading_schema(), output_schema()}) all.insert(all.end(), part.begin(), part.end());
    return all;
  }();
  return sections;
}

Scene build_scene(const std::filesystem::path& case_file, const SceneOptions& options) {
  CaseFile file = CaseFile::load(case_file, options.overrides, &case_schema());
  CaseNode root = file.root();
  Scene scene;
  scene.case_file = case_file;
  scene.profile = options.profile;
  scene.built_with = options;
  scene.name = root.string_or("name", case_file.parent_path().filename().string());
  // The name is the default output folder's last component (results/<name>) and the packing
  // cache's: one plain component of portable characters, so that it cannot reach outside
  // results/ ("..", "/") or write a name other tools cannot read back (a NUL, bad UTF-8).
  const bool portable = !scene.name.empty() && scene.name.front() != '.' &&
                        std::all_of(scene.name.begin(), scene.name.end(), [](char c) {
                          return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                                 c == '_' || c == '-' || c == '.' || c == '+';
                        });
  if (!portable) {
    const std::string expected = "a name of letters, digits, '_', '-', '+' and '.' (not first): it names the output folder results/<name>";
    if (root.has("name")) root.fail("name", expected);
    throw InputError(case_file.string() + ": name: the case folder's name is not " + expected + "; give the case a name:");
  }
  static constexpr std::string_view unit_systems[] = {"SI"};
  root.choice_or("units", "SI", unit_systems);
  scene.output.dir = prepare_output_dir(root.child_if("output"), scene.name, options);

  // The models first: the time section's defaults depend on them.
  std::optional<CaseNode> dem_node = root.child_if("dem");
  std::optional<CaseNode> continuum_node = root.child_if("continuum");
  if (!dem_node && !continuum_node) root.fail("dem", "a case needs a dem section, a continuum section, or both");
  std::optional<CaseNode> coupling = root.child_if("coupling");
  if (coupling && (!dem_node || !continuum_node))
    coupling->fail("overlap", "coupling needs both a dem and a continuum section");
  // The continuum first: a coupling's overlap cuts the DEM sample to its domain.
  if (continuum_node) scene.continuum = ContinuumPart::read(*continuum_node, coupling, options.petsc_options);
  dem::DemModel& model = scene.dem;
  if (dem_node) read_dem(*dem_node, scene, options);

  if (dem_node) {
    read_groups(root, model);
    read_initial(root, model);
    read_pulse(root, model);
  }
  read_initial_strain(root, scene);
  read_sensors(root, scene);
  if (dem_node) read_boundary(root, model);
  finalize_models(root, scene, coupling.has_value());

  const bool static_only = scene.static_only();
  std::optional<CaseNode> time = static_only ? root.child_if("time") : root.child("time");
  scene.end_time = time ? time->number("end", Range::positive(), "s") : 1.0;
  const std::optional<double> user_dt = time ? time->number_or_auto("dt", Range::positive(), "s") : std::nullopt;
  scene.safety = time ? time->number_or("safety", 0.3, Range::open_between(0.0, 1.0), "1") : 0.3;
  if (time) time->finish();

  // Coupled: the coupled system's step (the smaller of both, weighted); else each model's.
  scene.dt_critical = scene.model->critical_time_step();
  // A zero or NaN limit (a stiffness overflowing to inf, a zero mass) would give dt = 0 and a
  // run of no steps, or NaN everywhere.
  if (!static_only && !(scene.dt_critical > 0.0)) {
    std::ostringstream msg;
    msg << "the critical time step is " << scene.dt_critical
        << " s: a stiffness or a mass of the scene is out of range (check the moduli, densities and radii)";
    throw InputError(root.where() + ": " + msg.str());
  }
  if (static_only) {
    scene.dt = scene.end_time;  // one static solve
  } else if (user_dt) {
    if (*user_dt > scene.dt_critical) {
      std::ostringstream msg;
      msg << "time step " << *user_dt << " s is above the critical time step " << scene.dt_critical
          << " s (2/omega_max over bonds, contacts and the continuum, lowered by damping; docs/theory.md#critical-step); use dt <= " << scene.dt_critical << " or dt: auto";
      time->fail("dt", msg.str());
    }
    scene.dt = *user_dt;
  } else {
    if (!std::isfinite(scene.dt_critical))
      time->fail("dt", "the scene has no bond or contact stiffness, so dt: auto has no limit to scale; give dt in s");
    scene.dt = scene.safety * scene.dt_critical;
  }
  if (scene.end_time < 1e-9 * scene.dt) {
    std::ostringstream msg;
    msg << "time.end = " << scene.end_time << " s is not even 1e-9 of a time step (dt = " << scene.dt << " s): no step would run";
    time->fail("end", msg.str());
  }
  // A run shorter than one step is one step of time.end: the step it would take instead ran
  // the scene far past time.end (750 times, a calibration placeholder's soft bonds).
  if (scene.dt > scene.end_time) scene.dt = scene.end_time;
  const double steps = std::ceil(scene.end_time / scene.dt - 1e-9);
  // An ensemble's perturbation: only ever smaller, so a step under the limit stays under it; the
  // steps are counted before it, so that a pair's run ends within 1e-9 of time.end, not a step past.
  if (!static_only) scene.dt *= std::min(options.time_step_scale, 1.0);
  if (steps > 1e15) {
    std::ostringstream msg;
    msg << "time.end / dt = " << steps << " steps (time.end " << scene.end_time << " s, dt " << scene.dt
        << " s): more than 1e15; raise dt or lower time.end";
    time->fail("end", msg.str());
  }
  scene.steps = static_cast<long>(steps);
  read_output(root.child_if("output"), scene);
  std::vector<std::string> columns = sensor_columns(scene);
  columns.insert(columns.end(), {"E_kinetic", "E_bond", "E_contact", "W_external", "E_dissipated", "E_fracture", "E_total"});
  read_checks(root, scene, columns);
  // Plots name columns that this run writes.
  columns = series_columns(scene);
  for (const PlotPlan& plot : scene.output.plots) {
    std::vector<std::string> used{plot.x};
    used.insert(used.end(), plot.y.begin(), plot.y.end());
    used.insert(used.end(), plot.y2.begin(), plot.y2.end());
    for (const auto& c : used)
      if (std::find(columns.begin(), columns.end(), c) == columns.end())
        throw InputError(root.where() + ": output.plots: no series column '" + c + "' for " + plot.file.string());
  }
  root.finish();
  scene.resolved_case = file.resolved_yaml();
  if (scene.continuum && scene.continuum->band_follow()) check_band_follow(scene);
  return scene;
}

}  // namespace arlequin::app
