// SPDX-License-Identifier: GPL-3.0-or-later
// A 3D-interlock dry fabric of discrete-element yarns (docs/theory.md#weave; seed "third
// challenge", Figs. 17-18).
//
// Axes: weft along x, warp along y, thickness along z; t is the yarn thickness.
//  - Weft yarns, straight along x, in K layers at z = 2 k t (k = 0..K-1), in columns at
//    y_j = (j + 1/2) s_weft, j = 0..N_y-1, N_y = floor(L_y / s_weft).
//  - Stuffer warps, straight along y between two weft layers, z = (2 k + 1) t (k = 0..K-2), at
//    x_i = (i + 1/2) s_warp, i = 0..N_x-1, N_x = floor(L_x / s_warp).
//  - Binder warps along y, midway between two stuffer columns (x = (i + 1) s_warp, i = 0..N_x-2),
//    z(y) = (K-1) t + A cos(pi (y - y_0) / s_weft + i pi): over a weft column where the cosine
//    is 1 and under the next, each binder in phase opposition to its neighbours. The amplitude A
//    follows from the binder's crimp c = L_binder / L_y - 1, or is the smallest that clears the
//    weft columns when no crimp is given.
// A yarn is n_w x n_t parallel chains of DEs of radius R = t / (2 n_t): across its width (along
// x for a warp, y for a weft) at the pitch w / n_w (at least 2R), through its thickness at 2R
// along the path's normal. A chain of length L_c is split into n_s = floor(L_c / 2R) arcs of
// equal length, one DE at each arc's ends, consecutive DEs joined by a spring.
//
// The yarn law (seed Eqs. 6-8 and the density rule below Eq. 9): every DE of a yarn has the mass
// rho S L_y / n_DE (L_y the yarn's centre-line length, n_DE its DEs); a spring of rest length L0
// has K = E (S / n_p) / L0, for a chain of n_s equal springs seed Eq. 8's (n_s / n_p) E S / L_y;
// it breaks at the yarn's failure strain (max elongation).
//
// Contract: build_weave appends the DEs to model.particles (after any already there), adds one
// spring set per family ("weft", "stuffer", "binder"), and the groups "weft", "stuffer",
// "binder", one per yarn ("weft_<k>_<j>", "stuffer_<k>_<i>", "binder_<i>") and "edges" (the DEs
// within clamp_width of the fabric's border in x or y). It throws WeaveError naming the spec's
// field when the weave cannot be built as asked (a yarn too thin for its chains, binders that
// cross the weft at the given crimp), before anything is added.
#pragma once
#include <array>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>

#include "dem/dem_model.hpp"

namespace arlequin::dem {

struct WeaveSpec {
  double length_x = 0.0, length_y = 0.0;  // fabric size, m
  int weft_layers = 3;                    // K
  double weft_spacing = 0.0;              // s_weft, centre distance of weft columns, m
  double warp_spacing = 0.0;              // s_warp, centre distance of stuffer columns, m
  double yarn_width = 0.0;                // w, m
  double yarn_thickness = 0.0;            // t, m
  int chains_across = 1;                  // n_w
  int chains_through = 1;                 // n_t (n_p = n_w n_t)
  double crimp = 0.0;                     // binder crimp; 0: the smallest that clears the weft
  double clamp_width = 0.0;               // m, width of the "edges" group
  // The yarn (seed: Kevlar 1310 kg/m^3, 62 GPa).
  double density = 0.0;         // rho, kg/m^3 (over the section S)
  double modulus = 0.0;         // E, Pa
  double section = 0.0;         // S, m^2
  double failure_strain = 0.0;  // spring max elongation; 0: unbreakable
};

// What was built, for the log and the tests (closed forms in docs/theory.md#weave).
struct WeaveReport {
  int wefts = 0, stuffers = 0, binders = 0;       // yarn counts
  double weft_length = 0.0, stuffer_length = 0.0;  // centre-line length of one yarn, m
  double binder_length = 0.0;                      // m
  double amplitude = 0.0;                          // binder A, m
  double crimp = 0.0;                              // binder crimp, 1
  double thickness = 0.0;                          // fabric thickness (outer faces of the binders), m
  double areal_density = 0.0;                      // kg/m^2
  double fibre_volume_fraction = 0.0;              // S (total length) / (L_x L_y thickness)
  double radius = 0.0;                             // DE radius R, m
  double spring_stiffness = 0.0;                   // K of a spring of rest length 2R, N/m
  double mass = 0.0;                               // of all yarns, kg
  std::array<double, 3> family_mass{};             // of the weft, stuffer and binder yarns, kg
  std::size_t des = 0, springs = 0;
  std::size_t des_not_kept = 0;                    // refused by build_weave's keep
  double deepest_overlap = 0.0;                    // over 2R, of two DEs not joined by a spring
  // Rule of mixtures of the in-plane moduli over the thickness above, per pitch: E S times the
  // yarns per unit width, E_x the weft's (K per weft column), E_y the stuffers' (K - 1 per
  // column; the crimped binders carry nothing at small strain), Pa.
  double rule_of_mixtures_x = 0.0, rule_of_mixtures_y = 0.0;
};

// A spec field (by its case-file name) that makes the weave impossible, and why.
class WeaveError : public std::invalid_argument {
 public:
  WeaveError(std::string field, const std::string& why) : std::invalid_argument(why), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

// Interpenetration the builder accepts between two DEs that share no spring, over 2R: the
// crossing yarns touch by construction, and the sampled curves round that contact off.
inline constexpr double weave_overlap_tolerance = 0.001;

// keep (optional): only the DEs whose centre it accepts are created, with the springs between
// two of them and the groups' members among them; the report's yarn figures stay the whole
// fabric's, `des` and `springs` count what was created (a coupled scene's DEM patch).
WeaveReport build_weave(DemModel& model, const WeaveSpec& spec, const std::function<bool(const Vec3&)>& keep = {});

}  // namespace arlequin::dem
