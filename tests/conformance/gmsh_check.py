"""The conformance sweep's checks of one smoothed MSH / INP file against its
input, independent of getme's own reader: Gmsh's and meshio's readers, and
the file's bytes. compare() returns '' or the first difference found."""
import os

import gmsh
import meshio
import numpy as np

import inp_check


def node_section(data, binary):
    """(start, end) byte offsets of the $Nodes section's body."""
    a = data.index(b"$Nodes\n") + len(b"$Nodes\n")
    b = data.index(b"$EndNodes", a)
    return a, b


def bytes_outside_nodes(a, b):
    """'' when the two MSH files agree outside their node coordinates."""
    da, db = open(a, "rb").read(), open(b, "rb").read()
    binary = b"\n4.1 1 8\n" in da[:40] or b"\n2.2 1 8\n" in da[:40]
    sa, sb = node_section(da, binary), node_section(db, binary)
    if da[:sa[0]] != db[:sb[0]]:
        return "bytes before $Nodes differ"
    if da[sa[1]:] != db[sb[1]:]:
        return "bytes after $EndNodes differ"
    na, nb = da[sa[0]:sa[1]], db[sb[0]:sb[1]]
    if binary:
        # same layout, same length: only 8-byte coordinates may differ
        return "" if len(na) == len(nb) else "binary $Nodes length differs"
    la, lb = na.split(b"\n"), nb.split(b"\n")
    if len(la) != len(lb):
        return "$Nodes line count differs"
    for x, y in zip(la, lb):
        if x != y and (len(x.split()) != 3 or len(y.split()) != 3):
            # 4.1: only coordinate lines (3 fields); 2.2: 'tag x y z' lines
            if len(x.split()) == 4 and x.split()[0] == y.split()[0]:
                continue
            return "$Nodes line %r -> %r" % (x[:60], y[:60])
    return ""


def gmsh_model(path):
    """{(dim, tag): (types, element tags, node tags)}, {node tag: xyz},
    fixed node tags (classified on, or of elements of, entities of lower
    dimension than the mesh, partition cuts excepted), the mesh's dimension."""
    gmsh.initialize(["check"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(path)
        ents = gmsh.model.getEntities()
        els = {}
        top = 0
        for d, t in ents:
            ty, et, nt = gmsh.model.mesh.getElements(d, t)
            els[(d, t)] = (list(ty), [list(x) for x in et], [list(x) for x in nt])
            if len(ty):
                top = max(top, d)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        nodes = dict(zip(tags.tolist(), xyz.reshape(-1, 3).tolist()))
        fixed = set()
        for d, t in ents:
            # a partition boundary inside a top-dimensional entity is free
            # (getme fixes the mesh's own entities, not partition cuts)
            if len(gmsh.model.getPartitions(d, t)) and \
                    gmsh.model.getParent(d, t)[0] in (top, -1):
                continue
            if d < top:
                fixed.update(gmsh.model.mesh.getNodes(d, t)[0].tolist())
                for nt in els[(d, t)][2]:
                    fixed.update(nt)
        return els, nodes, fixed, top
    finally:
        gmsh.finalize()


def invalid_in_gmsh(path):
    """Elements of the file's highest dimension with a Jacobian determinant
    <= 0 at one of their nodes or their centre, as Gmsh computes it (its
    own validity, independent of getme's).  Gmsh's volume elements are
    positively oriented; a surface element's area vectors (Gmsh's
    Jacobians) are compared with its surface's normal, the sum of its
    elements' straight-corner normals: an element turned against the
    others of its surface is folded over them."""
    if not path.endswith(".msh"):
        return 0
    gmsh.initialize(["check"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(path)
        bad = 0
        dim = 3 if len(gmsh.model.mesh.getElements(3)[0]) else 2
        tags_all, xyz, _ = gmsh.model.mesh.getNodes()
        where = {int(t): i for i, t in enumerate(tags_all)}
        xyz = xyz.reshape(-1, 3)
        for _, ent in gmsh.model.getEntities(dim):
            types, tags, nodes = gmsh.model.mesh.getElements(dim, ent)
            areas, normals = [], []
            for t, tg, nt in zip(types, tags, nodes):
                props = gmsh.model.mesh.getElementProperties(t)
                local = np.asarray(props[4]).reshape(-1, dim)
                pts = np.vstack([local.mean(axis=0), local])
                pts = np.hstack([pts, np.zeros((len(pts), 3 - dim))]).ravel()
                jac, det, _ = gmsh.model.mesh.getJacobians(t, pts, tag=ent)
                k = len(pts) // 3
                if dim == 3:
                    bad += int((det.reshape(len(tg), k).min(axis=1) <= 0).sum())
                    continue
                j = jac.reshape(len(tg), k, 3, 3)   # rows: d/du, d/dv, normal
                areas.append(np.cross(j[:, :, 0, :], j[:, :, 1, :]))
                c = xyz[[where[int(n)] for n in nt]].reshape(len(tg), props[3], 3)
                normals.append(np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
                               if props[5] == 3 else
                               np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 1]))
            if areas:
                normal = sum(n.sum(axis=0) for n in normals)
                for a in areas:
                    bad += int((np.einsum("ekc,c->ek", a, normal).min(axis=1) <= 0).sum())
        return bad
    finally:
        gmsh.finalize()


def meshio_cells(path):
    m = meshio.read(path)
    return sorted((c.type, len(c.data)) for c in m.cells), len(m.points)


def compare(src, out, report):
    ext = os.path.splitext(src)[1]
    if ext == ".inp":
        cause, _ = inp_check.compare(src, out, report)
        return cause or inp_check.meshio_same(src, out)
    if ext != ".msh":
        return ""
    cause = bytes_outside_nodes(src, out)
    if cause:
        return cause
    ea, na, fixed, top = gmsh_model(src)
    eb, nb, _, _ = gmsh_model(out)
    if ea != eb:
        return "Gmsh reads other entities or elements"
    if na.keys() != nb.keys():
        return "Gmsh reads other node tags"
    moved = [t for t in fixed if na[t] != nb[t]]
    if moved:
        return "%d fixed nodes moved (lower-dimensional entities), e.g. %d" % (len(moved), moved[0])
    # every node that moved is a node of a top-dimension element
    if not any(na[t] != nb[t] for t in na) and report["after"]["q_mean"] != report["before"]["q_mean"]:
        return "report says q_mean changed but no node moved"
    try:
        if meshio_cells(src) != meshio_cells(out):
            return "meshio reads other cells"
    except Exception as e:                      # meshio cannot read the input
        try:
            meshio_cells(out)
        except Exception as e2:
            if type(e2) is not type(e):
                return "meshio reads the input but not the output: %s" % e2
    return ""
