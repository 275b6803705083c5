#!/usr/bin/python3
"""getme-mpi against getme smooth (ctest label mpi).

usage: test_mpi.py GETME_MPI GETME MPIEXEC SOURCE_DIR [--sanitized]

On distorted tet, hex and mixed meshes (bench/meshes.py's "quick" sizes,
distorted by `getme distort`): `mpirun -np 1..4 getme-mpi smooth` writes
the same bytes as `getme smooth` with 1 and 2 threads (tets: 1, 2, 3 and
4 ranks, 2 ranks also with 2 threads each; hexes and mixed: 1 and 3); fixed nodes keep
their input coordinates bit for bit; the output is valid (getme quality).
A rank that fails to read its part (GETME_MPI_FAIL_RANK) stops every rank
with one error line and leaves no output.  The finishing step runs on a
sub-mesh (-v says so); started too small (GETME_MPI_FINISH_FIRST=1) it
grows and the bytes stay the same; so with --param renumber=0.

--sanitized (the ASan+UBSan build): tets only, and LeakSanitizer off in
the MPI ranks (Open MPI's own start-up allocations are never freed);
address and undefined-behaviour checks stay on.
"""
import os
import struct
import subprocess
import sys
import tempfile

import meshes
from mpi_checks import GETME_MPI, MPIEXEC, SANITIZED, ENV, c, why


def mpirun(np, *args, env=ENV):
    return subprocess.run([MPIEXEC, "--oversubscribe", "-np", str(np), GETME_MPI,
                           *args], capture_output=True, text=True, env=env)


