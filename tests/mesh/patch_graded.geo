// The patch test of issue 27: a 2 x 2 square of triangles graded from 0.01 around its centre
// (r < 0.1) to 0.1 beyond r = 0.8, element sizes over a ratio of 10 (tests/mesh/patch_graded.yaml).
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 2, 2};
Point(10) = {1, 1, 0};
Field[1] = Distance;
Field[1].PointsList = {10};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.01;
Field[2].SizeMax = 0.1;
Field[2].DistMin = 0.1;
Field[2].DistMax = 0.8;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Physical Surface("square") = {1};
