#!/usr/bin/python3
"""Run `bench.py --quick` and check its results, so the benchmark never rots.

  check_quick.py --bench DIR --getme PATH --work DIR

Asserts that the run completes, that every case has the expected rows, and
that the values are sane: qualities in [0, 1], GETMe and smart Laplace
outputs valid with unchanged topology and boundary, better q_mean than the
distorted input, identical results for 1 and 2 threads, numpy's numbers
equal to getme's own report, plots written; the cost fields of issue #5
(ns/el-it, stage-1 ns/el-it, 2-thread speedup) present and positive, and
bench/scaling.py's outputs on the run.  Never asserts timings' values.
"""

import argparse
import json
import os
import subprocess
import sys

FAILS = []
PASSES = [0]


def check(cond, what):
    if cond:
        PASSES[0] += 1
    else:
        FAILS.append(what)
        print(f"FAIL: {what}")


EXPECTED = {  # method keys per case (netgen may be "skipped")
    "tet": ["getme-1", "getme-2", "paper-1", "paper-2", "laplace-1", "laplace-2", "gmsh-default",
            "gmsh-relocate3d", "netgen"],
    "hex": ["getme-1", "getme-2", "paper-1", "paper-2", "laplace-1", "laplace-2", "gmsh-default", "gmsh-relocate3d"],
    "mixed": ["getme-1", "getme-2", "paper-1", "paper-2", "laplace-1", "laplace-2", "gmsh-default", "gmsh-relocate3d"],
    "tri": ["getme-1", "getme-2", "paper-1", "paper-2", "laplace-1", "laplace-2", "gmsh-laplace2d", "gmsh-relocate2d"],
    "quad": ["getme-1", "getme-2", "paper-1", "paper-2", "laplace-1", "laplace-2", "gmsh-laplace2d", "gmsh-relocate2d"],
}


def check_case(case, c):
    init = c["initial"]
    rows = {r["method"]: r for r in c["rows"]}
    check(list(rows) == EXPECTED[case], f"{case}: rows {list(rows)}")
    check(0.0 <= init["q_min_star"] <= init["q_mean"] <= 1.0, f"{case}: initial qualities")
    check(init["q_mean"] < 0.6, f"{case}: distortion reached q_mean {init['q_mean']:.3f}")
    check(init["invalid"] == 0, f"{case}: distorted mesh valid")
    for key, r in rows.items():
        if r["status"].startswith("skipped"):
            check(key == "netgen", f"{case}/{key}: only netgen may be skipped")
            continue
        check(r["status"] == "ok", f"{case}/{key}: status {r['status']}")
        if r["status"] != "ok":
            continue
        check(0.0 <= r["q_min_star"] <= 1.0 and 0.0 <= r["q_mean"] <= 1.0,
              f"{case}/{key}: qualities in [0, 1]")
        check(sum(r["histogram"]) + r["invalid"] == r["elements"],
              f"{case}/{key}: histogram sums to the element count")
        check(r["peak_gib"] > 0 and r["seconds"] >= 0, f"{case}/{key}: measured")
        if key.startswith(("getme", "paper", "laplace")):
            check(r["topology"] == "no" and r["boundary_kept"],
                  f"{case}/{key}: topology {r['topology']}")
            check(r["invalid"] == 0, f"{case}/{key}: {r['invalid']} invalid")
            check(r["elements"] == init["elements"] and r["nodes"] == init["nodes"],
                  f"{case}/{key}: same counts")
            check(r["q_mean"] > init["q_mean"] + 0.1, f"{case}/{key}: q_mean improved")
            check(abs(r["report_q_mean"] - r["q_mean"]) < 1e-9
                  and abs(r["report_q_min_star"] - r["q_min_star"]) < 1e-9,
                  f"{case}/{key}: numpy agrees with getme's report")
            check(r["iterations_mean"] > 0 and len(r["history"]) > 0,
                  f"{case}/{key}: iterations and history")
            check_cost(case, key, r)
    # the finishing step starts from the paper's result and never lowers it
    if rows["getme-1"]["status"] == "ok" and rows["paper-1"]["status"] == "ok":
        check(rows["getme-1"]["q_min_star"] >= rows["paper-1"]["q_min_star"],
              f"{case}: q*min with the finishing step below the paper's")
        check(rows["getme-1"]["q_mean"] >= rows["paper-1"]["q_mean"] - 1e-9,
              f"{case}: q_mean with the finishing step below the paper's")
    for a, b in (("getme-1", "getme-2"), ("paper-1", "paper-2"), ("laplace-1", "laplace-2")):
        ra, rb = rows[a], rows[b]
        if ra["status"] == "ok" and rb["status"] == "ok":
            check(ra["q_mean"] == rb["q_mean"] and ra["q_min_star"] == rb["q_min_star"]
                  and ra["histogram"] == rb["histogram"],
                  f"{case}: {a} and {b} differ (results must not depend on threads)")
    check_speedup(case, c, rows)
    if case in ("hex", "quad"):
        # the paper's finding on structured meshes: GETMe lifts q*min far
        # above what smart Laplace reaches
        check(rows["getme-1"]["q_min_star"] > rows["laplace-1"]["q_min_star"],
              f"{case}: GETMe q*min above smart Laplace's")


