// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/virtual_tests.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>

#include "app/micromechanics.hpp"
#include "app/runner.hpp"
#include "app/text.hpp"
#include "common/atomic_file.hpp"
#include "common/case_file.hpp"
#include "common/schema.hpp"
#include "common/error.hpp"
#include "common/json.hpp"

namespace arlequin::app {
namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// ---- The keys of a virtual-test spec (common/schema.hpp) --------------------------------

constexpr KeyDoc suite_keys[] = {
    {"case", KeyType::file, "", {}, "", "the case whose sample is tested (its loads are replaced by the tests')"},
    {"samples", KeyType::list, "", {}, "(one: the case's)", "samples to test, each the case with overrides"},
    {"tests", KeyType::list, "", {}, "", "the load cases"},
    {"quasi_static", KeyType::section, "", {}, "(defaults)", "how an elastic test loads (quasi_static plan)"},
    {"failure", KeyType::section, "", {}, "(none)", "the tests go to failure, so loaded (failure plan)"},
    {"composite", KeyType::section, "", {}, "(none)", "a UD composite's phases: the elastic suite's theory row"},
};
constexpr KeyDoc sample_variant_keys[] = {
    {"name", KeyType::string, "", {}, "", "its folder name"},
    {"set", KeyType::strings, "", {}, "[]", "overrides of the case (key.path=value)"},
};
constexpr KeyDoc load_case_keys[] = {
    {"name", KeyType::string, "", {}, "", "its folder name"},
    {"tension", KeyType::string, "", {}, "(none)", "the tension axis, x | y | z (or shear)"},
    {"shear", KeyType::strings, "", {}, "(none)", "[face normal, direction] of a shear test"},
    {"modulus_estimate", KeyType::number, "Pa", Range::positive(), "(none)", "expected modulus, to size the loading"},
    {"set", KeyType::strings, "", {}, "[]", "overrides of the case for this test"},
    {"reference", KeyType::section, "", {}, "(none)", "a test to failure: the published ranges it is judged against"},
};
constexpr KeyDoc failure_reference_keys[] = {
    {"name", KeyType::string, "", {}, "", "where the ranges come from (e.g. seed Table 4 (#1-#3))"},
    {"stress", KeyType::numbers, "Pa", Range::non_negative(), "", "failure stress range [low, high]"},
    {"strain", KeyType::numbers, "1", Range::non_negative(), "", "failure strain range [low, high]"},
    {"broken", KeyType::section, "", {}, "(none)", "broken-bond percentage range per bond set"},
};
constexpr KeyDoc broken_range_keys[] = {
    {"<name>", KeyType::numbers, "%", Range::non_negative(), "", "[low, high] broken bonds of that set, %"},
};
constexpr KeyDoc composite_keys[] = {
    {"fibre", KeyType::section, "", {}, "", "the fibre's isotropic constants"},
    {"matrix", KeyType::section, "", {}, "", "the matrix's isotropic constants"},
    {"fibre_fraction", KeyType::number, "1", Range::between(0, 1), "", "fibre volume fraction"},
    {"references", KeyType::list, "", {}, "(none)", "published rows to print beside ours"},
};
constexpr KeyDoc phase_keys[] = {
    {"E", KeyType::number, "Pa", Range::positive(), "", "Young's modulus"},
    {"nu", KeyType::number, "1", Range::open_between(-1, 0.5), "", "Poisson's ratio"},
};
constexpr KeyDoc reference_row_keys[] = {
    {"name", KeyType::string, "", {}, "", "the row's source"},
    {"E_L", KeyType::number, "Pa", {}, "(none)", "longitudinal modulus"},
    {"E_T", KeyType::number, "Pa", {}, "(none)", "transverse modulus"},
    {"nu_LT", KeyType::number, "1", {}, "(none)", "Poisson's ratio, axial load"},
    {"nu_TT", KeyType::number, "1", {}, "(none)", "Poisson's ratio in the transverse plane"},
    {"G_LT", KeyType::number, "Pa", {}, "(none)", "axial shear modulus"},
    {"G_TT", KeyType::number, "Pa", {}, "(none)", "transverse shear modulus"},
};
constexpr KeyDoc quasi_static_keys[] = {
    {"strain", KeyType::number, "1", Range::open_between(0, 0.05), "2e-04", "final normal strain (tension) or shear angle"},
    {"ramp", KeyType::number, "transit times", Range::positive(), "3", "time over which the strain is applied"},
    {"plateau", KeyType::number, "transit times", Range::positive(), "3", "time it is held"},
    {"damping", KeyType::number, "1", Range::non_negative(), "0.5", "fraction of the fundamental mode's critical damping"},
    {"average", KeyType::number, "1", Range::open_between(0, 1), "0.5", "the last fraction of the plateau averaged"},
    {"rows_per_transit", KeyType::number, "1", Range::at_least(2), "20", "series rows per transit time"},
};
constexpr KeyDoc failure_plan_keys[] = {
    {"expected_strain", KeyType::number, "1", Range::open_between(0, 0.5), "0.01", "expected failure strain, sizes the pull"},
    {"transits", KeyType::number, "transit times", Range::positive(), "25", "time to reach the expected strain"},
    {"max_strain_factor", KeyType::number, "1", Range::at_least(1), "2", "the run ends at this multiple of it"},
    {"stop_below", KeyType::number, "1", Range::open_between(0, 1), "0.5", "stop once the stress falls below this fraction of its peak"},
    {"stop_after", KeyType::number, "transit times", Range::non_negative(), "0", "... and this long after the peak"},
    {"damping", KeyType::number, "1", Range::non_negative(), "0.05", "fraction of the fundamental mode's critical damping"},
    {"rise", KeyType::number, "transit times", Range::non_negative(), "1", "time over which the pull speed rises"},
    {"rows_per_transit", KeyType::number, "1", Range::at_least(2), "20", "series rows per transit time"},
    {"frames", KeyType::number, "1", Range::between(0, 10000), "0", "field frames over the run (particles, bonds)"},
};
constexpr SchemaSection plan_sections[] = {
    {"quasi_static plan", "an elastic test's loading (quasi_static:)", quasi_static_keys},
    {"failure plan", "a test to failure's loading (failure: of a suite, failure.test: of a calibration)", failure_plan_keys},
};
constexpr SchemaSection suite_sections[] = {
    {"", "a virtual-test spec (arlequin virtual-test)", suite_keys},
    {"samples[]", "a sample variant", sample_variant_keys},
    {"tests[]", "a load case", load_case_keys},
    {"tests[].reference", "published failure ranges", failure_reference_keys},
    {"tests[].reference.broken", "broken-bond ranges by bond set", broken_range_keys},
    {"composite", "a UD composite", composite_keys},
    {"composite.fibre", "fibre", phase_keys},
    {"composite.matrix", "matrix", phase_keys},
    {"composite.references[]", "a published row", reference_row_keys},
};

const Schema& suite_schema() {
  static const Schema schema = [] {
    std::vector<SchemaSection> sections(std::begin(suite_sections), std::end(suite_sections));
    sections.insert(sections.end(), std::begin(plan_sections), std::end(plan_sections));
    return Schema(std::move(sections));
  }();
  return schema;
}

// The shortest text that reads back as the same double.
std::string shortest(double value) {
  char buffer[32];
  return std::string(buffer, std::to_chars(buffer, buffer + sizeof buffer, value).ptr);
}

// The columns of a series.csv written by the runner.
struct SeriesTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;

