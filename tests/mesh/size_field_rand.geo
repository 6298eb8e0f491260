// A unit square with a MathEval size field Gmsh 4.8 cannot parse (Rand is not one of MathEval's
// functions): Gmsh throws inside an OpenMP region and aborts the process. perilin meshes .geo
// files in a child process and reports it (tests/bad_input/syntax/mesh_geo_aborts.yaml).
SetFactory("Built-in");
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 1, 0};
Point(4) = {0, 1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("square") = {1};
Field[1] = MathEval;
Field[1].F = "0.02 + 0.05*Rand(1)";
Background Field = 1;
