// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/calibrate.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "app/text.hpp"
#include "common/atomic_file.hpp"
#include "common/case_file.hpp"
#include "common/error.hpp"
#include "common/json.hpp"
#include "common/plots.hpp"
#include "common/schema.hpp"

namespace arlequin::app {

Override CalibrationSpec::bond_override(const std::string& leaf, double value) const {
  return Override(bond_key + "." + leaf, value, bond_origin);
}

namespace {

// Mean of n estimates with uncertainty sqrt(sum u_i^2 / n^2 + s^2 / n) (header).
Estimate pooled(const std::vector<Estimate>& v) {
  const double n = double(v.size());
  double mean = 0.0, u2 = 0.0;
  for (const auto& e : v) mean += e.value / n, u2 += e.uncertainty * e.uncertainty / (n * n);
  double s2 = 0.0;
  for (const auto& e : v) s2 += (e.value - mean) * (e.value - mean) / std::max(n - 1.0, 1.0);
  return {mean, std::sqrt(u2 + s2 / n)};
}

// Measures the case with the bond's (E_mu, r_mu), pooled over the spec's axes.
Measurement measure(const CalibrationSpec& spec, const SceneOptions& options, double E_mu, double r_mu,
                    const std::filesystem::path& dir) {
  std::vector<Estimate> young, poisson;
  Measurement m;
  for (int axis : spec.axes) {
    SceneOptions o = options;
    o.overrides.push_back(spec.bond_override("E_mu", E_mu));
    o.overrides.push_back(spec.bond_override("r_mu", r_mu));
    o.out_dir = dir / axis_names[axis];
    LoadCase load;
    load.name = "tension_" + std::string(axis_names[axis]);
    load.face = load.direction = axis;
    const VirtualTestResult r = run_virtual_test(spec.case_file, o, load, spec.plan);
    young.push_back(r.modulus);
    for (int k = 0; k < 3; ++k)
      if (k != axis) poisson.push_back(r.poisson[k]);
    m.wall_seconds += r.wall_seconds;
    m.particles = r.particles;
  }
  m.young = pooled(young);
  m.poisson = pooled(poisson);
  return m;
}

Json estimate_json(const Estimate& e) {
  Json j = Json::object();
  j["value"] = e.value;
  j["uncertainty"] = e.uncertainty;
  return j;
}
Estimate read_estimate(const Json& j) { return {j.at("value").get<double>(), j.at("uncertainty").get<double>()}; }

// ---- The keys of a calibration spec (common/schema.hpp) ---------------------------------

constexpr KeyDoc spec_keys[] = {
    {"case", KeyType::file, "", {}, "", "the case whose sample and bond section are calibrated"},
    {"bond", KeyType::string, "", {}, "dem.bond", "key path of the calibrated bond section"},
    {"r_mu", KeyType::numbers, "1", Range::positive(), "", "the grid of r_mu of the calibration curve (two or more)"},
    {"axes", KeyType::strings, "", {}, "(z)", "tension axes averaged per curve point"},
    {"tolerance", KeyType::number, "1", Range::positive(), "0.002", "relative tolerance on E_M and nu_M"},
    {"verify", KeyType::list, "", {}, "(none)", "other samples the calibrated pairs are checked on"},
    {"quasi_static", KeyType::section, "", {}, "(defaults)", "the tension tests' loading (quasi_static plan)"},
    {"targets", KeyType::list, "", {}, "(none)", "materials (E_M, nu_M) to calibrate (E_mu, r_mu) for"},
    {"failure", KeyType::section, "", {}, "(none)", "strengths (BBF sigma_f, RDEF thresholds) for failure stresses"},
};
constexpr KeyDoc verify_keys[] = {
    {"name", KeyType::string, "", {}, "", "the sample's name"},
    {"set", KeyType::strings, "", {}, "", "overrides of the case that make it"},
};
constexpr KeyDoc elastic_target_keys[] = {
    {"name", KeyType::string, "", {}, "", "the material's name"},
    {"E", KeyType::number, "Pa", Range::positive(), "", "target Young's modulus E_M"},
    {"nu", KeyType::number, "1", Range::open_between(-1, 0.5), "", "target Poisson's ratio nu_M"},
    {"reference", KeyType::section, "", {}, "(none)", "a published pair to print beside ours"},
};
constexpr KeyDoc reference_pair_keys[] = {
    {"E_mu", KeyType::number, "Pa", Range::positive(), "", "published E_mu"},
    {"r_mu", KeyType::number, "1", Range::positive(), "", "published r_mu"},
};
constexpr KeyDoc failure_spec_keys[] = {
    {"axis", KeyType::string, "", {}, "(z)", "the tension axis of the tests to failure, x | y | z"},
    {"tolerance", KeyType::number, "1", Range::open_between(0, 1), "0.02", "relative tolerance on the failure stress"},
    {"test", KeyType::section, "", {}, "(defaults)", "the tests' loading (failure plan)"},
    {"targets", KeyType::list, "", {}, "", "failure stresses to calibrate a strength for"},
};
constexpr KeyDoc failure_target_keys[] = {
    {"name", KeyType::string, "", {}, "", "a material: an elastic target's name, or one given with its E, E_mu, r_mu"},
    {"criterion", KeyType::choice, "", {}, "", "which strength is calibrated", "bbf | rdef"},
    {"stress", KeyType::number, "Pa", Range::positive(), "", "target failure stress sigma_f of the material"},
    {"E", KeyType::number, "(Pa)", Range::positive(), "(the elastic target's)", "Young's modulus, without an elastic target of this name"},
    {"E_mu", KeyType::number, "(Pa)", Range::positive(), "(the elastic target's)", "its bonds' E_mu, likewise"},
    {"r_mu", KeyType::number, "(1)", Range::positive(), "(the elastic target's)", "its bonds' r_mu, likewise"},
    {"initial", KeyType::number, "Pa", Range::positive(), "(reference)", "first guess of the strength"},
    {"reference", KeyType::number, "Pa", Range::positive(), "(none)", "published strength, printed beside ours"},
    {"variant", KeyType::string, "", {}, "", "name of a variant of the criterion (names its folder)"},
    {"set", KeyType::strings, "", {}, "(none)", "the variant's case options (key.path=value)"},
};
constexpr SchemaSection spec_sections[] = {
    {"", "a calibration spec (arlequin calibrate)", spec_keys},
    {"verify[]", "a verification sample", verify_keys},
    {"targets[]", "an elastic target", elastic_target_keys},
    {"targets[].reference", "a published pair", reference_pair_keys},
    {"failure", "the failure calibration", failure_spec_keys},
    {"failure.targets[]", "a failure target", failure_target_keys},
};

// The cache of curve points next to the sample: {"entries": [{"signature", "points": [...]}]}.
class CurveCache {
 public:
  CurveCache(std::filesystem::path file, std::string signature) : file_(std::move(file)), signature_(std::move(signature)) {
    if (std::filesystem::exists(file_)) {
      try {
        document_ = read_json_file(file_);
      } catch (const InputError&) {
        std::fprintf(stderr, "calibrate: ignoring an unreadable cache %s\n", file_.string().c_str());
      }
    }
    if (!document_.is_object() || !document_.contains("entries")) document_ = Json::object(), document_["entries"] = Json::array();
  }
  std::optional<CurvePoint> find(double r_mu) const {
    for (const Json& p : points())
      if (p.at("r_mu").get<double>() == r_mu)
        return CurvePoint{r_mu, read_estimate(p.at("young_per_E_mu")), read_estimate(p.at("poisson")), "cache"};
    return std::nullopt;
  }
  void store(const CurvePoint& point) {
    Json p = Json::object();
    p["r_mu"] = point.r_mu;
    p["young_per_E_mu"] = estimate_json(point.young_per_E_mu);
    p["poisson"] = estimate_json(point.poisson);
    Json entries = Json::array();
    bool stored = false;
    for (const Json& e : document_.at("entries")) {
      Json copy = e;
      if (e.at("signature").get<std::string>() == signature_) copy["points"].push_back(p), stored = true;
      entries.push_back(copy);
    }
    if (!stored) {
      Json e = Json::object();
      e["signature"] = signature_;
      e["points"].push_back(p);
      entries.push_back(e);
    }
    document_["entries"] = entries;
    write_json_atomically(file_, document_);
  }
  const std::filesystem::path& file() const { return file_; }

