// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/runner.hpp"

#include "app/checkpoint.hpp"
#include "app/zone_move.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <random>
#include <sstream>

#include <unistd.h>

#include "common/atomic_file.hpp"
#include "common/csv_series.hpp"
#include "common/error.hpp"
#include "common/fields_writer.hpp"
#include "common/interrupt.hpp"
#include "common/json.hpp"
#include "common/plots.hpp"
#include "common/state_file.hpp"
#include "dem/crack_front.hpp"

namespace arlequin::app {
namespace {

using Clock = std::chrono::steady_clock;

// The continuum's own terms of the energy balance: its tractions' and supports' work, and
// velocity Verlet's shadow correction at the run's step, which together close the balance of
// linear elasticity at any step (docs/theory.md#energy, decisions.md#d30). A coupled step counts
// its continuum's work too (its supports move a coupled DCB's arms) but keeps its own shadow
// term, which the coupling's invariant is tested with apart.
double continuum_work(const Scene& scene) {
  return scene.continuum && !scene.static_only() ? scene.continuum->external_work() : 0.0;
}
std::pair<double, double> continuum_balance_terms(const Scene& scene) {
  if (!scene.continuum || scene.static_only() || scene.model->coupled()) return {continuum_work(scene), 0.0};
  return {continuum_work(scene), scene.continuum->verlet_correction(scene.dt)};
}
// A row's energy balance (docs/theory.md#energy): with a continuum it covers both models and the
// coupling's work, and W_external the continuum's tractions and supports too
// (continuum_balance_terms). `flow` is the energy that entered, left or broke (|work|, the
// coupling's |work|, dissipated, fractured), which the run's verdict measures the balance against.
struct EnergyBalance {
  double external_work = 0.0, dissipated = 0.0, balance = 0.0, flow = 0.0;
};
EnergyBalance energy_balance(const Scene& scene, const SceneEnergies& energies, double initial_total) {
  const dem::Energies& e = energies.dem;
  const auto [continuum_work, verlet] = continuum_balance_terms(scene);
  EnergyBalance b;
  b.external_work = e.external_work + continuum_work;
  b.dissipated = e.dissipated + energies.continuum_dissipated;
  b.balance = energies.total() - verlet + b.dissipated + e.fracture - b.external_work - energies.coupling_work - initial_total;
  b.flow = std::abs(b.external_work) + std::abs(energies.coupling_work) + std::abs(b.dissipated) + std::abs(e.fracture);
  return b;
}
// series.csv's header as one text ("time,step,...,"), which a checkpoint holds to be recognised.
std::string column_list(const std::vector<std::string>& columns) {
  std::string list;
  for (const auto& c : columns) list += c + ",";
  return list;
}
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}


// The fields files runs left in `dir`, newest first: fields.h5 and the .part files of writers
// that were killed (not this process's own, which it is writing).
std::vector<std::filesystem::path> earlier_fields_files(const std::filesystem::path& dir) {
  const std::string own = "fields.h5.part." + std::to_string(::getpid());
  std::vector<std::pair<std::filesystem::file_time_type, std::filesystem::path>> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if ((name == "fields.h5" || name.starts_with("fields.h5.part.")) && name != own)
      found.emplace_back(entry.last_write_time(ec), entry.path());
  }
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::filesystem::path> files;
  for (const auto& f : found) files.push_back(f.second);
  return files;
}

// Writes the output files of one run; every file is replaced atomically. A restarted run
// (`restart`: the checkpoint read from the folder `checkpoint_dir`) starts from the rows and
// frames the checkpoint counts.
class Outputs {
 public:
  // `run`: the run's identity, which tags its fields file (carried over by restarts).
  Outputs(const Scene& scene, std::uint64_t run, const StateArchive* restart, const std::filesystem::path& checkpoint_dir)
      : scene_(&scene), run_(run) {
    std::error_code ec;
    std::filesystem::create_directories(scene.output.dir, ec);
    if (ec) throw InputError("cannot create the output folder '" + scene.output.dir.string() + "': " + ec.message());
    const bool fields = scene.output.particle_fields || scene.output.bond_fields || scene.output.continuum_fields;
    if (fields) {
      fields_.emplace(scene.output.dir / "fields.h5", scene.output.dir / "fields.xdmf");
      fields_->tag(run);
    }
    // The frames before the restart, while a killed writer's file is still there.
    if (fields && restart) carry_frames(*restart, checkpoint_dir);
    // A folder run before holds its outputs: what a killed writer left half done goes, and so
    // do the files this run will not write (fields of a run that had them, breaks of one with
    // failure, the checkpoint of another run), so that no file of the folder is from another run
    // than series.csv.
    remove_stale_temporaries(scene.output.dir);
    std::vector<const char*> not_written;
    if (!fields) not_written.insert(not_written.end(), {"fields.h5", "fields.xdmf"});
    if (!scene.dem.failure_enabled()) not_written.push_back("breaks.csv");
    if (!restart) not_written.push_back(checkpoint_file_name);
    for (const char* name : not_written) std::filesystem::remove(scene.output.dir / name, ec);
    series_.emplace(scene.output.dir / "series.csv", series_columns(scene));
    if (restart) restore_rows(*restart);
    write_file_atomically(scene.output.dir / "case.resolved.yaml", scene.resolved_case);
  }

  // The rows and frames written so far that the output schedule asked for: a run's last step
  // has a row and a frame even when none is due, which a restarted run must not keep.
  void mark_rows_on_schedule() { rows_on_schedule_ = series_->rows(); }
  void mark_frames_on_schedule() { frames_on_schedule_ = fields_ ? fields_->frames() : 0; }

