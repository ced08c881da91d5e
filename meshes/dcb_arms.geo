// SPDX-License-Identifier: GPL-3.0-or-later
// The coupled DCB's arms for linear elements (cases/dcb_coupled's P1 rows; its case takes the
// coarse mesh with quadratic ones, docs/decisions.md#d48; layout in dcb_arms_layout.geo): 0.5 mm
// along x and y, 0.25 mm through the thickness (six elements per arm), so node planes lie every
// 0.25 mm in z, where the band's overlap faces fall for half-thicknesses and widths in steps of
// 0.25 mm.
nx = 91; ny = 13; nz = 3;
Include "dcb_arms_layout.geo";
