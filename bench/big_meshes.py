#!/usr/bin/python3
"""big_meshes.py KIND SIZE OUT [BINARY_OUT] -- inputs for size tests
beyond the benchmark's own meshes (docs/bench.md, "Session 26"): meshes
nobody tuned getme on, at sizes the benchmark does not reach.

  part SIZE   a real CAD part as a user meshes it: an OpenCASCADE block
              with eight through holes, fragmented with a sphere and a box
              inclusion (3 volumes, each its own physical group, so their
              interfaces are fixed), meshed by Gmsh's parallel HXT with
              Mesh.Optimize = 0 (raw Delaunay tets, slivers included).
              SIZE is the largest mesh size: 0.066 gives ~3.0M tets,
              0.042 ~11.2M (about 90 s and 5 GB in Gmsh on 2 cores).
              Writes OUT as MSH 4.1 ASCII, and BINARY_OUT, if given, as
              binary (no other file is written).
  kuhn N      an N x N x N box of cubes, each split into 6 tets along its
              diagonal (6 N^3 tets, (N + 1)^3 nodes), written straight as
              MSH 4.1 binary without Gmsh (N = 171: 30.0M tets, 1.36 GB,
              ~20 s and ~3 GB here).  Every tet has the same quality
              (0.7560): distort it first (getme distort --seed 1), and the
              smoother should bring it back near that value.

  /usr/bin/python3 bench/big_meshes.py part 0.066 /work/cache/cad3.msh \\
      /work/cache/cad3-bin.msh
  /usr/bin/python3 bench/big_meshes.py kuhn 171 /work/cache/kuhn30.msh
"""
import sys

import numpy as np


def part(h, out, binary_out):
    import gmsh
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 1)
    gmsh.option.setNumber("General.NumThreads", 2)
    occ = gmsh.model.occ
    box = occ.addBox(0, 0, 0, 10, 6, 4)
    holes = [(3, occ.addCylinder(1.5 + 2.3 * i, 1.8 + 2.4 * j, -1, 0, 0, 6, 0.6))
             for i in range(4) for j in range(2)]
    body = occ.cut([(3, box)], holes)[0]
    occ.fragment(body, [(3, occ.addSphere(5, 3, 2, 1.0)),
                        (3, occ.addBox(0.5, 0.5, 1.0, 2, 0.6, 2))])
    occ.synchronize()
    vols = gmsh.model.getEntities(3)
    for k, (_, t) in enumerate(vols):
        gmsh.model.addPhysicalGroup(3, [t], k + 1)
    skin = [t for _, t in gmsh.model.getBoundary(vols, combined=True,
                                                  oriented=False)]
    gmsh.model.addPhysicalGroup(2, skin, 100)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeMin", h / 3)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
    gmsh.option.setNumber("Mesh.Algorithm3D", 10)  # HXT, parallel
    gmsh.option.setNumber("Mesh.Optimize", 0)
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.write(out)
    if binary_out:
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.write(binary_out)
    gmsh.finalize()


def kuhn(n, out):
    m = n + 1
    g = np.arange(m, dtype=np.float64)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    coords = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)
    del x, y, z
    i, j, k = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n),
                                               np.arange(n), indexing="ij"))
    corner = [((i + a) * m + (j + b)) * m + (k + c) for a, b, c in
              [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0),
               (0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1)]]
    del i, j, k
    # the six tets around the diagonal 0-7 (Kuhn's subdivision)
    six = [(0, 1, 3, 7), (0, 3, 2, 7), (0, 2, 6, 7),
           (0, 6, 4, 7), (0, 4, 5, 7), (0, 5, 1, 7)]
    tets = np.empty((len(corner[0]) * 6, 4), dtype=np.uint64)
    for t, nodes in enumerate(six):
        tets[t::6] = np.stack([corner[c] for c in nodes], 1)
    del corner
    # Gmsh's positive orientation: swap two corners if the first cube's
    # tets are negative (they all have the same sign)
    p = coords[tets[:6].astype(np.int64)]
    vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                    p[:, 3] - p[:, 0])
    if (vol < 0).all():
        tets[:, [1, 2]] = tets[:, [2, 1]]
    elif not (vol > 0).all():
        sys.exit("big_meshes.py: Kuhn tets of mixed orientation")
    nn, ne = len(coords), len(tets)
    u64 = lambda *v: np.array(v, np.uint64).tobytes()  # noqa: E731
    i32 = lambda *v: np.array(v, np.int32).tobytes()  # noqa: E731
    with open(out, "wb") as f:
        f.write(b"$MeshFormat\n4.1 1 8\n" + i32(1) + b"\n$EndMeshFormat\n")
        # one volume entity (tag 1), no physical group, no bounding entities
        f.write(b"$Entities\n" + u64(0, 0, 0, 1) + i32(1) +
                np.array([0, 0, 0, n, n, n], np.float64).tobytes() +
                u64(0) + u64(0) + b"\n$EndEntities\n")
        f.write(b"$Nodes\n" + u64(1, nn, 1, nn) + i32(3, 1, 0) + u64(nn))
        f.write(np.arange(1, nn + 1, dtype=np.uint64).tobytes())
        f.write(coords.tobytes() + b"\n$EndNodes\n")
        del coords
        f.write(b"$Elements\n" + u64(1, ne, 1, ne) + i32(3, 1, 4) + u64(ne))
        rows = np.empty((ne, 5), np.uint64)
        rows[:, 0] = np.arange(1, ne + 1, dtype=np.uint64)
        rows[:, 1:] = tets + 1
        f.write(rows.tobytes() + b"\n$EndElements\n")
    print(f"{out}: {nn} nodes, {ne} tets")


def main(argv):
    if not (len(argv) == 4 or (len(argv) == 5 and argv[1] == "part")) or \
            argv[1] not in ("part", "kuhn"):
        sys.exit(__doc__)
    if argv[1] == "part":
        part(float(argv[2]), argv[3], argv[4] if len(argv) == 5 else None)
    else:
        kuhn(int(argv[2]), argv[3])


if __name__ == "__main__":
    main(sys.argv)
