// A plate of length 2 W along x and width W = 1 across, with a central hole of diameter W/10.
// Meshed by perilin with particles.size (Mesh.MeshSizeMax). Physical groups become regions:
// "plate" (every particle), "left" and "right" (the loaded edges: the elements with a side on
// them), "hole" (the elements with a side on the hole).
W = 1;
L = 2 * W;
R = W / 20;
Point(1) = {-L / 2, -W / 2, 0};
Point(2) = {L / 2, -W / 2, 0};
Point(3) = {L / 2, W / 2, 0};
Point(4) = {-L / 2, W / 2, 0};
Point(5) = {0, 0, 0};
Point(6) = {R, 0, 0};
Point(7) = {0, R, 0};
Point(8) = {-R, 0, 0};
Point(9) = {0, -R, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};
Physical Surface("plate") = {1};
Physical Curve("left") = {4};
Physical Curve("right") = {2};
Physical Curve("hole") = {5, 6, 7, 8};
