#!/usr/bin/python3
"""
test_highorder_planar.py GETME [CGNS_HO_WRITE] WORKDIR -- planar second-order meshes
(tri6, quad8, quad9: Gmsh types 9, 16, 10) in MSH files written by Gmsh
(issue #12 part 2, docs/highorder.md).

The unit square is two surfaces: the left one counter-clockwise, the
right one clockwise (its curve loop reversed), so the reader must flip
the right surface's elements, corners and mid-edge nodes together
(formats/model/planar.c).  A wrong mid-node permutation makes a flipped
element's mid-nodes belong to the wrong edges: they would then be moved to
the wrong midpoints (or the element refused).  Checked: the input really
has clockwise elements; distort and smooth exit 0, 1 = 2 threads byte for
byte; the file is written back in its original node order (connectivity
unchanged); skin nodes bit-identical; every interior mid-edge node at its
edge's midpoint and the quad9 centre at its corners' mean (1e-12 of the
edge); det J has one sign at every node of each element (Gmsh's
getJacobians); q_mean rises.  Then the same mesh, every element made
clockwise, as an Abaqus deck (CPS6, CPS8R, M3D9) and as CGNS (TRI_6,
QUAD_8, QUAD_9 in a cell-dimension-2 base, written by libcgns).
"""
import os
import re
import subprocess
import sys

import gmsh
import numpy as np
from checks import WorkChecks

GETME, WORK = sys.argv[1], sys.argv[-1]
WRITER = sys.argv[2] if len(sys.argv) > 3 else None  # cgns_ho_write
W = WorkChecks(GETME, WORK)
FAILED = W.failed
check, run = W.check, W.run
DETS = {}

# Gmsh type -> (corners, mid-edge / centre nodes as (node, corners...))
TYPES = {
    9: (3, [(3, 0, 1), (4, 1, 2), (5, 2, 0)]),
    16: (4, [(4, 0, 1), (5, 1, 2), (6, 2, 3), (7, 3, 0)]),
}
TYPES[10] = (4, TYPES[16][1] + [(8, 0, 1, 2, 3)])


