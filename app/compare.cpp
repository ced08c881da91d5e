// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/compare.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/runner.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "common/json.hpp"
#include "common/plots.hpp"

namespace arlequin::app {
namespace {

struct Run {
  std::string name;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;  // series.csv
  double setup = 0.0, loop = 0.0, output = 0.0;
  std::size_t particles = 0;
  long nodes = 0, steps = 0;
  bool ok = true;
  bool checks_passed = true;  // the case's own checks (those evaluated)
  std::optional<double> first_break;  // s, summary.json's first_break_time
  double compute_seconds() const { return loop - output; }
  bool has(const std::string& name_) const { return std::find(columns.begin(), columns.end(), name_) != columns.end(); }
  // The last row's value of a column, 0 where the run has no such column (a pure DEM's continuum).
  double last(const std::string& name_) const { return has(name_) && !rows.empty() ? column(name_).back() : 0.0; }
  // Energies at the end, J.
  double dem_energy() const { return last("E_kinetic") + last("E_bond") + last("E_contact"); }
  double continuum_energy() const { return last("C_kinetic") + last("C_strain"); }
  std::vector<double> column(const std::string& name_) const {
    const std::size_t c = std::find(columns.begin(), columns.end(), name_) - columns.begin();
    std::vector<double> out;
    for (const auto& r : rows) out.push_back(r[c]);
    return out;
  }
};

// A scene built and waiting for its run. Both scenes of a comparison are built first, so that a
// bad second case or two cases without a common sensor are found before any run.
struct Prepared {
  std::unique_ptr<Scene> scene;  // in place: a coupling holds references into its scene
  double setup_seconds = 0.0;
};

Prepared prepare(const std::filesystem::path& case_file, SceneOptions options, const std::filesystem::path& out) {
  options.out_dir = out;
  const auto t0 = std::chrono::steady_clock::now();
  Prepared p;
  p.scene.reset(new Scene(build_scene(case_file, options)));  // direct initialisation: no move
  p.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return p;
}

Run execute(Prepared& prepared, const std::filesystem::path& out) {
  Scene& scene = *prepared.scene;
  RunOptions run_options;
  run_options.setup_seconds = prepared.setup_seconds;
  Run run;
  run.name = scene.name;
  run.particles = scene.dem.particles.size();
  Json counts = Json::object();
  if (scene.continuum) scene.continuum->describe(counts);
  scene.model->describe(counts);
  run.nodes = counts.value("continuum_nodes", 0L);
  try {
    run.checks_passed = run_scene(scene, run_options).all_checks_passed();
  } catch (const RunError&) {
    run.ok = false;
  }
  const Json summary = read_json_file(out / "summary.json");
  run.setup = run_options.setup_seconds;
  run.loop = summary.at("wall_time").at("time_loop").get<double>();
  run.output = summary.at("wall_time").at("output").get<double>();
  run.steps = long(summary.at("steps").get<std::int64_t>());
  if (summary.contains("first_break_time")) run.first_break = summary.at("first_break_time").get<double>();
  // series.csv: a header, then rows of numbers.
  std::stringstream csv(read_text_file(out / "series.csv"));
  std::string line;
  std::getline(csv, line);
  std::stringstream header(line);
  for (std::string c; std::getline(header, c, ',');) run.columns.push_back(c);
  while (std::getline(csv, line)) {
    std::stringstream cells(line);
    std::vector<double> row;
    for (std::string c; std::getline(cells, c, ',');) row.push_back(std::stod(c));
    run.rows.push_back(row);
  }
  return run;
}

// b(t) at the times ta, linear between b's own samples (held beyond its ends).
std::vector<double> resample(const std::vector<double>& tb, const std::vector<double>& b, const std::vector<double>& ta) {
  std::vector<double> out;
  for (double t : ta) {
    const auto it = std::lower_bound(tb.begin(), tb.end(), t);
    if (it == tb.begin()) out.push_back(b.front());
    else if (it == tb.end()) out.push_back(b.back());
    else {
      const std::size_t k = it - tb.begin();
      const double w = (t - tb[k - 1]) / (tb[k] - tb[k - 1]);
      out.push_back((1 - w) * b[k - 1] + w * b[k]);
    }
  }
  return out;
}

Json describe_run(const Run& r) {
  Json j = Json::object();
  j["name"] = r.name;
  j["particles"] = r.particles;
  j["continuum_nodes"] = r.nodes;
  j["steps"] = r.steps;
  j["setup_seconds"] = r.setup;
  j["compute_seconds"] = r.compute_seconds();
  j["output_seconds"] = r.output;
  j["completed"] = r.ok;
  j["checks_passed"] = r.checks_passed;
  if (r.first_break) j["first_break_time"] = *r.first_break;
  Json energy = Json::object();
  energy["dem"] = r.dem_energy();
  energy["continuum"] = r.continuum_energy();
  energy["fracture"] = r.last("E_fracture");
  j["energy_at_end"] = energy;
  return j;
}

}  // namespace

CompareOutcome run_compare(const std::filesystem::path& reference_case, const std::filesystem::path& other_case,
                 const SceneOptions& base, const std::filesystem::path& out_dir) {
  std::error_code ec;
  if (std::filesystem::equivalent(reference_case, other_case, ec))
    std::fprintf(stderr, "arlequin compare: warning: both runs are %s; the differences are run-to-run noise\n",
                 reference_case.string().c_str());
  Prepared prepared_a = prepare(reference_case, base, out_dir / "reference");
  Prepared prepared_b = prepare(other_case, base, out_dir / "other");
  // Shared sensor columns (the energy totals mean different things for a DEM and a coupled run).
  const std::vector<std::string> sensors_a = sensor_columns(*prepared_a.scene), sensors_b = sensor_columns(*prepared_b.scene);
  const std::vector<std::string> units_a = sensor_units(*prepared_a.scene);
  std::vector<std::string> shared, shared_units;
  for (std::size_t k = 0; k < sensors_a.size(); ++k)
    if (std::find(sensors_b.begin(), sensors_b.end(), sensors_a[k]) != sensors_b.end())
      shared.push_back(sensors_a[k]), shared_units.push_back(units_a[k]);
  if (shared.empty())
    throw InputError(other_case.string() + ": shares no sensor column with " + reference_case.string());
  const Run a = execute(prepared_a, out_dir / "reference");
  prepared_a.scene.reset();  // the first run's memory, before the second run
  const Run b = execute(prepared_b, out_dir / "other");

  const auto ta = a.column("time"), tb = b.column("time");
  Json sensors = Json::array();
  std::string csv = "sensor,max_relative_difference,rms_relative_difference,peak_relative_difference\n";
  std::vector<Plot> plots;
  std::printf("| sensor | max rel. difference | RMS rel. difference | peak rel. difference |\n|---|---|---|---|\n");
  for (std::size_t s = 0; s < shared.size(); ++s) {
    const std::string& name = shared[s];
    const auto va = a.column(name), vb = resample(tb, b.column(name), ta);
    double max_diff = 0, max_ref = 0, max_other = 0, sum_diff = 0, sum_ref = 0;
    for (std::size_t k = 0; k < va.size(); ++k) {
      const double d = vb[k] - va[k];
      max_diff = std::max(max_diff, std::abs(d));
      max_ref = std::max(max_ref, std::abs(va[k]));
      sum_diff += d * d;
      sum_ref += va[k] * va[k];
    }
    for (double v : b.column(name)) max_other = std::max(max_other, std::abs(v));  // its own peak, not resampled
    const double max_rel = max_diff / std::max(max_ref, 1e-300), rms_rel = std::sqrt(sum_diff / std::max(sum_ref, 1e-300));
    const double peak_rel = (max_other - max_ref) / std::max(max_ref, 1e-300);
    Json j = Json::object();
    j["sensor"] = name;
    j["max_relative_difference"] = max_rel;
    j["rms_relative_difference"] = rms_rel;
    j["peak_relative_difference"] = peak_rel;
    sensors.push_back(j);
    char row[256];
    std::snprintf(row, sizeof row, "%s,%.6g,%.6g,%.6g\n", name.c_str(), max_rel, rms_rel, peak_rel);
    csv += row;
    std::printf("| %s | %.3g %% | %.3g %% | %+.3g %% |\n", name.c_str(), 100 * max_rel, 100 * rms_rel, 100 * peak_rel);
    Plot& plot = plots.emplace_back();
    plot.file = "compare_" + name + ".png";
    plot.title = name + ": " + b.name + " against " + a.name;
    plot.x_label = "time [s]";
    plot.y_label = shared_units[s] == "1" ? name : name + " [" + shared_units[s] + "]";
    plot.curves.resize(2);
    plot.curves[0].label = a.name, plot.curves[0].x = ta, plot.curves[0].y = va;
    plot.curves[1].label = b.name, plot.curves[1].x = tb, plot.curves[1].y = b.column(name);
  }
  const double speedup = a.compute_seconds() / std::max(b.compute_seconds(), 1e-12);
  std::printf("%s: %zu DEs, %ld nodes, %ld steps, compute %.3f s (setup %.3f s, output %.3f s)\n", a.name.c_str(),
              a.particles, a.nodes, a.steps, a.compute_seconds(), a.setup, a.output);
  std::printf("%s: %zu DEs, %ld nodes, %ld steps, compute %.3f s (setup %.3f s, output %.3f s)\n", b.name.c_str(),
              b.particles, b.nodes, b.steps, b.compute_seconds(), b.setup, b.output);
  std::printf("speed-up of %s over %s (compute): %.2fx\n", b.name.c_str(), a.name.c_str(), speedup);
  for (const Run* r : {&a, &b}) {
    std::printf("%s at the end: DEM %.4g J, continuum %.4g J, fracture %.4g J", r->name.c_str(), r->dem_energy(),
                r->continuum_energy(), r->last("E_fracture"));
    if (r->first_break) std::printf("; first break at %.4g s", *r->first_break);
    std::printf("\n");
  }
  if (a.first_break && b.first_break)
    std::printf("first break: %+.3g %% of the reference's\n", 100 * (*b.first_break - *a.first_break) / *a.first_break);
  for (const Run* r : {&a, &b})
    if (!r->checks_passed) std::printf("%s: a check of its case FAILED (its summary.json says which)\n", r->name.c_str());

  Json report = Json::object();
  report["reference"] = describe_run(a);
  report["other"] = describe_run(b);
  report["speedup_compute"] = speedup;
  report["sensors"] = sensors;
  write_file_atomically(out_dir / "compare.csv", csv);
  write_json_atomically(out_dir / "compare.json", report);
  write_plots(out_dir, plots);
  return {a.ok && b.ok, a.checks_passed && b.checks_passed};
}

}  // namespace arlequin::app
