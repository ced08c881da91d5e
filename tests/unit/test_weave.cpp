// SPDX-License-Identifier: GPL-3.0-or-later
// The 3D-interlock builder (dem/weave.hpp) against the closed forms of its geometry
// (docs/theory.md#weave): yarn counts, DEs per chain, lengths, mass and areal density,
// spring stiffness; no interpenetration; a coupled scene's patch is the whole weave's part there;
// impossible weaves refused by the field at fault.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "dem/bonds/spring_bond.hpp"
#include "dem/weave.hpp"

namespace arlequin::dem {
namespace {

constexpr double pi = std::numbers::pi;

// 6 x 8 mm: 4 weft columns 2 mm apart in 3 layers, 3 stuffer columns 2 mm apart in 2 layers,
// 2 binders; yarns 0.9 x 0.3 mm of 3 chains of DEs of radius 0.15 mm.
WeaveSpec small_weave() {
  WeaveSpec s;
  s.length_x = 6e-3, s.length_y = 8e-3;
  s.weft_layers = 3;
  s.weft_spacing = 2e-3, s.warp_spacing = 2e-3;
  s.yarn_width = 0.9e-3, s.yarn_thickness = 0.3e-3;
  s.chains_across = 3, s.chains_through = 1;
  s.clamp_width = 1e-3;
  s.density = 1310.0, s.modulus = 62e9, s.section = pi * 0.9e-3 * 0.3e-3 / 4.0;
  s.failure_strain = 0.035;
  return s;
}

// Arc length of z = A cos(pi y / s + phase) over [0, L] by composite Simpson (independent of
// the builder's polyline).
double cosine_length(double A, double s, double L) {
  const int n = 20000;
  const double h = L / n, k = pi / s;
  double sum = 0.0;
  for (int m = 0; m <= n; ++m) {
    const double slope = A * k * std::sin(k * (m * h - 0.5 * s));
    sum += (m == 0 || m == n ? 1.0 : m % 2 ? 4.0 : 2.0) * std::sqrt(1.0 + slope * slope);
  }
  return sum * h / 3.0;
}

TEST(Weave, CountsLengthsMassAndArealDensityMatchTheClosedForms) {
  const WeaveSpec s = small_weave();
  DemModel model;
  const WeaveReport r = build_weave(model, s);
  // N_y = floor(8 / 2) = 4 columns x 3 layers; N_x = floor(6 / 2) = 3 stuffer columns x 2
  // layers; N_x - 1 = 2 binders.
  EXPECT_EQ(r.wefts, 12);
  EXPECT_EQ(r.stuffers, 6);
  EXPECT_EQ(r.binders, 2);
  EXPECT_DOUBLE_EQ(r.radius, 0.15e-3);
  EXPECT_NEAR(r.weft_length, 6e-3, 1e-15);
  EXPECT_NEAR(r.stuffer_length, 8e-3, 1e-15);
  // The binder: a cosine of the reported amplitude; the polyline's length to 1e-4 of the
  // quadrature's (its chord error is ~(kappa h)^2 / 24 ~ 3e-5 at the peaks).
  const double Lb = cosine_length(r.amplitude, s.weft_spacing, s.length_y);
  EXPECT_NEAR(r.binder_length / Lb, 1.0, 1e-4);
  EXPECT_NEAR(r.crimp, Lb / s.length_y - 1.0, 1e-4);
  // It passes over the top weft: A >= K t.
  EXPECT_GE(r.amplitude, 3 * s.yarn_thickness);

  // DEs: a straight chain of length L holds floor(L / 2R) + 1 DEs.
  const std::size_t weft_chain = 20 + 1, stuffer_chain = 26 + 1;
  const std::size_t straight = 12 * 3 * weft_chain + 6 * 3 * stuffer_chain;
  EXPECT_EQ(model.members(model.group_index("weft")).size(), 12 * 3 * weft_chain);
  EXPECT_EQ(model.members(model.group_index("stuffer")).size(), 6 * 3 * stuffer_chain);
  EXPECT_EQ(model.members(model.group_index("weft_1_2")).size(), 3 * weft_chain);
  const std::size_t binder_des = model.members(model.group_index("binder")).size();
  EXPECT_EQ(straight + binder_des, model.particles.size());
  EXPECT_EQ(r.des, model.particles.size());
  // One spring fewer than DEs per chain: 3 chains a yarn, 20 yarns.
  EXPECT_EQ(r.springs, model.particles.size() - 20 * 3);

  // Mass rho S L per yarn; areal density over L_x L_y.
  double mass = 0.0;
  for (std::size_t i = 0; i < model.particles.size(); ++i) mass += model.particles.mass(i);
  const double closed = s.density * s.section * (12 * 6e-3 + 6 * 8e-3 + 2 * Lb);
  EXPECT_NEAR(mass / closed, 1.0, 1e-4);
  // Per family (the plate's inertia shares): 12 weft yarns of 6 mm, 6 stuffers of 8 mm (exact),
  // 2 binders of Lb (the quadrature above, hence the total's tolerance).
  const double family[3] = {12 * 6e-3, 6 * 8e-3, 2 * Lb};
  for (int f = 0; f < 3; ++f) EXPECT_NEAR(r.family_mass[f] / (s.density * s.section * family[f]), 1.0, f < 2 ? 1e-12 : 1e-4) << f;
  EXPECT_NEAR(r.areal_density / (closed / (6e-3 * 8e-3)), 1.0, 1e-4);
  EXPECT_NEAR(r.thickness, 2 * r.amplitude + s.yarn_thickness, 1e-15);
  EXPECT_NEAR(r.fibre_volume_fraction * 6e-3 * 8e-3 * r.thickness / (s.section * (12 * 6e-3 + 6 * 8e-3 + 2 * Lb)), 1.0, 1e-4);
  // Rule of mixtures per pitch: K weft yarns per weft column, K - 1 stuffers per stuffer column.
  EXPECT_NEAR(r.rule_of_mixtures_x * s.weft_spacing * r.thickness / (s.modulus * s.section * s.weft_layers), 1.0, 1e-12);
  EXPECT_NEAR(r.rule_of_mixtures_y * s.warp_spacing * r.thickness / (s.modulus * s.section * (s.weft_layers - 1)), 1.0, 1e-12);

  // Seed Eq. 8: a weft chain has n_s = 20 springs of 0.3 mm: K = (n_s / n_p) E S / L_y.
  const auto& weft = dynamic_cast<const SpringBondSet&>(*model.bond_sets()[0]);
  EXPECT_EQ(model.bond_sets()[0]->name, "weft");
  EXPECT_NEAR(weft.stiffness_of(0) / (20.0 / 3.0 * s.modulus * s.section / 6e-3), 1.0, 1e-12);
  EXPECT_NEAR(r.spring_stiffness, s.modulus * s.section / (3 * 2 * r.radius), 1e-6);

  // Edges: the DEs within 1 mm of the border, none of the others.
  const auto& edges = model.members(model.group_index("edges"));
  std::size_t expected = 0;
  for (const Vec3& x : model.particles.position) expected += std::min({x.x, 6e-3 - x.x, x.y, 8e-3 - x.y}) < 1e-3;
  EXPECT_EQ(edges.size(), expected);
  EXPECT_GT(edges.size(), 0u);
}

// No two DEs that share no spring interpenetrate by more than the stated tolerance (1 % of
// 2R), by brute force over all pairs; and the amplitude is the smallest that clears: a crimp
// a little below the one reported is refused by name.
TEST(Weave, YarnsDoNotInterpenetrateAndTheDefaultCrimpIsTheSmallestThatClears) {
  WeaveSpec s = small_weave();
  DemModel model;
  const WeaveReport r = build_weave(model, s);
  const ParticleSet& p = model.particles;
  std::vector<std::uint8_t> joined_next(p.size(), 0);  // DE i and i + 1 share a spring
  for (const auto& set : model.bond_sets())
    for (std::size_t b = 0; b < set->size(); ++b) {
      ASSERT_EQ(set->second()[b], set->first()[b] + 1);
      joined_next[set->first()[b]] = 1;
    }
  double deepest = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      if (j == i + 1 && joined_next[i]) continue;
      deepest = std::max(deepest, (2 * r.radius - norm(p.position[j] - p.position[i])) / (2 * r.radius));
    }
  EXPECT_LE(deepest, weave_overlap_tolerance);
  EXPECT_NEAR(deepest, r.deepest_overlap, 1e-12);

