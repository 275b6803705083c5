#!/usr/bin/python3
"""Regression tests of issue #10: the getme command never loses data and
refuses damaged input with file and line.

usage: /usr/bin/python3 test_safety.py GETME_BINARY WORKDIR CASE
CASE: paths | damage | usability

paths:  --report / -o naming the input, an included file or the output
        (compared by device and inode), special files, symbolic links,
        missing directories, output extensions, temporary files.
damage: truncated files, unknown entities, NaN coordinates, degenerate
        elements, unknown --free names.
usability: the remaining items of the issue (quality without free nodes,
        CalculiX decks, ...).
Every refused run is checked for its exit code (the README's table), the
input's sha256 and the absence of any output or temporary file.
"""
import hashlib
import os
import re
import shutil
import signal
import stat
import subprocess
import sys

import gmsh

GETME, WORK, CASE = sys.argv[1], os.path.abspath(sys.argv[2]), sys.argv[3]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
from checks import Checks  # tests/support (PYTHONPATH set by ctest)

T = Checks(GETME)
check = T.check


def run(*args, expect=0, cwd=None):
    return T.run(*args, expect=expect, cwd=cwd, timeout=300)


def sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def path(name):
    return os.path.join(WORK, name)


def tmp_files():
    return sorted(f for f in os.listdir(WORK) if ".getme-tmp." in f)


def make_box(name, version=4.1, size=0.3, binary=False):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(path(name))
    gmsh.finalize()
    return path(name)


TET_DECK = """*HEADING
box
*NODE
1, 0, 0, 0
2, 1, 0, 0
3, 0, 1, 0
4, 0, 0, 1
5, 1, 1, 1
6, 0.3, 0.3, 0.3
*ELEMENT, TYPE=C3D4, ELSET=ALL
1, 1, 2, 3, 6
2, 1, 2, 6, 4
3, 1, 6, 3, 4
4, 2, 3, 6, 5
5, 2, 6, 4, 5
6, 6, 3, 4, 5
7, 2, 3, 4, 5
"""


# ---- paths ---------------------------------------------------------------

def refused(args, expect, inputs, outputs=(), message=None):
    """Run, expect the code, inputs' sha256 unchanged, outputs absent."""
    digests = {f: sha(f) for f in inputs}
    before = tmp_files()
    p = run(*args, expect=expect)
    for f, d in digests.items():
        check(sha(f) == d, f"{os.path.basename(f)} unchanged by {' '.join(args)}")
    for f in outputs:
        check(not os.path.lexists(f), f"no {os.path.basename(f)} after {' '.join(args)}")
    check(tmp_files() == before, f"no temporary file left by {' '.join(args)}")
    if message:
        check(re.search(message, p.stderr) is not None,
              f"message /{message}/ in {p.stderr.strip()!r}")
    return p


