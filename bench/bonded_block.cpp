// SPDX-License-Identifier: GPL-3.0-or-later
// Bonded-block benchmark (docs/validation.md R9, docs/performance.md): by default the case
// cases/bonded_block_tension (20 x 20 x 50 spheres, ~57 600 beam bonds, bottom fixed, top pulled
// at 0.1 m/s), 2000 steps with no output, on 1 and 2 OpenMP threads. Prints setup time, step
// time, particle-steps/s, bond-steps/s and memory; for a case with contact (cases/granular_bed,
// cases/fabric_impact) also contact-steps/s (touching pairs summed over the steps, per second)
// and the neighbour list's share of the step (its builds, timed apart); a case without bonds
// is then ranked by contact-steps/s. With --repeat R the thread counts alternate R
// times and the medians are printed; with --profile the phases of the step on each thread count
// against one thread (common/step_profile.hpp).
// The same for a virtual test run to its end (the REV failure test): --virtual-test SPEC --sample
// NAME --test NAME times the test's time loop (sensors and rows included) the same way.
// With --kernel, the beam sets' block kernel alone on one thread (docs/performance.md#beam-kernel):
// over the set's bonds in the case's configuration, over eight blocks' bonds again and again (their
// data in the first-level cache: the kernel's own cost), and the whole force pass (kernel, stored
// actions and each DE's sum); the fastest of five runs each, as nothing makes a run faster than it is.
// Usage: bench_bonded_block [--steps N] [--threads 1,2,4,...] [--repeat R] [--profile] [--kernel] [--set k=v ...] [CASE.yaml]
//        bench_bonded_block --virtual-test SPEC --sample NAME --test NAME [--threads ...] [--repeat R] [--profile] [--set k=v ...]
#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "app/scene.hpp"
#include "app/virtual_tests.hpp"
#include "common/error.hpp"
#include "common/statistics.hpp"
#include "common/step_profile.hpp"
#include "dem/bonds/beam_bond.hpp"

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

// FNV-1a of bytes: a fingerprint of a run's result, equal on every thread count when the run's
// results are the same to the bit.
std::uint64_t fingerprint(const void* data, std::size_t bytes, std::uint64_t hash = 1469598103934665603ull) {
  const auto* c = static_cast<const unsigned char*>(data);
  for (std::size_t k = 0; k < bytes; ++k) hash = (hash ^ c[k]) * 1099511628211ull;
  return hash;
}

struct Options {
  long steps = 2000;
  std::vector<int> threads{1, 2};
  int repeat = 1;
  bool profile = false;
  bool kernel = false;
  std::string case_file = std::string(ARLEQUIN_SOURCE_DIR) + "/cases/bonded_block_tension/case.yaml";
  std::string spec, sample, test;  // --virtual-test
  std::vector<arlequin::Override> overrides;  // --set key=value, on the case
};

Options parse(int argc, char** argv) {
  Options o;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    const auto value = [&] {
      if (k + 1 >= argc) throw arlequin::InputError(arg + ": expected a value after it");
      return std::string(argv[++k]);
    };
    if (arg == "--steps") o.steps = std::stol(value());
    else if (arg == "--repeat") o.repeat = std::max(1, std::stoi(value()));
    else if (arg == "--profile") o.profile = true;
    else if (arg == "--kernel") o.kernel = true;
    else if (arg == "--virtual-test") o.spec = value();
    else if (arg == "--sample") o.sample = value();
    else if (arg == "--test") o.test = value();
    else if (arg == "--set") o.overrides.push_back(value());
    else if (arg == "--threads") {
      o.threads.clear();
      std::stringstream list(value());
      for (std::string item; std::getline(list, item, ',');) o.threads.push_back(std::stoi(item));
      if (o.threads.empty() || o.threads.front() != 1) o.threads.insert(o.threads.begin(), 1);  // the reference
    } else if (!arg.starts_with("-")) o.case_file = arg;
    else throw arlequin::InputError("bench_bonded_block: unknown option '" + arg + "'");
  }
  if (!o.spec.empty() && (o.sample.empty() || o.test.empty()))
    throw arlequin::InputError("--virtual-test needs --sample NAME and --test NAME");
  return o;
}

struct Timing {
  double seconds = 0.0;  // the time loop
  double work = 0.0;     // bond-steps (block), contact-steps (a scene without bonds) or steps (virtual test)
  const char* unit = "bond-steps/s";
};

