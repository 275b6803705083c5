#!/usr/bin/python3
"""GETMe-sequential-style baseline for q*min (issue #9).

  sequential.py MESH.msh [-o OUT.msh] [--json R.json] [--steps N]
                [--patience N] [--sigma 1.5] [--penalty 0.01] [--relax 16]
                [--variant valid+monotone|monotone|valid] [--seed-free FILE.msh]
  sequential.py --compare [--sizes quick,small] [--cases tri,quad]

GETMe sequential (Vartziotis & Wipper, the q_min stage of GETMe, the
predecessor of GETMe adaptive), written here in plain Python over the public
element calls of libgetme (getme_element_quality, getme_element_transform):

  repeat: take the element with the lowest key among the elements with at
    least one free node (key = mean ratio quality + the element's penalty);
    transform it with getme_element_transform(type, xyz, sigma) (regularizing
    step, rescaled to keep the sum of edge lengths); move its free nodes to
    the transformed positions, relaxed: rho = 1, 1/2, 1/4, ... (--relax
    values, default 16, i.e. down to 2^-15; new = (1-rho) old + rho
    transformed), the first rho that is accepted is kept.
    Accepted (variant monotone, the one that converges): every element
    incident to a moved node stays valid AND the minimum quality over those
    elements rises strictly, so q*min never decreases.  Variant valid (the
    original rule): every incident element stays valid; q*min may fall, the
    mesh of the best q*min seen is kept and returned.  If no rho is accepted
    the nodes go back and the element's penalty grows by --penalty (so the
    next picks go elsewhere); an element's penalty is cleared whenever one
    of its nodes moves.
  stop: after --steps picks, or when q*min (best so far) has not risen for
    --patience picks.
  valid+monotone (the default): a valid run with --valid-relax rho values
    (default 4), then a monotone run with --relax values from its best mesh,
    each with the full --steps/--patience budget.

Fixed nodes are the bench's (bench/skin.py: skin and region interfaces);
qualities are libgetme's own (bench/quality.py's numpy yardstick gives the
same numbers and is what the final line and the --compare table report).
A planar mesh that runs clockwise is handled mirrored (y -> -y), as libgetme
does.

--compare runs it on the benchmark's planar meshes (bench/meshes.py, the
distortion of bench.py: `getme distort --seed 1 --target-qmean 0.47`, same
cache names), next to `getme smooth` (default; finish=0 corner_guard=0 =
the paper's GETMe adaptive alone; --method laplace), all with 1 thread, plus
sequential started from getme's outputs (as a post-process).  Writes
bench/results/sequential/sequential.{md,json}.  Docs: docs/bench.md.
"""

import argparse
import ctypes as C
import heapq
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)

from meshdata import Mesh, read_mesh, write_points  # noqa: E402
from quality import planar_orientation  # noqa: E402
from skin import fixed_mask  # noqa: E402

TYPES = {"tet": 0, "hex": 1, "prism": 2, "pyramid": 3, "tri": 4, "quad": 5}
RELAX = (1.0, 0.5, 0.25, 0.125)  # run()'s default; the CLI's is --relax
DEFAULT_RELAX = 16  # rho = 1 ... 2^-15 (see docs/bench.md: stronger than 4)
VARIANTS = ("monotone", "valid", "valid+monotone")
COMPARE_RUNS = "monotone:4,monotone:16,valid:4,valid+monotone:4+16,valid+monotone:16+16"


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------
# libgetme


def find_build():
    builds = sorted(e for e in os.listdir(REPO) if e.startswith("build"))
    for b in builds:
        if os.path.exists(os.path.join(REPO, b, "core", "libgetme.so")):
            return os.path.join(REPO, b)
    return None