  static SeriesTable read(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) throw RunError("cannot read " + path.string());
    SeriesTable t;
    std::string line, cell;
    std::getline(in, line);
    for (std::stringstream header(line); std::getline(header, cell, ',');) t.columns.push_back(cell);
    while (std::getline(in, line)) {
      std::vector<double>& row = t.rows.emplace_back();
      for (std::stringstream values(line); std::getline(values, cell, ',');) row.push_back(std::strtod(cell.c_str(), nullptr));
      if (row.size() != t.columns.size()) throw RunError(path.string() + ": a row has the wrong number of values");
    }
    return t;
  }
  std::size_t column(const std::string& name) const {
    const auto it = std::find(columns.begin(), columns.end(), name);
    if (it == columns.end()) throw RunError("series.csv has no column '" + name + "'");
    return std::size_t(it - columns.begin());
  }
};

// Average over the window with uncertainty sqrt(sd^2 + drift^2) (header).
Estimate window_average(const std::vector<double>& v) {
  const auto mean = [](auto begin, auto end) {
    double s = 0.0;
    for (auto it = begin; it != end; ++it) s += *it;
    return s / double(end - begin);
  };
  const std::size_t n = v.size(), half = n / 2;
  const double m = mean(v.begin(), v.end());
  double var = 0.0;
  for (double x : v) var += (x - m) * (x - m);
  const double sd = std::sqrt(var / double(n - 1));
  const double drift = mean(v.begin() + half, v.end()) - mean(v.begin(), v.begin() + half);
  return {m, std::hypot(sd, drift)};
}

// a / b with relative uncertainties added in quadrature.
Estimate ratio(const Estimate& a, const Estimate& b) {
  const double r = a.value / b.value;
  return {r, std::abs(r) * std::hypot(a.uncertainty / a.value, b.uncertainty / b.value)};
}

// The sample as the tests see it: the DEs' bounding box, their mean radius and mean density.
struct SampleGeometry {
  Vec3 lower, upper;
  double mean_radius = 0.0;
  double density = 0.0;  // kg/m^3, DE mass / box volume

  explicit SampleGeometry(const dem::ParticleSet& p) {
    if (p.size() == 0) throw InputError("a virtual test needs a DEM sample (dem section)");
    lower = upper = p.position[0];
    double mass = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        lower[k] = std::min(lower[k], p.position[i][k] - p.radius[i]);
        upper[k] = std::max(upper[k], p.position[i][k] + p.radius[i]);
      }
      mean_radius += p.radius[i];
      mass += p.mass(i);
    }
    mean_radius /= double(p.size());
    density = mass / volume();
  }
  double length(int k) const { return upper[k] - lower[k]; }
  double volume() const { return length(0) * length(1) * length(2); }
  double area(int normal) const { return volume() / length(normal); }
};

// Affine modulus (header): bond energy under the test's homogeneous strain on every centre.
double affine_modulus(const dem::DemModel& model, const SampleGeometry& g, const LoadCase& load) {
  constexpr double strain = 1e-6;
  dem::ParticleSet p = model.particles;
  for (std::size_t i = 0; i < p.size(); ++i) p.position[i][load.direction] += strain * (p.position[i][load.face] - g.lower[load.face]);
  double energy = 0.0;
  for (const auto& set : model.bond_sets()) energy += set->energy(p);
  return 2.0 * energy / (strain * strain * g.volume());
}

std::string group_name(int axis, bool upper) { return "face_" + std::string(axis_names[axis]) + (upper ? "max" : "min"); }
std::string displacement_column(int axis, bool upper) { return "u_" + group_name(axis, upper).substr(5); }

// The origin that messages about a test's generated sections name.
std::string generated_by(const LoadCase& load) { return "test " + load.name + " (generated)"; }

CaseValue map(std::vector<std::pair<std::string, CaseValue>> entries) { return CaseValue::map(std::move(entries)); }

// The slab of DE centres within one mean diameter of a face, as a group with a box region.
CaseValue slab_group(const SampleGeometry& g, int axis, bool upper) {
  const double t = 2.0 * g.mean_radius;
  Vec3 lo, hi;
  for (int k = 0; k < 3; ++k) {
    lo[k] = g.lower[k] - g.length(k), hi[k] = g.upper[k] + g.length(k);  // across the sample, with margin
    if (k == axis && upper) lo[k] = g.upper[k] - t;
    if (k == axis && !upper) hi[k] = g.lower[k] + t;
  }
  return map({{"name", group_name(axis, upper)}, {"region", map({{"box", CaseValue::list({lo, hi})}})}});
}

// The axes whose faces get slabs: the loaded one, and for tension the two lateral ones.
std::vector<int> slab_axes(const LoadCase& load) {
  if (load.shear()) return {load.face};
  std::vector<int> axes{load.face};
  for (int k = 0; k < 3; ++k)
    if (k != load.face) axes.push_back(k);
  return axes;
}

// The slabs of the test's faces as groups, displacement sensors on every slab (the loaded
// component on the loaded faces, the normal one on the others), force sensors on both
// loaded faces; no checks of the case's own.
std::vector<Override> gauge_overrides(const SampleGeometry& g, const LoadCase& load) {
  std::vector<CaseValue> groups, sensors;
  for (int k : slab_axes(load)) {
    for (bool upper : {false, true}) {
      groups.push_back(slab_group(g, k, upper));
      const int component = k == load.face ? load.direction : k;
      sensors.push_back(map({{"name", displacement_column(k, upper)},
                             {"type", "displacement"},
                             {"group", group_name(k, upper)},
                             {"component", std::string(axis_names[component])}}));
    }
  }
  for (bool upper : {false, true})
    sensors.push_back(map({{"name", upper ? "F_moved" : "F_held"},
                           {"type", "force"},
                           {"group", group_name(load.face, upper)},
                           {"component", std::string(axis_names[load.direction])}}));
  const std::string origin = generated_by(load);
  return {Override("groups", CaseValue::list(groups), origin), Override("sensors", CaseValue::list(sensors), origin),
          Override("checks", CaseValue::list({}), origin)};
}

// The generated sections of one quasi-static test (header).
std::vector<Override> test_overrides(const SampleGeometry& g, const LoadCase& load, const QuasiStatic& plan, double transit,
                                     double damping) {
  const CaseValue axis = CaseValue::list({std::string(axis_names[load.face])});
  Vec3 motion{};
  motion[load.direction] = plan.strain * g.length(load.face);
  const double ramp = plan.ramp * transit;
  const CaseValue boundary =
      load.shear()
          ? CaseValue::list({map({{"group", group_name(load.face, false)}, {"type", "fixed"}}),
                             map({{"group", group_name(load.face, true)},
                                  {"type", "displacement"},
                                  {"value", motion},
                                  {"ramp", ramp},
                                  {"rotation", "fixed"}})})
          : CaseValue::list({map({{"group", group_name(load.face, false)}, {"type", "velocity"}, {"value", Vec3{}}, {"components", axis}}),
                             map({{"group", group_name(load.face, true)},
                                  {"type", "displacement"},
                                  {"value", motion},
                                  {"ramp", ramp},
                                  {"components", axis}})});
  const std::string origin = generated_by(load);
  std::vector<Override> o = gauge_overrides(g, load);
  o.insert(o.end(), {Override("boundary", boundary, origin), Override("time.end", (plan.ramp + plan.plateau) * transit, origin),
                     Override("output.every", transit / plan.rows_per_transit, origin), Override("dem.damping", damping, origin)});
  return o;
}