// The block: build the case, run its steps with no output.
Timing run_block(const Options& o, int threads, arlequin::StepProfile* profile, bool first) {
  const double rss_before = memory_bytes().first;
  const auto t0 = Clock::now();
  arlequin::app::SceneOptions options;
  options.overrides = o.overrides;
  arlequin::app::Scene scene = arlequin::app::build_scene(o.case_file, options);
  const double setup = std::chrono::duration<double>(Clock::now() - t0).count();
  const double rss_built = memory_bytes().first;
  const double n = double(scene.dem.particles.size());
  double bonds = 0;
  for (const auto& set : scene.dem.bond_sets()) bonds += double(set->size());
  // With contact the neighbour list is timed apart, by a profile of the run's own if none was asked.
  const bool contact = scene.dem.has_contact();
  arlequin::StepProfile own;
  if (!profile && contact) profile = &own;
  scene.dem.set_profile(profile);
  // A --profile profile sums the repeated runs: this run's neighbour time is the difference.
  const auto neighbour_seconds = [&] {
    for (const auto& phase : profile ? profile->phases() : std::vector<arlequin::StepProfile::Phase>{})
      if (phase.name == "neighbour list") return phase.seconds;
    return 0.0;
  };
  const double neighbour_before = neighbour_seconds();
  double contact_steps = 0.0;
  const auto t1 = Clock::now();
  for (long s = 0; s < o.steps; ++s) {
    scene.dem.step(scene.dt);
    contact_steps += double(scene.dem.touching_contacts());
    if (profile) profile->count_step();
  }
  const double run = std::chrono::duration<double>(Clock::now() - t1).count();
  scene.dem.set_profile(nullptr);
  const auto& p = scene.dem.particles;
  const std::uint64_t print = fingerprint(p.velocity.data(), p.size() * sizeof(arlequin::Vec3),
                                          fingerprint(p.position.data(), p.size() * sizeof(arlequin::Vec3)));
  std::printf("threads %d: DEs %.0f, bonds %.0f, setup %.3f s, %ld steps %.3f s (%.3f ms/step), "
              "particle-steps/s %.3e, bond-steps/s %.3e, fingerprint %016llx\n",
              threads, n, bonds, setup, o.steps, run, 1e3 * run / o.steps, n * o.steps / run, bonds * o.steps / run,
              static_cast<unsigned long long>(print));
  if (contact) {
    const double neighbour = neighbour_seconds() - neighbour_before;
    std::printf("  contact-steps/s %.3e (touching pairs per step %.0f, candidates %zu), neighbour list %zu builds, "
                "%.3f ms/step (%.1f %% of the step)\n",
                contact_steps / run, contact_steps / double(o.steps), scene.dem.neighbours()->pairs().size(),
                scene.dem.neighbours()->builds(), 1e3 * neighbour / double(o.steps), 100.0 * neighbour / run);
  }
  if (first)
    std::printf("  memory: scene %.1f MB resident = %.0f B per DE + bond pair (%.0f B/DE if all charged to DEs, "
                "%.0f B/bond if all to bonds); peak RSS %.1f MB\n",
                (rss_built - rss_before) / 1e6, (rss_built - rss_before) / (n + bonds), (rss_built - rss_before) / n,
                (rss_built - rss_before) / bonds, memory_bytes().second / 1e6);
  if (bonds == 0.0 && contact) return {run, contact_steps, "contact-steps/s"};
  return {run, bonds * o.steps};
}

// --kernel: each beam set's block kernel and force pass on one thread, ns per block of bonds.
void time_beam_kernel(const Options& o) {
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
  using arlequin::dem::BeamBondSet;
  arlequin::app::SceneOptions options;
  options.overrides = o.overrides;
  arlequin::app::Scene scene = arlequin::app::build_scene(o.case_file, options);
  // Some steps first, so that the DEs have moved and turned off their reference.
  for (long s = 0; s < std::min(o.steps, 200L); ++s) scene.dem.step(scene.dt);
  auto& particles = scene.dem.particles;
  constexpr std::size_t block = BeamBondSet::block, cached = 8;  // blocks in the cached run
  bool timed = false;
  for (const auto& set : scene.dem.bond_sets()) {
    const auto* beams = dynamic_cast<const BeamBondSet*>(set.get());
    if (!beams || beams->size() < cached * block) continue;
    const std::size_t blocks = beams->size() / block, passes = std::max<std::size_t>(1, 2000000 / beams->size());
    BeamBondSet::ActionsBlock out;
    volatile double sink = 0.0;  // written from every block, so that no evaluation can be dropped
    const auto fastest = [](auto&& run) {
      double best = 1e300;
      for (int r = 0; r < 5; ++r) {
        const auto t0 = Clock::now();
        run();
        best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
      }
      return best;
    };
    const double all = fastest([&] {
      for (std::size_t pass = 0; pass < passes; ++pass)
        for (std::size_t k = 0; k < blocks; ++k) {
          beams->actions(k * block, block, particles, out, false);
          sink = out.force_on_j[0][0];
        }
    });
    const double one = fastest([&] {
      for (std::size_t pass = 0; pass < passes; ++pass)
        for (std::size_t k = 0; k < blocks; ++k) {
          beams->actions(k % cached * block, block, particles, out, false);
          sink = out.force_on_j[0][0];
        }
    });
    const double pass = fastest([&] {
      for (std::size_t k = 0; k < passes; ++k) beams->accumulate_forces(particles, {});
    });
    const double evaluated = double(passes) * double(blocks);
    std::printf("beam kernel, set '%s' (%zu bonds, blocks of %zu): over the set %.1f ns/block, over %zu blocks in cache "
                "%.1f ns/block, force pass %.1f ns/block (%.1f ns/bond)\n",
                set->name.c_str(), beams->size(), block, 1e9 * all / evaluated, cached, 1e9 * one / evaluated,
                1e9 * pass / evaluated, 1e9 * pass / (evaluated * double(block)));
    timed = true;
  }
  if (!timed) std::printf("beam kernel: %s has no beam set of %zu bonds or more\n", o.case_file.c_str(), cached * block);
}

