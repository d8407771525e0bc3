// flat_punch3d.geo -- 3D patch test: a punch [0,1]^2 x [0,0.5] on a base [0,1]^2 x [-0.5,0], flat on flat,
// with non-matching interface meshes. The boxes are two separate OpenCASCADE volumes (no fragment, so the
// faces at z = 0 are distinct); the slave face's edges are split in n_punch pieces, the master face's in
// n_base (Transfinite Curve), the volumes meshed with tetrahedra of size at most h.
//
// Physical names (runs/flat_punch3d.opts):
//   Physical Volume  "punch" (1), "base" (2)
//   Physical Surface "slave" (11): punch bottom z = 0;  "master" (21): base top z = 0
//                    "punch_top" (12) z = 0.5;  "base_bottom" (22) z = -0.5
//                    "punch_x0" (13), "base_x0" (23): faces x = 0;  "punch_y0" (14), "base_y0" (24): faces y = 0
//
// Parameters (-mesh_geo_set): n_punch (4), n_base (7), h (0.25).
// Mesh: gmsh -3 meshes/flat_punch3d.geo -format msh41 (rbcontact does it, cached).
DefineConstant[
  n_punch = {4, Min 1, Max 200, Name "Parameters/n_punch"},
  n_base  = {7, Min 1, Max 200, Name "Parameters/n_base"},
  h       = {0.25, Min 1e-3, Max 10, Name "Parameters/h"}
];
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 0.5};
Box(2) = {0, 0, -0.5, 1, 1, 0.5};
Mesh.MeshSizeMax = h;
c1[] = Boundary{ Surface{5}; };
c2[] = Boundary{ Surface{12}; };
For i In {0 : #c1[] - 1}
  Transfinite Curve{Abs(c1[i])} = n_punch + 1;
EndFor
For i In {0 : #c2[] - 1}
  Transfinite Curve{Abs(c2[i])} = n_base + 1;
EndFor
// OpenCASCADE box faces: x = 0, x = 1, y = 0, y = 1, z = min, z = max (box 2: 7..12)
Physical Volume("punch", 1) = {1};
Physical Volume("base", 2)  = {2};
Physical Surface("slave", 11)     = {5};
Physical Surface("punch_top", 12) = {6};
Physical Surface("punch_x0", 13)  = {1};
Physical Surface("punch_y0", 14)  = {3};
Physical Surface("master", 21)      = {12};
Physical Surface("base_bottom", 22) = {11};
Physical Surface("base_x0", 23)     = {7};
Physical Surface("base_y0", 24)     = {9};
