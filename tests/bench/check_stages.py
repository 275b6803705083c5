#!/usr/bin/python3
"""bench/stages.py end to end on a small example: two runs of the same build
at 1 and 2 threads.  Every stage it reports must have been found in the log
(a change of the CLI's log lines would silently turn them into zeros or
errors), the stage times must add up to no more than the command's wall
time, and the results (q*min, q_mean, iterations) must be identical across
builds and thread counts (the smoother is bit-identical for any thread
count)."""
import argparse
import json
import math
import os
import subprocess
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", required=True)
    ap.add_argument("--getme", required=True)
    ap.add_argument("--mesh", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    out, js = os.path.join(a.work, "stages.md"), os.path.join(a.work, "stages.json")
    subprocess.run([sys.executable, os.path.join(a.bench, "stages.py"), a.mesh,
                    "--run", f"a={a.getme}", "--run", f"b={a.getme}", "--reps", "1",
                    "--threads", "1,2", "--out", out, "--json", js], check=True,
                   capture_output=True)
    runs = json.load(open(js))
    fails = []
    if len(runs) != 4:
        fails.append(f"{len(runs)} runs, expected 4")
    for r in runs:
        for k in ("read", "before", "setup", "ns1", "stage2", "after", "write", "total",
                  "cpu", "rss"):
            # set-up = iteration 1 minus iteration 2, each logged to 0.01 s:
            # the bracket's set-up is about 0.01 s, so rounding, or a load
            # spike in iteration 2, can make it come out a little negative
            low = -0.05 if k == "setup" else 0.0
            if not (isinstance(r[k], float) and math.isfinite(r[k]) and r[k] >= low):
                fails.append(f"{r['build']} {r['threads']}t: {k} = {r[k]}")
        if not r["ns1"] > 0.0 or not r["rss"] > 1.0:
            fails.append(f"{r['build']} {r['threads']}t: ns1 {r['ns1']}, rss {r['rss']}")
        parts = r["read"] + r["before"] + r["stage2"] + r["after"] + r["write"]
        if parts > r["total"]:
            fails.append(f"{r['build']} {r['threads']}t: stages {parts} > total {r['total']}")
        for k in ("q_min_star", "q_mean", "iterations"):
            if r[k] != runs[0][k]:
                fails.append(f"{r['build']} {r['threads']}t: {k} {r[k]} != {runs[0][k]}")
    text = open(out).read()
    for want in ("| 1 | a |", "| 2 | b |", "| ratio a/b |", "| speedup a |", "| speedup b |"):
        if want not in text:
            fails.append(f"table lacks '{want}'")
    for f in fails:
        print("FAIL:", f)
    print(f"check_stages: {len(runs)} runs, {len(fails)} failures")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
