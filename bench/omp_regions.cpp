// SPDX-License-Identifier: GPL-3.0-or-later
// The cost of entering OpenMP for a loop too small for threads (common/parallel.hpp,
// run_threaded_if): a parallel region whose `if` clause is false still starts a team of one;
// an orphaned `omp for` outside any region runs in the calling thread. Prints ns per call of
// each, for a loop of 8 items, and of a real region on the threads there are.
// Usage: bench_omp_regions [calls] [threaded: 0 (default) or 1, to time the first two on threads]
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "common/parallel.hpp"

namespace {

double items[8];

template <class F>
double nanoseconds_per_call(long calls, F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < calls; ++k) f();
  return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / double(calls);
}

}  // namespace

int main(int argc, char** argv) {
  const long calls = argc > 1 ? std::atol(argv[1]) : 1000000;
  const long n = 8;
  bool threaded = false;  // read at run time, so the compiler cannot drop the region
  if (argc > 2) threaded = std::atoi(argv[2]) != 0;
  const double with_if = nanoseconds_per_call(calls, [&] {
#pragma omp parallel for schedule(static) if (threaded)
    for (long i = 0; i < n; ++i) items[i] += 1.0;
  });
  const double helper = nanoseconds_per_call(calls, [&] {
    arlequin::for_each_index(n, threaded, [](long i) { items[i] += 1.0; });
  });
  const double region = nanoseconds_per_call(calls / 10, [&] {
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; ++i) items[i] += 1.0;
  });
  std::printf("OpenMP overhead per loop of %ld items, %ld calls:\n", n, calls);
  const char* clause = threaded ? "true" : "false";
  std::printf("  parallel for with a %-5s if clause:   %8.1f ns\n", clause, with_if);
  std::printf("  for_each_index, threaded = %-5s:      %8.1f ns\n", clause, helper);
  std::printf("  parallel for on the threads there are: %6.1f ns\n", region);
  return items[0] > 0.0 ? 0 : 1;
}
