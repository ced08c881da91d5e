// SPDX-License-Identifier: GPL-3.0-or-later
// Quasi-static virtual material tests on a DEM sample: tension and simple shear of a box-shaped
// sample, the seed's "first challenge" (homogenised moduli of a REV, seed Fig. 3 and Table 3;
// docs/validation.md R2, R3), and the suites of them that `arlequin virtual-test` runs.
//
// A test is the sample case (dem sample, materials or bond law; no groups, boundary or sensors
// of its own) plus generated sections (overrides built as data, CaseValue):
//  - groups: one slab per loaded or gauged face, one mean DE diameter thick, from the DEs'
//    bounding box (the DEs whose centre lies in it);
//  - tension along axis a: the lower a-face held in component a only, the upper a-face moved
//    by a linear ramp to strain * L_a in component a only (rollers: lateral contraction free);
//    the four lateral faces free, with displacement sensors for the Poisson ratios;
//  - shear of the faces normal to n along d: the lower n-face fixed (all components and
//    rotations), the upper one moved by strain * L_n along d with its other components and
//    rotations held (a guided clamp); the lateral faces free. The result is the apparent
//    shear modulus of the block, bending of the block included;
//  - force sensors (component along the motion) on both loaded faces, displacement sensors
//    on every slab; time: the ramp, then a plateau with the load held; global viscous damping.
// Measures (seed: "sliding average ... excluding the ramp"): every series is averaged over
// the last `average` fraction of the plateau. Stress = force on the moved face / face area
// (the box's cross-section); strain_kk = (mean displacement of the upper k-slab - of the lower
// one) / distance between the slabs' centroids, which is the boundary average of the
// strain (divergence theorem) over the slabs' centre planes; shear angle likewise.
// Uncertainty of an average: sqrt(sd^2 + drift^2) with sd the standard deviation over the
// window (oscillation left) and drift the difference between the means of its two halves
// (creep towards equilibrium not finished): a bound, not a standard error. Moduli and Poisson
// ratios propagate relative uncertainties in quadrature.
//
// Time scale: a wave transit time T = L / sqrt(M / rho), L the sample length along the loaded
// faces' normal, rho the sample's mean density (DE mass / box volume), M the test's modulus
// estimate: given (e.g. a closed-form estimate), or else the affine one, the energy of the
// bonds under the test's homogeneous strain applied to every DE centre (M = 2 W / (strain^2 V):
// the P-wave modulus for tension, the shear modulus for shear; an upper bound, Voigt, so T is
// rather short). Ramp and plateau are in units of T; the damping c = zeta * 2 pi / T (1/s),
// zeta the fraction of critical damping of the fundamental mode (omega_1 = pi / T, both faces
// held); mass-proportional damping lets every mode decay as exp(-c t / 2).
#pragma once
#include <array>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "app/scene.hpp"
#include "common/schema.hpp"

namespace arlequin {
class CaseNode;
}

namespace arlequin::app {

// A time average with its uncertainty (see above).
struct Estimate {
  double value = std::numeric_limits<double>::quiet_NaN();
  double uncertainty = std::numeric_limits<double>::quiet_NaN();
};

// Which faces are loaded and how. Axes are 0, 1, 2 for x, y, z.
struct LoadCase {
  std::string name;
  int face = 2;       // the loaded faces are normal to this axis
  int direction = 2;  // the upper face moves along this axis
  std::optional<double> modulus_estimate;  // Pa, for the time scale; none: affine estimate
  std::vector<Override> overrides;         // the test's own `set: [key=value, ...]`, after the sample's

