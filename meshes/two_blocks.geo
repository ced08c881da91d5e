// Two unit cubes stacked along z that share no node: [0,1]^2 x [0,1] ("lower") and
// [0,1]^2 x [1,2] ("upper"), meshed apart (no BooleanFragments), so the face z = 1 carries a node
// of each body at every point (tests of natural neighbours over several bodies, as the coupled
// DCB's two arms). Element size is set by the caller.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {0, 0, 1, 1, 1, 1};
Physical Surface("boundary") = Surface{:};
Physical Volume("lower") = {1};
Physical Volume("upper") = {2};
