// SPDX-License-Identifier: GPL-3.0-or-later
// Bonded-block benchmark (docs/validation.md R9): the case cases/bonded_block_tension (20 x 20 x 50
// spheres, ~57 600 beam bonds, bottom fixed, top pulled at 0.1 m/s, dt = 1e-7 s), 2000 steps
// with no output, for 1 and 2 OpenMP threads. Prints setup time, step time, particle-steps/s,
// bond-steps/s and memory. Usage: bench_bonded_block [steps] [case.yaml]
#ifdef _OPENMP
#include <omp.h>
#endif

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "app/scene.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// Resident and peak resident memory of this process, bytes (Linux /proc).
std::pair<double, double> memory_bytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  double rss = 0, peak = 0;
  while (status >> key) {
    if (key == "VmRSS:") status >> rss;
    else if (key == "VmHWM:") status >> peak;
  }
  return {rss * 1024.0, peak * 1024.0};
}

}  // namespace

int main(int argc, char** argv) {
  const long steps = argc > 1 ? std::atol(argv[1]) : 2000;
  const std::string case_file =
      argc > 2 ? argv[2] : std::string(ARLEQUIN_SOURCE_DIR) + "/cases/bonded_block_tension/case.yaml";
  std::printf("bonded block benchmark: %s, %ld steps, no output\n", case_file.c_str(), steps);
  // Bytes the structure-of-arrays layout stores per DE and per beam bond (fields of
  // ParticleSet; BeamBondSet: two indices, L0, three stiffnesses, two unit vectors).
  using arlequin::Quat;
  using arlequin::Vec3;
  constexpr std::size_t per_de = 6 * sizeof(Vec3) + sizeof(Quat) + 2 * sizeof(double) + sizeof(arlequin::dem::GroupMask);
  constexpr std::size_t per_bond = 2 * sizeof(std::uint32_t) + 4 * sizeof(double) + 2 * sizeof(Vec3);
  std::printf("layout: %zu B per DE, %zu B per beam bond (targets <= 200, <= 150)\n", per_de, per_bond);
  double one_thread_rate = 0.0;
  for (int threads : {1, 2}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#else
    if (threads > 1) break;  // built without OpenMP: one thread only
#endif
    const double rss_before = memory_bytes().first;
    const auto t0 = Clock::now();
    arlequin::app::Scene scene = arlequin::app::build_scene(case_file, {});
    const double setup = std::chrono::duration<double>(Clock::now() - t0).count();
    const double rss_built = memory_bytes().first;
    const double n = double(scene.dem.particles.size());
    double bonds = 0;
    for (const auto& set : scene.dem.bond_sets()) bonds += double(set->size());

    const auto t1 = Clock::now();
    for (long s = 0; s < steps; ++s) scene.dem.step(scene.dt);
    const double run = std::chrono::duration<double>(Clock::now() - t1).count();
    const double bond_rate = bonds * steps / run;
    if (threads == 1) one_thread_rate = bond_rate;
    std::printf("threads %d: DEs %.0f, bonds %.0f, setup %.3f s, %ld steps %.3f s (%.3f ms/step)\n", threads, n,
                bonds, setup, steps, run, 1e3 * run / steps);
    std::printf("  particle-steps/s %.3e   bond-steps/s %.3e   speed-up vs 1 thread %.2f\n", n * steps / run,
                bond_rate, bond_rate / one_thread_rate);
    std::printf("  memory: scene %.1f MB resident = %.0f B per DE + bond pair (%.0f B/DE if all charged to DEs, "
                "%.0f B/bond if all to bonds); peak RSS %.1f MB\n",
                (rss_built - rss_before) / 1e6, (rss_built - rss_before) / (n + bonds),
                (rss_built - rss_before) / n, (rss_built - rss_before) / bonds, memory_bytes().second / 1e6);
  }
  return 0;
}
