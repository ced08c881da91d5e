// SPDX-License-Identifier: GPL-3.0-or-later
// Small DEM set-ups shared by the unit and verification tests.
#pragma once
#include <memory>
#include <numbers>

#include "dem/bonds/beam_bond.hpp"
#include "dem/dem_model.hpp"
#include "dem/samples.hpp"

namespace arlequin::test {

// R1 beam (N, mm units): R = 1 mm, L0 = 2 mm, r_mu = 0.5, E = 1e5 N/mm^2, nu = 0.3.
struct R1Beam {
  static constexpr double E = 1e5, nu = 0.3, r_mu = 0.5, R = 1.0, L = 2.0;
  static constexpr double rb = r_mu * R;
  static constexpr double S = std::numbers::pi * rb * rb;
  static constexpr double I = std::numbers::pi * rb * rb * rb * rb / 4.0;
  static constexpr double J = 2.0 * I;
  static constexpr double G = E / (2.0 * (1.0 + nu));
};

// Every touching pair of the model's DEs bonded by one beam batch, then finalized.
inline dem::BeamBondSet& bond_all_touching(dem::DemModel& model, const dem::BeamBondSet::Parameters& prm) {
  auto set = std::make_unique<dem::BeamBondSet>(prm);
  for (auto [i, j] : dem::close_pairs(model.particles, 0.01)) set->add(i, j, model.particles);
  auto& ref = *set;
  model.add_bond_set(std::move(set));
  return ref;
}

}  // namespace arlequin::test
