// unit_square.geo -- unit square, single elastic body, triangles (manufactured-solution and
// uniform-strain patch tests of the elastic FOM, tests/test_mms.cpp, tests/test_vonmises.cpp).
//
// Scene (2D plane, z = 0, dimensionless length units): square [0,L] x [0,L]. No contact pair
// (single body, so no slave/master).
//
// Physical names (contract, read as DMLabels with -dm_plex_gmsh_use_regions):
//   Physical Surface "square"   (tag 1)   the square
//   Physical Curve   "boundary" (tag 10)  the whole boundary (the four edges)
//   Physical Curve   "bottom"   (tag 11)  edge y = 0
//   Physical Curve   "right"    (tag 12)  edge x = L
//   Physical Curve   "top"      (tag 13)  edge y = L
//   Physical Curve   "left"     (tag 14)  edge x = 0
//
// Parameters (gmsh -setnumber NAME value):
//   L  (1.0)  edge length
//   h  (0.1)  mesh size (relative to L), multiplied by -clscale
// Mesh: gmsh -2 meshes/unit_square.geo -o unit_square.msh -format msh41   (format 2.2 mislabels with PETSc 3.18: docs/bad_input.md)

DefineConstant[
  L = {1.0, Min 1e-3, Max 100, Name "Parameters/L"},
  h = {0.1, Min 1e-4, Max 10,  Name "Parameters/h"}
];

Point(1) = {0, 0, 0, h*L};
Point(2) = {L, 0, 0, h*L};
Point(3) = {L, L, 0, h*L};
Point(4) = {0, L, 0, h*L};
Line(1) = {1, 2};   // bottom
Line(2) = {2, 3};   // right
Line(3) = {3, 4};   // top
Line(4) = {4, 1};   // left
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Physical Surface("square", 1)  = {1};
Physical Curve("boundary", 10) = {1, 2, 3, 4};
Physical Curve("bottom", 11)   = {1};
Physical Curve("right", 12)    = {2};
Physical Curve("top", 13)      = {3};
Physical Curve("left", 14)     = {4};
