// A scene: everything a run needs, built from a case file with only the parts the case uses
// (no contact search without a contact law, no HDF5 file without field output, no PETSc
// without a continuum).
//
// Case-file schema (SI units; every key checked; see cases/*/case.yaml for examples):
//   name, units: SI
//   time:    {end [s], dt: auto | [s], safety: 0.3}
//   dem:     {sample: {build: lattice | chain | particles, ...}, density [kg/m^3],
//             bond: {law: <bond law>, tolerance, ...law parameters},      (optional)
//             contact: {law: <contact law>, skin [m], ...law parameters}, (optional)
//             damping [1/s]}
//   groups:   [{name, region: {box | cylinder | sphere | half_space}} | {name, ids: [..]}]
//   boundary: [{group, type: fixed | velocity | displacement | force | free, value, ramp, rotation}]
//   initial:  [{group, velocity [m/s], angular_velocity [rad/s]}]
//   sensors:  [{name, type: force | displacement, group, component: x | y | z | all}]
//   output:   {dir, every [s], fields: [particles, bonds], fields_every [s]}
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "dem/dem_model.hpp"

namespace arlequin::app {

struct Sensor {
  enum class Kind { force, displacement };
  std::string name;
  Kind kind = Kind::force;
  int group = -1;
  int component = -1;  // 0, 1, 2, or -1 for all three
};

struct OutputPlan {
  std::filesystem::path dir;
  double every = 0.0;         // s, series.csv rows
  double fields_every = 0.0;  // s, HDF5 frames
  bool particle_fields = false;
  bool bond_fields = false;
};

struct Scene {
  std::string name;
  std::filesystem::path case_file;
  std::string resolved_case;  // YAML with defaults, as read
  dem::DemModel dem;
  double end_time = 0.0;      // s
  double dt = 0.0;            // s
  double dt_critical = 0.0;   // s
  double safety = 0.3;
  std::vector<Sensor> sensors;
  OutputPlan output;
};

struct SceneOptions {
  std::vector<std::string> overrides;  // --set key=value
  std::filesystem::path out_dir;       // --out, empty = from the case
};

// Throws InputError with file:line: key: message for any problem in the case.
Scene build_scene(const std::filesystem::path& case_file, const SceneOptions& options);

}  // namespace arlequin::app
