#!/usr/bin/python3
"""highorder_mesh.py IN.msh OUT.msh [--curve REL] -- the second-order
benchmark input (docs/bench.md, "Second order"): Gmsh raises IN's order
to 2 (mid-edge nodes at the midpoints of IN's possibly distorted corners,
so the tets stay straight-sided), and with --curve every interior
mid-edge node is then pushed off its edge by REL times the edge length,
perpendicular to it, so that every element is curved and the smoother's
check at all nodes runs for each (straight tet10 take the affine
shortcut of docs/highorder.md).  Writes binary MSH 4.1.

  /usr/bin/python3 bench/highorder_mesh.py \\
      /work/cache/tet-medium-g1-h1.08-seed1-q0.45.msh tet10.msh
  /usr/bin/python3 bench/highorder_mesh.py \\
      /work/cache/tet-medium-g1-h1.08-seed1-q0.45.msh tet10c.msh --curve 1e-6
"""
import sys

import gmsh
import numpy as np

EDGES = [(4, 0, 1), (5, 1, 2), (6, 0, 2), (7, 0, 3), (8, 2, 3), (9, 1, 3)]


def curve(rel):
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = np.array(xyz).reshape(-1, 3)
    idx = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    idx[tags] = np.arange(len(tags))
    low = np.zeros(len(tags), bool)
    for d in (0, 1, 2):
        t = gmsh.model.mesh.getNodes(d, -1, includeBoundary=True)[0]
        low[idx[np.array(t, dtype=np.int64)]] = True
    _, conn = gmsh.model.mesh.getElementsByType(11)
    conn = idx[np.array(conn, dtype=np.int64).reshape(-1, 10)]
    m = np.concatenate([conn[:, k] for k, _, _ in EDGES])
    a = np.concatenate([conn[:, i] for _, i, _ in EDGES])
    b = np.concatenate([conn[:, j] for _, _, j in EDGES])
    m, first = np.unique(m, return_index=True)
    a, b = a[first], b[first]
    keep = ~low[m]
    m, a, b = m[keep], a[keep], b[keep]
    e = xyz[b] - xyz[a]
    p = np.cross(e, np.array([0.3, 0.5, 0.8]))
    p *= (rel * np.linalg.norm(e, axis=1) / np.linalg.norm(p, axis=1))[:, None]
    for i, v in zip(m, xyz[m] + p):
        gmsh.model.mesh.setNode(int(tags[i]), v.tolist(), [])
    return len(m)


def main():
    args = sys.argv[1:]
    if "-h" in args or "--help" in args:
        print(__doc__)
        return
    rel = None
    if "--curve" in args:
        k = args.index("--curve")
        if k + 1 >= len(args):
            sys.exit("highorder_mesh.py: --curve needs a value (see --help)")
        rel = float(args[k + 1])
        del args[k:k + 2]
    if len(args) != 2:
        sys.exit("usage: highorder_mesh.py IN.msh OUT.msh [--curve REL] (see --help)")
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(args[0])
    gmsh.model.mesh.setOrder(2)
    if rel is not None:
        print("curved %d interior mid-edge nodes" % curve(rel))
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.write(args[1])
    gmsh.finalize()


if __name__ == "__main__":
    main()
