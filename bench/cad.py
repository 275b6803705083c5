#!/usr/bin/python3
"""getme on Gmsh meshes of real CAD parts (evidence for issue #9).

  /usr/bin/python3 bench/cad.py [--small] [--parts CrankArm,Pump_Nut]
                                [--cache DIR] [--getme PATH] [--out DIR]

Meshes real parts (OpenCASCADE's sample .brep files, Gmsh's demo .step
files) with Gmsh in two kinds, cached under --cache as PART-KIND-nN.msh
(N = bounding-box diagonal / mesh size):

  hex  all-hex by subdivision (Mesh.SubdivisionAlgorithm = 2).  Gmsh often
       leaves a few inverted hexes, which getme refuses (exit 6).  Made valid
       with Gmsh's own means only, in this order: the mesh as it is; mesh
       sizes 10 % finer / coarser; Mesh.SecondOrderLinear = 1 (the nodes that
       subdivision adds on edges and faces stay on the straight midpoints
       instead of being snapped to the CAD surface).  No element is ever
       deleted; a part that stays invalid is reported and skipped.
  tet  Gmsh's default 3-D Delaunay with Mesh.Optimize = 0, so that Gmsh's
       own optimizer can run as a separate method.

Methods, each in its own process (bench/runner.py): getme (defaults:
GETMe adaptive + finishing step + corner guard), getme-paper (finish=0,
corner_guard=0), laplace; on tets also gmsh-opt (Gmsh's optimize("") via
bench/gmsh_baseline.py, measured by getme's report of the next run) and
gmsh-opt+getme (getme defaults on gmsh-opt's output).  Numbers come from
getme's --report JSON (docs/quality.md, cli/report.c); q*min is checked
against bench/stats.py's independent numpy value (column q*min np).

Results: Markdown tables on stdout, bench/results/cad/cad.md and cad.json
(--out; the title says full or small).  Per hex part two checks: "min corner SJ after >= before" and
"q*min getme >= laplace", PASS/FAIL.  Docs: docs/bench.md.
Exit status: 0 all ran, 1 a run failed or a check failed, 2 usage.
"""

import argparse
import json
import math
import re
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import runner  # noqa: E402
import tables  # noqa: E402
from meshdata import read_mesh  # noqa: E402
from stats import mesh_stats  # noqa: E402

REPO = os.path.dirname(HERE)
OCC = "/usr/share/opencascade/data"
GMSH_DOC = "/usr/share/doc/gmsh-doc/doc/gmsh"

# part: (source, {(kind, small): N}) with mesh size = bounding-box diagonal / N.
# Calibrated on Gmsh 4.8.4 (counts measured at two N each, count ~ N^3):
# hex ~150k full, ~30k small; tet ~300k full, ~60k small (small N = 0.585 x).
PARTS = {
    "CrankArm": (f"{OCC}/occ/CrankArm.brep",
                 {("hex", False): 84, ("hex", True): 49,
                  ("tet", False): 177, ("tet", True): 104}),
    "Pump_TopCover": (f"{OCC}/occ/Pump_TopCover.brep",
                      {("hex", False): 67, ("hex", True): 39,
                       ("tet", False): 137, ("tet", True): 80}),
    "Pump_Nut": (f"{OCC}/occ/Pump_Nut.brep",
                 {("hex", False): 56, ("hex", True): 33,
                  ("tet", False): 117, ("tet", True): 68}),
    "component8": (f"{GMSH_DOC}/demos/boolean/component8.step.gz",
                   {("hex", False): 48, ("hex", True): 28,
                    ("tet", False): 98, ("tet", True): 57}),
    "linkrods": (f"{OCC}/step/linkrods.step",
                 {("hex", False): 70, ("hex", True): 41,
                  ("tet", False): 143, ("tet", True): 84}),
}
DEFAULT_PARTS = ",".join(PARTS)

