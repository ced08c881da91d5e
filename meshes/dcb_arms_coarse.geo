// SPDX-License-Identifier: GPL-3.0-or-later
// The coupled DCB's arms at 1 mm along x and y and 0.5 mm through the thickness (three elements
// per arm; layout in dcb_arms_layout.geo): the case's arms with quadratic elements
// (docs/decisions.md#d48), and the reduced coupled DCB of the test suite (linear), whose DEs are
// twice the case's.
nx = 46; ny = 7; nz = 2;
Include "dcb_arms_layout.geo";