// Mean reference coordinate along `axis` of the DEs of a face slab (those slab_group selects).
double centroid(const dem::ParticleSet& p, const SampleGeometry& g, int axis, bool upper) {
  const double t = 2.0 * g.mean_radius;
  double s = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.reference[i][axis];
    if (upper ? x >= g.upper[axis] - t : x <= g.lower[axis] + t) s += x, ++n;
  }
  return s / double(n);
}
double gauge_length(const dem::ParticleSet& p, const SampleGeometry& g, int axis) {
  return centroid(p, g, axis, true) - centroid(p, g, axis, false);
}

Json estimate_json(const Estimate& e) {
  Json j = Json::object();
  j["value"] = e.value;
  j["uncertainty"] = e.uncertainty;
  return j;
}

// ---- Suites ------------------------------------------------------------------------------

struct SampleVariant {
  std::string name;
  std::vector<Override> overrides;

  bool selected(const std::vector<std::string>& only_samples) const {  // by --sample (all when none is given)
    return only_samples.empty() || std::find(only_samples.begin(), only_samples.end(), name) != only_samples.end();
  }
  // The options of a test's run on this sample: the caller's, then this sample's overrides; its
  // outputs in out_dir/<sample>/<test>.
  SceneOptions options_for(const SceneOptions& caller, const std::string& test, const std::filesystem::path& out_dir) const {
    SceneOptions o = caller;
    o.overrides.insert(o.overrides.end(), overrides.begin(), overrides.end());
    o.out_dir = out_dir / name / test;
    return o;
  }
};

// The engineering constants of a unidirectional composite, in table order.
constexpr const char* constant_keys[] = {"E_L", "E_T", "nu_LT", "nu_TT", "G_LT", "G_TT"};
using Constants = std::array<double, 6>;
bool is_poisson(std::size_t c) { return c == 2 || c == 3; }

// A unidirectional composite (docs/validation.md R3): its phases, the closed forms and reference rows.
struct CompositeSpec {
  IsotropicPhase fibre{}, matrix{};
  double fraction = 0.0;
  std::vector<std::pair<std::string, Constants>> references;  // NaN: not given

  static IsotropicPhase read_phase(CaseNode node) {
    IsotropicPhase phase{node.number("E", Range::positive(), "Pa"), node.number("nu", Range::open_between(-1.0, 0.5), "1")};
    node.finish();
    return phase;
  }
  static CompositeSpec read(CaseNode node) {
    CompositeSpec c;
    c.fibre = read_phase(node.child("fibre"));
    c.matrix = read_phase(node.child("matrix"));
    c.fraction = node.number("fibre_fraction", Range::between(0.0, 1.0), "1");
    for (CaseNode row : node.list_or_empty("references")) {
      Constants values;
      for (std::size_t k = 0; k < values.size(); ++k)
        values[k] = row.has(constant_keys[k]) ? row.number(constant_keys[k], Range::any(), is_poisson(k) ? "1" : "Pa") : nan;
      c.references.emplace_back(row.string("name"), values);
      row.finish();
    }
    node.finish();
    return c;
  }
  Constants theory() const {
    const UnidirectionalModuli m = unidirectional_moduli(fibre, matrix, fraction);
    return {m.E_L, m.E_T, m.nu_LT, m.nu_TT, m.G_LT, m.G_TT};
  }
};

// The four tests of a composite suite, checked against their roles (run_virtual_test_suite).
struct CompositeTests {
  std::size_t L, T, LT, TT;  // indices into the suite's tests
  int transverse_prime;      // the axis that is neither L's nor T's

  static CompositeTests find(CaseNode& node, const std::vector<LoadCase>& tests) {
    const auto index = [&](const char* name) {
      for (std::size_t i = 0; i < tests.size(); ++i)
        if (tests[i].name == name) return i;
      node.fail("composite", std::string("a composite suite needs a test named ") + name);
    };
    CompositeTests c{index("L"), index("T"), index("LT"), index("TT"), 0};
    const LoadCase &l = tests[c.L], &t = tests[c.T], &lt = tests[c.LT], &tt = tests[c.TT];
    if (l.shear() || t.shear() || l.face == t.face) node.fail("composite", "L and T must be tensions along two different axes");
    c.transverse_prime = 3 - l.face - t.face;
    const auto spans = [](const LoadCase& s, int a, int b) {
      return s.shear() && ((s.face == a && s.direction == b) || (s.face == b && s.direction == a));
    };
    if (!spans(lt, l.face, t.face)) node.fail("composite", "LT must be a shear in the plane of L's and T's axes");
    if (!spans(tt, t.face, c.transverse_prime)) node.fail("composite", "TT must be a shear in the plane of T's axis and the third one");
    return c;
  }
  // E_L, E_T, nu_LT (mean over both transverse axes), nu_TT', G_LT, G_TT'.
  std::array<Estimate, 6> constants(const std::vector<VirtualTestResult>& r) const {
    const auto& lateral = r[L].poisson;
    const int a = (r[L].load.face + 1) % 3, b = (r[L].load.face + 2) % 3;
    const double mean = 0.5 * (lateral[a].value + lateral[b].value);
    const Estimate nu_lt{mean, std::hypot(0.5 * std::hypot(lateral[a].uncertainty, lateral[b].uncertainty),
                                          0.5 * (lateral[a].value - lateral[b].value))};
    return {r[L].modulus, r[T].modulus, nu_lt, r[T].poisson[transverse_prime], r[LT].modulus, r[TT].modulus};
  }
  // The closed form's modulus behind test i's time scale, if it is one of the four. L takes
  // E_T too: its lateral (Poisson) contraction moves at transverse wave speeds, far slower
  // than its axial waves.
  std::optional<double> estimate(std::size_t i, const Constants& theory) const {
    if (i == L || i == T) return theory[1];
    if (i == LT) return theory[4];
    if (i == TT) return theory[5];
    return std::nullopt;
  }
};

// Constant c's value for tables: moduli in GPa, Poisson ratios plain; uncertainties to 2 digits.
std::string table_value(std::size_t c, double v, bool uncertainty = false) {
  if (std::isnan(v)) return "-";
  if (uncertainty) return is_poisson(c) ? format("%.1g", v) : format("%.2g", v * 1e-9);
  return is_poisson(c) ? format("%.3f", v) : format("%.4g", v * 1e-9);
}