 private:
  const Json& points() const {
    static const Json none = Json::array();
    for (const Json& e : document_.at("entries"))
      if (e.at("signature").get<std::string>() == signature_) return e.at("points");
    return none;
  }
  std::filesystem::path file_;
  std::string signature_;
  Json document_;
};

// Linear interpolation of the curve at the r_mu where nu_M = target (the first crossing).
std::optional<double> crossing(const std::vector<CurvePoint>& curve, double target) {
  for (std::size_t i = 0; i + 1 < curve.size(); ++i) {
    const double a = curve[i].poisson.value - target, b = curve[i + 1].poisson.value - target;
    if (a == 0.0) return curve[i].r_mu;
    if ((a < 0.0) != (b < 0.0)) return curve[i].r_mu + (curve[i + 1].r_mu - curve[i].r_mu) * a / (a - b);
  }
  if (!curve.empty() && curve.back().poisson.value == target) return curve.back().r_mu;
  return std::nullopt;
}

// The strengths' rounds as CSV and their table (markdown), in calibration.json's "strengths".
void write_strengths(const CalibrationResult& result, const std::filesystem::path& out_dir, std::string& md, Json& summary) {
  std::string csv = "material,criterion,round,threshold,E_mu,r_mu,failure_stress,failure_strain,target_stress,error,broken_at_peak,"
                    "broken_at_end,particles,wall_seconds\n";
  md += "\n| material | criterion | target sigma_M GPa | sigma_f_mu GPa | achieved sigma_M GPa | error | eps_M at failure | rounds | "
        "reference sigma_f_mu GPa | E_mu GPa | r_mu | DEs |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  Json strengths = Json::array();
  for (const CalibratedStrength& s : result.strengths) {
    const auto& t = s.target;
    for (std::size_t n = 0; n < s.rounds.size(); ++n) {
      const FailureTestResult& r = s.rounds[n].test;
      csv += t.name + "," + t.label() + "," + std::to_string(n) + format(",%.9g", s.rounds[n].threshold) + format(",%.9g", s.E_mu) +
             format(",%.9g", s.r_mu) + format(",%.9g", r.peak_stress) + format(",%.6g", r.strain_at_peak) + format(",%.9g", t.stress) +
             format(",%.4g", r.peak_stress / t.stress - 1.0) + "," + broken_text(r.broken_at_peak, "; ") +
             "," + broken_text(r.broken_at_end, "; ") + "," + std::to_string(r.particles) +
             format(",%.1f", r.wall_seconds) + "\n";
    }
    const auto& last = s.rounds.back();
    md += "| " + t.name + " | " + t.label() + " | " + format("%.4g", t.stress * 1e-9) + " | " + format("%.5g", last.threshold * 1e-9) +
          " | " + format("%.4g", last.test.peak_stress * 1e-9) + " | " + format("%+.2f %%", 100.0 * (last.test.peak_stress / t.stress - 1.0)) +
          " | " + format("%.4g", last.test.strain_at_peak) + " | " + std::to_string(s.rounds.size()) + (s.converged ? "" : " (not converged)") +
          " | " + (t.reference ? format("%.4g", *t.reference * 1e-9) : std::string("-")) + " | " + format("%.5g", s.E_mu * 1e-9) + " | " +
          format("%.4f", s.r_mu) + " | " + std::to_string(last.test.particles) + " |\n";
    Json j = Json::object();
    j["name"] = t.name;
    j["criterion"] = t.criterion;
    if (!t.variant.empty()) j["variant"] = t.variant;
    j["target_stress"] = t.stress;
    j["threshold"] = last.threshold;
    j["failure_stress"] = last.test.peak_stress;
    j["failure_strain"] = last.test.strain_at_peak;
    j["converged"] = s.converged;
    j["rounds"] = s.rounds.size();
    j["E_mu"] = s.E_mu;
    j["r_mu"] = s.r_mu;
    if (t.reference) j["reference_threshold"] = *t.reference;
    strengths.push_back(j);
  }
  write_file_atomically(out_dir / "strength.csv", csv);
  summary["strengths"] = strengths;
}

// The curve (CSV, PNG) and the pairs' table, in calibration.json's "pairs".
void write_elastic(const CalibrationSpec& spec, const CalibrationResult& result, const std::filesystem::path& out_dir, std::string& md,
                   Json& summary) {
  std::string csv = "r_mu,E_M_per_E_mu,E_M_per_E_mu_u,nu_M,nu_M_u,source\n";
  for (const auto& p : result.curve)
    csv += format("%.9g", p.r_mu) + "," + format("%.9g", p.young_per_E_mu.value) + "," + format("%.3g", p.young_per_E_mu.uncertainty) +
           "," + format("%.9g", p.poisson.value) + "," + format("%.3g", p.poisson.uncertainty) + "," + p.source + "\n";
  write_file_atomically(out_dir / "curve.csv", csv);
  PlotCurve chosen{.label = "calibrated (r_mu, nu_M)", .style = PlotCurve::Style::points};
  for (const auto& pair : result.pairs) chosen.x.push_back(pair.r_mu), chosen.y.push_back(pair.achieved.front().poisson.value);
  const auto curve_column = [](std::string column, std::string label, bool right) {
    return PlotCurve{.label = std::move(label), .style = PlotCurve::Style::line_points, .right_axis = right, .csv = "curve.csv",
                     .x_column = "r_mu", .y_column = std::move(column)};
  };
  write_plots(out_dir, {Plot{.file = "curve.png",
                             .title = "Calibration curve: tension tests at E_mu = 1 Pa",
                             .x_label = "r_mu",
                             .y_label = "nu_M",
                             .y2_label = "E_M / E_mu",
                             .curves = {curve_column("nu_M", "nu_M", false), curve_column("E_M_per_E_mu", "E_M / E_mu", true), chosen}}});

  md +=
      "| material | target E_M GPa | target nu_M | E_mu GPa | r_mu | sample | DEs | achieved E_M GPa | E_M error | achieved nu_M | "
      "nu_M error | reference E_mu GPa | reference r_mu |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  Json pairs = Json::array();
  for (const auto& p : result.pairs) {
    const auto& t = p.target;
    Json j = Json::object();
    j["name"] = t.name;
    j["target_E_M"] = t.young;
    j["target_nu_M"] = t.poisson;
    j["E_mu"] = p.E_mu;
    j["r_mu"] = p.r_mu;
    if (t.reference_E_mu) j["reference_E_mu"] = *t.reference_E_mu;
    if (t.reference_r_mu) j["reference_r_mu"] = *t.reference_r_mu;
    Json& achieved = j["achieved"];
    for (const Measurement& m : p.achieved) {
      md += "| " + t.name + " | " + format("%.4g", t.young * 1e-9) + " | " + format("%.3f", t.poisson) + " | " +
            format("%.5g", p.E_mu * 1e-9) + " | " + format("%.4f", p.r_mu) + " | " + m.sample + " | " + std::to_string(m.particles) +
            " | " + format("%.4g", m.young.value * 1e-9) + format(" ± %.2g", m.young.uncertainty * 1e-9) + " | " +
            format("%+.2f %%", 100.0 * (m.young.value / t.young - 1.0)) + " | " + format("%.4f", m.poisson.value) +
            format(" ± %.2g", m.poisson.uncertainty) + " | " + format("%+.4f", m.poisson.value - t.poisson) + " | " +
            (t.reference_E_mu ? format("%.5g", *t.reference_E_mu * 1e-9) : std::string("-")) + " | " +
            (t.reference_r_mu ? format("%.4g", *t.reference_r_mu) : std::string("-")) + " |\n";
      Json a = Json::object();
      a["sample"] = m.sample;
      a["particles"] = m.particles;
      a["E_M"] = estimate_json(m.young);
      a["nu_M"] = estimate_json(m.poisson);
      a["wall_seconds"] = m.wall_seconds;
      achieved.push_back(a);
    }
    pairs.push_back(j);
  }
  summary["plan"] = spec.plan.describe();
  summary["pairs"] = pairs;
}

void write_outputs(const CalibrationSpec& spec, const CalibrationResult& result, const std::filesystem::path& out_dir) {
  std::string md;
  Json summary = Json::object();
  summary["case_file"] = std::filesystem::absolute(spec.case_file).string();
  if (!result.curve.empty()) write_elastic(spec, result, out_dir, md, summary);
  if (!result.strengths.empty()) write_strengths(result, out_dir, md, summary);
  write_file_atomically(out_dir / "calibration.md", md);
  write_json_atomically(out_dir / "calibration.json", summary);
  std::printf("\n%s", md.c_str());
  if (!result.curve.empty()) std::printf("curve: %s\n", std::filesystem::absolute(out_dir / "curve.png").string().c_str());
}

}  // namespace

const Schema& calibration_schema() {
  static const Schema schema = [] {
    std::vector<SchemaSection> sections(std::begin(spec_sections), std::end(spec_sections));
    for (const auto& s : plan_schema()) sections.push_back(s);
    return Schema(std::move(sections));
  }();
  return schema;
}

CalibrationSpec CalibrationSpec::read(const std::filesystem::path& spec_file) {
  CaseFile file = CaseFile::load(spec_file, {}, &calibration_schema());
  CaseNode root = file.root();
  CalibrationSpec spec;
  spec.case_file = root.existing_file("case");
  spec.bond_origin = root.where("bond") + ": bond";
  spec.bond_key = root.string_or("bond", spec.bond_key);
  const bool elastic = root.has("targets") || !root.has("failure");
  if (elastic) {
    spec.radius_ratios = root.numbers("r_mu", Range::positive(), "1");
    std::sort(spec.radius_ratios.begin(), spec.radius_ratios.end());
    if (spec.radius_ratios.size() < 2) root.fail("r_mu", "expected at least two values to interpolate between");
    if (std::adjacent_find(spec.radius_ratios.begin(), spec.radius_ratios.end()) != spec.radius_ratios.end())
      root.fail("r_mu", "a grid value is given twice (each is a set of runs)");
  }
  if (root.has("axes")) {
    spec.axes.clear();
    for (const std::string& a : root.strings("axes")) {
      spec.axes.push_back(axis_index(root, "axes", a));
      if (std::count(spec.axes.begin(), spec.axes.end(), spec.axes.back()) > 1) root.fail("axes", "axis " + a + " is given twice");
    }
    if (spec.axes.empty()) root.fail("axes", "expected at least one axis");
  }
  spec.tolerance = root.number_or("tolerance", spec.tolerance, Range::positive(), "1");
  for (CaseNode v : root.list_or_empty("verify")) {
    spec.verify.push_back({v.string("name"), v.overrides("set")});
    v.finish();
  }
  spec.plan = QuasiStatic::read(root.child_if("quasi_static"));
  for (CaseNode t : elastic ? root.list("targets") : std::vector<CaseNode>{}) {
    CalibrationTarget target{t.string("name"), t.number("E", Range::positive(), "Pa"), t.number("nu", Range::open_between(-1.0, 0.5), "1"),
                             std::nullopt, std::nullopt};
    if (auto ref = t.child_if("reference")) {
      target.reference_E_mu = ref->number("E_mu", Range::positive(), "Pa");
      target.reference_r_mu = ref->number("r_mu", Range::positive(), "1");
      ref->finish();
    }
    t.finish();
    spec.targets.push_back(target);
  }
  if (auto failure = root.child_if("failure")) {
    if (failure->has("axis")) spec.failure_axis = axis_index(*failure, "axis", failure->string("axis"));
    spec.failure_tolerance = failure->number_or("tolerance", spec.failure_tolerance, Range::open_between(0.0, 1.0), "1");
    spec.failure_plan = FailurePlan::read(failure->child_if("test"));
    static constexpr std::string_view criteria[] = {"bbf", "rdef"};
    for (CaseNode t : failure->list("targets")) {
      FailureTarget target;
      target.name = t.string("name");
      target.criterion = t.choice("criterion", criteria);
      target.stress = t.number("stress", Range::positive(), "Pa");
      const auto elastic_target = std::find_if(spec.targets.begin(), spec.targets.end(),
                                               [&](const CalibrationTarget& e) { return e.name == target.name; });
      if (elastic_target == spec.targets.end()) {  // the elastic parameters are given
        target.young = t.number("E", Range::positive(), "Pa (no elastic target of this name to take it from)");
        target.E_mu = t.number("E_mu", Range::positive(), "Pa (no elastic target of this name to take it from)");
        target.r_mu = t.number("r_mu", Range::positive(), "1 (no elastic target of this name to take it from)");
      } else {
        for (const char* key : {"E", "E_mu", "r_mu"})
          if (t.has(key)) t.fail(key, "comes from the elastic target '" + target.name + "' calibrated in this spec");
      }
      if (t.has("initial")) target.initial = t.number("initial", Range::positive(), "Pa");
      if (t.has("reference")) target.reference = t.number("reference", Range::positive(), "Pa");
      if (!target.initial && !target.reference) t.fail("initial", "give a first guess (initial) or a published value (reference)");
      target.variant = t.string_or("variant", "");
      if (!std::all_of(target.variant.begin(), target.variant.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }))
        t.fail("variant", "expected a name of letters, digits and '_' (it names a folder), got '" + target.variant + "'");
      if (t.has("set")) {
        if (target.variant.empty()) t.fail("set", "name the variant these options make (variant: ...)");
        target.overrides = t.overrides("set");
      }
      t.finish();
      spec.failure_targets.push_back(target);
    }
    failure->finish();
  }
  if (spec.targets.empty() && spec.failure_targets.empty()) root.fail("targets", "expected elastic targets, failure targets, or both");
  root.finish();
  return spec;
}

