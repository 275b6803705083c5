#!/usr/bin/python3
"""getme benchmark: GETMe adaptive against smart Laplace, Gmsh's and Netgen's
optimizers on generated, distorted meshes -- tables like the paper's.

  /usr/bin/python3 bench/bench.py --quick
  /usr/bin/python3 bench/bench.py --size small|medium|full [--cases tet,hex]
  /usr/bin/python3 bench/bench.py --sweep --size medium     (threshold_fraction)
  /usr/bin/python3 bench/bench.py --generate-only --size full

Meshes are generated with the Gmsh Python API and cached (--cache, default
bench/cache, git-ignored); distorted copies come from `getme distort` and are
cached too.  Every method then runs in its own process under /usr/bin/time
on the same distorted file; its output file is read back with meshio and
measured here in numpy (quality.py, skin.py), never trusted from the tool.
Results: tables on stdout, bench-<size>.{txt,csv,json} and PNG plots in
--out (default bench/results/<size>); under each case's table a "Cost and
scaling" table gives ns per element-iteration and the 2-thread speedup
(cost.py).  bench/scaling.py compares those across sizes.  Docs:
docs/bench.md.

Exit status: 0 all runs fine, 1 a run failed or gave an invalid mesh where
it must not, 2 usage, 3 a required tool is missing.
"""

import argparse
import os
import shutil
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import cost  # noqa: E402
import meshes  # noqa: E402
import methods as M  # noqa: E402
import runner  # noqa: E402
import tables  # noqa: E402
from meshdata import read_mesh  # noqa: E402
from stats import boundary_kept, mesh_stats, topology_change  # noqa: E402

REPO = os.path.dirname(HERE)
# q_mean the distortion aims at: the paper's initial meshes (0.4506 / 0.4709)
TARGET_QMEAN = {"tet": 0.45, "hex": 0.47, "mixed": 0.47, "tri": 0.47, "quad": 0.47}
SWEEP_FRACTIONS = (0.002, 0.005, 0.01, 0.02, 0.05)
CASE_TITLES = {"tet": "piston, Delaunay tets", "hex": "swept flange, hexes",
               "mixed": "block, hex/prism base + tet/pyramid cap",
               "tri": "flange section, triangles", "quad": "flange section, quads"}


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="small meshes, the whole run in about a minute (= --size quick)")
    ap.add_argument("--size", choices=("quick", "small", "medium", "full"))
    ap.add_argument("--cases", default=",".join(meshes.CASES),
                    help="comma list of " + ",".join(meshes.CASES))
    ap.add_argument("--methods", default="",
                    help="comma list of method keys (default: all that apply)")
    ap.add_argument("--out", help="result directory (default bench/results/SIZE)")
    ap.add_argument("--cache", default=os.environ.get("GETME_BENCH_CACHE",
                                                      os.path.join(HERE, "cache")),
                    help="generated/distorted meshes and run outputs "
                         "(default bench/cache, or $GETME_BENCH_CACHE)")
    ap.add_argument("--getme", help="the getme executable (default: build*/cli/getme, PATH)")
    ap.add_argument("--seed", type=int, default=1, help="distortion seed")
    ap.add_argument("--distort", choices=("getme", "none"), default="getme",
                    help="'none' benchmarks the generated meshes as they are")
    ap.add_argument("--sweep", action="store_true",
                    help="sweep getme's threshold_fraction on the tet and hex meshes")
    ap.add_argument("--fractions", default=",".join(str(f) for f in SWEEP_FRACTIONS),
                    help="threshold_fraction values of --sweep")
    ap.add_argument("--omp-wait-policy", choices=("active", "passive"),
                    help="OMP_WAIT_POLICY for the getme runs (default: as in the "
                         "environment; on a loaded machine 'passive' avoids "
                         "spinning threads, see docs/bench.md)")
    ap.add_argument("--generate-only", action="store_true")
    ap.add_argument("--replot", action="store_true",
                    help="redraw the PNGs of --out's bench-SIZE.json, run nothing")
    ap.add_argument("--keep-outputs", action="store_true",
                    help="keep every method's output mesh (in the cache)")
    ap.add_argument("--timeout", type=float, default=None,
                    help="seconds per run (default: 600 quick, none otherwise)")
    args = ap.parse_args(argv)
    if args.quick and args.size not in (None, "quick"):
        ap.error("--quick and --size are exclusive")
    args.size = "quick" if args.quick or not args.size else args.size
    args.cases = [c for c in args.cases.split(",") if c]
    bad = [c for c in args.cases if c not in meshes.CASES]
    if bad:
        ap.error(f"unknown case(s) {','.join(bad)}")
    args.methods = [m for m in args.methods.split(",") if m]
    known = {m.key for m in M.METHODS}
    bad = [m for m in args.methods if m not in known]
    if bad:
        ap.error(f"unknown method(s) {','.join(bad)}; known: {','.join(sorted(known))}")
    args.fractions = [float(f) for f in args.fractions.split(",") if f]
    args.out = args.out or os.path.join(HERE, "results", args.size)
    if args.timeout is None and args.size == "quick":
        args.timeout = 600.0
    return args


