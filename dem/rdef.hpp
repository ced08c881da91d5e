// SPDX-License-Identifier: GPL-3.0-or-later
// RDEF, the virial-stress element failure criterion (failure.hpp, docs/theory.md#rdef): every
// bond of a DE breaks when the equivalent stress of its virial stress reaches the DE's
// threshold; Omega_i = sphere volume / compaction, or the DE's Laguerre cell (`volume`,
// computed once in the reference configuration) with the bonds' virial taken on the cells'
// faces (VirialBranch::radical). A DE in one of the listed groups takes that group's threshold
// (the first listed that holds it), any other DE `threshold` (infinite: such DEs never fail by
// RDEF). With `average` = bonded_neighbours the stress judged is the volume average over the
// DE and the DEs of its threshold group it is still bonded to, which damps the DE-to-DE
// scatter of a random packing.
//
// Contract: prepare() once the DEs are final (DemModel::finalize); each breakable step's force
// pass carries scan_into()'s ForceScan, which accumulates the virial; find_failures() then
// reads it, once, for the events of that configuration.
#pragma once
#include <memory>
#include <utility>
#include <vector>

#include "dem/bonds/bond_set.hpp"
#include "dem/failure.hpp"
#include "dem/particles.hpp"

namespace arlequin::dem {

struct RdefSettings {
  double threshold = 0.0;  // Pa
  RdefEquivalent equivalent = RdefEquivalent::max_principal;
  double compaction = 0.63;  // solid fraction of the sample, for the DE's volume share
  std::vector<std::pair<int, double>> group_thresholds;  // (group index, Pa), e.g. per material
  RdefAverage average = RdefAverage::none;
  RdefVolume volume = RdefVolume::sphere;
};

class RdefCriterion {
 public:
  explicit RdefCriterion(RdefSettings settings) : settings_(std::move(settings)) {}

  // Each DE's threshold (that of the first of settings.group_thresholds whose group holds it;
  // group_members: per group, its DEs), threshold group and volume share. InputError for an
  // empty Laguerre cell.
  void prepare(const ParticleSet& p, const std::vector<std::vector<std::uint32_t>>& group_members);
  // Makes `scan` accumulate every intact bond's virial, on the branch the volumes ask for.
  void scan_into(ForceScan& scan);
  // The events of every intact bond one of whose DEs reached its threshold, in the configuration
  // of the force pass that scan_into() prepared.
  void find_failures(const ParticleSet& p, const std::vector<std::unique_ptr<BondSet>>& sets, double time,
                     std::vector<BreakEvent>& events);

 private:
  void average_over_bonded_neighbours(const std::vector<std::unique_ptr<BondSet>>& sets);

  RdefSettings settings_;
  std::vector<double> threshold_;  // Pa, per DE
  std::vector<int> class_;         // per DE: index of its group threshold, -1 for the default
  std::vector<double> omega_;      // each DE's volume share Omega_i, m^3
  std::vector<Sym3> stress_;       // scratch: virial per DE (force pass), then stress
  std::vector<double> equivalent_;  // scratch: its equivalent stress, or -1 below the threshold
  std::vector<Sym3> average_;       // scratch: neighbourhood sum of sigma Omega
  std::vector<double> volume_;      // scratch: neighbourhood volume, m^3
};

// Omega_i = (4/3) pi R_i^3 / compaction, m^3.
std::vector<double> sphere_volume_shares(const ParticleSet& p, double compaction);
// sigma_i = virial_i / (2 Omega_i) (seed Eq. 1), in place.
void divide_by_volumes(const std::vector<double>& omega, std::vector<Sym3>& virial);

}  // namespace arlequin::dem