# (key, getme smooth arguments, kinds); gmsh-opt rows are built separately.
GETME_METHODS = (
    ("getme", ()),
    ("getme-paper", ("--param", "finish=0", "--param", "corner_guard=0")),
    ("laplace", ("--method", "laplace")),
)
# Validity attempts for hexes: (label, size factor, SecondOrderLinear).
HEX_ATTEMPTS = (("as meshed", 1.0, 0), ("size x0.9", 0.9, 0),
                ("size x1.1", 1.1, 0), ("SecondOrderLinear=1", 1.0, 1))

COLUMNS = [  # (header, row key, format)
    ("Method", "method", "{}"),
    ("Elements", "elements", "{}"),
    ("q*min", "q_min_star", "{:.4f}"),
    ("q*min np", "np_q_min_star", "{:.4f}"),
    ("q_min", "q_min", "{:.4f}"),
    ("q_mean", "q_mean", "{:.4f}"),
    ("cornerSJ", "corner_sj", "{:.4f}"),
    ("hex SJ min", "hex_sj_min", "{:.4f}"),
    ("min dihedral", "min_dihedral", "{:.2f}"),
    ("Time s", "seconds", "{:.2f}"),
    ("worst free: reason", "worst_free_reason", "{}"),
    ("worst all fixed", "worst_all_fixed", "{}"),
]


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# ---------------------------------------------------------------- meshing

def source_file(part, cache):
    """The part's CAD file; .gz copies are gunzipped into the cache."""
    src = PARTS[part][0]
    if not src.endswith(".gz"):
        return src
    dst = os.path.join(cache, os.path.basename(src)[:-3])
    if not os.path.exists(dst):
        with open(dst, "wb") as f:
            subprocess.run(["gunzip", "-c", src], stdout=f, check=True)
    return dst


