#!/usr/bin/python3
"""Untangling benchmark (issue #12): tangle structured meshes of a few
hundred thousand elements, untangle them with getme_mesh_untangle(), then
smooth them with getme_smooth(), and print time, invalid elements before /
after, and q_min, q_mean after untangling and after smoothing.

  /usr/bin/python3 bench/untangle.py --lib build/core/libgetme.so
        [--cases tet,hex,prism,mixed] [--cells N] [--fraction F] [--seed S]
        [--push MIN,MAX] [--threads 1,2] [--json FILE]

Meshes: an N^3 grid of unit cubes (N = 40 by default) as hexes, 6 Kuhn
tets per cube, 2 prisms per cube, or cubes alternately hexes and 6
pyramids around a centre node (mixed).  Tangling: a fraction F (default
0.01) of the interior grid nodes, drawn with a fixed seed, are pushed by a
random vector of length MIN-MAX (0.8-1.6) cell sizes, through their neighbours.  The
skin is fixed (getme_mesh_fix_boundary).  Qualities are libgetme's mean
ratio (q = 0 for an invalid element).  Untangling is run with each thread
count and the outputs are compared byte for byte.
"""

import argparse
import ctypes as C
import json
import sys
import time

import numpy as np

TYPES = {"tet": 0, "hex": 1, "prism": 2, "pyramid": 3}
MAXREP = 8


class UntangleResult(C.Structure):  # getme_untangle_result of getme.h
    _fields_ = [("num_invalid_before", C.c_int64), ("num_invalid_after", C.c_int64),
                ("num_stuck", C.c_int64), ("num_reported", C.c_int32),
                ("remaining", C.c_int32 * MAXREP), ("num_moved", C.c_int32),
                ("sweeps", C.c_int), ("rings", C.c_int), ("seconds", C.c_double)]


class Stats(C.Structure):  # getme_quality_stats
    _fields_ = [("num_elements", C.c_int64), ("num_invalid", C.c_int64),
                ("num_free", C.c_int64), ("q_min", C.c_double),
                ("q_min_star", C.c_double), ("q_mean", C.c_double),
                ("q_max", C.c_double), ("num_below_04", C.c_int64),
                ("num_below_01", C.c_int64), ("histogram", C.c_int64 * 10),
                ("num_reported_invalid", C.c_int32),
                ("first_invalid", C.c_int32 * MAXREP)]


def load(path):
    lib = C.CDLL(path)
    lib.getme_mesh_create.argtypes = [C.POINTER(C.c_void_p), C.c_int, C.c_int32, C.c_void_p]
    lib.getme_mesh_add_elements.argtypes = [C.c_void_p, C.c_int, C.c_int32, C.c_void_p,
                                            C.c_void_p]
    lib.getme_mesh_fix_boundary.argtypes = [C.c_void_p, C.c_uint, C.c_void_p]
    lib.getme_mesh_free.argtypes = [C.c_void_p]
    lib.getme_mesh_error.restype = C.c_char_p
    lib.getme_mesh_error.argtypes = [C.c_void_p]
    lib.getme_mesh_get_coords.argtypes = [C.c_void_p, C.c_void_p]
    lib.getme_mesh_quality_stats.argtypes = [C.c_void_p, C.c_int, C.POINTER(Stats)]
    lib.getme_mesh_untangle.argtypes = [C.c_void_p, C.c_void_p,
                                        C.POINTER(UntangleResult)]
    lib.getme_smooth.argtypes = [C.c_void_p, C.c_void_p, C.c_void_p]
    # getme_params stays opaque here: a buffer of its size, set by name
    # through libgetme's parameter table (getme_params_set).
    lib.getme_params_init.argtypes = [C.c_void_p]
    lib.getme_params_sizeof.restype = C.c_size_t
    lib.getme_params_set.argtypes = [C.c_void_p, C.c_char_p, C.c_double]
    return lib