def load_core(lib_path=None):
    """libgetme as a ctypes CDLL: the project's Python package of the build
    tree (BUILD/python/getme, whose _lib.py loads it) if it imports, else
    the library file itself."""
    core = None
    if lib_path is None:
        build = find_build()
        if build and os.path.isdir(os.path.join(build, "python", "getme")):
            sys.path.insert(0, os.path.join(build, "python"))
            try:
                from getme import _lib
                core = _lib.core
            except Exception as exc:  # noqa: BLE001 (gmsh plugin missing, ...)
                log(f"Warning : the getme package did not import ({exc}); "
                    "loading libgetme directly")
            finally:
                sys.path.pop(0)
        if core is None:
            if build is None:
                raise RuntimeError("no build*/core/libgetme.so: build getme first")
            lib_path = os.path.join(build, "core", "libgetme.so")
    if core is None:
        core = C.CDLL(lib_path)
    # our own prototypes (pointers as plain addresses: no conversion per call)
    core.getme_element_quality.restype = C.c_double
    core.getme_element_quality.argtypes = [C.c_int, C.c_void_p]
    core.getme_element_transform.restype = C.c_int
    core.getme_element_transform.argtypes = [C.c_int, C.c_void_p, C.c_double, C.c_void_p]
    return core


# --------------------------------------------------------------------------
# GETMe sequential


