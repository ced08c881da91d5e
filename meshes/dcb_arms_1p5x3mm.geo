// SPDX-License-Identifier: GPL-3.0-or-later
// The coupled DCB's arms at 1.5 mm along x, 3 mm across y and 0.5 mm through the thickness
// (layout in dcb_arms_layout.geo), for the band that follows the crack (cases/dcb_coupled,
// README.md's fast configuration): dcb_arms_1p5mm.geo with half its element columns across the
// width, where the DCB's load and crack front are uniform and P2 elements take the arms'
// anticlastic bending; the element length along the crack path, which sets how the load swings
// as the damage front crosses an element, is kept (docs/decisions.md#d59).
nx = 31; ny = 3; nz = 2;
Include "dcb_arms_layout.geo";
