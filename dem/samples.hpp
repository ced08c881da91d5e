// SPDX-License-Identifier: GPL-3.0-or-later
// Sample builders: regular arrangements of DEs and bonding by proximity.
// (Random dense packings come with the composite REV work.)
#pragma once
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "dem/particles.hpp"

namespace arlequin::dem {

// counts[0] x counts[1] x counts[2] DEs on a simple-cubic lattice starting at origin.
void build_lattice(ParticleSet& p, const Vec3& origin, std::array<int, 3> counts, double spacing,
                   double radius, double density);

// count DEs from start along the unit direction, spacing apart.
void build_chain(ParticleSet& p, const Vec3& start, const Vec3& direction, int count,
                 double spacing, double radius, double density);

// Every pair i < j with |x_i - x_j| < (R_i + R_j)(1 + tolerance), sorted.
std::vector<std::pair<std::uint32_t, std::uint32_t>> close_pairs(const ParticleSet& p, double tolerance);

}  // namespace arlequin::dem
