#!/usr/bin/python3
"""bench/setup.sh builds from the library's sources and runs (it once
stopped building when adjacency.c's check_all changed its signature, and
nothing noticed), and what it hashes -- every array of the workspace, the
face table and the adjacency -- is the same bits on 1, 2 and 3 threads,
as the library promises for any thread count."""
import argparse
import os
import re
import subprocess
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", required=True)
    ap.add_argument("--mesh", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    hashes = {}
    # setup.sh compiles the core's sources (the slow part) and keeps the
    # binary (KEEP=1) for the other thread counts, which run it directly
    exe = os.path.join(a.work, "setup")
    raw = os.path.join(a.work, os.path.basename(a.mesh)[:-4] + ".raw")
    env = dict(os.environ, RAW=a.work, OUT=exe, KEEP="1",
               OMP_WAIT_POLICY="passive")
    for threads in (1, 2, 3):
        cmd = ([exe, raw] if threads > 1 else
               ["sh", os.path.join(a.bench, "setup.sh"), a.mesh]) + [str(threads), "1"]
        r = subprocess.run(cmd, capture_output=True, text=True, env=env)
        sys.stdout.write(r.stdout)
        sys.stderr.write(r.stderr)
        if r.returncode != 0:
            sys.exit("FAIL: the set-up on %d threads exited with %d"
                     % (threads, r.returncode))
        m = re.search(r"hashes: ws ([0-9a-f]{16}) adj ([0-9a-f]{16})", r.stdout)
        if not m:
            sys.exit("FAIL: no hashes line on %d threads" % threads)
        hashes[threads] = m.groups()
    if len(set(hashes.values())) != 1:
        sys.exit("FAIL: the set-up differs between thread counts: %r" % hashes)
    print("bench_setup: ok, hashes %s %s on 1, 2 and 3 threads" % hashes[1])


if __name__ == "__main__":
    main()
