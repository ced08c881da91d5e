// SPDX-License-Identifier: GPL-3.0-or-later
// Two unit cubes stacked along z and meshed apart, as two_blocks.geo, but structured with
// different node counts (4 and 5 along each edge): the face z = 1 carries the nodes of both
// bodies only at its corners. Joining the bodies there must be refused (test of
// MeshSource::joined).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {0, 0, 1, 1, 1, 1};
lower_faces() = Abs(Boundary{ Volume{1}; });
upper_faces() = Abs(Boundary{ Volume{2}; });
Transfinite Curve {Unique(Abs(Boundary{ Surface{lower_faces()}; }))} = 4;
Transfinite Curve {Unique(Abs(Boundary{ Surface{upper_faces()}; }))} = 5;
Transfinite Surface {:};
Transfinite Volume {:};
Physical Volume("lower") = {1};
Physical Volume("upper") = {2};
