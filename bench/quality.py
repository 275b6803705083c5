"""Mean ratio quality of mesh elements, vectorised in numpy.

An independent implementation of the definitions in docs/design.md §1 (the
same ones libgetme uses), so that the benchmark judges every method's output
-- ours, Gmsh's, Netgen's -- with one yardstick that shares no code with the
core.  Node order is Gmsh's for every type.

Volume types: for each node simplex k (four node indices a, b, c, d) the
matrix D_k = (p_b - p_a, p_c - p_a, p_d - p_a), S_k = D_k W^-1 and
q_k = 3 det(S_k)^(2/3) / tr(S_k^T S_k); q = mean over k; any det <= 0 makes
the element invalid (q = 0).  Planar types use x and y only.
"""

import numpy as np

# Node simplices: (corner, edge end 1, edge end 2, edge end 3), ordered so that
# det > 0 on the regular element (the paper's N^hex, 0-based).
SIMPLICES = {
    "tet": [(0, 1, 2, 3)],
    "hex": [(0, 3, 4, 1), (1, 0, 5, 2), (2, 1, 6, 3), (3, 2, 7, 0),
            (4, 7, 5, 0), (5, 4, 6, 1), (6, 5, 7, 2), (7, 6, 4, 3)],
    "prism": [(0, 1, 2, 3), (1, 2, 0, 4), (2, 0, 1, 5),
              (3, 5, 4, 0), (4, 3, 5, 1), (5, 4, 3, 2)],
    "pyramid": [(0, 1, 3, 4), (1, 2, 0, 4), (2, 3, 1, 4), (3, 0, 2, 4)],
}

# Target matrices: columns are the spanning edge vectors of a node simplex of
# the regular element (unit edge length).
_S3 = np.sqrt(3.0)
TARGET = {
    "tet": np.array([[1.0, 0.5, 0.5],
                     [0.0, _S3 / 2, _S3 / 6],
                     [0.0, 0.0, np.sqrt(2.0 / 3.0)]]),
    "hex": np.eye(3),
    "prism": np.array([[1.0, 0.5, 0.0],
                       [0.0, _S3 / 2, 0.0],
                       [0.0, 0.0, 1.0]]),
    "pyramid": np.array([[1.0, 0.0, 0.5],
                         [0.0, 1.0, 0.5],
                         [0.0, 0.0, 1.0 / np.sqrt(2.0)]]),
}

NUM_NODES = {"tet": 4, "hex": 8, "prism": 6, "pyramid": 5, "tri": 3, "quad": 4}
DIM = {"tet": 3, "hex": 3, "prism": 3, "pyramid": 3, "tri": 2, "quad": 2}

# Elements per vectorised chunk: bounds the temporaries (a few hundred MiB
# for hexes) on multi-million element meshes.
CHUNK = 1 << 18


def _simplex_quality(points, conn, simplex, winv):
    """q_k of one node simplex for every element; 0 where det <= 0."""
    a, b, c, d = (points[conn[:, i]] for i in simplex)
    dmat = np.stack([b - a, c - a, d - a], axis=2)  # columns are the edges
    smat = dmat @ winv
    with np.errstate(invalid="ignore"):  # non-finite input: judged invalid below
        det = np.linalg.det(smat)
    frob = np.einsum("nij,nij->n", smat, smat)
    q = np.zeros(len(conn))
    ok = (det > 0.0) & (frob > 0.0)
    q[ok] = 3.0 * np.cbrt(det[ok]) ** 2 / frob[ok]
    return q, ok


def _volume_quality(points, conn, etype):
    simplices = SIMPLICES[etype]
    winv = np.linalg.inv(TARGET[etype])
    total = np.zeros(len(conn))
    valid = np.ones(len(conn), dtype=bool)
    for simplex in simplices:
        q, ok = _simplex_quality(points, conn, simplex, winv)
        total += q
        valid &= ok
    return np.where(valid, total / len(simplices), 0.0)


def _cross2(u, v):
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def _tri_quality(xy, conn, orient):
    """q = 4 sqrt(3) A / sum |e|^2 with A the signed area."""
    p0, p1, p2 = xy[conn[:, 0]], xy[conn[:, 1]], xy[conn[:, 2]]
    area = 0.5 * orient * _cross2(p1 - p0, p2 - p0)
    edges = (np.sum((p1 - p0) ** 2, axis=1) + np.sum((p2 - p1) ** 2, axis=1)
             + np.sum((p0 - p2) ** 2, axis=1))
    q = np.zeros(len(conn))
    ok = (area > 0.0) & (edges > 0.0)
    q[ok] = 4.0 * _S3 * area[ok] / edges[ok]
    return q


def _quad_quality(xy, conn, orient):
    """Mean of the 4 corner values 2 det(D) / tr(D^T D), W = I."""
    total = np.zeros(len(conn))
    valid = np.ones(len(conn), dtype=bool)
    for k in range(4):
        pk = xy[conn[:, k]]
        e1 = xy[conn[:, (k + 1) % 4]] - pk
        e2 = xy[conn[:, (k + 3) % 4]] - pk
        det = orient * _cross2(e1, e2)
        frob = np.sum(e1 * e1, axis=1) + np.sum(e2 * e2, axis=1)
        ok = (det > 0.0) & (frob > 0.0)
        total += np.where(ok, 2.0 * det / np.where(ok, frob, 1.0), 0.0)
        valid &= ok
    return np.where(valid, total / 4.0, 0.0)


def planar_orientation(points, blocks):
    """+1 if the planar elements run counter-clockwise in the xy plane, -1 if
    all run clockwise (a mirrored mesh, accepted like libgetme does)."""
    signed = 0.0
    for etype, conn in blocks:
        if DIM[etype] == 2 and len(conn):
            p0, p1, p2 = (points[conn[:, i], :2] for i in range(3))
            area = _cross2(p1 - p0, p2 - p0)
            if np.all(area < 0.0):
                signed -= 1.0
            else:
                signed += 1.0
    return -1.0 if signed < 0.0 else 1.0


def element_quality(points, conn, etype, orient=1.0):
    """Mean ratio of every element of one type (array of len(conn))."""
    points = np.asarray(points, dtype=np.float64)
    conn = np.asarray(conn, dtype=np.int64)
    out = np.empty(len(conn))
    for start in range(0, len(conn), CHUNK):
        part = conn[start:start + CHUNK]
        if etype == "tri":
            q = _tri_quality(points[:, :2], part, orient)
        elif etype == "quad":
            q = _quad_quality(points[:, :2], part, orient)
        else:
            q = _volume_quality(points, part, etype)
        out[start:start + len(part)] = q
    return out