def paths_case():
    src = make_box("box.msh")
    dist = path("dist.msh")
    run("distort", src, "-o", dist, "--seed", "3", "-q")
    out = path("out.msh")
    # --report naming the input, by another name, a hard link, a symlink
    refused(["smooth", dist, "-o", out, "--report", dist, "-q"], 2, [dist], [out],
            "report .*dist.msh: refusing to overwrite the input")
    os.link(dist, path("hard.msh"))
    os.symlink("dist.msh", path("soft.json"))
    refused(["smooth", dist, "-o", out, "--report", path("hard.msh"), "-q"], 2, [dist], [out])
    refused(["smooth", dist, "-o", out, "--report", path("soft.json"), "-q"], 2, [dist], [out])
    p = subprocess.run([GETME, "smooth", "dist.msh", "-o", "out.msh", "--report",
                        "./dist.msh", "-q"], cwd=WORK, capture_output=True)
    check(p.returncode == 2 and not os.path.exists(out), "report ./dist.msh refused")
    # -o naming the input through a hard link
    refused(["smooth", dist, "-o", path("hard.msh"), "-q"], 2, [dist], [],
            "refusing to overwrite the input")
    # --report naming the output (existing or not, other spelling)
    refused(["smooth", dist, "-o", out, "--report", path("./out.msh"), "-q"], 2, [dist], [out],
            "it is the output file")
    open(out, "w").write("keep me\n")
    refused(["smooth", dist, "-o", out, "--report", out, "-q"], 2, [dist, out])
    os.remove(out)
    # --report / -o naming an *INCLUDEd file of an INP deck
    open(path("nodes.inc"), "w").write(TET_DECK.split("*ELEMENT")[0].split("*NODE\n")[1])
    deck = path("deck.inp")
    open(deck, "w").write("*HEADING\nx\n*NODE\n*INCLUDE, INPUT=nodes.inc\n*ELEMENT" +
                          TET_DECK.split("*ELEMENT")[1])
    refused(["smooth", deck, "-o", path("deck-out.inp"), "--report", path("nodes.inc"), "-q"],
            2, [deck, path("nodes.inc")], [path("deck-out.inp")], "which the input includes")
    os.link(path("nodes.inc"), path("nodes-link.inp"))
    refused(["smooth", deck, "-o", path("nodes-link.inp"), "-q"], 2,
            [deck, path("nodes.inc")], [], "overwrite")
    # --report naming the include copy the output writes
    # ("<output stem>.<included name>"): the mesh is written, the copy is
    # not replaced by JSON
    p = run("smooth", deck, "-o", path("deck-out.inp"), "--report",
            path("deck-out.nodes.inc"), "-q", expect=2)
    check("a file the output just wrote" in p.stderr, "report = include copy refused")
    check(open(path("deck-out.nodes.inc")).read().startswith("1, 0, 0, 0"),
          "the include copy is still the nodes, not JSON")
    run("smooth", deck, "-o", path("deck-out.inp"), "--report", path("deck.json"), "-q")
    check(os.path.exists(path("deck.json")), "report written next to a deck with includes")

    # special files: never replaced
    fifo = path("fifo.msh")
    os.mkfifo(fifo)
    refused(["smooth", dist, "-o", fifo, "-q"], 2, [dist], [], "is a FIFO")
    check(stat.S_ISFIFO(os.lstat(fifo).st_mode), "the FIFO is still a FIFO")
    refused(["smooth", dist, "-o", out, "--report", fifo, "-q"], 2, [dist], [out], "is a FIFO")
    os.symlink("/dev/null", path("null.msh"))
    refused(["smooth", dist, "-o", path("null.msh"), "-q"], 2, [dist], [],
            "is a character device")
    check(stat.S_ISCHR(os.stat("/dev/null").st_mode), "/dev/null is still a character device")
    check(os.path.islink(path("null.msh")), "the link to /dev/null is still a link")
    refused(["smooth", dist, "-o", "/dev/null", "-q"], 2, [dist], [])
    refused(["smooth", dist, "-o", "/dev/stdout", "-q"], 2, [dist], [])
    refused(["distort", dist, "-o", fifo, "--seed", "1", "-q"], 2, [dist], [], "is a FIFO")
    os.mkdir(path("adir.msh"))
    refused(["smooth", dist, "-o", path("adir.msh"), "-q"], 2, [dist], [], "is a directory")
    check(os.path.isdir(path("adir.msh")), "the directory is still a directory")

    # a symbolic link to a regular file: the file is written, the link stays
    open(path("target.msh"), "w").write("old\n")
    os.symlink("target.msh", path("link.msh"))
    run("smooth", dist, "-o", path("link.msh"), "-q")
    check(os.path.islink(path("link.msh")), "-o symlink: the link stays a link")
    check(open(path("target.msh"), "rb").read(6) == b"$MeshF", "-o symlink: its target was written")
    os.symlink("missing.msh", path("dangling.msh"))
    refused(["smooth", dist, "-o", path("dangling.msh"), "-q"], 2, [dist], [path("missing.msh")],
            "symbolic link to a missing file")

    # output directory missing / not writable: before reading (a malformed
    # input would give 4 if it were read first)
    bad = path("bad.msh")
    open(bad, "w").write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nnonsense\n")
    refused(["smooth", bad, "-o", path("nodir/out.msh"), "-q"], 7, [bad], [],
            "nodir/out.msh: cannot create a temporary file next to it")
    refused(["smooth", dist, "-o", out, "--report", path("nodir/r.json"), "-q"], 7, [dist], [out])
    if os.geteuid() != 0:  # root may write anywhere
        os.mkdir(path("ro"), 0o555)
        refused(["smooth", bad, "-o", path("ro/out.msh"), "-q"], 7, [bad], [])

    # output format = input format
    refused(["smooth", dist, "-o", path("out.inp"), "-q"], 2, [dist], [path("out.inp")],
            "must be one too")
    refused(["smooth", deck, "-o", path("deck.msh"), "-q"], 2, [deck], [path("deck.msh")])
    refused(["smooth", dist, "-o", path("out.vtk"), "-q"], 2, [dist], [path("out.vtk")])
    refused(["distort", dist, "-o", path("out.inp"), "--seed", "1", "-q"], 2, [dist], [])
    run("smooth", dist, "-o", path("OUT.MSH"), "-q")

    # temporary files: recognisable names; one left by a killed process is
    # removed by the next write of the same output, one of a live process
    # is not
    dead = 1
    while os.path.exists(f"/proc/{dead}") or dead == 1:
        dead = (dead * 7919 + 13) % 4000000 + 2
    stale = path(f".out.msh.getme-tmp.{dead}.12345")
    live = path(".out.msh.getme-tmp.1.777")
    other = path(f".other.msh.getme-tmp.{dead}.1")
    for f in (stale, live, other):
        open(f, "w").write("partial")
    run("smooth", dist, "-o", out, "-q")
    check(not os.path.exists(stale), "a dead process's temporary file is removed")
    check(os.path.exists(live) and os.path.exists(other),
          "temporary files of live processes / other outputs are kept")
    for f in (live, other):
        os.remove(f)
    # SIGKILL while writing leaves at most one such file, and the next run
    # removes it
    big = make_box("big.msh", size=0.03)
    for delay in (0.05, 0.3, 1.0, 2.0):
        p = subprocess.Popen([GETME, "smooth", big, "-o", path("big-out.msh"), "-q",
                              "--max-iter", "3"])
        try:
            p.wait(timeout=delay)
        except subprocess.TimeoutExpired:
            p.send_signal(signal.SIGKILL)
            p.wait()
    left = [f for f in os.listdir(WORK) if ".getme-tmp." in f]
    check(all(f.startswith(".big-out.msh.getme-tmp.") for f in left),
          f"only recognisable temporary files after SIGKILL ({left})")
    run("smooth", big, "-o", path("big-out.msh"), "-q", "--max-iter", "3")
    check(tmp_files() == [], f"the next run removed them ({tmp_files()})")
    # SIGTERM / SIGINT: whole output or nothing, never a temporary file
    for sig in (signal.SIGTERM, signal.SIGINT):
        for delay in (0.2, 0.6, 1.2):
            if os.path.exists(path("big-out2.msh")):
                os.remove(path("big-out2.msh"))
            p = subprocess.Popen([GETME, "smooth", big, "-o", path("big-out2.msh"), "-q",
                                  "--max-iter", "3"])
            try:
                p.wait(timeout=delay)
            except subprocess.TimeoutExpired:
                p.send_signal(sig)
                p.wait()
            check(tmp_files() == [], f"signal {sig} after {delay} s: no temporary file")
            if os.path.exists(path("big-out2.msh")):
                check(open(path("big-out2.msh"), "rb").read().rstrip().endswith(b"$EndElements"),
                      "an output that exists is complete")


