// Cantilever 10 x 1 x 1 along x: clamped at "clamp" (x = 0), loaded at "tip" (x = 10).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 10, 1, 1};
e = 1e-6;
Physical Surface("clamp") = Surface In BoundingBox{-e, -e, -e, e, 1 + e, 1 + e};
Physical Surface("tip") = Surface In BoundingBox{10 - e, -e, -e, 10 + e, 1 + e, 1 + e};
Physical Volume("beam") = {1};
