#!/usr/bin/python3
"""
test_highorder_inp.py GETME WORKDIR -- second-order elements in Abaqus /
CalculiX decks (issue #12 part 2, docs/highorder.md).

1. Node order, proved on CalculiX's own decks (Debian's calculix-ccx-test):
   with Abaqus -> Gmsh order of inp_deck.ABAQUS_TO_GMSH (the table
   formats/inp_types.c uses), the mid-edge nodes of C3D10, C3D15, C3D20
   and C3D20R lie at their edge's midpoint (all but those on curved
   geometry), and without it (Gmsh's order assumed) they do not.
2. Decks written by Gmsh (C3D10) and by meshio (hex20, written as
   C3D20RH, renamed C3D20R here), turned into a cantilever problem by the
   test: distorted and smoothed by getme, then read back through meshio
   (round trip to MSH) for Gmsh's Jacobians at every node; interior
   mid-nodes at midpoints, skin nodes bit-identical (same text), output
   equal to the input outside *NODE data; then solved by CalculiX (ccx
   exit 0): the tip deflection of the smoothed deck agrees with the
   undistorted deck's within 1%.
"""
import glob
import os
import re
import shutil
import subprocess
import sys

import gmsh
import meshio
import numpy as np

import ho_check
import inp_deck
from checks import WorkChecks

GETME, WORK = sys.argv[1], sys.argv[2]
W = WorkChecks(GETME, WORK)
FAILED = W.failed
check, path, run = W.check, W.path, W.run
CCX_TESTS = "/usr/share/doc/calculix-ccx-test/examples/test"


def midpoint_share(nodes, elems, perm, gtype):
    """(mid-edge nodes at their edge's midpoint, all mid-edge nodes) with
    node order perm (Gmsh's node k is perm[k])."""
    at, total = 0, 0
    for _, c in elems:
        g = [c[i] for i in perm]
        for k, a, b in ho_check.TYPES[gtype][2]:
            pa, pb = nodes[g[a]], nodes[g[b]]
            h = np.linalg.norm(pa - pb)
            at += np.linalg.norm(nodes[g[k]] - 0.5 * (pa + pb)) <= 1e-6 * h
            total += 1
    return at, total


def prove_on_calculix_decks():
    decks = sorted(glob.glob(os.path.join(CCX_TESTS, "*.inp")) +
                   glob.glob(os.path.join(CCX_TESTS, "*.inp.gz")))
    check(len(decks) > 100, "calculix-ccx-test decks found (%d)" % len(decks))
    share = {}
    for deck in decks:
        nodes, blocks = inp_deck.read(deck)
        for t, elems in blocks:
            nv = int("".join(ch for ch in t[3:] if ch.isdigit()))
            if nv not in inp_deck.ABAQUS_TO_GMSH or not elems:
                continue
            gtype, perm = inp_deck.ABAQUS_TO_GMSH[nv]
            s = share.setdefault(t, [0, 0, 0, 0, set()])
            a, n = midpoint_share(nodes, elems, perm, gtype)
            b, _ = midpoint_share(nodes, elems, list(range(nv)), gtype)
            s[0] += a
            s[1] += n
            s[2] += b
            s[4].add(os.path.basename(deck))
    for t in ("C3D10", "C3D15", "C3D20", "C3D20R"):
        a, n, b, _, files = share.get(t, [0, 1, 0, 0, set()])
        print("%-7s %3d decks: %6d of %6d mid-edge nodes at their midpoint "
              "with the table (%.3f), %.3f in Gmsh's order" %
              (t, len(files), a, n, a / n, b / n), flush=True)
        check(files and a / n > 0.8 and b / n < 0.7,
              "%s: table order proved on CalculiX's decks" % t)


