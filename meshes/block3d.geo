// block3d.geo -- unit cube, single elastic body, tetrahedra (3D sanity / smoke-test mesh).
//
// Scene (3D, dimensionless length units): box [0,1] x [0,1] x [0,1]. No contact pair
// (single body, so no slave/master).
//
// Physical names (contract, read as DMLabels with -dm_plex_gmsh_use_regions):
//   Physical Volume  "block"  (tag 1)   the cube
//   Physical Surface "bottom" (tag 11)  face z = 0
//   Physical Surface "top"    (tag 12)  face z = 1
//   Physical Surface "sides"  (tag 13)  the four faces x = 0, x = 1, y = 0, y = 1
//
// Parameters (gmsh -setnumber NAME value):
//   L  (1.0)  edge length
//   h  (0.17) mesh size, multiplied by -clscale
// Mesh: gmsh -3 meshes/block3d.geo -o block3d.msh -format msh41   (format 2.2 mislabels with PETSc 3.18: docs/bad_input.md)

DefineConstant[
  L = {1.0, Min 1e-3, Max 100, Name "Parameters/L"},
  h = {0.17,Min 1e-4, Max 10,  Name "Parameters/h"}
];

Point(1) = {0, 0, 0, h*L};
Point(2) = {L, 0, 0, h*L};
Point(3) = {L, L, 0, h*L};
Point(4) = {0, L, 0, h*L};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};                       // bottom, z = 0

out[] = Extrude {0, 0, L} { Surface{1}; };    // out[0] = top, out[1] = volume, out[2..5] = sides

Physical Volume("block", 1)    = {out[1]};
Physical Surface("bottom", 11) = {1};
Physical Surface("top", 12)    = {out[0]};
Physical Surface("sides", 13)  = {out[2], out[3], out[4], out[5]};
