// SPDX-License-Identifier: GPL-3.0-or-later
// Coupled-step benchmark: the explicit step of an Arlequin-coupled case (default
// cases/wave_bar_coupled: DEM quarter, P1 continuum, linear weights, coarse mediator), without
// output. Prints the time per step and the heap allocations per step made by our code (the
// standard: none in the time loop). Counting: the global operator new is replaced here, and
// malloc-family calls from our static libraries (Eigen's dense storage included) are wrapped at
// link time (-Wl,--wrap); allocations inside shared libraries (PETSc, libc++ internals) that do
// not go through operator new are not seen. Usage: bench_coupled_step [steps] [case.yaml]
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>

#include "app/scene.hpp"

namespace {
std::atomic<long> allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  ++allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

extern "C" {
void* __real_malloc(std::size_t n);
void* __real_calloc(std::size_t n, std::size_t size);
void* __real_realloc(void* p, std::size_t n);
void* __wrap_malloc(std::size_t n) {
  ++allocations;
  return __real_malloc(n);
}
void* __wrap_calloc(std::size_t n, std::size_t size) {
  ++allocations;
  return __real_calloc(n, size);
}
void* __wrap_realloc(void* p, std::size_t n) {
  ++allocations;
  return __real_realloc(p, n);
}
}

int main(int argc, char** argv) {
  const long steps = argc > 1 ? std::atol(argv[1]) : 2000;
  const std::string case_file =
      argc > 2 ? argv[2] : std::string(ARLEQUIN_SOURCE_DIR) + "/cases/wave_bar_coupled/case.yaml";
  arlequin::app::Scene scene = arlequin::app::build_scene(case_file, {});
  if (!scene.model->monitor()) {
    std::fprintf(stderr, "%s: not a coupled case\n", case_file.c_str());
    return 2;
  }
  for (int n = 0; n < 10; ++n) scene.model->step(scene.dt);  // scratch sized on first use
  const long before = allocations.load();
  const auto t0 = std::chrono::steady_clock::now();
  for (long n = 0; n < steps; ++n) scene.model->step(scene.dt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const long counted = allocations.load() - before;
  std::printf("coupled step benchmark: %s\n  %zu DEs, dt %.4g s, %ld steps\n  %.2f us per step (%.0f steps/s)\n"
              "  heap allocations in the time loop: %ld (%.2f per step)\n",
              case_file.c_str(), scene.dem.particles.size(), scene.dt, steps, 1e6 * seconds / double(steps),
              double(steps) / seconds, counted, double(counted) / double(steps));
  return 0;
}
