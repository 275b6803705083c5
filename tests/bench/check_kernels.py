#!/usr/bin/python3
"""bench/kernels.sh builds from the library's sources and runs (it once
stopped building when an include folder moved, and nothing noticed): exit
code 0, which kernels.c gives only when every lane kernel matched the
one-element kernel's bits on its pool, and all nine times it prints,
positive and finite.  Never the times' values."""
import argparse
import math
import os
import re
import subprocess
import sys

LINES = {
    "tet quality": 2, "tet transform": 2,
    "hex quality": 2, "hex transform": 2, "hex corner_sj": 1,
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    env = dict(os.environ, OUT=os.path.join(a.work, "kernels"))
    r = subprocess.run(["sh", os.path.join(a.bench, "kernels.sh"), "4096"],
                       capture_output=True, text=True, env=env)
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    if r.returncode != 0:
        sys.exit("FAIL: bench/kernels.sh exited with %d" % r.returncode)
    found = {}
    for line in r.stdout.splitlines():
        m = re.match(r"(tet|hex) (quality|transform|corner_sj) +(.*)$", line)
        if m:
            key = m.group(1) + " " + m.group(2)
            found[key] = [float(v) for v in re.findall(r"([0-9.]+) ns/el", m.group(3))]
    bad = []
    for key, n in LINES.items():
        vals = found.get(key)
        if vals is None or len(vals) != n:
            bad.append("%s: expected %d times, got %r" % (key, n, vals))
        elif not all(math.isfinite(v) and v > 0 for v in vals):
            bad.append("%s: times not positive: %r" % (key, vals))
    if os.path.exists(env["OUT"]):
        bad.append("the kernels binary was left behind")
    if bad:
        sys.exit("FAIL: " + "; ".join(bad))
    print("bench_kernels: ok")


if __name__ == "__main__":
    main()