def _positive(x):
    return isinstance(x, (int, float)) and x > 0


def check_cost(case, key, r):
    """ns per element-iteration (and GETMe's stage-1 figures) exist."""
    check(r.get("threads") == int(key.split("-")[1]),
          f"{case}/{key}: threads {r.get('threads')}")
    check(_positive(r.get("ns_el_it")), f"{case}/{key}: ns_el_it {r.get('ns_el_it')}")
    if key.startswith(("getme", "paper")):
        check(r.get("stage1_iterations") == r["iterations_mean"],
              f"{case}/{key}: stage-1 iterations {r.get('stage1_iterations')} "
              f"!= iterations_mean {r['iterations_mean']}")
        for field in ("stage1_seconds", "ns_el_it_stage1"):
            check(_positive(r.get(field)), f"{case}/{key}: {field} {r.get(field)}")


def check_speedup(case, c, rows):
    """time(1 thread) / time(2 threads) in the case and on the 2-thread rows."""
    speedup = c.get("speedup_2t") or {}
    for name, fields in (("getme", ("total", "stage1")), ("laplace", ("total",))):
        for field in fields:
            value = (speedup.get(name) or {}).get(field)
            check(_positive(value), f"{case}: speedup_2t {name} {field} {value}")
        value = rows[f"{name}-2"].get("speedup_2t")
        check(_positive(value), f"{case}/{name}-2: speedup_2t {value}")
    check("Cost and scaling" in c["text"] and "2-thread speedup" in c["text"],
          f"{case}: cost table and speedup line in the text")


def check_scaling(bench, out):
    """bench/scaling.py on the quick run: its files, a positive stage-1 cost."""
    cmd = ["/usr/bin/python3", os.path.join(bench, "scaling.py"), "--results", out,
           "--out", out, "--cases", ",".join(EXPECTED)]
    print(" ".join(cmd), flush=True)
    proc = subprocess.run(cmd, capture_output=True, text=True)
    check(proc.returncode == 0,
          f"scaling.py exit code {proc.returncode}: {proc.stderr[-500:]}")
    for ext in ("txt", "csv", "json", "png"):
        check(os.path.exists(os.path.join(out, f"scaling.{ext}")), f"scaling.{ext} written")
    path = os.path.join(out, "scaling.json")
    if os.path.exists(path):
        with open(path) as f:
            series = json.load(f)["series"]
        stage1 = [s for s in series if s["field"] == "ns_el_it_stage1"]
        check(len(stage1) == 2 * len(EXPECTED), f"scaling: {len(stage1)} stage-1 series")
        check(all(_positive(s["values"].get("quick")) for s in series),
              "scaling: every value positive")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", required=True)
    ap.add_argument("--getme", required=True)
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    out = os.path.join(args.work, "results")
    cmd = ["/usr/bin/python3", os.path.join(args.bench, "bench.py"), "--quick",
           "--out", out, "--cache", os.path.join(args.work, "cache"), "--getme", args.getme]
    print(" ".join(cmd), flush=True)
    proc = subprocess.run(cmd)
    check(proc.returncode == 0, f"bench.py exit code {proc.returncode}")
    path = os.path.join(out, "bench-quick.json")
    check(os.path.exists(path), "bench-quick.json written")
    if os.path.exists(path):
        with open(path) as f:
            data = json.load(f)
        check(sorted(data["cases"]) == sorted(EXPECTED), f"cases {sorted(data['cases'])}")
        check("CPU" in data["meta"]["header"], "CPU named")
        for case, c in data["cases"].items():
            check_case(case, c)
            for kind in ("quality-time", "histogram"):
                png = os.path.join(out, f"{case}-quick-{kind}.png")
                check(os.path.getsize(png) > 10000 if os.path.exists(png) else False,
                      f"{png} written")
        for ext in ("csv", "txt"):
            check(os.path.exists(os.path.join(out, f"bench-quick.{ext}")), f"{ext} written")
        csv_path = os.path.join(out, "bench-quick.csv")
        if os.path.exists(csv_path):
            with open(csv_path) as f:
                header = f.readline().strip().split(",")
            for field in ("ns_el_it", "ns_el_it_stage1", "speedup_2t"):
                check(field in header, f"CSV column {field}")
        check_scaling(args.bench, out)
    print(f"bench_quick: {PASSES[0]} passed, {len(FAILS)} failed")
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
