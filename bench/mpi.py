#!/usr/bin/python3
"""Distributed GETMe adaptive: getme-mpi on 1, 2, 4 ranks against the
threaded getme smooth (docs/distributed.md, "Benchmark").

usage: bench/mpi.py MESH [MESH...] --mpi GETME_MPI --getme GETME
                    [--ranks 1,2,4] [--out FILE.md] [--split N]

Per mesh and rank count: the smoothing loop's wall time (rank 0's
clock, the slowest rank sets it), time inside the communication hooks
(includes waiting for slower ranks), bytes sent to neighbours and
reduced globally per iteration, the interface (shared node copies) and
the max RSS per rank; and the threaded run with as many threads as
ranks (equal core count).  Also checks that every output has the same
bytes as getme smooth's.  This machine has 2 cores: runs with more ranks
than cores are oversubscribed, so their times show overhead, not speed-up.

--split N (issue #14, per-rank input): Gmsh partitions each mesh into N
split files (binary MSH 4.1, NAME_1..N.msh, written once, timed apart);
per rank count, getme-mpi reading the whole file on rank 0 (METIS split)
against every rank reading its own split files: the whole command's wall
time, the set-up / loop split and the peak RSS of every rank over the
whole run (reading and writing included); and whether the output parts,
joined by node tag, hold the rank-0 run's coordinates bit for bit.
--before EXE adds, per rank count, an older getme-mpi on the same split
files (before/after of the per-rank input's finishing step).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

RANK = re.compile(r"Rank (\d+): (\d+) elements \((\d+) owned\), (\d+) nodes "
                  r"\((\d+) shared copies\), loop ([\d.]+) s, comm ([\d.]+) s, "
                  r"sent ([\d.]+) MiB, reduced ([\d.]+) MiB, max RSS ([\d.]+) MiB")
ITERS = re.compile(r"GETMe adaptive: (\d+) iterations")
SPLIT = re.compile(r"(\d+) interface nodes, (\d+) ghost elements")


def run_mpi(exe, mesh, ranks, out):
    env = dict(os.environ, OMP_WAIT_POLICY="passive", OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    p = subprocess.run(["mpirun", "--oversubscribe", "-np", str(ranks), exe, "smooth",
                        mesh, "-o", out, "-v"], capture_output=True, text=True, env=env)
    if p.returncode:
        sys.exit(f"getme-mpi failed: {p.stderr}")
    rows = [tuple(float(x) for x in m.groups()) for m in RANK.finditer(p.stdout)]
    it = int(ITERS.search(p.stdout).group(1))
    sp = SPLIT.search(p.stdout)
    return rows, it, (int(sp.group(1)), int(sp.group(2)))


PEAK = re.compile(r"Peak RSS per rank \(whole run\): ([\d./]+) MiB")
LOOP = re.compile(r"GETMe adaptive: .* in ([\d.]+) s on")


def run_whole(exe, mesh, ranks, out):
    """Wall seconds, loop seconds, peak RSS per rank of one getme-mpi run."""
    import time
    env = dict(os.environ, OMP_WAIT_POLICY="passive", OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    t0 = time.time()
    p = subprocess.run(["mpirun", "--oversubscribe", "-np", str(ranks), exe, "smooth",
                        mesh, "-o", out, "-v"], capture_output=True, text=True, env=env)
    wall = time.time() - t0
    if p.returncode:
        sys.exit(f"getme-mpi failed: {p.stderr}")
    return (wall, float(LOOP.search(p.stdout).group(1)),
            [float(x) for x in PEAK.search(p.stdout).group(1).split("/")])


def node_bits(paths):
    """{tag: the 24 bytes of its coordinates} of the MSH files opened
    together (the test suite's reader, so both compare the same way)."""
    import struct
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                    "..", "tests", "support"))
    from gmsh_helpers import merged_nodes
    return {t: struct.pack("<3d", *x) for t, x in merged_nodes(paths)[0].items()}