def find_getme(explicit):
    """Command prefix that runs getme: the CLI given, else the first
    build*/cli/getme, else getme on the PATH."""
    cli = explicit
    if cli is None:
        builds = sorted(e for e in os.listdir(REPO) if e.startswith("build"))
        found = [os.path.join(REPO, e, "cli", "getme") for e in builds]
        found = [p for p in found if os.access(p, os.X_OK)]
        cli = found[0] if found else shutil.which("getme")
    if cli is None or not os.access(cli, os.X_OK):
        return None
    return [cli]


def distort(ctx, case, src):
    """The distorted copy of src (cached), made by `getme distort`."""
    if ctx.args.distort == "none":
        return src
    target = TARGET_QMEAN[case]
    dst = src[:-4] + f"-seed{ctx.args.seed}-q{target}.msh"
    if os.path.exists(dst):
        return dst
    log(f"Info    : distorting {os.path.basename(src)} (seed {ctx.args.seed}, "
        f"target q_mean {target})")
    tmp = dst[:-4] + ".tmp.msh"
    r = runner.run([*ctx.getme, "distort", src, "-o", tmp, "--seed", ctx.args.seed,
                    "--target-qmean", target], timeout=ctx.args.timeout)
    if r.returncode != 0:
        raise RuntimeError(f"getme distort failed on {src}: {r.error_line()}")
    os.replace(tmp, dst)
    return dst


def report_fields(report):
    """Iterations, time, history and final qualities from getme's --report
    JSON (tolerant of where the CLI puts them)."""
    iters = report.get("iterations", {})
    after = report.get("after", {})
    hist = report.get("history") or []
    return {
        "iterations_mean": iters.get("mean_stage"),
        "iterations_min": iters.get("min_stage"),
        "finish_passes": iters.get("finish_passes"),
        "corner_sj_before": (report.get("corner_sj") or {}).get("before"),
        "corner_sj_after": (report.get("corner_sj") or {}).get("after"),
        "seconds": report.get("seconds"),
        "report_q_min_star": after.get("q_min_star"),
        "report_q_mean": after.get("q_mean"),
        "report_fixed_nodes": report.get("fixed_nodes"),
        "runner": report.get("runner", "cli"),
        "history": [{"elapsed": h["elapsed"], "q_min_star": h["q_min_star"],
                     "q_mean": h["q_mean"], "stage": h.get("stage")}
                    for h in hist if "elapsed" in h],
    }


def measure(row, ref, path):
    """Read a method's output and fill the quality/topology fields of row."""
    mesh = read_mesh(path)
    st = mesh_stats(mesh)
    row.update({k: st[k] for k in ("nodes", "elements", "free_nodes", "q_min",
                                   "q_min_star", "q_mean", "n_le_04", "n_lt_01",
                                   "invalid", "histogram")})
    row["types"] = st["types"]
    row["q_min_star_by_type"] = st["q_min_star_by_type"]
    row["topology"] = topology_change(ref, mesh)
    row["boundary_kept"] = bool(boundary_kept(ref, mesh))
    if not row["boundary_kept"]:
        row["topology"] += "; boundary nodes moved"


