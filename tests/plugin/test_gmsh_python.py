"""getme.gmsh.optimize() through Debian's /usr/bin/python3 next to `import
gmsh`: one libgmsh in the process, a two-material OCC model with a named
fixed surface, distorted by our own validity-preserving moves, smoothed;
boundary / interface / fixed nodes bit-identical, tags unchanged, q*min up,
no invalid tet by a numpy mean ratio computed here; the result still writes
MSH and INP that meshio reads back.  Gmsh's own optimizers run on the same
distorted mesh for the comparison table.  Bad uses raise GetmeError with
the model unchanged."""
import os
import sys
import tempfile
import time

import gmsh
import numpy as np

import getme

FAILS = []


def check(cond, what):
    if not cond:
        FAILS.append(what)
        print("FAILED:", what)


def tet_quality(xyz, conn):
    """Mean ratio of linear tets, 12 (3V)^(2/3) / sum l^2; <= 0 invalid."""
    p = xyz[conn]
    a, b, c, d = p[:, 0], p[:, 1], p[:, 2], p[:, 3]
    det = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))
    l2 = sum(((p[:, i] - p[:, j]) ** 2).sum(1)
             for i in range(4) for j in range(i + 1, 4))
    q = 12.0 * np.cbrt((det / 2.0) ** 2) / l2
    return np.where(det > 0, q, 0.0)


def model_arrays():
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    order = np.argsort(tags)
    tags, xyz = tags[order], xyz.reshape(-1, 3)[order]
    etags, enodes = gmsh.model.mesh.getElementsByType(4)
    conn = np.searchsorted(tags, enodes).reshape(-1, 4)
    return tags, xyz, etags, conn


def boundary_nodes():
    out = {}
    for dim in range(3):
        for _, tag in gmsh.model.getEntities(dim):
            t, x, _ = gmsh.model.mesh.getNodes(dim, tag)
            out.update(zip(t.tolist(), x.reshape(-1, 3).tolist()))
    return out


def build_model():
    gmsh.model.add("two_materials")
    occ = gmsh.model.occ
    b1 = occ.addBox(0, 0, 0, 1, 1, 1)
    b2 = occ.addBox(1, 0, 0, 1, 1, 1)
    occ.fragment([(3, b1)], [(3, b2)])
    occ.synchronize()
    gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [1]),
                               "steel")
    gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [2]), "alu")
    face = gmsh.model.getEntitiesInBoundingBox(-.01, -.01, -.01,
                                               .01, 1.01, 1.01, 2)[0][1]
    gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [face], 10),
                               "clamp")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.1)
    gmsh.model.mesh.generate(3)


def distort(rounds=6, amount=0.5, seed=11):
    """Random moves of volume nodes, each kept only if every incident tet
    keeps a positive volume."""
    rng = np.random.default_rng(seed)
    tags, xyz, _, conn = model_arrays()
    free = set()
    for _, tag in gmsh.model.getEntities(3):
        free.update(gmsh.model.mesh.getNodes(3, tag)[0].tolist())
    free_idx = np.searchsorted(tags, sorted(free))
    incident = [[] for _ in range(len(tags))]
    for e, c in enumerate(conn):
        for n in c:
            incident[n].append(e)
    h = np.min([np.linalg.norm(xyz[c[0]] - xyz[c[1]]) for c in conn[:50]])
    for _ in range(rounds):
        for i in free_idx:
            old = xyz[i].copy()
            xyz[i] = old + rng.uniform(-amount, amount, 3) * h
            if tet_quality(xyz, conn[incident[i]]).min() <= 0:
                xyz[i] = old
    for i in free_idx:
        gmsh.model.mesh.setNode(int(tags[i]), xyz[i].tolist(), [])


def test_same_library():
    libs = getme.gmsh.loaded_gmsh_libraries()
    check(len(libs) == 1, "exactly one libgmsh mapped: %s" % libs)


