// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>

#include "app/runner.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "common/json.hpp"
#include "common/plots.hpp"

namespace arlequin::app {

SweepAxis parse_sweep_axis(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw InputError("--over " + text + ": expected key.path=value1,value2,...");
  SweepAxis axis{text.substr(0, eq), {}};
  // Values split at the commas outside brackets, so a value may be a YAML list ([[..], [..]]).
  int depth = 0;
  std::string value;
  for (char c : text.substr(eq + 1)) {
    depth += c == '[' ? 1 : c == ']' ? -1 : 0;
    if (depth < 0) throw InputError("--over " + text + ": unbalanced ']'");
    if (c == ',' && depth == 0) {
      if (!value.empty()) axis.values.push_back(value);
      value.clear();
    } else {
      value += c;
    }
  }
  if (depth != 0) throw InputError("--over " + text + ": unbalanced '['");
  if (!value.empty()) axis.values.push_back(value);
  if (axis.values.empty()) throw InputError("--over " + text + ": no values after '='");
  return axis;
}

namespace {

// sweep.png: the first check's value against the first axis when its values are numbers (one
// line per combination of the other axes); sweep_time.png: against the wall time, one point
// per run.
void plot_sweep(const std::filesystem::path& dir, const std::vector<SweepAxis>& axes,
                const std::vector<std::vector<std::string>>& picked, const std::vector<double>& value,
                const std::vector<double>& wall, const std::string& check) {
  std::vector<double> first(picked.size());
  bool numeric = true;
  for (std::size_t r = 0; r < picked.size(); ++r) {
    char* end = nullptr;
    first[r] = std::strtod(picked[r][0].c_str(), &end);
    numeric = numeric && end != picked[r][0].c_str() && *end == '\0';
  }
  const auto plot_against = [&](bool along_first_axis) {
    Plot spec;
    spec.file = along_first_axis ? "sweep.png" : "sweep_time.png";
    spec.title = "arlequin sweep: " + check;
    spec.y_label = check + " (checked value)";
    spec.x_label = along_first_axis ? axes[0].key : "wall time (s)";
    spec.log_y = std::all_of(value.begin(), value.end(), [](double v) { return v > 0.0; });
    std::vector<std::string> labels;
    for (std::size_t r = 0; r < picked.size(); ++r) {
      std::string label;
      // Axes going with another are named by it (their values can be whole sections).
      for (std::size_t k = along_first_axis ? 1 : 0; k < axes.size(); ++k)
        if (!axes[k].with_previous)
          label += (label.empty() ? "" : ", ") + axes[k].key.substr(axes[k].key.rfind('.') + 1) + "=" + picked[r][k];
      auto it = std::find(labels.begin(), labels.end(), label);
      if (it == labels.end()) {
        labels.push_back(label);
        PlotCurve& curve = spec.curves.emplace_back();
        curve.label = label;
        curve.style = along_first_axis ? PlotCurve::Style::line_points : PlotCurve::Style::points;
        it = labels.end() - 1;
      }
      PlotCurve& series = spec.curves[it - labels.begin()];
      series.x.push_back(along_first_axis ? first[r] : wall[r]);
      series.y.push_back(value[r]);
    }
    return spec;
  };
  std::vector<Plot> plots;
  if (numeric) plots.push_back(plot_against(true));
  plots.push_back(plot_against(false));
  write_plots(dir, plots);
}

struct SweepRow {
  std::vector<std::string> picked;  // one value per axis
  std::size_t particles = 0;
  long nodes = 0, steps = 0;
  std::vector<std::pair<double, double>> checks;  // value, relative error; empty if not run
  double wall = 0.0;
  std::string status;
};

// The Markdown header (names and rule lines) and the CSV header.
std::pair<std::string, std::string> format_header(const std::vector<SweepAxis>& axes,
                                                  const std::vector<std::string>& check_names) {
  std::string md = "|", rule = "|", csv;
  for (const auto& a : axes) md += " " + a.key + " |", rule += "---|", csv += a.key + ",";
  md += " DEs | nodes | steps |", rule += "---|---|---|", csv += "particles,continuum_nodes,steps,";
  for (const auto& c : check_names) md += " " + c + " | error |", rule += "---|---|", csv += c + "," + c + "_relative_error,";
  md += " wall s | status |", rule += "---|---|", csv += "wall_seconds,status";
  return {md + "\n" + rule, csv};
}

// A CSV field: quoted (RFC 4180, quotes doubled) when it holds a comma, a quote or a line break,
// as a swept box or vector does.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// One Markdown line and one CSV row; a run that never got to its checks shows "-" there.
std::pair<std::string, std::string> format_row(const SweepRow& row, std::size_t num_checks) {
  std::string line = "|", csv;
  for (const auto& v : row.picked) line += " " + v + " |", csv += csv_field(v) + ",";
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, " %zu | %ld | %ld |", row.particles, row.nodes, row.steps);
  line += buffer;
  csv += std::to_string(row.particles) + "," + std::to_string(row.nodes) + "," + std::to_string(row.steps) + ",";
  for (std::size_t c = 0; c < num_checks; ++c) {
    if (c < row.checks.size()) {
      std::snprintf(buffer, sizeof buffer, " %.6g | %.3g %% |", row.checks[c].first, 100 * row.checks[c].second);
      line += buffer;
      std::snprintf(buffer, sizeof buffer, "%.9g,%.6g,", row.checks[c].first, row.checks[c].second);
      csv += buffer;
    } else {
      line += " - | - |", csv += ",,";
    }
  }
  std::snprintf(buffer, sizeof buffer, " %.3f | %s |", row.wall, row.status.c_str());
  line += buffer;
  std::snprintf(buffer, sizeof buffer, "%.6f,", row.wall);
  csv += buffer + csv_field(row.status);
  return {line, csv};
}

}  // namespace

