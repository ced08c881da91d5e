// SPDX-License-Identifier: GPL-3.0-or-later
// Exact restart (docs/restart.md), through the `arlequin` executable as a user runs it: a run
// stopped half-way and restarted from its checkpoint writes the series.csv, breaks.csv and
// fields.xdmf of the uninterrupted run byte for byte; a Ctrl-C leaves a checkpoint that
// restarts; a checkpoint of another case, program version or time step, a truncated and a
// corrupted file are each refused in one line.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/checkpoint.hpp"
#include "common/json.hpp"
#include "common/state_file.hpp"
#include "support/cli.hpp"

namespace arlequin {
namespace {

namespace fs = std::filesystem;

struct RestartCase {
  std::string name;
  std::string case_file;  // relative to the source tree
  std::string what;       // what its state holds that a restart must carry
};

void PrintTo(const RestartCase& c, std::ostream* os) { *os << c.name; }

std::string source(const std::string& relative) { return std::string(ARLEQUIN_SOURCE_DIR) + "/" + relative; }

long steps_of(const fs::path& dir) { return Json::parse(test::read_text(dir / "summary.json"))["steps"].get<long>(); }

class Restart : public ::testing::TestWithParam<RestartCase> {};

std::size_t frames_in(const fs::path& xdmf) {
  const std::string text = test::read_text(xdmf);
  std::size_t n = 0;
  for (std::size_t at = text.find("<Grid Name=\"frame_"); at != std::string::npos; at = text.find("<Grid Name=\"frame_", at + 1)) ++n;
  return n;
}

TEST_P(Restart, HalfWayCheckpointContinuesToTheSameBits) {
  const RestartCase& c = GetParam();
  const fs::path out = test::scratch_dir("restart_" + c.name), whole = out / "whole", split = out / "split", moved = out / "moved",
                 alone = out / "alone";
  const std::string run = "run " + source(c.case_file) + " --quiet";
  const auto r = test::run_arlequin(run + " --out " + whole.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const long steps = steps_of(whole);
  ASSERT_GT(steps, 100);
  // Half the steps, the checkpoint written where --steps stops the run.
  const auto half = test::run_arlequin(run + " --out " + split.string() + " --steps " + std::to_string(steps / 2) +
                                       " --set output.checkpoint_every=1");
  ASSERT_EQ(half.exit_code, 0) << half.output;
  const fs::path checkpoint = split / "checkpoint.h5";
  ASSERT_TRUE(fs::exists(checkpoint));
  fs::copy_file(checkpoint, out / "alone.h5");
  // Into a new folder (--out; the frames so far come from the checkpoint's folder), then into
  // the checkpoint's own folder.
  const auto elsewhere = test::run_arlequin(run + " --out " + moved.string() + " --restart " + checkpoint.string());
  ASSERT_EQ(elsewhere.exit_code, 0) << elsewhere.output;
  const auto again = test::run_arlequin(run + " --out " + split.string() + " --restart " + checkpoint.string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  // A checkpoint with no fields file beside it: the series are whole, the frames start at the restart.
  const auto lonely = test::run_arlequin(run + " --out " + alone.string() + " --restart " + (out / "alone.h5").string());
  ASSERT_EQ(lonely.exit_code, 0) << lonely.output;
  for (const char* file : {"series.csv", "breaks.csv", "fields.xdmf"}) {
    if (!fs::exists(whole / file)) continue;
    EXPECT_EQ(test::read_text(split / file), test::read_text(whole / file)) << c.name << ": " << file << " restarted in place";
    EXPECT_EQ(test::read_text(moved / file), test::read_text(whole / file)) << c.name << ": " << file << " restarted elsewhere";
    if (std::string(file) != "fields.xdmf") {
      EXPECT_EQ(test::read_text(alone / file), test::read_text(whole / file)) << c.name << ": " << file << " without the fields";
    }
  }
  if (fs::exists(whole / "fields.xdmf")) {
    const std::size_t carried = Json::parse(test::read_text(split / "summary.json"))["restart_frames_carried"].get<std::size_t>();
    EXPECT_GT(carried, 0u);
    EXPECT_EQ(frames_in(alone / "fields.xdmf"), frames_in(whole / "fields.xdmf") - carried);
    EXPECT_NE(lonely.output.find("are not carried over"), std::string::npos) << lonely.output;
  }
  EXPECT_EQ(steps_of(split), steps);
  const Json summary = Json::parse(test::read_text(split / "summary.json"));
  const Json reference = Json::parse(test::read_text(whole / "summary.json"));
  // The counts include the contact search's rebuilds: a restarted list rebuilds when the
  // uninterrupted one did (and lists its pairs in the same order).
  EXPECT_EQ(summary["counts"], reference["counts"]);
  EXPECT_EQ(summary["energies"], reference["energies"]);
  if (reference.contains("damage_in_overlap_breaks")) {  // each held or broken bond of the overlap counted once
    EXPECT_EQ(summary["damage_in_overlap_breaks"], reference["damage_in_overlap_breaks"]);
  }
  EXPECT_EQ(summary["restarted_at_step"].get<long>(), steps / 2);
  EXPECT_EQ(summary["status"], "completed");
}

std::vector<RestartCase> restart_cases() {
  std::vector<RestartCase> cases = {
      {"DemBreaking", "cases/lattice_bar_failure/case.yaml", "BBF breaks, damping, a driven end's reaction work"},
      {"Cohesive", "tests/restart/data/cohesive_lattice.yaml",
       "cohesive damage and dissipation half-way through softening, breaks, contact search, damping"},
      {"Contact", "cases/demo_beam_impact/case.yaml", "an impact's contacts and the neighbour list"}};
#ifdef ARLEQUIN_WITH_CONTINUUM
  cases.push_back({"Coupled", "cases/wave_bar_coupled/case.yaml", "the continuum's fields and the coupling's multipliers"});
  cases.push_back({"CoupledFabric", "cases/fabric_impact_coupled/reduced.yaml",
                   "a weave's contacts weighted in the overlap, breaks, the overlap's springs held at their criterion"});
#endif
  return cases;
}

std::string case_name(const ::testing::TestParamInfo<RestartCase>& param) { return param.param.name; }

INSTANTIATE_TEST_SUITE_P(Cases, Restart, ::testing::ValuesIn(restart_cases()), case_name);

const std::string lattice = source("cases/lattice_bar_failure/case.yaml");

// A checkpoint of the lattice bar at step 200, in its own folder.
fs::path lattice_checkpoint(const std::string& name) {
  const fs::path out = test::scratch_dir("restart_" + name);
  const auto r = test::run_arlequin("run " + lattice + " --quiet --out " + out.string() + " --steps 200 --set output.checkpoint_every=1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return out / "checkpoint.h5";
}

// Runs the lattice bar with `args` (split at spaces, no quoting) writing to `out`, and sends
// `signal` once the run is inside its time loop: when series.csv first appears (the series is
// first written 2 s into the run, from the loop), not after a fixed delay, which a loaded machine
// can spend starting the process. Returns the wait status. Started directly: a shell's background
// job ignores SIGINT.
int run_and_signal(const std::string& args, const fs::path& out, int signal) {
  const std::string exe = std::string(ARLEQUIN_BINARY_DIR) + "/app/arlequin";
  std::vector<std::string> words = {exe, "run", lattice, "--quiet"};
  std::istringstream in(args);
  for (std::string word; in >> word;) words.push_back(word);
  words.push_back("--out");
  words.push_back(out.string());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  // The run lasts several seconds on a quiet machine; a minute bounds the wait if it never loops.
  for (int waited_ms = 0; !fs::exists(out / "series.csv") && waited_ms < 60000; waited_ms += 20) usleep(20000);
  kill(pid, signal);
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

TEST(RestartSignal, CtrlCLeavesACheckpointThatContinuesAsTheUninterruptedRun) {
  const fs::path out = test::scratch_dir("restart_sigint"), stopped = out / "stopped", whole = out / "whole";
  // Ten times the case's time: a run of several seconds, stopped inside its loop; no checkpoint_every.
  const std::string run = "run " + lattice + " --quiet --set time.end=3.0e-3";
  const int status = run_and_signal(" --set time.end=3.0e-3", stopped, SIGINT);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 130) << "the exit status after SIGINT: 128 + 2";
  const Json summary = Json::parse(test::read_text(stopped / "summary.json"));
  ASSERT_EQ(summary["status"], "interrupted");
  ASSERT_TRUE(fs::exists(stopped / "checkpoint.h5"));
  const long at = summary["steps"].get<long>(), end = at + 300;
  ASSERT_GT(at, 0);
  const auto again = test::run_arlequin(run + " --out " + stopped.string() + " --restart " + (stopped / "checkpoint.h5").string() +
                                        " --steps " + std::to_string(end));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const auto uninterrupted = test::run_arlequin(run + " --out " + whole.string() + " --steps " + std::to_string(end));
  ASSERT_EQ(uninterrupted.exit_code, 0) << uninterrupted.output;
  EXPECT_EQ(test::read_text(stopped / "series.csv"), test::read_text(whole / "series.csv"));
  EXPECT_EQ(test::read_text(stopped / "breaks.csv"), test::read_text(whole / "breaks.csv"));
}

// A run killed outright (SIGKILL: no outputs closed) leaves its periodic checkpoint and its
// fields in fields.h5.part.<pid>: the restart carries the frames from there and ends with the
// uninterrupted run's series and frames. A fields.h5 of another run in the folder is not taken.
TEST(RestartSignal, KilledRunRestartsFromItsLastCheckpointWithItsFrames) {
  const fs::path out = test::scratch_dir("restart_sigkill"), killed = out / "killed", whole = out / "whole";
  const std::string settings = " --set time.end=3.0e-3 --set output.checkpoint_every=2.0e-5 --set output.fields_every=1.0e-5";
  const int status = run_and_signal(settings, killed, SIGKILL);
  ASSERT_TRUE(WIFSIGNALED(status));
  ASSERT_TRUE(fs::exists(killed / "checkpoint.h5"));
  ASSERT_FALSE(fs::exists(killed / "fields.h5"));
  // Another run's fields.h5 beside the .part file, newer: its frames are at other times.
  const auto other = test::run_arlequin("run " + lattice + " --quiet --steps 2000 --set output.fields_every=7.0e-6 --out " + (out / "other").string());
  ASSERT_EQ(other.exit_code, 0) << other.output;
  fs::copy_file(out / "other" / "fields.h5", killed / "fields.h5");
  const StateArchive checkpoint = read_state_file(killed / "checkpoint.h5");
  const long end = checkpoint.integer("run/steps_done") + 300;
  const auto again = test::run_arlequin("run " + lattice + " --quiet" + settings + " --out " + killed.string() + " --restart " +
                                        (killed / "checkpoint.h5").string() + " --steps " + std::to_string(end));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(again.output.find("not carried over"), std::string::npos) << again.output;
  const auto uninterrupted = test::run_arlequin("run " + lattice + " --quiet" + settings + " --out " + whole.string() + " --steps " +
                                                std::to_string(end));
  ASSERT_EQ(uninterrupted.exit_code, 0) << uninterrupted.output;
  for (const char* file : {"series.csv", "breaks.csv", "fields.xdmf"})
    EXPECT_EQ(test::read_text(killed / file), test::read_text(whole / file)) << file;
  EXPECT_GT(checkpoint.integer("run/frames"), 0);
}

TEST(RestartFields, AnotherRunsFieldsAreNotCarried) {
  const fs::path file = lattice_checkpoint("fields_other"), dir = file.parent_path();
  const auto other = test::run_arlequin("run " + lattice + " --quiet --steps 300 --set output.fields_every=7.0e-6 --out " +
                                        test::scratch_dir("restart_fields_other_run").string());
  ASSERT_EQ(other.exit_code, 0) << other.output;
  fs::copy_file(test::scratch_path("restart_fields_other_run") / "fields.h5", dir / "fields.h5", fs::copy_options::overwrite_existing);
  const auto r = test::run_arlequin("run " + lattice + " --quiet --steps 400 --out " + test::scratch_dir("restart_fields_new").string() +
                                    " --restart " + file.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("another run's"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("are not carried over"), std::string::npos) << r.output;
}

// Each refusal: exit 2, one line naming the file and the reason, and no output written.
void expect_refused(const std::string& args, const std::string& reason) {
  const fs::path out = test::scratch_path("restart_refused");
  fs::remove_all(out);
  const auto r = test::run_arlequin("run " + lattice + " --quiet --out " + out.string() + args);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(out / "series.csv")) << reason;
  EXPECT_NE(r.output.find(reason), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(RestartRefusal, AnotherCaseNamesTheKeyButTimeEndAndOutputMayChange) {
  const fs::path file = lattice_checkpoint("refusal_case");
  expect_refused(" --restart " + file.string() + " --set dem.damping=1.0e4", "is a checkpoint of another case: 'dem.damping' differs");
  expect_refused(" --restart " + file.string() + " --set dem.bond.sigma_f=1.9e8", "'dem.bond.sigma_f' differs");
  expect_refused(" --restart " + file.string() + " --set time.end=3.0e-6", "is at step 200, past the last of this case");
  expect_refused(" --restart " + file.string() + " --set time.end=6.53018845964e-6", "is at step 200, the last of this case");
  expect_refused(" --restart " + file.string() + " --steps 150", "--steps 150: the run would stop at or before step 200");
  const auto r = test::run_arlequin("run " + lattice + " --quiet --out " + test::scratch_path("restart_refusal_case").string() +
                                    " --restart " + file.string() + " --steps 300 --set time.end=4.0e-4 --set output.every=4.0e-6");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST(RestartRefusal, AnotherVersionOrTimeStepIsRefused) {
  const fs::path file = lattice_checkpoint("refusal_version");
  StateArchive archive = read_state_file(file);
  archive.put_text("run/version", "0.0.0-other");
  write_state_file(file.parent_path() / "other_version.h5", archive);
  expect_refused(" --restart " + (file.parent_path() / "other_version.h5").string(), "was written by arlequin 0.0.0-other");
  archive.put_text("run/version", ARLEQUIN_VERSION);
  archive.put("run/dt", 0.5 * archive.number("run/dt"));
  write_state_file(file.parent_path() / "other_step.h5", archive);
  expect_refused(" --restart " + (file.parent_path() / "other_step.h5").string(), "was run with the time step");
}

TEST(RestartRefusal, TruncatedCorruptedOrForeignFilesAreRefused) {
  const fs::path file = lattice_checkpoint("refusal_file"), dir = file.parent_path();
  const std::string bytes = test::read_text(file);
  std::ofstream(dir / "truncated.h5", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  expect_refused(" --restart " + (dir / "truncated.h5").string(), "truncated");
  // One byte changed in the middle of the data: HDF5 may still read every dataset, the checksum
  // does not match.
  std::string changed = bytes;
  changed[changed.size() / 2] ^= 0x10;
  std::ofstream(dir / "corrupted.h5", std::ios::binary) << changed;
  expect_refused(" --restart " + (dir / "corrupted.h5").string(), "corrupted");
  expect_refused(" --restart " + lattice, "not an HDF5 file");
  expect_refused(" --restart " + (dir / "missing.h5").string(), "no such file");
  // The fields file is HDF5 but not a checkpoint.
  expect_refused(" --restart " + (dir / "fields.h5").string(), "not an arlequin checkpoint");
}

TEST(RestartCaseDifference, IgnoresTimeEndAndOutputOnly) {
  const std::string a = "name: x\ntime: {end: 1, dt: auto}\noutput: {every: 1}\ndem: {damping: 3}\n";
  EXPECT_EQ(app::case_difference(a, "name: x\ntime: {end: 2, dt: auto}\noutput: {every: 2, dir: y}\ndem: {damping: 3}\n"), "");
  EXPECT_EQ(app::case_difference(a, "name: x\ntime: {end: 1, dt: 1e-6}\noutput: {every: 1}\ndem: {damping: 3}\n"), "time.dt");
  EXPECT_EQ(app::case_difference(a, "name: x\ntime: {end: 1, dt: auto}\noutput: {every: 1}\ndem: {damping: 3, x: 1}\n"), "dem.x");
  EXPECT_EQ(app::case_difference(a, "name: x\ntime: {end: 1, dt: auto}\noutput: {every: 1}\n"), "dem");
}

}  // namespace
}  // namespace arlequin
