#!/usr/bin/python3
"""CPU samples of the windows of "stage 2" (after stage 1) of a getme run.

Runs `perf record -e cpu-clock -F FREQ -k CLOCK_MONOTONIC` on
`getme smooth IN -o OUT -v --threads T`, stamps every log line with
CLOCK_MONOTONIC as it arrives, and counts the samples (all threads) and the
wall time in each window:

  qmin1   last q_mean-stage iteration line -> first q*min-stage line
  qmin2   the second q*min-stage iteration
  qmin    last q_mean-stage iteration line -> last q*min-stage line
  finish  last q*min-stage line -> last "Finishing pass" line
  rest    -> "Done optimizing" (summary, restore; the hand-back is later)
  stage2  last q_mean-stage line -> "Done optimizing" (bench/stages.py's)

CPU seconds are samples / FREQ, so a loaded machine's waiting is not
counted; "busiest thread" is the CPU of the thread with most samples in
the window, what the window's wall time would be on idle cores if the
threads never waited for each other.  With --top N, the N symbols with most samples per window.

  /usr/bin/python3 bench/stage2_cpu.py --getme build/cli/getme IN --threads 2
"""
import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile
import time


def run(getme, mesh, threads, freq, out_dir):
    data = os.path.join(out_dir, "perf.data")
    out = os.path.join(out_dir, "out.msh")
    env = dict(os.environ, OMP_WAIT_POLICY="passive")
    cmd = ["perf", "record", "-q", "-e", "cpu-clock", "-F", str(freq),
           "-k", "CLOCK_MONOTONIC", "-o", data, "--", getme, "smooth", mesh,
           "-o", out, "-v", "--threads", str(threads)]
    p = subprocess.Popen(cmd, stderr=subprocess.STDOUT, stdout=subprocess.PIPE,
                         env=env, text=True)
    lines = []
    for line in p.stdout:
        lines.append((time.clock_gettime(time.CLOCK_MONOTONIC), line))
    p.wait()
    return data, lines


def windows(lines):
    last_mean = last_min = last_fin = done = None
    mins = []
    for t, line in lines:
        if re.search(r"It +\d+ \(qmean stage", line):
            last_mean = t
        elif re.search(r"It +\d+ \(q\*min stage", line):
            last_min = t
            mins.append(t)
        elif "Finishing pass" in line:
            last_fin = t
        elif "Done optimizing" in line:
            done = t
    last_min = last_min or last_mean
    last_fin = last_fin or last_min
    first = {"qmin1": (last_mean, mins[0])} if mins else {}
    if len(mins) > 1:
        first["qmin2"] = (mins[0], mins[1])
    return {**first, "qmin": (last_mean, last_min),
            "finish": (last_min, last_fin), "rest": (last_fin, done),
            "stage2": (last_mean, done)}


def samples(data):
    txt = subprocess.run(["perf", "script", "-i", data, "-F", "tid,time,ip,sym"],
                         capture_output=True, text=True).stdout
    out = []
    for line in txt.splitlines():
        m = re.match(r"\s*(\d+)\s+([0-9.]+):\s+[0-9a-f]+\s+(\S+)?", line)
        if m:
            out.append((float(m.group(2)), m.group(3) or "?", m.group(1)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh")
    ap.add_argument("--getme", action="append", required=True)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--freq", type=int, default=999)
    ap.add_argument("--top", type=int, default=0)
    ap.add_argument("--keep", help="keep each build's output as KEEP.N.msh "
                    "(N: its --getme position), e.g. to cmp them")
    a = ap.parse_args()
    for n, g in enumerate(a.getme):
        with tempfile.TemporaryDirectory() as d:
            data, lines = run(g, a.mesh, a.threads, a.freq, d)
            w = windows(lines)
            s = samples(data)
            if a.keep:
                os.replace(os.path.join(d, "out.msh"), f"{a.keep}.{n}.msh")
        print(f"{g} {os.path.basename(a.mesh)} threads {a.threads}")
        for name, (t0, t1) in w.items():
            if t0 is None or t1 is None:
                continue
            sel = [sym for t, sym, tid in s if t0 <= t < t1]
            per = collections.Counter(tid for t, sym, tid in s if t0 <= t < t1)
            busiest = max(per.values()) if per else 0
            print(f"  {name:7s} wall {t1 - t0:7.3f} s  CPU {len(sel) / a.freq:7.3f} s"
                  f"  busiest thread {busiest / a.freq:7.3f} s")
            if a.top and name != "stage2":
                for sym, n in collections.Counter(sel).most_common(a.top):
                    print(f"      {100.0 * n / max(len(sel), 1):5.1f}% {sym}")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