  // Those rows and the frames' index, for the checkpoint.
  void save_state(StateArchive& archive) const {
    archive.put_text("run/series_columns", column_list(series_->columns()));
    std::vector<double> rows;
    for (std::size_t r = 0; r < rows_on_schedule_; ++r) rows.insert(rows.end(), series_->row(r).begin(), series_->row(r).end());
    archive.put("run/series", rows);
    archive.put("run/frames", static_cast<std::int64_t>(frames_on_schedule_));
    archive.put("run/frame_times", fields_ ? fields_->frame_times(frames_on_schedule_) : std::vector<double>{});
    archive.put_text("run/frames_index", fields_ ? fields_->frames_index(frames_on_schedule_) : "");
  }

  // One row of series.csv with the row's energy balance; returns the sensors' values.
  std::vector<std::pair<std::string, double>> write_row(double time, long step, const SceneEnergies& energies,
                                                       const EnergyBalance& b) {
    row_.assign({time, double(step)});
    std::vector<std::pair<std::string, double>> values;
    const auto names = sensor_columns(*scene_);
    std::size_t column = 0;
    for (const Sensor& s : scene_->sensors) {
      const Vec3 v = sensor_value(s);
      for (int k = 0; k < 3; ++k)
        if (s.component < 0 || s.component == k) {
          row_.push_back(v[k]);
          values.emplace_back(names[column++], v[k]);
        }
    }
    const dem::Energies& e = energies.dem;
    for (double x : {e.kinetic, e.bond, e.contact, b.external_work, b.dissipated, e.fracture, energies.total(), b.balance})
      row_.push_back(x);
    if (scene_->continuum) {
      row_.push_back(energies.continuum_kinetic);
      row_.push_back(energies.continuum_strain);
    }
    if (const auto m = scene_->model->monitor())  // coupling_columns
      for (double x : {energies.coupling_work, m->constraint_residual, m->velocity_mismatch_rms, m->velocity_mismatch_max})
        row_.push_back(x);
    if (scene_->dem.failure_enabled()) {
      for (const auto& set : scene_->dem.bond_sets()) {
        const auto broken = set->broken();
        row_.push_back(double(std::count(broken.begin(), broken.end(), 1)) / double(std::max<std::size_t>(1, set->size())));
      }
      write_breaks(false);
    }
    series_->append(row_);
    return values;
  }

  void write_fields(double time) {
    if (!fields_) return;
    fields_->begin_frame(time);
    scene_->model->write_fields(*fields_, scene_->output);
    fields_->end_frame();
  }

  void close() {
    series_->flush();
    if (scene_->dem.failure_enabled()) write_breaks(true);
    if (fields_) fields_->close();
  }
  // A zone that moved (app/zone_move.hpp) goes on in `scene`: the breaks so far are written,
  // and those the new scene keeps of them (the bonds it has too) are not written again.
  void follow(const Scene& scene) {
    if (scene_->dem.failure_enabled()) write_breaks(true);
    scene_ = &scene;
    breaks_formatted_ = breaks_on_disk_ = scene.dem.breaks().size();
  }
  const CsvSeries& series() const { return *series_; }
  std::size_t frames_carried() const { return frames_carried_; }

  // The case's plots of series.csv columns, drawn once the file is complete.
  void write_plots() const {
    std::vector<Plot> plots;
    for (const PlotPlan& plan : scene_->output.plots) {
      Plot& plot = plots.emplace_back();
      plot.file = plan.file.string();
      plot.title = plan.title;
      plot.x_label = plan.x_label;
      plot.y_label = plan.y_label;
      plot.y2_label = plan.y2_label;
      const auto curve = [&](const std::string& y, double y_scale, bool right) {
        PlotCurve c;
        c.label = y;
        c.right_axis = right;
        c.csv = "series.csv";
        c.x_column = plan.x;
        c.y_column = y;
        c.x_scale = plan.x_scale;
        c.y_scale = y_scale;
        return c;
      };
      for (const auto& y : plan.y) plot.curves.push_back(curve(y, plan.y_scale, false));
      for (const auto& y : plan.y2) plot.curves.push_back(curve(y, plan.y2_scale, true));
      for (const auto& reference : plan.references) {
        PlotCurve c;
        c.label = reference.label;
        c.style = PlotCurve::Style::dashed;
        for (double x : reference.x) c.x.push_back(x * plan.x_scale);
        for (double y : reference.y) c.y.push_back(y * plan.y_scale);
        plot.curves.push_back(c);
      }
    }
    arlequin::write_plots(scene_->output.dir, plots);
  }

 private:
  Vec3 sensor_value(const Sensor& s) const {
    switch (s.kind) {
      case Sensor::Kind::force:
        return s.on_continuum ? scene_->continuum->reaction_on(s.group_name) : scene_->dem.reaction_on(s.group);
      case Sensor::Kind::displacement:
        return s.on_continuum ? scene_->continuum->mean_displacement(s.group_name) : scene_->dem.mean_displacement(s.group);
      case Sensor::Kind::velocity:
        return s.on_continuum ? scene_->continuum->mean_velocity(s.group_name) : scene_->dem.mean_velocity(s.group);
      case Sensor::Kind::energy:
        return {scene_->dem.group_energy(s.group), 0.0, 0.0};
      case Sensor::Kind::affine_deviation:
        return {affine_deviation(), 0.0, 0.0};
      case Sensor::Kind::crack:
        return {crack_measure(s.crack), 0.0, 0.0};
    }
    return {};
  }