  bool shear() const { return face != direction; }
  std::string describe() const;  // "tension along z", "shear of the z faces along x"
  // Reads {name, tension: z} or {name, shear: [z, x]} (faces, then direction), an optional
  // modulus_estimate [Pa] and set; InputError at the key otherwise.
  static LoadCase read(CaseNode& node);
};

// How slowly and how long; ramp and plateau in wave transit times (see above).
struct QuasiStatic {
  double strain = 2.0e-4;  // final normal strain (tension) or shear angle (shear)
  double ramp = 3.0;
  double plateau = 3.0;
  double damping = 0.5;    // zeta, fraction of critical damping of the fundamental mode; 0: none
  double average = 0.5;    // the last fraction of the plateau that is averaged
  double rows_per_transit = 20.0;

  // Reads an optional mapping (its keys: the schema section "quasi_static plan").
  static QuasiStatic read(std::optional<CaseNode> node);
  std::string describe() const;  // one line, for reports and cache keys (every field, exactly)
};

struct VirtualTestResult {
  LoadCase load;
  Estimate stress;    // Pa: sigma_aa on the moved face (tension), tau_nd (shear)
  Estimate strain;    // measured between the loaded slabs: eps_aa, or the shear angle gamma_nd
  Estimate modulus;   // stress / strain: E_a, or the apparent G_nd
  // A weave's tension along x or y: its rule of mixtures (dem::WeaveReport), Pa; NaN otherwise.
  double rule_of_mixtures = std::numeric_limits<double>::quiet_NaN();
  std::array<Estimate, 3> lateral_strain;  // tension: eps_kk of the free axes k; NaN otherwise
  std::array<Estimate, 3> poisson;         // tension: nu_ak = -eps_kk / eps_aa; NaN otherwise
  double force_imbalance = 0.0;  // |F_moved + F_held| / |F_moved| averaged: distance from equilibrium
  double kinetic_to_bond = 0.0;  // E_kinetic / E_bond at the end
  double transit_time = 0.0;     // s
  double modulus_used = 0.0;     // Pa, the estimate behind transit_time
  bool affine_estimate = false;  // modulus_used is the affine estimate
  double damping = 0.0;          // 1/s
  std::size_t particles = 0, bonds = 0;
  long steps = 0;
  double dt = 0.0;               // s
  double wall_seconds = 0.0;     // scene build + run
  std::filesystem::path out_dir;
};

// A tension test to failure (seed Table 4, Figs. 5-6): the upper face driven at a constant
// velocity along the axis, the lower face held, both in that component only (rollers); the
// velocity grows smoothly over `rise` transits (no step, so no ringing), then stays constant,
// the rate set so that the strain reaches expected_strain after `transits` transit times
// (same T as above). Damping is light: mass-proportional damping of a sample stretched at a
// constant rate makes the stress differ between the faces by about pi zeta E (strain per
// transit); zeta 0.05 and 4e-4 per transit keep that below 1 % of a failure stress at a
// strain of 1e-2. The run ends when the stress on the moved face has stayed below stop_below
// of its peak (past 0.2 expected_strain) for stop_after transit times (0: at the first output
// row below), or at max_strain_factor expected_strain. A brittle break makes the stress ring
// through zero for a few transits; to follow the damage after the peak down to a small
// stop_below, give stop_after a few transits so that a dip of the ringing does not end the run.
// Failure stress = peak of F_moved / area; failure strain = the gauge strain at that row.
struct FailurePlan {
  double expected_strain = 1.0e-2;
  double transits = 25.0;
  double max_strain_factor = 2.0;
  double stop_below = 0.5;
  double stop_after = 0.0;       // transit times
  double damping = 0.05;
  double rise = 1.0;             // transit times
  double rows_per_transit = 20.0;
  int frames = 0;                // HDF5/XDMF frames of particles and bonds over the run (0: none)

  // Reads an optional mapping with the fields above (absent ones keep their defaults).
  static FailurePlan read(std::optional<CaseNode> node);
  std::string describe() const;
  std::string end_rule() const;  // "below 0.5 of the peak[ for 3 T]", for describe and the stop reason
};

// The end rule of a test to failure (FailurePlan), fed one output row at a time.
class FailureStop {
 public:
  explicit FailureStop(const FailurePlan& plan);
  // True once the stress (Pa) has been below stop_below x its peak so far, at strains above
  // 0.2 expected_strain, for the plan's stop_after transits of consecutive rows (at least one).
  bool after_row(double stress, double strain);