// The curve and the elastic pairs (header, steps 1-3).
static void calibrate_elastic(const CalibrationSpec& spec, const SceneOptions& options, const std::filesystem::path& out_dir,
                       CalibrationResult& result) {
  // The cache key: the case as resolved with fixed placeholder bond values, and the test plan.
  SceneOptions probe_options = options;
  probe_options.overrides.push_back(spec.bond_override("E_mu", 1.0));
  probe_options.overrides.push_back(spec.bond_override("r_mu", 1.0));
  const Scene probe = build_scene(spec.case_file, probe_options);
  std::string signature = probe.resolved_case + "\n# plan: " + spec.plan.describe() + "\n# axes:";
  for (int a : spec.axes) signature.append(" ").append(axis_names[a]);
  CurveCache cache((probe.sample ? probe.sample_file.parent_path() : out_dir) / "calibration_cache.json", signature);
  std::printf("calibration of %s (%s); cache %s\n", spec.case_file.string().c_str(), spec.plan.describe().c_str(),
              cache.file().string().c_str());

  const auto point_at = [&](double r_mu, const char* source) {
    for (const auto& p : result.curve)
      if (p.r_mu == r_mu) return p;
    CurvePoint p;
    if (auto cached = cache.find(r_mu)) {
      p = *cached;
    } else {
      const Measurement m = measure(spec, options, 1.0, r_mu, out_dir / "curve" / ("r_" + format("%.6g", r_mu)));
      p = {r_mu, m.young, m.poisson, source};
      cache.store(p);
    }
    std::printf("  r_mu %.6g: E_M / E_mu = %.6g ± %.2g, nu_M = %.4f ± %.2g (%s)\n", r_mu, p.young_per_E_mu.value,
                p.young_per_E_mu.uncertainty, p.poisson.value, p.poisson.uncertainty, p.source.c_str());
    std::fflush(stdout);
    result.curve.push_back(p);
    std::sort(result.curve.begin(), result.curve.end(), [](const CurvePoint& a, const CurvePoint& b) { return a.r_mu < b.r_mu; });
    return p;
  };
  for (double r : spec.radius_ratios) point_at(r, "grid");

  std::vector<Measurement> per_unit;  // verification runs with E_M per unit E_mu
  for (const CalibrationTarget& target : spec.targets) {
    if (!crossing(result.curve, target.poisson)) {
      throw InputError("calibrate: target nu_M = " + format("%.4g", target.poisson) + " of '" + target.name +
                       "' is outside the curve's range (nu_M from " + format("%.4g", result.curve.front().poisson.value) +
                       " to " + format("%.4g", result.curve.back().poisson.value) + "); widen r_mu");
    }
    // Refine: measure at the interpolated r_mu until a point's nu_M is within the tolerance.
    const auto closest = [&] {
      return *std::min_element(result.curve.begin(), result.curve.end(), [&](const CurvePoint& a, const CurvePoint& b) {
        return std::abs(a.poisson.value - target.poisson) < std::abs(b.poisson.value - target.poisson);
      });
    };
    CurvePoint at = closest();
    for (int round = 0; round < 4 && std::abs(at.poisson.value - target.poisson) > spec.tolerance; ++round) {
      point_at(*crossing(result.curve, target.poisson), "refinement");
      at = closest();
    }
    CalibratedPair pair;
    pair.target = target;
    pair.r_mu = at.r_mu;
    pair.E_mu = target.young / at.young_per_E_mu.value;
    std::vector<CalibrationSpec::Variant> samples{{"calibration", {}}};
    samples.insert(samples.end(), spec.verify.begin(), spec.verify.end());
    for (const auto& sample : samples) {
      // Every pair is run on the calibration sample, which checks E_M proportional to E_mu;
      // on the other samples a pair with an r_mu measured before reuses that run, scaled.
      const auto known = std::find_if(per_unit.begin(), per_unit.end(), [&](const Measurement& u) {
        return u.sample == sample.name && u.r_mu == pair.r_mu;
      });
      Measurement m;
      if (sample.name != "calibration" && known != per_unit.end()) {
        m = *known;
        m.young = {known->young.value * pair.E_mu, known->young.uncertainty * pair.E_mu};
        m.wall_seconds = 0.0;
      } else {
        SceneOptions o = options;
        o.overrides.insert(o.overrides.end(), sample.overrides.begin(), sample.overrides.end());
        m = measure(spec, o, pair.E_mu, pair.r_mu, out_dir / target.name / sample.name);
        m.sample = sample.name;
        m.r_mu = pair.r_mu;
        Measurement unit = m;
        unit.young = {m.young.value / pair.E_mu, m.young.uncertainty / pair.E_mu};
        per_unit.push_back(unit);
      }
      std::printf("%s: E_mu = %.6g GPa, r_mu = %.5f on %s (%zu DEs): E_M = %.5g ± %.2g GPa (target %.5g), nu_M = %.4f ± %.2g "
                  "(target %.4f)\n",
                  target.name.c_str(), pair.E_mu * 1e-9, pair.r_mu, m.sample.c_str(), m.particles, m.young.value * 1e-9,
                  m.young.uncertainty * 1e-9, target.young * 1e-9, m.poisson.value, m.poisson.uncertainty, target.poisson);
      std::fflush(stdout);
      pair.achieved.push_back(m);
    }
    result.pairs.push_back(pair);
  }
}