  double crack_measure(const Sensor::Crack& c) const {
    const auto m = dem::measure_crack(*scene_->dem.bond_sets()[c.bond_set], scene_->dem.particles, c.axis, c.across, c.bins);
    switch (c.quantity) {
      case Sensor::CrackQuantity::tip: return m.tip;
      case Sensor::CrackQuantity::damage_front: return m.damage_front;
      case Sensor::CrackQuantity::crack_growth: return m.tip - c.initial_tip;
      case Sensor::CrackQuantity::softening_zone: return m.damage_front - c.initial_tip;
      case Sensor::CrackQuantity::process_zone: return m.damage_front - m.tip;
      case Sensor::CrackQuantity::dissipated: return m.dissipated + c.dissipated_left;
    }
    return 0.0;
  }

  // max |u - H X| / max |H X| over the DEs (u = position - reference, X = reference) and the
  // continuum nodes.
  double affine_deviation() const {
    const auto& H = *scene_->initial_gradient;
    std::array<double, 2> m = scene_->continuum ? scene_->continuum->affine_deviation(H) : std::array<double, 2>{0.0, 0.0};
    const dem::ParticleSet& p = scene_->dem.particles;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec3& X = p.reference[i];
      const Vec3 affine = rows_times(H, X);
      m[0] = std::max(m[0], norm(p.position[i] - X - affine));
      m[1] = std::max(m[1], norm(affine));
    }
    return m[1] > 0.0 ? m[0] / m[1] : m[0];
  }

  // breaks.csv: one row per broken bond. Rows are formatted once, as the breaks come, and the
  // file is rewritten atomically at most every 2 s of wall time (as series.csv) and at close,
  // so a long failure run with many breaks costs linear, not quadratic, I/O.
  void write_breaks(bool force) {
    const auto& breaks = scene_->dem.breaks();
    if (breaks_text_.empty()) breaks_text_ = "time,set,bond,first,second,group,criterion,mode,stress,energy,mode_mix\n";
    char line[320], mix[32] = "";
    for (; breaks_formatted_ < breaks.size(); ++breaks_formatted_) {
      const auto& e = breaks[breaks_formatted_];
      const auto& set = *scene_->dem.bond_sets()[e.set];
      if (e.mode_mix >= 0.0) std::snprintf(mix, sizeof mix, "%.6g", e.mode_mix);
      std::snprintf(line, sizeof line, "%.12g,%u,%u,%u,%u,%s,%s,%s,%.9g,%.9g,%s\n", e.time, e.set, e.bond, set.first()[e.bond],
                    set.second()[e.bond], set.name.c_str(), std::string(dem::name_of(e.criterion)).c_str(),
                    std::string(dem::name_of(e.mode)).c_str(), e.stress, e.energy, e.mode_mix >= 0.0 ? mix : "");
      breaks_text_ += line;
    }
    const auto now = std::chrono::steady_clock::now();
    const bool stale = breaks_on_disk_ < breaks_formatted_ || !breaks_file_written_;
    if (!stale || (!force && breaks_file_written_ && now - breaks_last_write_ < std::chrono::seconds(2))) return;
    write_file_atomically(scene_->output.dir / "breaks.csv", breaks_text_);
    breaks_on_disk_ = breaks_formatted_;
    breaks_file_written_ = true;
    breaks_last_write_ = now;
  }

  // The columns were checked against the scene's before (run_scene).
  void restore_rows(const StateArchive& restart) {
    const auto rows = restart.get<double>("run/series");
    const std::size_t width = series_->columns().size();
    for (std::size_t at = 0; at < rows.size(); at += width) series_->append(std::span<const double>(rows).subspan(at, width));
    rows_on_schedule_ = series_->rows();
  }

  // The frames of the checkpoint, from the first fields file of its folder that holds them (at
  // their times): fields.h5, or what a killed writer left, newest first.
  void carry_frames(const StateArchive& restart, const std::filesystem::path& dir) {
    const auto times = restart.get<double>("run/frame_times");
    if (times.empty()) return;
    std::string why = "no fields.h5 in '" + dir.string() + "'";
    for (const auto& file : earlier_fields_files(dir)) {
      try {
        fields_->carry_frames(file, run_, times, restart.text("run/frames_index"));
        frames_on_schedule_ = frames_carried_ = times.size();
        return;
      } catch (const RunError& e) {
        why = e.what();
      }
    }
    std::fprintf(stderr, "  warning: the %zu frames before the restart are not carried over (%s); fields.xdmf holds the frames from the restart on\n",
                 times.size(), why.c_str());
  }

  const Scene* scene_;
  std::uint64_t run_;
  std::size_t rows_on_schedule_ = 0, frames_on_schedule_ = 0;
  std::size_t frames_carried_ = 0;  // frames copied from before a restart
  std::optional<CsvSeries> series_;
  std::optional<FieldsWriter> fields_;
  std::vector<double> row_;
  std::string breaks_text_;           // breaks.csv as it will be written
  std::size_t breaks_formatted_ = 0;  // breaks already in breaks_text_
  std::size_t breaks_on_disk_ = 0;    // breaks in the file last written
  bool breaks_file_written_ = false;
  std::chrono::steady_clock::time_point breaks_last_write_;
};

