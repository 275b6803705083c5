#!/usr/bin/python3
"""Gmsh split partition files (Mesh.PartitionSplitMeshFiles=1: NAME_1.msh
.. NAME_N.msh) are read as one mesh and written as split files (ctest
label mpi).

usage: test_mpi_split.py GETME_MPI GETME MPIEXEC SOURCE_DIR [--sanitized]

The distorted mixed "quick" mesh is written by Gmsh unpartitioned and as 3
split files.  `getme smooth name_1.msh -o s.msh` merges name_2.msh and
name_3.msh, fixes the same nodes as the unpartitioned mesh (partition
boundaries are not fixed) and writes s_1.msh .. s_3.msh (no s.msh), whose
nodes, joined by tag, are the unpartitioned output's coordinates to the
16 digits Gmsh's writer prints; `mpirun -np 2 getme-mpi smooth` (each
rank reading its own parts natively, docs/distributed.md §3) writes parts
holding the unpartitioned output's coordinates bit for bit; an output that
would overwrite an input part is refused.
"""
import json
import os
import subprocess
import sys
import tempfile

import meshes
from mpi_checks import GETME_MPI, GETME, MPIEXEC, ENV, c
import gmsh
from gmsh_helpers import merged_nodes as nodes
N = 3


def parts(stem):
    return [f"{stem}_{k}.msh" for k in range(1, N + 1)]


with tempfile.TemporaryDirectory() as tmp:
    dist = os.path.join(tmp, "distorted.msh")
    c.run("distort", meshes.generate("mixed", "quick", os.path.join(tmp, "cache"),
                                     log=lambda *a: None),
          "-o", dist, "--seed", "3", "--amount", "0.6", "-q")
    whole, name = os.path.join(tmp, "whole.msh"), os.path.join(tmp, "name")
    gmsh.initialize(["test"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(dist)
    gmsh.write(whole)
    gmsh.model.mesh.partition(N)
    gmsh.option.setNumber("Mesh.PartitionSplitMeshFiles", 1)
    gmsh.write(name + ".msh")
    gmsh.finalize()
    c.check(all(os.path.exists(p) for p in parts(name)) and
            not os.path.exists(name + "_4.msh"), "Gmsh wrote 3 split files")

    fixed = {}
    for key, path, out in (("whole", whole, os.path.join(tmp, "w.msh")),
                           ("split", name + "_1.msh", os.path.join(tmp, "s.msh"))):
        rep = os.path.join(tmp, f"{key}.json")
        c.run("smooth", path, "-o", out, "-q", "--report", rep, env=ENV)
        fixed[key] = json.load(open(rep))["fixed_nodes"] if os.path.exists(rep) else -1
    c.check(fixed["whole"] > 0 and fixed["whole"] == fixed["split"],
            f"fixed nodes: {fixed['split']} split, {fixed['whole']} whole "
            "(partition boundaries are not fixed)")
    s_parts = parts(os.path.join(tmp, "s"))
    c.check(all(os.path.exists(p) for p in s_parts) and
            not os.path.exists(os.path.join(tmp, "s.msh")) and
            not os.path.exists(os.path.join(tmp, "s_4.msh")),
            "getme smooth wrote s_1.msh .. s_3.msh and no s.msh")
    if all(os.path.exists(p) for p in s_parts):
        a, _ = nodes([os.path.join(tmp, "w.msh")])
        b, np_out = nodes(s_parts)
        same = sum(tuple(float("%.16g" % v) for v in a[t]) == b.get(t) for t in a)
        c.check(a and same == len(a) and len(b) == len(a),
                f"{same} of {len(a)} nodes ({len(b)} in the parts): the "
                "unpartitioned result to 16 digits")
        c.check(np_out == N, f"Gmsh opens the parts with {np_out} partitions")
        w, _ = nodes([whole])
        moved = sum(a[t] != w[t] for t in a)
        c.check(moved > 0, f"{moved} nodes moved")

    m = os.path.join(tmp, "m.msh")
    p = subprocess.run([MPIEXEC, "--oversubscribe", "-np", "2", GETME_MPI, "smooth",
                        name + "_1.msh", "-o", m, "-q"], capture_output=True,
                       text=True, env=ENV)
    c.check(p.returncode == 0, f"getme-mpi -np 2: exit {p.returncode}: {p.stderr[-400:]}")
    m_parts = parts(os.path.join(tmp, "m"))
    if all(os.path.exists(q) for q in m_parts):
        a, _ = nodes([os.path.join(tmp, "w.msh")])
        m, np_m = nodes(m_parts)
        same = sum(m.get(t) == a[t] for t in a)
        c.check(a and same == len(a) and len(m) == len(a) and np_m == N,
                f"getme-mpi -np 2 on the split files: {same} of {len(a)} nodes "
                f"the unpartitioned result bit for bit, {np_m} partitions")
    else:
        c.check(False, "getme-mpi -np 2 wrote m_1.msh .. m_3.msh")

    # -o name.msh would write name_1.msh: the input's first part.
    before = [open(q, "rb").read() for q in parts(name)]
    p = subprocess.run([GETME, "smooth", name + "_1.msh", "-o", name + ".msh", "-q"],
                       capture_output=True, text=True, env=ENV)
    c.check(p.returncode != 0 and "input part" in p.stderr and
            [open(q, "rb").read() for q in parts(name)] == before,
            f"an output over an input part is refused (exit {p.returncode}: "
            f"{p.stderr.strip()[-200:]}), the parts are untouched")

    # A truncated part: one clear error naming it, no output part written.
    cut = os.path.join(tmp, "cut")
    for k, q in enumerate(parts(name), 1):
        data = open(q, "rb").read()
        open(f"{cut}_{k}.msh", "wb").write(data[:len(data) // 2] if k == 3 else data)
    p = subprocess.run([MPIEXEC, "--oversubscribe", "-np", "2", GETME_MPI, "smooth",
                        cut + "_1.msh", "-o", os.path.join(tmp, "t.msh"), "-q"],
                       capture_output=True, text=True, env=ENV)
    c.check(p.returncode != 0 and "cut_3.msh" in p.stderr and "truncated" in p.stderr
            and not any(os.path.exists(os.path.join(tmp, f"t_{k}.msh"))
                        for k in range(1, N + 1)),
            f"a truncated part is refused (exit {p.returncode}: "
            f"{p.stderr.strip()[:200]}), no output")

sys.exit(c.summary())