class Sequential:
    """GETMe sequential on one mesh (bench Mesh); points are updated in
    self.points (original orientation) by run()."""

    def __init__(self, core, mesh, fixed=None):
        self.core = core
        self.mesh = mesh
        self.mirror = mesh.dim == 2 and planar_orientation(mesh.points, mesh.blocks) < 0
        self.fixed = (fixed_mask(len(mesh.points), mesh.blocks, mesh.regions)
                      if fixed is None else fixed)
        pts = np.array(mesh.points, dtype=np.float64)
        if self.mirror:
            pts[:, 1] *= -1.0
        self.pts = pts
        # elements: type code, node tuple, offset (doubles) of its xyz in buf
        etypes, enodes, offs = [], [], []
        off = 0
        for etype, conn in mesh.blocks:
            code = TYPES[etype]
            for row in np.asarray(conn).tolist():
                etypes.append(code)
                enodes.append(tuple(row))
                offs.append(off)
                off += 3 * len(row)
        self.etype, self.enodes, self.off = etypes, enodes, offs
        self.ne = len(enodes)
        self.buf = (C.c_double * max(off, 1))()
        self.base = C.addressof(self.buf)
        # node -> element list and xyz slots in buf
        nn = len(pts)
        node_elems = [[] for _ in range(nn)]
        node_slots = [[] for _ in range(nn)]
        for e, nodes in enumerate(enodes):
            o = offs[e]
            for k, n in enumerate(nodes):
                node_elems[n].append(e)
                node_slots[n].append(o + 3 * k)
        self.node_elems, self.node_slots = node_elems, node_slots
        self._load_buf()
        fx = self.fixed.tolist()
        self.free_nodes = [tuple((k, n) for k, n in enumerate(nodes) if not fx[n])
                           for nodes in enodes]
        self.is_free = [len(f) > 0 for f in self.free_nodes]
        self.patch = {}  # element -> elements incident to its free nodes
        self.out = (C.c_double * 24)()
        self.out_addr = C.addressof(self.out)
        self._load_q()
        if min(self.q) <= 0.0:
            raise RuntimeError(f"{sum(1 for v in self.q if v <= 0.0)} invalid "
                               "elements in the input")

    def _load_buf(self):
        """Every element's xyz slots in buf from self.pts."""
        flat = self.pts.ravel().tolist()
        buf = self.buf
        for e, nodes in enumerate(self.enodes):
            o = self.off[e]
            for k, n in enumerate(nodes):
                buf[o + 3 * k:o + 3 * k + 3] = flat[3 * n:3 * n + 3]

    def _load_q(self):
        Q, base, etypes, offs = self.core.getme_element_quality, self.base, self.etype, self.off
        self.q = [Q(etypes[e], base + 8 * offs[e]) for e in range(self.ne)]

    def patch_of(self, e):
        p = self.patch.get(e)
        if p is None:
            s = set()
            for _, n in self.free_nodes[e]:
                s.update(self.node_elems[n])
            p = self.patch[e] = tuple(s)
        return p

    def q_min_star(self):
        q, free = self.q, self.is_free
        return min((q[e] for e in range(self.ne) if free[e]), default=1.0)

    def run(self, steps, patience, sigma=1.5, penalty=0.01, relax=RELAX,
            monotone=True, progress=0, tag=""):
        """monotone: a step must raise the minimum over the elements around
        the moved nodes (q*min never falls); else any valid step is taken
        (the original rule) and the mesh of the best q*min is kept."""
        core = self.core
        Q, T = core.getme_element_quality, core.getme_element_transform
        etype, off, base, buf = self.etype, self.off, self.base, self.buf
        out, out_addr = self.out, self.out_addr
        pts = self.pts
        node_slots, free_nodes = self.node_slots, self.free_nodes
        q = self.q
        pen = [0.0] * self.ne
        key_heap = [(q[e], e) for e in range(self.ne) if self.is_free[e]]
        heapq.heapify(key_heap)
        min_heap = list(key_heap)  # true qualities, for q*min
        heapq.heapify(min_heap)
        push, pop = heapq.heappush, heapq.heappop

        def set_node(n, x, y, z):
            for s in node_slots[n]:
                buf[s] = x
                buf[s + 1] = y
                buf[s + 2] = z

        def cur_qmin():
            while True:
                v, e = min_heap[0]
                if v == q[e]:
                    return v
                pop(min_heap)

        qmin = best = cur_qmin()
        best_pts = None if monotone else pts.copy()
        qsum = sum(q)
        accepted = rejected = 0
        last_improve = 0
        start = time.perf_counter()
        history = [(0, 0.0, qmin, qsum / self.ne)]
        step = 0
        while step < steps and step - last_improve < patience:
            k, e = pop(key_heap)
            if k != q[e] + pen[e]:
                continue  # stale entry
            step += 1
            t, o = etype[e], off[e]
            if T(t, base + 8 * o, sigma, out_addr) != 0:
                raise RuntimeError(f"getme_element_transform failed on element {e}")
            fn = free_nodes[e]
            old = [(n, pts[n, 0], pts[n, 1], pts[n, 2]) for _, n in fn]
            new = [(out[3 * kk], out[3 * kk + 1], out[3 * kk + 2]) for kk, _ in fn]
            patch = self.patch_of(e)
            floor = min(q[i] for i in patch) if monotone else 0.0
            ok = False
            for rho in relax:
                a = 1.0 - rho
                for (n, x, y, z), (nx, ny, nz) in zip(old, new):
                    set_node(n, a * x + rho * nx, a * y + rho * ny, a * z + rho * nz)
                nq = []
                m = 2.0
                for i in patch:
                    v = Q(etype[i], base + 8 * off[i])
                    if v <= floor:  # invalid (0) or not above the old min
                        m = -1.0
                        break
                    nq.append(v)
                if m > 0.0:
                    ok = True
                    break
            if ok:
                accepted += 1
                for (n, x, y, z), (nx, ny, nz) in zip(old, new):
                    pts[n] = (a * x + rho * nx, a * y + rho * ny, a * z + rho * nz)
                for i, v in zip(patch, nq):
                    qsum += v - q[i]
                    q[i] = v
                    pen[i] = 0.0
                    if self.is_free[i]:
                        push(key_heap, (v, i))
                        push(min_heap, (v, i))
                nm = cur_qmin()
                if nm > best:
                    best = nm
                    last_improve = step
                    if not monotone:
                        best_pts = pts.copy()
                qmin = nm
            else:
                rejected += 1
                for n, x, y, z in old:
                    set_node(n, x, y, z)
                pen[e] += penalty
                push(key_heap, (q[e] + pen[e], e))
            if progress and step % progress == 0:
                el = time.perf_counter() - start
                history.append((step, el, qmin, qsum / self.ne))
                log(f"Info    : {tag}step {step}: q*min {qmin:.6f} (best {best:.6f}), q_mean "
                    f"{qsum / self.ne:.6f}, accepted {accepted}, rejected "
                    f"{rejected}, {el:.1f} s")
            if len(key_heap) > 8 * self.ne:  # drop stale entries now and then
                key_heap = [(q[i] + pen[i], i) for i in range(self.ne) if self.is_free[i]]
                heapq.heapify(key_heap)
                min_heap = [(q[i], i) for i in range(self.ne) if self.is_free[i]]
                heapq.heapify(min_heap)
        if not monotone and best > qmin:
            pts[:] = best_pts  # back to the best mesh seen
            self._load_buf()
            self._load_q()
            q = self.q
        seconds = time.perf_counter() - start
        stop = "steps" if step >= steps else "patience"
        history.append((step, seconds, best, sum(q) / self.ne))
        return {"steps": step, "accepted": accepted, "rejected": rejected,
                "seconds": seconds, "stop": stop, "q_min_star": self.q_min_star(),
                "q_mean": sum(q) / self.ne, "last_improve_step": last_improve,
                "history": history}

    def points(self):
        """Current coordinates in the mesh's own orientation."""
        pts = self.pts.copy()
        if self.mirror:
            pts[:, 1] *= -1.0
        return pts