 private:
  double stop_below_, min_strain_;
  long rows_needed_;
  double peak_ = 0.0;
  long rows_below_ = 0;
};

struct FailureTestResult {
  LoadCase load;
  double peak_stress = 0.0;      // Pa, sigma_fail
  double strain_at_peak = 0.0;   // eps_fail
  double secant_modulus = 0.0;   // Pa, stress / strain where the stress first reaches half its peak
  double final_stress = 0.0, final_strain = 0.0;
  bool broke = false;            // the stress fell below stop_below of its peak
  std::vector<std::pair<std::string, double>> broken_at_peak, broken_at_end;  // bond set, fraction
  std::size_t breaks = 0;
  double fracture_energy = 0.0;  // J, energy of the broken bonds
  double transit_time = 0.0, damping = 0.0, velocity = 0.0;  // s, 1/s, m/s
  std::size_t particles = 0, bonds = 0;
  long steps = 0;
  double dt = 0.0;
  double wall_seconds = 0.0;
  std::filesystem::path out_dir;
};

// Runs one tension test to failure into options.out_dir (required); writes test.json and
// failure.png (stress and broken fractions per bond set against strain) next to the run's
// outputs. InputError for a shear load case or a case without failure criteria.
FailureTestResult run_failure_test(const std::filesystem::path& case_file, const SceneOptions& options,
                                   const LoadCase& load, const FailurePlan& plan);

// Runs one test of the sample case into options.out_dir (required) and measures it; options'
// overrides apply to the case before the test's own. Writes test.json next to the run's
// outputs. InputError if the case is not a DEM case or the load case is bad; RunError if the
// run stops or leaves no plateau rows.
VirtualTestResult run_virtual_test(const std::filesystem::path& case_file, const SceneOptions& options,
                                   const LoadCase& load, const QuasiStatic& plan);

// `arlequin virtual-test SPEC.yaml`: a suite of tests on one or more samples. The spec's keys are
// declared beside their reader (virtual_test_schema(), virtual_tests.cpp) and printed by
// `arlequin schema --of virtual-test`. With failure:, every test (tension only) runs to failure
// and its reference ranges (e.g. seed Table 4) fill out_dir/failure.md (failure.csv has every
// run). With composite:, the tests are named L (tension along the fibres), T (across), LT
// (shear in the L-T plane) and TT (shear in the T-T' plane, for G_TT'); their engineering
// constants are tabulated next to the closed forms (app/micromechanics.hpp) and the
// references, whose missing entries are left blank; tests without a modulus_estimate take the
// closed form's (E_T for L and T, G_LT, G_TT': the slowest motion of each test).
// Reads the case of every sample (or only those named in only_samples) x test (or only those named
// in only_tests) first, so that a
// bad override or a reference to a bond set the case lacks is an InputError before any run;
// then runs each into out_dir/<sample>/<test>/, prints one line per test and the tables, and writes out_dir/tests.csv and (with composite)
// out_dir/composite.md. options' overrides apply to the case before the sample's. Returns the
// number of runs that stopped (0: all measured).
int run_virtual_test_suite(const std::filesystem::path& spec_file, const SceneOptions& options,
                           const std::filesystem::path& out_dir, const std::vector<std::string>& only_samples = {},
                           const std::vector<std::string>& only_tests = {});

// Reads a virtual-test spec as run_virtual_test_suite does, without building a scene; InputError
// at the key.
void validate_virtual_test_spec(const std::filesystem::path& spec_file);
// The keys of a virtual-test spec, and those of the two loading plans that calibration specs
// share (sections "quasi_static plan", "failure plan").
const Schema& virtual_test_schema();
std::span<const SchemaSection> plan_schema();

}  // namespace arlequin::app
