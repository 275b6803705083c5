#!/usr/bin/python3
"""Where the time of one `getme smooth` command goes, for two or more builds.

usage: bench/stages.py MESH [MESH...] --run NAME=GETME --run NAME=GETME
                       [--reps N] [--threads 1,2] [--out FILE.md] [--json FILE]

Each run is `GETME smooth MESH -o tmp -v --threads T --report tmp.json`.  The
log's lines are time-stamped as they arrive (the CLI flushes stdout after
each line), which splits the command into stages without changing the
program, so old builds are measured the same way as new ones:

  read      the reader's own "Done reading (..., X s)"
  before    statistics and measures of the input ("Done reading" to
            "Optimizing mesh"); since 2026-11-27 (read10) the measures
            sweep is also the read's validity check and runs before "Done
            reading", so compare read+before across such builds
  read+before  the command's start to "Optimizing mesh"
  set-up    workspace, Morton order, stars, colouring, edge/face tables and
            the inclusion-exclusion check: time of iteration 1 minus one
            stage-1 iteration (the CLI's smoothing clock starts before them)
  stage 1   ns per element and iteration over stage-1 iterations 2..n
  stage 2   from the last stage-1 iteration to "Done optimizing" (q*min
            stage and finishing step)
  after     statistics, measures and worst lists of the result
  write     "Writing" to "Done writing"
  total     the whole command (wall), its CPU time (user + system; less
            sensitive to a loaded machine than wall time), and peak RSS
            (wait4's ru_maxrss)

Runs alternate build by build (A B A B ...) so that a shared machine's load
hits every build alike; the table gives medians over the repetitions and
the ratio of each build to the first.  With two thread counts it also gives
the speedup of the total and of stage 1, from the medians and from the best
(fastest) repetition of each: on a shared VM another guest's load only ever
adds time, and it hits a 2-thread run (which needs both vCPUs) more often
than a 1-thread one, so the two speedups bracket what the code does.  The
table's first line names the machine (CPU model, cores), since the ratios
between builds depend on it (docs/bench.md, session 34).
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import runner  # noqa: E402  (cpu_name: the table's first line)

IT = re.compile(r"It +(\d+) \((q\*?min|qmean) stage.*\(([0-9.]+) s\)")
READ = re.compile(r"Done reading .*\(\w+, ([0-9.]+) s\)")
DONE = re.compile(r"Done optimizing mesh \(Wall ([0-9.]+)s\)")

FIELDS = [("read", "read s", 2), ("before", "before s", 2),
          ("read_before", "read+before s", 2), ("setup", "set-up s", 2),
          ("ns1", "stage-1 ns/el-it", 1), ("stage2", "stage 2 s", 2), ("after", "after s", 2),
          ("write", "write s", 2), ("total", "total s", 2), ("cpu", "CPU s", 2),
          ("rss", "peak MiB", 0)]


def one(exe, mesh, threads, tmp):
    """One command; the stage times as a dict."""
    out, rep = os.path.join(tmp, "out" + os.path.splitext(mesh)[1]), os.path.join(tmp, "r.json")
    env = dict(os.environ, OMP_WAIT_POLICY=os.environ.get("OMP_WAIT_POLICY", "passive"))
    t0 = time.monotonic()
    p = subprocess.Popen([exe, "smooth", mesh, "-o", out, "-v", "--threads", str(threads),
                          "--report", rep], stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, text=True, env=env)
    arrive, its, read = {}, {1: [], 2: []}, None
    done = None
    for line in p.stdout:
        t = time.monotonic() - t0
        if m := READ.search(line):
            read, arrive["read"] = float(m.group(1)), t
        elif "Optimizing mesh" in line:
            arrive["opt"] = t
        elif m := IT.search(line):
            its[1 if m.group(2) == "qmean" else 2].append(float(m.group(3)))
        elif m := DONE.search(line):
            done, arrive["done"] = float(m.group(1)), t
        elif "Writing '" in line:
            arrive["writing"] = t
        elif "Done writing" in line:
            arrive["written"] = t
    _, status, ru = os.wait4(p.pid, 0)
    total = time.monotonic() - t0
    if status:
        sys.exit(f"{exe} failed on {mesh} (status {status})")
    r = json.load(open(rep))
    ne = sum(r["elements"].values())
    s1 = its[1]
    it1 = s1[1] - s1[0] if len(s1) > 1 else 0.0
    return {
        "read": read, "before": arrive["opt"] - arrive["read"],
        "read_before": arrive["opt"],
        "setup": s1[0] - it1,
        "ns1": (s1[-1] - s1[0]) / (len(s1) - 1) / ne * 1e9 if len(s1) > 1 else float("nan"),
        "stage2": done - s1[-1], "after": arrive["writing"] - arrive["done"],
        "write": arrive["written"] - arrive["writing"], "total": total,
        "cpu": ru.ru_utime + ru.ru_stime,
        "rss": ru.ru_maxrss / 1024.0, "q_min_star": r["after"]["q_min_star"],
        "q_mean": r["after"]["q_mean"],
        "iterations": f"{r['iterations']['mean_stage']}/{r['iterations']['min_stage']}",
    }


def parse_run(text):
    name, _, exe = text.partition("=")
    return name, exe


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--run", action="append", required=True, help="NAME=GETME (repeatable)")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--threads", default="1,2", help="comma-separated thread counts")
    ap.add_argument("--out", help="also write the table to this Markdown file")
    ap.add_argument("--json", help="also write every run to this JSON file")
    a = ap.parse_args()
    runs = [parse_run(r) for r in a.run]
    threads = [int(t) for t in a.threads.split(",")]
    head = "| mesh | threads | build | " + " | ".join(h for _, h, _ in FIELDS) + \
           " | iterations | q*min | qmean |"
    lines = [f"{runner.cpu_name()}, {time.strftime('%Y-%m-%d')}", "",
             f"{a.reps} alternating repetitions, medians; ratio: first build / this build "
             f"(>1 = faster); speedups from the medians and (best) from the fastest "
             f"repetitions", "", head, "|" + "---|" * (head.count("|") - 1)]
    every = []
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in a.meshes:
            res = {(n, t): [] for n, _ in runs for t in threads}
            for _ in range(a.reps):
                for t in threads:
                    for name, exe in runs:
                        r = one(exe, mesh, t, tmp)
                        res[(name, t)].append(r)
                        every.append({"mesh": mesh, "build": name, "threads": t, **r})
                        print(f"{os.path.basename(mesh)} {name} {t}t: " +
                              ", ".join(f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}"
                                        for k, v in r.items()), flush=True)
            med = {k: {f: statistics.median(x[f] for x in v) for f, _, _ in FIELDS}
                   for k, v in res.items()}
            short = os.path.basename(mesh).split("-g")[0]
            with open(mesh, "rb") as f:  # MSH "$MeshFormat\n4.1 0 8": 0 = ASCII
                head = f.read(64).split(b"\n")
            if len(head) > 1 and head[0].strip() == b"$MeshFormat" and \
                    head[1].split()[1:2] == [b"0"]:
                short += " (ASCII)"
            for t in threads:
                for name, _ in runs:
                    m, r0 = med[(name, t)], res[(name, t)][0]
                    lines.append(f"| {short} | {t} | {name} | " +
                                 " | ".join(f"{m[f]:.{d}f}" for f, _, d in FIELDS) +
                                 f" | {r0['iterations']} | {r0['q_min_star']:.6f} | "
                                 f"{r0['q_mean']:.6f} |")
                b = med[(runs[0][0], t)]
                for name, _ in runs[1:]:
                    m = med[(name, t)]
                    lines.append(f"| {short} | {t} | ratio {runs[0][0]}/{name} | " + " | ".join(
                        f"{b[f] / m[f]:.2f}" if m[f] >= 0.005 else "-" for f, _, _ in FIELDS) + " | | | |")
            if len(threads) > 1:
                best = {k: {f: min(x[f] for x in v) for f in ("ns1", "total")}
                        for k, v in res.items()}
                for name, _ in runs:
                    for tag, src in (("", med), (" (best)", best)):
                        a1, a2 = src[(name, threads[0])], src[(name, threads[-1])]
                        lines.append(f"| {short} | {threads[0]}→{threads[-1]} | speedup "
                                     f"{name}{tag} | | | | | {a1['ns1'] / a2['ns1']:.2f} | | | | "
                                     f"{a1['total'] / a2['total']:.2f} | | | | | |")
    text = "\n".join(lines)
    print(text)
    if a.out:
        os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
        with open(a.out, "w") as f:
            f.write(text + "\n")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(every, f, indent=1)


if __name__ == "__main__":
    main()
