// SPDX-License-Identifier: GPL-3.0-or-later
// The rise of an imposed velocity, shared by the DEM's and the continuum's velocity conditions so
// that a coupled run drives its continuum exactly as the pure-DEM run it replaces drives its DEs.
//
// Over `rise` seconds the velocity grows from 0 to its value V as V (1 - cos(pi t / rise)) / 2,
// then stays V. Neither the velocity nor the acceleration jumps (the acceleration is
// V pi / (2 rise) sin(pi t / rise), 0 at both ends): a linear rise's two jumps of the
// acceleration set off the structure's lowest modes, which light mass-proportional damping
// hardly takes out. The travel is its integral, V rise / 2 at t = rise, V (t - rise / 2) after.
#pragma once
#include <cmath>
#include <numbers>

namespace arlequin {

// The share of V reached at time t >= 0 (s); 1 from t = rise on, and at once without a rise.
inline double rise_speed_share(double t, double rise) {
  return t < rise ? 0.5 * (1.0 - std::cos(std::numbers::pi * t / rise)) : 1.0;
}

// The distance travelled by time t >= 0 per unit of V (s): the integral of rise_speed_share.
inline double rise_travel(double t, double rise) {
  if (t < rise) return 0.5 * t - rise / (2.0 * std::numbers::pi) * std::sin(std::numbers::pi * t / rise);
  return t - 0.5 * rise;
}

}  // namespace arlequin
