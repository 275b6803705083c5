#!/usr/bin/python3
"""A/B timing of getme builds or parameter sets on the same mesh.

usage: bench/ab.py MESH [MESH...] --run NAME=GETME[:--param,a=1,...] ...
                   [--reps N] [--threads T] [--out FILE.md]

Each run is `GETME smooth MESH -o tmp --threads T --report tmp.json` plus the
run's extra arguments (after ':' comma-separated).  Runs alternate
(A B A B ...) so that a shared machine's load hits every variant alike;
the table gives, per mesh and variant, the smoothing time (getme's own
`seconds`, min and median over the repetitions), the whole command's wall
time, q*min, q_mean and the iterations.  Compare ratios, not absolute
times: this machine is shared.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def parse_run(text):
    name, _, rest = text.partition("=")
    exe, _, extra = rest.partition(":")
    return name, exe, [a for a in extra.split(",") if a]


def one(exe, extra, mesh, threads, tmp):
    out, rep = os.path.join(tmp, "out" + os.path.splitext(mesh)[1]), os.path.join(tmp, "r.json")
    t0 = time.monotonic()
    p = subprocess.run([exe, "smooth", mesh, "-o", out, "--threads", str(threads),
                        "--report", rep, "-q", *extra], capture_output=True, text=True)
    wall = time.monotonic() - t0
    if p.returncode:
        sys.exit(f"{exe} failed on {mesh}: {p.stderr.strip()}")
    r = json.load(open(rep))
    it = r["iterations"]
    iters = f"{it['mean_stage']}/{it['min_stage']}"
    if it.get("finish_passes"):
        iters += f"+{it['finish_passes']}"
    return {"seconds": r["seconds"], "wall": wall, "q_min_star": r["after"]["q_min_star"],
            "q_mean": r["after"]["q_mean"], "iterations": iters}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--run", action="append", required=True,
                    help="NAME=GETME[:extra,args] (repeatable; at least two)")
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", help="also write the table to this Markdown file")
    a = ap.parse_args()
    runs = [parse_run(r) for r in a.run]
    os.environ.setdefault("OMP_WAIT_POLICY", "passive")
    lines = [f"threads {a.threads}, {a.reps} alternating repetitions, "
             f"OMP_WAIT_POLICY={os.environ['OMP_WAIT_POLICY']}", "",
             "| mesh | variant | smoothing s (min / median) | command s (min) | ratio to first | "
             "iterations | q*min | qmean |", "|---|---|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in a.meshes:
            res = {name: [] for name, _, _ in runs}
            for _ in range(a.reps):
                for name, exe, extra in runs:
                    res[name].append(one(exe, extra, mesh, a.threads, tmp))
                    print(f"{os.path.basename(mesh)} {name}: {res[name][-1]}", flush=True)
            base = min(r["seconds"] for r in res[runs[0][0]])
            for name, _, _ in runs:
                rs = res[name]
                s = [r["seconds"] for r in rs]
                lines.append(
                    f"| {os.path.basename(mesh)} | {name} | {min(s):.2f} / {statistics.median(s):.2f} | "
                    f"{min(r['wall'] for r in rs):.2f} | {min(s) / base:.2f} | {rs[0]['iterations']} | "
                    f"{rs[0]['q_min_star']:.4f} | {rs[0]['q_mean']:.4f} |")
    text = "\n".join(lines)
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
