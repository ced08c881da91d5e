// SPDX-License-Identifier: GPL-3.0-or-later
// A scene: everything a run needs, built from a case file with only the parts the case uses
// (no contact search without a contact law, no HDF5 file without field output, no PETSc
// without a continuum).
//
// The case-file keys are declared beside their readers (scene.cpp, continuum_part.cpp,
// common/region.cpp, each law's file) and printed by `arlequin schema [section]`.
#pragma once
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/continuum_part.hpp"
#include "app/scene_model.hpp"
#include "common/case_file.hpp"
#include "common/schema.hpp"
#include "common/step_profile.hpp"
#include "dem/dem_model.hpp"
#include "dem/sample_file.hpp"
#include "dem/weave.hpp"

namespace arlequin::app {

struct Sensor {
  // energy: DEM groups, one column; affine_deviation: one column, the whole scene's
  // max |u - H X| / max |H X| over DEs and continuum nodes against initial_strain's H.
  // crack: one column, a measure of a bond set's failed links (dem/crack_front.hpp).
  enum class Kind { force, displacement, velocity, energy, affine_deviation, crack };
  enum class CrackQuantity { tip, damage_front, crack_growth, softening_zone, process_zone, dissipated };
  std::string name;
  Kind kind = Kind::force;
  bool on_continuum = false;  // else on the DEM
  int group = -1;             // DEM group index
  std::string group_name;
  int component = -1;  // 0, 1, 2, or -1 for all three
  struct Crack {
    int bond_set = -1;
    CrackQuantity quantity = CrackQuantity::tip;
    Vec3 axis{1, 0, 0}, across{0, 1, 0};  // unit vectors
    int bins = 8;
    double initial_tip = 0.0;  // m, the tip when the scene was built (the pre-crack's)
    double dissipated_left = 0.0;  // J, by links a moving zone left behind (app/zone_move.hpp)
  } crack;
};

// A reference curve y(x) given by points (x increasing), linear between them.
struct ReferenceCurve {
  std::string label;
  std::vector<double> x, y;
  double at(double xq) const;  // NaN outside [x.front(), x.back()]
};

// An acceptance check of the case against its reference, evaluated on series.csv after the run:
// the final, largest or smallest value of a column, or the first time a column reaches a value
// (a wave's arrival). Relative tolerance.
struct Check {
  // curve: the largest |column / reference(versus) - 1| over the rows whose versus lies in over.
  enum class Kind { final_value, maximum, minimum, final_over_initial, crossing, curve };
  std::string column;
  Kind kind = Kind::final_value;
  double threshold = 0.0;     // crossing: the value to reach
  double expected = 0.0;      // the value, or the crossing time (s)
  double tolerance = 0.0;     // relative; or, when expected is not given, bounds:
  double at_most = INFINITY, at_least = -INFINITY;
  bool bounded = false;       // true: passes when at_least <= value <= at_most
  std::string note;           // where the expected value comes from
  std::string versus;         // curve: the column the reference is a function of; maximum,
                              // minimum: the column over ranges (empty: every row)
  ReferenceCurve reference;   // curve
  double over_low = 0.0, over_high = 0.0;  // curve, or maximum / minimum with versus: the range of versus judged
};

// A PNG plot of series.csv columns written at the end of a run (also a stopped one).
struct PlotPlan {
  std::filesystem::path file;  // relative to the output folder
  std::string title, x, x_label, y_label, y2_label;
  double x_scale = 1.0, y_scale = 1.0, y2_scale = 1.0;  // multiply the columns (e.g. 1/L for strain)
  std::vector<std::string> y, y2;                       // left and right axes
  std::vector<ReferenceCurve> references;               // dashed, left axis, in column units (scaled alike)
};

struct OutputPlan {
  std::filesystem::path dir;
  double every = 0.0;         // s, series.csv rows
  double fields_every = 0.0;  // s, HDF5 frames
  double checkpoint_every = 0.0;  // s, checkpoint.h5 (0: only when a signal stops the run)
  bool particle_fields = false;
  bool bond_fields = false;
  bool continuum_fields = false;
  std::vector<PlotPlan> plots;
};

struct SceneOptions {
  std::vector<Override> overrides;     // --set key=value, and those of sweeps and spec files
  std::filesystem::path out_dir;       // --out, empty = from the case
  std::string petsc_options;           // --petsc "...", after the case's own
  bool rebuild_sample = false;         // build the packing even if its cache file matches
  bool check_output_dir = true;        // refuse an output folder that cannot be written (not for `check`)
  bool write_sample_cache = true;      // save a packing built now to its cache file (not for `check`)
  StepProfile* profile = nullptr;      // --profile: runs time their step's phases into it
  double time_step_scale = 1.0;        // dt (auto or given) times this, at most 1: compare --ensemble's perturbation
  // A zone that moved (app/zone_move.hpp): the crack sensors' pre-crack tips, in the order of the
  // sensors, as the run's scene first measured them (the moved zone may hold no pre-crack).
  std::vector<double> crack_initial_tips{};
};

struct Scene {
  std::string name;
  std::filesystem::path case_file;
  std::string resolved_case;  // YAML with defaults, as read
  dem::DemModel dem;                           // empty (no DE) without a dem section
  std::unique_ptr<ContinuumPart> continuum;    // null without a continuum section
  std::unique_ptr<SceneModel> model;           // what the run steps (declared after what it refers to)
  std::optional<dem::SampleRecord> sample;     // with build: packing: its spec and report
  std::optional<dem::WeaveReport> weave;       // with build: weave: what was built
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
  StepProfile* profile = nullptr;  // SceneOptions::profile
  SceneOptions built_with;         // what build_scene was given (a zone that moves builds it again)

  // A static continuum and no DE: one solve, no time stepping (time is optional).
  bool static_only() const { return continuum && continuum->is_static() && dem.particles.size() == 0; }
};


// The options of `arlequin check` (and of the fuzz targets, which read as it does): those given,
// writing nothing, so that a case is validated where nothing can be written.
inline SceneOptions writing_nothing(SceneOptions options) {
  options.check_output_dir = false;
  options.write_sample_cache = false;
  return options;
}

// Column names of series.csv for the scene's sensors (one, or three for component: all).
std::vector<std::string> sensor_columns(const Scene& scene);
// The unit of each of those columns: N, m, m/s, J, or 1 (affine deviation).
std::vector<std::string> sensor_units(const Scene& scene);

// The schema of the sections that build_scene reads itself (app/case_schema.cpp adds the rest).
std::span<const SchemaSection> scene_schema();
// The energy columns of series.csv (SceneEnergies; E_total and E_balance over both models).
inline constexpr const char* energy_columns[] = {"E_kinetic",    "E_bond",     "E_contact", "W_external",
                                                 "E_dissipated", "E_fracture", "E_total",   "E_balance"};
// The columns series.csv adds for a coupled scene: the work of the multiplier forces (J) and
// the coupling's monitor (SceneModel::monitor), in this order.
inline constexpr const char* coupling_columns[] = {"W_coupling", "G_residual", "V_mismatch_rms", "V_mismatch_max"};
// Every column of the scene's series.csv, in order: time, step, sensors, energies, the
// continuum's energies, the coupling's, the broken fractions of each bond set.
std::vector<std::string> series_columns(const Scene& scene);

// Throws InputError with file:line: key: message for any problem in the case.
Scene build_scene(const std::filesystem::path& case_file, const SceneOptions& options);

}  // namespace arlequin::app