def nodes(path):
    """{tag: (x, y, z)} of an MSH file, read with Gmsh."""
    import gmsh
    gmsh.initialize(["test"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(path)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        return {int(t): tuple(xyz[3 * i:3 * i + 3]) for i, t in enumerate(tags)}
    finally:
        gmsh.finalize()


def bits(p):
    return struct.pack("<3d", *p)


with tempfile.TemporaryDirectory() as tmp:
    cache = os.path.join(tmp, "cache")
    for case in ("tet",) if SANITIZED else ("tet", "hex", "mixed"):
        src = meshes.generate(case, "quick", cache, log=lambda *a: None)
        inp = os.path.join(tmp, f"{case}-distorted.msh")
        c.run("distort", src, "-o", inp, "--seed", "3", "--amount", "0.6", "-q")
        ref = os.path.join(tmp, f"{case}-ref.msh")
        c.run("smooth", inp, "-o", ref, "--threads", "1", "-q", env=ENV)
        ref_bytes = open(ref, "rb").read()
        out2 = os.path.join(tmp, f"{case}-t2.msh")
        c.run("smooth", inp, "-o", out2, "--threads", "2", "-q", env=ENV)
        c.check(open(out2, "rb").read() == ref_bytes,
                f"{case}: getme smooth, 1 and 2 threads, same bytes")
        # every rank count on tets; 1 (no split) and 3 (ranks with several
        # neighbours) on the others, to keep the test short
        for np in ((1, 2, 3, 4) if case == "tet" else (1, 3)):
            for threads in ((1, 2) if np == 2 else (1,)):
                out = os.path.join(tmp, f"{case}-np{np}-t{threads}.msh")
                p = mpirun(np, "smooth", inp, "-o", out, "--threads",
                           str(threads), "-v")
                c.check(p.returncode == 0,
                        f"{case}: -np {np}: exit {p.returncode}: {why(p)}")
                same = os.path.exists(out) and open(out, "rb").read() == ref_bytes
                c.check(same, f"{case}: -np {np} --threads {threads}: the same "
                              f"bytes as getme smooth")
                if np == 3 and threads == 1:
                    c.check("comm" in p.stdout and "KiB" in p.stdout,
                            f"{case}: -v logs the communication per iteration")
                    c.check("on a sub-mesh of" in p.stdout,
                            f"{case}: the finishing step runs on a sub-mesh: "
                            f"{p.stdout[-600:]}")
        # the finishing step's sub-mesh too small at first (1 candidate):
        # it grows until exact, and the bytes stay getme smooth's
        out = os.path.join(tmp, f"{case}-grow.msh")
        p = mpirun(3, "smooth", inp, "-o", out, "-v",
                   env=dict(ENV, GETME_MPI_FINISH_FIRST="1"))
        c.check(p.returncode == 0 and "tries)" in p.stdout,
                f"{case}: a 1-candidate sub-mesh grows: {p.stdout[-600:]}")
        c.check(os.path.exists(out) and open(out, "rb").read() == ref_bytes,
                f"{case}: grown sub-mesh, the same bytes as getme smooth")
        # renumber=0: the finishing step's element keys carry no Morton code
        ref0 = os.path.join(tmp, f"{case}-ref-r0.msh")
        c.run("smooth", inp, "-o", ref0, "--param", "renumber=0", "-q", env=ENV)
        out = os.path.join(tmp, f"{case}-r0.msh")
        p = mpirun(3, "smooth", inp, "-o", out, "--param", "renumber=0")
        c.check(p.returncode == 0 and os.path.exists(out) and
                open(out, "rb").read() == open(ref0, "rb").read(),
                f"{case}: renumber=0, the same bytes as getme smooth")
        # fixed nodes bit for bit, output valid
        before, after = nodes(inp), nodes(ref)
        c.run("quality", ref, "-q")  # exit 6 if an element is invalid
        moved = sum(bits(before[t]) != bits(after[t]) for t in before)
        c.check(moved > 0, f"{case}: some nodes moved")
        # the skin is fixed: nodes on boundary faces, as getme smooth fixes
        # them, are unchanged (checked through the boundary of the volume)
        import gmsh
        gmsh.initialize(["test"])
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.open(inp)
            skin = set()
            for dim, tag in gmsh.model.getEntities(2):
                skin.update(int(t) for t in gmsh.model.mesh.getNodes(dim, tag, True)[0])
        finally:
            gmsh.finalize()
        fixed = sum(bits(before[t]) == bits(after[t]) for t in skin)
        c.check(skin and fixed == len(skin),
                f"{case}: {fixed} of {len(skin)} surface nodes bit-identical")

    # failure: rank 2 cannot read its part -> one error, no output
    inp = os.path.join(tmp, "tet-distorted.msh")
    out = os.path.join(tmp, "fail.msh")
    env = dict(ENV, GETME_MPI_FAIL_RANK="2")
    p = mpirun(3, "smooth", inp, "-o", out, env=env)
    errors = [line for line in p.stderr.splitlines() if line.startswith("Error")]
    c.check(p.returncode != 0, f"failure: exit {p.returncode}, want nonzero")
    c.check(len(errors) == 1 and "rank 2" in errors[0] and "part" in errors[0],
            f"failure: one error naming rank 2: {p.stderr[-400:]}")
    c.check(not os.path.exists(out), "failure: no output")
    c.check(not [f for f in os.listdir(tmp) if "getme-tmp" in f],
            "failure: no temporary file left")
    # out of memory inside the loop on one rank (the q*_min threshold's
    # histogram, failed by an LD_PRELOAD shim): every rank stops with one
    # error, none waits for the one that gave up (timeout: a hang fails)
    shim = os.environ.get("GETME_TEST_FAIL_ALLOC")
    if shim:
        env = dict(ENV, LD_PRELOAD=shim, GETME_TEST_FAIL_HIST_RANK="1")
        try:
            p = subprocess.run([MPIEXEC, "--oversubscribe", "-x", "LD_PRELOAD",
                                "-x", "GETME_TEST_FAIL_HIST_RANK", "-np", "3",
                                GETME_MPI, "smooth", inp, "-o", out],
                               capture_output=True, text=True, env=env,
                               timeout=120)
            errors = [l for l in p.stderr.splitlines() if l.startswith("Error")]
            # (every rank stops with GETME_ERR_NOMEM: the lowest is named)
            c.check(p.returncode == 1 and len(errors) == 1 and
                    "smoothing: out of memory" in errors[0] and
                    not os.path.exists(out),
                    f"out of memory in the loop on rank 1: exit {p.returncode},"
                    f" {errors}, no output")
        except subprocess.TimeoutExpired:
            c.check(False, "out of memory in the loop on rank 1: the other "
                           "ranks wait (timeout)")
    # an unreadable input: rank 0's one error, no output
    p = mpirun(2, "smooth", os.path.join(tmp, "missing.msh"), "-o", out)
    errors = [line for line in p.stderr.splitlines() if line.startswith("Error")]
    c.check(p.returncode == 3 and len(errors) == 1,
            f"missing input: exit {p.returncode} (want 3), {len(errors)} errors")
    c.check(not os.path.exists(out), "missing input: no output")

sys.exit(c.summary())