def gen_decks():
    """A 4 x 1 x 1 beam: tet10 written by Gmsh (C3D10), hex20 written by
    meshio (C3D20RH -> C3D20R)."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    for kind in ("tet10", "hex20"):
        gmsh.clear()
        gmsh.model.add(kind)
        if kind == "tet10":
            gmsh.model.occ.addBox(0, 0, 0, 4, 1, 1)
            gmsh.model.occ.synchronize()
            gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
        else:
            geo = gmsh.model.geo
            p = geo.addPoint(0, 0, 0)
            ln = geo.extrude([(0, p)], 4, 0, 0, [12], recombine=True)
            s = geo.extrude([ln[1]], 0, 1, 0, [3], recombine=True)
            geo.extrude([s[1]], 0, 0, 1, [3], recombine=True)
            geo.synchronize()
        gmsh.model.addPhysicalGroup(3, [1])
        gmsh.model.mesh.generate(3)
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
        gmsh.model.mesh.setOrder(2)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 0)
        gmsh.write(path(kind + ".msh"))
        if kind == "tet10":
            gmsh.write(path("mesh-tet10.inp"))
    gmsh.finalize()
    m = meshio.read(path("hex20.msh"))
    m = meshio.Mesh(m.points, [c for c in m.cells if c.type == "hexahedron20"])
    meshio.write(path("mesh-hex20.inp"), m)
    text = open(path("mesh-hex20.inp")).read()
    check("TYPE=C3D20RH" in text, "meshio writes hex20 as C3D20RH")
    # meshio writes 21 numbers on a line; CalculiX reads at most 16: go on
    # on a continuation line (after a trailing comma), as Abaqus allows
    head, elems = text.replace("TYPE=C3D20RH", "TYPE=C3D20R, ELSET=EALL") \
        .split("TYPE=C3D20R, ELSET=EALL\n")
    # and its 22-character numbers are longer than CalculiX's fields (20):
    # the shortest text that gives the same double instead
    nodes, elems0 = head.split("*NODE\n")
    elems0 = elems0.split("\n")
    for i, line in enumerate(elems0):
        v = line.split(",")
        if len(v) == 4 and not line.startswith("*"):
            elems0[i] = "%s, %r, %r, %r" % (v[0], float(v[1]), float(v[2]),
                                          float(v[3]))
    head = nodes + "*NODE\n" + "\n".join(elems0)
    lines = []
    for line in elems.split("\n"):
        v = [x.strip() for x in line.split(",") if x.strip()]
        lines.append(", ".join(v[:16]) + ",\n" + ", ".join(v[16:])
                     if len(v) == 21 else line)
    open(path("mesh-hex20.inp"), "w").write(
        head + "TYPE=C3D20R, ELSET=EALL\n" + "\n".join(lines))
    text = open(path("mesh-tet10.inp")).read()
    check("type=C3D10" in text, "Gmsh writes C3D10")
    open(path("mesh-tet10.inp"), "w").write(
        text.replace("ELSET=Volume1", "ELSET=EALL"))


def add_problem(kind):
    """Cantilever: x = 0 clamped, unit total load -z on the x = 4 face."""
    src = path("mesh-%s.inp" % kind)
    nodes, _ = inp_deck.read(src)
    fixed = [n for n, x in nodes.items() if x[0] == 0.0]
    tip = [n for n, x in nodes.items() if x[0] == 4.0]

    def nset(name, ids):
        lines = ["*NSET, NSET=%s" % name]
        for i in range(0, len(ids), 8):
            lines.append(", ".join(str(v) for v in ids[i:i + 8]))
        return "\n".join(lines)
    deck = path("beam-%s.inp" % kind)
    with open(deck, "w") as f:
        f.write(open(src).read().rstrip("\n") + "\n")
        f.write(nset("FIXED", fixed) + "\n" + nset("TIP", tip) + "\n")
        f.write("*MATERIAL, NAME=STEEL\n*ELASTIC\n210000., 0.3\n"
                "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n"
                "*STEP\n*STATIC\n*BOUNDARY\nFIXED, 1, 3\n*CLOAD\n")
        for n in tip:
            f.write("%d, 3, %.17g\n" % (n, -1.0 / len(tip)))
        f.write("*NODE PRINT, NSET=TIP\nU\n*END STEP\n")
    return deck


def solve(deck):
    """ccx on deck: (exit code, mean z displacement of the tip nodes)."""
    job = deck[:-4]
    r = subprocess.run(["ccx", "-i", os.path.basename(job)], cwd=WORK,
                       capture_output=True, text=True,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    uz = []
    if os.path.exists(job + ".dat"):
        for line in open(job + ".dat"):
            v = line.split()
            if len(v) == 4 and re.match(r"^\d+$", v[0]):
                uz.append(float(v[3]))
    return r.returncode, (np.mean(uz) if uz else float("nan")), len(uz)


def node_lines(deck):
    """*NODE data lines by node id (the text as written)."""
    out, on = {}, False
    for line in open(deck):
        if line.startswith("*"):
            on = line.upper().replace(" ", "").startswith("*NODE") and \
                not line.upper().replace(" ", "").startswith("*NODEPRINT")
            continue
        if on and line.strip():
            out[int(line.split(",")[0])] = line
    return out


def ho_elements(deck, gtype, nv):
    """Elements of the deck in Gmsh's order, as ho_check expects."""
    nodes, blocks = inp_deck.read(deck)
    perm = inp_deck.ABAQUS_TO_GMSH[nv][1]
    rows = [[c[i] for i in perm] for t, el in blocks for _, c in el]
    return nodes, {gtype: (None, np.array(rows))}


