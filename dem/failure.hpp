// SPDX-License-Identifier: GPL-3.0-or-later
// Bond failure: events, the virial stress of a DE, and the RDEF criterion.
//
// BBF (breakable bond): each bond law judges its own bonds (beam: maximal normal stress,
// N/S + r_b |M| / I over both ends, reaching sigma_f; spring: elongation reaching its maximum).
// RDEF (seed paper Eq. 1): the virial stress of DE i over its intact bonds,
//   sigma_i = 1 / (2 Omega_i) sum_j 1/2 (r_ij (x) f_ij + f_ij (x) r_ij),
// r_ij = x_j - x_i, f_ij the force of the bond on DE i (towards j in tension, so tension is
// positive), Omega_i the DE's volume share: sphere volume / compaction (so the shares add up to
// the sample volume on average), or (our option, `volume: laguerre`) its Laguerre cell, which
// adds up to it exactly and gives a small DE among large ones the room they leave it; with
// Laguerre cells r_ij / 2 becomes the branch from the DE to the cell face (the radical plane,
// through the contact point of touching spheres), so that sigma_i is the cell's own stress. When its equivalent stress (the largest principal stress, von Mises, or
// the hydrostatic stress) reaches the threshold, every bond of the DE breaks; the DE stays and
// interacts by contact.
// Averaged RDEF (our option, not in the seed): the stress judged is
//   sigma_bar_i = sum_k Omega_k sigma_k / sum_k Omega_k over k = i and the DEs bonded to i
// that share its threshold (its material), i.e. the virial of the DE's bonded neighbourhood
// in its own material over that neighbourhood's volume. In a random packing the per-DE
// virial of one uniform strain scatters with the DE's radius against its neighbours' (the
// bond forces grow with the neighbours' size, a sphere's Omega_i with R_i^3), so the most
// loaded DEs fail long before the macroscopic strength; the neighbourhood average keeps the
// criterion's meaning (a stress of the material around the DE) with less of that scatter, and
// Laguerre volume shares remove the part of it that comes from R_i^3.
#pragma once
#include <array>
#include <cstdint>
#include <string_view>

#include "common/vec3.hpp"

namespace arlequin::dem {

// Symmetric 3x3 tensor, Voigt order xx, yy, zz, yz, xz, xy.
using Sym3 = std::array<double, 6>;

// Adds sym(a (x) b) to t.
inline void add_symmetric_product(Sym3& t, const Vec3& a, const Vec3& b) {
  t[0] += a.x * b.x;
  t[1] += a.y * b.y;
  t[2] += a.z * b.z;
  t[3] += 0.5 * (a.y * b.z + a.z * b.y);
  t[4] += 0.5 * (a.x * b.z + a.z * b.x);
  t[5] += 0.5 * (a.x * b.y + a.y * b.x);
}

// Largest eigenvalue of a symmetric tensor (closed form, trigonometric).
double max_principal(const Sym3& t);
double von_mises(const Sym3& t);
double hydrostatic(const Sym3& t);  // trace / 3 (tension positive)

// The equivalent stress an RDEF threshold is compared with.
enum class RdefEquivalent : std::uint8_t { max_principal, von_mises, hydrostatic };
double equivalent_stress(const Sym3& t, RdefEquivalent kind);
// equivalent_stress(t, kind) if it reaches `threshold`, else -1. For max_principal a cheap upper
// bound (the mean plus twice Smith's scale, without the trigonometry) settles most DEs; the
// decision is the same as equivalent_stress's to the last bit.
double equivalent_stress_reaching(const Sym3& t, RdefEquivalent kind, double threshold);
enum class RdefAverage : std::uint8_t { none, bonded_neighbours };
// The DE's volume share Omega_i: its sphere volume / compaction, or its Laguerre cell
// (laguerre_cells.hpp) in the sample's box.
enum class RdefVolume : std::uint8_t { sphere, laguerre };
// Where a DE's share of a bond's virial is taken (bond_set.hpp, add_bond_virial): half-way
// along the bond (sphere volumes), or on the radical plane (Laguerre cells).
enum class VirialBranch : std::uint8_t { half, radical };

enum class FailureCriterion : std::uint8_t { bbf, elongation, rdef, cohesive };
enum class FailureMode : std::uint8_t { tension, compression, bending, shear, torsion };
std::string_view name_of(FailureCriterion c);
std::string_view name_of(FailureMode m);

struct BreakEvent {
  double time = 0.0;          // s
  std::uint32_t set = 0;      // index of the bond set
  std::uint32_t bond = 0;     // index in the set
  FailureCriterion criterion = FailureCriterion::bbf;
  FailureMode mode = FailureMode::tension;  // dominant stress at break
  double stress = 0.0;        // criterion value at break (Pa, or elongation for springs)
  double energy = 0.0;        // elastic energy the bond held, now dissipated (J); a cohesive
                              // link's: what its softening dissipated, and what it still held
  double mode_mix = -1.0;     // cohesive links: shear share B of the opening at failure; -1 else
};

}  // namespace arlequin::dem