std::string composite_tables(const CompositeSpec& spec, const std::vector<std::string>& samples,
                             const std::vector<std::array<Estimate, 6>>& measured, const std::vector<std::size_t>& particles,
                             const std::vector<std::array<double, 4>>& walls) {
  std::string md = "| source | DEs | E_L GPa | E_T GPa | nu_LT | nu_TT' | G_LT GPa | G_TT' GPa |\n|---|---|---|---|---|---|---|---|\n";
  std::vector<std::pair<std::string, Constants>> rows{{"theory (ROM; Hashin K23; Halpin-Tsai)", spec.theory()}};
  rows.insert(rows.end(), spec.references.begin(), spec.references.end());
  for (const auto& [name, values] : rows) {
    md += "| " + name + " | |";
    for (std::size_t c = 0; c < 6; ++c) md.append(" ").append(table_value(c, values[c])).append(" |");
    md += "\n";
  }
  for (std::size_t s = 0; s < samples.size(); ++s) {
    md += "| DEM " + samples[s] + " | " + std::to_string(particles[s]) + " |";
    for (std::size_t c = 0; c < 6; ++c)
      md.append(" ").append(table_value(c, measured[s][c].value)).append(" ± ").append(table_value(c, measured[s][c].uncertainty, true)).append(" |");
    md += "\n";
  }
  md += "\nDifferences of the DEM rows: moduli relative, (DEM - reference) / reference; Poisson ratios absolute, DEM - reference.\n\n"
        "| sample | against | E_L | E_T | nu_LT | nu_TT' | G_LT | G_TT' |\n|---|---|---|---|---|---|---|---|\n";
  for (std::size_t s = 0; s < samples.size(); ++s) {
    for (const auto& [name, values] : rows) {
      md += "| " + samples[s] + " | " + name + " |";
      for (std::size_t c = 0; c < 6; ++c) {
        const double v = measured[s][c].value;
        md += std::isnan(values[c]) ? std::string(" - |")
              : is_poisson(c)       ? format(" %+.3f |", v - values[c])
                                    : format(" %+.1f %% |", 100.0 * (v - values[c]) / values[c]);
      }
      md += "\n";
    }
  }
  md += "\nWall time per test, s (scene build + run):\n\n| sample | DEs | L | T | LT | TT' | total |\n|---|---|---|---|---|---|---|\n";
  for (std::size_t s = 0; s < samples.size(); ++s) {
    const auto& w = walls[s];
    md += "| " + samples[s] + " | " + std::to_string(particles[s]) + " |";
    for (double x : w) md += format(" %.0f |", x);
    md += format(" %.0f |\n", w[0] + w[1] + w[2] + w[3]);
  }
  return md;
}

std::string csv_header() {
  return "sample,test,load,particles,bonds,steps,dt,transit_time,modulus_estimate,damping,stress,stress_u,strain,strain_u,"
         "modulus,modulus_u,poisson_x,poisson_x_u,poisson_y,poisson_y_u,poisson_z,poisson_z_u,force_imbalance,"
         "kinetic_to_bond,wall_seconds,status\n";
}

std::string csv_row(const std::string& sample, const VirtualTestResult& r, const std::string& status) {
  std::string row = sample + "," + r.load.name + "," + r.load.describe() + "," + std::to_string(r.particles) + "," +
                    std::to_string(r.bonds) + "," + std::to_string(r.steps);
  for (double v : {r.dt, r.transit_time, r.modulus_used, r.damping, r.stress.value, r.stress.uncertainty, r.strain.value,
                   r.strain.uncertainty, r.modulus.value, r.modulus.uncertainty, r.poisson[0].value, r.poisson[0].uncertainty,
                   r.poisson[1].value, r.poisson[1].uncertainty, r.poisson[2].value, r.poisson[2].uncertainty,
                   r.force_imbalance, r.kinetic_to_bond, r.wall_seconds})
    row.append(",").append(format("%.9g", v));
  return row + "," + status + "\n";
}

// The `name` of a test or a sample: it names the folder of its results.
std::string folder_name(CaseNode& node) {
  std::string name = node.string("name");
  if (name.empty() || name.find_first_of("/\\ ,") != std::string::npos)
    node.fail("name", "expected a non-empty name without spaces, commas or slashes");
  return name;
}

// The last of `items` (tests or samples, read from `node`) must not share its folder name.
template <class Named>
void require_new_name(const CaseNode& node, const std::vector<Named>& items, const char* kind) {
  for (std::size_t k = 0; k + 1 < items.size(); ++k)
    if (items[k].name == items.back().name) node.fail("name", std::string(kind) + " '" + items.back().name + "' is defined twice");
}

}  // namespace

std::span<const SchemaSection> plan_schema() { return plan_sections; }
const Schema& virtual_test_schema() { return suite_schema(); }

std::string LoadCase::describe() const {
  return shear() ? "shear of the " + std::string(axis_names[face]) + " faces along " + std::string(axis_names[direction])
                 : "tension along " + std::string(axis_names[face]);
}

LoadCase LoadCase::read(CaseNode& node) {
  LoadCase load;
  load.name = folder_name(node);
  if (node.has("tension") == node.has("shear"))
    node.fail("tension", "give exactly one of tension: axis or shear: [face, direction]" + node.misspelling_hint("tension") +
                             node.misspelling_hint("shear"));
  if (node.has("tension")) {
    load.face = load.direction = axis_index(node, "tension", node.string("tension"));
  } else {
    const auto axes = node.strings("shear");
    if (axes.size() != 2) node.fail("shear", "expected [face normal, direction], e.g. [z, x]");
    load.face = axis_index(node, "shear", axes[0]);
    load.direction = axis_index(node, "shear", axes[1]);
    if (load.face == load.direction) node.fail("shear", "the direction must differ from the face normal (that is tension)");
  }
  if (node.has("modulus_estimate")) load.modulus_estimate = node.number("modulus_estimate", Range::positive(), "Pa");
  load.overrides = node.overrides_or_empty("set");
  return load;
}

QuasiStatic QuasiStatic::read(std::optional<CaseNode> node) {
  QuasiStatic q;
  if (!node) return q;
  node->add_schema_section("quasi_static plan");
  q.strain = node->number_or("strain", q.strain, Range::open_between(0.0, 0.05), "1");
  q.ramp = node->number_or("ramp", q.ramp, Range::positive(), "transit times");
  q.plateau = node->number_or("plateau", q.plateau, Range::positive(), "transit times");
  q.damping = node->number_or("damping", q.damping, Range::non_negative(), "1");
  q.average = node->number_or("average", q.average, Range::open_between(0.0, 1.0), "1");
  q.rows_per_transit = node->number_or("rows_per_transit", q.rows_per_transit, Range::at_least(2.0), "1");
  node->finish();
  return q;
}

std::string QuasiStatic::describe() const {
  return "strain " + shortest(strain) + ", ramp " + shortest(ramp) + " T, plateau " + shortest(plateau) + " T, damping " +
         shortest(damping) + " of critical, average over the last " + shortest(average) + " of the plateau, " +
         shortest(rows_per_transit) + " rows per T";
}

namespace {

std::size_t bond_count(const dem::DemModel& model) {
  std::size_t n = 0;
  for (const auto& set : model.bond_sets()) n += set->size();
  return n;
}

// What every test needs before its run: a probe of the case (with the test's own overrides)
// gives the sample's extent, the modulus behind the time scale and the damping rate.
struct TestSetup {
  SceneOptions options;  // the caller's, then the test's own overrides
  Scene probe;
  SampleGeometry geometry;
  double modulus = 0.0;  // Pa
  bool affine = false;
  double transit = 0.0;  // s
  double damping = 0.0;  // 1/s

