#!/usr/bin/python3
"""test_found.py GETME WORK -- regressions for what the conformance sweep
(conformance.py, docs/conformance.md) found on outside files, each on the
smallest hand-made input that shows it (no outside package needed).

1. INP planar decks whose element blocks turn opposite ways (Gmsh writes
   one *ELEMENT block per surface, oriented like the surface: machine.geo
   of Gmsh's demos has 21 such surfaces).  getme read them as 10,896
   inverted triangles and stopped with exit 8; the MSH file of the same
   mesh smoothed fine.  Now each block that is clockwise as a whole is
   handed to libgetme reversed, as the MSH reader does per surface: the
   deck smooths, the output equals the input outside moved *NODE lines,
   and an element that is really inverted inside a block is still found.
2. Second-order elements that stay invalid (a folded mid-node, every node
   fixed: Gmsh's tet10 meshes of curved parts have them) were counted in
   the exit-8 error but not named ("10 elements could not be untangled
   (10 with every node fixed): , ..."): the list came from the corner
   qualities, which do not see mid-nodes.  Now it is the untangler's own.
3. A deck whose first line is data before any keyword (CalculiX's own
   beamfsh1.inp starts with ">**", and ccx runs it) was refused with exit
   4.  Such lines are now ignored as ccx ignores them, with one warning
   naming file and line, and written back as they are.
4. A partitioned MSH 4.1 file (read through the Gmsh SDK adapter) was
   written by Gmsh's writer, which in binary wrote the entities' bounding
   boxes as zeros (Gmsh's t21.geo); now the input is copied with new
   coordinates in $Nodes only, as for every other MSH file.
"""
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from checks import WorkChecks  # noqa: E402

GETME, WORK = sys.argv[1], sys.argv[2]
W = WorkChecks(GETME, WORK)
check, path, run = W.check, W.path, W.run


def two_squares_deck(second_order, flip_one=False):
    """Two unit squares side by side in z = 0, each cut into 4 triangles
    around a free centre node that is off-centre (so smoothing moves it).
    The left block is counter-clockwise, the right one clockwise, as Gmsh
    writes two surfaces of opposite orientation.  flip_one: one element of
    the left block turned clockwise too (really inverted)."""
    nodes = {1: (0, 0), 2: (1, 0), 3: (2, 0), 4: (2, 1), 5: (1, 1), 6: (0, 1),
             7: (0.3, 0.35), 8: (1.7, 0.65)}
    left = [(1, 2, 7), (2, 5, 7), (5, 6, 7), (6, 1, 7)]          # ccw
    right = [(2, 8, 3), (3, 8, 4), (4, 8, 5), (5, 8, 2)]         # cw
    if flip_one:
        left[0] = (2, 1, 7)
    elems = []
    nid = 100
    mids = {}

    def mid(a, b):
        nonlocal nid
        k = (min(a, b), max(a, b))
        if k not in mids:
            nid += 1
            mids[k] = nid
            nodes[nid] = tuple(0.5 * (p + q) for p, q in zip(nodes[a], nodes[b]))
        return mids[k]
    for block in (left, right):
        out = []
        for a, b, c in block:
            out.append((a, b, c, mid(a, b), mid(b, c), mid(c, a)) if second_order else (a, b, c))
        elems.append(out)
    t = "CPS6" if second_order else "CPS3"
    lines = ["*HEADING", "two surfaces of opposite orientation", "*NODE"]
    lines += ["%d, %.17g, %.17g, 0" % (n, x, y) for n, (x, y) in sorted(nodes.items())]
    eid = 0
    for name, block in zip(("Surface1", "Surface2"), elems):
        lines.append("*ELEMENT, type=%s, ELSET=%s" % (t, name))
        for e in block:
            eid += 1
            lines.append("%d, %s" % (eid, ", ".join(map(str, e))))
    lines += ["*NSET, NSET=CORNERS", "1, 3, 4, 6", "** end"]
    return "\n".join(lines) + "\n"


