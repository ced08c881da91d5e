// SPDX-License-Identifier: GPL-3.0-or-later
// The run's checkpoint (docs/restart.md): one HDF5 file, `checkpoint.h5` in the output folder,
// holding what continues the run bit for bit (the scene's models, SceneModel::save_state, and the
// runner's schedule and rows, app/runner.cpp) and what identifies it: the program version, the
// resolved case and the time step.
//
// Contract: check_same_run() refuses, with one InputError line naming the file, a checkpoint of
// another program version, of another case (the resolved cases differ in a key other than
// time.end and the output section; the line names the first such key), or of another time step.
// read_state_file() (common/state_file.hpp) has already refused a truncated or corrupted file.
#pragma once
#include <filesystem>
#include <string>

#include "app/scene.hpp"
#include "common/state_archive.hpp"

namespace arlequin::app {

inline constexpr const char* checkpoint_file_name = "checkpoint.h5";

// Version, resolved case and time step of the scene, under "run/".
void put_run_identity(StateArchive& archive, const Scene& scene);
void check_same_run(const StateArchive& archive, const Scene& scene, const std::filesystem::path& file);
// The first key (dotted path) where two resolved cases differ, other than time.end and the
// output section; empty when they agree there.
std::string case_difference(const std::string& checkpoint_yaml, const std::string& scene_yaml);
// load_state of the scene's models, a StateMismatch becoming the InputError "FILE is not a
// checkpoint of this scene: ...".
void load_scene_state(Scene& scene, const StateArchive& archive, const std::filesystem::path& file);

}  // namespace arlequin::app
