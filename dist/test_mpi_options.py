#!/usr/bin/python3
"""getme-mpi smooth takes getme smooth's options (ctest label mpi).

usage: test_mpi_options.py GETME_MPI GETME MPIEXEC SOURCE_DIR [--sanitized]

On bench/meshes.py's "quick" meshes (distorted by `getme distort`), each
option changes the result (the output differs from the default run) and
`mpirun -np 2|3 getme-mpi smooth` with it writes the same bytes as
`getme smooth` with it: --free-interfaces with --param and --max-iter,
--fix DIM:TAG (its nodes keep their input coordinates bit for bit).
--report writes the same JSON as getme smooth's but for timings and the
output's name; --worst N with -v lists N elements; --help answers; a bad
option or --method laplace is one error, exit 2; an inverted element is
refused with --no-untangle (exit 6, no output) and untangled by default to
getme smooth's bytes; one that cannot be untangled exits 8, no output, or
getme smooth's partly untangled bytes with --allow-invalid; a planar mesh is refused (exit 5, no output).
"""
import json
import os
import struct
import subprocess
import sys
import tempfile

import meshes
from mpi_checks import GETME_MPI, MPIEXEC, ENV, c


def mpirun(np, *args):
    return subprocess.run([MPIEXEC, "--oversubscribe", "-np", str(np), GETME_MPI,
                           *args], capture_output=True, text=True, env=ENV)


def data(path):
    return open(path, "rb").read() if os.path.exists(path) else None


def errors(p):
    return [ln for ln in p.stderr.splitlines() if ln.startswith("Error")]