def gmsh_mesh(cad, path, n, kind, linear=0):
    """Mesh cad with size diagonal/n and write MSH 4.1 to path; returns
    Gmsh's version."""
    import gmsh
    gmsh.initialize(["cad"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(cad)
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(-1, -1)
        gmsh.option.setNumber("Mesh.MeshSizeMax",
                              math.dist((x0, y0, z0), (x1, y1, z1)) / n)
        if kind == "hex":
            gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 2)
            gmsh.option.setNumber("Mesh.SecondOrderLinear", linear)
        else:
            gmsh.option.setNumber("Mesh.Optimize", 0)
        gmsh.model.mesh.generate(3)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.write(path + ".tmp.msh")
        os.replace(path + ".tmp.msh", path)
        return gmsh.option.getString("General.Version")
    finally:
        gmsh.finalize()


def invalid_count(getme, path):
    """0 if getme accepts the mesh, else its number of inverted/degenerate
    elements (getme quality exits 6 on them, like getme smooth)."""
    r = runner.run([getme, "quality", path])
    if r.returncode == 0:
        return 0
    m = re.search(r"(\d+) invalid \(", r.stderr + r.stdout)
    return int(m.group(1)) if m else -1


def mesh_file(args, part, kind):
    """(path, how it was made valid) of the part's cached mesh, meshing it if
    needed; path None if no attempt gave a valid mesh."""
    n0 = PARTS[part][1][(kind, args.small)]
    attempts = HEX_ATTEMPTS if kind == "hex" else (("as meshed", 1.0, 0),)
    tried = []
    for label, factor, linear in attempts:
        n = round(n0 / factor)  # finer mesh = larger N
        suffix = "-lin" if linear else ""
        path = os.path.join(args.cache, f"{part}-{kind}-n{n}{suffix}.msh")
        if not os.path.exists(path):
            log(f"Info    : meshing {part} ({kind}, N {n}{suffix})")
            gmsh_mesh(source_file(part, args.cache), path, n, kind, linear)
        bad = invalid_count(args.getme, path)
        if bad == 0:
            return path, label, tried
        log(f"Warning : {os.path.basename(path)} has {bad} invalid elements")
        tried.append(f"{label} (N {n}): {bad} invalid")
    return None, None, tried


# ---------------------------------------------------------------- methods

def report_row(report, when="after"):
    """The table fields of getme's --report JSON (when: before/after)."""
    stats = report[when]
    meas = report["measures"][when]
    row = {"elements": stats["elements"], "q_min_star": stats["q_min_star"],
           "q_min": stats["q_min"], "q_mean": stats["q_mean"],
           "invalid": stats["invalid"],
           "corner_sj": report["corner_sj"][when]}
    if "hex" in meas:
        row["hex_sj_min"] = meas["hex"]["scaled_jacobian"]["min"]
    if "tet" in meas:
        row["min_dihedral"] = meas["tet"]["min_dihedral"]["min"]
    if when == "after":
        worst, free = report["worst_elements"], report["worst_free_elements"]
        row["seconds"] = report["seconds"]
        row["iterations"] = report["iterations"]["total"]
        row["worst_free_reason"] = free[0]["reason"] if free else "none"
        fixed = sum(1 for w in worst if w["reason"] == "all_nodes_fixed")
        row["worst_all_fixed"] = f"{fixed}/{len(worst)}"
    return row


def run_getme(args, src, dst, extra):
    """getme smooth src -> dst; (report dict or None, error line)."""
    rep = dst[:-4] + ".json"
    r = runner.run([args.getme, "smooth", src, "-o", dst, "--threads", "2",
                    "--report", rep, *extra])
    if r.returncode != 0:
        return None, f"exit {r.returncode}: {r.error_line()}"
    with open(rep) as f:
        return json.load(f), ""


def numpy_check(row, path):
    """q*min of the output measured independently (bench/stats.py)."""
    row["np_q_min_star"] = mesh_stats(read_mesh(path))["q_min_star"]


def run_mesh(args, part, kind, src):
    """All methods on one mesh: the rows of its table (input first)."""
    work = os.path.join(args.cache, "runs")
    os.makedirs(work, exist_ok=True)
    base = os.path.join(work, os.path.basename(src)[:-4])
    rows = []
    for key, extra in GETME_METHODS:
        log(f"Info    : {part} {kind}: {key}")
        dst = f"{base}-{key}.msh"
        report, err = run_getme(args, src, dst, extra)
        if report is None:
            rows.append({"method": key, "status": err})
            continue
        if not rows:
            rows.append(dict(report_row(report, "before"), method="input"))
            numpy_check(rows[-1], src)
        rows.append(dict(report_row(report), method=key))
        numpy_check(rows[-1], dst)
    if kind == "tet":
        rows += gmsh_rows(args, part, src, base)
    for path in os.listdir(work):  # outputs are large: keep nothing
        os.remove(os.path.join(work, path))
    return rows


def gmsh_rows(args, part, src, base):
    """gmsh-opt (Gmsh's optimize("") in its own process) and gmsh-opt+getme."""
    log(f"Info    : {part} tet: gmsh-opt")
    opt = f"{base}-gmsh-opt.msh"
    r = runner.run([runner.PYTHON, os.path.join(HERE, "gmsh_baseline.py"),
                    src, opt, "--method", ""])
    if r.returncode != 0:
        err = f"failed: {r.error_line()}"
        return [{"method": "gmsh-opt", "status": err},
                {"method": "gmsh-opt+getme", "status": err}]
    seconds = r.last_json().get("seconds")
    if invalid_count(args.getme, opt):
        return [{"method": "gmsh-opt", "status": "invalid elements in output",
                 "seconds": seconds}]
    log(f"Info    : {part} tet: gmsh-opt+getme")
    dst = f"{base}-gmsh-opt-getme.msh"
    report, err = run_getme(args, opt, dst, ())
    if report is None:
        return [{"method": "gmsh-opt", "status": f"not measured: {err}"},
                {"method": "gmsh-opt+getme", "status": err}]
    gopt = dict(report_row(report, "before"), method="gmsh-opt", seconds=seconds)
    numpy_check(gopt, opt)
    both = dict(report_row(report), method="gmsh-opt+getme")
    both["seconds"] = seconds + both["seconds"]
    numpy_check(both, dst)
    return [gopt, both]


# ---------------------------------------------------------------- checks, output

def hex_checks(rows, method="getme"):
    """PASS/FAIL of issue #9's two hex claims for one getme method."""
    by = {r["method"]: r for r in rows if r.get("status", "ok") == "ok"}
    out = {}
    g, inp, lap = by.get(method), by.get("input"), by.get("laplace")
    if g and inp:
        out["sj"] = "PASS" if g["corner_sj"] >= inp["corner_sj"] else "FAIL"
    if g and lap:
        out["qmin"] = "PASS" if g["q_min_star"] >= lap["q_min_star"] else "FAIL"
    return out


def table(rows, kind):
    cols = [c for c in COLUMNS
            if not (kind == "tet" and c[1] in ("hex_sj_min", "corner_sj"))
            and not (kind == "hex" and c[1] == "min_dihedral")]
    lines = ["| " + " | ".join(h for h, _, _ in cols) + " |",
             "|" + "|".join("---" for _ in cols) + "|"]
    for row in rows:
        if row.get("status", "ok") != "ok":
            cells = [row["method"], f"**{row['status']}**"] + [""] * (len(cols) - 2)
        else:
            cells = [tables._cell(row, k, f) for _, k, f in cols]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def summary_table(results):
    lines = ["| Part | Hexes | Made valid by | cornerSJ before | cornerSJ after "
             "| min corner SJ after >= before | q*min getme | q*min laplace "
             "| q*min getme >= laplace | getme-paper: SJ, q*min checks |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for res in results:
        if res["kind"] != "hex":
            continue
        if not res.get("mesh"):
            lines.append(f"| {res['part']} | - | **no valid mesh** "
                         f"({'; '.join(res['tried'])}) | | | SKIPPED | | | SKIPPED | |")
            continue
        by = {r["method"]: r for r in res["rows"]}
        get = lambda m, k: tables._cell(by.get(m, {}), k, "{:.4f}")  # noqa: E731
        c, cp = res["checks"], res["checks_paper"]
        fix = res["fix"] + (f" (tried first: {'; '.join(res['tried'])})"
                            if res["tried"] else "")
        lines.append(f"| {res['part']} | {by.get('input', {}).get('elements', '-')} "
                     f"| {fix} | {get('input', 'corner_sj')} "
                     f"| {get('getme', 'corner_sj')} | {c.get('sj', 'n/a')} "
                     f"| {get('getme', 'q_min_star')} | {get('laplace', 'q_min_star')} "
                     f"| {c.get('qmin', 'n/a')} "
                     f"| {cp.get('sj', 'n/a')}, {cp.get('qmin', 'n/a')} |")
    return "\n".join(lines)


def markdown(results, meta):
    out = [f"# getme on Gmsh meshes of real CAD parts ({meta['size']})", "",
           f"`{meta['command']}`  ", f"Gmsh {meta['gmsh']}, {meta['getme_version']}, "
           f"{meta['cpu']}, load average at start {meta['load']}, "
           f"{meta['minutes']:.1f} min wall.", "",
           "q*min: worst element with a free node; cornerSJ: getme's minimum "
           "corner scaled Jacobian (report `corner_sj`); hex SJ min: Verdict's "
           "hex scaled Jacobian incl. the centre (`measures.*.hex.scaled_jacobian.min`); "
           "min dihedral in degrees; worst all fixed: how many of the 10 worst "
           "elements after smoothing have every node fixed.  Time: the smoothing "
           "call (gmsh-opt: optimize(\"\"); gmsh-opt+getme: both).  The PASS/FAIL "
           "columns judge getme's defaults; the last column applies the same two "
           "checks to getme-paper, for comparison only.", "",
           "## Hex checks (issue #9, getme defaults)", "", summary_table(results)]
    for kind in ("hex", "tet"):
        out += ["", f"## {kind} meshes"]
        for res in results:
            if res["kind"] != kind:
                continue
            out += ["", f"### {res['part']} ({os.path.basename(res['mesh'] or '-')}, "
                        f"made valid by: {res['fix'] or 'nothing worked'})", ""]
            out.append(table(res["rows"], kind) if res["mesh"] else
                       "Skipped: " + "; ".join(res["tried"]))
    return "\n".join(out) + "\n"


def gmsh_version():
    import gmsh
    gmsh.initialize(["cad"])
    try:
        return gmsh.option.getString("General.Version")
    finally:
        gmsh.finalize()


def find_getme(explicit):
    if explicit:
        return explicit
    for b in sorted(e for e in os.listdir(REPO) if e.startswith("build")):
        path = os.path.join(REPO, b, "cli", "getme")
        if os.access(path, os.X_OK):
            return path
    return shutil.which("getme")


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--parts", default=DEFAULT_PARTS,
                    help=f"comma list of {','.join(PARTS)} (default {DEFAULT_PARTS})")
    ap.add_argument("--kinds", default="hex,tet", help="hex,tet (default both)")
    ap.add_argument("--small", action="store_true",
                    help="~30k hexes / ~60k tets per part instead of ~150k / ~300k")
    ap.add_argument("--cache", default="/work/cache/cad", help="meshes (default %(default)s)")
    ap.add_argument("--getme", help="getme CLI (default build*/cli/getme, PATH)")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "cad"))
    args = ap.parse_args(argv)
    args.parts = [p for p in args.parts.split(",") if p]
    args.kinds = [k for k in args.kinds.split(",") if k]
    bad = [p for p in args.parts if p not in PARTS] + \
          [k for k in args.kinds if k not in ("hex", "tet")]
    if bad:
        ap.error(f"unknown part/kind {','.join(bad)}")
    args.getme = find_getme(args.getme)
    if not args.getme:
        ap.error("no getme CLI found: build it or pass --getme")
    return args


