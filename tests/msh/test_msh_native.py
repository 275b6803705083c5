#!/usr/bin/python3
"""
test_msh_native.py GETME WORKDIR -- the native MSH 4.1 and 2.2
reader/writer against the Gmsh path (GETME_MSH_READER=gmsh) on
Gmsh-generated meshes.

For each mesh (ASCII and binary): `getme smooth` once per reader; the two
outputs must hold the same coordinates per node tag (bit for bit) and the
same elements per element tag (read back with the gmsh Python API), the
same `getme quality` report, and the same log (fixed counts, qualities).
The native output must equal the input outside $Nodes (binary: same size),
and every node that is not free in the mesh must keep its input bytes.
MSH 2.2 against 4.1 on volumes of one physical group (with and without
a second group over one of them): the same coordinates, the surfaces
between the volumes fixed.  Sections before $MeshFormat and blanks after
section names read as Gmsh reads them; MSH 2.2 with $ParametricNodes
smoothed with only coordinates changed.  Then the error cases: exit code, one error
line naming the file (and the line for ASCII), input untouched, no
output, no temporary file left.
"""
import hashlib
import os
import re
import subprocess
import sys

import gmsh
import numpy as np

from checks import WorkChecks  # PYTHONPATH: tests/support

GETME, WORK = sys.argv[1], sys.argv[2]
W = WorkChecks(GETME, WORK)
FAILED = W.failed
check, path = W.check, W.path


# ---- mesh generation --------------------------------------------------------

def start(name):
    gmsh.clear()
    gmsh.option.setNumber("Mesh.RecombineAll", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 1e22)
    gmsh.model.add(name)


def write(name, binary, version=4.1):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(path(name))


def two_volumes():
    """Tet box of two physical volumes sharing an interface."""
    start("two")
    occ = gmsh.model.occ
    a = occ.addBox(0, 0, 0, 1, 1, 1)
    b = occ.addBox(1, 0, 0, 1, 1, 1)
    occ.fragment([(3, a)], [(3, b)])
    occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [1], 11)
    gmsh.model.setPhysicalName(3, 11, "left")
    gmsh.model.addPhysicalGroup(3, [2], 12)
    gmsh.model.setPhysicalName(3, 12, "right")
    gmsh.model.addPhysicalGroup(2, [s for _, s in gmsh.model.getEntities(2)], 5)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.22)
    gmsh.model.mesh.generate(3)


def hex_block():
    """Swept hex block (transfinite quads extruded in layers)."""
    start("hex")
    geo = gmsh.model.geo
    p = [geo.addPoint(x, y, 0) for x, y in [(0, 0), (2, 0), (2, 1), (0, 1)]]
    lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
    s = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    for ln, n in zip(lines, [9, 5, 9, 5]):
        geo.mesh.setTransfiniteCurve(ln, n)
    geo.mesh.setTransfiniteSurface(s)
    geo.mesh.setRecombine(2, s)
    geo.extrude([(2, s)], 0, 0, 1, [5], recombine=True)
    geo.synchronize()
    gmsh.model.mesh.generate(3)


def mixed():
    """Hexes and prisms (extruded quads and triangles) under a tet volume
    whose quad faces get pyramids."""
    start("mixed")
    geo = gmsh.model.geo
    pts = [geo.addPoint(x, y, 0, 0.3) for x, y in
           [(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1)]]
    L = lambda a, b: geo.addLine(pts[a], pts[b])
    l01, l12, l23, l34, l45, l50, l14 = (L(0, 1), L(1, 2), L(2, 3), L(3, 4),
                                         L(4, 5), L(5, 0), L(1, 4))
    s1 = geo.addPlaneSurface([geo.addCurveLoop([l01, l14, l45, l50])])
    s2 = geo.addPlaneSurface([geo.addCurveLoop([l12, l23, l34, -l14])])
    for ln in (l01, l14, l45, l50):
        geo.mesh.setTransfiniteCurve(ln, 5)
    geo.mesh.setTransfiniteSurface(s1)
    geo.mesh.setRecombine(2, s1)
    geo.extrude([(2, s1), (2, s2)], 0, 0, 0.5, [3], recombine=True)
    geo.synchronize()
    tops = [t for d, t in gmsh.model.getEntities(2)
            if abs(gmsh.model.getBoundingBox(d, t)[2] - 0.5) < 1e-9 and
            abs(gmsh.model.getBoundingBox(d, t)[5] - 0.5) < 1e-9]
    geo.extrude([(2, t) for t in tops], 0, 0, 1)
    geo.synchronize()
    gmsh.model.mesh.generate(3)