def gmsh_nodes(path, dim=-1, tag=-1):
    """{tag: coordinate bits} of the nodes of an MSH file (of one physical
    group if dim, tag are given), read with Gmsh."""
    import gmsh
    gmsh.initialize(["test"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(path)
        if dim >= 0:
            tags, xyz = gmsh.model.mesh.getNodesForPhysicalGroup(dim, tag)
        else:
            tags, xyz, _ = gmsh.model.mesh.getNodes()
        return {int(t): struct.pack("<3d", *xyz[3 * i:3 * i + 3])
                for i, t in enumerate(tags)}
    finally:
        gmsh.finalize()


def same_as_smooth(tmp, name, inp, np, opts, default=None):
    """getme smooth and getme-mpi -np np with opts: same bytes; different
    from default (bytes of the default run) if given.  The reference."""
    ref = os.path.join(tmp, f"{name}-ref.msh")
    c.run("smooth", inp, "-o", ref, "--threads", "1", "-q", *opts, env=ENV)
    out = os.path.join(tmp, f"{name}-np{np}.msh")
    p = mpirun(np, "smooth", inp, "-o", out, "-q", *opts)
    c.check(p.returncode == 0, f"{name}: -np {np}: exit {p.returncode}: "
                               f"{p.stderr[-400:]}")
    c.check(data(out) is not None and data(out) == data(ref),
            f"{name}: -np {np} {' '.join(opts)}: the same bytes as getme smooth")
    if default is not None:
        c.check(data(ref) != default, f"{name}: {' '.join(opts)} changes the result")
    return ref


with tempfile.TemporaryDirectory() as tmp:
    cache = os.path.join(tmp, "cache")
    # --help, usage errors: one error line (rank 0's), exit 2
    p = subprocess.run([GETME_MPI, "--help"], capture_output=True, text=True, env=ENV)
    c.check(p.returncode == 0 and "--fix NAME" in p.stdout and "--report" in p.stdout
            and "finish_fraction" in p.stdout and "planar" in p.stdout,
            f"--help: exit {p.returncode}, options and parameter table")
    mixed = os.path.join(tmp, "mixed.msh")
    c.run("distort", meshes.generate("mixed", "quick", cache, log=lambda *a: None),
          "-o", mixed, "--seed", "3", "--amount", "0.6", "-q")
    out = os.path.join(tmp, "usage.msh")
    for bad, what in ((["--bogus"], "unknown option"), (["--method", "laplace"], "laplace"),
                      (["--param", "nosuch=1"], "unknown parameter")):
        p = mpirun(2, "smooth", mixed, "-o", out, *bad)
        c.check(p.returncode == 2 and len(errors(p)) == 1 and what in errors(p)[0],
                f"{' '.join(bad)}: exit {p.returncode} (want 2), errors {errors(p)}")
        c.check(not os.path.exists(out), f"{' '.join(bad)}: no output")

    # options change the result and getme-mpi follows getme smooth
    default = data(same_as_smooth(tmp, "mixed-default", mixed, 2, []))
    same_as_smooth(tmp, "mixed-free", mixed, 3,
                   ["--free-interfaces", "--param", "finish_fraction=0.02",
                    "--max-iter", "40"], default)
    fixed_ref = same_as_smooth(tmp, "mixed-fix", mixed, 2, ["--fix", "3:1"], default)
    group, after = gmsh_nodes(mixed, 3, 1), gmsh_nodes(fixed_ref)
    kept = sum(after[t] == b for t, b in group.items())
    c.check(group and kept == len(group),
            f"--fix 3:1: {kept} of {len(group)} nodes of the group bit-identical")

    # --report: getme smooth's JSON but for timings and the output name
    reports = []
    for tool in ("smooth", "mpi"):
        rep = os.path.join(tmp, f"report-{tool}.json")
        o = os.path.join(tmp, f"report-{tool}.msh")
        args = ["smooth", mixed, "-o", o, "--report", rep, "--worst", "2", "-v"]
        if tool == "smooth":
            p = c.run(*args, "--threads", "1", env=ENV)
        else:
            p = mpirun(3, *args)
            c.check(p.returncode == 0, f"--report: exit {p.returncode}")
            c.check("Worst 2 elements" in p.stdout and "comm" in p.stdout,
                    "-v --worst 2: the worst elements and the communication")
        r = json.load(open(rep)) if os.path.exists(rep) else {}
        for k in ("seconds", "output"):
            r.pop(k, None)
        for h in r.get("history", []):
            h.pop("elapsed", None)
        r.get("untangle", {}).pop("seconds", None)
        reports.append(r)
    c.check(reports[0] and reports[0] == reports[1] and len(reports[1]["worst_elements"]) == 2,
            "--report: the same JSON as getme smooth's (timings aside)")

    # an inverted element: two nodes of one tet swapped (MSH 2.2); with the
    # one a third into the list untangling succeeds, with the one in the
    # middle it does not (exit 8)
    import gmsh

    def inverted(src, name, k):
        gmsh.initialize(["test"])
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(src)
        gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
        gmsh.write(os.path.join(tmp, name + ".v2.msh"))
        gmsh.finalize()
        lines = open(os.path.join(tmp, name + ".v2.msh")).read().split("\n")
        start = lines.index("$Elements") + 2
        tets = [i for i in range(start, len(lines)) if lines[i].split()[1:2] == ["4"]]
        victim = lines[tets[len(tets) // k]].split()
        victim[-1], victim[-2] = victim[-2], victim[-1]
        lines[tets[len(tets) // k]] = " ".join(victim)
        path = os.path.join(tmp, name + ".msh")
        open(path, "w").write("\n".join(lines))
        return path, victim[0]

    clean = meshes.generate("tet", "quick", cache, log=lambda *a: None)
    inv, tag = inverted(clean, "inverted", 3)
    out = os.path.join(tmp, "inverted-out.msh")
    p = mpirun(2, "smooth", inv, "-o", out, "--no-untangle")
    c.check(p.returncode == 6 and len(errors(p)) == 1 and tag in errors(p)[0],
            f"--no-untangle: exit {p.returncode} (want 6), the element named: {errors(p)}")
    c.check(not os.path.exists(out), "--no-untangle: no output")
    ref = os.path.join(tmp, "inverted-ref.msh")
    c.run("smooth", inv, "-o", ref, "--threads", "1", "-q", env=ENV)
    p = mpirun(2, "smooth", inv, "-o", out)
    c.check(p.returncode == 0 and "Warning : 1 invalid (inverted or degenerate) "
            "element in the input, 0 remain" in p.stdout, f"untangled: exit {p.returncode}")
    c.check(data(out) is not None and data(out) == data(ref),
            "untangled and smoothed: the same bytes as getme smooth")
    stuck, tag = inverted(clean, "stuck", 2)
    out = os.path.join(tmp, "stuck-out.msh")
    p = mpirun(2, "smooth", stuck, "-o", out)
    c.check(p.returncode == 8 and len(errors(p)) == 1 and tag in errors(p)[0],
            f"not untangled: exit {p.returncode} (want 8), named: {errors(p)}")
    c.check(not os.path.exists(out), "not untangled: no output")
    ref = os.path.join(tmp, "stuck-ref.msh")
    c.run("smooth", stuck, "-o", ref, "-q", "--allow-invalid", expect=8, env=ENV)
    p = mpirun(2, "smooth", stuck, "-o", out, "-q", "--allow-invalid")
    c.check(p.returncode == 8 and data(out) is not None and data(out) == data(ref),
            f"--allow-invalid: exit {p.returncode} (want 8), getme smooth's partly "
            "untangled bytes")

    # planar: refused with a reason
    quad = meshes.generate("quad", "quick", cache, log=lambda *a: None)
    out = os.path.join(tmp, "quad-out.msh")
    p = mpirun(2, "smooth", quad, "-o", out)
    c.check(p.returncode == 5 and len(errors(p)) == 1 and "planar" in errors(p)[0],
            f"planar: exit {p.returncode} (want 5): {errors(p)}")
    c.check(not os.path.exists(out), "planar: no output")

sys.exit(c.summary())
