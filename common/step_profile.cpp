// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/step_profile.hpp"

#include <algorithm>
#include <cstdio>

namespace arlequin {

namespace {

std::string line(const char* format, auto... values) {
  char text[256];
  std::snprintf(text, sizeof text, format, values...);
  return text;
}

// Karp-Flatt serial fraction of a speed-up S on T threads.
double serial_fraction(double speed_up, int threads) {
  return (1.0 / speed_up - 1.0 / threads) / (1.0 - 1.0 / threads);
}

std::size_t name_width(const std::vector<StepProfile::Phase>& phases) {
  std::size_t width = 10;
  for (const auto& p : phases) width = std::max(width, p.name.size());
  return width;
}

}  // namespace

std::string StepProfile::table() const {
  const double total = seconds(), per_step = 1e3 / static_cast<double>(std::max(steps_, 1L));
  const int w = static_cast<int>(name_width(phases_));
  std::string out = line("%-*s %12s %8s %8s\n", w, "phase", "ms/step", "share", "serial");
  for (const Phase& p : phases_)
    out += line("%-*s %12.4f %7.1f%% %7.1f%%\n", w, p.name.c_str(), p.seconds * per_step, 100.0 * p.seconds / total,
                100.0 * p.serial_seconds / total);
  out += line("%-*s %12.4f %7.1f%% %7.1f%%\n", w, "step", total * per_step, 100.0, 100.0 * serial_seconds() / total);
  return out;
}

std::string StepProfile::comparison(const StepProfile& one, const StepProfile& many, int threads) {
  const long steps = one.steps_;
  const double per_step = 1e3 / static_cast<double>(std::max(steps, 1L));
  const int w = static_cast<int>(std::max(name_width(one.phases_), name_width(many.phases_)));
  std::string out = line("profile on 1 and T = %d threads, %ld steps; e: Karp-Flatt serial fraction; serial: share of the "
                         "T-thread step on one thread by design\n",
                         threads, steps);
  out += line("%-*s %11s %11s %8s %8s %9s\n", w, "phase", "1 thr ms", "T thr ms", "speedup", "e (K-F)", "serial");
  const double total_many = many.seconds();
  for (const Phase& p : one.phases_) {
    const auto it = std::find_if(many.phases_.begin(), many.phases_.end(), [&](const Phase& q) { return q.name == p.name; });
    if (it == many.phases_.end() || !(p.seconds > 0.0 && it->seconds > 0.0)) continue;  // not run (a phase of the runner)
    const double s = p.seconds / it->seconds;
    out += line("%-*s %11.4f %11.4f %7.2fx %7.1f%% %8.1f%%\n", w, p.name.c_str(), p.seconds * per_step,
                it->seconds * per_step, s, 100.0 * serial_fraction(s, threads), 100.0 * it->serial_seconds / total_many);
  }
  const double s = one.seconds() / total_many;
  out += line("%-*s %11.4f %11.4f %7.2fx %7.1f%% %8.1f%%\n", w, "step", one.seconds() * per_step, total_many * per_step, s,
              100.0 * serial_fraction(s, threads), 100.0 * many.serial_seconds() / total_many);
  return out;
}

}  // namespace arlequin
