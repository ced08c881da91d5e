// SPDX-License-Identifier: GPL-3.0-or-later
// The `arlequin` command line: run and check case files.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/compare.hpp"
#include "app/calibrate.hpp"
#include "app/case_schema.hpp"
#include "app/runner.hpp"
#include "app/scene.hpp"
#include "app/sweep.hpp"
#include "app/virtual_tests.hpp"
#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/interrupt.hpp"
#include "common/json.hpp"
#include "common/state_file.hpp"
#include "dem/bonds/bond_set.hpp"
#include "dem/contacts/contact_law.hpp"

namespace {

using namespace arlequin;

constexpr const char* usage_main =
    "usage: arlequin <command> [options]\n"
    "\n"
    "commands:\n"
    "  run CASE.yaml     run a case, write results (series.csv, fields.h5/.xdmf, summary.json)\n"
    "  check CASE.yaml   validate a case, print it with defaults and its critical time step\n"
    "  sweep CASE.yaml   run a case over several values of its keys; table of errors and run times\n"
    "  build-sample CASE.yaml   build the case's packing (dem.sample.build: packing) and save it\n"
    "  virtual-test SPEC.yaml   quasi-static tension/shear tests of a sample (moduli, Poisson ratios),\n"
    "                           or tension tests to failure (failure stress and strain, broken bonds)\n"
    "  calibrate SPEC.yaml      fit beam bonds (E_mu, r_mu) to a material's (E_M, nu_M) on a packing,\n"
    "                           and BBF / RDEF strengths to its tensile failure stress\n"
    "  compare A.yaml B.yaml    run two cases sharing sensors; B's difference to A against run time\n"
    "  laws                     list the bond and contact laws (dem.material.bond.law, dem.contact.law)\n"
    "  schema [SECTION] [--of case | virtual-test | calibrate]\n"
    "                           the keys of a case file (or of a spec file): type, unit, range,\n"
    "                           default, help; all, or the sections under SECTION\n"
    "\n"
    "options: --version, --help; 'arlequin <command> --help' for a command's options\n";

constexpr const char* usage_run =
    "usage: arlequin run CASE.yaml [--out DIR] [--set key.path=value ...] [--steps N] [--restart FILE]\n"
    "  --out DIR      write results to DIR instead of output.dir of the case\n"
    "  --restart FILE continue the run of checkpoint FILE (checkpoint.h5 of its output folder: written\n"
    "                 on Ctrl-C or SIGTERM, and every output.checkpoint_every) into the output folder,\n"
    "                 appending to series.csv and breaks.csv; the case may change only time.end and output\n"
    "  --set k=v      override a case value (YAML syntax), e.g. --set time.end=1e-3\n"
    "  --steps N      stop after N steps (before time.end the case's checks are not evaluated)\n"
    "  --petsc \"...\"  PETSc options of a static continuum solve (checked before the run), e.g. --petsc \"-ksp_type cg -pc_type jacobi\"\n"
    "  --quiet        no progress line\n"
    "  --profile      print the wall time of each phase of the step (docs/performance.md)\n"
    "exit codes: 0 done and the case's checks passed, 2 bad input, 3 run stopped, 5 a check failed,\n"
    "  130 / 143 interrupted by Ctrl-C / SIGTERM (outputs so far closed and kept)\n";

constexpr const char* usage_check =
    "usage: arlequin check CASE.yaml [--set key.path=value ...]\n"
    "  prints the case as resolved (with defaults), the DE and bond counts, the critical\n"
    "  time step and the time step that a run would use\n";

constexpr const char* usage_build_sample =
    "usage: arlequin build-sample CASE.yaml [--set key.path=value ...]\n"
    "  builds the random dense packing of a case whose dem.sample.build is packing (even when its\n"
    "  cache file matches), stores it in the cache file and prints its report and radius histogram\n";

constexpr const char* usage_compare =
    "usage: arlequin compare REFERENCE.yaml OTHER.yaml [--out DIR] [--ensemble N] [--window COLUMN=LO:HI]\n"
    "                        [--set k=v ...] [--set-reference k=v ...] [--set-other k=v ...]\n"
    "  builds both cases first (a bad case, or none of their sensors shared, stops it before any\n"
    "  run), runs them (results in DIR/reference and DIR/other, default results/compare), then for\n"
    "  every sensor column they share prints OTHER's max and RMS difference relative to REFERENCE,\n"
    "  both runs' sizes and compute times and the speed-up; writes compare.csv, compare.json and\n"
    "  compare_<sensor>.png. Each run is judged by its own case's checks: exit 5 if one fails.\n"
    "  --ensemble N: N pairs, pair k = 0..N-1 with both time steps x (1 - k 1e-9) (results of k >= 1 in\n"
    "  DIR/pair_k/): the median and range over the pairs, and the reference's own spread; for runs\n"
    "  whose outcome is a draw (contacts, breakage; docs/decisions.md#d44)\n"
    "  --window COLUMN=LO:HI: the differences and peaks over the rows whose COLUMN (time or a shared\n"
    "  sensor) lies in [LO, HI] (OTHER at REFERENCE's times there, and its own rows for its peak); e.g.\n"
    "  the DCB's Delta=0.5e-3:2.0e-3 (docs/decisions.md#d51); the plots draw the whole histories against COLUMN\n"
    "  --set applies to both cases, --set-reference and --set-other (after it) to one: e.g. the\n"
    "  coupled case with --set-other continuum.solver=nem against a pure DEM, which has no continuum\n";

constexpr const char* usage_virtual_test =
    "usage: arlequin virtual-test SPEC.yaml [--out DIR] [--sample NAME ...] [--test NAME ...] [--set k=v ...] [--profile]\n"
    "  runs the spec's quasi-static tests (tension, shear) on each of its samples (only the named\n"
    "  ones with --sample, only the named tests with --test), results in DIR/<sample>/<test>/ (default results/<folder>_<spec>/);\n"
    "  prints moduli and Poisson ratios with their uncertainty, writes DIR/tests.csv and, for a\n"
    "  composite spec, DIR/composite.md (engineering constants against closed forms and references);\n"
    "  with a failure section every test runs to failure: DIR/failure.csv and DIR/failure.md.\n"
    "  --set applies to the sample case. --profile: the wall time of each phase of the step, summed\n"
    "  over the runs (docs/performance.md). Spec format: app/virtual_tests.hpp\n";

constexpr const char* usage_calibrate =
    "usage: arlequin calibrate SPEC.yaml [--out DIR] [--set k=v ...]\n"
    "  fits the beam bonds' (E_mu, r_mu) of a one-material packing to target (E_M, nu_M): tension\n"
    "  tests over the spec's r_mu grid (nu_M depends on r_mu only), then E_mu by proportionality;\n"
    "  a verification run per target. With a failure section: sigma_f_mu (BBF) or the RDEF threshold\n"
    "  reproducing a tensile failure stress, by tests to failure. Writes curve.csv, curve.png,\n"
    "  strength.csv, calibration.md/.json to DIR (default results/<folder>_<spec>/); curve points\n"
    "  are cached next to the sample file. Exit 5 if a strength did not converge.\n"
    "  --set applies to the sample case. Spec format: app/calibrate.hpp\n";

constexpr const char* usage_sweep =
    "usage: arlequin sweep CASE.yaml --over key.path=v1,v2,... [--with key.path=w1,w2,...] [--over ...] [--out DIR] [--set k=v ...]\n"
    "  runs every combination of the --over values (results in DIR/<run>/, default\n"
    "  results/<name>_sweep/), prints a Markdown table of the case's checks (value, relative\n"
    "  error) against wall time, and writes DIR/sweep.csv, sweep.png and sweep_time.png;\n"
    "  --with values go one for one with the axis before it (w1 with v1, ...)\n";

struct Arguments {
  std::string command;
  std::string case_file;
  std::string second_case;  // compare
  app::SceneOptions scene;
  long steps = -1;
  std::filesystem::path restart;  // run --restart
  std::vector<app::SweepAxis> axes;
  std::vector<std::string> samples;  // virtual-test --sample
  std::vector<std::string> tests;    // virtual-test --test
  bool profile = false;              // run, virtual-test --profile
  std::string document = "case";     // schema --of
  bool quiet = false;
  bool help = false;
  int ensemble = 1;                  // compare --ensemble
  app::CompareWindow window;         // compare --window
  std::vector<Override> reference_overrides, other_overrides;  // compare --set-reference, --set-other
};

Arguments parse(int argc, char** argv) {
  Arguments a;
  std::vector<std::string> args(argv + 1, argv + argc);
  static constexpr std::string_view commands[] = {"run", "check", "sweep", "build-sample", "compare", "virtual-test", "calibrate", "laws", "schema"};
  if (args.empty()) throw InputError("no command given\n" + std::string(usage_main));
  a.command = args[0];
  if (a.command == "--help" || a.command == "-h") return a.help = true, a;
  if (a.command == "--version") return a;
  if (std::find(std::begin(commands), std::end(commands), a.command) == std::end(commands)) {
    const auto guess = closest_match(a.command, commands);
    throw InputError("unknown command '" + a.command + "'" +
                     (guess ? "; did you mean '" + std::string(*guess) + "'?" : "; commands: run, check, sweep, build-sample, compare, virtual-test, calibrate, laws, schema"));
  }
  for (std::size_t k = 1; k < args.size(); ++k) {
    const std::string& arg = args[k];
    const auto value = [&](const char* what) -> std::string {
      if (k + 1 >= args.size()) throw InputError(arg + ": expected " + what + " after it");
      return args[++k];
    };
    // The value after arg as a whole number in [lo, hi]; `expected` says so in the error.
    const auto whole_number = [&](const char* what, long lo, long hi, const std::string& expected) {
      const std::string v = value(what);
      long n = 0;
      // from_chars takes the whole text or fails: no empty string, spaces or overflow read as a number.
      const auto [end, error] = std::from_chars(v.data(), v.data() + v.size(), n);
      if (v.empty() || error != std::errc() || end != v.data() + v.size() || n < lo || n > hi)
        throw InputError(arg + ": expected " + expected + ", got '" + v + "'");
      return n;
    };
    if (arg == "--help" || arg == "-h") {
      a.help = true;
    } else if (arg == "--set") {
      a.scene.overrides.push_back(value("key.path=value"));
    } else if (arg.starts_with("--set=")) {
      a.scene.overrides.push_back(arg.substr(6));
    } else if (arg == "--petsc") {
      a.scene.petsc_options += " " + value("a quoted PETSc option string");
    } else if ((arg == "--over" || arg == "--with") && a.command == "sweep") {
      a.axes.push_back(app::parse_sweep_axis(value("key.path=v1,v2,...")));
      a.axes.back().with_previous = arg == "--with";
    } else if (arg == "--out" && (a.command == "run" || a.command == "sweep" || a.command == "compare" || a.command == "virtual-test" || a.command == "calibrate")) {
      a.scene.out_dir = value("a directory");
    } else if (arg == "--steps" && a.command == "run") {
      a.steps = whole_number("a number of steps", 0, std::numeric_limits<long>::max(), "a whole number >= 0");
    } else if ((arg == "--set-reference" || arg == "--set-other") && a.command == "compare") {
      (arg == "--set-other" ? a.other_overrides : a.reference_overrides).emplace_back(value("key.path=value"), arg);
    } else if (arg == "--window" && a.command == "compare") {
      a.window = app::parse_compare_window(value("COLUMN=LO:HI"));
    } else if (arg == "--ensemble" && a.command == "compare") {
      a.ensemble = int(whole_number("a number of pairs", 1, 1000, "a whole number of pairs from 1 to 1000"));
    } else if (arg == "--restart" && a.command == "run") {
      a.restart = value("a checkpoint file");
    } else if (arg == "--of" && a.command == "schema") {
      a.document = value("case, virtual-test or calibrate");
      if (a.document != "case" && a.document != "virtual-test" && a.document != "calibrate")
        throw InputError("arlequin schema --of " + a.document + ": expected case, virtual-test or calibrate");
    } else if (arg == "--sample" && a.command == "virtual-test") {
      a.samples.push_back(value("a sample name"));
    } else if (arg == "--test" && a.command == "virtual-test") {
      a.tests.push_back(value("a test name"));
    } else if (arg == "--profile" && (a.command == "run" || a.command == "virtual-test")) {
      a.profile = true;
    } else if (arg == "--quiet" && a.command == "run") {
      a.quiet = true;
    } else if (!arg.starts_with("-") && a.case_file.empty()) {
      a.case_file = arg;
    } else if (!arg.starts_with("-") && a.command == "compare" && a.second_case.empty()) {
      a.second_case = arg;
    } else {
      throw InputError("arlequin " + a.command + ": unknown option '" + arg + "' (see arlequin " + a.command + " --help)");
    }
  }
  if (a.command == "laws" && !a.case_file.empty()) throw InputError("arlequin laws: takes no case file");
  if (!a.help && a.command != "laws" && a.command != "schema" && a.case_file.empty()) throw InputError("arlequin " + a.command + ": no case file given");
  if (!a.help && a.command == "compare" && a.second_case.empty())
    throw InputError("arlequin compare: give two case files (the reference first)");
  if (!a.help && a.command == "sweep" && a.axes.empty()) throw InputError("arlequin sweep: give at least one --over key=v1,v2");
  return a;
}

// The registries' rows: each law's case-file name and one-line summary.
int list_laws() {
  std::size_t width = 0;  // of the longest name, so the summaries line up
  for (const auto& law : dem::bond_laws()) width = std::max(width, law.name.size());
  for (const auto& law : dem::contact_laws()) width = std::max(width, law.name.size());
  const auto row = [&](std::string_view name, std::string_view summary) {
    std::printf("  %-*s %s\n", int(width), std::string(name).c_str(), std::string(summary).c_str());
  };
  std::printf("bond laws (dem.material.bond.law):\n");
  for (const auto& law : dem::bond_laws()) row(law.name, law.summary);
  std::printf("contact laws (dem.contact.law):\n");
  for (const auto& law : dem::contact_laws()) row(law.name, law.summary);
  return 0;
}

// A document's schema (a case file, a virtual-test or calibration spec), or its sections under
// one path ("dem", "coupling.overlap", "bond").
int print_schema(const std::string& document, const std::string& section) {
  const Schema& schema = document == "virtual-test" ? app::virtual_test_schema()
                         : document == "calibrate"  ? app::calibration_schema()
                                                    : app::case_schema();
  const std::string text = schema.describe(section);
  if (text.empty()) {
    std::vector<std::string_view> paths;
    for (const auto& s : schema.sections()) paths.push_back(s.path);
    const auto guess = closest_match(section, paths);
    throw InputError("arlequin schema: no section '" + section + "'" +
                     (guess ? "; did you mean '" + std::string(*guess) + "'?" : ""));
  }
  std::fputs(text.c_str(), stdout);
  return 0;
}

void print_scene_facts(const app::Scene& scene) {
  const auto& model = scene.dem;
  std::printf("case: %s\n  DEs: %zu", scene.name.c_str(), model.particles.size());
  if (scene.des_not_created > 0) std::printf(" (%zu more of the sample lie beyond the overlap: not created)", scene.des_not_created);
  std::printf("\n");
  if (scene.sample) {
    const auto& r = scene.sample->report;
    std::printf("  packing (%s): compaction %.4f, coordination %.2f (interior %.2f), fabric eigenvalues %.4f %.4f %.4f,"
                " max overlap %.1e R, built in %.1f s\n",
                scene.sample_file.string().c_str(), r.compaction, r.mean_coordination, r.interior_coordination,
                r.fabric_eigenvalues[0], r.fabric_eigenvalues[1], r.fabric_eigenvalues[2], r.max_overlap, r.seconds);
  }
  if (scene.weave) {
    const auto& w = *scene.weave;
    std::printf("  weave: %d weft, %d stuffer, %d binder yarns (lengths %.4g, %.4g, %.4g mm); binder amplitude %.4g mm, crimp %.4f;"
                " DE radius %.4g mm, spring K %.4g N/m\n"
                "    areal density %.4f kg/m^2, thickness %.4g mm, fibre volume fraction %.3f, yarn mass %.4g g,"
                " deepest overlap of unjoined DEs %.2g of 2R\n"
                "    rule of mixtures over that thickness: E_x %.4g GPa (weft), E_y %.4g GPa (stuffers; crimped binders carry nothing)\n"
                "    mass shares: weft %.4f, stuffers %.4f, binders %.4f\n",
                w.wefts, w.stuffers, w.binders, w.weft_length * 1e3, w.stuffer_length * 1e3, w.binder_length * 1e3, w.amplitude * 1e3,
                w.crimp, w.radius * 1e3, w.spring_stiffness, w.areal_density, w.thickness * 1e3, w.fibre_volume_fraction, w.mass * 1e3,
                w.deepest_overlap, w.rule_of_mixtures_x * 1e-9, w.rule_of_mixtures_y * 1e-9, w.family_mass[0] / w.mass,
                w.family_mass[1] / w.mass, w.family_mass[2] / w.mass);
  }
  for (const auto& set : model.bond_sets()) {
    std::printf("  %s (%s): %zu\n", set->name == "bonds" ? "bonds" : (set->name + " bonds").c_str(), std::string(set->law()).c_str(),
                set->size());
    if (const std::string more = set->describe(); !more.empty()) std::printf("    %s\n", more.c_str());
  }
  if (model.particles.size() > 0)
    std::printf("  contact: %s\n", model.has_contact() ? "on" : "off (no contact search)");
  if (scene.continuum) {
    Json counts = Json::object();
    scene.continuum->describe(counts);
    std::printf("  continuum: %s\n", counts.dump(-1).c_str());
  }
  // A coupling's overlap, weights, operators and the critical steps of both models.
  std::istringstream summary(scene.model->summary());
  for (std::string line; std::getline(summary, line);) std::printf("  %s\n", line.c_str());
  std::printf("  critical time step: %.6e s\n  time step: %.6e s (%.3f of critical)\n  steps: %ld to t = %.6e s\n",
              scene.dt_critical, scene.dt, scene.dt / scene.dt_critical,
              scene.steps, scene.end_time);
}

int run(const Arguments& a) {
  const auto t0 = std::chrono::steady_clock::now();
  // A checkpoint that cannot be read is refused before the scene is built.
  const std::optional<StateArchive> restart = a.restart.empty() ? std::nullopt : std::optional(read_state_file(a.restart));
  StepProfile profile;
  app::SceneOptions scene_options = a.scene;
  if (a.profile) scene_options.profile = &profile;
  app::Scene scene = app::build_scene(a.case_file, scene_options);
  app::RunOptions options;
  if (restart) {
    options.restart = &*restart;
    options.restart_file = a.restart;
  }
  options.max_steps = a.steps;
  options.show_progress = !a.quiet && isatty(STDERR_FILENO) && std::getenv("CI") == nullptr;
  options.announce_run_time = !a.quiet;
  options.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  print_scene_facts(scene);
  if (restart && restart->has("run/steps_done"))
    std::printf("  restart: from step %lld of %s\n", static_cast<long long>(restart->integer("run/steps_done")), a.restart.c_str());
  const app::RunResult r = app::run_scene(scene, options);
  std::printf("done: %ld steps, t = %.6e s, wall %.3f s (output %.3f s; %.0f steps/s without output), setup %.3f s\n",
              r.steps, r.simulated_time, r.wall_seconds, r.output_seconds, app::steps_per_second(r), options.setup_seconds);
  const auto& e = r.energies;
  std::printf("energies [J]: kinetic %.6e  bond %.6e  contact %.6e  external work %.6e  dissipated %.6e  fracture %.6e\n",
              e.kinetic, e.bond, e.contact, e.external_work, e.dissipated, e.fracture);
  for (const auto& [name, value] : r.sensors) std::printf("sensor %s = %.9e\n", name.c_str(), value);
  if (a.profile) std::printf("profile of the step, %d thread(s):\n%s", max_threads(), profile.table().c_str());
  for (const auto& c : r.checks) {
    if (c.check->bounded)
      std::printf("check %s %s: %.6e within [%.6g, %.6g]: %s\n", c.check->column.c_str(), app::describe(*c.check).c_str(),
                  c.value, c.check->at_least, c.check->at_most, c.passed ? "ok" : "FAILED");
    else
      std::printf("check %s %s: %.6e vs %.6e expected (error %.3g %%, tolerance %.3g %%): %s\n", c.check->column.c_str(),
                  app::describe(*c.check).c_str(), c.value, c.check->expected, 100 * c.relative_error,
                  100 * c.check->tolerance, c.passed ? "ok" : "FAILED");
  }
  if (!r.checks_skipped.empty()) std::printf("checks not evaluated: %s\n", r.checks_skipped.c_str());
  std::printf("results: %s\n", std::filesystem::absolute(scene.output.dir).string().c_str());
  return r.all_checks_passed() ? 0 : 5;
}

int sweep(const Arguments& a) {
  std::filesystem::path out = a.scene.out_dir;
  if (out.empty()) out = "results/" + std::filesystem::path(a.case_file).parent_path().filename().string() + "_sweep";
  app::SceneOptions base = a.scene;
  base.out_dir.clear();
  const bool ok = app::run_sweep(a.case_file, base, a.axes, out);
  std::printf("sweep table: %s\n", std::filesystem::absolute(out / "sweep.csv").string().c_str());
  return ok ? 0 : 5;
}

int build_sample(const Arguments& a) {
  app::SceneOptions options = a.scene;
  options.rebuild_sample = true;
  options.check_output_dir = false;  // writes the sample's cache file only
  app::Scene scene = app::build_scene(a.case_file, options);
  if (!scene.sample) throw InputError(a.case_file + ": dem.sample.build is not packing: there is no sample to build");
  print_scene_facts(scene);
  std::printf("radius histogram (centre m, DEs):\n");
  for (const auto& [centre, count] : scene.sample->report.radius_histogram) std::printf("  %.4e %zu\n", centre, count);
  std::printf("sample: %s\n", std::filesystem::absolute(scene.sample_file).string().c_str());
  return 0;
}

int compare(const Arguments& a) {
  std::filesystem::path out = a.scene.out_dir;
  if (out.empty()) out = "results/compare";
  app::SceneOptions base = a.scene;
  base.out_dir.clear();
  app::SceneOptions reference = base, other = base;
  reference.overrides.insert(reference.overrides.end(), a.reference_overrides.begin(), a.reference_overrides.end());
  other.overrides.insert(other.overrides.end(), a.other_overrides.begin(), a.other_overrides.end());
  const app::CompareOutcome outcome = app::run_compare(a.case_file, a.second_case, reference, other, out, a.ensemble, a.window);
  std::printf("comparison: %s (compare.csv, compare.json, compare_<sensor>.png)\n",
              std::filesystem::absolute(out).string().c_str());
  if (!outcome.completed) return 3;
  return outcome.checks_passed ? 0 : 5;
}

// Default results folder of a spec-driven command: results/<spec folder>_<spec name>.
std::filesystem::path spec_out_dir(const Arguments& a) {
  if (!a.scene.out_dir.empty()) return a.scene.out_dir;
  const std::filesystem::path spec(a.case_file);
  return "results/" + std::filesystem::absolute(spec).parent_path().filename().string() + "_" + spec.stem().string();
}

int virtual_test(const Arguments& a) {
  app::SceneOptions base = a.scene;
  base.out_dir.clear();
  StepProfile profile;
  if (a.profile) base.profile = &profile;
  const std::filesystem::path out = spec_out_dir(a);
  const int stopped = app::run_virtual_test_suite(a.case_file, base, out, a.samples, a.tests);
  if (a.profile) std::printf("profile of the step, summed over the runs, %d thread(s):\n%s", max_threads(), profile.table().c_str());
  std::printf("results: %s\n", std::filesystem::absolute(out).string().c_str());
  return stopped == 0 ? 0 : 3;
}

int calibrate(const Arguments& a) {
  app::SceneOptions base = a.scene;
  base.out_dir.clear();
  const std::filesystem::path out = spec_out_dir(a);
  const app::CalibrationResult result = app::calibrate(app::CalibrationSpec::read(a.case_file), base, out);
  std::printf("results: %s\n", std::filesystem::absolute(out).string().c_str());
  for (const auto& s : result.strengths)
    if (!s.converged) {
      std::fprintf(stderr, "calibrate: the %s strength of %s did not reach the failure tolerance in %zu rounds\n",
                   s.target.criterion.c_str(), s.target.name.c_str(), s.rounds.size());
      return 5;
    }
  return 0;
}

int check(const Arguments& a) {
  app::Scene scene = app::build_scene(a.case_file, app::writing_nothing(a.scene));
  std::printf("# %s: valid\n%s\n", a.case_file.c_str(), scene.resolved_case.c_str());
  print_scene_facts(scene);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Arguments a = parse(argc, argv);
    if (a.command == "--version") return std::printf("arlequin %s\n", ARLEQUIN_VERSION), 0;
    if (a.help) {
      std::fputs(a.command == "run"     ? usage_run
                 : a.command == "check" ? usage_check
                 : a.command == "sweep" ? usage_sweep
                 : a.command == "virtual-test" ? usage_virtual_test
                 : a.command == "calibrate" ? usage_calibrate
                 : a.command == "compare" ? usage_compare
                 : a.command == "build-sample" ? usage_build_sample
                                        : usage_main,
                 stdout);
      return 0;
    }
    if (a.command == "run") return run(a);
    if (a.command == "sweep") return sweep(a);
    if (a.command == "build-sample") return build_sample(a);
    if (a.command == "virtual-test") return virtual_test(a);
    if (a.command == "calibrate") return calibrate(a);
    if (a.command == "compare") return compare(a);
    if (a.command == "laws") return list_laws();
    if (a.command == "schema") return print_schema(a.document, a.case_file);
    return check(a);
  } catch (const InputError& e) {
    std::fprintf(stderr, "arlequin: error: %s\n", e.what());
    return 2;
  } catch (const RunError& e) {
    std::fprintf(stderr, "arlequin: run stopped: %s\n", e.what());
    return 3;
  } catch (const Interrupted& e) {
    std::fprintf(stderr, "arlequin: %s\n", e.what());
    return 128 + e.signal();  // the shell's convention for a process ended by a signal
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arlequin: internal error: %s\n", e.what());
    return 4;
  }
}