def default_steps(num_elements):
    return max(200000, 50 * num_elements)


def default_patience(num_elements):
    return max(50000, 5 * num_elements)


def run_sequential(core, mesh, args, tag="", relax_count=None, variant=None,
                   valid_relax_count=None):
    """One run on mesh: variant monotone, valid, or valid+monotone (valid,
    then monotone from valid's best mesh, each with its own step budget)."""
    ne = mesh.num_elements
    variant = variant or args.variant
    steps = args.steps or default_steps(ne)
    patience = args.patience or default_patience(ne)
    relax = tuple(0.5 ** k for k in range(relax_count or args.relax))
    t0 = time.perf_counter()
    seq = Sequential(core, mesh)
    setup = time.perf_counter() - t0
    progress = args.progress or max(10000, steps // 50)
    valid_relax = tuple(0.5 ** k for k in range(valid_relax_count or args.valid_relax))
    phases = []
    for phase in variant.split("+"):
        if phase == "valid" and "+" in variant:
            phase_relax = valid_relax  # see --valid-relax
        else:
            phase_relax = relax
        phases.append(seq.run(steps, patience, sigma=args.sigma, penalty=args.penalty,
                              relax=phase_relax, monotone=phase == "monotone",
                              progress=progress, tag=f"{tag}{phase}: "))
        phases[-1]["relax"] = list(phase_relax)
    res = dict(phases[-1])
    for k in ("steps", "accepted", "rejected", "seconds"):
        res[k] = sum(p[k] for p in phases)
    res["stop"] = "+".join(p["stop"] for p in phases)
    res["history"] = [h for p in phases for h in p["history"]]
    if len(phases) > 1:
        res["phases"] = [{k: v for k, v in p.items() if k != "history"} for p in phases]
    res.update({"setup_seconds": setup, "steps_limit": steps, "patience": patience,
                "sigma": args.sigma, "penalty": args.penalty,
                "relax": [p["relax"] for p in phases] if len(phases) > 1 else list(relax),
                "variant": variant})
    return seq, res


def write_mesh(src, mesh, points, path):
    """src (read as mesh) rewritten with new coordinates."""
    write_points(src, mesh, points, path, app="sequential")


def seed_free(mesh, path):
    """mesh with the free nodes' coordinates taken from path (same node tags;
    its fixed nodes must sit where mesh's do)."""
    other = read_mesh(path)
    if not np.array_equal(other.tags, mesh.tags) or len(other.blocks) != len(mesh.blocks) \
            or any(not np.array_equal(c1, c2) for (_, c1), (_, c2)
                   in zip(mesh.blocks, other.blocks)):
        raise RuntimeError(f"{path}: not the same nodes and elements as the input")
    fixed = fixed_mask(len(mesh.points), mesh.blocks, mesh.regions)
    if not np.array_equal(other.points[fixed], mesh.points[fixed]):
        raise RuntimeError(f"{path}: fixed nodes moved")
    pts = mesh.points.copy()
    pts[~fixed] = other.points[~fixed]
    return Mesh(pts, mesh.blocks, mesh.regions, mesh.tags)


def cmd_single(args):
    from stats import mesh_stats
    core = load_core(args.lib)
    mesh = src = read_mesh(args.mesh)
    if args.seed_free:
        mesh = seed_free(src, args.seed_free)
    before = mesh_stats(mesh)
    log(f"Info    : {os.path.basename(args.mesh)}: {mesh.num_elements} elements, "
        f"{before['free_nodes']} free nodes; q*min {before['q_min_star']:.6f}, "
        f"q_mean {before['q_mean']:.6f}")
    seq, res = run_sequential(core, mesh, args)
    pts = seq.points()
    after = mesh_stats(Mesh(pts, mesh.blocks, mesh.regions, mesh.tags))
    if args.output:
        write_mesh(args.mesh, src, pts, args.output)  # every node that differs from the file
    print(f"q*min {after['q_min_star']:.6f}  q_mean {after['q_mean']:.6f}  steps "
          f"{res['steps']} (accepted {res['accepted']}, stop: {res['stop']})  "
          f"seconds {res['seconds']:.1f}", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"before": before, "after": after, "run": res}, f, indent=1)
    return 0


