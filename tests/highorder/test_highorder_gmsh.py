#!/usr/bin/python3
"""
test_highorder_gmsh.py GETME WORKDIR -- second-order elements through Gmsh
itself (docs/highorder.md): the Python API on a live model after
gmsh.model.mesh.setOrder(2), and the CLI's Gmsh reading path.

1. For tet10, hex20, hex27, prism15, prism18: Gmsh meshes a cube (a tet
   cylinder for tet10: curved skin), raises the order, getme.gmsh.distort()
   and getme.gmsh.optimize() work on the live model.  Gmsh's Jacobians
   are positive at every node, interior mid-nodes sit at the midpoint of
   their corners, nodes on surfaces, curves and points keep their
   coordinates bit for bit (curved skin mid-nodes included), q_mean rises.
2. GETME_MSH_READER=gmsh (the model builder) and the native reader give
   the same coordinates (to 1e-12) from `getme smooth` on a tet10 file.
"""
import os
import subprocess
import sys

import gmsh
import numpy as np

import ho_check
import getme  # PYTHONPATH: the build's python directory
from checks import WorkChecks

GETME, WORK = sys.argv[1], sys.argv[2]
W = WorkChecks(GETME, WORK)
FAILED = W.failed
check = W.check


def model(kind):
    gmsh.clear()
    gmsh.model.add(kind)
    if kind == "tet10":
        gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, 1, 0.5)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15)
    elif kind.startswith("pyr"):
        # hex block and tet block sharing a quad face: pyramids on it
        geo = gmsh.model.geo
        p = geo.addPoint(0, 0, 0)
        ln = geo.extrude([(0, p)], 1, 0, 0, [4], recombine=True)
        s = geo.extrude([ln[1]], 0, 1, 0, [4], recombine=True)
        v = geo.extrude([s[1]], 0, 0, 1, [4], recombine=True)
        geo.extrude([[e for e in v if e[0] == 2][2]], 1, 0, 0)
        geo.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
    else:
        geo = gmsh.model.geo
        p = geo.addPoint(0, 0, 0)
        ln = geo.extrude([(0, p)], 1, 0, 0, [4], recombine=True)
        s = geo.extrude([ln[1]], 0, 1, 0, [4],
                        recombine=not kind.startswith("prism"))
        geo.extrude([s[1]], 0, 0, 1, [4], recombine=True)
        geo.synchronize()
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete",
                          1 if kind in ("hex20", "prism15", "pyr13") else 0)
    gmsh.model.mesh.setOrder(2)


def state():
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    coords = dict(zip(tags.tolist(), np.array(xyz).reshape(-1, 3)))
    low = set()
    for d in (0, 1, 2):
        low.update(gmsh.model.mesh.getNodes(d, -1, includeBoundary=True)[0]
                   .tolist())
    elems = {}
    for t in gmsh.model.mesh.getElementTypes(3):
        _, nt = gmsh.model.mesh.getElementsByType(t)
        nv = gmsh.model.mesh.getElementProperties(t)[3]
        elems[t] = (None, np.array(nt).reshape(-1, nv))
    worst = np.inf
    for t in elems:
        p = gmsh.model.mesh.getElementProperties(t)
        _, dets, _ = gmsh.model.mesh.getJacobians(t, p[4])
        worst = min(worst, np.min(dets))
    return coords, low, elems, worst


def live(kind):
    model(kind)
    c0, low, e0, w0 = state()
    moved = getme.gmsh.distort(seed=4, amount=0.4, rounds=3)
    c1, _, e1, w1 = state()
    check(moved > 0 and w1 > 0, "%s: distort moved %d nodes, min det J %g" %
          (kind, moved, w1))
    interior = set(c0) - low
    check(ho_check.midpoint_errors(c1, e1, interior) < 1e-12,
          "%s: distorted interior mid-nodes at midpoints" % kind)
    res = getme.gmsh.optimize(log=0)
    c2, low2, e2, w2 = state()
    check(low2 == low, "%s: classification unchanged" % kind)
    check(w2 > 0, "%s: min node det J after optimize %g" % (kind, w2))
    check(all(np.array_equal(c0[t], c2[t]) for t in low),
          "%s: skin nodes (curved mid-nodes included) bit-identical" % kind)
    check(ho_check.midpoint_errors(c2, e2, interior) < 1e-12,
          "%s: interior mid-nodes at midpoints" % kind)
    so = res.get("second_order")
    gr, gtag = ho_check.worst_jacobian_ratio()
    check(so is not None and
          so["elements"] == sum(len(e2[t][1]) for t in e2) and
          abs(so["jacobian_ratio_after"] - gr) < 1e-9 and
          so["element_after"] == gtag and
          so["jacobian_ratio_before"] <= so["jacobian_ratio_after"] + 1 and
          so["element_before"] > 0,
          "%s: result's second_order = Gmsh's worst ratio %.12g (element %d):"
          " %s" % (kind, gr, gtag, so))
    q0, q1 = res["q_mean_before"], res["q_mean_after"]
    check(q1 > q0, "%s: q_mean %.4f -> %.4f" % (kind, q0, q1))
    print("%-8s live model: q_mean %.4f -> %.4f, min node det J %.4g" %
          (kind, q0, q1, w2), flush=True)


def reader_paths():
    model("tet10")
    getme.gmsh.distort(seed=2, amount=0.4, rounds=3)
    src = os.path.join(WORK, "cyl.msh")
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.write(src)
    outs = []
    for reader in ("native", "gmsh"):
        out = os.path.join(WORK, "cyl-%s.msh" % reader)
        env = dict(os.environ, GETME_MSH_READER=reader, OMP_NUM_THREADS="2",
                   OMP_WAIT_POLICY="passive")
        r = subprocess.run([GETME, "smooth", src, "-o", out], env=env,
                           capture_output=True, text=True)
        check(r.returncode == 0, "%s reader: %s" % (reader, r.stderr))
        outs.append(out)
    # the Gmsh path writes the file with Gmsh (entity bounding boxes
    # differ in the last digits), so compare the nodes tag by tag.  The two
    # paths number this file's nodes differently, which changes the last
    # bits of the result (so does the linear mesh of the same file: 77
    # nodes differ by an ulp), hence a tolerance, not bit equality.
    a, _, _ = ho_check.load(outs[0])
    b, _, _ = ho_check.load(outs[1])
    c, _, _ = ho_check.load(src)
    check(a.keys() == b.keys() and
          max(np.abs(a[t] - b[t]).max() for t in a) < 1e-12 and
          any(not np.array_equal(a[t], c[t]) for t in a),
          "native and Gmsh readers: the same coordinates (1e-12)")


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
for kind in ("tet10", "hex20", "hex27", "prism15", "prism18", "pyr13",
             "pyr14"):
    live(kind)
reader_paths()
gmsh.finalize()
print("%d failure(s)" % len(FAILED))
sys.exit(1 if FAILED else 0)
