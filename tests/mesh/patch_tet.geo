// The 3D patch test of issue 27: a unit cube of tetrahedra graded from 0.02 at its centre to 0.2
// at r = 0.45, element sizes over a ratio of 10 (tests/mesh/patch_tet.yaml).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Point(100) = {0.5, 0.5, 0.5};
Field[1] = Distance;
Field[1].PointsList = {100};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.02;
Field[2].SizeMax = 0.2;
Field[2].DistMin = 0.0;
Field[2].DistMax = 0.45;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.RandomSeed = 1;
Physical Volume("cube") = {1};
