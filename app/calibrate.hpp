// SPDX-License-Identifier: GPL-3.0-or-later
// Calibration of beam-bond micro parameters (E_mu, r_mu) against macroscopic elastic targets
// (E_M, nu_M) with quasi-static virtual tensile tests (docs/theory.md#calibration; seed Table 1,
// docs/validation.md R2; docs/references.md#andre2012, section 4):
// on a given packing, nu_M depends (almost) only on r_mu, and at fixed r_mu the bond forces,
// hence E_M, are proportional to E_mu. So:
//  1. the calibration curve: tension tests (virtual_tests.hpp) at E_mu = 1 Pa over a grid of
//     r_mu, giving E_M / E_mu and nu_M per r_mu (averaged over the chosen tension axes);
//  2. per target: r_mu where the curve's nu_M (linear between neighbouring points) equals the
//     target, refined by measuring there and interpolating again until |nu_M - target| <=
//     tolerance (at most 4 rounds); E_mu = E_target / (E_M / E_mu) at that r_mu;
//  3. verification runs of the pair at the material's own E_mu: the achieved E_M and nu_M, on
//     the calibration sample (E_M there matches by construction, a check of the proportionality)
//     and on the spec's other samples (another seed, another size: the packing's own effect);
//     there, a pair whose r_mu an earlier pair had reuses that run, E_M scaled by E_mu.
// The curve is measured with the case's own nu_mu (targets share it). Curve points are cached
// next to the sample file (calibration_cache.json), keyed by the case as resolved and the test
// plan, so a second calibration on the same packing only runs what is new.
//
// Failure calibration (docs/theory.md#calibration; seed Table 1's sigma_f_mu): at fixed elastic
// micro parameters the sample's macroscopic tensile failure stress is proportional to the
// micro strength (every bond force scales with it up to the first break, and the cascade after
// it is the same in units of the failure strain), so, from a first guess s_0, tests to failure
// (virtual_tests.hpp, run_failure_test) give sigma_n and s_{n+1} = s_n target / sigma_n, until
// |sigma_n / target - 1| <= the failure tolerance (at most 5 rounds). The criterion is BBF (the
// bond's sigma_f) or RDEF (dem.failure.rdef.threshold, the bond left without sigma_f).
//
// Averages over n axes: the mean, uncertainty sqrt(sum u_i^2 / n^2 + s^2 / n), s the spread
// (standard deviation) between the axes; nu_M pools both lateral ratios of every axis.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/scene.hpp"
#include "app/virtual_tests.hpp"

namespace arlequin::app {

struct CalibrationTarget {
  std::string name;
  double young = 0.0;    // E_M, Pa
  double poisson = 0.0;  // nu_M
  std::optional<double> reference_E_mu, reference_r_mu;  // a published pair (seed Table 1), for the report
};

// A macroscopic tensile strength to reproduce with one failure criterion.
struct FailureTarget {
  std::string name;       // an elastic target's name: its calibrated pair and E are used
  std::string criterion;  // "bbf" or "rdef"
  double stress = 0.0;    // Pa, sigma_f macro
  std::optional<double> young, E_mu, r_mu;     // Pa, Pa, 1: required without an elastic target of that name
  std::optional<double> initial, reference;   // Pa: first guess (default: reference), a published value
  std::string variant;                        // optional name of a variant of the criterion
  std::vector<Override> overrides;            // its case options ("key=value"), e.g. RDEF's average
  // "bbf", "rdef" or "rdef_<variant>": folders and tables.
  std::string label() const { return variant.empty() ? criterion : criterion + "_" + variant; }
};

// Spec file (strict YAML; `arlequin calibrate SPEC.yaml`): its keys are declared beside their
// reader (calibration_schema(), calibrate.cpp) and printed by `arlequin schema --of calibrate`.
// Give each verify sample its own sample file (name= or dem.sample.file=), else its packing
// replaces the calibration sample's cached one. A failure target's variant + set run the same
// criterion with other case options (e.g. dem.failure.rdef.average=bonded_neighbours), shown
// as rdef_<variant>; a failure test's expected strain is the target stress / E.
struct CalibrationSpec {
  std::filesystem::path case_file;
  std::string bond_key = "dem.bond";
  std::string bond_origin = "bond";  // where bond_key was given, for messages about its overrides
  // `bond_key.leaf=value`, an override of the calibrated bond section.
  Override bond_override(const std::string& leaf, double value) const;
  std::vector<double> radius_ratios;
  std::vector<int> axes{2};
  double tolerance = 0.002;
  struct Variant {
    std::string name;
    std::vector<Override> overrides;
  };
  std::vector<Variant> verify;
  QuasiStatic plan;
  std::vector<CalibrationTarget> targets;
  std::vector<FailureTarget> failure_targets;
  FailurePlan failure_plan;
  int failure_axis = 2;
  double failure_tolerance = 0.02;

  static CalibrationSpec read(const std::filesystem::path& spec_file);  // InputError at the key
};

struct CurvePoint {
  double r_mu = 0.0;
  Estimate young_per_E_mu;  // E_M / E_mu
  Estimate poisson;         // nu_M
  std::string source;       // "grid", "refinement" or "cache"
};

// E_M and nu_M of a case pooled over the spec's tension axes.
struct Measurement {
  std::string sample;  // "calibration", or the name of a verify variant
  double r_mu = 0.0;
  Estimate young;      // E_M, Pa
  Estimate poisson;
  std::size_t particles = 0;
  double wall_seconds = 0.0;
};

struct CalibratedPair {
  CalibrationTarget target;
  double E_mu = 0.0;  // Pa
  double r_mu = 0.0;
  std::vector<Measurement> achieved;  // the calibration sample first, then the verify variants
};

struct CalibratedStrength {
  FailureTarget target;
  double E_mu = 0.0, r_mu = 0.0, young = 0.0;  // Pa, 1, Pa: the elastic parameters used
  struct Round {
    double threshold;  // Pa: sigma_f (bbf) or the RDEF threshold
    FailureTestResult test;
  };
  std::vector<Round> rounds;  // the last one is the result
  bool converged = false;
};

struct CalibrationResult {
  std::vector<CurvePoint> curve;  // sorted by r_mu
  std::vector<CalibratedPair> pairs;
  std::vector<CalibratedStrength> strengths;
};

// Runs the calibration into out_dir (runs in out_dir/curve/r_<r_mu>/<axis>/,
// out_dir/<target>/<sample>/<axis>/ and out_dir/<target>/failure_<criterion>/round_<n>/), writes
// curve.csv, curve.png (with elastic targets), strength.csv (with failure targets),
// calibration.md and calibration.json there, and prints the curve, the pairs and strengths.
// options' overrides apply to the case. Before any run the case is read with each verify
// sample's and each failure target's overrides: InputError for a bad one, or for an RDEF target
// whose case has a BBF strength. InputError if a target's nu_M is outside the curve's range
// (widen r_mu); RunError if a run stops.
CalibrationResult calibrate(const CalibrationSpec& spec, const SceneOptions& options, const std::filesystem::path& out_dir);

// The keys of a calibration spec (with the loading plans of virtual_tests.hpp).
const Schema& calibration_schema();

}  // namespace arlequin::app
