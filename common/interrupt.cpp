// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/interrupt.hpp"

#include <utility>

namespace arlequin {

namespace {

volatile std::sig_atomic_t g_caught = 0;

// Async-signal-safe: one store. SA_RESETHAND has already put back the default action.
void record(int signal) { g_caught = signal; }

}  // namespace

InterruptScope::InterruptScope() {
  g_caught = 0;
  struct sigaction action {};
  action.sa_handler = record;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  // A signal the process was started ignoring (SIGINT in a background job, nohup) stays ignored.
  for (const auto& [signal, previous] : {std::pair{SIGINT, &previous_int_}, std::pair{SIGTERM, &previous_term_}}) {
    sigaction(signal, nullptr, previous);
    if (previous->sa_handler != SIG_IGN) sigaction(signal, &action, nullptr);
  }
}

InterruptScope::~InterruptScope() {
  sigaction(SIGINT, &previous_int_, nullptr);
  sigaction(SIGTERM, &previous_term_, nullptr);
}

int take_interrupt() {
  const int signal = g_caught;
  g_caught = 0;
  return signal;
}

std::string signal_name(int signal) {
  if (signal == SIGINT) return "SIGINT (Ctrl-C)";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

}  // namespace arlequin
