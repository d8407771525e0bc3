// pin_in_hole.geo -- conforming curved contact: a pin in a plate's hole of almost the same radius
// (hard case "conforming curved contact", docs/hard_cases.md).
//
// Scene (2D plane, z = 0, dimensionless length units):
//   * "plate": square [-L, L]^2 with a circular hole of radius R centred at the origin  -> MASTER body
//   * "pin"  : annulus of outer radius Rp = R - c (clearance c) and inner radius ri,
//              centred at the origin: a uniform gap c all around                        -> SLAVE body
//   Pushing the pin's core down by more than c closes the gap over a long arc of the lower half:
//   the contact zone is wide and curved (a conforming contact), the opposite of Hertz.
//
// Physical names (contract, read as DMLabels with -dm_plex_gmsh_use_regions):
//   Physical Surface "pin"          (tag 1)  slave body
//   Physical Surface "plate"        (tag 2)  master body
//   Physical Curve   "slave"        (tag 11) lower half of the pin's outer circle
//   Physical Curve   "master"       (tag 12) lower half of the hole
//   Physical Curve   "pin_core"     (tag 13) the pin's inner circle (imposed displacement)
//   Physical Curve   "plate_outer"  (tag 14) the plate's outer boundary (clamped)
//
// Parameters (gmsh -setnumber NAME value): R (1.0), c (0.002), ri (0.3), L (2.5),
//   lc_slave (0.03) on the pin's outer circle, lc_master (0.02) on the hole (master 1.5x finer than the
//   slave, docs/contact.md), lc_core (0.1), lc_outer (0.4). Sizes are multiplied by -clscale.
// Mesh: gmsh -2 meshes/pin_in_hole.geo -o pin_in_hole.msh -format msh41   (format 2.2 mislabels with PETSc 3.18: docs/bad_input.md)

DefineConstant[
  R         = {1.0,   Min 0.1, Max 10, Name "Parameters/R"},
  c         = {0.002, Min 0.0, Max 0.1, Name "Parameters/c"},
  ri        = {0.3,   Min 0.05, Max 0.9, Name "Parameters/ri"},
  L         = {2.5,   Min 1.5, Max 20, Name "Parameters/L"},
  lc_slave  = {0.03,  Min 1e-4, Max 1, Name "Parameters/lc_slave"},
  lc_master = {0.02,  Min 1e-4, Max 1, Name "Parameters/lc_master"},
  lc_core   = {0.1,   Min 1e-4, Max 1, Name "Parameters/lc_core"},
  lc_outer  = {0.4,   Min 1e-4, Max 2, Name "Parameters/lc_outer"}
];
Rp = R - c;

// ---------------- pin (slave): annulus Rp / ri ----------------
Point(1) = {0, 0, 0, lc_core};
Point(2) = { Rp, 0, 0, lc_slave};
Point(3) = {0,  Rp, 0, lc_slave};
Point(4) = {-Rp, 0, 0, lc_slave};
Point(5) = {0, -Rp, 0, lc_slave};
Point(6) = { ri, 0, 0, lc_core};
Point(7) = {0,  ri, 0, lc_core};
Point(8) = {-ri, 0, 0, lc_core};
Point(9) = {0, -ri, 0, lc_core};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};   // slave, left quarter
Circle(4) = {5, 1, 2};   // slave, right quarter
Circle(5) = {6, 1, 7};
Circle(6) = {7, 1, 8};
Circle(7) = {8, 1, 9};
Circle(8) = {9, 1, 6};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};

// ---------------- plate (master): square with the hole R ----------------
Point(11) = { R, 0, 0, lc_master};
Point(12) = {0,  R, 0, lc_master};
Point(13) = {-R, 0, 0, lc_master};
Point(14) = {0, -R, 0, lc_master};
Circle(11) = {11, 1, 12};
Circle(12) = {12, 1, 13};
Circle(13) = {13, 1, 14};   // master, left quarter
Circle(14) = {14, 1, 11};   // master, right quarter
Point(21) = {-L, -L, 0, lc_outer};
Point(22) = { L, -L, 0, lc_outer};
Point(23) = { L,  L, 0, lc_outer};
Point(24) = {-L,  L, 0, lc_outer};
Line(21) = {21, 22};
Line(22) = {22, 23};
Line(23) = {23, 24};
Line(24) = {24, 21};
Curve Loop(11) = {21, 22, 23, 24};
Curve Loop(12) = {11, 12, 13, 14};
Plane Surface(11) = {11, 12};

// ---------------- physical groups ----------------
Physical Surface("pin", 1)         = {1};
Physical Surface("plate", 2)       = {11};
Physical Curve("slave", 11)        = {3, 4};
Physical Curve("master", 12)       = {13, 14};
Physical Curve("pin_core", 13)     = {5, 6, 7, 8};
Physical Curve("plate_outer", 14)  = {21, 22, 23, 24};