def skin_nodes(nodes):
    return {n for n, x in nodes.items()
            if x[0] in (0.0, 4.0) or x[1] in (0.0, 1.0) or x[2] in (0.0, 1.0)}


def beam(kind):
    gtype, nv = (11, 10) if kind == "tet10" else (17, 20)
    deck = add_problem(kind)
    n0, e0 = ho_elements(deck, gtype, nv)
    check(ho_check.midpoint_errors(n0, e0) < 1e-9,
          "%s: the deck's mid-nodes at midpoints in the table's order" % kind)
    dis, out = path("beam-%s-d.inp" % kind), path("beam-%s-s.inp" % kind)
    r = run("distort", deck, "-o", dis, "--seed", "7", "--target-qmean", "0.55")
    check(r.returncode == 0, "%s: distort: %s" % (kind, r.stderr))
    r = run("smooth", dis, "-o", out, "-v")
    check(r.returncode == 0, "%s: smooth exit %d: %s" % (kind, r.returncode,
                                                         r.stderr[-400:]))
    n1, e1 = ho_elements(dis, gtype, nv)
    n2, e2 = ho_elements(out, gtype, nv)
    skin = skin_nodes(n0)
    interior = set(n0) - skin
    moved = sum(1 for n in interior if not np.array_equal(n1[n], n0[n]))
    check(moved > 0, "%s: distort moved %d interior nodes" % (kind, moved))
    check(ho_check.midpoint_errors(n2, e2, interior) < 1e-12,
          "%s: smoothed interior mid-nodes at midpoints" % kind)
    l1, l2 = node_lines(dis), node_lines(out)
    check(all(l1[n] == l2[n] for n in skin),
          "%s: skin node lines unchanged" % kind)
    a, b = open(dis).read().split("\n"), open(out).read().split("\n")
    check(len(a) == len(b) and all(
        x == y or (x.split(",")[0] == y.split(",")[0] and
                   int(x.split(",")[0]) in l1) for x, y in zip(a, b)),
          "%s: output equals input outside *NODE coordinates" % kind)
    # meshio round trip to MSH, then Gmsh's Jacobians at every node
    m = meshio.read(out)
    msh = path("beam-%s-s.msh" % kind)
    meshio.write(msh, m, file_format="gmsh")
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    w, bad = ho_check.min_node_jacobian(msh)
    gmsh.finalize()
    check(bad == 0 and w > 0, "%s: min node det J %g (meshio -> Gmsh)" %
          (kind, w))
    rc0, u0, n0tip = solve(deck)
    rc2, u2, n2tip = solve(out)
    print("%s: ccx exit %d/%d, tip uz %.6g undistorted, %.6g smoothed "
          "(%d nodes)" % (kind, rc0, rc2, u0, u2, n2tip), flush=True)
    check(rc0 == 0 and rc2 == 0 and n2tip > 0, "%s: ccx solved" % kind)
    check(u0 < 0 and abs(u2 - u0) <= 0.01 * abs(u0),
          "%s: tip deflection %g vs %g" % (kind, u2, u0))


if os.path.isdir(CCX_TESTS):
    prove_on_calculix_decks()
else:
    check(False, "calculix-ccx-test is installed (%s)" % CCX_TESTS)
check(shutil.which("ccx") is not None, "ccx on PATH")
gen_decks()
for kind in ("tet10", "hex20"):
    beam(kind)
print("%d failure(s)" % len(FAILED))
sys.exit(1 if FAILED else 0)
