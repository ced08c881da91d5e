// SPDX-License-Identifier: GPL-3.0-or-later
// The two arms of the coupled DCB (cases/dcb_coupled), for dcb_arms.geo and dcb_arms_coarse.geo,
// which set the node counts first: nx along x, ny along y, nz per 0.5 mm layer in z.
// x along the beam (0 to L = 45 mm), y across (0 to b = 6 mm), z through the thickness, lower arm
// 0 to h = 1.5 mm, upper arm h to 2h. The arms are two bodies that share no node: along the
// pre-crack they are free of each other, beyond it only the DEM band (the cohesive interface)
// joins them. Each arm is three layers of 0.5 mm glued together, so that the load strips of the
// end face (x = 0, z in [0.5, 1] mm and [2, 2.5] mm, where cases/dcb drives its load-line DEs)
// are physical surfaces: "load_bottom", "load_top". Structured (transfinite), so that both arms
// have the same nodes on the mid-plane: a case may join them there (continuum.mesh.join). With
// `fused = 1` set first, the six layers are one body (dcb_arms_coarse_fused.geo, for tests).
SetFactory("OpenCASCADE");
L = 45e-3; b = 6e-3; h = 1.5e-3; t = 0.5e-3;
For k In {0:5}
  Box(k + 1) = {0, 0, k * t, L, b, t};
EndFor
If (!Exists(fused))
  fused = 0;
EndIf
If (fused)
  BooleanFragments{ Volume{1, 2, 3, 4, 5, 6}; Delete; }{}
Else
  BooleanFragments{ Volume{1, 2, 3}; Delete; }{}
  BooleanFragments{ Volume{4, 5, 6}; Delete; }{}
EndIf
e = 1e-7;
Transfinite Curve {Curve In BoundingBox{-e, -e, -e, L + e, e, 2 * h + e}} = nx;   // along x (y = 0 face)
Transfinite Curve {Curve In BoundingBox{-e, b - e, -e, L + e, b + e, 2 * h + e}} = nx;
Transfinite Curve {Curve In BoundingBox{-e, -e, -e, e, b + e, 2 * h + e}} = nz;    // x = 0 face: z edges, then y edges
Transfinite Curve {Curve In BoundingBox{L - e, -e, -e, L + e, b + e, 2 * h + e}} = nz;
// nz_band, if set first: the node count through the two layers next to the mid-plane (z in
// [h - t, h + t]), where a DEM band's overlap lies, instead of nz.
If (Exists(nz_band))
  Transfinite Curve {Curve In BoundingBox{-e, -e, 2 * t - e, e, b + e, 4 * t + e}} = nz_band;
  Transfinite Curve {Curve In BoundingBox{L - e, -e, 2 * t - e, L + e, b + e, 4 * t + e}} = nz_band;
EndIf
For k In {0:6}
  Transfinite Curve {Curve In BoundingBox{-e, -e, k * t - e, e, b + e, k * t + e}} = ny;
  Transfinite Curve {Curve In BoundingBox{L - e, -e, k * t - e, L + e, b + e, k * t + e}} = ny;
  Transfinite Curve {Curve In BoundingBox{-e, -e, k * t - e, L + e, e, k * t + e}} = nx;
  Transfinite Curve {Curve In BoundingBox{-e, b - e, k * t - e, L + e, b + e, k * t + e}} = nx;
EndFor
Transfinite Surface {:};
Transfinite Volume {:};
Physical Surface("load_bottom") = {Surface In BoundingBox{-e, -e, t - e, e, b + e, 2 * t + e}};
Physical Surface("load_top") = {Surface In BoundingBox{-e, -e, 4 * t - e, e, b + e, 5 * t + e}};
Physical Volume("lower") = {Volume In BoundingBox{-e, -e, -e, L + e, b + e, h + e}};
Physical Volume("upper") = {Volume In BoundingBox{-e, -e, h - e, L + e, b + e, 2 * h + e}};
