#!/usr/bin/python3
"""A Gmsh-partitioned MSH file (one file with partition entities, as
`gmsh -part N` writes it) smooths like the unpartitioned mesh (ctest
label mpi).

usage: test_mpi_partitioned.py GETME_MPI GETME MPIEXEC SOURCE_DIR [--sanitized]

The distorted mixed "quick" mesh (4 physical volumes) is written by Gmsh
unpartitioned and partitioned into 3 (one file).  The partition boundaries
are not fixed: the same number of fixed nodes as the unpartitioned mesh
(--report); `getme smooth` on both gives the same coordinates bit for bit
(the Gmsh SDK adapter, which reads the partitioned file, writes MSH 4.1 by
patching the input's $Nodes with round-trip numbers, not through Gmsh's
%.16g writer);
`mpirun -np 2 getme-mpi smooth` on the partitioned file (each rank
reading its own partitions natively, docs/distributed.md §3) writes the
unpartitioned output's coordinates bit for bit (no rounding to Gmsh's 16
digits: the native writer copies the file with only the coordinates
changed), and Gmsh reopens both outputs with their 3 partitions.
"""
import json
import os
import subprocess
import sys
import tempfile

import meshes
from mpi_checks import GETME_MPI, MPIEXEC, ENV, c
import gmsh


def nodes(path):
    """{tag: (x, y, z)} and the number of partitions of an MSH file."""
    gmsh.initialize(["test"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(path)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        return ({int(t): tuple(xyz[3 * i:3 * i + 3]) for i, t in enumerate(tags)},
                max((max(gmsh.model.getPartitions(d, t), default=0)
                     for d, t in gmsh.model.getEntities()), default=0))
    finally:
        gmsh.finalize()


with tempfile.TemporaryDirectory() as tmp:
    dist = os.path.join(tmp, "distorted.msh")
    c.run("distort", meshes.generate("mixed", "quick", os.path.join(tmp, "cache"),
                                     log=lambda *a: None),
          "-o", dist, "--seed", "3", "--amount", "0.6", "-q")
    whole, parts = os.path.join(tmp, "whole.msh"), os.path.join(tmp, "parts.msh")
    gmsh.initialize(["test"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(dist)
    gmsh.write(whole)
    gmsh.model.mesh.partition(3)
    gmsh.write(parts)
    gmsh.finalize()

    fixed, out = {}, {}
    for name, path in (("whole", whole), ("parts", parts)):
        out[name] = os.path.join(tmp, f"{name}-out.msh")
        rep = os.path.join(tmp, f"{name}.json")
        c.run("smooth", path, "-o", out[name], "-q", "--report", rep, env=ENV)
        fixed[name] = json.load(open(rep))["fixed_nodes"] if os.path.exists(rep) else -1
    c.check(fixed["whole"] > 0 and fixed["whole"] == fixed["parts"],
            f"fixed nodes: {fixed['parts']} partitioned, {fixed['whole']} whole "
            "(partition boundaries are not fixed)")
    a, _ = nodes(out["whole"])
    b, np_out = nodes(out["parts"])
    same = sum(a[t] == b.get(t) for t in a)
    c.check(a and same == len(a),
            f"{same} of {len(a)} nodes: the unpartitioned result bit for bit")
    mpi_out = os.path.join(tmp, "parts-mpi.msh")
    p = subprocess.run([MPIEXEC, "--oversubscribe", "-np", "2", GETME_MPI, "smooth",
                        parts, "-o", mpi_out, "-q"], capture_output=True, text=True,
                       env=ENV)
    c.check(p.returncode == 0, f"getme-mpi -np 2: exit {p.returncode}: {p.stderr[-400:]}")
    m, np_mpi = nodes(mpi_out) if os.path.exists(mpi_out) else ({}, 0)
    same = sum(m.get(t) == a[t] for t in a)
    c.check(a and same == len(a) and len(m) == len(a),
            f"getme-mpi -np 2 on the partitioned file: {same} of {len(a)} "
            "nodes the unpartitioned result bit for bit")
    c.check(np_out == 3 and np_mpi == 3,
            f"Gmsh reopens the outputs with 3 partitions ({np_out}, {np_mpi})")

sys.exit(c.summary())
