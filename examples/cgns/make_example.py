#!/usr/bin/python3
"""Regenerate examples/cgns/hybrid.cgns (the bundled file is its output).

A hybrid mesh made by Gmsh -- a hex block, tet blocks with pyramids where
they meet the hexes, an extruded prism cylinder -- with the outer faces
tagged by physical surface, written as AFLR3 .ugrid and converted
to CGNS by the CGNS project's aflr3_to_cgns (Debian cgns-convert), which
turns the surface tags into BCs.  `getme distort` then moves interior nodes
so that there is something to smooth.

usage: make_example.py GETME [OUT.cgns]
"""
import os
import subprocess
import sys
import tempfile

import gmsh
import meshio
import numpy as np


def hybrid_geometry(size=0.2, edge_nodes=6, layers=4):
    """Start Gmsh and build the example's model: a structured hex cube
    (edge_nodes per edge), two unstructured boxes meshed with tets
    (pyramids where they meet the hexes) at size, and a cylinder
    extruded in layers of prisms.  tests/cgns/test_cgns_interop.py
    builds the same model, coarser."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    occ = gmsh.model.occ
    b1 = occ.addBox(0, 0, 0, 1, 1, 1)
    b2 = occ.addBox(1, 0, 0, 1, 1, 1)
    b3 = occ.addBox(0, 1, 0, 2, 1, 1)
    occ.fragment([(3, b1)], [(3, b2), (3, b3)])
    disk = occ.addDisk(3.5, 0.5, 0, 0.5, 0.5)
    occ.extrude([(2, disk)], 0, 0, 1, numElements=[layers], recombine=True)
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    for dim, tag in gmsh.model.getBoundary([(3, b1)], combined=False,
                                           oriented=False, recursive=True):
        if dim == 1:
            gmsh.model.mesh.setTransfiniteCurve(tag, edge_nodes)
    for dim, tag in gmsh.model.getBoundary([(3, b1)], combined=False,
                                           oriented=False):
        gmsh.model.mesh.setTransfiniteSurface(tag)
        gmsh.model.mesh.setRecombine(2, tag)
    gmsh.model.mesh.setTransfiniteVolume(b1)


def main():
    getme = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "hybrid.cgns")
    work = tempfile.mkdtemp(prefix="getme-cgns-example-")
    hybrid_geometry()
    # the skin: z = 0 faces are "floor", everything else "walls"
    floor, walls = [], []
    for dim, tag in gmsh.model.getBoundary(gmsh.model.getEntities(3),
                                           oriented=False):
        zmax = gmsh.model.getBoundingBox(dim, tag)[5]
        (floor if zmax < 1e-9 else walls).append(tag)
    gmsh.model.addPhysicalGroup(2, floor, 1)
    gmsh.model.addPhysicalGroup(2, walls, 2)
    gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], 3)
    gmsh.model.mesh.generate(3)
    msh = os.path.join(work, "hybrid.msh")
    gmsh.write(msh)
    gmsh.finalize()

    m = meshio.read(msh)
    blocks, refs = {}, {}
    for c, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
        blocks.setdefault(c.type, []).append(c.data)
        refs.setdefault(c.type, []).append(phys)
    cells = {k: np.vstack(v) for k, v in blocks.items()}
    ref = {k: np.concatenate(v) for k, v in refs.items()}

    def block(kind, nv):
        return cells.get(kind, np.zeros((0, nv), int))

    # AFLR3 ASCII .ugrid: counts, coordinates, boundary faces, their tags,
    # then tets, pyramids, prisms, hexes; 1-based.  UGRID numbers a pyramid
    # (1, 0, 4, 2, 3) relative to Gmsh's order (apex third).
    tri, quad = block("triangle", 3), block("quad", 4)
    tet, pyr = block("tetra", 4), block("pyramid", 5)[:, [1, 0, 4, 2, 3]]
    pri, hexa = block("wedge", 6), block("hexahedron", 8)
    ugrid = os.path.join(work, "hybrid.ugrid")
    with open(ugrid, "w") as f:
        f.write(f"{len(m.points)} {len(tri)} {len(quad)} {len(tet)} {len(pyr)} "
                f"{len(pri)} {len(hexa)}\n")
        for p in m.points:
            f.write(f"{p[0]!r} {p[1]!r} {p[2]!r}\n")
        for arr in (tri, quad):
            for row in arr:
                f.write(" ".join(str(v + 1) for v in row) + "\n")
        for kind, arr in (("triangle", tri), ("quad", quad)):
            for r in ref.get(kind, [])[:len(arr)]:
                f.write(f"{r}\n")
        for arr in (tet, pyr, pri, hexa):
            for row in arr:
                f.write(" ".join(str(v + 1) for v in row) + "\n")
    raw = os.path.join(work, "hybrid-raw.cgns")
    subprocess.run(["aflr3_to_cgns", "-f", ugrid, raw], check=True,
                   capture_output=True)
    subprocess.run([getme, "distort", raw, "-o", out, "--seed", "7", "--rounds", "4",
                    "-q"], check=True)
    print("wrote", out)


if __name__ == "__main__":
    main()
