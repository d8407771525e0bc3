// flat_punch.geo -- flat punch (rectangle) resting on a base (rectangle), flat-on-flat.
//
// Scene (2D plane, z = 0, dimensionless length units):
//   * "punch": [0,1] x [0,0.5]    -> SLAVE body
//   * "base" : [0,1] x [-0.5,0]   -> MASTER body
//   The bodies touch along y = 0 (gap 0) but are separate surfaces with separate
//   geometric points: no shared node ids.  Unstructured triangles; the interface
//   sizes differ (h_base/h_punch ~ 1.6), the punch is uniform and the base size grows
//   linearly from h_base at x = 0 to base_grading*h_base at x = 1, so the interface
//   nodes of the two bodies do not coincide (except the end nodes x = 0 and x = 1,
//   which are geometrically shared corners).
//
// Physical names (contract, read as DMLabels with -dm_plex_gmsh_use_regions):
//   Physical Surface "punch"       (tag 1)  slave body
//   Physical Surface "base"        (tag 2)  master body
//   Physical Curve   "slave"       (tag 11) punch bottom, y = 0
//   Physical Curve   "master"      (tag 12) base top, y = 0
//   Physical Curve   "punch_top"   (tag 13) y = 0.5
//   Physical Curve   "punch_left"  (tag 14) punch, x = 0
//   Physical Curve   "base_bottom" (tag 15) y = -0.5
//   Physical Curve   "base_left"   (tag 16) base, x = 0
//   Physical Curve   "punch_right" (tag 17) punch, x = 1   (extra, optional)
//   Physical Curve   "base_right"  (tag 18) base, x = 1    (extra, optional)
//
// Parameters (gmsh -setnumber NAME value):
//   h_punch (0.05)      uniform punch mesh size
//   h_base  (0.08)      base mesh size at x = 0
//   base_grading (1.18) base mesh size at x = 1 is base_grading*h_base
//   All sizes are multiplied by -clscale.
// Mesh: gmsh -2 meshes/flat_punch.geo -o flat_punch.msh -format msh41   (format 2.2 mislabels with PETSc 3.18: docs/bad_input.md)

DefineConstant[
  h_punch      = {0.05, Min 1e-4, Max 1, Name "Parameters/h_punch"},
  h_base       = {0.08, Min 1e-4, Max 1, Name "Parameters/h_base"},
  base_grading = {1.18, Min 0.5,  Max 2, Name "Parameters/base_grading"}
];

// ---------------- punch (slave) ----------------
Point(1) = {0, 0,   0, h_punch};
Point(2) = {1, 0,   0, h_punch};
Point(3) = {1, 0.5, 0, h_punch};
Point(4) = {0, 0.5, 0, h_punch};
Line(1) = {1, 2};  // slave
Line(2) = {2, 3};  // punch_right
Line(3) = {3, 4};  // punch_top
Line(4) = {4, 1};  // punch_left
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// ---------------- base (master) ----------------
Point(101) = {0, -0.5, 0, h_base};
Point(102) = {1, -0.5, 0, base_grading*h_base};
Point(103) = {1,  0,   0, base_grading*h_base};
Point(104) = {0,  0,   0, h_base};
Line(101) = {101, 102};  // base_bottom
Line(102) = {102, 103};  // base_right
Line(103) = {103, 104};  // master
Line(104) = {104, 101};  // base_left
Curve Loop(101) = {101, 102, 103, 104};
Plane Surface(101) = {101};

// ---------------- physical groups ----------------
Physical Surface("punch", 1)       = {1};
Physical Surface("base", 2)        = {101};
Physical Curve("slave", 11)        = {1};
Physical Curve("master", 12)       = {103};
Physical Curve("punch_top", 13)    = {3};
Physical Curve("punch_left", 14)   = {4};
Physical Curve("base_bottom", 15)  = {101};
Physical Curve("base_left", 16)    = {104};
Physical Curve("punch_right", 17)  = {2};
Physical Curve("base_right", 18)   = {102};
