"""Checks shared by the second-order tests: node order tables in Gmsh's
order (docs/highorder.md), read through the gmsh Python API, Jacobians by
Gmsh's own code."""
import gmsh
import numpy as np

# Gmsh type -> (name, corners, mid-edge nodes as (node, corner a, corner b),
# face/body nodes as (node, corners...)).  Proved against Gmsh's reference
# elements in check_tables() and against meshes in midpoint_errors().
TYPES = {
    11: ("tet10", 4, [(4, 0, 1), (5, 1, 2), (6, 0, 2), (7, 0, 3), (8, 2, 3),
                      (9, 1, 3)], []),
    17: ("hex20", 8, [(8, 0, 1), (9, 0, 3), (10, 0, 4), (11, 1, 2),
                      (12, 1, 5), (13, 2, 3), (14, 2, 6), (15, 3, 7),
                      (16, 4, 5), (17, 4, 7), (18, 5, 6), (19, 6, 7)], []),
    18: ("prism15", 6, [(6, 0, 1), (7, 0, 2), (8, 0, 3), (9, 1, 2),
                        (10, 1, 4), (11, 2, 5), (12, 3, 4), (13, 3, 5),
                        (14, 4, 5)], []),
}
TYPES[12] = ("hex27", 8, TYPES[17][2],
             [(20, 0, 1, 2, 3), (21, 0, 1, 5, 4), (22, 0, 3, 7, 4),
              (23, 1, 2, 6, 5), (24, 2, 3, 7, 6), (25, 4, 5, 6, 7),
              (26, 0, 1, 2, 3, 4, 5, 6, 7)])
TYPES[13] = ("prism18", 6, TYPES[18][2],
             [(15, 0, 1, 4, 3), (16, 0, 2, 5, 3), (17, 1, 2, 5, 4)])


def check_tables():
    """Every table entry is the midpoint / centre of its corners in Gmsh's
    reference element (getElementProperties)."""
    bad = []
    for t, (name, nc, edges, faces) in TYPES.items():
        p = gmsh.model.mesh.getElementProperties(t)
        ref = np.array(p[4]).reshape(-1, 3)
        if p[3] != nc + len(edges) + len(faces):
            bad.append("%s: %d nodes" % (name, p[3]))
        for entry in edges + faces:
            k, cs = entry[0], entry[1:]
            if not np.allclose(ref[k], ref[list(cs)].mean(axis=0)):
                bad.append("%s node %d" % (name, k))
    return bad


def load(path):
    """(tag -> xyz dict, {type: (elem tags, node tags (n, nv))}, the tags
    of nodes classified on entities of dimension < 3) of a file."""
    gmsh.clear()
    gmsh.open(path)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    coords = dict(zip(tags.tolist(), np.array(xyz).reshape(-1, 3)))
    elems = {}
    for t in gmsh.model.mesh.getElementTypes(3):
        et, nt = gmsh.model.mesh.getElementsByType(t)
        nv = gmsh.model.mesh.getElementProperties(t)[3]
        elems[t] = (et, np.array(nt).reshape(-1, nv))
    low = set()
    for d in (0, 1, 2):
        low.update(gmsh.model.mesh.getNodes(d, -1, includeBoundary=True)[0]
                   .tolist())
    return coords, elems, low


def min_node_jacobian(path):
    """Smallest det J over every node of every 3-D element, by Gmsh
    (gmsh.model.mesh.getJacobians at the reference nodes), and how many
    elements have one <= 0."""
    gmsh.clear()
    gmsh.open(path)
    worst, bad = np.inf, 0
    for t in gmsh.model.mesh.getElementTypes(3):
        p = gmsh.model.mesh.getElementProperties(t)
        _, dets, _ = gmsh.model.mesh.getJacobians(t, p[4])
        d = np.array(dets).reshape(-1, p[3])
        worst = min(worst, d.min())
        bad += int((d.min(axis=1) <= 0).sum())
    return worst, bad


def midpoint_errors(coords, elems, nodes=None):
    """Largest distance, relative to the edge length, of a mid-edge node
    from its edge's midpoint (only nodes in `nodes` if given), and of a
    face/body node from its corners' mean."""
    worst = 0.0
    for t, (_, conn) in elems.items():
        _, _, edges, faces = TYPES[t]
        for entry in edges + faces:
            k, cs = entry[0], list(entry[1:])
            for row in conn:
                if nodes is not None and row[k] not in nodes:
                    continue
                c = np.array([coords[row[i]] for i in cs])
                h = np.linalg.norm(c[0] - c[1])
                worst = max(worst, np.linalg.norm(coords[row[k]] - c.mean(0)) / h)
    return worst


def min_node_jacobian_arrays(xyz, gtype, conn):
    """min_node_jacobian() of nodes xyz (n x 3) and elements conn (0-based,
    Gmsh order) of Gmsh type gtype, through a discrete Gmsh model."""
    gmsh.clear()
    gmsh.model.add("jac")
    gmsh.model.addDiscreteEntity(3, 1)
    n = len(xyz)
    gmsh.model.mesh.addNodes(3, 1, list(range(1, n + 1)),
                             np.asarray(xyz, dtype=float).ravel().tolist())
    gmsh.model.mesh.addElementsByType(1, gtype, [],
                                      (np.asarray(conn) + 1).ravel().tolist())
    p = gmsh.model.mesh.getElementProperties(gtype)
    _, dets, _ = gmsh.model.mesh.getJacobians(gtype, p[4])
    d = np.array(dets).reshape(-1, p[3])
    return d.min(), int((d.min(axis=1) <= 0).sum())