  TestSetup(const std::filesystem::path& case_file, const SceneOptions& caller, const LoadCase& load, double zeta)
      : options(with_test_overrides(caller, load)), probe(build_scene(case_file, options)), geometry(probe.dem.particles) {
    if (options.out_dir.empty()) throw InputError("virtual test " + load.name + ": no output folder given");
    affine = !load.modulus_estimate;
    modulus = load.modulus_estimate ? *load.modulus_estimate : affine_modulus(probe.dem, geometry, load);
    if (!(modulus > 0.0)) throw InputError(case_file.string() + ": the sample has no bond stiffness to test");
    transit = geometry.length(load.face) / std::sqrt(modulus / geometry.density);
    damping = zeta * 2.0 * std::numbers::pi / transit;
  }
  static SceneOptions with_test_overrides(SceneOptions o, const LoadCase& load) {
    o.overrides.insert(o.overrides.end(), load.overrides.begin(), load.overrides.end());
    return o;
  }
  // test.json: the fields every test records (the caller adds its measures), then the run's.
  Json record(const std::filesystem::path& case_file, const std::string& load, const std::string& plan) const {
    Json j = Json::object();
    j["case_file"] = std::filesystem::absolute(case_file).string();
    j["load"] = load;
    j["plan"] = plan;
    j["transit_time"] = transit;
    j["modulus_estimate"] = modulus;
    j["modulus_estimate_source"] = affine ? "affine (bond energy under homogeneous strain)" : "given";
    j["damping"] = damping;
    return j;
  }
  static void write_record(Json& j, const Scene& scene, long steps, double wall_seconds) {
    j["particles"] = scene.dem.particles.size();
    j["bonds"] = bond_count(scene.dem);
    j["steps"] = steps;
    j["dt"] = scene.dt;
    j["wall_seconds"] = wall_seconds;
    write_json_atomically(scene.output.dir / "test.json", j);
  }
  // Builds and runs the test scene: the probe's options plus `generated`.
  std::pair<Scene, RunResult> run(const std::filesystem::path& case_file, const std::vector<Override>& generated,
                                  const RunOptions& run_options = {}) const {
    SceneOptions o = options;
    o.overrides.insert(o.overrides.end(), generated.begin(), generated.end());
    Scene scene = build_scene(case_file, o);
    RunResult result = run_scene(scene, run_options);
    return {std::move(scene), std::move(result)};
  }
};

}  // namespace

VirtualTestResult run_virtual_test(const std::filesystem::path& case_file, const SceneOptions& options,
                                   const LoadCase& load, const QuasiStatic& plan) {
  const auto t0 = std::chrono::steady_clock::now();
  const TestSetup setup(case_file, options, load, plan.damping);
  const SampleGeometry& g = setup.geometry;
  VirtualTestResult r;
  r.load = load;
  r.out_dir = options.out_dir;
  r.affine_estimate = setup.affine;
  r.modulus_used = setup.modulus;
  r.transit_time = setup.transit;
  r.damping = setup.damping;
  // Named references, not a structured binding: the lambdas below use the scene, and clang 14
  // (the fuzz build's) cannot capture structured bindings.
  const auto scene_and_run = setup.run(case_file, test_overrides(g, load, plan, r.transit_time, r.damping));
  const Scene& scene = scene_and_run.first;
  const RunResult& run = scene_and_run.second;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.particles = scene.dem.particles.size();
  r.bonds = bond_count(scene.dem);
  if (scene.weave && !load.shear() && load.face < 2)
    r.rule_of_mixtures = load.face == 0 ? scene.weave->rule_of_mixtures_x : scene.weave->rule_of_mixtures_y;
  r.steps = run.steps;
  r.dt = scene.dt;
  r.kinetic_to_bond = run.energies.kinetic / run.energies.bond;

  // Plateau window: the last `average` of the hold.
  const SeriesTable series = SeriesTable::read(scene.output.dir / "series.csv");
  const double window_start = scene.end_time - plan.average * plan.plateau * r.transit_time;
  std::vector<const std::vector<double>*> window;
  for (const auto& row : series.rows)
    if (row[0] >= window_start * (1.0 - 1e-12)) window.push_back(&row);
  if (window.size() < 4)
    throw RunError(scene.output.dir.string() + ": fewer than 4 output rows in the averaging window; raise rows_per_transit");
  const auto column = [&](const std::string& name) {
    const std::size_t c = series.column(name);
    std::vector<double> v;
    for (const auto* row : window) v.push_back((*row)[c]);
    return v;
  };
  // Strain between the slabs of axis k (their sensors record the loaded component).
  Json gauges = Json::object();
  const auto strain_between = [&](int k) {
    const double gauge = gauge_length(scene.dem.particles, g, k);
    gauges[std::string(axis_names[k])] = gauge;
    const auto upper = column(displacement_column(k, true)), lower = column(displacement_column(k, false));
    std::vector<double> e(upper.size());
    for (std::size_t i = 0; i < e.size(); ++i) e[i] = (upper[i] - lower[i]) / gauge;
    return window_average(e);
  };
  std::vector<double> stress = column("F_moved"), imbalance(stress.size());
  const auto held = column("F_held");
  for (std::size_t i = 0; i < stress.size(); ++i) {
    imbalance[i] = std::abs(stress[i] + held[i]) / std::abs(stress[i]);
    stress[i] /= g.area(load.face);
  }
  r.stress = window_average(stress);
  r.force_imbalance = window_average(imbalance).value;
  r.strain = strain_between(load.face);
  r.modulus = ratio(r.stress, r.strain);
  if (!load.shear()) {
    for (int k : slab_axes(load)) {
      if (k == load.face) continue;
      r.lateral_strain[k] = strain_between(k);
      const Estimate nu = ratio(r.lateral_strain[k], r.strain);
      r.poisson[k] = {-nu.value, nu.uncertainty};
    }
  }

  Json j = setup.record(case_file, load.describe(), plan.describe());
  j["test"] = load.name;
  j["stress"] = estimate_json(r.stress);
  j["strain"] = estimate_json(r.strain);
  j["modulus"] = estimate_json(r.modulus);
  for (int k = 0; k < 3; ++k)
    if (!std::isnan(r.poisson[k].value)) j["poisson_" + std::string(axis_names[k])] = estimate_json(r.poisson[k]);
  j["gauge_lengths"] = gauges;
  j["force_imbalance"] = r.force_imbalance;
  j["kinetic_to_bond_energy"] = r.kinetic_to_bond;
  TestSetup::write_record(j, scene, r.steps, r.wall_seconds);
  return r;
}

FailurePlan FailurePlan::read(std::optional<CaseNode> node) {
  FailurePlan f;
  if (!node) return f;
  node->add_schema_section("failure plan");
  f.expected_strain = node->number_or("expected_strain", f.expected_strain, Range::open_between(0.0, 0.5), "1");
  f.transits = node->number_or("transits", f.transits, Range::positive(), "transit times");
  f.max_strain_factor = node->number_or("max_strain_factor", f.max_strain_factor, Range::at_least(1.0), "1");
  f.stop_below = node->number_or("stop_below", f.stop_below, Range::open_between(0.0, 1.0), "1");
  f.stop_after = node->number_or("stop_after", f.stop_after, Range::non_negative(), "transit times");
  f.damping = node->number_or("damping", f.damping, Range::non_negative(), "1");
  f.rise = node->number_or("rise", f.rise, Range::non_negative(), "transit times");
  f.rows_per_transit = node->number_or("rows_per_transit", f.rows_per_transit, Range::at_least(2.0), "1");
  f.frames = static_cast<int>(node->number_or("frames", f.frames, Range::between(0.0, 10000.0), "1"));
  node->finish();
  return f;
}

std::string FailurePlan::describe() const {
  return "expected strain " + shortest(expected_strain) + " after " + shortest(transits) + " T (rise " + shortest(rise) +
         " T), end " + end_rule() + " or at " + shortest(max_strain_factor) +
         " x the expected strain, damping " + shortest(damping) + " of critical, " + shortest(rows_per_transit) + " rows per T";
}

