#!/usr/bin/python3
"""Gmsh-partitioned input read per rank (ctest label mpi,
docs/distributed.md §3).

usage: test_mpi_parts.py GETME_MPI GETME MPIEXEC SOURCE_DIR [--sanitized]

The distorted tet, hex and mixed "quick" meshes are written by Gmsh
(binary MSH 4.1) unpartitioned, as 3 split files (NAME_1..3.msh) and as
one file with 3 partitions.  `mpirun -np P getme-mpi smooth` on them,
every rank reading its own parts with the native reader, must give:
 - output parts OUT_1..3.msh (one OUT.msh for one partitioned file) whose
   nodes, joined by tag, carry `getme smooth`'s coordinates on the
   unpartitioned file bit for bit (fixed nodes included), P = 1, 2, 3
   (and 4 > 3 parts: rank 0 reads and splits, same bits) -- mixed: 1-4
   ranks on the split files, 1 and 3 on the one file; tets: 3 ranks and
   2 on the one file; hexes: 2 ranks;
 - the same number of fixed nodes as getme smooth (skin, interfaces of
   the mixed mesh's 4 physical volumes across the partition cuts);
 - rank 0's -v log: the finishing step ran on a sub-mesh, and the
   "Quality before/after" lines with their histograms and the measures'
   ranges and minima are getme smooth's (reduced over the parts);
 - each output part the size of its input part (binary: only coordinates
   change) and Gmsh opening the output parts with their 3 partitions;
 - a truncated or a missing part at -np 2 and 3: one error line naming
   the rank and the file, getme smooth's exit code (4 parse, 3 open), no
   output part and no temporary file;
 - an output part that is an input part refused (exit 2), the inputs
   untouched; a stale OUT_4.msh of an earlier run reported;
 - a rank failing to write its part (GETME_MPI_FAIL_WRITE): exit 7, one
   error line, no file left; a rank failing to rename
   (GETME_MPI_FAIL_RENAME): the error lists exactly the parts that are
   new.
"""
import json
import os
import struct
import subprocess
import sys
import tempfile

import gmsh
import meshes
from gmsh_helpers import merged_nodes
from mpi_checks import GETME_MPI, MPIEXEC, SANITIZED, ENV, c

N = 3


def mpirun(np, *args, env=None):
    return subprocess.run([MPIEXEC, "--oversubscribe", "-np", str(np), GETME_MPI,
                           *args], capture_output=True, text=True,
                          env=dict(ENV, **(env or {})))


def nodes(paths):
    """{tag: coordinate bits} of the MSH files merged, and the partitions."""
    xyz, parts = merged_nodes(paths)
    return {t: struct.pack("<3d", *p) for t, p in xyz.items()}, parts


