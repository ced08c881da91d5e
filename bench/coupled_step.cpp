// SPDX-License-Identifier: GPL-3.0-or-later
// Coupled-step benchmark: the explicit step of an Arlequin-coupled case (default
// cases/wave_bar_coupled: DEM quarter, P1 continuum, linear weights, coarse mediator), without
// output. Prints the time per step and the heap allocations per step made by our code (the
// standard: none in the time loop), then the all-DEM run the case replaces (default
// cases/wave_bar_dem) and the coupled model's speed-up over it for the same simulated time.
// Counting: the global operator new is replaced here, and malloc-family calls from our static
// libraries (Eigen's dense storage included) are wrapped at link time (-Wl,--wrap); allocations
// inside shared libraries (PETSc, libc++ internals) that do not go through operator new are not
// seen. Usage: bench_coupled_step [steps] [case.yaml] [all_dem_case.yaml]
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

namespace {
struct Timing {
  double seconds_per_step;
  long allocations;  // in the timed steps
};
// The scene's model over `steps` steps, after ten that size its scratch.
Timing time_steps(arlequin::app::Scene& scene, long steps) {
  for (int n = 0; n < 10; ++n) scene.model->step(scene.dt);
  const long before = allocations.load();
  const auto t0 = std::chrono::steady_clock::now();
  for (long n = 0; n < steps; ++n) scene.model->step(scene.dt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return {seconds / double(steps), allocations.load() - before};
}
}  // namespace

int main(int argc, char** argv) {
  const long steps = argc > 1 ? std::atol(argv[1]) : 2000;
  const std::string source = ARLEQUIN_SOURCE_DIR;
  const std::string case_file = argc > 2 ? argv[2] : source + "/cases/wave_bar_coupled/case.yaml";
  const std::string reference_file = argc > 3 ? argv[3] : source + "/cases/wave_bar_dem/case.yaml";
  arlequin::app::Scene scene = arlequin::app::build_scene(case_file, {});
  if (!scene.model->coupled()) {
    std::fprintf(stderr, "%s: not a coupled case\n", case_file.c_str());
    return 2;
  }
  const Timing coupled = time_steps(scene, steps);
  std::printf("coupled step benchmark: %s\n  %zu DEs, dt %.4g s, %ld steps\n  %.2f us per step (%.0f steps/s)\n"
              "  heap allocations in the time loop: %ld (%.2f per step)\n",
              case_file.c_str(), scene.dem.particles.size(), scene.dt, steps, 1e6 * coupled.seconds_per_step,
              1.0 / coupled.seconds_per_step, coupled.allocations, double(coupled.allocations) / double(steps));
  // The run it replaces: the same simulated time all-DEM, at that model's own step.
  arlequin::app::Scene reference = arlequin::app::build_scene(reference_file, {});
  const double all_dem = time_steps(reference, steps).seconds_per_step;
  std::printf("all-DEM reference: %s\n  %zu DEs, dt %.4g s, %.2f us per step\n"
              "  speed-up of the coupled model for the same simulated time: %.2fx\n",
              reference_file.c_str(), reference.dem.particles.size(), reference.dt, 1e6 * all_dem,
              (all_dem / reference.dt) / (coupled.seconds_per_step / scene.dt));
  return 0;
}
