#!/usr/bin/python3
"""Read and write throughput of libgetme_formats, old build against new.

usage: bench/io.py FILE... --run NAME=IO_BENCH [--run NAME=IO_BENCH]
                   [--threads 1,2] [--reps 3] [--out T.md] [--json T.json]

Each IO_BENCH is a build's tests/formats/io_bench (an old build without
it: compile tests/formats/io_bench.c against that build with
-Dnum_threads=verbose and give it OMP_NUM_THREADS; this script sets both).
Per file, thread count and build, runs alternate build by build:
    io_bench FILE OUT --threads T --move --no-skin
so every node is free and every node line is rewritten (the worst case of
a smoothing run's output), without the boundary search.  Columns:
  read s / write s  the wall time of getme_doc_open / getme_doc_write;
  reader CPU s      (one thread) CPU samples of a separate read-only run
                    under `perf record -F 999`, outside libgetme.so: the
                    reader and the mesh build, not doc.c's validity check
                    (the same code in both builds);
  MB/s              file size / reader CPU s (read), file size / write s.
The outputs of all builds are compared with cmp (must be identical).
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile


def perf_split(data):
    out = subprocess.run(["perf", "report", "-i", data, "--no-children",
                          "--sort", "dso,sym", "--stdio", "-F",
                          "sample,dso,sym"], capture_output=True,
                         text=True).stdout
    reader = checks = 0
    for line in out.splitlines():
        m = re.match(r"\s+(\d+)\s+(\S+)\s+\[(.)\]\s+(\S+)", line)
        if not m:
            continue
        n, dso, sym = int(m.group(1)), m.group(2), m.group(4)
        if dso.startswith("libgetme.so") and not sym.startswith(
                "getme_mesh_add"):
            checks += n
        else:
            reader += n
    return reader, checks


def run(bench, path, out, threads, tmp):
    env = dict(os.environ, OMP_NUM_THREADS=str(threads),
               OMP_WAIT_POLICY="passive")
    args = ["--threads", str(threads), "--move", "--no-skin"]
    res = {}
    if threads == 1:  # CPU samples of reading alone
        data = os.path.join(tmp, "perf.data")
        subprocess.run(["perf", "record", "-q", "-F", "999", "-o", data,
                        "--", bench, path] + args, capture_output=True,
                       env=env, check=True)
        reader, checks = perf_split(data)
        res["reader_cpu"] = reader / 999.0
        res["checks_cpu"] = checks / 999.0
    cmd = [bench, path, out] + args
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    m = re.search(r"read (\S+) write (\S+)", r.stdout)
    if r.returncode or not m:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr}")
    res["read"] = float(m.group(1))
    res["write"] = float(m.group(2))
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("files", nargs="+")
    ap.add_argument("--run", action="append", required=True)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--out")
    ap.add_argument("--json")
    a = ap.parse_args()
    builds = [r.split("=", 1) for r in a.run]
    threads = [int(t) for t in a.threads.split(",")]
    rows, raw = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for path in a.files:
            size = os.path.getsize(path) / 1e6
            ext = os.path.splitext(path)[1]
            for t in threads:
                res = {name: [] for name, _ in builds}
                for rep in range(a.reps):
                    for name, bench in builds:
                        out = os.path.join(tmp, f"{name}{ext}")
                        res[name].append(run(bench, path, out, t, tmp))
                    first = os.path.join(tmp, f"{builds[0][0]}{ext}")
                    for name, _ in builds[1:]:
                        other = os.path.join(tmp, f"{name}{ext}")
                        if subprocess.run(["cmp", "-s", first, other]).returncode:
                            sys.exit(f"outputs differ: {path}, {t} threads")
                for name, _ in builds:
                    med = {k: statistics.median(r[k] for r in res[name])
                           for k in res[name][0]}
                    row = {"file": os.path.basename(path), "MB": size,
                           "threads": t, "build": name, **med}
                    rows.append(row)
                    raw.append({**row, "runs": res[name]})
                    print(json.dumps(row), flush=True)
    lines = [f"{a.reps} alternating repetitions, medians; outputs identical "
             "(cmp); MB/s = file MB / reader CPU s (read, one thread) or "
             "file MB / write s", "",
             "| file | MB | threads | build | read s | reader CPU s | read MB/s (CPU) | write s | write MB/s |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        cpu = r.get("reader_cpu")
        lines.append(
            f"| {r['file']} | {r['MB']:.0f} | {r['threads']} | {r['build']} "
            f"| {r['read']:.2f} | {cpu:.2f} | {r['MB'] / cpu:.0f} "
            if cpu else
            f"| {r['file']} | {r['MB']:.0f} | {r['threads']} | {r['build']} "
            f"| {r['read']:.2f} | | ")
        lines[-1] += f"| {r['write']:.2f} | {r['MB'] / r['write']:.0f} |"
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(raw, f, indent=1)


if __name__ == "__main__":
    main()
