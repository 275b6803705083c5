"""Quality statistics of one mesh and topology comparison of two meshes,
the numbers of the benchmark tables (all computed in numpy, never taken from
the tool that produced the mesh)."""

import numpy as np

from quality import element_quality, planar_orientation
from skin import fixed_mask, free_elements

HIST_EDGES = np.linspace(0.0, 1.0, 11)  # the ten 0.1 bins of libgetme's stats


def qualities(mesh):
    """Per-block quality arrays, in block order."""
    orient = planar_orientation(mesh.points, mesh.blocks) if mesh.dim == 2 else 1.0
    return [element_quality(mesh.points, conn, etype, orient)
            for etype, conn in mesh.blocks]


def mesh_stats(mesh):
    """Dict of the table values of one mesh (plus the quality histogram)."""
    fixed = fixed_mask(len(mesh.points), mesh.blocks, mesh.regions)
    per_block = qualities(mesh)
    q = np.concatenate(per_block) if per_block else np.zeros(0)
    free = np.concatenate([free_elements(conn, fixed) for _, conn in mesh.blocks])
    valid = q > 0.0
    hist, _ = np.histogram(q[valid], bins=HIST_EDGES)
    counts, worst = {}, {}
    for (etype, conn), qb in zip(mesh.blocks, per_block):
        counts[etype] = counts.get(etype, 0) + len(conn)
        fb = free_elements(conn, fixed)
        if fb.any():  # q*_min per type: which element type limits the mesh
            worst[etype] = min(worst.get(etype, 1.0), float(qb[fb].min()))
    return {
        "nodes": int(len(mesh.points)),
        "elements": int(len(q)),
        "types": counts,
        "q_min_star_by_type": worst,
        "free_nodes": int(np.count_nonzero(~fixed)),
        "free_elements": int(np.count_nonzero(free)),
        "q_min": float(q.min()) if len(q) else 1.0,
        "q_min_star": float(q[free].min()) if free.any() else 1.0,
        "q_mean": float(q.mean()) if len(q) else 1.0,
        "n_le_04": int(np.count_nonzero(q <= 0.4)),
        "n_lt_01": int(np.count_nonzero(q < 0.1)),
        "invalid": int(np.count_nonzero(~valid)),
        "histogram": [int(h) for h in hist],
    }


def _canonical(conn):
    """Rows in lexicographic order: writers may group elements differently
    (Gmsh writes per entity), which is not a topology change."""
    conn = np.asarray(conn)
    return conn[np.lexsort(conn.T[::-1])]


def topology_change(ref, mesh):
    """'no' if mesh has ref's node count and the same elements (same node
    lists, in any element order), else a short description of the change."""
    if len(ref.points) == len(mesh.points) and len(ref.blocks) == len(mesh.blocks):
        same = all(t1 == t2 and c1.shape == c2.shape
                   and (np.array_equal(c1, c2)
                        or np.array_equal(_canonical(c1), _canonical(c2)))
                   for (t1, c1), (t2, c2) in zip(ref.blocks, mesh.blocks))
        if same:
            return "no"
    dn = len(mesh.points) - len(ref.points)
    de = mesh.num_elements - ref.num_elements
    if dn == 0 and de == 0:
        return "yes (reconnected)"
    return f"yes (nodes {dn:+d}, elements {de:+d})"


def boundary_kept(ref, mesh):
    """True if every fixed (skin/interface) node of mesh sits exactly where
    a fixed node of ref sits and their numbers agree: nothing on the
    boundary moved.  Compared by coordinates, so renumbering is harmless."""
    def fixed_points(m):
        mask = fixed_mask(len(m.points), m.blocks, m.regions)
        used = np.zeros(len(m.points), dtype=bool)
        for _, conn in m.blocks:
            used[np.asarray(conn).ravel()] = True
        pts = m.points[mask & used]
        return pts[np.lexsort(pts.T[::-1])]
    a, b = fixed_points(ref), fixed_points(mesh)
    return a.shape == b.shape and np.array_equal(a, b)
