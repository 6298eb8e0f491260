// Ganzenmueller et al. sec. 3.1.2 (Fig. 5-6): a bar meshed by a deliberately poor stochastic
// tetrahedral mesh. The bar is 200 x 4 x 4 (the paper's is 500 long; the pulse's centre reaches
// x = 126 at t = 94 and its front 150, so 200 is all the run sees). Twelve balls at random places
// (Gmsh's Rand: the same numbers on every run) with random radii ask for elements of 0.25-0.6
// inside and the largest size (particles.size) outside; Mesh.Optimize = 0 leaves the slivers
// Delaunay made. At particles.size 3: 1443 tetrahedra, radii cbrt(V) over a range of 10
// (docs/mesh.md, "A pressure pulse on stochastic meshes"); particles.refine splits each into 8.
SetFactory("Built-in");
L = 200;
W = 4;
Point(1) = {0, 0, 0};
Point(2) = {L, 0, 0};
Point(3) = {L, W, 0};
Point(4) = {0, W, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
out[] = Extrude {0, 0, W} { Surface{1}; };
Physical Volume("bar") = {out[1]};
N = 12;
For i In {1:N}
  Field[i] = Ball;
  Field[i].Radius = 0.3 + Rand(1.2);
  Field[i].Thickness = 0.5;
  Field[i].VIn = 0.25 + Rand(0.35);
  Field[i].VOut = 1e22;
  Field[i].XCenter = Rand(L);
  Field[i].YCenter = Rand(W);
  Field[i].ZCenter = Rand(W);
EndFor
Field[N + 1] = Min;
Field[N + 1].FieldsList = {1:N};
Background Field = N + 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.Optimize = 0;
