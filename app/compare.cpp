// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/compare.hpp"

#include <algorithm>
#include <charconv>
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
#include "common/statistics.hpp"

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

// Whether each row of r lies in the window.
std::vector<bool> rows_inside(const Run& r, const CompareWindow& window) {
  if (window.column.empty()) return std::vector<bool>(r.rows.size(), true);
  std::vector<bool> inside;
  for (double v : r.column(window.column)) inside.push_back(window.low <= v && v <= window.high);
  return inside;
}

// One sensor column of run b against the reference run a over the window (the header's definitions).
struct Difference {
  double max_rel = 0, rms_rel = 0, peak_rel = 0;
};

Difference difference(const Run& a, const Run& b, const std::string& name, const CompareWindow& window) {
  const auto own = b.column(name);  // at its own rows: for its peak, not resampled
  const auto va = a.column(name), vb = resample(b.column("time"), own, a.column("time"));
  const auto in_a = rows_inside(a, window), in_b = rows_inside(b, window);
  double max_diff = 0, max_ref = 0, max_other = 0, sum_diff = 0, sum_ref = 0;
  for (std::size_t k = 0; k < va.size(); ++k) {
    if (!in_a[k]) continue;
    const double d = vb[k] - va[k];
    max_diff = std::max(max_diff, std::abs(d));
    max_ref = std::max(max_ref, std::abs(va[k]));
    sum_diff += d * d;
    sum_ref += va[k] * va[k];
  }
  for (std::size_t k = 0; k < own.size(); ++k)
    if (in_b[k]) max_other = std::max(max_other, std::abs(own[k]));
  const double ref = std::max(max_ref, 1e-300);
  return {max_diff / ref, std::sqrt(sum_diff / std::max(sum_ref, 1e-300)), (max_other - max_ref) / ref};
}

// b's first break relative to a's; none where either run has no break.
std::optional<double> first_break_difference(const Run& a, const Run& b) {
  if (!a.first_break || !b.first_break) return std::nullopt;
  return (*b.first_break - *a.first_break) / *a.first_break;
}

// A figure of the pairs: the value of one pair, or the median and the range of several; in %.
std::string figure(const std::vector<double>& v, bool sign) {
  const char* one = sign ? "%+.3g %%" : "%.3g %%";
  char text[128];
  if (v.size() == 1) {
    std::snprintf(text, sizeof text, one, 100 * v[0]);
  } else {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    std::snprintf(text, sizeof text, sign ? "%+.3g %% (%+.3g to %+.3g %%)" : "%.3g %% (%.3g to %.3g %%)",
                  100 * median(v), 100 * *lo, 100 * *hi);
  }
  return text;
}

double largest_magnitude(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

Json numbers(const std::vector<double>& v) {
  Json j = Json::array();
  for (double x : v) j.push_back(x);
  return j;
}

}  // namespace

CompareWindow parse_compare_window(const std::string& text) {
  const auto refuse = [&text]() {
    return InputError("--window '" + text + "': expected COLUMN=LO:HI with numbers LO <= HI, e.g. Delta=0.5e-3:2.0e-3");
  };
  const std::size_t equals = text.find('='), colon = text.find(':', equals == std::string::npos ? 0 : equals);
  if (equals == 0 || equals == std::string::npos || colon == std::string::npos) throw refuse();
  const auto number = [&](std::size_t from, std::size_t to) {
    double v = 0.0;
    // from_chars takes the whole text or fails: no empty string, spaces or trailing characters.
    const auto [end, error] = std::from_chars(text.data() + from, text.data() + to, v);
    if (from == to || error != std::errc() || end != text.data() + to || !std::isfinite(v)) throw refuse();
    return v;
  };
  CompareWindow w{text.substr(0, equals), number(equals + 1, colon), number(colon + 1, text.size())};
  if (w.low > w.high) throw refuse();
  return w;
}