# --------------------------------------------------------------------------
# --compare


def cli_path():
    build = find_build()
    cli = os.path.join(build, "cli", "getme") if build else None
    if not cli or not os.access(cli, os.X_OK):
        raise RuntimeError("build*/cli/getme not found: build getme first")
    return cli


def distorted(cli, case, size, cache, seed=1):
    """bench.py's distorted copy (same command, same cache name)."""
    import bench
    import meshes
    import runner
    src = meshes.generate(case, size, cache, log=log)
    target = bench.TARGET_QMEAN[case]
    dst = src[:-4] + f"-seed{seed}-q{target}.msh"
    if not os.path.exists(dst):
        log(f"Info    : distorting {os.path.basename(src)}")
        tmp = dst[:-4] + ".tmp.msh"
        r = runner.run([cli, "distort", src, "-o", tmp, "--seed", seed,
                        "--target-qmean", target])
        if r.returncode != 0:
            raise RuntimeError(f"getme distort failed on {src}: {r.error_line()}")
        os.replace(tmp, dst)
    return src, dst


GETME_RUNS = (
    ("getme", "getme smooth (default)", ["--method", "getme"]),
    ("adaptive", "getme smooth, finish=0 corner_guard=0 (GETMe adaptive alone)",
     ["--method", "getme", "--param", "finish=0", "--param", "corner_guard=0"]),
    ("laplace", "getme smooth --method laplace (smart Laplace)", ["--method", "laplace"]),
)


def row_of(key, label, st, seconds, extra=None):
    row = {"method": key, "label": label, "q_min_star": st["q_min_star"],
           "q_mean": st["q_mean"], "q_min": st["q_min"], "invalid": st["invalid"],
           "n_le_04": st["n_le_04"], "seconds": seconds}
    row.update(extra or {})
    return row


