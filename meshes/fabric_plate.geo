// SPDX-License-Identifier: GPL-3.0-or-later
// The seed's 22 x 50 mm target (cases/fabric_impact/case.yaml's weave: clamped 1 mm, binders
// from z = -0.726 to 1.926 mm) as a homogenised plate at 1 mm in the plane
// (fabric_plate_layout.geo).
Lx = 22e-3; Ly = 50e-3; c = 1e-3; z0 = -0.726e-3; z1 = 1.926e-3; h = 1e-3;
Include "fabric_plate_layout.geo";