def test_optimize(workdir):
    build_model()
    distort()
    gmsh.write(os.path.join(workdir, "distorted.msh"))
    bnd0 = boundary_nodes()
    clamp0 = gmsh.model.mesh.getNodesForPhysicalGroup(2, 10)
    tags0, xyz0, etags0, conn0 = model_arrays()
    q0 = tet_quality(xyz0, conn0)
    check(q0.min() > 0, "distorted mesh valid")

    t = time.time()
    res = getme.gmsh.optimize(fix=["clamp"], log=1)
    seconds = time.time() - t
    tags1, xyz1, etags1, conn1 = model_arrays()
    q1 = tet_quality(xyz1, conn1)
    check(np.array_equal(tags0, tags1), "node tags unchanged")
    check(np.array_equal(etags0, etags1) and np.array_equal(conn0, conn1),
          "element tags and connectivity unchanged")
    check(boundary_nodes() == bnd0,
          "nodes on surfaces, curves, points bit-identical")
    clamp1 = gmsh.model.mesh.getNodesForPhysicalGroup(2, 10)
    check(np.array_equal(clamp0[1], clamp1[1]), "clamp nodes bit-identical")
    check(q1.min() > 0, "no invalid tet (numpy mean ratio)")
    check(res["q_min_star_after"] > res["q_min_star_before"] + 0.05,
          "q*min improved: %s" % res)
    check(abs(q1.min() - res["q_min_after"]) < 1e-9,
          "numpy q_min %.12f == getme q_min %.12f"
          % (q1.min(), res["q_min_after"]))
    check(abs(q1.mean() - res["q_mean_after"]) < 1e-9, "numpy q_mean")
    moved = int((xyz0 != xyz1).any(axis=1).sum())
    check(moved == res["num_moved"] and moved > 100, "moved %d" % moved)

    stats = getme.quality(xyz1, {"tet": conn1})
    check(np.allclose(stats["qualities"], q1, rtol=0, atol=1e-12),
          "getme.quality(arrays) equals the numpy mean ratio")
    mq = getme.quality()
    check(abs(mq["q_mean"] - q1.mean()) < 1e-12, "getme.quality(model)")

    for ext in ("msh", "inp"):
        path = os.path.join(workdir, "smoothed." + ext)
        gmsh.write(path)
        check(os.path.getsize(path) > 0, "wrote " + ext)
    try:
        import meshio
        m = meshio.read(os.path.join(workdir, "smoothed.msh"))
        n_tets = sum(len(c.data) for c in m.cells if c.type == "tetra")
        check(n_tets == len(etags1), "meshio reads the MSH back")
        m = meshio.read(os.path.join(workdir, "smoothed.inp"))
        check(sum(len(c.data) for c in m.cells if c.type == "tetra")
              == len(etags1), "meshio reads the INP back")
    except ImportError:
        print("meshio not available: skipped the meshio read-back")
    return [("GETMe adaptive", res["q_min_star_before"], q1.min(),
             q1.mean(), len(etags1), seconds)]


def gmsh_optimizer_rows(workdir):
    rows = []
    for method in ("", "Relocate3D"):
        gmsh.open(os.path.join(workdir, "distorted.msh"))
        t = time.time()
        gmsh.model.mesh.optimize(method, force=True)
        seconds = time.time() - t
        _, xyz, etags, conn = model_arrays()
        q = tet_quality(xyz, conn)
        rows.append(("gmsh optimize(%r)" % method, None, q.min(), q.mean(),
                     len(etags), seconds))
        gmsh.model.remove()
    return rows


def expect_error(fn, words):
    before = model_arrays()[1].copy()
    try:
        fn()
        check(False, "no error for " + words)
    except getme.GetmeError as e:
        check(words in str(e), "message %r contains %r" % (str(e), words))
    check(np.array_equal(before, model_arrays()[1]), "model unchanged")


def test_bad_uses():
    gmsh.open(os.path.join(WORK, "distorted.msh"))
    expect_error(lambda: getme.gmsh.optimize(dimTags=[(3, 42)], log=0),
                 "does not exist")
    expect_error(lambda: getme.gmsh.optimize(fix=["nope"], log=0),
                 "Unknown physical group")
    expect_error(lambda: getme.gmsh.optimize(method="magic", log=0),
                 "Unknown method")
    expect_error(lambda: getme.gmsh.optimize(sigma=-1, log=0),
                 "out of range")
    gmsh.model.mesh.setOrder(3)  # order 2 is smoothed (tests/highorder)
    try:
        getme.gmsh.optimize(log=0)
        check(False, "third order refused")
    except getme.GetmeError as e:
        check("order 3" in str(e), str(e))
    gmsh.model.mesh.setOrder(1)