def compare_case(core, cli, case, size, args, work):
    import runner
    from stats import boundary_kept, mesh_stats, topology_change
    src, dist = distorted(cli, case, size, args.cache)
    ref = read_mesh(dist)
    init = mesh_stats(ref)
    log(f"Info    : {case}-{size}: {init['elements']} elements, {init['free_nodes']} "
        f"free nodes; distorted q*min {init['q_min_star']:.4f} q_mean {init['q_mean']:.4f}")
    rows = [row_of("initial", "initial (distorted)", init, None)]
    outputs = {}
    for key, label, extra in GETME_RUNS:
        dst = os.path.join(work, f"{case}-{size}-{key}.msh")
        rep = dst[:-4] + ".json"
        env = dict(os.environ, OMP_WAIT_POLICY="PASSIVE")
        r = runner.run([cli, "smooth", dist, "-o", dst, "--threads", 1, "--report", rep,
                        "-q", *extra], env=env)
        if r.returncode != 0:
            raise RuntimeError(f"{label} failed on {dist}: {r.error_line()}")
        with open(rep) as f:
            report = json.load(f)
        out = read_mesh(dst)
        st = mesh_stats(out)
        topo = topology_change(ref, out)
        kept = boundary_kept(ref, out)
        rows.append(row_of(key, label, st, report.get("seconds"),
                           {"topology": topo, "boundary_kept": bool(kept),
                            "fixed_nodes_cli": report.get("fixed_nodes"),
                            "fixed_nodes_bench": init["nodes"] - init["free_nodes"]}))
        outputs[key] = dst
        log(f"Info    : {case}-{size}: {label}: q*min {st['q_min_star']:.4f} q_mean "
            f"{st['q_mean']:.4f} ({report.get('seconds'):.2f} s)")
    def rho_text(v, vr, r):
        if v == "valid+monotone":
            return f"{vr}+{r} rho values"
        return f"{r} rho values"
    starts = [(f"seq-{v}-r{vr}+{r}" if v == "valid+monotone" else f"seq-{v}-r{r}",
               f"GETMe sequential {v}, {rho_text(v, vr, r)}", ref, v, vr, r)
              for v, vr, r in args.compare_runs]
    for key in args.post:
        starts.append((f"{key}+seq", f"{dict((k, l) for k, l, _ in GETME_RUNS)[key]}"
                       f" + GETMe sequential {args.variant}, "
                       f"{rho_text(args.variant, args.valid_relax, args.relax)}",
                       seed_free(ref, outputs[key]), args.variant, args.valid_relax,
                       args.relax))
    for key, label, start, variant, vrelax, relax in starts:
        log(f"Info    : {case}-{size}: running {label}")
        seq, res = run_sequential(core, start, args, tag=f"{case}-{size} {key} ",
                                  relax_count=relax, variant=variant,
                                  valid_relax_count=vrelax)
        out = Mesh(seq.points(), ref.blocks, ref.regions, ref.tags)
        st = mesh_stats(out)
        lib_qmin = res["q_min_star"]
        if abs(lib_qmin - st["q_min_star"]) > 1e-9:
            log(f"Warning : libgetme q*min {lib_qmin} vs numpy {st['q_min_star']}")
        hist = res.pop("history")
        rows.append(row_of(key, label, st, res["seconds"],
                           {"topology": topology_change(ref, out),
                            "boundary_kept": bool(boundary_kept(ref, out)),
                            "run": res, "history": hist}))
        log(f"Info    : {case}-{size}: {label}: q*min {st['q_min_star']:.4f} q_mean "
            f"{st['q_mean']:.4f} ({res['steps']} steps, {res['accepted']} accepted, "
            f"stop {res['stop']}, {res['seconds']:.1f} s)")
    for p in outputs.values():
        for f in (p, p[:-4] + ".json"):
            if os.path.exists(f):
                os.remove(f)
    return {"case": case, "size": size, "mesh": os.path.basename(src),
            "distorted": os.path.basename(dist), "elements": init["elements"],
            "nodes": init["nodes"], "free_nodes": init["free_nodes"], "rows": rows}