def params(lib, num_threads):
    p = C.create_string_buffer(lib.getme_params_sizeof())
    lib.getme_params_init(p)
    if lib.getme_params_set(p, b"num_threads", float(num_threads)) != 0:
        raise RuntimeError("getme_params_set num_threads failed")
    return p


# ---- meshes ---------------------------------------------------------------

def grid(n):
    r = np.arange(n + 1, dtype=np.float64)
    z, y, x = np.meshgrid(r, r, r, indexing="ij")
    pts = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    i, j, k = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    i, j, k = k.ravel(), j.ravel(), i.ravel()  # x fastest

    def g(a, b, c):
        return (i + a) + (n + 1) * ((j + b) + (n + 1) * (k + c))
    hexes = np.stack([g(0, 0, 0), g(1, 0, 0), g(1, 1, 0), g(0, 1, 0),
                      g(0, 0, 1), g(1, 0, 1), g(1, 1, 1), g(0, 1, 1)], axis=1)
    return pts, hexes, (i, j, k)


def orient_tets(pts, tets):
    e = pts[tets[:, 1:]] - pts[tets[:, :1]]
    det = np.einsum("ij,ij->i", e[:, 0], np.cross(e[:, 1], e[:, 2]))
    neg = det < 0
    tets[neg, 1], tets[neg, 2] = tets[neg, 2].copy(), tets[neg, 1].copy()
    return tets


def make(case, n):
    pts, h, (i, j, k) = grid(n)
    if case == "hex":
        return pts, [("hex", h)]
    if case == "tet":  # Kuhn: 6 tets around the diagonal 0-6 of every cube
        paths = [(1, 2), (2, 3), (3, 7), (7, 4), (4, 5), (5, 1)]
        tets = np.concatenate([np.stack([h[:, 0], h[:, a], h[:, b], h[:, 6]], axis=1)
                               for a, b in paths])
        return pts, [("tet", orient_tets(pts, tets))]
    if case == "prism":
        p1 = h[:, [0, 1, 2, 4, 5, 6]]
        p2 = h[:, [0, 2, 3, 4, 6, 7]]
        return pts, [("prism", np.concatenate([p1, p2]))]
    # mixed: a checkerboard of hexes and cubes split into 6 pyramids
    split = (i + j + k) % 2 == 1
    hs = h[split]
    centre = len(pts) + np.arange(len(hs))
    cpts = (pts[hs[:, 0]] + pts[hs[:, 6]]) / 2
    faces = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (3, 2, 6, 7), (0, 3, 7, 4),
             (1, 5, 6, 2)]  # inward normals
    pyr = np.concatenate([np.stack([hs[:, a], hs[:, b], hs[:, c], hs[:, d], centre],
                                   axis=1) for a, b, c, d in faces])
    return np.concatenate([pts, cpts]), [("hex", h[~split]), ("pyramid", pyr)]


def tangle(pts, n, fraction, seed, push=(0.8, 1.6)):
    rng = np.random.default_rng(seed)
    ijk = np.stack(np.meshgrid(np.arange(n + 1), np.arange(n + 1), np.arange(n + 1),
                               indexing="ij"), axis=-1).reshape(-1, 3)[:, ::-1]
    interior = np.flatnonzero(np.all((ijk >= 2) & (ijk <= n - 2), axis=1))
    pick = rng.choice(interior, size=max(1, int(fraction * len(interior))), replace=False)
    d = rng.normal(size=(len(pick), 3))
    d *= (rng.uniform(push[0], push[1], size=len(pick)) / np.linalg.norm(d, axis=1))[:, None]
    out = pts.copy()
    out[pick] += d
    return out, len(pick)


def build(lib, pts, blocks):
    m = C.c_void_p()
    pts = np.ascontiguousarray(pts)
    if lib.getme_mesh_create(C.byref(m), 3, len(pts), pts.ctypes.data):
        raise RuntimeError("getme_mesh_create failed")
    for kind, conn in blocks:
        c = np.ascontiguousarray(conn, dtype=np.int32)
        if lib.getme_mesh_add_elements(m, TYPES[kind], len(c), c.ctypes.data, None):
            raise RuntimeError(lib.getme_mesh_error(m).decode())
    lib.getme_mesh_fix_boundary(m, 3, None)
    return m


