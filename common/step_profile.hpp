// SPDX-License-Identifier: GPL-3.0-or-later
// Wall time of each phase of the time step (arlequin run --profile, bench_bonded_block
// --profile): the models and the runner time their phases into a StepProfile when one is
// attached, and cost one test per phase when none is.
//
// Each phase records its wall seconds and the part of them that ran on one thread by design (a
// loop below common/parallel.hpp's thresholds, or serial code): on T threads that part is the
// step's serial work as the code decides it. Imbalance and the barriers inside a threaded phase
// do not show there; they show in the phase's speed-up between two profiles of the same steps on
// 1 and T threads, from which the benchmark prints the Karp-Flatt serial fraction
//   e = (1/S - 1/T) / (1 - 1/T),  S = t_1 / t_T
// (Karp and Flatt 1990, docs/references.md#karp1990): the fraction f of Amdahl's law
// S = 1 / (f + (1 - f) / T) that the measured speed-up implies.
#pragma once
#include <chrono>
#include <string>
#include <vector>

namespace arlequin {

class StepProfile {
 public:
  struct Phase {
    std::string name;
    double seconds = 0.0;         // wall time, all steps
    double serial_seconds = 0.0;  // of which on one thread by design
  };
  // Index of the phase so named; added (at the end of the table) on first use.
  int phase(const std::string& name) {
    for (std::size_t k = 0; k < phases_.size(); ++k)
      if (phases_[k].name == name) return static_cast<int>(k);
    phases_.push_back({name});
    return static_cast<int>(phases_.size()) - 1;
  }
  void add(int phase, double seconds, bool on_threads) {
    phases_[static_cast<std::size_t>(phase)].seconds += seconds;
    if (!on_threads) phases_[static_cast<std::size_t>(phase)].serial_seconds += seconds;
  }
  const std::vector<Phase>& phases() const { return phases_; }
  void count_step() { ++steps_; }  // one more step timed
  long steps() const { return steps_; }
  double seconds() const {
    double total = 0.0;
    for (const Phase& p : phases_) total += p.seconds;
    return total;
  }
  double serial_seconds() const {
    double total = 0.0;
    for (const Phase& p : phases_) total += p.serial_seconds;
    return total;
  }
  // The table: per phase, ms per step, its share of the step and its serial share; a last row
  // for the whole step.
  std::string table() const;
  // The same phases over the same steps on 1 and `threads` threads side by side, with each
  // phase's speed-up and Karp-Flatt serial fraction, and the whole step's.
  static std::string comparison(const StepProfile& one_thread, const StepProfile& threaded, int threads);

 private:
  std::vector<Phase> phases_;
  long steps_ = 0;
};

// Times the scope into profile's phase (nothing without a profile).
class PhaseTimer {
 public:
  PhaseTimer(StepProfile* profile, int phase, bool on_threads)
      : profile_(profile), phase_(phase), on_threads_(on_threads) {
    if (profile_) start_ = std::chrono::steady_clock::now();
  }
  ~PhaseTimer() {
    if (profile_)
      profile_->add(phase_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(), on_threads_);
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  StepProfile* profile_;
  int phase_;
  bool on_threads_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace arlequin
