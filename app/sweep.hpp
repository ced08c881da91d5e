// SPDX-License-Identifier: GPL-3.0-or-later
// `arlequin sweep`: runs one case over the Cartesian product of overridden values and tabulates,
// per run, the case's checks (value, relative error) against the wall time: the user's
// "error against run time" view of a discretisation or solver choice.
#pragma once
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "app/scene.hpp"

namespace arlequin::app {

struct SweepAxis {
  std::string key;                  // case key path, e.g. continuum.mesh.size
  std::vector<std::string> values;  // YAML texts
  // --with: the values go with the previous axis's, one for one (a group that must follow a
  // radius), instead of multiplying the runs.
  bool with_previous = false;
};

// Parses "key=v1,v2,v3" (commas inside brackets belong to a value: "key=[1,2],[3,4]");
// InputError naming the option if malformed.
SweepAxis parse_sweep_axis(const std::string& text);

// Runs every combination into out_dir/<run index>/, prints a Markdown table on stdout and
// writes, after every run, out_dir/sweep.csv (atomically), sweep.png (the first check's value
// against the first axis if its values are numbers, a line per combination of the other axes)
// and sweep_time.png (that value against the wall time, a point per run). Returns false if any
// run failed or missed a check. Throws InputError if a --with axis has no axis before it or not
// as many values.
bool run_sweep(const std::filesystem::path& case_file, const SceneOptions& base,
               const std::vector<SweepAxis>& axes, const std::filesystem::path& out_dir);

}  // namespace arlequin::app