# ---- damaged input ---------------------------------------------------------

def set_coord(src, dst, value, binary):
    """Copy an MSH file with the first coordinate of the first node with a
    nonzero tag replaced by value (a float)."""
    import struct
    data = bytearray(open(src, "rb").read())
    version = data.split(b"\n")[1].split()[0]
    if not binary:
        lines = data.decode().split("\n")
        i = lines.index("$Nodes")
        if version == b"2.2":
            j = i + 2
            f = lines[j].split()
            f[1] = repr(value)
            lines[j] = " ".join(f)
        else:
            j = i + 2
            while True:  # a block header "dim tag param n" with n > 0
                dim, tag, param, n = map(int, lines[j].split())
                if n:
                    break
                j += 1
            k = j + 1 + n  # first coordinate line of that block
            f = lines[k].split()
            f[0] = repr(value)
            lines[k] = " ".join(f)
            j = k
        open(dst, "w").write("\n".join(lines))
        return j + 1  # 1-based line number
    at = data.index(b"$Nodes\n") + len(b"$Nodes\n")
    if version == b"2.2":
        at = data.index(b"\n", at) + 1 + 4  # count line, then int tag
    else:
        at += 4 * 8  # numEntityBlocks numNodes min max
        while True:
            dim, tag, param = struct.unpack("<iii", data[at:at + 12])
            n = struct.unpack("<Q", data[at + 12:at + 20])[0]
            at += 20
            if n:
                at += 8 * n  # tags
                break
    data[at:at + 8] = struct.pack("<d", value)
    open(dst, "wb").write(bytes(data))
    return None


