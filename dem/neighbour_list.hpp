// SPDX-License-Identifier: GPL-3.0-or-later
// Verlet list of candidate contact pairs, built from a cell list with a skin.
//
// Contract: after build(), pairs() holds every pair i < j, not excluded, whose surfaces are
// closer than `skin` (|x_i - x_j| < R_i + R_j + skin). The list stays valid while the two
// largest displacements since the build add up to at most the skin (no pair left out can have
// closed its gap); needs_rebuild() checks exactly that.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "common/state_archive.hpp"
#include "dem/particles.hpp"

namespace arlequin::dem {

class NeighbourList {
 public:
  explicit NeighbourList(double skin) : skin_(skin) {}

  // Pairs never to list (bonded DEs interact through their bond); i < j in each.
  void set_exclusions(std::vector<std::pair<std::uint32_t, std::uint32_t>> excluded);
  void build(const ParticleSet& p);
  bool needs_rebuild(const ParticleSet& p) const;
  std::span<const std::pair<std::uint32_t, std::uint32_t>> pairs() const { return pairs_; }
  std::size_t builds() const { return builds_; }
  double skin() const { return skin_; }
  // Checkpoint: the list and the positions it was built at (so the restarted run rebuilds when
  // the uninterrupted one would, with the pairs in the same order), under `prefix`. The
  // exclusions are the caller's to set again. load_state: StateMismatch unless the list is of
  // n_particles DEs (each pair i < j < n_particles).
  void save_state(StateArchive& archive, const std::string& prefix) const;
  void load_state(const StateArchive& archive, const std::string& prefix, std::size_t n_particles);

  // A DE of a radius above this ratio to the median is tested against every DE rather than
  // binned: the cells stay the size of the many small DEs.
  static constexpr double large_radius_ratio = 4.0;
  // The radius above which a DE is large: large_radius_ratio x the median of `radii` (not
  // empty); `scratch` takes a copy of them (the Laguerre cells bin their spheres the same way).
  static double large_radius(std::span<const double> radii, std::vector<double>& scratch);

 private:
  double skin_;
  std::vector<std::uint64_t> excluded_;  // sorted keys i * 2^32 + j
  std::vector<std::uint32_t> excluded_start_;  // per DE, where its keys begin in excluded_ (build's)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs_;
  std::vector<Vec3> position_at_build_;
  std::vector<std::uint32_t> cell_start_;  // build's grid: per cell, where its DEs begin in cell_des_
  std::vector<std::uint32_t> cell_des_;    // the binned DEs, by cell, then index
  std::vector<std::uint32_t> scratch_next_;
  std::vector<std::uint32_t> cell_of_de_;  // build's: each binned DE's cell
  std::vector<Vec3> binned_position_;      // build's: cell_des_'s positions and radii, in its order
  std::vector<double> binned_radius_;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> found_;  // build's pairs, per thread
  std::vector<std::uint32_t> first_start_;  // build's: per DE, where its pairs (as the first) begin
  mutable std::vector<std::pair<double, double>> largest_moves_;  // needs_rebuild's, per thread
  std::vector<std::uint32_t> large_;   // DEs kept out of the cells (build's scratch)
  std::vector<double> scratch_radius_;  // build's scratch, for the median radius
  std::size_t builds_ = 0;
};

}  // namespace arlequin::dem
