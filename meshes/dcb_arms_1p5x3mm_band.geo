// SPDX-License-Identifier: GPL-3.0-or-later
// dcb_arms_1p5x3mm.geo with the two 0.5 mm layers next to the mid-plane cut in two (0.25 mm
// elements through the thickness where a DEM band's overlap lies), for studies of how the
// hybrid arms' stiffness depends on where the overlap's weight ramp falls in the elements
// (cases/dcb_coupled/README.md). The thinner layers halve the continuum's critical step.
nx = 31; ny = 3; nz = 2; nz_band = 3;
Include "dcb_arms_layout.geo";