def generate(kind, n=6):
    gmsh.clear()
    gmsh.model.add(kind)
    geo = gmsh.model.geo
    pts = [geo.addPoint(x, y, 0) for x, y in
           ((0, 0), (.5, 0), (1, 0), (1, 1), (.5, 1), (0, 1))]
    ln = [geo.addLine(pts[i], pts[(i + 1) % 6]) for i in range(6)]
    mid = geo.addLine(pts[1], pts[4])
    left = geo.addCurveLoop([ln[0], mid, ln[4], ln[5]])
    right = geo.addCurveLoop([-ln[3], -ln[2], -ln[1], mid])  # clockwise
    geo.addPlaneSurface([left])
    geo.addPlaneSurface([right])
    geo.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0 / n)
    if kind != "tri6":
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.model.mesh.generate(2)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete",
                          1 if kind == "quad8" else 0)
    gmsh.model.mesh.setOrder(2)
    gmsh.option.setNumber("Mesh.RecombineAll", 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    name = os.path.join(WORK, kind + ".msh")
    gmsh.write(name)
    return name


def load(path):
    gmsh.clear()
    gmsh.open(path)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    coords = dict(zip(tags.tolist(), np.array(xyz).reshape(-1, 3)))
    elems = {}
    for t in gmsh.model.mesh.getElementTypes(2):
        _, nt = gmsh.model.mesh.getElementsByType(t)
        nv = gmsh.model.mesh.getElementProperties(t)[3]
        elems[t] = np.array(nt).reshape(-1, nv)
    low = set()
    for d in (0, 1):
        low.update(gmsh.model.mesh.getNodes(d, -1, includeBoundary=True)[0]
                   .tolist())
    signs = []
    for t in elems:
        p = gmsh.model.mesh.getElementProperties(t)
        ref = np.zeros((p[3], 3))
        ref[:, :2] = np.array(p[4]).reshape(-1, 2)
        # Gmsh's 2-D det is unsigned: take the signed xy minor of its
        # Jacobian matrices (columns d/du, d/dv)
        jac, _, _ = gmsh.model.mesh.getJacobians(t, ref.ravel().tolist())
        j = np.array(jac).reshape(-1, p[3], 3, 3)
        d = j[..., 0, 0] * j[..., 1, 1] - j[..., 0, 1] * j[..., 1, 0]
        DETS[t] = d
        signs.append((np.sign(d).min(1) * np.sign(d).max(1)).min())
    return coords, elems, low, min(signs)


def signed_area(coords, row, nc):
    p = np.array([coords[row[i]] for i in range(nc)])
    return 0.5 * sum(p[i, 0] * p[(i + 1) % nc, 1] - p[(i + 1) % nc, 0] *
                     p[i, 1] for i in range(nc))


def midpoint_error(coords, elems, interior):
    worst = 0.0
    for t, conn in elems.items():
        nc, mids = TYPES[t]
        for row in conn:
            for k, *cs in mids:
                if row[k] not in interior:
                    continue
                c = np.array([coords[row[i]] for i in cs])
                h = np.linalg.norm(c[0] - c[1])
                worst = max(worst, np.linalg.norm(coords[row[k]] - c.mean(0))
                            / h)
    return worst


def case(kind):
    src = generate(kind)
    c0, e0, low, s0 = load(src)
    gtype = {"tri6": 9, "quad8": 16, "quad9": 10}[kind]
    check(list(e0) == [gtype], "%s: Gmsh wrote type %d only (%s)" %
          (kind, gtype, list(e0)))
    areas = [signed_area(c0, r, TYPES[gtype][0]) for r in e0[gtype]]
    check(min(areas) < 0 < max(areas),
          "%s: the input has clockwise and counter-clockwise elements" % kind)
    dis = src[:-4] + "-d.msh"
    o1, o2 = src[:-4] + "-s1.msh", src[:-4] + "-s2.msh"
    r = run("distort", src, "-o", dis, "--seed", "3", "--target-qmean", "0.55")
    check(r.returncode == 0, "%s: distort exit %d %s" % (kind, r.returncode,
                                                        r.stderr[-300:]))
    c1, e1, _, s1 = load(dis)
    interior = set(c1) - low
    check(midpoint_error(c1, e1, interior) < 1e-12,
          "%s: distorted interior mid-nodes at midpoints" % kind)
    check(s1 > 0, "%s: distorted: det J of one sign per element" % kind)
    r1 = run("smooth", dis, "-o", o1, "-v", threads=1)
    r2 = run("smooth", dis, "-o", o2, "-v", threads=2)
    check(r1.returncode == 0 and r2.returncode == 0,
          "%s: smooth exit %d/%d %s" % (kind, r1.returncode, r2.returncode,
                                        r1.stderr[-300:]))
    check(open(o1, "rb").read() == open(o2, "rb").read(),
          "%s: 1 and 2 threads byte-identical" % kind)
    q = [float(v) for v in re.findall(r"qmean ([0-9.]+)", r1.stdout + r1.stderr)]
    check(len(q) >= 2 and q[-1] > q[0] + 0.05, "%s: q_mean rises %s" % (kind, q))
    c2, e2, low2, s2 = load(o1)
    check(low2 == low, "%s: classification unchanged" % kind)
    check(all(np.array_equal(e1[t], e2[t]) for t in e1),
          "%s: written back in the original node order" % kind)
    check(all(np.array_equal(c1[t], c2[t]) for t in low),
          "%s: skin nodes bit-identical" % kind)
    moved = sum(1 for t in interior if not np.array_equal(c1[t], c2[t]))
    check(moved > len(interior) // 2, "%s: smoothing moved %d of %d interior "
          "nodes" % (kind, moved, len(interior)))
    err = midpoint_error(c2, e2, interior)
    check(err < 1e-12, "%s: smoothed interior mid-nodes at midpoints (%g)"
          % (kind, err))
    check(s2 > 0, "%s: smoothed: det J of one sign at every node" % kind)
    print("%-6s ok: q_mean %.4f -> %.4f, %d interior nodes moved" %
          (kind, q[0], q[-1], moved), flush=True)


def read_inp_nodes(path):
    xyz, on = {}, False
    for line in open(path):
        if line.startswith("*"):
            on = line.upper().startswith("*NODE")
            continue
        if on and line.strip():
            f = line.split(",")
            xyz[int(f[0])] = np.array([float(v) for v in f[1:4]])
    return xyz


def flip(row, nc):
    """Reverse an element: corners 0, nc-1, ..., 1 and the mid-edge nodes
    in reverse (the centre stays): an independent statement of the rule
    in planar.c."""
    row = list(row)
    mids = row[nc:2 * nc]
    return [row[0]] + row[1:nc][::-1] + mids[::-1] + row[2 * nc:]


def cgns_case(kind, c0, low, rows):
    import h5py
    gtype, sids = {"tri6": (9, "TRI_6"), "quad8": (16, "QUAD_8"),
                   "quad9": (10, "QUAD_9")}[kind]
    tags = sorted(c0)
    index = {t: i + 1 for i, t in enumerate(tags)}
    txt = os.path.join(WORK, kind + "-cgns.txt")
    with open(txt, "w") as f:
        f.write("%d\n" % len(tags))
        for t in tags:
            f.write("%r %r %r\n" % tuple(c0[t]))
        f.write("%s %d %d\n" % (sids, len(rows), len(rows[0])))
        for r in rows:
            f.write(" ".join(str(index[v]) for v in r) + "\n")
    src = os.path.join(WORK, kind + ".cgns")
    r = subprocess.run([WRITER, txt, src, "2"], capture_output=True, text=True)
    check(r.returncode == 0, "%s CGNS: cgns_ho_write %s" % (kind, r.stderr))
    o1, o2 = src[:-5] + "-s1.cgns", src[:-5] + "-s2.cgns"
    r1 = run("smooth", src, "-o", o1, threads=1)
    r2 = run("smooth", src, "-o", o2, threads=2)
    check(r1.returncode == 0 and r2.returncode == 0,
          "%s CGNS: smooth exit %d/%d %s" % (kind, r1.returncode,
                                             r2.returncode, r1.stderr[-300:]))

    def coords(path):
        with h5py.File(path, "r") as h:
            g = h["Base"]["Zone"]["GridCoordinates"]
            x = np.stack([g["Coordinate" + a][" data"][()] for a in "XYZ"], 1)
        return {t: x[index[t] - 1] for t in tags}
    c2 = coords(o1)
    c3 = coords(o2)
    check(all(np.array_equal(c2[t], c3[t]) for t in tags),
          "%s CGNS: 1 = 2 threads" % kind)
    skin = {t for t, p in c0.items() if p[0] in (0, 1) or p[1] in (0, 1)}
    check(all(np.array_equal(c0[t], c2[t]) for t in skin),
          "%s CGNS: skin nodes bit-identical" % kind)
    inner = set(tags) - skin
    moved = sum(1 for t in inner if not np.array_equal(c0[t], c2[t]))
    check(moved > len(inner) // 2, "%s CGNS: moved %d of %d" %
          (kind, moved, len(inner)))
    err = midpoint_error(c2, {gtype: np.array(rows)}, inner)
    check(err < 1e-12, "%s CGNS: interior mid-nodes at midpoints (%g)" %
          (kind, err))
    nc = TYPES[gtype][0]
    check(all(signed_area(c2, r, nc) < 0 for r in rows),
          "%s CGNS: every element still clockwise (valid)" % kind)
    print("%-6s CGNS (%s, all clockwise) ok: %d interior nodes moved" %
          (kind, sids, moved), flush=True)


def inp_case(kind):
    """The same mesh as an Abaqus deck (CPS6, CPS8R, M3D9), every element
    clockwise: the core smooths it as its mirror image (getme.h)."""
    gtype, abq = {"tri6": (9, "CPS6"), "quad8": (16, "CPS8R"),
                  "quad9": (10, "M3D9")}[kind]
    c0, e0, low, _ = load(os.path.join(WORK, kind + "-d.msh"))
    nc = TYPES[gtype][0]
    rows = [r if signed_area(c0, r, nc) < 0 else flip(r, nc)
            for r in e0[gtype]]
    check(all(signed_area(c0, r, nc) < 0 for r in rows) and
          midpoint_error(c0, {gtype: np.array(rows)}, set(c0) - low) < 1e-12,
          "%s INP: flip() keeps the mid-nodes on their edges" % kind)
    src = os.path.join(WORK, kind + ".inp")
    with open(src, "w") as f:
        f.write("*NODE\n")
        for t in sorted(c0):
            f.write("%d, %r, %r, %r\n" % ((t,) + tuple(c0[t])))
        f.write("*ELEMENT, TYPE=%s, ELSET=ALL\n" % abq)
        for i, r in enumerate(rows):
            f.write("%d, %s\n" % (i + 1, ", ".join(str(v) for v in r)))
    o1, o2 = src[:-4] + "-s1.inp", src[:-4] + "-s2.inp"
    r1 = run("smooth", src, "-o", o1, "-v", threads=1)
    r2 = run("smooth", src, "-o", o2, "-v", threads=2)
    check(r1.returncode == 0 and r2.returncode == 0,
          "%s INP: smooth exit %d/%d %s" % (kind, r1.returncode, r2.returncode,
                                            r1.stderr[-300:]))
    check(open(o1, "rb").read() == open(o2, "rb").read(),
          "%s INP: 1 and 2 threads byte-identical" % kind)
    c2 = read_inp_nodes(o1)
    skin = {t for t, p in c0.items() if p[0] in (0, 1) or p[1] in (0, 1)}
    check(all(np.array_equal(c0[t], c2[t]) for t in skin),
          "%s INP: skin nodes bit-identical" % kind)
    inner = set(c0) - skin
    moved = sum(1 for t in inner if not np.array_equal(c0[t], c2[t]))
    check(moved > len(inner) // 2, "%s INP: moved %d of %d" %
          (kind, moved, len(inner)))
    err = midpoint_error(c2, {gtype: np.array(rows)}, inner)
    check(err < 1e-12, "%s INP: interior mid-nodes at midpoints (%g)" %
          (kind, err))
    check(all(signed_area(c2, r, nc) < 0 for r in rows),
          "%s INP: every element still clockwise (valid)" % kind)
    q = [float(v) for v in re.findall(r"qmean ([0-9.]+)", r1.stdout + r1.stderr)]
    check(len(q) >= 2 and q[-1] > q[0] + 0.05, "%s INP: q_mean rises %s" %
          (kind, q))
    if WRITER:
        cgns_case(kind, c0, low, rows)
    print("%-6s INP (%s, all clockwise) ok: q_mean %.4f -> %.4f" %
          (kind, abq, q[0], q[-1]),
          flush=True)


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
for kind in ("tri6", "quad8", "quad9"):
    case(kind)
    inp_case(kind)
gmsh.finalize()
print("%d failure(s)" % len(FAILED))
sys.exit(1 if FAILED else 0)