CompareOutcome run_compare(const std::filesystem::path& reference_case, const std::filesystem::path& other_case,
                           const SceneOptions& reference, const SceneOptions& other, const std::filesystem::path& out_dir,
                           int ensemble, const CompareWindow& window) {
  std::error_code ec;
  if (std::filesystem::equivalent(reference_case, other_case, ec))
    std::fprintf(stderr, "arlequin compare: warning: both runs are %s; the differences are run-to-run noise\n",
                 reference_case.string().c_str());
  const auto pair_dir = [&](int k) { return k == 0 ? out_dir : out_dir / ("pair_" + std::to_string(k)); };
  const auto pair_options = [&](const SceneOptions& side, int k) {
    SceneOptions options = side;
    options.time_step_scale = 1.0 - k * ensemble_time_step_perturbation;
    return options;
  };
  Prepared prepared_a = prepare(reference_case, pair_options(reference, 0), out_dir / "reference");
  Prepared prepared_b = prepare(other_case, pair_options(other, 0), out_dir / "other");
  // Shared sensor columns (the energy totals mean different things for a DEM and a coupled run).
  const std::vector<std::string> sensors_a = sensor_columns(*prepared_a.scene), sensors_b = sensor_columns(*prepared_b.scene);
  const std::vector<std::string> units_a = sensor_units(*prepared_a.scene);
  std::vector<std::string> shared, shared_units;
  for (std::size_t k = 0; k < sensors_a.size(); ++k)
    if (std::find(sensors_b.begin(), sensors_b.end(), sensors_a[k]) != sensors_b.end())
      shared.push_back(sensors_a[k]), shared_units.push_back(units_a[k]);
  if (shared.empty())
    throw InputError(other_case.string() + ": shares no sensor column with " + reference_case.string());
  if (!window.column.empty() && window.column != "time" &&
      std::find(shared.begin(), shared.end(), window.column) == shared.end()) {
    std::string columns = "time";
    for (const auto& c : shared) columns += ", " + c;
    throw InputError("--window " + window.column + "=...: '" + window.column + "' is not a column of both runs; they share " +
                     columns);
  }
  if (ensemble > 1 && prepared_a.scene->static_only() && prepared_b.scene->static_only())
    throw InputError("--ensemble " + std::to_string(ensemble) + ": both cases are static solves, which have no time step to "
                     "perturb: every pair would be the same");

  // The pairs, one run at a time (a scene's memory freed before the next is built).
  std::vector<Run> reference_runs, other_runs;
  for (int k = 0; k < ensemble; ++k) {
    if (ensemble > 1) {
      std::printf("pair %d of 0..%d: time steps x (1 - %d x %.0e)\n", k, ensemble - 1, k, ensemble_time_step_perturbation);
      std::fflush(stdout);  // before the runs' own lines
    }
    if (k > 0) prepared_a = prepare(reference_case, pair_options(reference, k), pair_dir(k) / "reference");
    reference_runs.push_back(execute(prepared_a, pair_dir(k) / "reference"));
    prepared_a.scene.reset();
    if (k > 0) prepared_b = prepare(other_case, pair_options(other, k), pair_dir(k) / "other");
    other_runs.push_back(execute(prepared_b, pair_dir(k) / "other"));
    prepared_b.scene.reset();
  }
  const Run& a = reference_runs[0];
  const Run& b = other_runs[0];
  const std::size_t pairs = reference_runs.size();
  if (!window.column.empty()) {
    char range[128];
    std::snprintf(range, sizeof range, "%s in [%g, %g]", window.column.c_str(), window.low, window.high);
    const auto rows_in = [&window](const Run& r) {
      const auto inside = rows_inside(r, window);
      return long(std::count(inside.begin(), inside.end(), true));
    };
    for (const auto* runs : {&reference_runs, &other_runs})
      for (const Run& r : *runs)
        if (rows_in(r) == 0) throw InputError("--window " + window.column + "=...: no row of " + r.name + "'s series.csv has " + range);
    std::printf("over the rows of %s with %s: %ld of %zu\n", a.name.c_str(), range, rows_in(a), a.rows.size());
  }

  Json sensors = Json::array();
  std::string csv = "sensor,max_relative_difference,rms_relative_difference,peak_relative_difference";
  if (pairs > 1)
    csv += ",max_relative_min,max_relative_max,peak_relative_min,peak_relative_max,reference_spread_max_relative,"
           "reference_spread_peak_min,reference_spread_peak_max";
  csv += "\n";
  std::vector<Plot> plots;
  // The plots' abscissa: the window's column (the DCB's P against Delta), time without one.
  const std::string abscissa = window.column.empty() ? "time" : window.column;
  const std::string abscissa_unit =
      abscissa == "time" ? "s" : shared_units[std::find(shared.begin(), shared.end(), abscissa) - shared.begin()];
  const auto labelled = [](const std::string& column, const std::string& unit) {
    return unit == "1" ? column : column + " [" + unit + "]";
  };
  if (pairs > 1)
    std::printf("%zu pairs: the median over them (lowest to highest); the reference's own spread is its runs of pairs "
                "1..%zu against its run of pair 0\n", pairs, pairs - 1);
  std::printf("| sensor | max rel. difference | RMS rel. difference | peak rel. difference |%s\n|---|---|---|---|%s\n",
              pairs > 1 ? " reference's own spread: max rel., peak |" : "", pairs > 1 ? "---|" : "");
  for (std::size_t s = 0; s < shared.size(); ++s) {
    const std::string& name = shared[s];
    std::vector<double> max_rel, rms_rel, peak_rel, spread, peak_spread;  // spread: the reference's, max rel.
    for (std::size_t k = 0; k < pairs; ++k) {
      const Difference d = difference(reference_runs[k], other_runs[k], name, window);
      max_rel.push_back(d.max_rel), rms_rel.push_back(d.rms_rel), peak_rel.push_back(d.peak_rel);
      if (k > 0) {
        const Difference own = difference(a, reference_runs[k], name, window);
        spread.push_back(own.max_rel), peak_spread.push_back(own.peak_rel);
      }
    }
    double spread_largest = 0, own_lo = 0, own_hi = 0;
    if (pairs > 1) {
      spread_largest = largest_magnitude(spread);
      const auto [lo, hi] = std::minmax_element(peak_spread.begin(), peak_spread.end());
      own_lo = *lo, own_hi = *hi;
    }
    Json j = Json::object();
    j["sensor"] = name;
    j["max_relative_difference"] = median(max_rel);
    j["rms_relative_difference"] = median(rms_rel);
    j["peak_relative_difference"] = median(peak_rel);
    char row[512];
    std::snprintf(row, sizeof row, "%s,%.6g,%.6g,%.6g", name.c_str(), median(max_rel), median(rms_rel), median(peak_rel));
    csv += row;
    if (pairs > 1) {
      Json members = Json::object();
      members["max_relative_difference"] = numbers(max_rel);
      members["rms_relative_difference"] = numbers(rms_rel);
      members["peak_relative_difference"] = numbers(peak_rel);
      j["pairs"] = members;
      j["reference_spread_max_relative"] = numbers(spread);
      j["reference_spread_peak_relative"] = numbers(peak_spread);
      const auto [max_lo, max_hi] = std::minmax_element(max_rel.begin(), max_rel.end());
      const auto [peak_lo, peak_hi] = std::minmax_element(peak_rel.begin(), peak_rel.end());
      std::snprintf(row, sizeof row, ",%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g", *max_lo, *max_hi, *peak_lo, *peak_hi,
                    spread_largest, own_lo, own_hi);
      csv += row;
    }
    csv += "\n";
    sensors.push_back(j);
    std::printf("| %s | %s | %s | %s |", name.c_str(), figure(max_rel, false).c_str(), figure(rms_rel, false).c_str(),
                figure(peak_rel, true).c_str());
    if (pairs > 1) std::printf(" up to %.3g %%, %+.3g to %+.3g %% |", 100 * spread_largest, 100 * own_lo, 100 * own_hi);
    std::printf("\n");
    if (name == abscissa) continue;  // itself against itself
    // Pair 0's two histories named in the legend, the further pairs' dashed in their run's colour.
    Plot& plot = plots.emplace_back();
    plot.file = "compare_" + name + ".png";
    plot.title = name + ": " + b.name + " against " + a.name + (pairs > 1 ? " (" + std::to_string(pairs) + " pairs)" : "");
    plot.x_label = labelled(abscissa, abscissa_unit);
    plot.y_label = labelled(name, shared_units[s]);
    for (std::size_t k = 0; k < pairs; ++k)
      for (const Run* r : {&reference_runs[k], &other_runs[k]}) {
        PlotCurve& curve = plot.curves.emplace_back();
        curve.label = k == 0 ? r->name : "";
        curve.style = k == 0 ? PlotCurve::Style::line : PlotCurve::Style::dashed;
        curve.colour = r == &reference_runs[k] ? 0 : 1;
        curve.x = r->column(abscissa), curve.y = r->column(name);
      }
  }

  // First breaks: per pair, none where a run of the pair has none (null in compare.json).
  std::vector<double> speedups, first_breaks, reference_first_breaks;
  Json first_break_pairs = Json::array(), reference_first_break_pairs = Json::array();
  for (std::size_t k = 0; k < pairs; ++k) {
    speedups.push_back(reference_runs[k].compute_seconds() / std::max(other_runs[k].compute_seconds(), 1e-12));
    const auto d = first_break_difference(reference_runs[k], other_runs[k]);
    if (d) first_breaks.push_back(*d);
    first_break_pairs.push_back(d ? Json(*d) : Json());
    if (k == 0) continue;
    const auto own = first_break_difference(a, reference_runs[k]);
    if (own) reference_first_breaks.push_back(*own);
    reference_first_break_pairs.push_back(own ? Json(*own) : Json());
  }
  const double speedup = median(speedups);
  const char* of_pair_0 = pairs > 1 ? " (pair 0)" : "";
  for (const Run* r : {&a, &b})
    std::printf("%s%s: %zu DEs, %ld nodes, %ld steps, compute %.3f s (setup %.3f s, output %.3f s)\n", r->name.c_str(),
                of_pair_0, r->particles, r->nodes, r->steps, r->compute_seconds(), r->setup, r->output);
  if (pairs == 1) {
    std::printf("speed-up of %s over %s (compute): %.2fx\n", b.name.c_str(), a.name.c_str(), speedup);
  } else {
    const auto [lo, hi] = std::minmax_element(speedups.begin(), speedups.end());
    std::printf("speed-up of %s over %s (compute): %.2fx (%.2fx to %.2fx)\n", b.name.c_str(), a.name.c_str(), speedup,
                *lo, *hi);
  }
  for (const Run* r : {&a, &b}) {
    std::printf("%s%s at the end: DEM %.4g J, continuum %.4g J, fracture %.4g J", r->name.c_str(), of_pair_0,
                r->dem_energy(), r->continuum_energy(), r->last("E_fracture"));
    if (r->first_break) std::printf("; first break at %.4g s", *r->first_break);
    std::printf("\n");
  }
  if (!first_breaks.empty()) {
    std::printf("first break: %s of the reference's", figure(first_breaks, true).c_str());
    if (pairs > 1 && first_breaks.size() < pairs) std::printf(" (%zu of %zu pairs broke in both runs)", first_breaks.size(), pairs);
    if (!reference_first_breaks.empty())
      std::printf("; the reference's own spread up to %.3g %%", 100 * largest_magnitude(reference_first_breaks));
    std::printf("\n");
  }
  bool completed = true, checks_passed = true;
  for (std::size_t k = 0; k < pairs; ++k)
    for (const Run* r : {&reference_runs[k], &other_runs[k]}) {
      completed = completed && r->ok;
      checks_passed = checks_passed && r->checks_passed;
      if (!r->checks_passed)
        std::printf("%s%s: a check of its case FAILED (its summary.json says which)\n", r->name.c_str(),
                    pairs > 1 ? (" (pair " + std::to_string(k) + ")").c_str() : "");
    }

  Json report = Json::object();
  report["reference"] = describe_run(a);
  report["other"] = describe_run(b);
  report["speedup_compute"] = speedup;
  if (!window.column.empty()) report["window"] = Json{{"column", window.column}, {"low", window.low}, {"high", window.high}};
  report["sensors"] = sensors;
  if (pairs == 1 && !first_breaks.empty()) report["first_break_relative_difference"] = first_breaks.front();
  if (pairs > 1) {
    Json e = Json::object();
    e["pairs"] = pairs;
    e["time_step_perturbation"] = ensemble_time_step_perturbation;
    e["speedup_compute_pairs"] = numbers(speedups);
    if (!first_breaks.empty()) e["first_break_relative_difference"] = median(first_breaks);
    e["first_break_relative_difference_pairs"] = first_break_pairs;
    e["reference_spread_first_break_relative"] = reference_first_break_pairs;
    report["ensemble"] = e;
  }
  write_file_atomically(out_dir / "compare.csv", csv);
  write_json_atomically(out_dir / "compare.json", report);
  write_plots(out_dir, plots);
  return {completed, checks_passed};
}

}  // namespace arlequin::app
