#!/usr/bin/python3
"""A stand-in for the `getme` CLI that drives libgetme through ctypes.
bench.py runs it instead of the CLI only when told to (`--getme-runner
ctypes`) or when the CLI at hand cannot read .msh files (`--getme-runner
auto` and `getme formats` lists no msh; today's CLI always can).
bench/untangle.py borrows its Params and Result structures.

  getme_ctypes.py --lib libgetme.so smooth IN -o OUT [--method getme|laplace]
                  [--threads N] [--report R.json] [--param NAME=VALUE ...]
  getme_ctypes.py --lib libgetme.so distort IN -o OUT --seed S [--target-qmean Q]
  getme_ctypes.py --lib libgetme.so quality IN

Same library calls and the same --report JSON keys as the CLI (the subset
bench.py reads).  Fixed nodes are the skin and region interfaces
(getme_mesh_fix_boundary), regions being the Gmsh physical tags -- what the
CLI fixes on the benchmark's meshes.  Output: the input opened with the Gmsh
API, moved nodes set, written as binary MSH (entities, classification and
tags unchanged).  Used only by the benchmark; smoothing time is
getme_smooth() alone, as in the CLI.
"""

import argparse
import ctypes as C
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from meshdata import read_mesh, write_points  # noqa: E402

TYPES = {"tet": 0, "hex": 1, "prism": 2, "pyramid": 3, "tri": 4, "quad": 5}
MAX_RELAX = 16


class Progress(C.Structure):
    _fields_ = [("iteration", C.c_int), ("stage", C.c_int), ("cycle", C.c_int),
                ("q_min_star", C.c_double), ("q_mean", C.c_double),
                ("threshold", C.c_double), ("num_transformed", C.c_int32),
                ("num_relaxed", C.c_int32), ("elapsed", C.c_double)]


PROGRESS_FN = C.CFUNCTYPE(C.c_int, C.POINTER(Progress), C.c_void_p)


class Params(C.Structure):  # getme_params of getme.h
    _fields_ = [("method", C.c_int), ("max_iter", C.c_int), ("tol", C.c_double),
                ("sigma", C.c_double), ("num_relax_mean", C.c_int),
                ("relax_mean", C.c_double * MAX_RELAX), ("num_relax_min", C.c_int),
                ("relax_min", C.c_double * MAX_RELAX),
                ("max_no_min_improve", C.c_int), ("min_tol", C.c_double),
                ("threshold_fraction", C.c_double), ("keep_best", C.c_int),
                ("finish", C.c_int), ("finish_fraction", C.c_double),
                ("finish_max_passes", C.c_int), ("corner_guard", C.c_int),
                ("corner_floor", C.c_double),
                ("num_threads", C.c_int), ("renumber", C.c_int),
                ("untangle", C.c_int),
                ("progress", PROGRESS_FN), ("progress_data", C.c_void_p)]


class Result(C.Structure):
    _fields_ = [("iterations", C.c_int), ("iterations_mean", C.c_int),
                ("iterations_min", C.c_int), ("cycles_min", C.c_int),
                ("passes_finish", C.c_int), ("moved_finish", C.c_int32),
                ("corner_sj_initial", C.c_double), ("corner_sj", C.c_double),
                ("q_min_star_initial", C.c_double), ("q_mean_initial", C.c_double),
                ("q_min_star", C.c_double), ("q_mean", C.c_double),
                ("q_min", C.c_double), ("threshold", C.c_double),
                ("seconds", C.c_double), ("stop_reason", C.c_int),
                ("num_invalid_initial", C.c_int64), ("untangle_sweeps", C.c_int),
                ("untangle_seconds", C.c_double)]


class Lib:
    def __init__(self, path):
        lib = C.CDLL(path)
        lib.getme_mesh_create.argtypes = [C.POINTER(C.c_void_p), C.c_int, C.c_int32, C.c_void_p]
        lib.getme_mesh_add_elements.argtypes = [C.c_void_p, C.c_int, C.c_int32,
                                                C.c_void_p, C.c_void_p]
        lib.getme_mesh_fix_boundary.argtypes = [C.c_void_p, C.c_uint, C.POINTER(C.c_int32)]
        lib.getme_mesh_error.restype = C.c_char_p
        lib.getme_mesh_error.argtypes = [C.c_void_p]
        lib.getme_mesh_get_coords.argtypes = [C.c_void_p, C.c_void_p]
        lib.getme_mesh_free.argtypes = [C.c_void_p]
        lib.getme_smooth.argtypes = [C.c_void_p, C.POINTER(Params), C.POINTER(Result)]
        lib.getme_params_init.argtypes = [C.POINTER(Params)]
        lib.getme_params_set.argtypes = [C.POINTER(Params), C.c_char_p, C.c_double]
        lib.getme_params_sizeof.restype = C.c_size_t
        lib.getme_mesh_distort.argtypes = [C.c_void_p, C.c_uint64, C.c_double,
                                           C.c_double, C.c_int]
        lib.getme_mesh_num_fixed.argtypes = [C.c_void_p]
        if lib.getme_params_sizeof() != C.sizeof(Params):
            raise RuntimeError("getme_params layout differs from getme.h's")
        self.lib = lib

    def check(self, status, mesh, what):
        if status != 0:
            msg = self.lib.getme_mesh_error(mesh).decode() if mesh else ""
            raise RuntimeError(f"{what} failed ({status}): {msg}")