bool run_sweep(const std::filesystem::path& case_file, const SceneOptions& base, const std::vector<SweepAxis>& axes,
               const std::filesystem::path& out_dir) {
  std::size_t runs = 1;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    if (!axes[k].with_previous) {
      runs *= axes[k].values.size();
    } else if (k == 0 || axes[k].values.size() != axes[k - 1].values.size()) {
      throw InputError("--with " + axes[k].key + ": expected as many values as the --over or --with before it" +
                       (k == 0 ? std::string(" (there is none)") : " (" + std::to_string(axes[k - 1].values.size()) + ")"));
    }
  }
  std::vector<std::string> check_names;  // from the first scene built
  bool columns_known = false, header_printed = false;
  std::vector<SweepRow> rows;
  std::size_t printed = 0;
  // Rows are printed as they come once the check columns are known (from the first scene that
  // could be built); a run whose scene could not be built still gets its row.
  const auto print_rows = [&](bool final) {
    if (!header_printed && (columns_known || final)) {
      std::printf("%s\n", format_header(axes, check_names).first.c_str());
      header_printed = true;
    }
    for (; header_printed && printed < rows.size(); ++printed)
      std::printf("%s\n", format_row(rows[printed], check_names.size()).first.c_str());
    std::fflush(stdout);
  };
  // sweep.csv and sweep.png from the rows so far: at the end, and when a later run's input is bad
  // (its error ends the sweep, the finished rows stay).
  const auto write_table = [&] {
    std::string csv = format_header(axes, check_names).second + "\n";
    std::vector<std::vector<std::string>> picked;
    std::vector<double> first_value, wall;
    for (const SweepRow& row : rows) {
      csv += format_row(row, check_names.size()).second + "\n";
      if (!row.checks.empty()) {
        picked.push_back(row.picked);
        first_value.push_back(row.checks[0].first);
        wall.push_back(row.wall);
      }
    }
    write_file_atomically(out_dir / "sweep.csv", csv);
    if (!picked.empty()) plot_sweep(out_dir, axes, picked, first_value, wall, check_names[0]);
  };
  bool all_ok = true;
  for (std::size_t run = 0; run < runs; ++run) {
    // Mixed-radix digits of `run` pick one value per axis.
    SceneOptions options = base;
    options.out_dir = out_dir / std::to_string(run);
    SweepRow row;
    std::size_t index = 0;
    for (std::size_t k = 0, rest = run; k < axes.size(); ++k) {
      if (!axes[k].with_previous) {
        index = rest % axes[k].values.size();
        rest /= axes[k].values.size();
      }
      row.picked.push_back(axes[k].values[index]);
      options.overrides.push_back(Override(axes[k].key + "=" + row.picked.back(), axes[k].with_previous ? "--with" : "--over"));
    }
    const auto t0 = std::chrono::steady_clock::now();
    RunOptions run_options;
    row.status = "not built";
    try {
      Scene scene = build_scene(case_file, options);
      run_options.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (!columns_known)
        for (const auto& c : scene.checks) check_names.push_back(c.column);
      columns_known = true;
      Json counts = Json::object();
      if (scene.continuum) scene.continuum->describe(counts);
      scene.model->describe(counts);
      row.particles = scene.dem.particles.size();
      row.nodes = counts.value("continuum_nodes", 0L);
      row.status = "stopped";
      const RunResult r = run_scene(scene, run_options);
      row.steps = r.steps;
      row.wall = run_options.setup_seconds + r.wall_seconds;
      for (const auto& c : r.checks) row.checks.emplace_back(c.value, c.relative_error);
      row.status = r.all_checks_passed() ? "ok" : "check failed";
    } catch (const RunError& e) {
      std::fprintf(stderr, "arlequin sweep: run %zu (%s): %s\n", run, options.out_dir.string().c_str(), e.what());
    } catch (const InputError&) {
      if (!rows.empty()) write_table();
      throw;
    }
    all_ok = all_ok && row.status == "ok";
    rows.push_back(std::move(row));
    print_rows(false);
    // After every run, so that a long sweep stopped part way keeps the table of the runs done.
    if (columns_known) write_table();
  }
  print_rows(true);
  write_table();
  return all_ok;
}

}  // namespace arlequin::app
