#!/usr/bin/python3
"""Tests of the benchmark's own yardstick: bench/quality.py and bench/skin.py.

  test_quality.py --bench DIR [--lib libgetme.so]

The benchmark judges every tool's output with these numpy functions, so they
must be right on their own: exact 1 on regular elements, invariant under
translation, rotation and uniform scaling, 0 on inverted elements, the
triangle/quad formulas equal to the general polygon mean ratio (docs/design.md
§1), and -- with --lib -- equal to libgetme's getme_element_quality()
on random elements of every type (two independent implementations of one
definition).
"""

import argparse
import ctypes
import sys
import unittest

import numpy as np

ARGS = None
S3 = np.sqrt(3.0)
REGULAR = {
    "tet": [[0, 0, 0], [1, 0, 0], [0.5, S3 / 2, 0], [0.5, S3 / 6, np.sqrt(2 / 3)]],
    "hex": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
            [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    "prism": [[0, 0, 0], [1, 0, 0], [0.5, S3 / 2, 0],
              [0, 0, 1], [1, 0, 1], [0.5, S3 / 2, 1]],
    "pyramid": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                [0.5, 0.5, 1 / np.sqrt(2)]],
    "tri": [[0, 0, 0], [1, 0, 0], [0.5, S3 / 2, 0]],
    "quad": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
}
TYPE_ID = {"tet": 0, "hex": 1, "prism": 2, "pyramid": 3, "tri": 4, "quad": 5}


def q_of(etype, pts):
    """Quality of one element given as a point list."""
    from quality import element_quality
    pts = np.asarray(pts, dtype=float)
    return element_quality(pts, [list(range(len(pts)))], etype)[0]


def perturbed(etype, rng, amount=0.15):
    """A random valid element near the regular one."""
    base = np.asarray(REGULAR[etype], dtype=float)
    while True:
        pts = base + rng.uniform(-amount, amount, base.shape)
        if etype in ("tri", "quad"):
            pts[:, 2] = 0.0
        if q_of(etype, pts) > 0.05:
            return pts


def rotation(rng, planar):
    if planar:
        a = rng.uniform(0, 2 * np.pi)
        return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q @ np.diag(np.sign(np.diag(r)))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def polygon_mean_ratio(xy):
    """docs/design.md §1: q = (2/n) sum delta_k / phi_k."""
    n = len(xy)
    alpha, beta = 1 - np.cos(2 * np.pi / n), np.sin(2 * np.pi / n)
    total = 0.0
    for k in range(n):
        e1 = xy[(k + 1) % n] - xy[k]
        e2 = xy[(k - 1) % n] - xy[k]
        delta = (e1[0] * e2[1] - e1[1] * e2[0]) / (2 * alpha * beta)
        phi = np.sum((e1 - e2) ** 2) / (4 * beta ** 2) + np.sum((e1 + e2) ** 2) / (4 * alpha ** 2)
        if delta <= 0:
            return 0.0
        total += delta / phi
    return 2.0 / n * total


