// twin_bumps.geo -- an active zone that splits in two (hard case, docs/hard_cases.md).
//
// Scene (2D plane, z = 0, dimensionless length units):
//   * "pad"  : slab x in [-W, W], top at y = g0 + A + H, bottom y(x) = g0 + A cos^2(pi x / W): two bump
//              tips at x = -W/2 and W/2 (height g0 above the block), a recess of depth A between them  -> SLAVE
//   * "block": rectangle [-1.2, 1.2] x [-1, 0]                                                       -> MASTER
//   Pushing the pad's top down: no contact below g0, then two contact zones around the tips, which
//   merge into one across the recess at larger pushes (A = 0.01: near a push of 0.03 with E = 100).
//
// Physical names: Surface "pad" (tag 1, slave body), "block" (tag 2, master body); Curve "slave" (tag 21)
// the pad's bottom; "master" (tag 22) the block top, x in [-0.8, 0.8]; "pad_top" (tag 23); "block_bottom" (24).
// (Physical tags 21-24 are used by no entity: docs/bad_input.md, gmsh format 2.2.)
// Parameters: W (0.5), H (0.2), A (0.01), g0 (0.001), lc_slave (0.015), lc_master (0.01), lc_far (0.08).
// Mesh: gmsh -2 meshes/twin_bumps.geo -o twin_bumps.msh -format msh41

DefineConstant[
  W         = {0.5,   Min 0.1, Max 2, Name "Parameters/W"},
  H         = {0.2,   Min 0.05, Max 2, Name "Parameters/H"},
  A         = {0.01,  Min 0.0, Max 0.2, Name "Parameters/A"},
  g0        = {0.001, Min 0.0, Max 0.1, Name "Parameters/g0"},
  lc_slave  = {0.015, Min 1e-4, Max 1, Name "Parameters/lc_slave"},
  lc_master = {0.01,  Min 1e-4, Max 1, Name "Parameters/lc_master"},
  lc_far    = {0.08,  Min 1e-4, Max 2, Name "Parameters/lc_far"}
];

// pad: bottom spline through 41 points of y = g0 + A cos^2(pi x / W), x from -W to W
n = 40;
For i In {0:n}
  x = -W + 2 * W * i / n;
  Point(100 + i) = {x, g0 + A * Cos(Pi * x / W)^2, 0, lc_slave};
EndFor
Point(200) = { W, g0 + A + H, 0, lc_far};
Point(201) = {-W, g0 + A + H, 0, lc_far};
Spline(1) = {100:100 + n};          // bottom, left to right (slave)
Line(2)   = {100 + n, 200};         // right side
Line(3)   = {200, 201};             // top (pushed)
Line(4)   = {201, 100};             // left side
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// block
Point(301) = {-1.2, -1, 0, lc_far};
Point(302) = { 1.2, -1, 0, lc_far};
Point(303) = { 1.2,  0, 0, lc_far};
Point(304) = { 0.8,  0, 0, lc_master};
Point(305) = {-0.8,  0, 0, lc_master};
Point(306) = {-1.2,  0, 0, lc_far};
Line(11) = {301, 302};
Line(12) = {302, 303};
Line(13) = {303, 304};
Line(14) = {304, 305};   // master
Line(15) = {305, 306};
Line(16) = {306, 301};
Curve Loop(11) = {11, 12, 13, 14, 15, 16};
Plane Surface(11) = {11};

Physical Surface("pad", 1)          = {1};
Physical Surface("block", 2)        = {11};
Physical Curve("slave", 21)         = {1};
Physical Curve("master", 22)        = {14};
Physical Curve("pad_top", 23)       = {3};
Physical Curve("block_bottom", 24)  = {11};
