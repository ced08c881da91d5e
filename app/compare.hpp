// SPDX-License-Identifier: GPL-3.0-or-later
// `arlequin compare`: runs two cases that share sensors (e.g. pure DEM and coupled) and
// reports, for each shared sensor column, the second run's difference to the first (the
// reference) against both runs' run times and sizes: the user's "error against run time" view.
//
// Differences, with b interpolated linearly onto a's output times:
//   max relative = max |b - a| / max |a|,  RMS relative = rms(b - a) / rms(a),
//   peak relative = (max |b| - max |a|) / max |a| (b at its own samples: a peak between a's is kept),
// over every row, or over a window (`--window COLUMN=LO:HI`): a's rows, and b's own samples for its
// peak, whose COLUMN lies in [LO, HI] (the DCB's Delta in [0.5, 2] mm, docs/decisions.md#d51); the
// plots then draw each sensor's whole history against COLUMN (the DCB's P(Delta)).
// Also each run's energies at its end (DEM kinetic + bond + contact, continuum kinetic + strain,
// fracture) and first break (summary.json), and the second's first break relative to the first's.
// Writes compare.csv (one row per sensor), compare.json (runs, speed-up, sensors, the first
// break's relative difference where both runs broke) and one PNG per sensor overlaying both time
// histories, into the output folder (atomically).
//
// An ensemble (`--ensemble N`, docs/decisions.md#d44) runs N pairs: pair k with both cases' time
// steps scaled by 1 - k 1e-9, a perturbation far below either model's discretisation error that
// changes the last bits of every step. Where the runs are chaotic (contacts and breakage) each
// pair is one draw; the figures above are then the median over the pairs with their range, and
// the reference's runs k >= 1 against its run 0 give the reference's own spread, below which no
// difference means anything.
#pragma once
#include <filesystem>
#include <string>

#include "app/scene.hpp"

namespace arlequin::app {

// What the two runs came to: both completed, and both passed their case's checks.
struct CompareOutcome {
  bool completed = true;
  bool checks_passed = true;
};

// The rows a comparison looks at: those whose `column` (a sensor column of both runs, or time)
// lies in [low, high]; every row where `column` is empty.
struct CompareWindow {
  std::string column;
  double low = 0.0, high = 0.0;
};

// "COLUMN=LO:HI" (LO <= HI, numbers); InputError naming the option and the text otherwise.
CompareWindow parse_compare_window(const std::string& text);

// The relative change of the time step between two pairs of an ensemble.
inline constexpr double ensemble_time_step_perturbation = 1e-9;

// Builds both scenes, then runs them one after the other, each judged by its own checks; with
// ensemble > 1, the further pairs after them (each pair's scenes built just before it runs).
// Pair 0 writes to out_dir/reference and out_dir/other, pair k to out_dir/pair_k/... InputError,
// before any run, when a case is bad, the cases share no sensor column, or an ensemble is asked
// of two static solves, or the window's column is not one of both runs (after the runs, when a run
// of any pair has no row in the window). With an ensemble, compare.json's "reference" and "other" and the runs'
// printed sizes and energies are pair 0's; every difference and the speed-up are medians (the
// first break's under "ensemble", with each pair's).
CompareOutcome run_compare(const std::filesystem::path& reference_case, const std::filesystem::path& other_case,
                           const SceneOptions& reference, const SceneOptions& other, const std::filesystem::path& out_dir,
                           int ensemble = 1, const CompareWindow& window = {});

}  // namespace arlequin::app
