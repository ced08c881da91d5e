// SPDX-License-Identifier: GPL-3.0-or-later
// The seed's target four times larger in area, 44 x 100 mm (cases/fabric_impact/large.yaml's
// weave: clamped 1 mm, binders from z = -0.726 to 1.926 mm), as a homogenised plate at 1 mm in
// the plane (fabric_plate_layout.geo): the plate of cases/fabric_impact_coupled/large.yaml.
Lx = 44e-3; Ly = 100e-3; c = 1e-3; z0 = -0.726e-3; z1 = 1.926e-3; h = 1e-3;
Include "fabric_plate_layout.geo";