// The case of a failure target's runs: its overrides, the bond pair (E_mu, r_mu) and strength s
// (BBF sigma_f, or the RDEF threshold).
static SceneOptions failure_target_options(const CalibrationSpec& spec, const SceneOptions& options, const FailureTarget& target,
                                           double E_mu, double r_mu, double s) {
  SceneOptions o = options;
  o.overrides.insert(o.overrides.end(), target.overrides.begin(), target.overrides.end());
  o.overrides.push_back(spec.bond_override("E_mu", E_mu));
  o.overrides.push_back(spec.bond_override("r_mu", r_mu));
  o.overrides.push_back(target.criterion == "bbf" ? spec.bond_override("sigma_f", s)
                                                  : Override("dem.failure.rdef.threshold", s, "calibrate: target " + target.name));
  return o;
}

// Before any run, the case is read with each verify sample's and each failure target's
// overrides as their runs will read it (the bond values not yet calibrated are placeholders), so
// that a bad override stops calibrate at once rather than after the r_mu grid.
static void check_every_variant(const CalibrationSpec& spec, const SceneOptions& options) {
  SceneOptions base = options;
  base.check_output_dir = false;
  for (const CalibrationSpec::Variant& sample : spec.verify) {
    SceneOptions o = base;
    o.overrides.insert(o.overrides.end(), sample.overrides.begin(), sample.overrides.end());
    o.overrides.push_back(spec.bond_override("E_mu", 1.0));
    o.overrides.push_back(spec.bond_override("r_mu", 1.0));
    build_scene(spec.case_file, o);
  }
  for (const FailureTarget& target : spec.failure_targets) {
    const double first_guess = target.initial ? *target.initial : *target.reference;
    const Scene probe = build_scene(spec.case_file, failure_target_options(spec, base, target, target.E_mu.value_or(1.0),
                                                                           target.r_mu.value_or(1.0), first_guess));
    if (target.criterion == "rdef")  // the RDEF threshold alone must decide
      for (const auto& set : probe.dem.bond_sets())
        if (set->has_strength())
          throw InputError(spec.case_file.string() + ": bond set '" + set->name + "' has a BBF strength (sigma_f); the RDEF target '" +
                           target.name + "' needs a case without one");
  }
}

