// SPDX-License-Identifier: GPL-3.0-or-later
// What a case measures and writes: sensors, checks, output folder, rows, fields, plots (and their keys).
#include "app/scene_readers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/region.hpp"
#include "common/schema.hpp"
#include "dem/crack_front.hpp"
#include <unistd.h>
#include <cerrno>
#include <cstring>

namespace arlequin::app {
namespace {

constexpr KeyDoc sensor_keys[] = {
    {"name", KeyType::string, "", {}, "", "column name (with _x, _y, _z per component)"},
    {"type", KeyType::choice, "", {}, "", "what it measures", "force | displacement | velocity | energy | affine_deviation | crack"},
    {"on", KeyType::choice, "", {}, "(dem if the case has DEs)", "which model's group", "dem | continuum"},
    {"group", KeyType::string, "", {}, "", "the group measured (reaction force, mean displacement or velocity, energy)"},
    {"component", KeyType::choice, "", {}, "all", "one component, or all three", "x | y | z | all"},
    {"bonds", KeyType::string, "", {}, "interface", "crack: the bond set whose failed links are measured"},
    {"quantity", KeyType::choice, "", {}, "tip", "crack: what is measured (docs/theory.md#crack-measures)",
     "tip | damage_front | crack_growth | softening_zone | process_zone | dissipated"},
    {"axis", KeyType::vec3, "1", {}, "[1, 0, 0]", "crack: the direction the crack runs along"},
    {"across", KeyType::vec3, "1", {}, "[0, 1, 0]", "crack: the width direction, averaged over"},
    {"bins", KeyType::integer, "", Range::at_least(1), "8", "crack: strips across the width"},
};
constexpr KeyDoc check_keys[] = {
    {"column", KeyType::string, "", {}, "", "the series.csv column judged"},
    {"statistic", KeyType::choice, "", {}, "final", "what of the column is judged", "final | max | min | final_over_initial"},
    {"crossing", KeyType::number, "column unit", {}, "(none)", "judge the time the column first reaches this value instead"},
    {"expected", KeyType::number, "(the column's, or s)", {}, "(none)", "reference value (with tolerance)"},
    {"tolerance", KeyType::number, "1", Range::positive(), "", "relative tolerance on expected"},
    {"at_most", KeyType::number, "(column unit; 1 against a reference)", {}, "(none)", "upper bound (instead of expected)"},
    {"at_least", KeyType::number, "(column unit; 1 against a reference)", {}, "(none)", "lower bound (instead of expected)"},
    {"note", KeyType::string, "", {}, "", "where the reference comes from, shown with the result"},
    {"reference", KeyType::section, "", {}, "(none)", "a reference curve of the column against 'versus': the check is then the largest relative deviation"},
    {"versus", KeyType::string, "", {}, "(none)",
     "with reference: the column (or time) the reference curve is a function of; with max or min: the column (or time) 'over' ranges"},
    {"over", KeyType::numbers, "(versus unit)", {}, "(the reference's span; all rows)",
     "with reference, or max or min and versus: the range [low, high] of versus judged"},
};
constexpr KeyDoc output_keys[] = {
    {"dir", KeyType::string, "", {}, "(results/<name>)", "output folder, relative to the working directory"},
    {"every", KeyType::number, "s", Range::positive(), "(time.end / 100)", "interval of series.csv rows"},
    {"fields", KeyType::strings, "", {}, "[]", "field sets written to fields.h5: particles, bonds, continuum"},
    {"fields_every", KeyType::number, "s", Range::positive(), "(every)", "interval of fields.h5 frames"},
    {"plots", KeyType::list, "", {}, "(none)", "plots of series columns, drawn by the Python package"},
    {"checkpoint_every", KeyType::number, "s", Range::positive(), "(none)",
     "interval of checkpoint.h5 (the whole state, for --restart), also written when the run ends; "
     "without it only SIGINT or SIGTERM writes one"},
};
constexpr KeyDoc reference_keys[] = {
    {"label", KeyType::string, "", {}, "reference", "legend text"},
    {"x", KeyType::numbers, "(the x column's)", {}, "", "abscissae, increasing"},
    {"y", KeyType::numbers, "(the y column's)", {}, "", "values at x"},
};
constexpr KeyDoc plot_keys[] = {
    {"file", KeyType::string, "", {}, "", "image name in the output folder: .png, .svg or .pdf"},
    {"title", KeyType::string, "", {}, "", "title"},
    {"x", KeyType::string, "", {}, "", "column on the x axis"},
    {"x_scale", KeyType::number, "1", {}, "1", "factor on x (e.g. 1 / L for a strain)"},
    {"x_label", KeyType::string, "", {}, "(x)", "x axis label"},
    {"y", KeyType::strings, "", {}, "", "columns on the left axis"},
    {"y_scale", KeyType::number, "1", {}, "1", "factor on the left axis' columns"},
    {"y_label", KeyType::string, "", {}, "", "left axis label"},
    {"y2", KeyType::strings, "", {}, "[]", "columns on the right axis"},
    {"y2_scale", KeyType::number, "1", {}, "1", "factor on the right axis' columns"},
    {"y2_label", KeyType::string, "", {}, "", "right axis label"},
    {"references", KeyType::list, "", {}, "[]", "reference curves drawn on the left axis"},
};

constexpr SchemaSection output_sections[] = {
    {"sensors[]", "a series.csv column (or three)", sensor_keys},
    {"checks[]", "an acceptance check judged at time.end", check_keys},
    {"output", "results", output_keys},
    {"output.plots[]", "a plot of series columns", plot_keys},
    {"output.plots[].references[]", "a reference curve of a plot", reference_keys},
    {"checks[].reference", "a reference curve of a check", reference_keys},
};

}  // namespace

std::span<const SchemaSection> output_schema() { return output_sections; }

void read_sensors(CaseNode root, Scene& scene) {
  static constexpr std::string_view types[] = {"force", "displacement", "velocity", "energy", "affine_deviation", "crack"};
  static constexpr std::string_view models[] = {"dem", "continuum"};
  static constexpr std::string_view crack_quantities[] = {"tip", "damage_front", "crack_growth", "softening_zone", "process_zone",
                                                          "dissipated"};
  const bool has_dem = scene.dem.particles.size() > 0;
  std::vector<CaseNode> nodes;
  for (CaseNode s : root.list_or_empty("sensors")) {
    nodes.push_back(s);
    Sensor sensor;
    sensor.name = s.string("name");
    if (sensor.name.empty() || sensor.name.find_first_of(", \"") != std::string::npos)
      s.fail("name", "expected a non-empty name without commas, quotes or spaces");
    for (const Sensor& other : scene.sensors)
      if (other.name == sensor.name) s.fail("name", "sensor '" + sensor.name + "' is defined twice");
    const std::string type = s.choice("type", types);
    if (type == "affine_deviation") {
      // A patch test's measure: the whole scene against the initial_strain field.
      if (!scene.initial_gradient) s.fail("type", "an affine_deviation sensor needs an initial_strain section");
      sensor.kind = Sensor::Kind::affine_deviation;
      sensor.component = 0;
      s.finish();
      scene.sensors.push_back(sensor);
      continue;
    }
    if (type == "crack") {
      sensor.kind = Sensor::Kind::crack;
      sensor.component = 0;
      const std::string set_name = s.string_or("bonds", "interface");
      sensor.crack.bond_set = scene.dem.bond_set_index(set_name);
      if (sensor.crack.bond_set < 0) s.fail("bonds", "no bond set named '" + set_name + "'");
      const std::string quantity = s.choice_or("quantity", "tip", crack_quantities);
      sensor.crack.quantity = Sensor::CrackQuantity(
          std::find(std::begin(crack_quantities), std::end(crack_quantities), quantity) - std::begin(crack_quantities));
      for (auto [key, fallback, target] : {std::tuple{"axis", Vec3{1, 0, 0}, &sensor.crack.axis},
                                           std::tuple{"across", Vec3{0, 1, 0}, &sensor.crack.across}}) {
        const Vec3 v = s.vec3_or(key, fallback, Range::any(), "1");
        if (!(norm(v) > 0.0)) s.fail(key, "expected a non-zero direction");
        *target = normalized(v);
      }
      sensor.crack.bins = int(s.integer_or("bins", 8, Range::at_least(1)));
      const auto& set = *scene.dem.bond_sets()[sensor.crack.bond_set];
      const auto& tips = scene.built_with.crack_initial_tips;
      sensor.crack.initial_tip = tips.empty() ? dem::measure_crack(set, scene.dem.particles, sensor.crack.axis, sensor.crack.across,
                                                                   sensor.crack.bins).tip
                                              : tips.at(scene.sensors.size());
      const bool from_initial_tip = sensor.crack.quantity == Sensor::CrackQuantity::crack_growth ||
                                    sensor.crack.quantity == Sensor::CrackQuantity::softening_zone;
      if (from_initial_tip && std::isnan(sensor.crack.initial_tip))
        s.fail("quantity", "lengths from the initial tip need links that start failed (a pre-crack)");
      s.finish();
      scene.sensors.push_back(sensor);
      continue;
    }
    sensor.kind = type == "force"          ? Sensor::Kind::force
                  : type == "displacement" ? Sensor::Kind::displacement
                  : type == "velocity"     ? Sensor::Kind::velocity
                                           : Sensor::Kind::energy;
    sensor.on_continuum = s.choice_or("on", has_dem ? "dem" : "continuum", models) == "continuum";
    if (sensor.on_continuum) {
      if (!scene.continuum) s.fail("on", "the case has no continuum");
      if (sensor.kind == Sensor::Kind::energy) s.fail("type", "energy sensors are for DEM groups");
      sensor.group_name = s.string("group");
      if (!scene.continuum->has_group(sensor.group_name))
        s.fail("group", "the continuum mesh has no physical group '" + sensor.group_name + "'");
    } else {
      if (!has_dem) s.fail("on", "the case has no DEM");
      sensor.group = group_of(s, scene.dem);
      sensor.group_name = s.string("group");
      if (sensor.kind == Sensor::Kind::force) scene.dem.watch_reaction(sensor.group);
    }
    if (sensor.kind == Sensor::Kind::energy) {
      sensor.component = 0;  // a scalar: one column
    } else {
      const std::string c = s.choice_or("component", "all", component_names);
      sensor.component = c == "all" ? -1 : c[0] - 'x';
    }
    s.finish();
    scene.sensors.push_back(sensor);
  }
  // A sensor's columns may repeat no column of series.csv, built-in or another sensor's: a
  // check or a plot would read the first of two columns of one name.
  std::vector<std::string> taken{"time", "step", "C_kinetic", "C_strain"};
  taken.insert(taken.end(), std::begin(energy_columns), std::end(energy_columns));
  taken.insert(taken.end(), std::begin(coupling_columns), std::end(coupling_columns));
  for (const auto& set : scene.dem.bond_sets()) taken.push_back("broken_" + set->name);
  for (std::size_t k = 0; k < scene.sensors.size(); ++k) {
    const Sensor& s = scene.sensors[k];
    std::vector<std::string> columns{s.name};
    if (s.component < 0) columns = {s.name + "_x", s.name + "_y", s.name + "_z"};
    for (const std::string& c : columns) {
      if (std::find(taken.begin(), taken.end(), c) != taken.end())
        nodes[k].fail("name", "series.csv already has a column '" + c +
                                  "' (built-in: time, step, the energies, the coupling's and broken_<bond set>; or another sensor's)");
      taken.push_back(c);
    }
  }
}

namespace {
ReferenceCurve read_reference(CaseNode node) {
  ReferenceCurve r;
  r.label = node.string_or("label", "reference");
  r.x = node.numbers("x", Range::any(), "(the x column's)");
  r.y = node.numbers("y", Range::any(), "(the y column's)");
  if (r.x.size() < 2 || r.x.size() != r.y.size()) node.fail("y", "expected as many values as x, two or more");
  for (std::size_t k = 1; k < r.x.size(); ++k)
    if (!(r.x[k] > r.x[k - 1])) node.fail("x", "expected increasing abscissae");
  node.finish();
  return r;
}
}  // namespace

double ReferenceCurve::at(double xq) const {
  if (!(xq >= x.front() && xq <= x.back())) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t k = std::max<std::size_t>(1, std::lower_bound(x.begin(), x.end(), xq) - x.begin());
  const double w = (xq - x[k - 1]) / (x[k] - x[k - 1]);
  return y[k - 1] + w * (y[k] - y[k - 1]);
}

void read_checks(CaseNode root, Scene& scene, const std::vector<std::string>& columns) {
  for (CaseNode c : root.list_or_empty("checks")) {
    Check check;
    // The name under `key`, which must be a series column.
    const auto series_column = [&](const char* key) {
      std::string name = c.string(key);
      if (std::string_view(key) == "versus" && name == "time") return name;  // a function of time, or a range of it
      if (std::find(columns.begin(), columns.end(), name) == columns.end()) {
        std::string known;
        for (const auto& k : columns) known += (known.empty() ? "" : ", ") + k;
        c.fail(key, "no series column '" + name + "' (columns: " + known + ")");
      }
      return name;
    };
    check.column = series_column("column");
    static constexpr std::string_view statistics[] = {"final", "max", "min", "final_over_initial"};
    if (auto reference = c.child_if("reference")) {
      check.kind = Check::Kind::curve;
      check.reference = read_reference(*reference);
      check.versus = series_column("versus");
      const auto over = c.has("over") ? c.numbers("over", Range::any(), "(versus unit)")
                                      : std::vector<double>{check.reference.x.front(), check.reference.x.back()};
      if (over.size() != 2 || !(over[0] < over[1]) || over[0] < check.reference.x.front() || over[1] > check.reference.x.back())
        c.fail("over", "expected [low, high] within the reference curve's span");
      check.over_low = over[0], check.over_high = over[1];
      if (!c.has("at_most")) c.fail("at_most", "a check against a reference curve needs at_most, the largest relative deviation allowed");
    } else if (c.has("crossing")) {
      check.kind = Check::Kind::crossing;
      check.threshold = c.number("crossing", Range::any(), "column unit");
    } else {
      const std::string statistic = c.choice_or("statistic", "final", statistics);
      check.kind = statistic == "final"  ? Check::Kind::final_value
                   : statistic == "max"  ? Check::Kind::maximum
                   : statistic == "min"  ? Check::Kind::minimum
                                         : Check::Kind::final_over_initial;
      // A maximum or minimum over the rows whose `versus` lies in `over` (e.g. a peak load before
      // the specimen splits).
      const bool extremum = check.kind == Check::Kind::maximum || check.kind == Check::Kind::minimum;
      if (c.has("versus") || c.has("over")) {
        if (!extremum) c.fail(c.has("versus") ? "versus" : "over", "is read with a reference curve or with statistic: max | min");
        check.versus = series_column("versus");
        const auto over = c.numbers("over", Range::any(), "(versus unit)");
        if (over.size() != 2 || !(over[0] < over[1])) c.fail("over", "expected [low, high] with low < high");
        check.over_low = over[0], check.over_high = over[1];
      }
    }
    const char* unit = check.kind == Check::Kind::crossing ? "s" : check.kind == Check::Kind::curve ? "1" : "column unit";
    check.bounded = c.has("at_most") || c.has("at_least");
    if (check.bounded) {
      if (c.has("expected")) c.fail("expected", "give either expected and tolerance, or at_most / at_least");
      // Only the bounds given (an unbounded side has no number a case file could hold).
      if (c.has("at_most")) check.at_most = c.number("at_most", Range::any(), unit);
      if (c.has("at_least")) check.at_least = c.number("at_least", Range::any(), unit);
    } else {
      check.expected = c.number("expected", Range::any(), unit);
      check.tolerance = c.number("tolerance", Range::positive(), "1");
    }
    check.note = c.string_or("note", "");
    c.finish();
    scene.checks.push_back(check);
  }
}

namespace {
// 'path', built by appending (GCC 12 warns falsely of overlapping copies in "'" + s + "'").
std::string quoted(const std::filesystem::path& path) {
  std::string text = "'";
  text += path.string();
  text += "'";
  return text;
}
}  // namespace

// The output folder (--out, else output.dir, else results/<name>), checked now (unless
// options.check_output_dir is off, as for `check`), so that one that cannot be written is bad
// input before any work. Nothing is created here; the run creates it.
std::filesystem::path prepare_output_dir(std::optional<CaseNode> out, const std::string& name, const SceneOptions& options) {
  std::filesystem::path dir = out ? out->string_or("dir", "results/" + name) : "results/" + name;
  if (!options.out_dir.empty()) dir = options.out_dir;
  if (!options.check_output_dir) return dir;
  // The folder itself, or the nearest of its parents that exists, must be a folder we may write
  // in and enter; a parent we may not look into is a problem of its own.
  std::string problem;
  std::error_code ec;
  std::filesystem::path existing = std::filesystem::absolute(dir, ec);
  for (;;) {
    const auto status = std::filesystem::status(existing, ec);
    if (std::filesystem::exists(status)) break;
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory) {
      problem = quoted(existing) + ": " + ec.message();
      break;
    }
    if (!existing.has_parent_path() || existing == existing.parent_path()) break;
    existing = existing.parent_path();
  }
  if (problem.empty() && !std::filesystem::is_directory(existing, ec))
    problem = quoted(existing) + " is not a folder";
  else if (problem.empty() && access(existing.c_str(), W_OK | X_OK) != 0)
    problem = quoted(existing) + " is not writable (" + std::strerror(errno) + ")";
  if (!problem.empty()) {
    const std::string message = "cannot write the outputs to '" + dir.string() + "': " + problem;
    if (options.out_dir.empty() && out && out->has("dir")) out->fail("dir", message);
    throw InputError((options.out_dir.empty() ? "output folder" : "--out") + std::string(": ") + message);
  }
  return dir;
}

