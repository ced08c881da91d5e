// SPDX-License-Identifier: GPL-3.0-or-later
// Stopping a run by hand (Ctrl-C, or SIGTERM from a batch system) without losing what it wrote.
//
// Contract: while an InterruptScope lives, the first SIGINT or SIGTERM only records the signal
// (the handler then falls back to the default action, so a second Ctrl-C ends the process at
// once). The time loop polls take_interrupt() once a step and, when it returns a signal, throws
// Interrupted: the run closes its outputs as after a failure and the exception travels up past
// the loops that survive a RunError (sweeps, virtual-test suites), so the whole command stops
// with exit code 128 + signal. Outside a scope both signals keep their previous handlers, so a
// Ctrl-C during set-up (mesh, packing) ends the process as usual: nothing is half-written, as
// every output file is written atomically. A signal the process was started ignoring (SIGINT
// in a shell's background job, nohup) stays ignored.
#pragma once
#include <csignal>
#include <stdexcept>
#include <string>

namespace arlequin {

class Interrupted : public std::runtime_error {
 public:
  Interrupted(int signal, const std::string& what) : std::runtime_error(what), signal_(signal) {}
  int signal() const { return signal_; }

 private:
  int signal_;
};

class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

 private:
  struct sigaction previous_int_{}, previous_term_{};
};

// The signal caught since the last call (SIGINT or SIGTERM), or 0; the record is cleared.
int take_interrupt();

// "SIGINT (Ctrl-C)", "SIGTERM", or "signal N".
std::string signal_name(int signal);

}  // namespace arlequin
