// SPDX-License-Identifier: GPL-3.0-or-later
// For tests of thread independence: sets the OpenMP thread count for the scope's lifetime and
// puts the previous count back, also when an assertion leaves the test early.
#pragma once
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
