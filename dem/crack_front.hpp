// SPDX-License-Identifier: GPL-3.0-or-later
// Where an interface has failed: the crack tip and the damage front of a bond set with a damage
// variable (cohesive links) or broken flags, measured along a direction and averaged across
// the width (docs/theory.md#crack-measures).
//
// Each link sits at the mid-point of its DEs' reference positions. The width (along `across`)
// is cut into `bins` equal strips between the outermost links; in each strip the tip is the
// furthest position along `axis` of a fully damaged (or broken) link, the damage front that of
// a link with any damage; both are averaged over the strips that hold such a link (NaN when
// none does).
#pragma once
#include "dem/bonds/bond_set.hpp"

namespace arlequin::dem {

struct CrackFront {
  double tip = 0.0;           // m, along axis
  double damage_front = 0.0;  // m, along axis
  double dissipated = 0.0;    // J, by the links' softening (0 for laws without)
};

CrackFront measure_crack(const BondSet& set, const ParticleSet& p, const Vec3& axis, const Vec3& across, int bins);

}  // namespace arlequin::dem