def run_method(ctx, case, method, src, ref, params=(), tag=None):
    key = method.key + (f"-{tag}" if tag else "")
    work = os.path.join(ctx.work, f"{case}-{key}")
    dst, report = work + ".msh", work + ".report.json"
    row = {"size": ctx.args.size, "case": case, "method": key,
           "label": method.label + (f" [{tag}]" if tag else ""), "status": "ok"}
    log(f"Info    : {case}: running {row['label']}")
    env = None
    if method.tool == "getme" and ctx.args.omp_wait_policy:
        env = dict(os.environ, OMP_WAIT_POLICY=ctx.args.omp_wait_policy.upper())
    r = runner.run(M.command(method, ctx.getme, src, dst, report, params),
                   timeout=ctx.args.timeout, env=env)
    row["peak_gib"], row["wall"] = r.peak_gib, r.wall
    if r.returncode != 0 or not os.path.exists(dst):
        row["status"] = f"failed: {r.error_line()}"
        log(f"Error   : {case}: {row['label']} failed: {r.error_line()}")
        return row
    if method.tool == "getme":
        import json
        with open(report) as f:
            row.update(report_fields(json.load(f)))
        im, imin = row.get("iterations_mean"), row.get("iterations_min")
        passes = row.get("finish_passes") or 0
        row["iterations"] = (f"{im}/{imin}" + (f"+{passes}" if passes else "")
                             if method.args[1] == "getme" else f"{im}")
    else:
        row["seconds"] = r.last_json().get("seconds")
        row["iterations"] = "1" if method.tool == "gmsh" else "5 steps"
    if row.get("seconds") is None:
        row["seconds"] = r.wall
    measure(row, ref, dst)
    row.update(cost.cost_fields(row))
    same = r.last_json().get("same_connectivity")
    if row["topology"].startswith("yes (reconnected)") and same:
        # Gmsh renumbered the nodes but kept the connectivity
        row["topology"] = row["topology"].replace("yes (reconnected)", "no (renumbered)")
    base = ctx.baseline(case, method, src)
    row["delta_gib"] = row["peak_gib"] - base if base is not None else None
    if not ctx.args.keep_outputs:
        for p in (dst, report):
            if os.path.exists(p):
                os.remove(p)
    return row


class Context:
    def __init__(self, args, getme):
        self.args = args
        self.getme = getme
        self.work = os.path.join(args.cache, f"runs-{args.size}")
        os.makedirs(self.work, exist_ok=True)
        self._baselines = {}

    def baseline(self, case, method, src):
        """Peak GiB of loading (and writing) the mesh with the method's tool,
        without smoothing."""
        key = (case, M.baseline_key(method))
        if key not in self._baselines:
            dst = os.path.join(self.work, f"{case}-{method.tool}-load.msh")
            r = runner.run(M.baseline_command(method, self.getme, src, dst),
                           timeout=self.args.timeout)
            self._baselines[key] = r.peak_gib if r.returncode == 0 else None
            if os.path.exists(dst):
                os.remove(dst)
        return self._baselines[key]


def selected_methods(args, case):
    out = []
    for m in M.METHODS:
        if case not in m.cases or (args.methods and m.key not in args.methods):
            continue
        out.append(m)
    return out


def initial_row(case, size, st):
    row = {"size": size, "case": case, "method": "initial",
           "label": "Initial (distorted)", "status": "ok", "topology": "-"}
    row.update({k: st[k] for k in ("nodes", "elements", "free_nodes", "q_min",
                                   "q_min_star", "q_mean", "n_le_04", "n_lt_01",
                                   "invalid", "histogram")})
    return row


def check_row(row, notes):
    """Flag what must not happen: relocation methods changing topology or
    leaving invalid elements, our numbers disagreeing with getme's own."""
    bad = False
    if row.get("status") != "ok":
        return True
    if row["method"].startswith(("getme", "paper", "laplace")):
        if row["topology"] != "no" or row["invalid"]:
            notes.append(f"  ERROR: {row['label']}: topology {row['topology']}, "
                         f"{row['invalid']} invalid elements")
            bad = True
        fixed = row.get("report_fixed_nodes")
        if fixed is not None and fixed != row["nodes"] - row["free_nodes"]:
            notes.append(f"  note: {row['label']}: getme fixed {fixed} nodes, numpy "
                         f"counts {row['nodes'] - row['free_nodes']} on skin/interfaces")
        for key in ("q_min_star", "q_mean"):
            theirs = row.get("report_" + key)
            if theirs is not None and abs(theirs - row[key]) > 1e-6:
                notes.append(f"  note: {row['label']}: getme reports {key} "
                             f"{theirs:.6f}, numpy measures {row[key]:.6f}")
    return bad


