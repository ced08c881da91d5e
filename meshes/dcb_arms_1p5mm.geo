// SPDX-License-Identifier: GPL-3.0-or-later
// The coupled DCB's arms at 1.5 mm along x and y and 0.5 mm through the thickness (layout in
// dcb_arms_layout.geo): between dcb_arms_coarse.geo (1 mm) and dcb_arms_2mm.geo, for the
// error-against-run-time sweep of cases/dcb_coupled (band_sweep.py; the README's table).
nx = 31; ny = 5; nz = 2;
Include "dcb_arms_layout.geo";
