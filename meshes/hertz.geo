// hertz.geo -- Hertz problem: elastic half-cylinder on a large elastic foundation.
//
// Scene (2D plane, z = 0, dimensionless length units):
//   * "cylinder"  : half-disk of radius R, centre (0,R), flat edge on top (y = R),
//                   curved arc below, lowest point (0,0)                    -> SLAVE body
//   * "foundation": block [-10,10] x [-10,0]                                 -> MASTER body
//   Initial gap 0: the point (0,0) belongs geometrically to both bodies, but the bodies
//   are separate surfaces with separate geometric points, so no node ids are shared.
//
// Physical names (contract, read as DMLabels with -dm_plex_gmsh_use_regions):
//   Physical Surface "cylinder"          (tag 1)  slave body
//   Physical Surface "foundation"        (tag 2)  master body
//   Physical Curve   "slave"             (tag 11) cylinder arc within +-25 deg of (0,0)
//   Physical Curve   "master"            (tag 12) foundation top y = 0, x in [-0.5,0.5]
//   Physical Curve   "cylinder_top"      (tag 13) flat edge of the cylinder, y = R
//   Physical Curve   "foundation_bottom" (tag 14) foundation bottom, y = -10
//   (rest of the cylinder arc, the rest of the foundation top and its sides: unnamed)
//
// Mesh sizes: Distance+Threshold fields around (0,0), restricted per body:
//   cylinder  : h = h_slave  for r < d_fine, growing linearly to hmax_cyl at r = d_cyl
//   foundation: h = h_master for r < d_fine, growing linearly to hmax_fnd at r = d_fnd
//   h_master = h_slave / 1.5 (master 1.5x finer than the slave: non-matching; a master coarser than the slave makes the P1 pressure oscillate, docs/contact.md).  Sizes are absolute (do not scale
//   with R) and are multiplied by -clscale.
//
// Parameters (gmsh -setnumber NAME value):
//   R (1.0), h_slave (0.01), h_master (0.0067), d_fine (0.15),
//   hmax_cyl (0.1), d_cyl (1.5), hmax_fnd (0.5), d_fnd (5.0)
// Mesh: gmsh -2 meshes/hertz.geo -o hertz.msh -format msh41   (format 2.2 mislabels with PETSc 3.18: docs/bad_input.md)

DefineConstant[
  R        = {1.0,   Min 0.1,  Max 5,  Name "Parameters/R"},
  h_slave  = {0.01,  Min 1e-4, Max 1,  Name "Parameters/h_slave"},
  h_master = {0.0067,Min 1e-4, Max 1,  Name "Parameters/h_master"},
  d_fine   = {0.15,  Min 0,    Max 5,  Name "Parameters/d_fine"},
  hmax_cyl = {0.1,   Min 1e-4, Max 1,  Name "Parameters/hmax_cyl"},
  d_cyl    = {1.5,   Min 0,    Max 10, Name "Parameters/d_cyl"},
  hmax_fnd = {0.5,   Min 1e-4, Max 5,  Name "Parameters/hmax_fnd"},
  d_fnd    = {5.0,   Min 0,    Max 20, Name "Parameters/d_fnd"}
];

a = 25*Pi/180;   // half-angle of the slave arc

// ---------------- cylinder (slave) ----------------
Point(1) = {0,          R,              0, hmax_cyl};  // centre (not meshed)
Point(2) = {-R,         R,              0, hmax_cyl};
Point(3) = {-R*Sin(a),  R - R*Cos(a),   0, hmax_cyl};  // slave start
Point(4) = {0,          0,              0, h_slave};   // contact point
Point(5) = { R*Sin(a),  R - R*Cos(a),   0, hmax_cyl};  // slave end
Point(6) = { R,         R,              0, hmax_cyl};

Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};  // slave
Circle(3) = {4, 1, 5};  // slave
Circle(4) = {5, 1, 6};
Line(5)   = {6, 2};     // cylinder_top
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

// ---------------- foundation (master) ----------------
Point(101) = {-10, -10, 0, hmax_fnd};
Point(102) = { 10, -10, 0, hmax_fnd};
Point(103) = { 10,   0, 0, hmax_fnd};
Point(104) = { 0.5,  0, 0, hmax_fnd};
Point(105) = {-0.5,  0, 0, hmax_fnd};
Point(106) = {-10,   0, 0, hmax_fnd};

Line(101) = {101, 102};  // foundation_bottom
Line(102) = {102, 103};
Line(103) = {103, 104};
Line(104) = {104, 105};  // master
Line(105) = {105, 106};
Line(106) = {106, 101};
Curve Loop(101) = {101, 102, 103, 104, 105, 106};
Plane Surface(101) = {101};

// ---------------- size fields ----------------
Field[1] = Distance;             // distance to the contact point (0,0)
Field[1].PointsList = {4};

Field[2] = Threshold;            // cylinder sizes
Field[2].InField = 1;
Field[2].SizeMin = h_slave;
Field[2].SizeMax = hmax_cyl;
Field[2].DistMin = d_fine;
Field[2].DistMax = d_cyl;

Field[3] = Threshold;            // foundation sizes
Field[3].InField = 1;
Field[3].SizeMin = h_master;
Field[3].SizeMax = hmax_fnd;
Field[3].DistMin = d_fine;
Field[3].DistMax = d_fnd;

Field[4] = Restrict;
Field[4].InField = 2;
Field[4].PointsList = {2, 3, 4, 5, 6};
Field[4].CurvesList = {1, 2, 3, 4, 5};
Field[4].SurfacesList = {1};

Field[5] = Restrict;
Field[5].InField = 3;
Field[5].PointsList = {101, 102, 103, 104, 105, 106};
Field[5].CurvesList = {101, 102, 103, 104, 105, 106};
Field[5].SurfacesList = {101};

Field[6] = Min;
Field[6].FieldsList = {4, 5};
Background Field = 6;

Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromCurvature = 0;

// ---------------- physical groups ----------------
Physical Surface("cylinder", 1)           = {1};
Physical Surface("foundation", 2)         = {101};
Physical Curve("slave", 11)               = {2, 3};
Physical Curve("master", 12)              = {104};
Physical Curve("cylinder_top", 13)        = {5};
Physical Curve("foundation_bottom", 14)   = {101};
