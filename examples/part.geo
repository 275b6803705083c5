// A box with a cylinder insert (two materials) and a clamped face: the
// model of the `getme gmsh` example in docs/gmsh.md and of its test
// (tests/plugin/test_cli_gmsh.sh).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 2, 1, 1};
Cylinder(2) = {1, 0.5, -0.2, 0, 0, 1.4, 0.3};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Physical Volume("matrix") = {3};
Physical Volume("insert") = {2};
Physical Surface("clamp") = {1};