  s.crimp = 0.97 * r.crimp;
  DemModel refused;
  try {
    build_weave(refused, s);
    FAIL() << "a crimp below the clearing one was accepted";
  } catch (const WeaveError& e) {
    EXPECT_EQ(e.field(), "crimp");
    EXPECT_NE(std::string(e.what()).find("cut through the weft"), std::string::npos) << e.what();
  }
  EXPECT_EQ(refused.particles.size(), 0u);
  // Above it, the crimp asked for is the crimp built.
  s.crimp = 1.1 * r.crimp;
  DemModel steeper;
  EXPECT_NEAR(build_weave(steeper, s).crimp, s.crimp, 1e-6);
}

// A coupled scene's patch (keep: x < 2.5 mm): the DEs created are the full weave's DEs there,
// at the same places and with the same masses; every spring joins two of them and is one of the
// full weave's; every group holds only them; the report's yarn figures stay the whole fabric's.
TEST(Weave, AKeptPatchIsThePartOfTheWholeWeaveItCovers) {
  const WeaveSpec s = small_weave();
  DemModel whole, patch;
  const WeaveReport all = build_weave(whole, s);
  const auto inside = [](const Vec3& x) { return x.x < 2.5e-3; };
  const WeaveReport kept = build_weave(patch, s, inside);
  std::vector<std::size_t> of_whole;  // the whole weave's index of each kept DE, in order
  for (std::size_t i = 0; i < whole.particles.size(); ++i)
    if (inside(whole.particles.position[i])) of_whole.push_back(i);
  ASSERT_EQ(patch.particles.size(), of_whole.size());
  ASSERT_GT(of_whole.size(), 100u);
  EXPECT_LT(of_whole.size(), whole.particles.size());
  EXPECT_EQ(kept.des, of_whole.size());
  EXPECT_EQ(kept.des_not_kept, all.des - kept.des);
  for (std::size_t k = 0; k < of_whole.size(); ++k) {
    EXPECT_EQ(patch.particles.position[k], whole.particles.position[of_whole[k]]);
    EXPECT_EQ(patch.particles.mass(k), whole.particles.mass(of_whole[k]));
  }
  std::set<std::pair<std::size_t, std::size_t>> whole_springs;
  for (const auto& set : whole.bond_sets())
    for (std::size_t b = 0; b < set->size(); ++b) whole_springs.insert({set->first()[b], set->second()[b]});
  std::size_t springs = 0;
  for (const auto& set : patch.bond_sets())
    for (std::size_t b = 0; b < set->size(); ++b, ++springs)
      EXPECT_TRUE(whole_springs.count({of_whole[set->first()[b]], of_whole[set->second()[b]]}));
  std::size_t expected = 0;  // the whole weave's springs between two kept DEs
  for (const auto& [i, j] : whole_springs) expected += inside(whole.particles.position[i]) && inside(whole.particles.position[j]);
  EXPECT_EQ(springs, expected);
  EXPECT_EQ(kept.springs, expected);
  for (const char* family : {"weft", "stuffer", "binder", "edges"})
    for (std::uint32_t i : patch.members(patch.group_index(family))) EXPECT_LT(i, patch.particles.size());
  EXPECT_EQ(kept.wefts, all.wefts);
  EXPECT_DOUBLE_EQ(kept.areal_density, all.areal_density);
}

TEST(Weave, ImpossibleWeavesNameTheFieldAtFault) {
  const auto field_of = [](WeaveSpec s) {
    DemModel model;
    try {
      build_weave(model, s);
    } catch (const WeaveError& e) {
      return e.field();
    }
    return std::string("(built)");
  };
  WeaveSpec s = small_weave();
  s.chains_across = 4;  // 4 chains of 0.3 mm in 0.9 mm
  EXPECT_EQ(field_of(s), "chains_across");
  s = small_weave();
  s.warp_spacing = 1.5e-3;  // a binder between stuffers 1.5 mm apart cuts them (0.9 mm yarns)
  EXPECT_EQ(field_of(s), "warp_spacing");
  s = small_weave();
  s.weft_spacing = 0.8e-3;  // weft columns 0.9 mm wide, 0.8 mm apart
  EXPECT_EQ(field_of(s), "weft_spacing");
  s = small_weave();
  s.length_y = 3e-3;  // one weft column
  EXPECT_EQ(field_of(s), "weft_spacing");
  EXPECT_EQ(field_of(small_weave()), "(built)");
}

}  // namespace
}  // namespace arlequin::dem
