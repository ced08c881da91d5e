#include "app/sweep.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "app/runner.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "common/json.hpp"

namespace arlequin::app {

SweepAxis parse_sweep_axis(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw InputError("--over " + text + ": expected key.path=value1,value2,...");
  SweepAxis axis{text.substr(0, eq), {}};
  std::stringstream values(text.substr(eq + 1));
  for (std::string v; std::getline(values, v, ',');)
    if (!v.empty()) axis.values.push_back(v);
  return axis;
}

bool run_sweep(const std::filesystem::path& case_file, const SceneOptions& base, const std::vector<SweepAxis>& axes,
               const std::filesystem::path& out_dir) {
  std::size_t runs = 1;
  for (const auto& a : axes) runs *= a.values.size();
  std::string csv, header;
  bool all_ok = true;
  for (std::size_t run = 0; run < runs; ++run) {
    // Mixed-radix digits of `run` pick one value per axis.
    SceneOptions options = base;
    options.out_dir = out_dir / std::to_string(run);
    std::vector<std::string> picked;
    for (std::size_t k = 0, rest = run; k < axes.size(); rest /= axes[k].values.size(), ++k) {
      picked.push_back(axes[k].values[rest % axes[k].values.size()]);
      options.overrides.push_back(axes[k].key + "=" + picked.back());
    }
    const auto t0 = std::chrono::steady_clock::now();
    Scene scene = build_scene(case_file, options);
    RunOptions run_options;
    run_options.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::string status = "ok";
    RunResult r;
    try {
      r = run_scene(scene, run_options);
      if (!r.all_checks_passed()) status = "check failed";
    } catch (const RunError& e) {
      status = "stopped";
    }
    all_ok = all_ok && status == "ok";
    const double wall = run_options.setup_seconds + r.wall_seconds;
    if (run == 0) {
      std::string md = "|", rule = "|";
      for (const auto& a : axes) md += " " + a.key + " |", rule += "---|", header += a.key + ",";
      md += " DEs | nodes | steps |", rule += "---|---|---|";
      header += "particles,continuum_nodes,steps,";
      for (const auto& c : r.checks) {
        md += " " + c.check->column + " | error |", rule += "---|---|";
        header += c.check->column + "," + c.check->column + "_relative_error,";
      }
      md += " wall s | status |", rule += "---|---|";
      header += "wall_seconds,status";
      std::printf("%s\n%s\n", md.c_str(), rule.c_str());
    }
    Json counts = Json::object();
    if (scene.continuum) scene.continuum->describe(counts);
    const long nodes = counts.find("continuum_nodes") ? long(counts.at("continuum_nodes").as_integer()) : 0;
    std::string line = "|", row;
    for (const auto& v : picked) line += " " + v + " |", row += v + ",";
    char buffer[256];
    std::snprintf(buffer, sizeof buffer, " %zu | %ld | %ld |", scene.dem.particles.size(), nodes, r.steps);
    line += buffer;
    row += std::to_string(scene.dem.particles.size()) + "," + std::to_string(nodes) + "," + std::to_string(r.steps) + ",";
    for (const auto& c : r.checks) {
      std::snprintf(buffer, sizeof buffer, " %.6g | %.3g %% |", c.value, 100 * c.relative_error);
      line += buffer;
      std::snprintf(buffer, sizeof buffer, "%.9g,%.6g,", c.value, c.relative_error);
      row += buffer;
    }
    std::snprintf(buffer, sizeof buffer, " %.3f | %s |", wall, status.c_str());
    line += buffer;
    std::snprintf(buffer, sizeof buffer, "%.6f,%s", wall, status.c_str());
    row += buffer;
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
    csv += row + "\n";
  }
  write_file_atomically(out_dir / "sweep.csv", header + "\n" + csv);
  return all_ok;
}

}  // namespace arlequin::app
