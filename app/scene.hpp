// A scene: everything a run needs, built from a case file with only the parts the case uses
// (no contact search without a contact law, no HDF5 file without field output, no PETSc
// without a continuum).
//
// Case-file schema (SI units; every key checked; see cases/*/case.yaml for examples):
//   name, units: SI
//   time:    {end [s], dt: auto | [s], safety: 0.3}   (optional for a static continuum alone)
//   (at least one of dem and continuum; continuum: see app/continuum_part.hpp)
//   dem:     {sample: {build: lattice | chain | particles, ...}, density [kg/m^3],
//             bond: {law: <bond law>, tolerance, ...law parameters},      (optional)
//             contact: {law: <contact law>, skin [m], ...law parameters}, (optional)
//             damping [1/s], failure: {rdef: {threshold [Pa], material_thresholds: {<material>: [Pa]},
//                                                equivalent: max_principal | von_mises | hydrostatic,
//                                                average: none | bonded_neighbours, compaction}}}
//             (BBF strengths are bond-law parameters: sigma_f for beams, max_elongation for springs)
//   groups:   [{name, region: {box | cylinder | sphere | half_space}} | {name, ids: [..]}]
//   boundary: [{group, type: fixed | velocity | displacement | force | free, value, ramp, rise, rotation,
//               components}]
//   initial:  [{group, velocity [m/s], angular_velocity [rad/s]}]
//   initial_strain: {gradient: [[..], [..], [..]]}: start from u = H x (DEM and continuum)
//   pulse:    {group, direction, center [m], wavelength [m], amplitude [m/s], speed [m/s]}: a
//             raised-cosine velocity pulse travelling along `direction` (DEM)
//   sensors:  [{name, type: force | displacement | velocity | energy, group, component: x | y | z | all,
//               on: dem | continuum (default: the model the case has; dem if both)}
//              | {name, type: affine_deviation}]  (needs initial_strain: see Sensor)
//   checks:   [{column, statistic: final | max | min | final_over_initial, expected, tolerance, note}
//              | {column, statistic, at_most, at_least, note}
//              | {column, crossing: value, expected: time [s], tolerance, note}]
//   output:   {dir, every [s], fields: [particles, bonds, continuum], fields_every [s],
//              plots: [{file, title, x, x_scale, x_label, y: [..], y_scale, y_label, y2: [..], y2_scale, y2_label}]}
#pragma once
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/continuum_part.hpp"
#include "common/case_file.hpp"
#include "dem/dem_model.hpp"
#include "dem/sample_file.hpp"

namespace arlequin::app {

struct Sensor {
  // energy: DEM groups, one column; affine_deviation: one column, the whole scene's
  // max |u - H X| / max |H X| over DEs and continuum nodes against initial_strain's H.
  enum class Kind { force, displacement, velocity, energy, affine_deviation };
  std::string name;
  Kind kind = Kind::force;
  bool on_continuum = false;  // else on the DEM
  int group = -1;             // DEM group index
  std::string group_name;
  int component = -1;  // 0, 1, 2, or -1 for all three
};

// An acceptance check of the case against its reference, evaluated on series.csv after the run:
// the final, largest or smallest value of a column, or the first time a column reaches a value
// (a wave's arrival). Relative tolerance.
struct Check {
  enum class Kind { final_value, maximum, minimum, final_over_initial, crossing };
  std::string column;
  Kind kind = Kind::final_value;
  double threshold = 0.0;     // crossing: the value to reach
  double expected = 0.0;      // the value, or the crossing time (s)
  double tolerance = 0.0;     // relative; or, when expected is not given, bounds:
  double at_most = INFINITY, at_least = -INFINITY;
  bool bounded = false;       // true: passes when at_least <= value <= at_most
  std::string note;           // where the expected value comes from
};

// A PNG plot of series.csv columns written at the end of a run (also a stopped one).
struct PlotPlan {
  std::filesystem::path file;  // relative to the output folder
  std::string title, x, x_label, y_label, y2_label;
  double x_scale = 1.0, y_scale = 1.0, y2_scale = 1.0;  // multiply the columns (e.g. 1/L for strain)
  std::vector<std::string> y, y2;                       // left and right axes
};

struct OutputPlan {
  std::filesystem::path dir;
  double every = 0.0;         // s, series.csv rows
  double fields_every = 0.0;  // s, HDF5 frames
  bool particle_fields = false;
  bool bond_fields = false;
  bool continuum_fields = false;
  std::vector<PlotPlan> plots;
};

struct Scene {
  std::string name;
  std::filesystem::path case_file;
  std::string resolved_case;  // YAML with defaults, as read
  dem::DemModel dem;                           // empty (no DE) without a dem section
  std::unique_ptr<ContinuumPart> continuum;    // null without a continuum section
  std::optional<dem::SampleRecord> sample;     // with build: packing: its spec and report
  std::filesystem::path sample_file;           // where the packing is cached
  std::size_t des_not_created = 0;             // sample DEs beyond a coupling's overlap
  std::optional<std::array<Vec3, 3>> initial_gradient;  // initial_strain's H, by rows
  double end_time = 0.0;      // s
  double dt = 0.0;            // s
  double dt_critical = 0.0;   // s
  double safety = 0.3;
  long steps = 0;             // to reach end_time: ceil(end_time / dt), at least 1
  std::vector<Sensor> sensors;
  std::vector<Check> checks;
  OutputPlan output;

  // A static continuum and no DE: one solve, no time stepping (time is optional).
  bool static_only() const { return continuum && continuum->is_static() && dem.particles.size() == 0; }
};

struct SceneOptions {
  std::vector<Override> overrides;     // --set key=value, and those of sweeps and spec files
  std::filesystem::path out_dir;       // --out, empty = from the case
  std::string petsc_options;           // --petsc "...", after the case's own
  bool rebuild_sample = false;         // build the packing even if its cache file matches
  bool check_output_dir = true;        // refuse an output folder that cannot be written (not for `check`)
};

// Column names of series.csv for the scene's sensors (one, or three for component: all).
std::vector<std::string> sensor_columns(const Scene& scene);
// The columns series.csv adds for a coupled scene: the work of the multiplier forces (J) and
// the coupling's monitor (ContinuumPart::coupling_monitor), in this order.
inline constexpr const char* coupling_columns[] = {"W_coupling", "G_residual", "V_mismatch_rms", "V_mismatch_max"};

// Throws InputError with file:line: key: message for any problem in the case.
Scene build_scene(const std::filesystem::path& case_file, const SceneOptions& options);

}  // namespace arlequin::app
