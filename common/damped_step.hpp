// SPDX-License-Identifier: GPL-3.0-or-later
// The stable step of velocity Verlet with viscous damping, shared by the DEM and the continuum.
#pragma once
#include <cmath>
#include <limits>

namespace arlequin {

// Viscous damping c (1/s) applied from the half-step velocity (force -c m v(n+1/2), used by both
// half kicks) makes a mode of frequency omega step as v' = (1 - c dt) v - dt omega^2 x,
// x' = x + dt v'; its amplification matrix has det 1 - c dt and trace 2 - c dt - dt^2 omega^2, and
// both roots stay inside the unit circle iff dt^2 omega^2 + 2 c dt < 4 (Jury's conditions; derived
// here, docs/theory.md#critical-step): dt_c = 4 / (c + sqrt(c^2 + 4 omega^2)), which is 2/omega
// undamped (to the bit) and 2/c without stiffness; infinite with neither.
inline double damped_critical_step(double omega2, double c) {
  if (!(omega2 > 0.0) && !(c > 0.0)) return std::numeric_limits<double>::infinity();
  return 4.0 / (c + std::sqrt(c * c + 4.0 * omega2));
}

}  // namespace arlequin