def damage_case():
    m41 = make_box("d41.msh")
    m22 = make_box("d22.msh", version=2.2)
    b22 = make_box("b22.msh", version=2.2, binary=True)
    b41 = make_box("b41.msh", binary=True)
    out = path("out.msh")

    # truncated files: refused with file and line, whatever the reader
    for src, cut in ((m22, 16), (m22, 1000), (b22, 16), (m41, 16)):
        data = open(src, "rb").read()
        bad = src[:-4] + f"-cut{cut}.msh"
        open(bad, "wb").write(data[:-cut])
        for reader in ("", "gmsh"):
            env = dict(os.environ, GETME_MSH_READER=reader) if reader else None
            p = subprocess.run([GETME, "smooth", bad, "-o", out, "-q"], capture_output=True,
                               text=True, env=env)
            where = "byte" if src == b22 else "line"
            check(p.returncode == 4, f"{os.path.basename(bad)} ({reader or 'default'}) -> "
                                     f"{p.returncode}, want 4 ({p.stderr.strip()})")
            check(os.path.basename(bad) in p.stderr and where in p.stderr,
                  f"truncation message names file and {where}: {p.stderr.strip()}")
            check(not os.path.exists(out), "no output for a truncated file")
    # MSH 2.2 damage inside the file: an element line short of a node, a
    # section with more lines than it declares
    lines = open(m22).read().split("\n")
    e = lines.index("$Elements") + 2
    short = lines[:]
    short[e + 3] = " ".join(short[e + 3].split()[:-1])
    open(path("short22.msh"), "w").write("\n".join(short))
    p = refused(["smooth", path("short22.msh"), "-o", out, "-q"], 4, [path("short22.msh")],
                [out], r"short22.msh', line %d: bad element line" % (e + 4))
    extra = lines[:]
    extra.insert(e + 2, extra[e + 1])
    open(path("extra22.msh"), "w").write("\n".join(extra))
    refused(["smooth", path("extra22.msh"), "-o", out, "-q"], 4, [path("extra22.msh")], [out],
            "holds more entries than it declares|wrong count")

    # an element block of an entity that does not exist (Gmsh refuses it)
    lines = open(m41).read().split("\n")
    e = lines.index("$Elements") + 2
    while lines[e].split()[0] != "3":
        e += int(lines[e].split()[3]) + 1
    f = lines[e].split()
    f[1] = "77"
    lines[e] = " ".join(f)
    open(path("noent.msh"), "w").write("\n".join(lines))
    refused(["smooth", path("noent.msh"), "-o", out, "-q"], 4, [path("noent.msh")], [out],
            r"noent.msh', line %d: element block of entity 77 \(dimension 3\): no such entity"
            % (e + 1))
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.open(path("noent.msh"))
        gmsh_ok = True
    except Exception:
        gmsh_ok = False
    gmsh.finalize()
    check(not gmsh_ok, "Gmsh itself refuses the unknown entity")

    # NaN / Inf coordinates: exit 4, file and line (binary: the node / byte)
    for src, binary in ((m41, False), (m22, False), (b41, True), (b22, True)):
        for value in (float("nan"), float("inf"), float("-inf")):
            bad = src[:-4] + "-nonfinite.msh"
            line = set_coord(src, bad, value, binary)
            want = r"line %d: node \d+ has a coordinate that is not a finite" % line \
                if line else "node \\d+ has a coordinate that is not a finite"
            refused(["smooth", bad, "-o", out, "-q"], 4, [bad], [out], want)
    deck = path("nan.inp")
    open(deck, "w").write(TET_DECK.replace("6, 0.3, 0.3, 0.3", "6, 0.3, nan, 0.3"))
    refused(["smooth", deck, "-o", path("nan-out.inp"), "-q"], 4, [deck], [], r"nan.inp:9: node 6: bad coordinate")

    # a degenerate tet (a node twice): exit 6 and the file's element tag
    lines = open(m41).read().split("\n")
    e = lines.index("$Elements") + 2
    while lines[e].split()[0] != "3":
        e += int(lines[e].split()[3]) + 1
    f = lines[e + 1].split()
    tag41 = f[0]
    f[4] = f[3]
    lines[e + 1] = " ".join(f)
    open(path("deg41.msh"), "w").write("\n".join(lines))
    refused(["smooth", path("deg41.msh"), "-o", out, "-q"], 6, [path("deg41.msh")], [out],
            r"deg41.msh', line %d: element %s is degenerate" % (e + 2, tag41))
    lines = open(m22).read().split("\n")
    e = lines.index("$Elements") + 2
    while lines[e].split()[1] != "4":
        e += 1
    f = lines[e].split()
    tag22 = f[0]
    f[-1] = f[-2]
    lines[e] = " ".join(f)
    open(path("deg22.msh"), "w").write("\n".join(lines))
    refused(["smooth", path("deg22.msh"), "-o", out, "-q"], 6, [path("deg22.msh")], [out],
            r"element %s is degenerate" % tag22)
    deck = path("deg.inp")
    open(deck, "w").write(TET_DECK.replace("3, 1, 6, 3, 4", "3, 1, 6, 3, 3"))
    refused(["smooth", deck, "-o", path("deg-out.inp"), "-q"], 6, [deck], [],
            r"deg.inp:13: element 3 is degenerate: node 3 appears twice")
    run("quality", deck, expect=6)

    # --free with an unknown name: refused for every format
    for src in (m41, m22):
        refused(["smooth", src, "-o", out, "--free", "nosuch", "-q"], 2, [src], [out],
                "Unknown physical group 'nosuch' to free")
    deck = path("ok.inp")
    open(deck, "w").write(TET_DECK)
    refused(["smooth", deck, "-o", path("ok-out.inp"), "--free", "nosuch", "-q"], 2, [deck], [],
            "no node or element set named 'nosuch' to free")
    run("smooth", deck, "-o", path("ok-out.inp"), "--free", "ALL", "-q")
    cg = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                      "cgns", "hybrid.cgns")
    refused(["smooth", cg, "-o", path("x.cgns"), "--free", "nosuch", "-q"], 2, [cg],
            [path("x.cgns")])


