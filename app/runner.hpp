// SPDX-License-Identifier: GPL-3.0-or-later
// Runs a scene to its end time: the time loop, outputs (series.csv, fields.h5/.xdmf,
// summary.json in the output folder, each written atomically), progress and health checks.
//
// Contract: on success returns the run's figures; on a RunError (NaN, blow-up) the outputs so
// far are flushed and closed, summary.json records the failure, and the error is rethrown. A
// SIGINT or SIGTERM during the time loop ends it the same way, with status "interrupted", and
// throws Interrupted (common/interrupt.hpp), which no RunError handler catches; one that comes
// after the last step lets the run complete (status "completed") and then throws Interrupted.
// Checkpoints (docs/restart.md): output.checkpoint_every writes checkpoint.h5 in the output folder
// at that interval of simulated time and when the run ends; a SIGINT or SIGTERM writes one
// before the outputs close, whatever the case says; a failed run writes none (its last one stays).
#pragma once
#include <algorithm>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "app/scene.hpp"
#include "common/state_archive.hpp"

namespace arlequin::app {

struct RunOptions {
  long max_steps = -1;         // --steps N: stop after N steps (< 0: run to the end time)
  bool show_progress = false;  // progress line on stderr (a terminal, not CI)
  bool announce_run_time = false;  // without that line: one line on stderr if the run will last over a minute
  double setup_seconds = 0.0;  // wall time spent building the scene, for the summary
  // Called after each series.csv row with the row's sensor values (column, value); a
  // non-empty answer ends the run there as completed, with that reason in the summary
  // (e.g. a test to failure once the sample has broken).
  std::function<std::string(const std::vector<std::pair<std::string, double>>&)> stop_after_row;
  // --restart FILE: the checkpoint read from `restart_file` (common/state_file.hpp). The run checks
  // it is of this scene (app/checkpoint.hpp), takes its state and continues from its step,
  // appending to the series and the breaks and extending the fields (their frames come from the
  // fields.h5 beside the checkpoint).
  const StateArchive* restart = nullptr;
  std::filesystem::path restart_file;
};

struct RunResult {
  long steps = 0;
  double simulated_time = 0.0;  // s
  double wall_seconds = 0.0;    // time loop only
  double output_seconds = 0.0;  // of which writing outputs (rows, frames)
  dem::Energies energies;
  std::vector<std::pair<std::string, double>> sensors;  // last value of each column
  std::string stop_reason;      // why stop_after_row ended the run early (empty: it did not)
  std::string damage_in_overlap;  // the first break where the coupling weights the bonds (empty: none)
  std::size_t damage_in_overlap_breaks = 0;  // all such breaks
  struct CheckResult {
    const Check* check;
    double value;           // final value, or crossing time (NaN: never reached)
    double relative_error;
    bool passed;
  };
  std::vector<CheckResult> checks;
  std::string checks_skipped;   // why the checks were not evaluated (empty: they were)
  bool all_checks_passed() const {
    return std::all_of(checks.begin(), checks.end(), [](const CheckResult& c) { return c.passed; });
  }
};

RunResult run_scene(Scene& scene, const RunOptions& options);

// The energy balance's verdict on a series.csv row (docs/stability.md#energy-balance): empty while
// |balance| <= balance_limit x budget or the balance is not finite (the finite check's to name),
// else why the run stops. `budget` is the energy that
// started in, entered, left or broke in the scene (the start's energy or round-off floor, |work|,
// the coupling's |work|, dissipated, fractured), `parts` the energies the message lists (name, J),
// `likely_cause` what the message suggests.
constexpr double balance_limit = 0.25;
std::string unbalanced(double balance, double budget, const std::vector<std::pair<std::string, double>>& parts,
                       const std::string& likely_cause);

std::string describe(const Check& check);  // "final value", "maximum over Delta in [0, 0.002]", ...
// Steps per second of the time loop without its output (summary.json's and the closing line's).
double steps_per_second(const RunResult& r);

}  // namespace arlequin::app
