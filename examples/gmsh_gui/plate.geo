// A planar plate with two holes, meshed with triangles: the GUI demo model
// for GETMe adaptive (docs/gmsh.md, "The Gmsh GUI").
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 4, 2};
Disk(2) = {1.2, 1, 0, 0.45};
Disk(3) = {2.9, 1.1, 0, 0.3};
BooleanDifference{ Surface{1}; Delete; }{ Surface{2, 3}; Delete; }
Physical Surface("plate") = {1};
Physical Curve("holes") = {5, 6};
Mesh.MeshSizeMax = 0.12;
