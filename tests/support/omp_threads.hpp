// SPDX-License-Identifier: GPL-3.0-or-later
// For tests of thread independence: sets the OpenMP thread count for the scope's lifetime and
// puts the previous count back, also when an assertion leaves the test early; OmpThreadsOfRuns
// does the same for the runs the test starts (OMP_NUM_THREADS).
#pragma once
#include <cstdlib>
#include <string>

namespace arlequin::test {

class OmpThreadsOfRuns {
 public:
  explicit OmpThreadsOfRuns(int threads) { setenv("OMP_NUM_THREADS", std::to_string(threads).c_str(), 1); }
  ~OmpThreadsOfRuns() { had_ ? setenv("OMP_NUM_THREADS", before_.c_str(), 1) : unsetenv("OMP_NUM_THREADS"); }
  OmpThreadsOfRuns(const OmpThreadsOfRuns&) = delete;
  OmpThreadsOfRuns& operator=(const OmpThreadsOfRuns&) = delete;

 private:
  bool had_ = std::getenv("OMP_NUM_THREADS") != nullptr;
  std::string before_ = had_ ? std::getenv("OMP_NUM_THREADS") : "";
};

}  // namespace arlequin::test

#ifdef _OPENMP
#include <omp.h>

namespace arlequin::test {

class OmpThreads {
 public:
  explicit OmpThreads(int threads) : before_(omp_get_max_threads()) { omp_set_num_threads(threads); }
  ~OmpThreads() { omp_set_num_threads(before_); }
  OmpThreads(const OmpThreads&) = delete;
  OmpThreads& operator=(const OmpThreads&) = delete;

 private:
  int before_;
};

}  // namespace arlequin::test
#endif