void read_output(std::optional<CaseNode> out, Scene& scene) {
  static constexpr std::string_view field_kinds[] = {"particles", "bonds", "continuum"};
  OutputPlan& plan = scene.output;
  plan.every = scene.end_time / 100.0;
  if (out) {
    plan.every = out->number_or("every", plan.every, Range::positive(), "s");
    for (const std::string& f : out->strings_or("fields", {})) {
      if (std::find(std::begin(field_kinds), std::end(field_kinds), f) == std::end(field_kinds))
        out->fail("fields", "unknown field set '" + f + "' (expected particles, bonds, continuum)");
      (f == "particles" ? plan.particle_fields : f == "bonds" ? plan.bond_fields : plan.continuum_fields) = true;
    }
    plan.fields_every = out->number_or("fields_every", plan.every, Range::positive(), "s");
    if (out->has("checkpoint_every")) plan.checkpoint_every = out->number("checkpoint_every", Range::positive(), "s");
    for (CaseNode p : out->list_or_empty("plots")) {
      PlotPlan plot;
      plot.file = p.string("file");
      const auto ext = plot.file.extension();
      if ((ext != ".png" && ext != ".svg" && ext != ".pdf") || plot.file.has_parent_path())
        p.fail("file", "expected a file name ending in .png, .svg or .pdf (written in the output folder)");
      plot.title = p.string_or("title", "");
      plot.x = p.string("x");
      plot.x_scale = p.number_or("x_scale", 1.0, Range::any(), "1");
      plot.x_label = p.string_or("x_label", plot.x);
      plot.y = p.strings("y");
      plot.y_scale = p.number_or("y_scale", 1.0, Range::any(), "1");
      plot.y_label = p.string_or("y_label", "");
      plot.y2 = p.strings_or("y2", {});
      plot.y2_scale = p.number_or("y2_scale", 1.0, Range::any(), "1");
      plot.y2_label = p.string_or("y2_label", "");
      for (CaseNode r : p.list_or_empty("references")) plot.references.push_back(read_reference(r));
      p.finish();
      plan.plots.push_back(plot);
    }
    out->finish();
  }
}

