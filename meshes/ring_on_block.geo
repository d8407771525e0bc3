// ring_on_block.geo -- half ring (lower half of an annulus) pressed onto an elastic block.
//
// Scene (2D plane, z = 0, dimensionless length units):
//   * "block": rectangle [-1.5,1.5] x [-1,0]                       -> MASTER body
//   * "ring" : lower half of an annulus, centre (0, g0+Ro), outer
//              radius Ro, inner radius Ri = 0.8*Ro; its lowest point
//              is (0, g0), i.e. initial gap g0 above the block top  -> SLAVE body
//   The ring (geometry AND its mesh sizes) scales with Ro about its lowest point (0,g0):
//   x = (0,g0) + (Ro/1.0) * (x_ref - (0,g0)).  The two bodies share no nodes.
//
// Physical names (contract, read as DMLabels with -dm_plex_gmsh_use_regions):
//   Physical Surface "ring"          (tag 1)  slave body
//   Physical Surface "block"         (tag 2)  master body
//   Physical Curve   "slave"         (tag 11) outer ring arc within +-35 deg of the lowest point
//   Physical Curve   "ring_top"      (tag 12) the two flat ends of the ring at y = g0+Ro
//                                             (x in [-Ro,-Ri] and [Ri,Ro])
//   Physical Curve   "master"        (tag 13) block top y = 0, x in [-0.6, 0.6]
//   Physical Curve   "block_bottom"  (tag 14) block bottom y = -1
//   (rest of the block top, block sides, ring inner arc and the rest of the outer arc: unnamed)
//
// Parameters (gmsh -setnumber NAME value):
//   Ro        outer radius (default 1.0, range 0.95..1.15)
//   g0        initial gap (default 0.005)
//   lc_slave  ring mesh size on "slave"           (at Ro = 1)
//   lc_ring   ring mesh size away from "slave"    (at Ro = 1)
//   lc_master block mesh size on "master" (lc_slave / 1.5 = 0.0167)
//             (master 1.5x finer than the slave: non-matching; a master coarser than the slave makes the P1 pressure oscillate, docs/contact.md)
//   lc_block  block mesh size at the block corners
// All sizes are multiplied by -clscale.  Defaults: ~1590 nodes per body, ~50 on "slave".
// Mesh: gmsh -2 meshes/ring_on_block.geo -o ring_on_block.msh -format msh41   (format 2.2 mislabels with PETSc 3.18: docs/bad_input.md)

DefineConstant[
  Ro        = {1.0,   Min 0.95, Max 1.15, Step 0.01, Name "Parameters/Ro"},
  g0        = {0.005, Min 0.0,  Max 0.1, Name "Parameters/g0"},
  lc_slave  = {0.025, Min 1e-4, Max 1, Name "Parameters/lc_slave"},
  lc_ring   = {0.0203, Min 1e-4, Max 1, Name "Parameters/lc_ring"},
  lc_master = {0.0167,Min 1e-4, Max 1, Name "Parameters/lc_master"},
  lc_block  = {0.0575, Min 1e-4, Max 1, Name "Parameters/lc_block"}
];

Ri = 0.8*Ro;
s  = Ro/1.0;          // scale factor of the ring about (0,g0)
yc = g0 + Ro;         // ring centre height
a  = 35*Pi/180;       // half-angle of the slave arc

// ---------------- ring (slave) ----------------
Point(1)  = {0,            yc,             0, s*lc_ring};   // centre (not meshed)
Point(2)  = {-Ro,          yc,             0, s*lc_ring};   // outer left end
Point(3)  = {-Ro*Sin(a),   yc - Ro*Cos(a), 0, s*lc_slave};  // slave arc start
Point(4)  = {0,            g0,             0, s*lc_slave};  // lowest point
Point(5)  = { Ro*Sin(a),   yc - Ro*Cos(a), 0, s*lc_slave};  // slave arc end
Point(6)  = { Ro,          yc,             0, s*lc_ring};   // outer right end
Point(7)  = { Ri,          yc,             0, s*lc_ring};   // inner right end
Point(8)  = {0,            yc - Ri,        0, s*lc_ring};   // inner lowest point
Point(9)  = {-Ri,          yc,             0, s*lc_ring};   // inner left end

Circle(1) = {2, 1, 3};   // outer, left (not slave)
Circle(2) = {3, 1, 4};   // slave, left half
Circle(3) = {4, 1, 5};   // slave, right half
Circle(4) = {5, 1, 6};   // outer, right (not slave)
Line(5)   = {6, 7};      // right flat top end
Circle(6) = {7, 1, 8};   // inner arc, right half
Circle(7) = {8, 1, 9};   // inner arc, left half
Line(8)   = {9, 2};      // left flat top end

Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8};
Plane Surface(1) = {1};

// ---------------- block (master) ----------------
Point(101) = {-1.5, -1, 0, lc_block};
Point(102) = { 1.5, -1, 0, lc_block};
Point(103) = { 1.5,  0, 0, lc_block};
Point(104) = { 0.6,  0, 0, lc_master};
Point(105) = {-0.6,  0, 0, lc_master};
Point(106) = {-1.5,  0, 0, lc_block};

Line(101) = {101, 102};  // bottom
Line(102) = {102, 103};  // right side
Line(103) = {103, 104};  // top, right part
Line(104) = {104, 105};  // top, central part = master
Line(105) = {105, 106};  // top, left part
Line(106) = {106, 101};  // left side

Curve Loop(101) = {101, 102, 103, 104, 105, 106};
Plane Surface(101) = {101};

// ---------------- physical groups ----------------
Physical Surface("ring", 1)          = {1};
Physical Surface("block", 2)         = {101};
Physical Curve("slave", 11)          = {2, 3};
Physical Curve("ring_top", 12)       = {5, 8};
Physical Curve("master", 13)         = {104};
Physical Curve("block_bottom", 14)   = {101};
