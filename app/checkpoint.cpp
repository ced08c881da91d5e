// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/checkpoint.hpp"

#include <yaml-cpp/yaml.h>

#include <sstream>

#include "common/error.hpp"

namespace arlequin::app {
namespace {

std::string text_of(const YAML::Node& node) {
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

// What a restart may change (docs/restart.md).
bool free_to_change(const std::string& path) { return path == "time.end" || path == "output"; }

// First path under `at` where a and b differ ("" if none), skipping what is free to change.
std::string first_difference(const YAML::Node& a, const YAML::Node& b, const std::string& at) {
  if (free_to_change(at)) return "";
  if (a.IsMap() && b.IsMap()) {
    for (const auto& entry : a) {
      const std::string key = entry.first.as<std::string>(), path = at.empty() ? key : at + "." + key;
      if (!b[key]) {
        if (free_to_change(path)) continue;
        return path;
      }
      if (const std::string d = first_difference(entry.second, b[key], path); !d.empty()) return d;
    }
    for (const auto& entry : b) {
      const std::string key = entry.first.as<std::string>(), path = at.empty() ? key : at + "." + key;
      if (!a[key] && !free_to_change(path)) return path;
    }
    return "";
  }
  if (a.IsSequence() && b.IsSequence() && a.size() == b.size()) {
    for (std::size_t k = 0; k < a.size(); ++k)
      if (const std::string d = first_difference(a[k], b[k], at + '[' + std::to_string(k) + ']'); !d.empty()) return d;
    return "";
  }
  if (a.Type() != b.Type() || (a.IsScalar() && a.Scalar() != b.Scalar()) || (!a.IsScalar() && text_of(a) != text_of(b)))
    return at.empty() ? "(the whole case)" : at;
  return "";
}

}  // namespace

void put_run_identity(StateArchive& archive, const Scene& scene) {
  archive.put_text("run/version", ARLEQUIN_VERSION);
  archive.put_text("run/case", scene.resolved_case);
  archive.put("run/dt", scene.dt);
}

std::string case_difference(const std::string& checkpoint_yaml, const std::string& scene_yaml) {
  return first_difference(YAML::Load(checkpoint_yaml), YAML::Load(scene_yaml), "");
}

void check_same_run(const StateArchive& archive, const Scene& scene, const std::filesystem::path& file) {
  const std::string where = '\'' + file.string() + '\'';
  try {
    if (const std::string version = archive.text("run/version"); version != ARLEQUIN_VERSION)
      throw InputError(where + " was written by arlequin " + version + ", this is " + ARLEQUIN_VERSION +
                       ": a checkpoint restarts only in the version that wrote it");
    const std::string theirs = archive.text("run/case");
    if (const std::string key = case_difference(theirs, scene.resolved_case); !key.empty())
      throw InputError(where + " is a checkpoint of another case: '" + key +
                       "' differs (a restart may change only time.end and the output section)");
    if (const double dt = archive.number("run/dt"); dt != scene.dt) {
      std::ostringstream msg;
      msg.precision(17);
      msg << where << " was run with the time step " << dt << " s, this case has " << scene.dt << " s";
      throw InputError(msg.str());
    }
  } catch (const StateMismatch& e) {
    throw InputError(where + " is not an arlequin run's checkpoint: " + e.what());
  } catch (const YAML::Exception& e) {
    throw InputError(where + ": its case cannot be read (" + e.msg + ")");
  }
}

void load_scene_state(Scene& scene, const StateArchive& archive, const std::filesystem::path& file) {
  try {
    scene.model->load_state(archive);
  } catch (const StateMismatch& e) {
    throw InputError("'" + file.string() + "' is not a checkpoint of this scene: " + e.what());
  }
}

}  // namespace arlequin::app