def planar_blocks_case():
    for second_order in (0, 1):
        tag = "CPS6" if second_order else "CPS3"
        text = two_squares_deck(second_order)
        src, out = path("two-%s.inp" % tag), path("two-%s-out.inp" % tag)
        open(src, "w").write(text)
        p = run("smooth", src, "-o", out, "--report", out + ".json")
        check(p.returncode == 0, "%s: two opposite blocks smooth (exit %d: %s)"
              % (tag, p.returncode, (p.stdout + p.stderr)[-300:]))
        check("invalid (inverted" not in p.stdout,
              "%s: no element is reported invalid: %s" % (tag, p.stdout[-300:]))
        if p.returncode:
            continue
        a, b = text.split("\n"), open(out).read().split("\n")
        changed = [i for i, (x, y) in enumerate(zip(a, b)) if x != y]
        check(len(a) == len(b) and changed,
              "%s: same line count, some node moved (%d lines)" % (tag, len(changed)))
        # only the free centre nodes 7 and 8 (and, second order, the
        # mid-nodes of their edges) move; the skin stays byte for byte
        moved = {int(b[i].split(",")[0]) for i in changed}
        check(moved and moved <= {7, 8} | set(range(101, 120)) and
              all(a[i].split(",")[0] == b[i].split(",")[0] for i in changed),
              "%s: only interior node lines changed: %s" % (tag, sorted(moved)))
        skin = {1, 2, 3, 4, 5, 6}
        check(not moved & skin, "%s: skin nodes unchanged" % tag)
        import json
        r = json.load(open(out + ".json"))
        check(r["before"]["invalid"] == 0 and r["after"]["invalid"] == 0 and
              r["after"]["q_min"] > r["before"]["q_min"],
              "%s: valid before and after, q_min %.4f -> %.4f" % (
                  tag, r["before"]["q_min"], r["after"]["q_min"]))
    # an element really inverted inside a counter-clockwise block is still
    # found (and untangled: its centre node is free)
    src, out = path("flipped.inp"), path("flipped-out.inp")
    open(src, "w").write(two_squares_deck(0, flip_one=True))
    p = run("smooth", src, "-o", out)
    check(re.search(r"Warning : 1 invalid \(inverted or degenerate\) element", p.stdout)
          is not None, "a flipped element in a block is found: %s" % p.stdout[-400:])


def tet10_msh(mid0):
    """One tet10 (file id 7), Gmsh order, every node on the skin; mid-node
    4 of edge 0-1 at (mid0, 0, 0)."""
    xyz = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (mid0, 0, 0), (0.5, 0.5, 0),
           (0, 0.5, 0), (0, 0, 0.5), (0, 0.5, 0.5), (0.5, 0, 0.5)]
    s = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$Entities", "0 0 0 1",
         "1 0 0 0 1 1 1 0 0", "$EndEntities", "$Nodes", "1 10 1 10", "3 1 0 10"]
    s += [str(i + 1) for i in range(10)]
    s += ["%.17g %.17g %.17g" % p for p in xyz]
    s += ["$EndNodes", "$Elements", "1 1 7 7", "3 1 11 1",
          "7 " + " ".join(str(i + 1) for i in range(10)), "$EndElements"]
    return "\n".join(s) + "\n"


def ho_untangle_message_case():
    # d x / d u at corner 0 along edge 0-1 is 4 x4 - 3 x0 - x1 = 4 * 0.2 - 1
    # < 0: the node Jacobian at corner 0 is negative, the corners are fine
    src, out = path("tet10-folded.msh"), path("tet10-folded-out.msh")
    if os.path.exists(out):
        os.remove(out)
    open(src, "w").write(tet10_msh(0.2))
    p = run("smooth", src, "-o", out)
    err = [ln for ln in p.stderr.splitlines() + p.stdout.splitlines()
           if ln.startswith("Error")]
    check(p.returncode == 8, "folded tet10 with every node fixed: exit %d, want 8"
          % p.returncode)
    check(len(err) == 1 and re.search(
        r"tet10-folded.msh: 1 element could not be untangled \(1 with every node "
        r"fixed\): 7; no output", err[0]) is not None,
        "the error names element 7: %s" % err)
    check(not os.path.exists(out), "no output written")
    # the straight tet10 is fine
    open(src, "w").write(tet10_msh(0.5))
    p = run("smooth", src, "-o", out)
    check(p.returncode == 0, "straight tet10: exit %d" % p.returncode)


def leading_data_case():
    body = two_squares_deck(0).split("\n", 2)[2]          # without *HEADING
    text = ">**\n** comment\n" + body
    src, out = path("lead.inp"), path("lead-out.inp")
    open(src, "w").write(text)
    p = run("smooth", src, "-o", out)
    check(p.returncode == 0, "deck with a data line before its first keyword: exit %d"
          % p.returncode)
    warn = [ln for ln in p.stdout.splitlines() if ln.startswith("Warning")]
    check(len(warn) == 1 and "lead.inp:1: 1 data line before the first keyword ignored"
          in warn[0], "one warning naming file and line: %s" % warn)
    if p.returncode == 0:
        b = open(out).read()
        check(b.split("\n")[:2] == [">**", "** comment"], "leading lines written back")


def partitioned_binary_case():
    import gmsh
    import gmsh_check
    src, out = path("parts.msh"), path("parts-out.msh")
    gmsh.initialize(["test"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.partition(2)
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.write(src)
    finally:
        gmsh.finalize()
    p = run("smooth", src, "-o", out, "-q")
    check(p.returncode == 0, "partitioned binary file: exit %d %s" % (p.returncode, p.stderr))
    if p.returncode == 0:
        cause = gmsh_check.bytes_outside_nodes(src, out)
        check(cause == "", "partitioned binary file: only $Nodes changes (%s)" % cause)
        check(open(src, "rb").read() != open(out, "rb").read(), "some node moved")


planar_blocks_case()
ho_untangle_message_case()
leading_data_case()
partitioned_binary_case()
print("%d failed" % len(W.failed))
sys.exit(1 if W.failed else 0)
