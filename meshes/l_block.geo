// SPDX-License-Identifier: GPL-3.0-or-later
// An L-shaped block, not convex: the unit cube [0,1]^3, a slab [1,1.1] x [0,1]^2 beside it and
// the cube [0,1] x [1,2] x [0,1], fragmented, so the mesh has faces on the planes x = 1 and
// y = 1 that cut it into those three boxes (tests of natural neighbours over convex pieces that
// share faces; the slab's far face is meshed apart from its near one). Element size is set by
// the caller. Boundary groups by outward normal, the notch's faces with the outer ones; the
// three boxes are volume groups too.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {1, 0, 0, 0.1, 1, 1};
Box(3) = {0, 1, 0, 1, 1, 1};
BooleanFragments{ Volume{1, 2, 3}; Delete; }{}
e = 1e-6;
Physical Surface("boundary") = CombinedBoundary{ Volume{:}; };
Physical Surface("xmin") = Surface In BoundingBox{-e, -e, -e, e, 2 + e, 1 + e};
Physical Surface("xmax") = {Surface In BoundingBox{1.1 - e, -e, -e, 1.1 + e, 1 + e, 1 + e},
                            Surface In BoundingBox{1 - e, 1 - e, -e, 1 + e, 2 + e, 1 + e}};
Physical Surface("ymin") = Surface In BoundingBox{-e, -e, -e, 1.1 + e, e, 1 + e};
Physical Surface("ymax") = {Surface In BoundingBox{-e, 2 - e, -e, 1 + e, 2 + e, 1 + e},
                            Surface In BoundingBox{1 - e, 1 - e, -e, 1.1 + e, 1 + e, 1 + e}};
Physical Surface("zmin") = Surface In BoundingBox{-e, -e, -e, 1.1 + e, 2 + e, e};
Physical Surface("zmax") = Surface In BoundingBox{-e, -e, 1 - e, 1.1 + e, 2 + e, 1 + e};
Physical Volume("block") = Volume{:};
Physical Volume("cube") = Volume In BoundingBox{-e, -e, -e, 1 + e, 1 + e, 1 + e};
Physical Volume("slab") = Volume In BoundingBox{1 - e, -e, -e, 1.1 + e, 1 + e, 1 + e};
Physical Volume("arm") = Volume In BoundingBox{-e, 1 - e, -e, 1 + e, 2 + e, 1 + e};