def bench_case(ctx, case, meta):
    src = meshes.generate(case, ctx.args.size, ctx.args.cache, log=log)
    gen = read_mesh(src)
    gen_st = mesh_stats(gen)
    dist = distort(ctx, case, src)
    ref = read_mesh(dist) if dist != src else gen
    init = mesh_stats(ref)
    if topology_change(gen, ref) != "no":
        raise RuntimeError(f"getme distort changed the topology of {src}")
    types = ", ".join(f"{n} {t}" for t, n in init["types"].items())
    title = (f"{case}-{ctx.args.size}: {CASE_TITLES[case]}; {types}, "
             f"{init['nodes']} nodes ({init['free_nodes']} free)")
    rows = [initial_row(case, ctx.args.size, init)]
    for method in selected_methods(ctx.args, case):
        if method.tool == "netgen" and not M.netgen_available():
            rows.append({"size": ctx.args.size, "case": case, "method": method.key,
                         "label": method.label,
                         "status": "skipped (python3-netgen not installed)"})
            continue
        rows.append(run_method(ctx, case, method, dist, ref))
    notes = [f"  run {meta['date']}, load average {meta['load_average'][0]:.2f}",
             f"  generated: q*min {gen_st['q_min_star']:.4f}, q_mean "
             f"{gen_st['q_mean']:.4f}; distorted (seed {ctx.args.seed}): q*min "
             f"{init['q_min_star']:.4f}, q_mean {init['q_mean']:.4f}"]
    failed = any(check_row(r, notes) for r in rows[1:]
                 if not r["status"].startswith("skipped"))
    speedup = add_speedups(rows[1:])
    text = tables.format_table(title, rows, notes) + "\n\n" + cost_table(
        f"Cost and scaling, {case}-{ctx.args.size}", rows[1:], speedup)
    print(text + "\n", flush=True)
    case_out = {"title": title, "mesh": os.path.basename(src),
                "distorted": os.path.basename(dist), "generated": gen_st,
                "initial": init, "initial_row": rows[0], "rows": rows[1:],
                "speedup_2t": speedup, "text": text}
    return case_out, failed


def add_speedups(rows):
    """time(1 thread) / time(2 threads) per getme method, also put on the
    2-thread rows (for the CSV)."""
    speedup = cost.speedups(rows)
    for row in rows:
        s = speedup.get(cost.smoother(row) or "")
        if s and row.get("threads") == 2:
            row["speedup_2t"] = s.get("total")
            row["speedup_2t_stage1"] = s.get("stage1")
    return speedup


def cost_table(title, rows, speedup):
    """Time per element-iteration of getme's own methods, the 2-thread
    speedup under it (cost.py says how each number is made)."""
    ours = [r for r in rows if cost.is_smoother(r)]
    if not ours:
        return title + ": no getme runs"
    return tables.format_cost_table(title, ours, [cost.speedup_note(speedup)])


def merge_previous(path, cases):
    """Cases of an earlier run of the same size that this run did not redo
    (so big cases can be run one at a time), followed by this run's."""
    import json
    if not os.path.exists(path):
        return cases
    with open(path) as f:
        old = json.load(f).get("cases", {})
    merged = {c: v for c, v in old.items() if c not in cases}
    merged.update(cases)
    return {c: merged[c] for c in meshes.CASES if c in merged}


def write_outputs(args, meta, cases, stem):
    import plots
    os.makedirs(args.out, exist_ok=True)
    new = list(cases)
    cases = merge_previous(os.path.join(args.out, f"{stem}.json"), cases)
    all_rows = [r for c in cases.values() for r in [c["initial_row"]] + c["rows"]]
    tables.write_csv(os.path.join(args.out, f"{stem}.csv"), all_rows)
    tables.write_json(os.path.join(args.out, f"{stem}.json"),
                      {"meta": meta, "cases": cases})
    with open(os.path.join(args.out, f"{stem}.txt"), "w") as f:
        f.write(meta["header"] + "\n\n")
        f.write("\n\n".join(c["text"] for c in cases.values()) + "\n")
    for case, c in ((k, cases[k]) for k in new):
        plots.plot_quality_time(c, os.path.join(args.out, f"{case}-{args.size}-quality-time.png"),
                                meta["cpu"])
        plots.plot_histogram(c, os.path.join(args.out, f"{case}-{args.size}-histogram.png"))