def markdown(results, meta):
    lines = [f"# GETMe sequential baseline vs getme smooth ({meta['date']})", "",
             f"CPU: {meta['cpu']}; load average at start {meta['load'][0]:.2f} "
             "(shared machine: times are indicative).  getme runs with 1 thread; "
             "sequential is single-threaded Python over libgetme's "
             "element calls (its time is not comparable with C).  q*min / q_mean "
             "measured by bench/stats.py on every result.", "",
             f"Sequential: sigma {meta['sigma']}, rho = 1, 1/2, 1/4, ... (the "
             "number of values is in each row; valid+monotone: valid phase + "
             "monotone phase), "
             f"penalty {meta['penalty']}, steps = {meta['steps_rule']}, "
             f"patience = {meta['patience_rule']}.  Command: `{meta['command']}`", ""]
    for r in results:
        lines += [f"## {r['case']}-{r['size']}: {r['elements']} elements, "
                  f"{r['nodes']} nodes ({r['free_nodes']} free)", "",
                  "| method | q*min | q_mean | invalid | time s | steps (accepted) / stop |",
                  "|---|---|---|---|---|---|"]
        for row in r["rows"]:
            run = row.get("run")
            steps = (f"{run['steps']} ({run['accepted']}) / {run['stop']}"
                     if run else "")
            t = "" if row["seconds"] is None else f"{row['seconds']:.2f}"
            lines.append(f"| {row['label']} | {row['q_min_star']:.4f} | "
                         f"{row['q_mean']:.4f} | {row['invalid']} | {t} | {steps} |")
        done = r["rows"][1:]
        bad = [row["method"] for row in done if row.get("topology") != "no"
               or not row.get("boundary_kept") or row["invalid"]]
        fixed = {(row.get("fixed_nodes_cli"), row.get("fixed_nodes_bench"))
                 for row in done if row.get("fixed_nodes_cli") is not None}
        lines += ["", "Checks: " + ("every row keeps the topology and the fixed "
                                    "nodes, no invalid element" if not bad else
                                    f"PROBLEM in {', '.join(bad)}")
                  + "; fixed nodes getme CLI / bench skin: "
                  + ", ".join(f"{a} / {b}" for a, b in sorted(fixed)) + "."]
        by = {row["method"]: row for row in r["rows"]}
        seqs = [row for row in r["rows"] if row["method"].startswith("seq-")]
        if seqs and "getme" in by:
            best = max(seqs, key=lambda row: row["q_min_star"])
            d = by["getme"]["q_min_star"] - best["q_min_star"]
            lines += ["", f"getme default minus the best sequential run from the "
                      f"distorted mesh ({best['method']}): q*min {d:+.4f}, q_mean "
                      f"{by['getme']['q_mean'] - best['q_mean']:+.4f}."]
        lines.append("")
    return "\n".join(lines)


