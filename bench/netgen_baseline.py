#!/usr/bin/python3
"""Run Netgen's own volume optimizer (Debian's python3-netgen) on a tet mesh,
in its own process.

  netgen_baseline.py IN OUT [--load-only]

The tets are handed to Netgen through its neutral format (ImportMesh), then
Mesh.OptimizeVolumeMesh() runs: in netgen 6.2 that is OptimizeVolume with
default MeshingParameters and 5 steps of its default "cmdmustm" sequence --
edge collapse (c), smoothing (m), edge split (d), face/edge swaps (u, s, t):
it changes the topology, unlike GETMe.  Only that call is timed.  The result
is compressed (unused points dropped) and written as MSH 2.2 with meshio
(meshio's 4.1 files lack the $Entities Gmsh needs),
tets in Gmsh node order.  --load-only does everything but the optimization
(the memory baseline).  Prints one JSON line {"method", "seconds"}.
"""

import argparse
import json
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from meshdata import read_mesh  # noqa: E402
from skin import boundary_faces  # noqa: E402

# Netgen's tets have the opposite orientation to Gmsh's: swap two nodes.
SWAP = [1, 0, 2, 3]


def write_neutral(path, points, tets, regions, tris):
    """Netgen neutral format: points; 'domain n1..n4' tets; 'bc n1..n3'
    surface triangles (1-based)."""
    with open(path, "w") as f:
        f.write(f"{len(points)}\n")
        np.savetxt(f, points, fmt="%.17g")
        f.write(f"{len(tets)}\n")
        np.savetxt(f, np.column_stack([regions, tets[:, SWAP] + 1]), fmt="%d")
        f.write(f"{len(tris)}\n")
        np.savetxt(f, np.column_stack([np.ones(len(tris), np.int64), tris + 1]),
                   fmt="%d")


def read_neutral(path):
    """Points, tets (Gmsh order, 0-based) and domains of a neutral file."""
    with open(path) as f:
        tok = f.read().split()
    n = int(tok[0])
    pts = np.array(tok[1:1 + 3 * n], dtype=np.float64).reshape(n, 3)
    pos = 1 + 3 * n
    ne = int(tok[pos])
    vol = np.array(tok[pos + 1:pos + 1 + 5 * ne], dtype=np.int64).reshape(ne, 5)
    return pts, vol[:, 1:][:, SWAP] - 1, vol[:, 0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--load-only", action="store_true")
    args = ap.parse_args()

    mesh = read_mesh(args.input)
    if [t for t, _ in mesh.blocks] != ["tet"]:
        print("Error   : Netgen's volume optimizer takes tetrahedral meshes only",
              file=sys.stderr)
        return 2
    tets = mesh.blocks[0][1]
    # Netgen's domains must be numbered 1..n
    region_ids, regions = np.unique(mesh.regions[0], return_inverse=True)
    # faces come sorted and -1 padded in front: a triangle is the last three
    skin = boundary_faces(mesh.blocks, mesh.regions)[:, 1:]

    import netgen.meshing as ngm
    ngm.SetMessageImportance(0)
    with tempfile.TemporaryDirectory() as tmp:
        src = os.path.join(tmp, "in.mesh")
        write_neutral(src, mesh.points, tets, regions + 1, skin)
        ngmesh = ngm.ImportMesh(src)
        seconds = 0.0
        if not args.load_only:
            start = time.perf_counter()
            ngmesh.OptimizeVolumeMesh()
            seconds = time.perf_counter() - start
        ngmesh.Compress()
        dst = os.path.join(tmp, "out.mesh")
        ngmesh.Export(dst, "Neutral Format")
        _, out_tets, domains = read_neutral(dst)
        # the neutral file rounds coordinates to ~7 digits: take them exactly
        points = np.array([p.p for p in ngmesh.Points()], dtype=np.float64)
    domains = region_ids[domains - 1]  # back to the input's region ids

    import meshio
    out = meshio.Mesh(points, [("tetra", out_tets)],
                      cell_data={"gmsh:physical": [domains],
                                 "gmsh:geometrical": [domains]})
    tmp_out = args.output + ".tmp.msh"
    meshio.write(tmp_out, out, file_format="gmsh22", binary=True)
    os.replace(tmp_out, args.output)
    print(json.dumps({"method": "netgen", "seconds": seconds}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