def write_inputs(src, stem):
    """stem-whole.msh, stem_1..N.msh, stem-one.msh (binary MSH 4.1)."""
    gmsh.initialize(["test"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.open(src)
        gmsh.write(stem + "-whole.msh")
        # Gmsh 4.11's partition topology fails on the swept hex mesh ("No
        # mesh elements were found"); without it the cuts' nodes stay in
        # the partitioned volumes, which the reader handles alike
        gmsh.option.setNumber("Mesh.PartitionCreateTopology",
                              0 if "hex" in stem else 1)
        gmsh.model.mesh.partition(N)
        gmsh.option.setNumber("Mesh.PartitionSplitMeshFiles", 1)
        gmsh.write(stem + ".msh")
        gmsh.option.setNumber("Mesh.PartitionSplitMeshFiles", 0)
        gmsh.write(stem + "-one.msh")
    finally:
        gmsh.finalize()


def parts(stem):
    return [f"{stem}_{k}.msh" for k in range(1, N + 1)]


def stats_logged(text):
    """The 'Quality before/after' lines with their histograms, and the
    measures' ranges and minima (getme-mpi does not print the means)."""
    out = []
    for line in text.splitlines():
        if "Quality" in line or "< quality <" in line:
            out.append(line)
        elif "Measures" in line:
            out.append(",".join(f.split(" mean ")[0] for f in line.split(",")))
    return out


def fixed_logged(text):
    """The fixed-node count of getme-mpi's 'Parts set up' line."""
    for line in text.splitlines():
        if "Parts set up" in line and " fixed)" in line:
            return int(line.split(" fixed)")[0].rsplit("(", 1)[1])
    return -1


with tempfile.TemporaryDirectory() as tmp:
    cases = ("tet",) if SANITIZED else ("tet", "hex", "mixed")
    for case in cases:
        src = meshes.generate(case, "quick", os.path.join(tmp, "cache"),
                              log=lambda *a: None)
        dist = os.path.join(tmp, f"{case}-d.msh")
        c.run("distort", src, "-o", dist, "--seed", "3", "--amount", "0.6", "-q")
        stem = os.path.join(tmp, case)
        write_inputs(dist, stem)
        ref, rep = os.path.join(tmp, f"{case}-ref.msh"), os.path.join(tmp, "r.json")
        p = c.run("smooth", stem + "-whole.msh", "-o", ref, "-v", "--report",
                  rep, env=ENV)
        want_stats = stats_logged(p.stdout + p.stderr)
        want_fixed = json.load(open(rep))["fixed_nodes"]
        want, _ = nodes([ref])
        inputs, _ = nodes([stem + "-whole.msh"])
        moved = sum(want[t] != inputs[t] for t in want)
        c.check(moved > 100, f"{case}: getme smooth moved {moved} nodes")

        ranks = {"mixed": (1, 2, 3, 4), "tet": (3,), "hex": (2,)}[case]
        for np in ranks:
            out = os.path.join(tmp, f"{case}-o{np}")
            # -v: the finishing step's sub-mesh line, the histograms; np 2:
            # element indices ranked on rank 0 as for tags that are not one
            # dense run (the code path; the bits here do not depend on the
            # indices: ties in the finishing step's order are rare)
            p = mpirun(np, "smooth", stem + "_1.msh", "-o", out + ".msh", "-v",
                       env={"GETME_MPI_RANK_TAGS": "1"} if np == 2 else None)
            if np <= N:
                log = p.stdout + p.stderr
                c.check("Finishing step on rank 0 on a sub-mesh of" in log,
                        f"{case} -np {np}: the finishing step ran on a "
                        "sub-mesh (rank 0's log)")
                got_stats = stats_logged(log)
                c.check(got_stats == want_stats and len(want_stats) >= 24,
                        f"{case} -np {np}: quality statistics and measures "
                        f"as getme smooth's: {got_stats} / {want_stats}")
            outs = parts(out)
            if np > N and not os.environ.get("GETME_TEST_GMSH_PLUGIN"):
                # more ranks than parts falls back to rank 0 reading all
                # parts, which needs the Gmsh plugin: without it, one
                # clear error and no output
                errs = [l for l in p.stderr.splitlines()
                        if l.startswith("Error")]
                c.check(p.returncode == 5 and len(errs) == 1 and
                        not any(map(os.path.exists, outs)),
                        f"{case} -np {np} without the Gmsh plugin: exit "
                        f"{p.returncode}, errors {errs}, no output part")
                continue
            ok = p.returncode == 0 and all(map(os.path.exists, outs))
            c.check(ok and not os.path.exists(out + ".msh"),
                    f"{case} split files, -np {np}: exit {p.returncode}, "
                    f"{out}_1..3.msh written, no {out}.msh {p.stderr[-300:]}")
            if not ok:
                continue
            got, np_out = nodes(outs)
            same = sum(got.get(t) == b for t, b in want.items())
            c.check(same == len(want) and len(got) == len(want),
                    f"{case} -np {np}: {same} of {len(want)} nodes have getme "
                    f"smooth's coordinate bits ({len(got)} in the parts)")
            c.check(np_out == N, f"{case} -np {np}: Gmsh opens the output "
                                 f"parts with {np_out} partitions")
            if np <= N:
                c.check(fixed_logged(p.stderr + p.stdout) == want_fixed,
                        f"{case} -np {np}: {fixed_logged(p.stderr + p.stdout)} "
                        f"fixed nodes, getme smooth {want_fixed}")
                c.check(all(os.path.getsize(o) == os.path.getsize(i)
                            for o, i in zip(outs, parts(stem))),
                        f"{case} -np {np}: each output part the size of its "
                        "input part")
        for np in {"mixed": (1, 3), "tet": (2,), "hex": ()}[case]:
            out = os.path.join(tmp, f"{case}-one{np}.msh")
            p = mpirun(np, "smooth", stem + "-one.msh", "-o", out)
            if not os.path.exists(out):
                c.check(False, f"{case} one partitioned file -np {np}: exit "
                               f"{p.returncode} {p.stderr[-300:]}")
                continue
            got, np_out = nodes([out])
            same = sum(got.get(t) == b for t, b in want.items())
            c.check(p.returncode == 0 and same == len(want) and np_out == N and
                    fixed_logged(p.stderr + p.stdout) == want_fixed and
                    os.path.getsize(out) == os.path.getsize(stem + "-one.msh"),
                    f"{case} one file with {N} partitions, -np {np}: {same} of "
                    f"{len(want)} nodes getme smooth's bits, {np_out} "
                    "partitions, fixed nodes and file size kept")

    # Failures: a truncated and a missing part stop every rank.
    stem = os.path.join(tmp, cases[-1])
    bad = os.path.join(tmp, "bad")
    os.mkdir(bad)
    for k, q in enumerate(parts(stem), 1):
        data = open(q, "rb").read()
        open(os.path.join(bad, f"cut_{k}.msh"), "wb").write(
            data[:len(data) // 2] if k == 3 else data)
        if k != 2:
            open(os.path.join(bad, f"miss_{k}.msh"), "wb").write(data)
    for np in (2, 3):
        for name, file, rank, code in (("cut", "cut_3.msh", np - 1, 4),
                                       ("miss", "miss_2.msh", 0 if np == 2 else 1, 3)):
            p = mpirun(np, "smooth", os.path.join(bad, f"{name}_1.msh"), "-o",
                       os.path.join(bad, "o.msh"))
            errors = [l for l in p.stderr.splitlines() if l.startswith("Error")]
            left = [f for f in os.listdir(bad) if f.startswith("o") or "getme-tmp" in f]
            c.check(p.returncode == code and len(errors) == 1 and
                    f"rank {rank} of {np}" in errors[0] and file in errors[0] and
                    not left,
                    f"{name} part, -np {np}: exit {p.returncode} (want {code}), "
                    f"{errors}, left {left}")

    # An output part that is an input part; a stale part of an earlier run.
    before = [open(q, "rb").read() for q in parts(stem)]
    p = mpirun(2, "smooth", stem + "_1.msh", "-o", stem + ".msh")
    c.check(p.returncode == 2 and "input part" in p.stderr and
            [open(q, "rb").read() for q in parts(stem)] == before,
            f"an output over an input part is refused (exit {p.returncode}: "
            f"{p.stderr.strip()[-200:]}), the parts untouched")
    stale = os.path.join(tmp, "st")
    open(stale + "_4.msh", "w").write("old")
    p = mpirun(3, "smooth", stem + "_1.msh", "-o", stale + ".msh")
    c.check(p.returncode == 0 and "st_4.msh" in p.stderr + p.stdout and
            open(stale + "_4.msh").read() == "old",
            f"a stale part of an earlier run is reported and left as it is "
            f"(exit {p.returncode})")

    # A rank failing to write its part: nobody's part is written.  A rank
    # failing to rename: the parts already renamed are named as new.
    wdir = os.path.join(tmp, "w")
    os.mkdir(wdir)
    p = mpirun(3, "smooth", stem + "_1.msh", "-o", os.path.join(wdir, "o.msh"),
               env={"GETME_MPI_FAIL_WRITE": "1"})
    errors = [l for l in p.stderr.splitlines() if l.startswith("Error")]
    c.check(p.returncode == 7 and len(errors) == 1 and "rank 1 of 3" in errors[0]
            and "o_2.msh" in errors[0] and not os.listdir(wdir),
            f"a rank failing to write: exit {p.returncode}, {errors}, nothing "
            f"left ({os.listdir(wdir)})")
    p = mpirun(3, "smooth", stem + "_1.msh", "-o", os.path.join(wdir, "o.msh"),
               env={"GETME_MPI_FAIL_RENAME": "1"})
    errors = [l for l in p.stderr.splitlines() if l.startswith("Error")]
    left = sorted(os.listdir(wdir))
    c.check(p.returncode == 7 and len(errors) == 1 and
            errors[0].endswith("new parts: " + " ".join(
                os.path.join(wdir, f"o_{k}.msh") for k in (1, 3)) +
                "; the others are as before") and left == ["o_1.msh", "o_3.msh"],
            f"a rank failing to rename: exit {p.returncode}, {errors}, left {left}")

sys.exit(c.summary())
