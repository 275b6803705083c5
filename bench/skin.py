"""Skin, region interfaces and free nodes of a mesh, in numpy.

A node is fixed when it lies on the mesh skin (a face -- an edge in 2-D --
with one incident element), on a face between elements of different regions
(docs/design.md §5), or is used by no element.  Every other node is free;
q*_min is the minimum quality over elements with at least one free node.
Computed here from connectivity alone so that outputs of other tools, whose
files carry no classification we trust, are judged the same way.
"""

import numpy as np

# Faces per element type as local node indices (orientation is irrelevant:
# faces are matched by their sorted node sets).
FACES = {
    "tet": [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)],
    "hex": [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5),
            (2, 3, 7, 6), (3, 0, 4, 7)],
    "prism": [(0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)],
    "pyramid": [(0, 1, 2, 3), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)],
    "tri": [(0, 1), (1, 2), (2, 0)],
    "quad": [(0, 1), (1, 2), (2, 3), (3, 0)],
}


def _face_keys(blocks, regions):
    """All element faces as rows of 4 sorted node ids (-1 padded), with the
    region of the element each comes from."""
    keys, owner_region = [], []
    for (etype, conn), reg in zip(blocks, regions):
        conn = np.asarray(conn, dtype=np.int64)
        for face in FACES[etype]:
            k = np.full((len(conn), 4), -1, dtype=np.int64)
            k[:, :len(face)] = conn[:, face]
            keys.append(k)
            owner_region.append(np.asarray(reg, dtype=np.int64))
    if not keys:
        return np.zeros((0, 4), np.int64), np.zeros(0, np.int64)
    keys = np.sort(np.concatenate(keys), axis=1)
    return keys, np.concatenate(owner_region)


def boundary_faces(blocks, regions):
    """Rows of node ids (-1 padded) of skin faces and interface faces."""
    keys, reg = _face_keys(blocks, regions)
    if len(keys) == 0:
        return keys
    order = np.lexsort(keys.T[::-1])
    keys, reg = keys[order], reg[order]
    same_as_next = np.all(keys[1:] == keys[:-1], axis=1)
    # start of each run of identical faces and its length
    starts = np.flatnonzero(np.concatenate(([True], ~same_as_next)))
    counts = np.diff(np.append(starts, len(keys)))
    skin = starts[counts == 1]
    pairs = starts[counts == 2]
    interface = pairs[reg[pairs] != reg[pairs + 1]]
    return keys[np.concatenate((skin, interface))]


def fixed_mask(num_nodes, blocks, regions):
    """Boolean mask of fixed nodes (skin, interfaces, unused)."""
    fixed = np.ones(num_nodes, dtype=bool)
    for _, conn in blocks:
        fixed[np.asarray(conn).ravel()] = False  # used nodes start free
    faces = boundary_faces(blocks, regions)
    ids = faces.ravel()
    fixed[ids[ids >= 0]] = True
    return fixed


def free_elements(conn, fixed):
    """Elements with at least one free node."""
    return np.any(~fixed[np.asarray(conn)], axis=1)
