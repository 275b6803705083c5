#!/usr/bin/env python3
# Make the bundled example: a bracket with two holes, tet-meshed by Gmsh
# (OpenCASCADE), then distorted with `getme distort` (see examples/README.md).
# usage: /usr/bin/python3 examples/make_bracket.py OUT.msh MESH_SIZE
import gmsh, sys
gmsh.initialize(); gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("bracket")
occ = gmsh.model.occ
b = occ.addBox(0, 0, 0, 4, 2, 1)
c1 = occ.addCylinder(1, 1, -0.1, 0, 0, 1.2, 0.45)
c2 = occ.addCylinder(3, 1, -0.1, 0, 0, 1.2, 0.3)
out, _ = occ.cut([(3, b)], [(3, c1), (3, c2)])
occ.synchronize()
vols = [t for d, t in gmsh.model.getEntities(3)]
gmsh.model.addPhysicalGroup(3, vols, 1); gmsh.model.setPhysicalName(3, 1, "steel")
surfs = [t for d, t in gmsh.model.getEntities(2)]
gmsh.model.addPhysicalGroup(2, surfs, 2); gmsh.model.setPhysicalName(2, 2, "skin")
gmsh.option.setNumber("Mesh.MeshSizeMax", float(sys.argv[2]))
gmsh.model.mesh.generate(3)
gmsh.write(sys.argv[1])
gmsh.finalize()
