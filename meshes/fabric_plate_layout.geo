// SPDX-License-Identifier: GPL-3.0-or-later
// The homogenised woven plate of the coupled impact (cases/fabric_impact_coupled), for
// fabric_plate.geo and fabric_plate_large.geo, which set first: the fabric's extent Lx (weft,
// along x) and Ly (warp, along y), its clamped border c, the thickness range z0..z1 (the DEM
// weave's bounding box: outer faces of the binders) and the element size h in the plane.
// The plate spans the free fabric, [c, Lx - c] x [c, Ly - c]: its four side faces, the physical
// surface "edges", are where the pure-DEM case clamps its yarns (the DEs within c of the
// border), so holding them clamps the same span. One element layer through the thickness.
// Structured: a line along x extruded along y, then through z; tetrahedra (no recombination).
Point(1) = {c, c, z0};
ax[] = Extrude {Lx - 2 * c, 0, 0} { Point{1}; Layers{Ceil((Lx - 2 * c) / h)}; };
ay[] = Extrude {0, Ly - 2 * c, 0} { Line{ax[1]}; Layers{Ceil((Ly - 2 * c) / h)}; };
az[] = Extrude {0, 0, z1 - z0} { Surface{ay[1]}; Layers{1}; };
Physical Volume("plate") = {az[1]};
Physical Surface("edges") = {az[2], az[3], az[4], az[5]};