// The strengths (header): tests to failure with s_{n+1} = s_n target / sigma_n.
static void calibrate_strengths(const CalibrationSpec& spec, const SceneOptions& options, const std::filesystem::path& out_dir,
                         CalibrationResult& result) {
  for (const FailureTarget& target : spec.failure_targets) {
    CalibratedStrength strength;
    strength.target = target;
    const auto pair = std::find_if(result.pairs.begin(), result.pairs.end(),
                                   [&](const CalibratedPair& p) { return p.target.name == target.name; });
    strength.E_mu = pair != result.pairs.end() ? pair->E_mu : *target.E_mu;
    strength.r_mu = pair != result.pairs.end() ? pair->r_mu : *target.r_mu;
    strength.young = pair != result.pairs.end() ? pair->target.young : *target.young;
    FailurePlan plan = spec.failure_plan;
    plan.expected_strain = target.stress / strength.young;
    LoadCase load;
    load.name = "tension_" + std::string(axis_names[spec.failure_axis]);
    load.face = load.direction = spec.failure_axis;
    double threshold = target.initial ? *target.initial : *target.reference;
    for (int round = 0; round < 5; ++round) {
      SceneOptions o = failure_target_options(spec, options, target, strength.E_mu, strength.r_mu, threshold);
      o.out_dir = out_dir / target.name / ("failure_" + target.label()) / ("round_" + std::to_string(round));
      const FailureTestResult test = run_failure_test(spec.case_file, o, load, plan);
      strength.rounds.push_back({threshold, test});
      const double error = test.peak_stress / target.stress - 1.0;
      std::printf("%s %s round %d: threshold %.6g GPa -> sigma_M = %.5g GPa at strain %.4g (target %.5g GPa, %+.2f %%), %.0f s\n",
                  target.name.c_str(), target.label().c_str(), round, threshold * 1e-9, test.peak_stress * 1e-9,
                  test.strain_at_peak, target.stress * 1e-9, 100.0 * error, test.wall_seconds);
      std::fflush(stdout);
      if (!test.broke)
        throw RunError("calibrate: " + target.name + " (" + target.label() + ") did not break by strain " +
                       format("%.4g", test.final_strain) + "; raise failure.test.max_strain_factor or lower the first guess");
      if (std::abs(error) <= spec.failure_tolerance) {
        strength.converged = true;
        break;
      }
      threshold *= target.stress / test.peak_stress;
    }
    result.strengths.push_back(strength);
  }
}

CalibrationResult calibrate(const CalibrationSpec& spec, const SceneOptions& options, const std::filesystem::path& out_dir) {
  check_every_variant(spec, options);
  CalibrationResult result;
  if (!spec.targets.empty()) calibrate_elastic(spec, options, out_dir, result);
  calibrate_strengths(spec, options, out_dir, result);
  write_outputs(spec, result, out_dir);
  return result;
}


}  // namespace arlequin::app