def main(argv=None):
    import time
    args = parse_args(argv)
    os.makedirs(args.cache, exist_ok=True)
    os.makedirs(args.out, exist_ok=True)
    os.environ.setdefault("OMP_WAIT_POLICY", "passive")
    start, load = time.time(), "%.1f %.1f %.1f" % runner.load_average()
    help_text = subprocess.run([args.getme, "smooth", "--help"],
                               capture_output=True, text=True).stdout
    if "untangl" in help_text.lower():
        log("Warning : this getme can untangle, but cad.py does not use it yet")
    results = []
    for kind in args.kinds:
        for part in args.parts:
            mesh, fix, tried = mesh_file(args, part, kind)
            res = {"part": part, "kind": kind, "mesh": mesh, "fix": fix,
                   "tried": tried, "rows": []}
            if mesh:
                res["rows"] = run_mesh(args, part, kind, mesh)
                if kind == "hex":
                    res["checks"] = hex_checks(res["rows"])
                    res["checks_paper"] = hex_checks(res["rows"], "getme-paper")
            else:
                log(f"Warning : {part} {kind}: no valid mesh, skipped")
            results.append(res)
    version = subprocess.run([args.getme, "--version"], capture_output=True,
                             text=True).stdout.strip() or "getme"
    meta = {"size": "small" if args.small else "full",
            "command": " ".join(["/usr/bin/python3", "bench/cad.py"] + (argv or sys.argv[1:])),
            "gmsh": gmsh_version(), "getme_version": version,
            "cpu": runner.cpu_name(), "load": load,
            "minutes": (time.time() - start) / 60}
    md = markdown(results, meta)
    print(md)
    stem = os.path.join(args.out, "cad")
    with open(stem + ".md", "w") as f:
        f.write(md)
    tables.write_json(stem + ".json", {"meta": meta, "results": results})
    failed = any(r.get("status", "ok") != "ok" for res in results for r in res["rows"])
    failed |= any("FAIL" in res.get("checks", {}).values() for res in results)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
