// hertz3d.geo -- 3D Hertz: a solid hemisphere of radius R (flat face up, at z = R) touching a block [-L/2,L/2]^2 x [-L/2,0]
// at the origin (runs/hertz3d.opts). The hemisphere is split at the height zc where its surface is rc from the axis:
// the curved face of the lower cap is the slave surface; the block's top face is the master.
//
// Physical names: volumes "sphere" (1), "block" (2); surfaces "slave" (11, the cap's curved face), "sphere_top" (12,
// z = R), "master" (21, z = 0), "block_bottom" (22, z = -L/2).
// Parameters (-mesh_geo_set): R (1), L (6), rc (0.5), h_fine (0.035: the size at the contact point, growing by 0.3 per
// unit distance beyond 0.6 rc), h_far (0.8), master_ratio (0.5: the block's size / the sphere's near the contact).
DefineConstant[
  R      = {1.0, Min 0.1, Max 10, Name "Parameters/R"},
  L      = {6.0, Min 1, Max 100, Name "Parameters/L"},
  rc     = {0.5, Min 0.05, Max 1, Name "Parameters/rc"},
  h_fine = {0.035, Min 1e-3, Max 1, Name "Parameters/h_fine"},
  h_far  = {0.8, Min 1e-2, Max 10, Name "Parameters/h_far"},
  master_ratio = {0.5, Min 0.1, Max 2, Name "Parameters/master_ratio"}
];
SetFactory("OpenCASCADE");
zc = R - Sqrt(R*R - rc*rc);
// the sphere turned so that its parametrization's poles are on the y axis, away from the contact point (a mesh
// pole there has a fan of slivers and a wrong nodal pressure)
Sphere(1) = {0, 0, R, R};
Rotate {{1, 0, 0}, {0, 0, R}, Pi/2} { Volume{1}; }
Box(2) = {-2*R, -2*R, R, 4*R, 4*R, 2*R};
hemi() = BooleanDifference{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(4) = {-2*R, -2*R, zc, 4*R, 4*R, 2*R};
parts() = BooleanFragments{ Volume{hemi()}; Delete; }{ Volume{4}; Delete; };
s() = Volume In BoundingBox{-R - 1e-6, -R - 1e-6, -1e-6, R + 1e-6, R + 1e-6, R + 1e-6};
out() = parts();
out() -= s();
Recursive Delete { Volume{out()}; }
Box(3) = {-L/2, -L/2, -L/2, L, L, L/2};
eps = 1e-3;
// OpenCASCADE bounding boxes of curved faces are loose: select the cap face with a margin, then drop the disk
capCurved() = Surface In BoundingBox{-1.2 * rc, -1.2 * rc, -eps, 1.2 * rc, 1.2 * rc, 0.5 * (zc + R)};
disk() = Surface In BoundingBox{-rc - eps, -rc - eps, zc - eps, rc + eps, rc + eps, zc + eps};
capCurved() -= disk();
top() = Surface In BoundingBox{-R - eps, -R - eps, R - eps, R + eps, R + eps, R + eps};
blockTop() = Surface In BoundingBox{-L/2 - eps, -L/2 - eps, -eps, L/2 + eps, L/2 + eps, eps};
blockBottom() = Surface In BoundingBox{-L/2 - eps, -L/2 - eps, -L/2 - eps, L/2 + eps, L/2 + eps, -L/2 + eps};
Physical Volume("sphere", 1) = {s()};
Physical Volume("block", 2) = {3};
Physical Surface("slave", 11) = {capCurved()};
Physical Surface("sphere_top", 12) = {top()};
Physical Surface("master", 21) = {blockTop()};
Physical Surface("block_bottom", 22) = {blockBottom()};
// mesh size: h_fine near the contact, growing with the distance from it to h_far; the master (block) side
// finer than the slave (ratio master_ratio), as the contact docs recommend
Field[1] = MathEval;
Field[1].F = Sprintf("Min(%g, %g + 0.3 * Max(0, Sqrt(x*x + y*y + z*z) - %g))", h_far, h_fine, 0.6 * rc);
Field[2] = MathEval;
Field[2].F = Sprintf("Min(%g, %g + 0.3 * Max(0, Sqrt(x*x + y*y + z*z) - %g))", h_far, master_ratio * h_fine, 0.6 * rc);
Field[3] = Restrict;
Field[3].InField = 2;
Field[3].VolumesList = {3};
Field[4] = Min;
Field[4].FieldsList = {1, 3};
Background Field = 4;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