std::string FailurePlan::end_rule() const {
  return "below " + shortest(stop_below) + " of the peak" + (stop_after > 0.0 ? " for " + shortest(stop_after) + " T" : std::string());
}

FailureStop::FailureStop(const FailurePlan& plan)
    : stop_below_(plan.stop_below),
      min_strain_(0.2 * plan.expected_strain),
      rows_needed_(std::max(1L, std::lround(std::ceil(plan.stop_after * plan.rows_per_transit)))) {}

bool FailureStop::after_row(double stress, double strain) {
  peak_ = std::max(peak_, stress);
  rows_below_ = strain > min_strain_ && stress < stop_below_ * peak_ ? rows_below_ + 1 : 0;
  return rows_below_ >= rows_needed_;
}

namespace {

// InputError unless the case of a test to failure, as built for it, can break.
void require_failure_criterion(const Scene& probe, const std::filesystem::path& case_file, const LoadCase& load) {
  if (!probe.dem.failure_enabled())
    throw InputError(case_file.string() + ": test " + load.name +
                     " runs to failure but the case has no failure criterion (a bond law's sigma_f, or dem.failure.rdef)");
}

}  // namespace

FailureTestResult run_failure_test(const std::filesystem::path& case_file, const SceneOptions& options, const LoadCase& load,
                                   const FailurePlan& plan) {
  if (load.shear()) throw InputError("test " + load.name + ": a test to failure is a tension test");
  const auto t0 = std::chrono::steady_clock::now();
  const TestSetup setup(case_file, options, load, plan.damping);
  require_failure_criterion(setup.probe, case_file, load);
  const SampleGeometry& g = setup.geometry;
  const int a = load.face;
  const double area = g.area(a), gauge = gauge_length(setup.probe.dem.particles, g, a);
  FailureTestResult r;
  r.load = load;
  r.out_dir = options.out_dir;
  r.transit_time = setup.transit;
  r.damping = setup.damping;
  r.velocity = plan.expected_strain * g.length(a) / (plan.transits * setup.transit);
  // Displacement v (t - rise / 2) after the rise: the end strain is max_strain_factor x expected.
  const double rise = plan.rise * setup.transit;
  const double end = plan.max_strain_factor * plan.expected_strain * g.length(a) / r.velocity + 0.5 * rise;
  const CaseValue axis = CaseValue::list({std::string(axis_names[a])});
  Vec3 velocity{};
  velocity[a] = r.velocity;
  std::vector<CaseValue> broken;
  for (const auto& set : setup.probe.dem.bond_sets()) broken.push_back("broken_" + set->name);
  const std::string origin = generated_by(load);
  std::vector<Override> generated = gauge_overrides(g, load);
  generated.insert(
      generated.end(),
      {Override("boundary",
                CaseValue::list({map({{"group", group_name(a, false)}, {"type", "velocity"}, {"value", Vec3{}}, {"components", axis}}),
                                 map({{"group", group_name(a, true)},
                                      {"type", "velocity"},
                                      {"value", velocity},
                                      {"rise", rise},
                                      {"components", axis}})}),
                origin),
       Override("time.end", end, origin), Override("output.every", setup.transit / plan.rows_per_transit, origin),
       Override("dem.damping", setup.damping, origin),
       // Seed Figs. 5-6: broken bonds per group and the stress against the strain.
       Override("output.plots",
                CaseValue::list({map({{"file", "failure.png"},
                                      {"title", "Tension to failure: " + load.name},
                                      {"x", displacement_column(a, true)},
                                      {"x_scale", 1.0 / gauge},
                                      {"x_label", "strain"},
                                      {"y", CaseValue::list({"F_moved"})},
                                      {"y_scale", 1e-9 / area},
                                      {"y_label", "stress GPa"},
                                      {"y2", CaseValue::list(broken)},
                                      {"y2_scale", 100},
                                      {"y2_label", "broken bonds %"}})}),
                origin)});
  if (plan.frames > 0)
    generated.insert(generated.end(), {Override("output.fields", CaseValue::list({"particles", "bonds"}), origin),
                                       Override("output.fields_every", end / plan.frames, origin)});

  // The stress on the moved face, row by row; stop once it has fallen well below its peak.
  FailureStop stop(plan);
  RunOptions run_options;
  const std::string moved = displacement_column(a, true), held = displacement_column(a, false);
  run_options.stop_after_row = [&](const std::vector<std::pair<std::string, double>>& row) -> std::string {
    double force = 0.0, upper = 0.0, lower = 0.0;
    for (const auto& [name, value] : row) {
      if (name == "F_moved") force = value;
      if (name == moved) upper = value;
      if (name == held) lower = value;
    }
    if (stop.after_row(force / area, (upper - lower) / gauge))
      return "the stress fell " + plan.end_rule();
    return {};
  };
  const auto [scene, run] = setup.run(case_file, generated, run_options);
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.particles = scene.dem.particles.size();
  r.bonds = bond_count(scene.dem);
  r.steps = run.steps;
  r.dt = scene.dt;
  r.broke = !run.stop_reason.empty();
  r.breaks = scene.dem.breaks().size();
  r.fracture_energy = run.energies.fracture;

  const SeriesTable series = SeriesTable::read(scene.output.dir / "series.csv");
  const std::size_t force = series.column("F_moved"), upper = series.column(moved), lower = series.column(held);
  const auto stress_of = [&](const std::vector<double>& row) { return row[force] / area; };
  const auto strain_of = [&](const std::vector<double>& row) { return (row[upper] - row[lower]) / gauge; };
  std::size_t at_peak = 0;
  for (std::size_t i = 0; i < series.rows.size(); ++i)
    if (stress_of(series.rows[i]) > stress_of(series.rows[at_peak])) at_peak = i;
  r.peak_stress = stress_of(series.rows[at_peak]);
  r.strain_at_peak = strain_of(series.rows[at_peak]);
  r.final_stress = stress_of(series.rows.back());
  r.final_strain = strain_of(series.rows.back());
  for (const auto& row : series.rows)
    if (stress_of(row) >= 0.5 * r.peak_stress) {
      r.secant_modulus = stress_of(row) / strain_of(row);
      break;
    }
  for (const auto& set : scene.dem.bond_sets()) {
    const std::size_t c = series.column("broken_" + set->name);
    r.broken_at_peak.emplace_back(set->name, series.rows[at_peak][c]);
    r.broken_at_end.emplace_back(set->name, series.rows.back()[c]);
  }

  Json j = setup.record(case_file, load.describe() + ", to failure", plan.describe());
  j["test"] = load.name;
  j["velocity"] = r.velocity;
  j["failure_stress"] = r.peak_stress;
  j["failure_strain"] = r.strain_at_peak;
  j["secant_modulus"] = r.secant_modulus;
  j["final_stress"] = r.final_stress;
  j["final_strain"] = r.final_strain;
  j["broke"] = r.broke;
  Json& peak_json = j["broken_at_peak"];
  for (const auto& [name, f] : r.broken_at_peak) peak_json[name] = f;
  Json& end_json = j["broken_at_end"];
  for (const auto& [name, f] : r.broken_at_end) end_json[name] = f;
  j["breaks"] = r.breaks;
  j["fracture_energy"] = r.fracture_energy;
  j["gauge_length"] = gauge;
  TestSetup::write_record(j, scene, r.steps, r.wall_seconds);
  return r;
}