std::vector<std::string> series_columns(const Scene& scene) {
  std::vector<std::string> columns{"time", "step"};
  for (auto& c : sensor_columns(scene)) columns.push_back(c);
  columns.insert(columns.end(), std::begin(energy_columns), std::end(energy_columns));
  if (scene.continuum) columns.insert(columns.end(), {"C_kinetic", "C_strain"});
  if (scene.model->coupled()) columns.insert(columns.end(), std::begin(coupling_columns), std::end(coupling_columns));
  if (scene.dem.failure_enabled())
    for (const auto& set : scene.dem.bond_sets()) columns.push_back("broken_" + set->name);
  return columns;
}

std::vector<std::string> sensor_columns(const Scene& scene) {
  std::vector<std::string> out;
  for (const Sensor& s : scene.sensors) {
    if (s.component >= 0) {
      out.push_back(s.name);
    } else {
      for (const char* axis : {"_x", "_y", "_z"}) out.push_back(s.name + axis);
    }
  }
  return out;
}

std::vector<std::string> sensor_units(const Scene& scene) {
  std::vector<std::string> out;
  for (const Sensor& s : scene.sensors) {
    const char* unit = s.kind == Sensor::Kind::force          ? "N"
                       : s.kind == Sensor::Kind::displacement ? "m"
                       : s.kind == Sensor::Kind::velocity     ? "m/s"
                       : s.kind == Sensor::Kind::energy       ? "J"
                       : s.kind == Sensor::Kind::crack        ? (s.crack.quantity == Sensor::CrackQuantity::dissipated ? "J" : "m")
                                                              : "1";
    out.insert(out.end(), s.component >= 0 ? 1 : 3, unit);
  }
  return out;
}

}  // namespace arlequin::app