def stats(lib, m):
    s = Stats()
    lib.getme_mesh_quality_stats(m, -1, C.byref(s))
    return s


def coords(lib, m, nn):
    out = np.empty((nn, 3))
    lib.getme_mesh_get_coords(m, out.ctypes.data)
    return out


def run_case(lib, case, args):
    pts, blocks = make(case, args.cells)
    tpts, pushed = tangle(pts, args.cells, args.fraction, args.seed, args.push)
    ne = sum(len(c) for _, c in blocks)
    rows, ref = [], None
    for nt in args.threads:
        p = params(lib, nt)
        m = build(lib, tpts, blocks)
        before = stats(lib, m)
        ur = UntangleResult()
        t0 = time.perf_counter()
        st = lib.getme_mesh_untangle(m, p, C.byref(ur))
        wall = time.perf_counter() - t0
        after_u = stats(lib, m)
        x = coords(lib, m, len(tpts))
        same = None
        if ref is None:
            ref = x
        else:
            same = bool(np.array_equal(ref.view(np.uint64), x.view(np.uint64)))
        t0 = time.perf_counter()
        sst = lib.getme_smooth(m, p, None) if st == 0 else -1
        smooth_seconds = time.perf_counter() - t0
        after_s = stats(lib, m) if sst == 0 else None
        lib.getme_mesh_free(m)
        row = {"case": case, "elements": ne, "nodes": len(tpts), "pushed_nodes": pushed,
               "threads": nt, "status": st, "invalid_before": before.num_invalid,
               "invalid_after": ur.num_invalid_after, "sweeps": ur.sweeps,
               "rings": ur.rings, "nodes_moved": ur.num_moved,
               "untangle_seconds": ur.seconds, "untangle_wall": wall,
               "q_min_untangled": after_u.q_min, "q_mean_untangled": after_u.q_mean,
               "q_mean_before": before.q_mean,
               "smooth_status": sst,
               "q_min_smoothed": after_s.q_min if after_s else None,
               "q_mean_smoothed": after_s.q_mean if after_s else None,
               "smooth_seconds": smooth_seconds if after_s else None,
               "same_as_1_thread": same}
        rows.append(row)
        print("%-6s %8d el %5d pushed %2d thr: invalid %5d -> %d in %.3f s (%d sweeps, "
              "%d rings, %d nodes moved); untangled q_min %.4f q_mean %.4f; smoothed "
              "q_min %s q_mean %s (%.2f s)%s" % (
                  case, ne, pushed, nt, before.num_invalid, ur.num_invalid_after,
                  ur.seconds, ur.sweeps, ur.rings, ur.num_moved, after_u.q_min,
                  after_u.q_mean,
                  "%.4f" % after_s.q_min if after_s else "-",
                  "%.4f" % after_s.q_mean if after_s else "-",
                  smooth_seconds if after_s else 0.0,
                  "" if same is None else ", bit-identical to 1 thread: %s" % same),
              flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lib", required=True)
    ap.add_argument("--cases", default="tet,hex,prism,mixed")
    ap.add_argument("--cells", type=int, default=40)
    ap.add_argument("--fraction", type=float, default=0.01)
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--push", default="0.8,1.6",
                    help="push lengths in cell sizes, MIN,MAX (default 0.8,1.6)")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--json")
    args = ap.parse_args()
    args.threads = [int(t) for t in args.threads.split(",")]
    args.push = tuple(float(v) for v in args.push.split(","))
    lib = load(args.lib)
    rows = []
    for case in args.cases.split(","):
        rows += run_case(lib, case, args)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    bad = [r for r in rows if r["invalid_after"] or r["same_as_1_thread"] is False]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
