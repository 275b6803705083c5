"""A minimal Abaqus/CalculiX deck reader for the second-order tests: *NODE
and *ELEMENT data (continuation lines included), enough to check node
order; and the Abaqus -> Gmsh node order of the types (docs/highorder.md)."""
import gzip

import numpy as np

# Gmsh's node k is Abaqus' node ABAQUS_TO_GMSH[type][k] (0-based).
ABAQUS_TO_GMSH = {
    10: (11, [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]),
    15: (18, [0, 1, 2, 3, 4, 5, 6, 8, 12, 7, 13, 14, 9, 11, 10]),
    20: (17, [0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 16, 9, 17, 10, 18, 19, 12, 15,
              13, 14]),
}


def read(path):
    """(node id -> xyz, [(TYPE, [(elem id, [node ids])])])"""
    opener = gzip.open if path.endswith(".gz") else open
    nodes, blocks = {}, []
    mode, nv, cur, pending = None, 0, None, []
    with opener(path, "rt", errors="replace") as f:
        for raw in f:
            line = raw.strip()
            if not line or line.startswith("**"):
                continue
            if line.startswith("*"):
                kw = line.upper().replace(" ", "")
                mode = None
                if kw.startswith("*NODE") and not kw.startswith("*NODEPRINT") \
                        and not kw.startswith("*NODEFILE") \
                        and not kw.startswith("*NODEOUTPUT"):
                    mode = "node"
                elif kw.startswith("*ELEMENT") and "TYPE=" in kw:
                    t = kw.split("TYPE=")[1].split(",")[0]
                    digits = "".join(c for c in t[3:] if c.isdigit())
                    if t.startswith("C3D") and digits:
                        mode, nv = "elem", int(digits)
                        cur = (t, [])
                        blocks.append(cur)
                        pending = []
                continue
            vals = [v for v in line.replace(",", " ").split()]
            if mode == "node":
                xyz = [float(v) for v in vals[1:4]]
                nodes[int(vals[0])] = np.array(xyz + [0.0] * (3 - len(xyz)))
            elif mode == "elem":
                pending += [int(v) for v in vals]
                if len(pending) >= nv + 1:
                    cur[1].append((pending[0], pending[1:nv + 1]))
                    pending = []
    return nodes, blocks