def planar(quads):
    start("quad" if quads else "tri")
    occ = gmsh.model.occ
    occ.addRectangle(0, 0, 0, 2, 1)
    occ.addDisk(3, 0.5, 0, 0.5, 0.5)
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15)
    if quads:
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.model.mesh.generate(2)


def partial_groups():
    """Three volumes, physical groups on two of them only."""
    start("partial")
    occ = gmsh.model.occ
    boxes = [occ.addBox(i, 0, 0, 1, 1, 1) for i in range(3)]
    occ.fragment([(3, boxes[0])], [(3, b) for b in boxes[1:]])
    occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [1], 1)
    gmsh.model.addPhysicalGroup(3, [3], 2)
    gmsh.model.setPhysicalName(3, 2, "third")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.model.mesh.generate(3)


def periodic():
    start("periodic")
    occ = gmsh.model.occ
    occ.addBox(0, 0, 0, 1, 1, 1)
    occ.synchronize()
    tr = [1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    gmsh.model.mesh.setPeriodic(2, [2], [1], tr)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
    gmsh.model.mesh.generate(3)


def second_order():
    start("order2")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(3)  # second order is smoothed (tests/highorder)


def add_node_data(name):
    """Append an ASCII $NodeData section (a view as Gmsh would write it)."""
    with open(path(name)) as f:
        text = f.read()
    tags = re.search(r"\$Nodes\n\d+ (\d+) (\d+) (\d+)", text)
    lo, hi = int(tags.group(2)), int(tags.group(3))
    rows = "".join("%d %g\n" % (t, 0.5 * t) for t in range(lo, hi + 1))
    with open(path(name), "a") as f:
        f.write('$NodeData\n1\n"t"\n1\n0\n3\n0\n1\n%d\n%s$EndNodeData\n'
                % (hi - lo + 1, rows))


def make_sparse(src, dst):
    """Node tags t -> 1000 t + 7 (a sparse numbering), ASCII MSH 4.1."""
    lines = open(path(src)).read().split("\n")
    out, i = [], 0
    new = lambda t: str(1000 * int(t) + 7)
    while i < len(lines):
        ln = lines[i]
        out.append(ln)
        i += 1
        if ln == "$Nodes":
            nb, nn, lo, hi = lines[i].split()
            out.append("%s %s %s %s" % (nb, nn, new(lo), new(hi)))
            i += 1
            for _ in range(int(nb)):
                d, t, p, n = lines[i].split()
                out.append(lines[i])
                i += 1
                out += [new(x) for x in lines[i:i + int(n)]]
                out += lines[i + int(n):i + 2 * int(n)]
                i += 2 * int(n)
        elif ln == "$Elements":
            out.append(lines[i])
            nb = int(lines[i].split()[0])
            i += 1
            for _ in range(nb):
                n = int(lines[i].split()[3])
                out.append(lines[i])
                i += 1
                for ln2 in lines[i:i + n]:
                    f = ln2.split()
                    out.append(" ".join([f[0]] + [new(x) for x in f[1:]]) + " ")
                i += n
    open(path(dst), "w").write("\n".join(out))


def to_binary(src, dst):
    gmsh.clear()
    gmsh.open(path(src))
    write(dst, True)


def one_group(overlap):
    """Three boxes fragmented into one body, all in one physical volume
    group (MSH 2.2 then has no elements on the surfaces between them);
    with overlap also a group of the first box alone, so that Gmsh's MSH
    2.2 writer lists that box's elements twice."""
    start("overlap" if overlap else "onegroup")
    occ = gmsh.model.occ
    boxes = [occ.addBox(i, 0, 0, 1, 1, 1) for i in range(3)]
    occ.fragment([(3, boxes[0])], [(3, b) for b in boxes[1:]])
    occ.synchronize()
    vols = [t for _, t in gmsh.model.getEntities(3)]
    gmsh.model.addPhysicalGroup(3, vols, 1)
    gmsh.model.setPhysicalName(3, 1, "all")
    if overlap:
        gmsh.model.addPhysicalGroup(3, [vols[0]], 2)
        gmsh.model.setPhysicalName(3, 2, "first")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
    gmsh.model.mesh.generate(3)


def same_as_41(name):
    """The MSH 2.2 copies (ASCII, binary) of name-ascii.msh smooth to the
    same coordinates as the 4.1 file, bit for bit: the surfaces between
    the volumes stay fixed though 2.2 saved no elements on them, and
    elements listed once per physical group are read once."""
    outs = {}
    for flavour in ("ascii", "bin", "22a", "22b"):
        src = path("%s-%s.msh" % (name, flavour))
        out = path("%s-%s.out.msh" % (name, flavour))
        rc, log = run(["smooth", src, "-o", out, "-v"])
        check(rc == 0, "%s: exit %d\n%s" % (src, rc, log))
        fixed = re.search(r"Done reading .*\((\d+) fixed\)", log)
        outs[flavour] = (load(out) if rc == 0 else None,
                         fixed.group(1) if fixed else None, log)
    for flavour in ("22a", "22b"):
        # ASCII files hold Gmsh's %.16g, binary ones the doubles
        ref = outs["ascii" if flavour == "22a" else "bin"]
        got = outs[flavour]
        if ref[0] is None or got[0] is None:
            continue
        check(got[1] == ref[1], "%s-%s: %s fixed nodes, 4.1: %s" %
              (name, flavour, got[1], ref[1]))
        check(np.array_equal(got[0][0], ref[0][0]) and
              got[0][1].tobytes() == ref[0][1].tobytes(),
              "%s-%s: coordinates differ from the 4.1 file's" % (name, flavour))
        if name == "overlap":
            check("listed again under another physical group" in got[2],
                  "%s-%s: no note of the repeated elements" % (name, flavour))
    fixed = lower_dim_nodes(path(name + "-ascii.msh"), 3)
    i = load(path(name + "-ascii.msh"))
    ref = outs["ascii"]
    if ref[0] is not None:
        same = np.all(i[1] == ref[0][1], axis=1)
        moved = {int(t) for t, s in zip(i[0], same) if not s}
        check(moved and not (moved & fixed), "%s: %d moved, %d on surfaces" %
              (name, len(moved), len(moved & fixed)))
    print("ok %-28s 2.2 = 4.1" % name, flush=True)


def lenient():
    """What Gmsh's reader accepts, the native one too: sections it does not
    know before $MeshFormat, blanks after section names; and MSH 2.2 with
    $ParametricNodes (Mesh.SaveParametric), read and written through the
    Gmsh path."""
    for name in ("two-ascii.msh", "two-22a.msh"):
        plain = path(name[:-4] + ".plain.out.msh")
        rc, log = run(["smooth", path(name), "-o", plain])
        check(rc == 0, "%s: exit %d\n%s" % (name, rc, log))
        data = open(path(name), "rb").read()
        variants = {
            "comments": b"$Comments\nmade by hand\n$EndComments\n" + data,
            "blanks": re.sub(rb"(?m)^(\$\w+)\n", rb"\1 \t\n", data)}
        for what, text in variants.items():
            src = path("%s.%s.msh" % (name[:-4], what))
            out = path("%s.%s.out.msh" % (name[:-4], what))
            open(src, "wb").write(text)
            rc, log = run(["smooth", src, "-o", out], "native")
            check(rc == 0, "%s: exit %d\n%s" % (src, rc, log))
            if rc == 0 and os.path.exists(plain):
                a, b = load(plain), load(out)
                check(np.array_equal(a[0], b[0]) and
                      a[1].tobytes() == b[1].tobytes(),
                      "%s: coordinates differ from the plain file's" % src)
    start("param")
    gmsh.model.occ.addSphere(0, 0, 0, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.SaveParametric", 1)
    write("param-22a.msh", False, 2.2)
    gmsh.option.setNumber("Mesh.SaveParametric", 0)
    src, out = path("param-22a.msh"), path("param-22a.out.msh")
    check(b"$ParametricNodes" in open(src, "rb").read(), "no $ParametricNodes")
    rc, log = run(["smooth", src, "-o", out])
    check(rc == 0, "param-22a.msh: exit %d\n%s" % (rc, log))
    if rc == 0:
        a, b = open(src).read().split("\n"), open(out).read().split("\n")
        check(len(a) == len(b), "param-22a.msh: line count changed")
        # only node lines change, and in them only x y z
        changed = [(x, y) for x, y in zip(a, b) if x != y]
        check(changed and all(x.split()[0] == y.split()[0] and
                              x.split()[4:] == y.split()[4:]
                              for x, y in changed),
              "param-22a.msh: %d lines changed, not only coordinates" %
              len(changed))
        i, o = load(src), load(out)
        check(np.array_equal(i[0], o[0]), "param-22a.msh: node tags differ")
    print("ok lenient headers, parametric 2.2", flush=True)


# ---- running getme ----------------------------------------------------------

def run(args, reader=None):
    env = dict(os.environ)
    env.pop("GETME_MSH_READER", None)
    if reader:
        env["GETME_MSH_READER"] = reader
    p = subprocess.run([GETME] + args, env=env, capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def normalize(log, names):
    log = re.sub(r"\(Wall [0-9.]+s\)", "(Wall)", log)
    log = re.sub(r", [0-9.]+ s\)", ")", log)
    log = re.sub(r"\([0-9.]+ s\)", "()", log)
    for n in names:
        log = log.replace(n, "FILE")
    return log


def load(p):
    gmsh.clear()
    gmsh.open(p)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    order = np.argsort(tags)
    elems = {}
    types, etags, ntags = gmsh.model.mesh.getElements()
    for t, et, nt in zip(types, etags, ntags):
        nv = len(nt) // len(et)
        o = np.argsort(et, kind="stable")
        elems[t] = (np.asarray(et)[o], np.asarray(nt).reshape(-1, nv)[o])
    return tags[order], xyz.reshape(-1, 3)[order], elems


def lower_dim_nodes(p, top):
    """Tags of nodes Gmsh classifies on entities below the top dimension."""
    gmsh.clear()
    gmsh.open(p)
    out = set()
    for d in range(top):
        out.update(int(t) for t in gmsh.model.mesh.getNodes(d, -1)[0])
    return out


def split_nodes(data):
    a = data.index(b"$Nodes\n")
    b = data.index(b"$EndNodes", a)
    return data[:a], data[b:]


def compare(name, top, extra=()):
    src = path(name)
    outs, logs, failed = {}, {}, len(FAILED)
    for reader in ("gmsh", "native"):
        out = path("%s.%s.msh" % (name[:-4], reader))
        rc, log = run(["smooth", src, "-o", out, "-v"] + list(extra), reader)
        check(rc == 0, "%s %s: exit %d\n%s" % (name, reader, rc, log))
        outs[reader], logs[reader] = out, normalize(log, [out, src])
    if len(FAILED) > failed:
        return
    check(logs["gmsh"] == logs["native"],
          "%s %s: logs differ:\n%s\n---\n%s" % (name, extra, logs["gmsh"],
                                                logs["native"]))
    g, n = load(outs["gmsh"]), load(outs["native"])
    check(np.array_equal(g[0], n[0]), name + ": node tags differ")
    # exact: the Gmsh path patches $Nodes of MSH 4.1 and 2.2 in place too,
    # with the native writer's shortest round-trip numbers (MSH 4.0 goes
    # through Gmsh's writer, %.16g)
    check(g[1].tobytes() == n[1].tobytes(), name + ": coordinates differ")
    if b"\n4.0 " not in open(src, "rb").read(40):
        check(open(outs["gmsh"], "rb").read() == open(outs["native"], "rb").read(),
              name + ": the two paths write different bytes")
    check(sorted(g[2]) == sorted(n[2]), name + ": element types differ")
    for t in g[2]:
        check(np.array_equal(g[2][t][0], n[2][t][0]) and
              np.array_equal(g[2][t][1], n[2][t][1]),
              "%s: elements of type %d differ" % (name, t))
    q = [normalize(run(["quality", outs[r]])[1], [outs[r]])
         for r in ("gmsh", "native")]
    check(q[0] == q[1], name + ": quality reports differ")
    # native output = input outside $Nodes; non-free nodes untouched
    data_in, data_out = open(src, "rb").read(), open(outs["native"], "rb").read()
    check(split_nodes(data_in) == split_nodes(data_out),
          name + ": native output differs outside $Nodes")
    if b"\n4.1 1 8\n" in data_in[:40] or b"\n2.2 1 8\n" in data_in[:40]:
        check(len(data_in) == len(data_out), name + ": binary size changed")
    i = load(src)
    fixed = lower_dim_nodes(src, top)
    same = np.all(i[1] == n[1], axis=1)
    moved = {int(t) for t, s in zip(i[0], same) if not s}
    check(moved and not (moved & fixed),
          "%s: %d moved nodes, %d of them fixed" % (name, len(moved),
                                                   len(moved & fixed)))
    print("ok %-28s %s: %d nodes moved" % (name, " ".join(extra), len(moved)),
          flush=True)


# ---- error cases ------------------------------------------------------------

def digest(p):
    return hashlib.sha256(open(p, "rb").read()).hexdigest()


def expect_error(name, code, want, reader="native"):
    src = path(name)
    before = digest(src)
    out = path("err-out.msh")
    if os.path.exists(out):
        os.remove(out)
    rc, log = run(["smooth", src, "-o", out], reader)
    errors = [ln for ln in log.splitlines() if ln.startswith("Error")]
    check(rc == code, "%s: exit %d, want %d\n%s" % (name, rc, code, log))
    check(len(errors) == 1 and src in errors[0] and
          all(re.search(w, errors[0]) for w in want),
          "%s: error line %r, want %s" % (name, errors, want))
    check(digest(src) == before, name + ": input modified")
    check(not os.path.exists(out), name + ": output written")
    check(not [f for f in os.listdir(WORK) if ".tmp." in f],
          name + ": temporary file left")
    print("ok error %-22s exit %d: %s" % (name, rc, errors[0] if errors else ""),
          flush=True)


def corrupt(src, dst, fn):
    data = open(path(src), "rb").read()
    open(path(dst), "wb").write(fn(data))


def errors():
    corrupt("two-bin.msh", "trunc-bin.msh",
            lambda d: d[:d.index(b"$Elements") + 4000])
    expect_error("trunc-bin.msh", 4, [r"end of file", r"byte \d+"])
    corrupt("two-ascii.msh", "trunc-ascii.msh",
            lambda d: d[:d.index(b"$Nodes") + 3000])
    expect_error("trunc-ascii.msh", 4, [r"line \d+", r"end of file"])
    corrupt("two-ascii.msh", "bad-format.msh",
            lambda d: d.replace(b"4.1 0 8", b"4.1 7 8", 1))
    expect_error("bad-format.msh", 4, [r"line \d+", r"MeshFormat"])

    def missing(d):
        a = d.index(b"$Elements")
        nl = d.index(b"\n", d.index(b"\n", d.index(b"\n", a) + 1) + 1)
        end = d.index(b"\n", nl + 1)
        f = d[nl + 1:end].split()
        return d[:nl + 1] + b" ".join([f[0], b"99999999"] + f[2:]) + d[end:]
    corrupt("two-ascii.msh", "missing-node.msh", missing)
    expect_error("missing-node.msh", 4, [r"line \d+", r"node 99999999"])
    expect_error("order2.msh", 5, [r"order 3", r"20-node tetrahedron"])
    expect_error("order2.msh", 5, [r"order 3", r"20-node tetrahedron"],
                 "gmsh")
    # same file, same message from both paths
    g = run(["smooth", path("order2.msh"), "-o", path("x.msh")], "gmsh")[1]
    n = run(["smooth", path("order2.msh"), "-o", path("x.msh")], "native")[1]
    check([l for l in g.splitlines() if l.startswith("Error")] ==
          [l for l in n.splitlines() if l.startswith("Error")],
          "third-order message differs:\n%s\n%s" % (g, n))
    # unknown --fix name: usage error, same message
    msgs = []
    for reader in ("gmsh", "native"):
        rc, log = run(["smooth", path("two-bin.msh"), "-o", path("x.msh"),
                       "--fix", "nosuch"], reader)
        check(rc == 2, "unknown --fix: exit %d (%s)" % (rc, reader))
        msgs.append([l for l in log.splitlines() if l.startswith("Error")])
    check(msgs[0] == msgs[1], "unknown --fix messages differ: %s" % msgs)
    # forced native on a file it declines (MSH 4.0 goes to Gmsh)
    gmsh.clear()
    gmsh.open(path("two-ascii.msh"))
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.0)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.write(path("v40.msh"))
    expect_error("v40.msh", 5, [r"native"])
    check(run(["quality", path("v40.msh")])[0] == 0, "MSH 4.0 fallback")
    # ... and written back with only node coordinates changed (Gmsh's
    # writer zeroed every entity's bounding box in $Entities)
    rc, log = run(["smooth", path("two-40a.msh"), "-o", path("v40.out.msh")])
    check(rc == 0, "MSH 4.0 smooth: exit %d\n%s" % (rc, log))
    if rc == 0:
        a = open(path("two-40a.msh")).read().split("\n")
        b = open(path("v40.out.msh")).read().split("\n")
        changed = [(x, y) for x, y in zip(a, b) if x != y]
        check(len(a) == len(b) and changed and
              all(len(x.split()) == 4 and x.split()[0] == y.split()[0]
                  for x, y in changed),
              "MSH 4.0: %d lines changed, not only node coordinates"
              % len(changed))
    # MSH 2.2 read natively: damage named with file and line / byte
    corrupt("two-22a.msh", "trunc-22a.msh",
            lambda d: d[:d.index(b"$Elements") + 3000])
    expect_error("trunc-22a.msh", 4, [r"line \d+", r"end of file"])
    corrupt("two-22b.msh", "trunc-22b.msh", lambda d: d[:len(d) - 100])
    expect_error("trunc-22b.msh", 4, [r"byte \d+", r"end of file"])
    corrupt("two-22a.msh", "nonode-22a.msh",
            lambda d: d.replace(b"\n$Elements\n", b"\n$Elements\n", 1)[
                :d.index(b"\n", d.index(b"$Elements") + 11) + 1] +
            b"1 4 2 0 1 1 2 3 99999999\n" +
            d[d.index(b"\n", d.index(b"\n", d.index(b"$Elements") + 11) + 1) + 1:])
    expect_error("nonode-22a.msh", 4, [r"line \d+", r"node 99999999"])


def main():
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    cases = [("two", two_volumes, 3), ("hex", hex_block, 3),
             ("mixed", mixed, 3), ("tri", lambda: planar(False), 2),
             ("quad", lambda: planar(True), 2),
             ("partial", partial_groups, 3), ("periodic", periodic, 3)]
    for name, gen, _ in cases:
        gen()
        write(name + "-ascii.msh", False)
        write(name + "-bin.msh", True)
        write(name + "-22a.msh", False, 2.2)
        write(name + "-22b.msh", True, 2.2)
        if name == "two": # from the CAD model: entities with real boxes
            write("two-40a.msh", False, 4.0)
    second_order()
    write("order2.msh", False)
    gmsh.clear()
    gmsh.open(path("mixed-bin.msh"))
    types = set(gmsh.model.mesh.getElementTypes(3))
    check(types == {4, 5, 6, 7}, "mixed mesh has types %s" % types)
    make_sparse("two-ascii.msh", "sparse-ascii.msh")
    to_binary("sparse-ascii.msh", "sparse-bin.msh")
    corrupt("partial-ascii.msh", "nodedata-ascii.msh", lambda d: d)
    add_node_data("nodedata-ascii.msh")
    for name, _, top in cases:
        for flavour in ("ascii", "bin", "22a", "22b"):
            compare("%s-%s.msh" % (name, flavour), top)
    compare("sparse-ascii.msh", 3)
    compare("sparse-bin.msh", 3)
    compare("nodedata-ascii.msh", 3)
    compare("two-bin.msh", 3, ["--fix", "left"])
    compare("two-ascii.msh", 3, ["--fix", "3:12", "--free-interfaces"])
    compare("partial-bin.msh", 3, ["--fix", "third"])
    compare("two-22b.msh", 3, ["--fix", "left"])
    compare("two-22a.msh", 3, ["--fix", "3:12", "--free-interfaces"])
    lenient()
    for overlap, name in ((False, "onegroup"), (True, "overlap")):
        one_group(overlap)
        write(name + "-ascii.msh", False)
        write(name + "-bin.msh", True)
        write(name + "-22a.msh", False, 2.2)
        write(name + "-22b.msh", True, 2.2)
        same_as_41(name)
    errors()
    gmsh.finalize()
    print("test_msh_native: %d failures" % len(FAILED))
    return 1 if FAILED else 0


if __name__ == "__main__":
    sys.exit(main())