// A progress line on stderr, at most twice a second: step, simulated time, rate, ETA.
// Without the line (output not a terminal, a CI log), a run that will take more than a minute
// says once, after 2 s, how long it will take: a time.end of 1e10 steps is not a silent hang.
class Progress {
 public:
  Progress(bool enabled, bool announce, long first, long total)
      : enabled_(enabled), announce_(announce && !enabled), first_(first), total_(total), start_(Clock::now()), last_(start_) {}
  void update(long step, double t) {
    if (announce_ && seconds_since(start_) > 2.0) {
      announce_ = false;
      const double rate = (step - first_) / seconds_since(start_), left = (total_ - step) / std::max(rate, 1e-9);
      if (left > 60.0)
        std::fprintf(stderr, "  run time: about %.3g %s to go at %.0f steps/s (%ld of %ld steps done)\n",
                     left < 3600.0 ? left / 60.0 : left / 3600.0, left < 3600.0 ? "min" : "h", rate, step, total_);
    }
    if (!enabled_ || seconds_since(last_) < 0.5) return;
    last_ = Clock::now();
    const double elapsed = seconds_since(start_);
    const double rate = (step - first_) / std::max(elapsed, 1e-9);
    std::fprintf(stderr, "\r  step %ld/%ld  t = %.4e s  %.0f steps/s  ETA %.0f s   ", step, total_, t, rate,
                 (total_ - step) / std::max(rate, 1e-9));
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_, announce_;
  long first_, total_;  // steps: the run's first (0, or the restart's), its last
  Clock::time_point start_, last_;
};

Json energies_json(const dem::Energies& e) {
  Json j = Json::object();
  j["kinetic"] = e.kinetic;
  j["bond"] = e.bond;
  j["contact"] = e.contact;
  j["external_work"] = e.external_work;
  j["dissipated"] = e.dissipated;
  j["fracture"] = e.fracture;
  j["total"] = e.total();
  return j;
}

}  // namespace

double steps_per_second(const RunResult& r) { return r.steps / std::max(r.wall_seconds - r.output_seconds, 1e-9); }

std::string describe(const Check& check) {
  switch (check.kind) {
    case Check::Kind::final_value: return "final value";
    case Check::Kind::maximum:
    case Check::Kind::minimum: {
      std::string text = check.kind == Check::Kind::maximum ? "maximum" : "minimum";
      if (check.versus.empty()) return text;
      std::ostringstream range;
      range << " over " << check.versus << " in [" << check.over_low << ", " << check.over_high << "]";
      return text + range.str();
    }
    case Check::Kind::final_over_initial: return "final / initial";
    case Check::Kind::crossing: return "crossing time";
    case Check::Kind::curve: return "largest deviation from the reference";
  }
  return "";
}

namespace {

// Evaluates the case's checks on the rows of series.csv.
std::vector<RunResult::CheckResult> evaluate_checks(const Scene& scene, const CsvSeries& series) {
  std::vector<RunResult::CheckResult> out;
  const auto& columns = series.columns();
  for (const Check& c : scene.checks) {
    const std::size_t col = std::find(columns.begin(), columns.end(), c.column) - columns.begin();
    double value = std::numeric_limits<double>::quiet_NaN();
    const bool crossing = c.kind == Check::Kind::crossing;
    if (c.kind == Check::Kind::final_value && series.rows() > 0) value = series.row(series.rows() - 1)[col];
    if (c.kind == Check::Kind::final_over_initial && series.rows() > 0)
      value = series.row(series.rows() - 1)[col] / series.row(0)[col];
    if (c.kind == Check::Kind::maximum || c.kind == Check::Kind::minimum) {
      const std::size_t versus = std::find(columns.begin(), columns.end(), c.versus) - columns.begin();
      bool first = true;
      for (std::size_t r = 0; r < series.rows(); ++r) {
        if (!c.versus.empty() && !(series.row(r)[versus] >= c.over_low && series.row(r)[versus] <= c.over_high)) continue;
        const double x = series.row(r)[col];
        if (first || (c.kind == Check::Kind::maximum ? x > value : x < value)) value = x;
        first = false;
      }
    }
    for (std::size_t r = 1; crossing && r < series.rows(); ++r) {
      const double a = series.row(r - 1)[col] - c.threshold, b = series.row(r)[col] - c.threshold;
      if ((a < 0) != (b < 0) || b == 0) {  // linear interpolation of the crossing time
        const double t0 = series.row(r - 1)[0], t1 = series.row(r)[0];
        value = t0 + (t1 - t0) * a / (a - b);
        break;
      }
    }
    if (c.kind == Check::Kind::curve) {
      const std::size_t versus = std::find(columns.begin(), columns.end(), c.versus) - columns.begin();
      // A row that cannot be compared (a non-finite value) makes the check fail, as no row does.
      bool compared = false, finite = true;
      double worst = 0.0;
      for (std::size_t r = 0; r < series.rows(); ++r) {
        const double x = series.row(r)[versus];
        if (!(x >= c.over_low && x <= c.over_high)) continue;
        const double deviation = std::abs(series.row(r)[col] / c.reference.at(x) - 1.0);
        compared = true;
        finite = finite && std::isfinite(deviation);
        worst = std::max(worst, deviation);
      }
      if (compared && finite) value = worst;
    }
    if (c.bounded) {
      out.push_back({&c, value, 0.0, value <= c.at_most && value >= c.at_least});
      continue;
    }
    const double error = std::abs(value - c.expected) / std::max(std::abs(c.expected), 1e-300);
    out.push_back({&c, value, error, error <= c.tolerance});
  }
  return out;
}

}  // namespace

std::string unbalanced(double balance, double budget, const std::vector<std::pair<std::string, double>>& parts,
                       const std::string& likely_cause) {
  // A balance that is not finite is left to the finite check, which names the DE.
  if (!(std::abs(balance) > balance_limit * budget) || !std::isfinite(balance)) return {};
  std::ostringstream msg;
  msg << "the energy balance is off by " << balance << " J, " << 100.0 * std::abs(balance) / budget << " % of the " << budget
      << " J that started in, entered, left or broke in the scene (limit " << 100.0 * balance_limit << " %; now";
  for (std::size_t k = 0; k < parts.size(); ++k) msg << (k ? ", " : " ") << parts[k].first << " " << parts[k].second << " J";
  msg << "): the run is unstable, however slowly; likely cause: " << likely_cause;
  return msg.str();
}

