// SPDX-License-Identifier: GPL-3.0-or-later
// The coupled DCB's arms at about 2 mm along x and y (1.96 mm, 2 mm) and 0.5 mm through the
// thickness (layout in dcb_arms_layout.geo): a coarser alternative to dcb_arms_coarse.geo for the
// quadratic arms, a quarter of its nodes, for the error-against-run-time sweep of
// cases/dcb_coupled (band_sweep.py; the README's table has what it costs in accuracy).
nx = 24; ny = 4; nz = 2;
Include "dcb_arms_layout.geo";