// A virtual test to its end; the time loop's wall time is the profile's (always attached).
Timing run_virtual_test(const Options& o, int threads, arlequin::StepProfile& profile) {
  const auto out = std::filesystem::temp_directory_path() / "bench_bonded_block_virtual_test";
  std::filesystem::remove_all(out);
  arlequin::app::SceneOptions options;
  options.overrides = o.overrides;
  options.profile = &profile;
  const double before = profile.seconds();
  const long steps_before = profile.steps();
  arlequin::app::run_virtual_test_suite(o.spec, options, out, {o.sample}, {o.test});
  const double run = profile.seconds() - before;
  const long steps = profile.steps() - steps_before;
  std::ifstream series_file(out / o.sample / o.test / "series.csv", std::ios::binary);
  const std::string series((std::istreambuf_iterator<char>(series_file)), std::istreambuf_iterator<char>());
  std::printf("threads %d: %s %s, %ld steps %.3f s (%.3f ms/step), fingerprint of series.csv %016llx\n", threads,
              o.sample.c_str(), o.test.c_str(), steps, run, 1e3 * run / double(std::max(steps, 1L)),
              static_cast<unsigned long long>(fingerprint(series.data(), series.size())));
  return {run, double(steps), "steps/s"};
}

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  if (o.kernel) {
    time_beam_kernel(o);
    return 0;
  }
  const bool virtual_test = !o.spec.empty();
  if (virtual_test)
    std::printf("virtual-test benchmark: %s, sample %s, test %s\n", o.spec.c_str(), o.sample.c_str(), o.test.c_str());
  else
    std::printf("bonded block benchmark: %s, %ld steps, no output\n", o.case_file.c_str(), o.steps);
  // Bytes the structure-of-arrays layout stores per DE and per beam bond (fields of
  // ParticleSet; BeamBondSet: two indices, L0, beam radius, three stiffnesses, two unit vectors,
  // the broken flag, the energy and failure-measure records; and the gather's scratch: nine
  // action components and two bond ends).
  using arlequin::Quat;
  using arlequin::Vec3;
  constexpr std::size_t per_de = 6 * sizeof(Vec3) + sizeof(Quat) + 2 * sizeof(double);
  constexpr std::size_t per_bond = 2 * sizeof(std::uint32_t) + 5 * sizeof(double) + 2 * sizeof(Vec3) + 1 + 2 * sizeof(double);
  constexpr std::size_t per_bond_gather = 9 * sizeof(double) + 2 * sizeof(std::uint32_t);
  if (!virtual_test)
    std::printf("layout: %zu B per DE, %zu B per beam bond + %zu B of gather scratch (targets <= 200, <= 150)\n", per_de,
                per_bond, per_bond_gather);
  std::map<int, std::vector<double>> rates;  // work per second of each run, by thread count
  const char* unit = "";
  std::map<int, arlequin::StepProfile> profiles;
  for (int r = 0; r < o.repeat; ++r)
    for (int threads : o.threads) {
#ifdef _OPENMP
      omp_set_num_threads(threads);
#else
      if (threads > 1) continue;  // built without OpenMP: one thread only
#endif
      arlequin::StepProfile& profile = profiles[threads];
      const Timing t = virtual_test ? run_virtual_test(o, threads, profile)
                                    : run_block(o, threads, o.profile ? &profile : nullptr, r == 0 && threads == o.threads.front());
      rates[threads].push_back(t.work / t.seconds);
      unit = t.unit;
    }
  const double one = arlequin::median(rates[1]);
  std::printf("median of %d run(s) per thread count, alternated:\n", o.repeat);
  for (const auto& [threads, list] : rates)
    std::printf("  threads %2d: %s %.3e  speed-up vs 1 thread %.2fx\n", threads, unit, arlequin::median(list), arlequin::median(list) / one);
  if (o.profile) {
    for (const auto& [threads, profile] : profiles) {
      if (threads == 1) std::printf("\n%s", profile.table().c_str());
      else std::printf("\n%s", arlequin::StepProfile::comparison(profiles[1], profile, threads).c_str());
    }
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_bonded_block: %s\n", e.what());
  return 2;
}
