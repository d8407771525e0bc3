// half_disks.geo -- two half-disks, arc against arc, separated by a small gap.
//
// Scene (2D plane, z = 0, dimensionless length units):
//   * "upper": half-disk of radius 1, centre (0, 1+gap), flat edge on top
//              (y = 1+gap), curved arc below; lowest point (0, gap)      -> SLAVE body
//   * "lower": half-disk of radius Rl, centre (0, -Rl), flat edge at the
//              bottom (y = -Rl), curved arc above; top point (0, 0)       -> MASTER body
//   The lower disk (geometry AND its mesh sizes) scales with Rl about its top point (0,0):
//   x = (Rl/1.0) * x_ref.  The two bodies share no nodes.
//
// Physical names (contract, read as DMLabels with -dm_plex_gmsh_use_regions):
//   Physical Surface "upper"        (tag 1)  slave body
//   Physical Surface "lower"        (tag 2)  master body
//   Physical Curve   "slave"        (tag 11) upper arc within +-60 deg of its lowest point
//   Physical Curve   "master"       (tag 12) lower arc within +-60 deg of its top point
//   Physical Curve   "upper_top"    (tag 13) flat edge of the upper disk, y = 1+gap
//   Physical Curve   "lower_bottom" (tag 14) flat edge of the lower disk, y = -Rl
//   (remaining parts of both arcs: unnamed)
//
// Parameters (gmsh -setnumber NAME value):
//   gap       initial gap (default 1e-3)
//   Rl        radius of the lower disk (default 1.0, range 0.7..1.3)
//   lc_slave  upper mesh size on "slave"            (default 0.018)
//   lc_upper  upper mesh size at the flat edge      (default 0.045)
//   lc_master lower mesh size on "master" (at Rl=1) (default 0.012 = lc_slave / 1.5)
//             (master 1.5x finer than the slave: non-matching; a master coarser than the slave makes the P1 pressure oscillate, docs/contact.md)
//   lc_lower  lower mesh size at the flat edge      (default 0.06, at Rl=1)
// All sizes are multiplied by -clscale.
// Mesh: gmsh -2 meshes/half_disks.geo -o half_disks.msh -format msh41   (format 2.2 mislabels with PETSc 3.18: docs/bad_input.md)

DefineConstant[
  gap       = {1e-3,   Min 0,    Max 0.1,  Name "Parameters/gap"},
  Rl        = {1.0,    Min 0.7,  Max 1.3,  Step 0.01, Name "Parameters/Rl"},
  lc_slave  = {0.018,  Min 1e-4, Max 1,    Name "Parameters/lc_slave"},
  lc_upper  = {0.045,  Min 1e-4, Max 1,    Name "Parameters/lc_upper"},
  lc_master = {0.012,  Min 1e-4, Max 1,    Name "Parameters/lc_master"},
  lc_lower  = {0.06,   Min 1e-4, Max 1,    Name "Parameters/lc_lower"}
];

a = 60*Pi/180;   // half-angle of slave / master arcs

// ---------------- upper half-disk (slave) ----------------
yu = 1 + gap;    // centre height
Point(1) = {0,       yu,          0, lc_upper};  // centre (not meshed)
Point(2) = {-1,      yu,          0, lc_upper};  // left end of flat edge
Point(3) = {-Sin(a), yu - Cos(a), 0, lc_slave};  // slave start
Point(4) = {0,       gap,         0, lc_slave};  // lowest point
Point(5) = { Sin(a), yu - Cos(a), 0, lc_slave};  // slave end
Point(6) = { 1,      yu,          0, lc_upper};  // right end of flat edge

Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};   // slave
Circle(3) = {4, 1, 5};   // slave
Circle(4) = {5, 1, 6};
Line(5)   = {6, 2};      // upper_top
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

// ---------------- lower half-disk (master), scales with Rl about (0,0) ----------------
s = Rl/1.0;
Point(101) = {0,           -Rl,              0, s*lc_lower};   // centre (not meshed)
Point(102) = {-Rl,         -Rl,              0, s*lc_lower};   // left end of flat edge
Point(103) = {-Rl*Sin(a),  -Rl + Rl*Cos(a),  0, s*lc_master};  // master start
Point(104) = {0,           0,                0, s*lc_master};  // top point
Point(105) = { Rl*Sin(a),  -Rl + Rl*Cos(a),  0, s*lc_master};  // master end
Point(106) = { Rl,         -Rl,              0, s*lc_lower};   // right end of flat edge

Circle(101) = {102, 101, 103};
Circle(102) = {103, 101, 104};  // master
Circle(103) = {104, 101, 105};  // master
Circle(104) = {105, 101, 106};
Line(105)   = {106, 102};       // lower_bottom
// counter-clockwise loop (reversed curves) so that the triangles are positively oriented
Curve Loop(101) = {-105, -104, -103, -102, -101};
Plane Surface(101) = {101};

// ---------------- physical groups ----------------
Physical Surface("upper", 1)        = {1};
Physical Surface("lower", 2)        = {101};
Physical Curve("slave", 11)         = {2, 3};
Physical Curve("master", 12)        = {102, 103};
Physical Curve("upper_top", 13)     = {5};
Physical Curve("lower_bottom", 14)  = {105};
