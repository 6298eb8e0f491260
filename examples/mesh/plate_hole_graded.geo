// The plate with a hole of plate_hole.geo (2 W x W, W = 1, hole diameter W/10), meshed finer
// near the hole: element size 0.005 m on the hole, growing linearly with the distance from it to
// 0.02 m at 0.5 m (a gentle grading: a steeper one biases the stress at the hole, docs/mesh.md).
// particles.size (Mesh.MeshSizeMax) should be the coarse size, 0.02. Physical groups as in
// plate_hole.geo.
Include "plate_hole.geo"; // the geometry and groups; curves 5-8 are the hole
// The size field alone sets the element size (bounded above by particles.size), not the points.
Field[1] = Distance;
Field[1].CurvesList = {5, 6, 7, 8};
Field[1].NumPointsPerCurve = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = 0.005;
Field[2].SizeMax = 0.02;
Field[2].DistMin = 0;
Field[2].DistMax = 0.5;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