class QualityTest(unittest.TestCase):
    def test_regular_is_one(self):
        for etype, pts in REGULAR.items():
            self.assertAlmostEqual(q_of(etype, pts), 1.0, places=12, msg=etype)

    def test_invariance(self):
        rng = np.random.default_rng(7)
        for etype in REGULAR:
            for _ in range(20):
                pts = perturbed(etype, rng)
                q = q_of(etype, pts)
                rot = rotation(rng, etype in ("tri", "quad"))
                moved = (pts @ rot.T) * rng.uniform(0.01, 100.0) + rng.uniform(-50, 50, 3)
                if etype in ("tri", "quad"):
                    moved[:, 2] = 0.0
                self.assertAlmostEqual(q_of(etype, moved), q, places=10, msg=etype)
                self.assertLess(q, 1.0)

    def test_inverted_and_degenerate_are_zero(self):
        for etype, pts in REGULAR.items():
            pts = np.asarray(pts, dtype=float)
            mirrored = pts * np.array([-1.0, 1.0, 1.0])
            if etype in ("tri", "quad"):
                # a planar mesh is judged by its orientation as a whole: one
                # clockwise element among counter-clockwise ones is invalid
                from quality import element_quality
                both = np.vstack([pts, mirrored])
                n = len(pts)
                q = element_quality(both, [list(range(n)), list(range(n, 2 * n))], etype)
                self.assertGreater(q[0], 0.99)
                self.assertEqual(q[1], 0.0)
            else:
                self.assertEqual(q_of(etype, mirrored), 0.0, msg=etype)
            self.assertEqual(q_of(etype, np.zeros_like(pts)), 0.0, msg=etype)
            bad = pts.copy()
            bad[0, 0] = np.nan
            self.assertEqual(q_of(etype, bad), 0.0, msg=etype)

    def test_planar_formulas_match_polygon_mean_ratio(self):
        rng = np.random.default_rng(3)
        for etype in ("tri", "quad"):
            for _ in range(50):
                pts = perturbed(etype, rng, 0.3)
                self.assertAlmostEqual(q_of(etype, pts), polygon_mean_ratio(pts[:, :2]),
                                       places=12, msg=etype)

    def test_known_values(self):
        # a right isosceles triangle: 4 sqrt(3) (1/2) / (1 + 1 + 2) = sqrt(3)/2
        self.assertAlmostEqual(q_of("tri", [[0, 0, 0], [1, 0, 0], [0, 1, 0]]), S3 / 2, places=14)
        # a 2 x 1 rectangle: every corner 2*2/(4+1) = 0.8
        self.assertAlmostEqual(q_of("quad", [[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]]),
                               0.8, places=14)
        # a 2 x 1 x 1 box: every corner 3 * 2^(2/3) / 6
        box = np.asarray(REGULAR["hex"], dtype=float) * [2, 1, 1]
        self.assertAlmostEqual(q_of("hex", box), 3 * 2 ** (2 / 3) / 6, places=14)

    def test_agrees_with_libgetme(self):
        if not ARGS.lib:
            self.skipTest("no --lib given")
        lib = ctypes.CDLL(ARGS.lib)
        lib.getme_element_quality.restype = ctypes.c_double
        lib.getme_element_quality.argtypes = [ctypes.c_int, ctypes.c_void_p]
        rng = np.random.default_rng(11)
        for etype in REGULAR:
            for _ in range(200):
                pts = np.ascontiguousarray(perturbed(etype, rng, 0.3))
                theirs = lib.getme_element_quality(TYPE_ID[etype], pts.ctypes.data)
                self.assertAlmostEqual(q_of(etype, pts), theirs, places=12, msg=etype)


class SkinTest(unittest.TestCase):
    def grid_hexes(self, n):
        """n^3 unit hexes of an (n+1)^3 node grid, Gmsh node order."""
        idx = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)  # [z, y, x]
        conn = []
        for k in range(n):
            for j in range(n):
                for i in range(n):
                    conn.append([idx[k, j, i], idx[k, j, i + 1], idx[k, j + 1, i + 1],
                                 idx[k, j + 1, i], idx[k + 1, j, i], idx[k + 1, j, i + 1],
                                 idx[k + 1, j + 1, i + 1], idx[k + 1, j + 1, i]])
        return np.array(conn)

    def test_hex_grid_skin(self):
        from skin import fixed_mask, free_elements
        conn = self.grid_hexes(3)
        fixed = fixed_mask(64, [("hex", conn)], [np.zeros(27, int)])
        self.assertEqual(int(np.count_nonzero(~fixed)), 8)  # the 2x2x2 inner nodes
        self.assertEqual(int(np.count_nonzero(free_elements(conn, fixed))), 27)

    def test_region_interface_is_fixed(self):
        from skin import fixed_mask
        conn = self.grid_hexes(4)
        # the lower two layers are region 1, the upper two region 2: the
        # 3x3 inner nodes of the middle plane become fixed
        regions = np.where(np.arange(64) < 32, 1, 2)
        free_one = ~fixed_mask(125, [("hex", conn)], [np.ones(64, int)])
        free_two = ~fixed_mask(125, [("hex", conn)], [regions])
        self.assertEqual(int(free_one.sum()), 27)
        self.assertEqual(int(free_two.sum()), 18)

    def test_unused_nodes_are_fixed(self):
        from skin import fixed_mask
        conn = self.grid_hexes(2)
        fixed = fixed_mask(30, [("hex", conn)], [np.zeros(8, int)])
        self.assertTrue(fixed[27:].all())
        self.assertEqual(int((~fixed).sum()), 1)


def main():
    global ARGS
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", required=True, help="the bench/ directory")
    ap.add_argument("--lib", help="libgetme.so, to compare with the core")
    ARGS, rest = ap.parse_known_args()
    sys.path.insert(0, ARGS.bench)
    prog = unittest.main(argv=[sys.argv[0]] + rest, exit=False, verbosity=1)
    res = prog.result
    failed = len(res.failures) + len(res.errors)
    print(f"bench_quality: {res.testsRun - failed - len(res.skipped)} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