def test_untangle():
    """An interior node pushed far through its tets: refused with
    untangle=0 (model unchanged), untangled then smoothed by default."""
    gmsh.open(os.path.join(WORK, "distorted.msh"))
    bnd0 = boundary_nodes()
    tags, xyz, _, conn = model_arrays()
    free = sorted(set(tags.tolist()) - set(bnd0))
    tag = free[len(free) // 2]
    i = int(np.searchsorted(tags, tag))
    gmsh.model.mesh.setNode(tag, (xyz[i] + [0.6, 0.0, 0.0]).tolist(), [])
    invalid = int((tet_quality(model_arrays()[1], conn) <= 0).sum())
    check(invalid > 0, "pushed node inverts tets")
    expect_error(lambda: getme.gmsh.optimize(log=0, untangle=0), "invalid")
    res = getme.gmsh.optimize(log=0)
    u = res["untangle"]
    check(u["invalid_before"] == invalid and u["invalid_after"] == 0 and
          u["sweeps"] > 0, "untangle counts %s (%d invalid)" % (u, invalid))
    q = tet_quality(model_arrays()[1], conn)
    check(q.min() > 0.1, "valid and smoothed after untangling: %.4f" % q.min())
    check(boundary_nodes() == bnd0, "boundary nodes bit-identical")


def test_gui_logic():
    """The ONELAB side of getme.gui without a display: the panel's
    parameters, the demo distortion on "check", Smooth on "getme", the
    results written back into the panel."""
    import json
    from getme import gui
    here = os.path.dirname(os.path.abspath(__file__))
    gmsh.open(os.path.join(here, "..", "..", "examples", "gmsh_gui",
                           "plate.geo"))
    gmsh.model.mesh.generate(2)
    gmsh.onelab.set(json.dumps(gui.parameters()))
    gmsh.onelab.setNumber(gui.P + "5Distort mesh now (demo)", [1])
    gmsh.onelab.setString("ONELAB/Action", ["check"])
    gui.handle_events()
    q_bad = getme.quality()["q_min_star"]
    check(gmsh.onelab.getNumber(gui.P + "5Distort mesh now (demo)") == [0],
          "demo box unticked after distorting")
    gmsh.onelab.setNumber(gui.P + "1Sigma", [1.5])
    gmsh.onelab.setString("ONELAB/Action", ["getme"])
    gui.handle_events()
    after = gmsh.onelab.getNumber(gui.P + "Result/1q*min after")
    check(after and after[0] > q_bad + 0.3 and
          abs(after[0] - getme.quality()["q_min_star"]) < 1e-12,
          "GUI smoothing result %s (distorted %.4f)" % (after, q_bad))
    check(gmsh.onelab.getString("ONELAB/Action") == [""], "action consumed")
    passes = gmsh.onelab.getNumber(gui.P + "Result/5Finishing passes")
    check(passes and passes[0] >= 1, "the panel's finishing step ran: %s" % passes)
    tag = gmsh.onelab.getNumber(gui.P + "Result/7Worst element tag")
    etypes, etags, _ = gmsh.model.mesh.getElements(2)
    check(tag and int(tag[0]) in set(int(t) for ts in etags for t in ts),
          "the panel names the worst element by its Gmsh tag: %s" % tag)


def test_worst_and_topology():
    """A cylinder with a coarse curved skin: Gmsh leaves tets that span
    between skin nodes (no free node).  The report names them as such, the
    free-node list starts at q*min, and topology=1 hands them to Gmsh's
    optimizer first, which then changes some elements."""
    for topology in (0, 1):
        gmsh.model.add("cyl%d" % topology)
        gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, 1, 0.3)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.12)
        gmsh.option.setNumber("Mesh.Optimize", 0)
        gmsh.model.mesh.generate(3)
        r = getme.gmsh.optimize(log=0, topology=topology)
        worst, free = r["worst"], r["worst_free"]
        check(len(worst) == 10 and len(free) == 10, "ten worst of each kind")
        check(abs(worst[0]["quality"] - r["q_min_after"]) < 1e-12,
              "worst = qmin")
        check(abs(free[0]["quality"] - r["q_min_star_after"]) < 1e-12,
              "worst with a free node = q*min")
        check(all(w["num_free"] == 0 and w["reason"] == "all_nodes_fixed"
                  for w in worst if w["quality"] < r["q_min_star_after"]),
              "elements below q*min have no free node and say so")
        check(all(w["num_free"] > 0 and w["reason"] in
                  ("improvable", "local_optimum") for w in free),
              "free-node reasons")
        etags, _ = gmsh.model.mesh.getElementsByType(4)
        check(set(w["tag"] for w in worst) <= set(etags.tolist()),
              "worst tags are the model's")
        stuck = r["q_min_after"] < r["q_min_star_after"]
        if topology == 0:
            check(stuck, "the test model has worst elements without a free node")
            check(r["topology"] is None, "no topology step unless asked")
        else:
            t = r["topology"]
            check(t is not None and t["changed"] > 0 and
                  t["elements_after"] == len(etags),
                  "topology=1 ran Gmsh's optimizer: %s" % t)
        gmsh.model.remove()
    gmsh.option.setNumber("Mesh.Optimize", 1)


if __name__ == "__main__":
    WORK = tempfile.mkdtemp(prefix="getme_plugin_")
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    test_same_library()
    rows = test_optimize(WORK)
    rows += gmsh_optimizer_rows(WORK)
    print("%-28s %9s %9s %8s %8s %8s" % ("method", "q*min in", "qmin out",
                                         "qmean", "tets", "seconds"))
    for name, qin, qmin, qmean, n, s in rows:
        print("%-28s %9s %9.4f %8.4f %8d %8.3f"
              % (name, "%.4f" % qin if qin is not None else "-", qmin, qmean,
                 n, s))
    test_bad_uses()
    test_untangle()
    test_gui_logic()
    test_worst_and_topology()
    gmsh.finalize()
    print("plugin_gmsh_python: %d failed" % len(FAILS))
    sys.exit(1 if FAILS else 0)