namespace {

// One line per test for the console.
std::string describe_result(const VirtualTestResult& r) {
  std::string line = r.load.shear() ? "G" : "E";
  line += format(" = %.5g", r.modulus.value * 1e-9) + format(" ± %.2g GPa", r.modulus.uncertainty * 1e-9);
  if (!std::isnan(r.rule_of_mixtures)) line += format(" (the weave's rule of mixtures %.4g GPa)", r.rule_of_mixtures * 1e-9);
  for (int k = 0; k < 3; ++k)
    if (!std::isnan(r.poisson[k].value))
      line += ", nu_" + std::string(axis_names[r.load.face]) + std::string(axis_names[k]) + format(" %.4f", r.poisson[k].value) +
              format(" ± %.2g", r.poisson[k].uncertainty);
  line += format(", imbalance %.1e", r.force_imbalance) + ", " + std::to_string(r.particles) + " DEs, " +
          std::to_string(r.steps) + " steps" + format(", wall %.1f s", r.wall_seconds);
  return line;
}

}  // namespace

namespace {

// A published range for a test to failure (e.g. seed Table 4 over its samples).
struct FailureReference {
  struct Broken {
    std::string set;                // a bond set of the case
    std::array<double, 2> percent;  // %
    std::string where;              // "spec.yaml:12: tests[0].reference.broken.fibre"
  };
  std::string name;
  std::array<double, 2> stress{}, strain{};  // Pa; 1
  std::vector<Broken> broken;

