// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/plots.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>

#include "common/json.hpp"

extern char** environ;

namespace arlequin {
namespace {

const char* style_name(PlotCurve::Style style) {
  switch (style) {
    case PlotCurve::Style::points: return "points";
    case PlotCurve::Style::line_points: return "line_points";
    case PlotCurve::Style::dashed: return "dashed";
    case PlotCurve::Style::line: break;
  }
  return "line";
}

Json plot_json(const Plot& plot) {
  Json j = Json::object();
  j["file"] = plot.file;
  j["title"] = plot.title;
  j["x_label"] = plot.x_label;
  j["y_label"] = plot.y_label;
  j["y2_label"] = plot.y2_label;
  j["log_x"] = plot.log_x;
  j["log_y"] = plot.log_y;
  j["log_y2"] = plot.log_y2;
  Json& curves = j["series"] = Json::array();
  for (const PlotCurve& c : plot.curves) {
    Json s = Json::object();
    s["label"] = c.label;
    s["style"] = style_name(c.style);
    s["right_axis"] = c.right_axis;
    if (c.colour >= 0) s["colour"] = c.colour;
    if (!c.csv.empty()) {
      s["csv"] = c.csv;
      s["x"] = c.x_column;
      s["y"] = c.y_column;
      s["x_scale"] = c.x_scale;
      s["y_scale"] = c.y_scale;
    } else {
      s["x_values"] = c.x;
      s["y_values"] = c.y;
    }
    curves.push_back(std::move(s));
  }
  return j;
}

std::string file_list(const std::vector<Plot>& plots) {
  std::string list;
  for (const Plot& p : plots) list += (list.empty() ? "" : ", ") + p.file;
  return list;
}

// Runs `python -m arlequin.plot dir` with python/ first on PYTHONPATH; returns its exit status
// (127 when it cannot be started) and its standard error.
int run_plotter(const std::string& python, const std::filesystem::path& dir, std::string& errors) {
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) return 127;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);

  std::vector<std::string> env_text;
  const char* old_path = std::getenv("PYTHONPATH");
  env_text.push_back(std::string("PYTHONPATH=") + ARLEQUIN_PYTHON_DIR + (old_path && *old_path ? std::string(":") + old_path : ""));
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "PYTHONPATH=", 11) != 0) env_text.emplace_back(*e);
  std::vector<char*> env;
  for (std::string& e : env_text) env.push_back(e.data());
  env.push_back(nullptr);
  std::string module = "-m", name = "arlequin.plot", folder = dir.string(), program = python;
  char* argv[] = {program.data(), module.data(), name.data(), folder.data(), nullptr};

  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv, env.data());
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
  char buffer[4096];
  for (ssize_t n; (n = read(pipe_fds[0], buffer, sizeof buffer)) > 0;) errors.append(buffer, std::size_t(n));
  close(pipe_fds[0]);
  if (spawned != 0) return 127;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status)) return 127;
  return WEXITSTATUS(status);
}

}  // namespace

void write_plots(const std::filesystem::path& dir, const std::vector<Plot>& plots) {
  if (plots.empty()) return;
  Json spec = Json::object();
  Json& list = spec["plots"] = Json::array();
  for (const Plot& p : plots) list.push_back(plot_json(p));
  write_json_atomically(dir / "plots.json", spec);

  const char* chosen = std::getenv("ARLEQUIN_PYTHON");
  const std::string python = chosen && *chosen ? chosen : ARLEQUIN_PYTHON;
  std::string errors;
  const int status = run_plotter(python, dir, errors);
  while (!errors.empty() && errors.back() == '\n') errors.pop_back();
  if (status == 127)
    std::fprintf(stderr, "plots skipped (%s): cannot run %s; install python3 and python3-matplotlib\n", file_list(plots).c_str(),
                 python.c_str());
  else if (!errors.empty())
    std::fprintf(stderr, "%s\n", errors.c_str());  // the plotter's own lines: what it skipped and why
  else if (status != 0)
    std::fprintf(stderr, "plots skipped (%s): python3 -m arlequin.plot exited with %d\n", file_list(plots).c_str(), status);
}

}  // namespace arlequin
