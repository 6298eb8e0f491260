// A 1 x 0.2 x 0.2 block meshed with tetrahedra: tests/mesh/ and examples/mesh/bar_tet.yaml.
SetFactory("Built-in");
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 0.2, 0};
Point(4) = {0, 0.2, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
out[] = Extrude {0, 0, 0.2} { Surface{1}; };
// out[0] the top, out[1] the volume, out[2..5] the sides on lines 1..4
Physical Volume("block") = {out[1]};
Physical Surface("left") = {out[5]};
Physical Surface("right") = {out[3]};
Physical Surface("bottom") = {out[2]};
Physical Surface("back") = {1};
