// Unit cube [0,1]^3 (patch tests, convergence). Element size is set by the caller.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
e = 1e-6;
Physical Surface("xmin") = Surface In BoundingBox{-e, -e, -e, e, 1 + e, 1 + e};
Physical Surface("xmax") = Surface In BoundingBox{1 - e, -e, -e, 1 + e, 1 + e, 1 + e};
Physical Surface("ymin") = Surface In BoundingBox{-e, -e, -e, 1 + e, e, 1 + e};
Physical Surface("ymax") = Surface In BoundingBox{-e, 1 - e, -e, 1 + e, 1 + e, 1 + e};
Physical Surface("zmin") = Surface In BoundingBox{-e, -e, -e, 1 + e, 1 + e, e};
Physical Surface("zmax") = Surface In BoundingBox{-e, -e, 1 - e, 1 + e, 1 + e, 1 + e};
Physical Surface("boundary") = Surface{:};
Physical Volume("domain") = {1};