  static std::optional<FailureReference> read(std::optional<CaseNode> node) {
    if (!node) return std::nullopt;
    const auto range = [](CaseNode& n, std::string_view key, const char* unit) {
      const auto v = n.numbers(key, Range::non_negative(), unit);
      if (v.size() != 2 || v[0] > v[1]) n.fail(key, "expected a range [low, high]");
      return std::array<double, 2>{v[0], v[1]};
    };
    FailureReference r;
    r.name = node->string("name");
    r.stress = range(*node, "stress", "Pa");
    r.strain = range(*node, "strain", "1");
    if (auto broken = node->child_if("broken")) {
      for (const std::string& set : broken->keys())
        r.broken.push_back({set, range(*broken, set, "%"), broken->where(set) + ": " + broken->key_path(set)});
      broken->finish();
    }
    node->finish();
    return r;
  }
};

std::string describe_failure(const FailureTestResult& r) {
  return format("sigma_fail = %.4g GPa", r.peak_stress * 1e-9) + format(" at strain %.4g", r.strain_at_peak) +
         format(", secant E %.4g GPa", r.secant_modulus * 1e-9) + (r.broke ? ", broke" : ", did not break") +
         "; broken % at the peak: " + broken_text(r.broken_at_peak) + "; at the end: " + broken_text(r.broken_at_end) + ", " +
         std::to_string(r.particles) + " DEs, " + std::to_string(r.steps) + " steps" + format(", wall %.1f s", r.wall_seconds);
}

// Every selected sample with every test, read as its run will read it (TestSetup's probe), before
// any run: a bad override in a sample's or a test's set:, a test to failure whose case cannot
// break, or a reference to a bond set the case lacks, then stops the suite at once rather than
// when that test starts, maybe hours in. The packings the runs load are built (and cached) here
// instead of at their first test.
void check_every_test(const std::filesystem::path& case_file, const SceneOptions& options, const std::vector<SampleVariant>& samples,
                      const std::vector<std::string>& only_samples, const std::vector<LoadCase>& tests, bool to_failure,
                      const std::vector<std::optional<FailureReference>>& references) {
  const auto t0 = std::chrono::steady_clock::now();
  std::size_t checked = 0;
  for (const SampleVariant& sample : samples) {
    if (!sample.selected(only_samples)) continue;
    for (std::size_t t = 0; t < tests.size(); ++t) {
      SceneOptions o = TestSetup::with_test_overrides(sample.options_for(options, tests[t].name, {}), tests[t]);
      o.check_output_dir = false;
      const Scene scene = build_scene(case_file, o);
      ++checked;
      if (to_failure) require_failure_criterion(scene, case_file, tests[t]);
      if (t >= references.size() || !references[t]) continue;
      std::vector<std::string_view> sets;
      std::string listed;
      for (const auto& set : scene.dem.bond_sets()) {
        sets.push_back(set->name);
        listed += (listed.empty() ? "" : ", ") + set->name;
      }
      for (const auto& b : references[t]->broken)
        if (std::find(sets.begin(), sets.end(), b.set) == sets.end()) {
          const auto guess = closest_match(b.set, sets);
          throw InputError(b.where + ": the case has no bond set '" + b.set + "'" +
                           (guess ? "; did you mean '" + std::string(*guess) + "'?" : " (its bond sets: " + listed + ")"));
        }
    }
  }
  std::printf("the case read with each test's overrides before any run: %zu reads, %.1f s\n", checked,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

int run_failure_suite(const std::filesystem::path& case_file, const SceneOptions& options, const std::filesystem::path& out_dir,
                      const std::vector<SampleVariant>& samples, const std::vector<std::string>& only_samples,
                      const std::vector<LoadCase>& tests, const std::vector<std::optional<FailureReference>>& references,
                      const FailurePlan& plan) {
  std::printf("tests to failure of %s: %s\n", case_file.string().c_str(), plan.describe().c_str());
  std::string csv = "sample,test,load,particles,bonds,steps,dt,transit_time,velocity,failure_stress,failure_strain,secant_modulus,"
                    "final_stress,final_strain,broke,breaks,fracture_energy,broken_at_peak,broken_at_end,wall_seconds,status\n";
  std::string md = "| sample | test | DEs | sigma_fail GPa | eps_fail 1e-3 | secant E GPa | broken % at the peak | broken % at the end | wall s |\n"
                   "|---|---|---|---|---|---|---|---|---|\n";
  int stopped = 0;
  for (const SampleVariant& sample : samples) {
    if (!sample.selected(only_samples)) continue;
    for (std::size_t t = 0; t < tests.size(); ++t) {
      const LoadCase& load = tests[t];
      try {
        const FailureTestResult r = run_failure_test(case_file, sample.options_for(options, load.name, out_dir), load, plan);
        std::printf("%s %s: %s\n", sample.name.c_str(), load.name.c_str(), describe_failure(r).c_str());
        csv += sample.name + "," + load.name + "," + load.describe() + "," + std::to_string(r.particles) + "," +
               std::to_string(r.bonds) + "," + std::to_string(r.steps);
        for (double v : {r.dt, r.transit_time, r.velocity, r.peak_stress, r.strain_at_peak, r.secant_modulus, r.final_stress,
                         r.final_strain})
          csv += format(",%.9g", v);
        csv += std::string(",") + (r.broke ? "1" : "0") + "," + std::to_string(r.breaks) + format(",%.9g", r.fracture_energy) + "," +
               broken_text(r.broken_at_peak, "; ") + "," + broken_text(r.broken_at_end, "; ") + format(",%.1f", r.wall_seconds) + ",ok\n";
        md += "| " + sample.name + " | " + load.name + " | " + std::to_string(r.particles) + " | " + format("%.3f", r.peak_stress * 1e-9) +
              " | " + format("%.2f", r.strain_at_peak * 1e3) + " | " + format("%.4g", r.secant_modulus * 1e-9) + " | " +
              broken_text(r.broken_at_peak) + " | " + broken_text(r.broken_at_end) + " | " + format("%.0f", r.wall_seconds) + " |\n";
      } catch (const RunError& e) {
        ++stopped;
        std::printf("%s %s: stopped: %s\n", sample.name.c_str(), load.name.c_str(), e.what());
        csv += sample.name + "," + load.name + "," + load.describe() + std::string(18, ',') + "stopped\n";
        md += "| " + sample.name + " | " + load.name + " | stopped: " + e.what() + " | | | | | | |\n";
      }
      if (const auto& ref = references[t]) {
        std::string broken;
        for (const auto& b : ref->broken)
          broken += (broken.empty() ? "" : ", ") + b.set + format(" %.3g", b.percent[0]) + format("-%.3g", b.percent[1]);
        md += "| " + ref->name + " | " + load.name + " | | " + format("%.2f", ref->stress[0] * 1e-9) + format("-%.2f", ref->stress[1] * 1e-9) +
              " | " + format("%.2f", ref->strain[0] * 1e3) + format("-%.2f", ref->strain[1] * 1e3) + " | | | " + broken + " | |\n";
      }
      std::fflush(stdout);
      write_file_atomically(out_dir / "failure.csv", csv);
      write_file_atomically(out_dir / "failure.md", md);
    }
  }
  std::printf("\n%s", md.c_str());
  return stopped;
}

}  // namespace

namespace {

// A virtual-test spec as read (its keys: virtual_test_schema()).
struct SuiteSpec {
  std::filesystem::path case_file;
  std::vector<SampleVariant> samples;
  QuasiStatic plan;
  std::vector<LoadCase> tests;
  std::vector<std::optional<FailureReference>> references;  // with a failure plan, one per test
  std::optional<FailurePlan> failure;
  std::optional<CompositeSpec> composite;
  std::optional<CompositeTests> roles;
};

SuiteSpec read_suite(const std::filesystem::path& spec_file) {
  CaseFile file = CaseFile::load(spec_file, {}, &suite_schema());
  CaseNode root = file.root();
  SuiteSpec spec;
  spec.case_file = root.existing_file("case");
  std::vector<SampleVariant>& samples = spec.samples;
  for (CaseNode s : root.list_or_empty("samples")) {
    const std::string name = folder_name(s);
    samples.push_back({name, s.overrides_or_empty("set")});
    require_new_name(s, samples, "sample");
    s.finish();
  }
  if (samples.empty()) samples.push_back({"base", {}});
  spec.plan = QuasiStatic::read(root.child_if("quasi_static"));
  const std::optional<CaseNode> failure_node = root.child_if("failure");
  std::vector<LoadCase>& tests = spec.tests;
  for (CaseNode t : root.list("tests")) {
    tests.push_back(LoadCase::read(t));
    require_new_name(t, tests, "test");
    if (failure_node) {
      if (tests.back().shear()) t.fail("shear", "a test to failure (failure section) is a tension test");
      spec.references.push_back(FailureReference::read(t.child_if("reference")));
    }
    t.finish();
  }
  if (failure_node) {
    if (root.has("composite")) root.fail("composite", "a failure suite has no composite table; run the elastic suite for it");
    spec.failure = FailurePlan::read(failure_node);
  } else if (auto node = root.child_if("composite")) {
    spec.composite = CompositeSpec::read(*node);
    spec.roles = CompositeTests::find(root, tests);
    const Constants theory = spec.composite->theory();
    for (std::size_t i = 0; i < tests.size(); ++i)
      if (!tests[i].modulus_estimate) tests[i].modulus_estimate = spec.roles->estimate(i, theory);
  }
  root.finish();
  return spec;
}

}  // namespace

void validate_virtual_test_spec(const std::filesystem::path& spec_file) { read_suite(spec_file); }

int run_virtual_test_suite(const std::filesystem::path& spec_file, const SceneOptions& options,
                           const std::filesystem::path& out_dir, const std::vector<std::string>& only_samples,
                           const std::vector<std::string>& only_tests) {
  SuiteSpec spec = read_suite(spec_file);
  const std::filesystem::path& case_file = spec.case_file;
  const std::vector<SampleVariant>& samples = spec.samples;
  const QuasiStatic& plan = spec.plan;
  std::vector<LoadCase>& tests = spec.tests;
  const auto& references = spec.references;
  const auto& failure = spec.failure;
  const auto& composite = spec.composite;
  const auto& roles = spec.roles;
  // --sample and --test name what the spec has: an unknown name gets the closest, or the list.
  const auto require_known = [&](const std::vector<std::string>& asked, const auto& items, const std::string& what) {
    std::vector<std::string_view> names;
    std::string listed;
    for (const auto& item : items) {
      names.push_back(item.name);
      listed += (listed.empty() ? "" : ", ") + item.name;
    }
    for (const auto& name : asked)
      if (std::find(names.begin(), names.end(), name) == names.end()) {
        const auto guess = closest_match(name, names);
        throw InputError(spec_file.string() + ": --" + what + " " + name + ": no " + what + " of that name" +
                         (guess ? "; did you mean '" + std::string(*guess) + "'?" : "; " + what + "s: " + listed));
      }
  };
  require_known(only_samples, samples, "sample");
  require_known(only_tests, tests, "test");
  if (!only_tests.empty())
    std::erase_if(tests, [&](const LoadCase& t) { return std::find(only_tests.begin(), only_tests.end(), t.name) == only_tests.end(); });
  check_every_test(case_file, options, samples, only_samples, tests, failure.has_value(), references);
  if (failure) return run_failure_suite(case_file, options, out_dir, samples, only_samples, tests, references, *failure);

  std::printf("virtual tests of %s: %s\n", case_file.string().c_str(), plan.describe().c_str());
  std::string csv = csv_header();
  std::vector<std::string> names;
  std::vector<std::array<Estimate, 6>> constants;
  std::vector<std::size_t> particles;
  std::vector<std::array<double, 4>> walls;
  int stopped = 0;
  for (const SampleVariant& sample : samples) {
    if (!sample.selected(only_samples)) continue;
    std::vector<VirtualTestResult> results;
    for (const LoadCase& load : tests) {
      try {
        results.push_back(run_virtual_test(case_file, sample.options_for(options, load.name, out_dir), load, plan));
        std::printf("%s %s (%s): %s\n", sample.name.c_str(), load.name.c_str(), load.describe().c_str(),
                    describe_result(results.back()).c_str());
        csv += csv_row(sample.name, results.back(), "ok");
      } catch (const RunError& e) {
        ++stopped;
        std::printf("%s %s: stopped: %s\n", sample.name.c_str(), load.name.c_str(), e.what());
        VirtualTestResult failed;
        failed.load = load;
        results.push_back(failed);
        csv += csv_row(sample.name, failed, "stopped");
      }
      std::fflush(stdout);
      write_file_atomically(out_dir / "tests.csv", csv);
    }
    if (roles) {
      names.push_back(sample.name);
      constants.push_back(roles->constants(results));
      particles.push_back(results[roles->L].particles);
      walls.push_back({results[roles->L].wall_seconds, results[roles->T].wall_seconds, results[roles->LT].wall_seconds,
                       results[roles->TT].wall_seconds});
    }
  }
  if (composite) {
    const std::string md = composite_tables(*composite, names, constants, particles, walls);
    write_file_atomically(out_dir / "composite.md", md);
    std::printf("\n%s", md.c_str());
  }
  return stopped;
}

}  // namespace arlequin::app