def split_bench(a, lines):
    """Rank-0 reading against per-rank reading of N split files."""
    import time
    import gmsh
    nparts = a.split
    lines += ["", f"Per-rank input ({nparts} Gmsh split files) against rank 0 "
              "reading the whole file:", "",
              "| mesh | ranks | input | wall s | loop s | peak RSS MiB per rank | "
              "same coordinates |", "|---|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in a.meshes:
            name = os.path.basename(mesh).split("-g")[0]
            stem = os.path.join(tmp, name)
            t0 = time.time()
            gmsh.initialize(["bench"])
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.option.setNumber("Mesh.Binary", 1)
            gmsh.open(mesh)
            gmsh.write(stem + "-whole.msh")
            gmsh.option.setNumber("Mesh.PartitionCreateTopology",
                                  0 if name.startswith("hex") else 1)
            gmsh.model.mesh.partition(nparts)
            gmsh.option.setNumber("Mesh.PartitionSplitMeshFiles", 1)
            gmsh.write(stem + ".msh")
            gmsh.finalize()
            print(f"{name}: Gmsh wrote {nparts} split files in "
                  f"{time.time() - t0:.1f} s", flush=True)
            for ranks in (int(r) for r in a.ranks.split(",")):
                ref = os.path.join(tmp, "r.msh")
                w, lp, rss = run_whole(a.mpi, stem + "-whole.msh", ranks, ref)
                lines.append(f"| {name} | {ranks} | whole file, rank 0 | {w:.1f} | "
                             f"{lp:.1f} | {'/'.join(f'{x:.0f}' for x in rss)} | |")
                print(lines[-1], flush=True)
                want = node_bits([ref])
                runs = [("", a.mpi)] + ([(" (before)", a.before)] if a.before
                                        else [])
                for label, exe in runs:
                    out = os.path.join(tmp, "o")
                    w, lp, rss = run_whole(exe, stem + "_1.msh", ranks,
                                           out + ".msh")
                    got = node_bits([f"{out}_{k}.msh"
                                     for k in range(1, nparts + 1)])
                    same = len(got) == len(want) and all(
                        got.get(t) == b for t, b in want.items())
                    lines.append(f"| {name} | {ranks} | {nparts} split files, "
                                 f"per rank{label} | {w:.1f} | {lp:.1f} | "
                                 f"{'/'.join(f'{x:.0f}' for x in rss)} | "
                                 f"{'yes' if same else 'NO'} |")
                    print(lines[-1], flush=True)


def run_threads(exe, mesh, threads, out, rep):
    env = dict(os.environ, OMP_WAIT_POLICY="passive")
    t = subprocess.run(["/usr/bin/time", "-f", "%M", exe, "smooth", mesh, "-o", out,
                        "--threads", str(threads), "--report", rep, "-q"],
                       capture_output=True, text=True, env=env)
    if t.returncode:
        sys.exit(f"getme failed: {t.stderr}")
    r = json.load(open(rep))
    return r["seconds"], r["iterations"]["total"], int(t.stderr.split()[-1]) / 1024.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--mpi", required=True)
    ap.add_argument("--getme", required=True)
    ap.add_argument("--ranks", default="1,2,4")
    ap.add_argument("--out")
    ap.add_argument("--split", type=int, default=0)
    ap.add_argument("--before", default="")
    a = ap.parse_args()
    if a.split:
        lines = []
        split_bench(a, lines)
        if a.out:
            with open(a.out, "w") as f:
                f.write("\n".join(lines) + "\n")
        return
    lines = ["| mesh | run | loop s | comm s (max) | KiB/iter sent (sum) | "
             "KiB/iter reduced (per rank) | shared copies (sum) | max RSS MiB "
             "per rank | same bytes |", "|---|---|---|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in a.meshes:
            name = os.path.basename(mesh).split("-g")[0]
            ext = os.path.splitext(mesh)[1]
            ref = os.path.join(tmp, "ref" + ext)
            for threads in sorted({int(r) for r in a.ranks.split(",")} | {1}):
                out = ref if threads == 1 else os.path.join(tmp, "t" + ext)
                s, it, rss = run_threads(a.getme, mesh, threads, out,
                                         os.path.join(tmp, "r.json"))
                same = open(out, "rb").read() == open(ref, "rb").read()
                lines.append(f"| {name} | getme smooth, {threads} thread(s) | {s:.2f} | | "
                             f"| | | {rss:.0f} | {'yes' if same else 'NO'} |")
                print(lines[-1], flush=True)
            for ranks in (int(r) for r in a.ranks.split(",")):
                out = os.path.join(tmp, "m" + ext)
                rows, it, (iface, ghosts) = run_mpi(a.mpi, mesh, ranks, out)
                same = open(out, "rb").read() == open(ref, "rb").read()
                loop = max(r[5] for r in rows)
                comm = max(r[6] for r in rows)
                sent = sum(r[7] for r in rows) * 1024 / it
                red = rows[0][8] * 1024 / it
                shared = sum(r[4] for r in rows)
                rss = "/".join(f"{r[9]:.0f}" for r in rows)
                lines.append(f"| {name} | getme-mpi, {ranks} rank(s) | {loop:.2f} | "
                             f"{comm:.2f} | {sent:.1f} | {red:.1f} | {shared:.0f} | "
                             f"{rss} | {'yes' if same else 'NO'} |")
                print(lines[-1], flush=True)
    if a.out:
        with open(a.out, "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
