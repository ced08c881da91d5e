// Continuum of the coupled wave bar (cases/wave_bar_coupled): x from 2a to 118a, nearly the
// whole bar (DE centres 0 to 118a; the coupling's overlap leaves out the tetrahedra of the
// pure-DEM zone), cross-section 4a x 4a (the 5 x 5 DE bar's centres), a = 2 mm, structured
// (transfinite) with element size h = 4a: node planes every 4a from
// x = 2a, so overlap faces at 14a, 18a, 22a, 26a, 30a, 38a fall on them. Two volumes glued at
// x = 62a, so that plane is a physical surface ("probe") for sensors; "right" is the free end.
SetFactory("OpenCASCADE");
a = 2e-3; x0 = 2 * a; xp = 62 * a; x1 = 118 * a; w = 4 * a;
Box(1) = {x0, 0, 0, xp - x0, w, w};
Box(2) = {xp, 0, 0, x1 - xp, w, w};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
e = 1e-5;
// Axial curves first (their boxes also catch the cross-section edges), then the cross-sections.
Transfinite Curve {Curve In BoundingBox{x0 - e, -e, -e, xp + e, w + e, w + e}} = 16;
Transfinite Curve {Curve In BoundingBox{xp - e, -e, -e, x1 + e, w + e, w + e}} = 15;
Transfinite Curve {Curve In BoundingBox{x0 - e, -e, -e, x0 + e, w + e, w + e}} = 2;
Transfinite Curve {Curve In BoundingBox{xp - e, -e, -e, xp + e, w + e, w + e}} = 2;
Transfinite Curve {Curve In BoundingBox{x1 - e, -e, -e, x1 + e, w + e, w + e}} = 2;
Transfinite Surface {:};
Transfinite Volume {:};
Physical Surface("probe") = {Surface In BoundingBox{xp - e, -e, -e, xp + e, w + e, w + e}};
Physical Surface("right") = {Surface In BoundingBox{x1 - e, -e, -e, x1 + e, w + e, w + e}};
// The four side faces: "lateral" (held in the static patch test, cases/patch_coupled).
Physical Surface("lateral") = {Surface In BoundingBox{x0 - e, -e, -e, x1 + e, e, w + e},
                               Surface In BoundingBox{x0 - e, w - e, -e, x1 + e, w + e, w + e},
                               Surface In BoundingBox{x0 - e, -e, -e, x1 + e, w + e, e},
                               Surface In BoundingBox{x0 - e, -e, w - e, x1 + e, w + e, w + e}};
Physical Volume("bar") = {1, 2};
