#!/usr/bin/python3
"""Distributed GETMe adaptive: getme-mpi on 1, 2, 4 ranks against the
threaded getme smooth (docs/distributed.md, "Benchmark").

usage: bench/mpi.py MESH [MESH...] --mpi GETME_MPI --getme GETME
                    [--ranks 1,2,4] [--out FILE.md]

Per mesh and rank count: the smoothing loop's wall time (rank 0's
clock, the slowest rank sets it), time inside the communication hooks
(includes waiting for slower ranks), bytes sent to neighbours and
reduced globally per iteration, the interface (shared node copies) and
the max RSS per rank; and the threaded run with as many threads as
ranks (equal core count).  Also checks that every output has the same
bytes as getme smooth's.  This machine has 2 cores: runs with more ranks
than cores are oversubscribed, so their times show overhead, not speed-up.
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
    a = ap.parse_args()
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