def build(lib, mesh):
    handle = C.c_void_p()
    pts = np.ascontiguousarray(mesh.points, dtype=np.float64)
    lib.check(lib.lib.getme_mesh_create(C.byref(handle), mesh.dim, len(pts),
                                        pts.ctypes.data), None, "getme_mesh_create")
    for (etype, conn), reg in zip(mesh.blocks, mesh.regions):
        c = np.ascontiguousarray(conn, dtype=np.int32)
        r = np.ascontiguousarray(reg, dtype=np.int32)
        lib.check(lib.lib.getme_mesh_add_elements(handle, TYPES[etype], len(c),
                                                  c.ctypes.data, r.ctypes.data),
                  handle, "getme_mesh_add_elements")
    lib.check(lib.lib.getme_mesh_fix_boundary(handle, 3, None), handle,
              "getme_mesh_fix_boundary")
    return handle


def write(lib, handle, mesh, src, path):
    """Write src again with the new coordinates (meshdata.write_points)."""
    pts = np.empty_like(mesh.points)
    lib.check(lib.lib.getme_mesh_get_coords(handle, pts.ctypes.data), handle, "get_coords")
    write_points(src, mesh, pts, path, app="getme_ctypes")


def cmd_smooth(lib, args):
    mesh = read_mesh(args.input)
    handle = build(lib, mesh)
    params = Params()
    lib.lib.getme_params_init(C.byref(params))
    settings = [("method", 0.0 if args.method == "getme" else 1.0),
                ("num_threads", float(args.threads))]
    settings += [(p.split("=")[0], float(p.split("=")[1])) for p in args.param]
    for name, value in settings:
        lib.check(lib.lib.getme_params_set(C.byref(params), name.encode(), value),
                  None, f"parameter {name}")
    history = []

    def progress(p, _data):
        q = p.contents
        history.append({"iteration": q.iteration, "stage": q.stage, "cycle": q.cycle,
                        "q_min_star": q.q_min_star, "q_mean": q.q_mean,
                        "threshold": q.threshold, "elapsed": q.elapsed})
        return 0

    params.progress = PROGRESS_FN(progress)
    res = Result()
    lib.check(lib.lib.getme_smooth(handle, C.byref(params), C.byref(res)), handle,
              "getme_smooth")
    write(lib, handle, mesh, args.input, args.output)
    if args.report:
        report = {"runner": "getme_ctypes", "method": args.method,
                  "fixed_nodes": lib.lib.getme_mesh_num_fixed(handle),
                  "after": {"q_min_star": res.q_min_star, "q_mean": res.q_mean},
                  "iterations": {"total": res.iterations,
                                 "mean_stage": res.iterations_mean,
                                 "min_stage": res.iterations_min,
                                 "min_cycles": res.cycles_min},
                  "seconds": res.seconds, "history": history}
        with open(args.report, "w") as f:
            json.dump(report, f)
    lib.lib.getme_mesh_free(handle)


def cmd_distort(lib, args):
    mesh = read_mesh(args.input)
    handle = build(lib, mesh)
    rounds = 100 if args.target_qmean > 0 else args.rounds
    lib.check(lib.lib.getme_mesh_distort(handle, args.seed, args.amount,
                                         args.target_qmean, rounds), handle, "distort")
    write(lib, handle, mesh, args.input, args.output)
    lib.lib.getme_mesh_free(handle)


def cmd_quality(lib, args):
    handle = build(lib, read_mesh(args.input))
    lib.lib.getme_mesh_free(handle)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lib", required=True)
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("smooth")
    s.add_argument("input")
    s.add_argument("-o", "--output", required=True)
    s.add_argument("--method", choices=("getme", "laplace"), default="getme")
    s.add_argument("--threads", type=int, default=0)
    s.add_argument("--report")
    s.add_argument("--param", action="append", default=[])
    d = sub.add_parser("distort")
    d.add_argument("input")
    d.add_argument("-o", "--output", required=True)
    d.add_argument("--seed", type=int, required=True)
    d.add_argument("--amount", type=float, default=0.5)
    d.add_argument("--rounds", type=int, default=1)
    d.add_argument("--target-qmean", type=float, default=0.0)
    q = sub.add_parser("quality")
    q.add_argument("input")
    args = ap.parse_args()
    try:
        lib = Lib(args.lib)
        {"smooth": cmd_smooth, "distort": cmd_distort, "quality": cmd_quality}[args.cmd](lib, args)
    except (RuntimeError, OSError) as exc:
        print(f"Error   : {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
