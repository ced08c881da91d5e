// SPDX-License-Identifier: GPL-3.0-or-later
// Continuum of the random-packing patch test (cases/patch_coupled/random_packing.yaml): the bar
// x from 8 to 24 mm (the overlap 8..12 mm and the pure continuum), cross-section 4 x 4 mm,
// unstructured tetrahedra of size h (continuum.mesh.size overrides it). "right" is the end
// x = 24 mm, "lateral" the four side faces.
SetFactory("OpenCASCADE");
x0 = 8e-3; x1 = 24e-3; w = 4e-3; h = 1e-3;
Box(1) = {x0, 0, 0, x1 - x0, w, w};
Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = h;
e = 1e-6;
Physical Surface("right") = {Surface In BoundingBox{x1 - e, -e, -e, x1 + e, w + e, w + e}};
Physical Surface("lateral") = {Surface In BoundingBox{x0 - e, -e, -e, x1 + e, e, w + e},
                               Surface In BoundingBox{x0 - e, w - e, -e, x1 + e, w + e, w + e},
                               Surface In BoundingBox{x0 - e, -e, -e, x1 + e, w + e, e},
                               Surface In BoundingBox{x0 - e, -e, w - e, x1 + e, w + e, w + e}};
Physical Volume("bar") = {1};
