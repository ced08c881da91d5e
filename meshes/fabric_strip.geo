// SPDX-License-Identifier: GPL-3.0-or-later
// A woven strip 40 x 4 mm as a homogenised plate at 1 mm (fabric_plate_layout.geo, no clamped
// border): the plate of cases/fabric_impact_coupled/yarn_pulse.yaml, whose weave has the impact
// case's yarns and thickness (z from -0.726 to 1.926 mm).
Lx = 40e-3; Ly = 4e-3; c = 0; z0 = -0.726e-3; z1 = 1.926e-3; h = 1e-3;
Include "fabric_plate_layout.geo";