def cmd_compare(args):
    import runner
    core = load_core(args.lib)
    cli = cli_path()
    work = os.path.join(args.cache, "runs-sequential")
    os.makedirs(work, exist_ok=True)
    meta = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "cpu": runner.cpu_name(), "load": runner.load_average(),
            "sigma": args.sigma, "penalty": args.penalty,
            "steps_rule": (str(args.steps) if args.steps else
                           "max(200000, 50 x elements)"),
            "patience_rule": (str(args.patience) if args.patience else
                              "max(50000, 5 x elements)"),
            "command": "/usr/bin/python3 bench/sequential.py " + " ".join(sys.argv[1:]),
            "getme": cli}
    results = []
    for size in args.sizes:
        for case in args.cases:
            results.append(compare_case(core, cli, case, size, args, work))
    text = markdown(results, meta)
    print(text, flush=True)
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "sequential.md"), "w") as f:
        f.write(text)
    with open(os.path.join(args.out, "sequential.json"), "w") as f:
        json.dump({"meta": meta, "results": results}, f, indent=1)
    log(f"Info    : written {args.out}/sequential.{{md,json}}")
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh", nargs="?", help="MSH mesh (planar tri/quad or volume)")
    ap.add_argument("-o", "--output", help="write the result (same format, via Gmsh)")
    ap.add_argument("--json", help="write before/after statistics and the run as JSON")
    ap.add_argument("--steps", type=int, default=0,
                    help="maximum picks per phase (default max(200000, 50 x elements))")
    ap.add_argument("--patience", type=int, default=0,
                    help="stop after this many picks without a q*min rise "
                         "(default max(50000, 5 x elements))")
    ap.add_argument("--sigma", type=float, default=1.5)
    ap.add_argument("--penalty", type=float, default=0.01,
                    help="added to a rejected element's key (cleared when its "
                         "nodes move)")
    ap.add_argument("--relax", type=int, default=DEFAULT_RELAX,
                    help="relaxation factors tried: 1, 1/2, ... (this many; "
                         f"default {DEFAULT_RELAX})")
    ap.add_argument("--variant", choices=VARIANTS, default="valid+monotone",
                    help="monotone: a step must raise the min around the moved "
                         "nodes; valid: any valid step, best mesh kept; "
                         "valid+monotone (default, the strongest measured): the "
                         "one, then the other from valid's best mesh")
    ap.add_argument("--valid-relax", type=int, default=4,
                    help="valid+monotone: rho values of the valid phase (default 4: "
                         "with many tiny rho nearly every step is valid, nothing is "
                         "penalized and the loop stalls on the worst element)")
    ap.add_argument("--compare-runs", default=COMPARE_RUNS,
                    help="--compare: VARIANT:RELAX runs from the distorted mesh "
                         "(valid+monotone:VALID_RELAX+RELAX)")
    ap.add_argument("--seed-free", metavar="FILE",
                    help="start from FILE's free-node positions (same mesh, e.g. "
                         "getme's output): sequential as a post-process")
    ap.add_argument("--progress", type=int, default=0,
                    help="progress line every N picks (default steps/50, >= 10000)")
    ap.add_argument("--lib", help="libgetme.so (default: the build tree's)")
    ap.add_argument("--compare", action="store_true")
    ap.add_argument("--render", action="store_true",
                    help="rewrite --out's sequential.md from its sequential.json")
    ap.add_argument("--sizes", default="quick,small")
    ap.add_argument("--cases", default="tri,quad")
    ap.add_argument("--post", default="getme,adaptive",
                    help="--compare: getme runs sequential also post-processes")
    ap.add_argument("--cache", default=os.environ.get("GETME_BENCH_CACHE", "/work/cache"))
    ap.add_argument("--out", default=os.path.join(HERE, "results", "sequential"))
    args = ap.parse_args(argv)
    args.sizes = [s for s in args.sizes.split(",") if s]
    args.cases = [c for c in args.cases.split(",") if c]
    args.post = [p for p in args.post.split(",") if p]
    runs = []
    for r in (r for r in args.compare_runs.split(",") if r):
        variant, rho = r.split(":")
        counts = [int(c) for c in rho.split("+")]
        runs.append((variant, counts[0] if len(counts) > 1 else args.valid_relax,
                     counts[-1]))
    args.compare_runs = runs
    bad = [v for v, _, _ in args.compare_runs if v not in VARIANTS]
    if bad:
        ap.error(f"unknown variant(s) {bad}")
    if args.render:
        with open(os.path.join(args.out, "sequential.json")) as f:
            data = json.load(f)
        text = markdown(data["results"], data["meta"])
        with open(os.path.join(args.out, "sequential.md"), "w") as f:
            f.write(text)
        print(text)
        return 0
    if args.compare:
        return cmd_compare(args)
    if not args.mesh:
        ap.error("a mesh, or --compare")
    return cmd_single(args)


if __name__ == "__main__":
    try:
        sys.exit(main())
    except RuntimeError as exc:
        log(f"Error   : {exc}")
        sys.exit(1)
