// SPDX-License-Identifier: GPL-3.0-or-later
#include "dem/rdef.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "common/error.hpp"
#include "dem/laguerre_cells.hpp"

namespace arlequin::dem {

void RdefCriterion::prepare(const ParticleSet& p, const std::vector<std::vector<std::uint32_t>>& group_members) {
  threshold_.assign(p.size(), settings_.threshold);
  class_.assign(p.size(), -1);
  // Last to first, so that the first listed group holding a DE sets its threshold.
  for (std::size_t g = settings_.group_thresholds.size(); g-- > 0;)
    for (const std::uint32_t i : group_members[settings_.group_thresholds[g].first]) {
      threshold_[i] = settings_.group_thresholds[g].second;
      class_[i] = static_cast<int>(g);
    }
  omega_ = settings_.volume == RdefVolume::laguerre ? laguerre_volumes(p.reference, p.radius)
                                                    : sphere_volume_shares(p, settings_.compaction);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!(omega_[i] > 0.0))
      throw InputError("RDEF: DE " + std::to_string(i) + " has an empty Laguerre cell (its centre lies in its neighbours' " +
                       "cells: spheres overlapping by more than their radii); use volume: sphere");
}

void RdefCriterion::scan_into(ForceScan& scan) {
  stress_.assign(omega_.size(), Sym3{});
  scan.virial = stress_;
  scan.branch = settings_.volume == RdefVolume::laguerre ? VirialBranch::radical : VirialBranch::half;
}

void RdefCriterion::find_failures(const ParticleSet& p, const std::vector<std::unique_ptr<BondSet>>& sets, double time,
                                  std::vector<BreakEvent>& events) {
  divide_by_volumes(omega_, stress_);  // the virial of the step's force pass
  if (settings_.average == RdefAverage::bonded_neighbours) average_over_bonded_neighbours(sets);
  equivalent_.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)  // -1: the DE holds
    equivalent_[i] = equivalent_stress_reaching(stress_[i], settings_.equivalent, threshold_[i]);
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const BondSet& set = *sets[s];
    for (std::size_t b = 0; b < set.size(); ++b) {
      const std::uint32_t i = set.first()[b], j = set.second()[b];
      const double stress = std::max(equivalent_[i], equivalent_[j]);
      if (set.broken()[b] || stress < 0.0) continue;
      events.push_back({time, static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(b), FailureCriterion::rdef,
                        FailureMode::tension, stress, set.bond_energy(b, p)});
    }
  }
}

void RdefCriterion::average_over_bonded_neighbours(const std::vector<std::unique_ptr<BondSet>>& sets) {
  // sum Omega sigma / sum Omega over the DE and its partners with the DE's own threshold (its
  // material): across a fibre-matrix interface the stresses differ by the stiffness ratio, and
  // mixing them would fail the matrix at once.
  std::vector<Sym3>& sigma = stress_;
  const std::size_t n = sigma.size();
  average_.resize(n);
  volume_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    volume_[i] = omega_[i];
    for (int c = 0; c < 6; ++c) average_[i][c] = omega_[i] * sigma[i][c];
  }
  for (const auto& set : sets)
    for (std::size_t b = 0; b < set->size(); ++b) {
      if (set->broken()[b]) continue;
      const std::uint32_t i = set->first()[b], j = set->second()[b];
      if (class_[i] != class_[j]) continue;
      for (int c = 0; c < 6; ++c) {
        average_[i][c] += omega_[j] * sigma[j][c];
        average_[j][c] += omega_[i] * sigma[i][c];
      }
      volume_[i] += omega_[j];
      volume_[j] += omega_[i];
    }
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 6; ++c) sigma[i][c] = average_[i][c] / volume_[i];
}

std::vector<double> sphere_volume_shares(const ParticleSet& p, double compaction) {
  std::vector<double> omega(p.size());
  for (std::size_t i = 0; i < omega.size(); ++i) omega[i] = 4.0 / 3.0 * std::numbers::pi * std::pow(p.radius[i], 3) / compaction;
  return omega;
}

void divide_by_volumes(const std::vector<double>& omega, std::vector<Sym3>& virial) {
  for (std::size_t i = 0; i < virial.size(); ++i)
    for (double& c : virial[i]) c /= 2.0 * omega[i];
}

}  // namespace arlequin::dem