def make_meta(args, getme):
    cpu = runner.cpu_name()
    load = runner.load_average()
    date = time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())
    header = (f"getme benchmark, size {args.size}, {date}\n"
              f"CPU: {cpu}; load average at start {load[0]:.2f} (shared machine: "
              f"times are indicative)\n"
              "Mem = peak RSS of the process (/usr/bin/time); dMem = minus a run of "
              "the same tool that only loads/writes the mesh.\n"
              f"getme runs as: {' '.join(getme or ['-'])}; OMP_WAIT_POLICY="
              f"{args.omp_wait_policy or os.environ.get('OMP_WAIT_POLICY', 'unset (libgomp: spin, then sleep)')}\n"
              "Time = the smoothing call only (getme's report, or timed inside the "
              "Gmsh/Netgen process).  q*min: min over elements with a free node "
              "(free = not on skin or region interface).")
    return {"size": args.size, "cpu": cpu, "load_average": load, "header": header,
            "date": date,
            "getme": " ".join(getme or []), "seed": args.seed, "generator_version": meshes.GENERATOR_VERSION}


def sweep(ctx, meta):
    """getme (1 thread) with each threshold_fraction on the tet and hex meshes."""
    method = M.METHODS[0]
    cases, failed = {}, False
    for case in [c for c in ctx.args.cases if c in ("tet", "hex")]:
        src = meshes.generate(case, ctx.args.size, ctx.args.cache, log=log)
        dist = distort(ctx, case, src)
        ref = read_mesh(dist)
        init = mesh_stats(ref)
        rows = []
        for frac in ctx.args.fractions:
            row = run_method(ctx, case, method, dist, ref,
                             params=(("threshold_fraction", frac),), tag=f"tf={frac}")
            row["threshold_fraction"] = frac
            rows.append(row)
        notes = []
        failed |= any(check_row(r, notes) for r in rows)
        title = f"threshold_fraction sweep, {case}-{ctx.args.size} ({init['elements']} elements)"
        text = tables.format_table(title, [initial_row(case, ctx.args.size, init)] + rows, notes)
        print(text + "\n", flush=True)
        cases[case] = {"title": title, "initial": init, "initial_row": initial_row(
            case, ctx.args.size, init), "rows": rows, "text": text}
    os.makedirs(ctx.args.out, exist_ok=True)
    stem = f"sweep-{ctx.args.size}"
    cases = merge_previous(os.path.join(ctx.args.out, stem + ".json"), cases)
    all_rows = [r for c in cases.values() for r in c["rows"]]
    tables.write_csv(os.path.join(ctx.args.out, stem + ".csv"), all_rows)
    tables.write_json(os.path.join(ctx.args.out, stem + ".json"), {"meta": meta, "cases": cases})
    with open(os.path.join(ctx.args.out, stem + ".txt"), "w") as f:
        f.write(meta["header"] + "\n\n" + "\n\n".join(c["text"] for c in cases.values()) + "\n")
    return failed


def replot(args):
    import json
    import plots
    path = os.path.join(args.out, f"bench-{args.size}.json")
    with open(path) as f:
        data = json.load(f)
    for case, c in data["cases"].items():
        plots.plot_quality_time(c, os.path.join(args.out, f"{case}-{args.size}-quality-time.png"),
                                data["meta"]["cpu"])
        plots.plot_histogram(c, os.path.join(args.out, f"{case}-{args.size}-histogram.png"))
    log(f"Info    : plots of {path} redrawn")
    return 0


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.replot:
        return replot(args)
    if args.generate_only:
        for case in args.cases:
            meshes.generate(case, args.size, args.cache, log=log)
        return 0
    getme = find_getme(args.getme)
    needs_getme = args.distort == "getme" or args.sweep or any(
        m.tool == "getme" for c in args.cases for m in selected_methods(args, c))
    if getme is None and needs_getme:
        log("Error   : getme executable not found: build it (cmake --build "
            "build-... --target ...) or pass --getme PATH")
        return 3
    ctx = Context(args, getme)
    meta = make_meta(args, getme)
    print(meta["header"] + "\n", flush=True)
    if args.sweep:
        return 1 if sweep(ctx, meta) else 0
    cases, failed = {}, False
    for case in args.cases:
        cases[case], bad = bench_case(ctx, case, meta)
        failed |= bad
    write_outputs(args, meta, cases, f"bench-{args.size}")
    log(f"Info    : results written to {args.out}")
    return 1 if failed else 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except RuntimeError as exc:
        log(f"Error   : {exc}")
        sys.exit(1)