RunResult run_scene(Scene& built, const RunOptions& options) {
  // The scene the run steps: the one built, or the last a zone that follows a crack moved to.
  Scene* scene = &built;
  std::unique_ptr<Scene> moved;
  dem::DemModel* model = &scene->dem;
  long total_steps = scene->steps;
  const bool static_only = scene->static_only();  // one solve, whatever --steps says
  if (options.max_steps >= 0) total_steps = std::min(total_steps, options.max_steps);

  RunResult result;
  double initial_total = scene->model->energies().total() - continuum_balance_terms(*scene).second;
  // A healthy run's kinetic energy stays below what it started with plus the work put in;
  // far above that (x100) the run has blown up. The first step's kinetic energy counts
  // the motion that boundary conditions impose. A scene at rest has round-off forces (a bond's
  // rest length is a computed distance), and the motion they cause grows (a free packing: 1e-31
  // J after 350 steps, 1e-27 J after 5600 in Runs.BondedPackingAtRestRunsToTheEnd). Its scale:
  // a stiffest spring k ~ m (2 / dt_c)^2 stretched by a rounding error of position eps X
  // accelerates its DE by ~ eps X / dt_c^2, so after a time t the DEs move at ~ eps X t / dt_c^2;
  // the energy scale is at least that motion's, round_off (eps X / dt_c) times (t / dt_c)^2
  // (~4e-21 J there after 5600 steps). Both from the scene as built, before a restart moves it.
  double energy_scale = std::abs(initial_total);
  const double round_off = model->round_off_kinetic_energy(scene->dt_critical);
  double output_seconds = 0.0, next_row = 0.0, next_frame = 0.0;
  const double checkpoint_every = scene->output.checkpoint_every;
  double next_checkpoint = checkpoint_every;
  // Float steps accumulate round-off: an output is due within a millionth of a step.
  const double slack = 1e-6 * scene->dt;
  long steps_done = 0;
  // Tags the run's fields file, so that a restart takes frames from its own run's file only; a
  // restarted run keeps its run's. Not a simulation value: nothing in the physics reads it.
  std::uint64_t run_id = (std::uint64_t{std::random_device{}()} << 32) ^ std::random_device{}() ^
                         static_cast<std::uint64_t>(Clock::now().time_since_epoch().count());

  // A restart: every refusal before any output is touched, then the state.
  const StateArchive* restart = options.restart;
  if (restart) {
    const std::string file = "'" + options.restart_file.string() + "'";
    check_same_run(*restart, *scene, options.restart_file);
    try {
      run_id = static_cast<std::uint64_t>(restart->integer("run/id"));
      steps_done = restart->integer("run/steps_done");
      if (steps_done < 0 || (model->particles.size() > 0 && restart->integer("dem/steps") != steps_done))
        throw StateMismatch("its step counts disagree (run " + std::to_string(steps_done) + ")");
      next_row = restart->number("run/next_row");
      next_frame = restart->number("run/next_frame");
      initial_total = restart->number("run/initial_total");
      energy_scale = restart->number("run/energy_scale");
      const auto names = series_columns(*scene);
      const std::string columns = column_list(names);
      if (restart->text("run/series_columns") != columns)
        throw StateMismatch("its series.csv has the columns '" + restart->text("run/series_columns") + "', this scene '" + columns + "'");
      if (restart->get<double>("run/series").size() % names.size() != 0) throw StateMismatch("its series rows are not whole rows");
      const auto frame_times = restart->get<double>("run/frame_times");
      if (static_cast<std::int64_t>(frame_times.size()) != restart->integer("run/frames") || !restart->has("run/frames_index"))
        throw StateMismatch("its frame count and frame times disagree");
      const auto sensors = restart->get<double>("run/sensors");
      for (std::size_t k = 0; k < sensors.size() && k + 2 < names.size(); ++k) result.sensors.emplace_back(names[k + 2], sensors[k]);
      result.damage_in_overlap = restart->text("run/damage_in_overlap");
      result.damage_in_overlap_breaks = static_cast<std::size_t>(restart->integer("run/damage_in_overlap_breaks"));
    } catch (const StateMismatch& e) {
      throw InputError(file + " is not a checkpoint of this scene: " + e.what());
    }
    // A restart has steps to run: a finished run is extended by a later time.end.
    if (steps_done >= scene->steps)
      throw InputError(file + " is at step " + std::to_string(steps_done) + (steps_done == scene->steps ? ", the last" : ", past the last") +
                       " of this case (time.end " + std::to_string(scene->end_time) + " s): give a later time.end to continue it");
    if (total_steps <= steps_done)
      throw InputError("--steps " + std::to_string(total_steps) + ": the run would stop at or before step " +
                       std::to_string(steps_done) + ", where " + file + " restarts it");
    next_checkpoint = steps_done * scene->dt + checkpoint_every;  // the case's interval, from here
    load_scene_state(*scene, *restart, options.restart_file);
  }
  Outputs outputs(*scene, run_id, restart, options.restart_file.parent_path());
  // The runner's part of the checkpoint: where the run is, its output schedule, the scales its
  // checks use, and what it has reported; the rows and frames are the outputs'.
  std::string checkpoint_error;  // the first checkpoint that could not be written
  const auto save_checkpoint = [&] {
    StateArchive archive;
    put_run_identity(archive, *scene);
    scene->model->save_state(archive);
    archive.put("run/id", static_cast<std::int64_t>(run_id));
    archive.put("run/steps_done", std::int64_t{steps_done});
    for (const auto& [name, value] : {std::pair{"next_row", next_row}, {"next_frame", next_frame}, {"initial_total", initial_total}, {"energy_scale", energy_scale}})
      archive.put("run/" + std::string(name), value);
    std::vector<double> sensors;
    for (const auto& [name, value] : result.sensors) sensors.push_back(value);
    archive.put("run/sensors", sensors);
    archive.put_text("run/damage_in_overlap", result.damage_in_overlap);
    archive.put("run/damage_in_overlap_breaks", static_cast<std::int64_t>(result.damage_in_overlap_breaks));
    outputs.save_state(archive);
    // A checkpoint that cannot be written (a full disk) does not stop the run: the last one stays.
    try {
      write_state_file(scene->output.dir / checkpoint_file_name, archive);
    } catch (const RunError& e) {
      if (checkpoint_error.empty()) {
        std::fprintf(stderr, "  warning: %s; the run goes on, its last checkpoint stays\n", e.what());
        checkpoint_error = e.what();
      }
    }
  };
  const long first_step = steps_done;
  Progress progress(options.show_progress, options.announce_run_time, first_step, total_steps);
  const auto current_time = [&] { return steps_done * scene->dt; };
  // Outputs are written after step n when it ends on a row or a frame, or is the last.
  const auto output_after = [&](long n) { return n * scene->dt + slack >= std::min(next_row, next_frame) || n == total_steps; };
  const std::string likely_cause =
      std::string(scene->continuum ? "the continuum's force taken once every too many steps (coupling.continuum_substeps: an "
                                    "impulse method's resonance, docs/theory.md#continuum-substeps), "
                                  : "") +
      "a time step too close to the stability limit, or work a boundary condition does not report";
  const auto write_outputs = [&] {
    const auto t0 = Clock::now();
    // A row takes every model's energies (the continuum's strain energy is a pass over it); a
    // frame alone needs only the DEM's, for the summary.
    // The last step has both whether due or not; only a due one moves the schedule on, so a
    // run stopped early (--steps) and restarted keeps the schedule of the uninterrupted run.
    const bool row_due = current_time() + slack >= next_row, frame_due = current_time() + slack >= next_frame;
    const bool last = steps_done == total_steps;
    const SceneEnergies energies = row_due || last ? scene->model->energies() : SceneEnergies{model->energies()};
    result.energies = energies.dem;
    if (row_due || last) {
      const EnergyBalance balance = energy_balance(*scene, energies, initial_total);
      result.sensors = outputs.write_row(current_time(), steps_done, energies, balance);
      // The balance's verdict (after the row, which shows it), for a time loop (a static solve's
      // balance is its complementary energy): what it is measured against is the blow-up test's
      // scale (the start's energy, or the round-off floor) and the energy flow.
      if (!static_only) {
        const double start = std::max(energy_scale, round_off * std::pow(current_time() / scene->dt_critical, 2));
        const dem::Energies& e = energies.dem;
        std::vector<std::pair<std::string, double>> parts{{"DEM kinetic", e.kinetic}, {"bonds", e.bond}, {"contacts", e.contact}};
        if (scene->continuum)
          parts.insert(parts.end(), {{"continuum kinetic", energies.continuum_kinetic}, {"continuum strain", energies.continuum_strain}});
        if (const std::string why = unbalanced(balance.balance, start + balance.flow, parts, likely_cause); !why.empty()) {
          std::ostringstream at;
          at << "step " << steps_done << " (t = " << current_time() << " s): ";
          throw RunError(at.str() + why);
        }
      }
      if (row_due) next_row += scene->output.every, outputs.mark_rows_on_schedule();
      if (options.stop_after_row) result.stop_reason = options.stop_after_row(result.sensors);
    }
    if (frame_due || last) {
      outputs.write_fields(current_time());
      if (frame_due) next_frame += scene->output.fields_every, outputs.mark_frames_on_schedule();
    }
    output_seconds += seconds_since(t0);
  };

  // --profile: the DEM times its phases, the runner its own, and the rest of a model step (the
  // continuum and the coupling) is one phase.
  StepProfile* const profile = scene->profile;
  struct {
    int checks = 0, outputs = 0, rest = 0;
  } phase;
  if (profile) {
    model->set_profile(profile);
    if (scene->continuum) phase.rest = profile->phase("continuum and coupling");
    phase.checks = profile->phase("energy and overlap checks");
    phase.outputs = profile->phase("sensors, energies, output");
  }
  const auto step_model = [&] {
    if (!profile || !scene->continuum) return scene->model->step(scene->dt);
    const double timed_before = profile->seconds();
    const auto t0 = Clock::now();
    scene->model->step(scene->dt);
    profile->add(phase.rest, std::max(0.0, seconds_since(t0) - (profile->seconds() - timed_before)), true);
  };

  // A band that follows a crack (app/zone_move.hpp): looked at every zone_check_steps steps,
  // between two macro steps; each move's energy jump is its own term of the balance (the start's
  // total moves by it), and what it leaves behind stays counted.
  const bool follows = scene->continuum && scene->continuum->band_follow();
  constexpr long zone_check_steps = 100;
  Json zone_moves = Json::array();
  std::size_t breaks_left_behind = 0;
  std::optional<double> first_break_time;
  double zone_energy_jumps = 0.0;
  // After a move of the start, the settling of the DEs around it; its row in zone_moves.
  BandSettling settling;
  std::size_t settling_row = 0;
  const auto record_settling = [&] {
    if (settling.steps_done() == 0) return;
    Json& row = zone_moves[settling_row];
    row["settling_steps"] = settling.steps_done();
    row["settling_particles"] = settling.particles();
    row["settling_dissipated"] = settling.dissipated();
  };
  const auto move_zone_to = [&](BandPlace place) {
    const bool start_moves = place.from > scene->continuum->band_follow()->from;
    const std::size_t breaks_before = model->breaks().size();
    if (!first_break_time && breaks_before > 0) first_break_time = model->breaks().front().time;
    ZoneMove move;
    std::unique_ptr<Scene> next;
    try {
      next = move_zone(built, *scene, place, move);
    } catch (const InputError& e) {  // the moved band's case refused (a step above its critical one)
      std::ostringstream at;
      at << "step " << steps_done << " (t = " << current_time() << " s): the band could not move to [" << place.from << ", " << place.to
         << "] m: " << e.what();
      throw RunError(at.str());
    }
    if (profile) model->set_profile(nullptr), next->dem.set_profile(profile);
    outputs.follow(*next);
    moved = std::move(next);
    scene = moved.get();
    model = &scene->dem;
    breaks_left_behind += breaks_before - model->breaks().size();
    initial_total += move.energy_jump();
    zone_energy_jumps += move.energy_jump();
    Json row = Json::object();
    row["step"] = steps_done;
    row["time"] = current_time();
    row["from"] = place.from;
    row["to"] = place.to;
    row["particles"] = move.des;
    row["particles_added"] = move.des_added;
    row["particles_dropped"] = move.des_dropped;
    row["continuum_nodes_added"] = move.nodes_added;
    row["continuum_nodes_from_des"] = move.nodes_from_des;
    row["displacement_residual"] = scene->model->displacement_residual();
    row["broken_bonds_left_behind"] = move.links_dropped_broken;
    row["energy_jump"] = move.energy_jump();
    row["energy_before"] = move.energy_before;
    row["seconds"] = move.setup_seconds;
    if (move.relaxation.steps > 0) {
      row["relaxation_steps"] = move.relaxation.steps;
      row["relaxation_imbalance_before"] = move.relaxation.imbalance_before;
      row["relaxation_imbalance_after"] = move.relaxation.imbalance_after;
      row["relaxation_free_rigid_motions"] = move.relaxation.free_rigid_motions;
      row["relaxation_fracture"] = move.relaxation.fracture;
    }
    zone_moves.push_back(row);
    if (start_moves) {  // a settle_time of 0 starts none
      record_settling();
      settling.start(*scene);
      settling_row = zone_moves.size() - 1;
    } else {
      settling.carry_to(*scene);
    }
    std::fprintf(stderr,
                 "  the band moved at step %ld (t = %.6g s) to [%.6g, %.6g] m: %zu DEs (%zu added, %zu dropped), %zu continuum nodes "
                 "added, energy %+.3g J of %.3g J, %.2f s\n",
                 steps_done, current_time(), place.from, place.to, move.des, move.des_added, move.des_dropped, move.nodes_added, move.energy_jump(),
                 move.energy_before, move.setup_seconds);
    if (move.relaxation.steps > 0)
      std::fprintf(stderr, "  relaxed in %d pseudo-time steps: imbalance sum m|a - a_target|^2 %.3g -> %.3g J/s^2 (%d free rigid motions)\n",
                   move.relaxation.steps, move.relaxation.imbalance_before, move.relaxation.imbalance_after, move.relaxation.free_rigid_motions);
  };

  const auto t_start = Clock::now();
  std::string failure;
  std::exception_ptr interrupted;  // Ctrl-C or SIGTERM: rethrown once the outputs are closed
  const InterruptScope interrupt_scope;
  const auto interruption = [&](int signal) {
    return Interrupted(signal, "interrupted by " + signal_name(signal) + " after step " + std::to_string(steps_done) +
                                   ", t = " + std::to_string(current_time()) + " s; the outputs so far are closed and kept");
  };
  try {
    if (static_only) {
      scene->continuum->solve_static();  // a static continuum alone: one solve, one output
      total_steps = 0;
    }
    if (!restart) write_outputs();
    for (long n = first_step + 1; n <= total_steps; ++n) {
      if (const int signal = take_interrupt()) throw interruption(signal);
      if (output_after(n)) model->record_energies_in_next_step();  // the step's force pass gives the row's bond energies
      step_model();
      ++steps_done;
      if (settling.active()) {
        settling.after_step(*model, *scene->model);
        if (!settling.active()) record_settling();
      }
      if (profile) profile->count_step();
      model->check_finite();  // the DEM times it
      {
        const PhaseTimer timer(profile, phase.checks, false);
        if (n == 1) energy_scale = std::max(energy_scale, model->kinetic_energy());
        if (const auto damage = scene->model->damage_in_overlap()) {
          const bool first = result.damage_in_overlap.empty();
          if (first) result.damage_in_overlap = "step " + std::to_string(n) + ": " + damage->description;
          result.damage_in_overlap_breaks += damage->breaks;
          if (damage->stop)
            throw RunError(result.damage_in_overlap + "; the run stops (coupling.on_damage_in_overlap: stop; warn goes on)");
          if (first)
            std::fprintf(stderr, "  warning: %s; the run goes on (coupling.on_damage_in_overlap: %s)\n", result.damage_in_overlap.c_str(),
                         damage->held ? "hold" : "warn");
        }
        if (n % 50 == 0 || n == total_steps)
          model->check_energy(100.0 * (std::max(energy_scale, round_off * std::pow(n * scene->dt / scene->dt_critical, 2)) +
                                      std::abs(model->external_work() + continuum_work(*scene))) +
                             1e-300);
      }
      {
        const PhaseTimer timer(profile, phase.outputs, false);
        if (output_after(n)) write_outputs();
        if (checkpoint_every > 0.0 && current_time() + slack >= next_checkpoint && n < total_steps) {
          save_checkpoint();
          while (next_checkpoint <= current_time() + slack) next_checkpoint += checkpoint_every;
        }
        progress.update(n, current_time());
      }
      if (follows && n % zone_check_steps == 0 && n < total_steps && scene->model->accepts_set_state())
        if (const std::optional<BandPlace> place = band_place(*scene)) move_zone_to(*place);
      if (!result.stop_reason.empty()) break;
    }
  } catch (const RunError& e) {
    failure = e.what();
  } catch (const Interrupted& e) {
    failure = e.what();
    interrupted = std::current_exception();
  }
  if (profile) model->set_profile(nullptr);
  // The state at the end, or where a signal stopped the run: between two steps, so whole.
  // (Not of a zone that moved: its case is no longer the case's, zone_move.hpp.)
  if (!static_only && !moved && (interrupted || (failure.empty() && checkpoint_every > 0.0))) save_checkpoint();
  progress.finish();
  result.steps = steps_done;
  result.simulated_time = current_time();
  result.wall_seconds = seconds_since(t_start);
  result.output_seconds = output_seconds;
  outputs.close();
  outputs.write_plots();

  Json summary = Json::object();
  summary["name"] = scene->name;
  summary["case_file"] = std::filesystem::absolute(scene->case_file).string();
  summary["version"] = ARLEQUIN_VERSION;
  summary["status"] = failure.empty() ? "completed" : interrupted ? "interrupted" : "failed";
  if (!failure.empty()) summary["error"] = failure;
  if (restart) {
    summary["restarted_from"] = std::filesystem::absolute(options.restart_file).string();
    summary["restarted_at_step"] = first_step;
    summary["restart_frames_carried"] = outputs.frames_carried();
  }
  if (!checkpoint_error.empty()) summary["checkpoint_error"] = checkpoint_error;
  if (!result.stop_reason.empty()) summary["stopped_early"] = result.stop_reason;
  if (!result.damage_in_overlap.empty()) {
    summary["damage_in_overlap"] = result.damage_in_overlap;
    summary["damage_in_overlap_breaks"] = result.damage_in_overlap_breaks;
  }
  summary["steps"] = result.steps;
  summary["simulated_time"] = result.simulated_time;
  summary["dt"] = scene->dt;
  summary["dt_critical"] = scene->dt_critical;
  Json& counts = summary["counts"];
  counts["particles"] = model->particles.size();
  if (scene->des_not_created > 0) counts["particles_not_created"] = scene->des_not_created;
  if (model->failure_enabled()) counts["broken_bonds"] = model->breaks().size() + breaks_left_behind;
  if (!first_break_time && !model->breaks().empty()) first_break_time = model->breaks().front().time;  // s; events are in time order
  if (first_break_time) summary["first_break_time"] = *first_break_time;
  if (follows) {
    summary["zone_moves"] = zone_moves;
    summary["zone_energy_jumps"] = zone_energy_jumps;
    record_settling();
    double settled = 0.0;
    for (const Json& row : zone_moves) settled += row.value("settling_dissipated", 0.0);
    summary["zone_settling_dissipated"] = settled;
  }
  if (!model->bond_sets().empty()) {
    Json& bonds = counts["bonds"];
    for (const auto& set : model->bond_sets()) bonds[set->name] = set->size();
  }
  if (scene->continuum) scene->continuum->describe(counts);
  scene->model->describe(counts);
  if (const auto* list = model->neighbours()) {
    counts["contact_candidates"] = list->pairs().size();
    counts["neighbour_rebuilds"] = list->builds();
  }
  Json& wall = summary["wall_time"];
  wall["setup"] = options.setup_seconds;
  wall["time_loop"] = result.wall_seconds;
  wall["output"] = output_seconds;
  wall["steps_per_second"] = steps_per_second(result);
  summary["energies"] = energies_json(result.energies);
  // The checks are stated for the whole case: a run cut short by --steps is not judged.
  if (failure.empty() && !scene->checks.empty() && !static_only && options.max_steps >= 0 && options.max_steps < scene->steps)
    result.checks_skipped = "the run stopped at step " + std::to_string(result.steps) + " of " + std::to_string(scene->steps) +
                            " (--steps), before time.end";
  else if (failure.empty())
    result.checks = evaluate_checks(built, outputs.series());
  if (!result.checks_skipped.empty()) summary["checks_skipped"] = result.checks_skipped;
  Json& checks = summary["checks"];
  checks = Json::array();
  for (const auto& c : result.checks) {
    Json j = Json::object();
    j["column"] = c.check->column;
    j["kind"] = describe(*c.check);
    j["value"] = c.value;
    if (c.check->bounded) {
      if (std::isfinite(c.check->at_most)) j["at_most"] = c.check->at_most;
      if (std::isfinite(c.check->at_least)) j["at_least"] = c.check->at_least;
    } else {
      j["expected"] = c.check->expected;
      j["relative_error"] = c.relative_error;
      j["tolerance"] = c.check->tolerance;
    }
    j["passed"] = c.passed;
    if (!c.check->note.empty()) j["note"] = c.check->note;
    checks.push_back(j);
  }
  Json& sensors = summary["sensors"];
  sensors = Json::object();
  for (const auto& [name, value] : result.sensors) sensors[name] = value;
  write_json_atomically(scene->output.dir / "summary.json", summary);
  if (interrupted) std::rethrow_exception(interrupted);
  if (!failure.empty()) throw RunError(failure);
  // A signal after the last step (final outputs, a static solve) leaves this run complete but
  // still ends the command: a suite must not carry on.
  if (const int signal = take_interrupt()) throw interruption(signal);
  return result;
}

}  // namespace arlequin::app
