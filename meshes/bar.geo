// Bar 1 x 0.1 x 0.1 along x (wave propagation): loaded at "left" (x = 0), free at "right".
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 0.1, 0.1};
e = 1e-6;
Physical Surface("left") = Surface In BoundingBox{-e, -e, -e, e, 0.1 + e, 0.1 + e};
Physical Surface("right") = Surface In BoundingBox{1 - e, -e, -e, 1 + e, 0.1 + e, 0.1 + e};
Physical Volume("bar") = {1};
