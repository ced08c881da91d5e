// SPDX-License-Identifier: GPL-3.0-or-later
// An L-shaped block of three unit cubes fused into one volume: its mesh has no faces on the planes
// x = 1 and y = 1 inside it, so natural neighbours cannot cut it into convex pieces (a test of
// that refusal). Element size is set by the caller.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {1, 0, 0, 1, 1, 1};
Box(3) = {0, 1, 0, 1, 1, 1};
BooleanUnion{ Volume{1}; Delete; }{ Volume{2, 3}; Delete; }
Physical Surface("boundary") = Surface{:};
Physical Volume("block") = Volume{:};
