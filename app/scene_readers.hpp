// SPDX-License-Identifier: GPL-3.0-or-later
// The readers of a case file's sections, one file per part (used by build_scene only):
// read_dem.cpp (the dem section), read_loading.cpp (groups, boundary, initial, pulse,
// initial_strain), read_output.cpp (sensors, checks, output). Each declares its keys beside its
// code; scene_schema() gathers them with the top level's.
#pragma once
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "app/scene.hpp"
#include "common/case_file.hpp"
#include "common/schema.hpp"

namespace arlequin::app {

inline constexpr std::string_view component_names[] = {"x", "y", "z", "all"};

// read_dem.cpp
std::span<const SchemaSection> dem_schema();
void read_dem(CaseNode dem_node, Scene& scene, const SceneOptions& options);

// read_loading.cpp
std::span<const SchemaSection> loading_schema();
void read_groups(CaseNode root, dem::DemModel& model);
int group_of(CaseNode& node, const dem::DemModel& model);  // the group named by node's `group`
void read_boundary(CaseNode root, dem::DemModel& model);
void read_initial(CaseNode root, dem::DemModel& model);
void read_pulse(CaseNode root, dem::DemModel& model);
void read_initial_strain(CaseNode root, Scene& scene);

// read_output.cpp
std::span<const SchemaSection> output_schema();
void read_sensors(CaseNode root, Scene& scene);
void read_checks(CaseNode root, Scene& scene, const std::vector<std::string>& columns);
std::filesystem::path prepare_output_dir(std::optional<CaseNode> out, const std::string& name, const SceneOptions& options);
void read_output(std::optional<CaseNode> out, Scene& scene);

}  // namespace arlequin::app
