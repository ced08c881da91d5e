// SPDX-License-Identifier: GPL-3.0-or-later
// Dense random packings of spherical DEs in a region: the seed's "first challenge"
// (docs/theory.md#packing). Radii follow a truncated Gaussian; as many DEs as the target
// compaction needs are inserted at random at reduced size, then grown to full size in steps
// with the overlaps relaxed after each (athermal compression to just below jamming). Every
// pair closer than (R_i + R_j)(1 + bond_tolerance) counts as a bond for the coordination.
//
// Contract of build_packing:
//  - appends the DEs to p, at rest, identity orientation, groups 0, mass from `density`;
//    DEs already in p are ignored (neither moved nor avoided);
//  - the spheres lie in the region and overlap each other and the walls by at most 1e-3 mean
//    radii (report.max_overlap; ~1e-5 in practice), and the interior mean coordination is at
//    least min_coordination; otherwise RunError says which to change (a target compaction
//    above jamming for the distribution, or too small a bond tolerance);
//  - the result depends on the spec only: same spec and seed, same bits (single thread, no
//    unordered containers, own normal transform of std::mt19937_64 words), on one platform
//    (std::log / std::cos are libm's);
//  - throws std::invalid_argument for a bad spec or an unbounded region (half space,
//    infinite cylinder).
//
// The number of DEs follows from the region volume, the target compaction and the radius
// distribution. Wall layers are looser than the bulk, so the count allows for a wall deficit
// (packing.cpp), corrected by a second pass when the first misses the target by > 0.005.
// Everything is measured in the interior, the region eroded by interior_margin mean radii (the
// whole region if it is too small): compaction as the share of the interior's volume inside
// spheres (sampled on a lattice of quarter-radius spacing), coordination over the DEs centred
// in it, fabric over the bonds with both ends in it.
#pragma once
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "common/region.hpp"
#include "dem/particles.hpp"

namespace arlequin::dem {

struct PackingSpec {
  Region region;                    // box, finite cylinder or sphere
  double mean_radius = 0.0;         // m, mean of the untruncated Gaussian
  double relative_std = 0.0;        // standard deviation / mean radius
  double truncation = 2.0;          // radii kept within mean (1 +- truncation relative_std)
  double target_compaction = 0.63;  // solid fraction of the interior
  double min_coordination = 6.0;    // required mean bonds per DE, in the interior
  std::uint64_t seed = 1;
  double bond_tolerance = 0.03;     // a pair is bonded if |x_i - x_j| < (R_i + R_j)(1 + tol)
  bool operator==(const PackingSpec&) const = default;
};

struct PackingReport {
  std::size_t count = 0;                    // DEs appended
  double compaction = 0.0;                  // solid fraction of the interior
  double mean_coordination = 0.0;           // 2 bonds / DEs, all DEs (wall layers included)
  double interior_coordination = 0.0;       // mean bonds of the interior DEs
  std::array<double, 3> fabric_eigenvalues{};  // of (1/N_c) sum n (x) n, interior pairs, ascending
  double max_overlap = 0.0;                 // largest DE-DE or DE-wall overlap / mean radius
  std::vector<std::pair<double, std::size_t>> radius_histogram;  // (bin centre m, DEs)
  double seconds = 0.0;                     // wall-clock time of build_packing
};

// The interior: points at least this many mean radii inside the region's boundary.
inline constexpr double interior_margin = 2.0;

PackingReport build_packing(ParticleSet& p, const PackingSpec& spec, double density);

// About how many DEs build_packing makes for the spec: the region's volume times the target
// compaction over the mean sphere volume, 4/3 pi R^3 (1 + 3 std^2) (the truncation ignored).
// For refusing a packing beyond the memory before it is built; throws as build_packing does
// for a bad spec or an unbounded region.
double estimated_count(const PackingSpec& spec);

}  // namespace arlequin::dem