# ---- usability -------------------------------------------------------------

def hex_grid_deck(n, h, extra_ids=False):
    """A perfect n^3 hex grid of spacing h, as CalculiX's own test decks
    (C3D8I; with extra_ids, 10 node ids and a trailing comma per element
    line, as ccx's dloadlinI.inp)."""
    def nid(i, j, k):
        return 1 + i + (n + 1) * (j + (n + 1) * k)
    lines = ["*HEADING", "grid", "*NODE, NSET=NALL"]
    for k in range(n + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                lines.append(f"{nid(i, j, k)}, {i * h!r}, {j * h!r}, {k * h!r}")
    lines.append("*ELEMENT, TYPE=C3D8I, ELSET=EALL")
    e = 0
    for k in range(n):
        for j in range(n):
            for i in range(n):
                e += 1
                c = [nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
                     nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1),
                     nid(i, j + 1, k + 1)]
                if extra_ids:
                    c += [c[0] + 1000, c[1] + 1000]
                lines.append(f"{e}, " + ", ".join(map(str, c)) + ("," if extra_ids else ""))
    lines += ["*MATERIAL, NAME=STEEL", "*ELASTIC", "210000., .3",
              "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL", ""]
    return "\n".join(lines) + "\n"


def usability_case():
    # quality of a mesh without any free node: no made-up q*min of 1
    one = path("one.inp")
    open(one, "w").write("*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0.2, 0.2, 0.1\n"
                         "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n")
    p = run("quality", one)
    check("no element has a free node" in p.stdout and "q*min 1.0000" not in p.stdout,
          f"quality without free nodes says so: {p.stdout.splitlines()[1]}")
    check("qmin 0.2977" in p.stdout, "qmin still printed")
    p = run("smooth", one, "-o", path("one-out.inp"), "--report", path("one.json"))
    check("q*min 1.0000" not in p.stdout and "no element has a free node" in p.stdout,
          "smooth's log says so too")
    import json
    rep = json.load(open(path("one.json")))
    check(rep["before"]["q_min_star"] is None and rep["after"]["q_min_star"] is None,
          "report: q_min_star null without free nodes")

    # perfect hexes: nodes that move by a rounding step keep their text
    deck = path("grid.inp")
    open(deck, "w").write(hex_grid_deck(4, 0.25))
    run("smooth", deck, "-o", path("grid-out.inp"), "-q")
    check(open(deck, "rb").read() == open(path("grid-out.inp"), "rb").read(),
          "a perfect hex grid deck comes back byte for byte")
    # ... although the smoother did move some of them by a rounding step
    # (seen through the MSH writer, which writes every coordinate it has)
    nodes, hexes = [], []
    for ln in hex_grid_deck(4, 0.25).split("\n"):
        f = [x.strip() for x in ln.split(",")]
        if len(f) == 4 and "." in ln:
            nodes.append((int(f[0]), [float(v) for v in f[1:]]))
        elif len(f) == 9 and f[0].isdigit():
            hexes.append([int(v) for v in f])
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.addDiscreteEntity(3, 1)
    gmsh.model.mesh.addNodes(3, 1, [t for t, _ in nodes], [c for _, x in nodes for c in x])
    gmsh.model.mesh.addElementsByType(1, 5, [h[0] for h in hexes], [v for h in hexes for v in h[1:]])
    gmsh.write(path("grid.msh"))
    gmsh.finalize()
    run("smooth", path("grid.msh"), "-o", path("grid-out.msh"), "-q")

    def coords(f):
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(f)
        t, x, _ = gmsh.model.mesh.getNodes()
        gmsh.finalize()
        return dict(zip(t.tolist(), x.reshape(-1, 3).tolist()))
    a, b = coords(path("grid.msh")), coords(path("grid-out.msh"))
    diffs = [max(abs(p - q) for p, q in zip(a[t], b[t])) for t in a if a[t] != b[t]]
    check(diffs and max(diffs) < 1e-12,
          f"the smoother moves {len(diffs)} grid nodes by rounding steps only")
    # a node that really moves is still written
    moved = hex_grid_deck(4, 0.25).replace("34, 0.75, 0.25, 0.25", "34, 0.7, 0.3, 0.25")
    check(moved != hex_grid_deck(4, 0.25), "test deck edit applies")
    open(path("moved.inp"), "w").write(moved)
    run("smooth", path("moved.inp"), "-o", path("moved-out.inp"), "-q")
    out_lines = open(path("moved-out.inp")).read().split("\n")
    changed = [(x, y) for x, y in zip(moved.split("\n"), out_lines) if x != y]
    check(changed and all(x.split(",")[0] == y.split(",")[0] for x, y in changed),
          f"moved nodes rewritten ({len(changed)} lines), nothing else")

    # element lines with extra node ids (ccx ignores them): warning naming
    # file and line, accepted, written back byte for byte
    deck = path("extra.inp")
    text = hex_grid_deck(3, 0.5, extra_ids=True)
    open(deck, "w").write(text)
    p = run("smooth", deck, "-o", path("extra-out.inp"))
    line = text.split("\n").index("*ELEMENT, TYPE=C3D8I, ELSET=EALL") + 2
    check(re.search(r"Warning : .*extra.inp:%d: element 1 has more node ids than its type "
                    r"needs.*\(27 elements" % line, p.stdout) is not None,
          f"warning names file and line: {p.stdout[:400]!r}")
    out = open(path("extra-out.inp")).read()
    els = [x for x in text.split("\n") if re.match(r"^\d+, \d+, \d+, \d+, \d+, \d+, \d+, \d+, \d+, \d+, \d+,$", x)]
    check(len(els) == 27 and all(x in out.split("\n") for x in els),
          "element lines with extra ids kept byte for byte")
    p = run("smooth", deck, "-o", path("extra-out2.inp"), "-q")
    check("Warning" not in p.stdout, "-q silences the warning")
    # too few ids is still an error
    bad = text.replace("1, 1, 2, 6, 5, 17, 18, 22, 21, 1001, 1002,", "1, 1, 2, 6")
    check(bad != text, "test deck edit applies (too few ids)")
    open(path("few.inp"), "w").write(bad)
    refused(["smooth", path("few.inp"), "-o", path("few-out.inp"), "-q"], 4,
            [path("few.inp")], [path("few-out.inp")], r"few.inp:%d: element 1" % line)
    # CalculiX's own decks, when its test package is installed
    ccx = "/usr/share/doc/calculix-ccx-test/examples/test"
    for name in ("dloadlinI", "beampsensfreq"):
        src = os.path.join(ccx, name + ".inp.gz")
        if not os.path.exists(src):
            print(f"(skipped {name}: calculix-ccx-test not installed)")
            continue
        import gzip
        data = gzip.open(src).read()
        open(path(name + ".inp"), "wb").write(data)
        p = run("smooth", path(name + ".inp"), "-o", path(name + "-out.inp"))
        check("more node ids than its type needs" in p.stdout, f"{name}: warning")
        check(open(path(name + "-out.inp"), "rb").read() == data,
              f"{name}: perfect hexes come back byte for byte")


# ---- main ---------------------------------------------------------------

CASES = {"paths": paths_case, "damage": damage_case, "usability": usability_case}
CASES[CASE]()
sys.exit(T.summary())
