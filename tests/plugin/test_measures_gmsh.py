"""getme's gamma and SICN against Gmsh's own, element by element.

Gmsh 4.8.4 (Debian's python3-gmsh) has no gmsh.model.mesh.
getElementQualities (it came with 4.9); its per-element gamma and SICN are
reachable through the mesh statistics export instead: with
Print.PostGamma / Print.PostSICN / Print.PostElement set, gmsh.write("x.pos")
writes for every element the same MElement::gammaShapeMeasure() and
minSICNShapeMeasure() that getElementQualities(tags, "gamma" / "minSICN")
returns in later versions, printed with 6 significant digits.  So the
tolerance is the printing's: |getme - gmsh| <= 5e-6 |gmsh| + 1e-12.

Meshes: for every type, a Gmsh-generated mesh distorted by
getme.gmsh.distort() (valid, badly shaped elements), and 400 single elements
of the type with random node moves of up to 0.3 / 0.5 edge lengths (many
inverted ones).  Expected differences, asserted as such (docs/quality.md):
  - gamma of hexes and pyramids: Gmsh 4.8.4 has none and returns 0; getme
    reports NaN ("not defined");
  - 2-D elements: Gmsh orients each element by its corner at node 1 (the
    triangle 0 1 2), getme by the mesh (counter-clockwise in the xy plane):
    the values are compared where that corner is counter-clockwise; for a
    clockwise triangle getme's SICN is the negative of Gmsh's.
The mesh-level statistics of getme.quality() (min, mean) are checked
against the same Gmsh values.  Prints the largest differences per type.
Last, independently of Gmsh: the dihedral angles of random tets and of
affine hexes and prisms (planar faces) against the angles of their face
normals.
"""
import os
import re
import sys
import tempfile

import gmsh
import numpy as np

import getme

from gmsh_helpers import structured_hex_volume, two_unit_boxes  # tests/support

FAILS = []
PASSED = [0]
GMSH_TYPE = {"tet": 4, "hex": 5, "prism": 6, "pyramid": 7, "tri": 2, "quad": 3}
NODES = {"tet": 4, "hex": 8, "prism": 6, "pyramid": 5, "tri": 3, "quad": 4}
S3 = np.sqrt(3.0)
REGULAR = {
    "tet": [[0, 0, 0], [1, 0, 0], [.5, S3 / 2, 0], [.5, S3 / 6, np.sqrt(2 / 3)]],
    "hex": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
            [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    "prism": [[0, 0, 0], [1, 0, 0], [.5, S3 / 2, 0],
              [0, 0, 1], [1, 0, 1], [.5, S3 / 2, 1]],
    "pyramid": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                [.5, .5, 1 / np.sqrt(2)]],
    "tri": [[0, 0, 0], [1, 0, 0], [.5, S3 / 2, 0]],
    "quad": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]}


def check(cond, what):
    if cond:
        PASSED[0] += 1
    else:
        FAILS.append(what)
        print("FAILED:", what, flush=True)


def gmsh_values(kind, x):
    """Gmsh's SICN and gamma of the elements x ((m, nv, 3) coordinates), in
    order, from the .pos mesh statistics of a scratch model that holds just
    them (the export of a generated model would also hold its lines and
    points, which have no SICN)."""
    m, nv = x.shape[:2]
    current = gmsh.model.getCurrent()
    gmsh.model.add("scratch")
    dim = 2 if kind in ("tri", "quad") else 3
    gmsh.model.addDiscreteEntity(dim, 1)
    gmsh.model.mesh.addNodes(dim, 1, list(range(1, m * nv + 1)), x.ravel().tolist())
    gmsh.model.mesh.addElementsByType(1, GMSH_TYPE[kind], list(range(1, m + 1)),
                                      list(range(1, m * nv + 1)))
    for opt, v in (("PostElementary", 0), ("PostElement", 1), ("PostSICN", 1),
                   ("PostSIGE", 0), ("PostGamma", 1), ("PostDisto", 0)):
        gmsh.option.setNumber("Print." + opt, v)
    fd, path = tempfile.mkstemp(suffix=".pos")
    os.close(fd)
    try:
        gmsh.write(path)
        text = open(path).read()
    finally:
        os.remove(path)
        gmsh.model.remove()
        gmsh.model.setCurrent(current)
    prefix = {"tet": "SS", "hex": "SH", "prism": "SI", "pyramid": "SY",
              "tri": "ST", "quad": "SQ"}[kind]
    tags, sicn, gamma = [], [], []
    for match in re.finditer(prefix + r"\(([^)]*)\)\{([^}]*)\}", text):
        v = [float(t) for t in match.group(2).split(",")]
        tags.append(int(v[0]))
        sicn.append(v[nv])
        gamma.append(v[2 * nv])
    check(sorted(tags) == list(range(1, m + 1)), f"{kind}: Gmsh wrote every element")
    order = np.argsort(tags)
    return np.array(sicn)[order], np.array(gamma)[order]


def model_elements(kind):
    """(element tags, (m, nv, 3) coordinates) of one type in the model."""
    ntags, xyz, _ = gmsh.model.mesh.getNodes()
    order = np.argsort(ntags)
    ntags, xyz = ntags[order], xyz.reshape(-1, 3)[order]
    etags, enodes = gmsh.model.mesh.getElementsByType(GMSH_TYPE[kind])
    conn = np.searchsorted(ntags, enodes).reshape(-1, NODES[kind])
    return np.array(etags), xyz[conn], xyz, conn


def compare(kind, label, x, g_sicn, g_gamma):
    """Element by element; returns (max |d| SICN, max |d| gamma, compared)."""
    ours_s = np.array([getme.element_measure(kind, "sicn", e) for e in x])
    ours_g = np.array([getme.element_measure(kind, "gamma", e) for e in x])
    if kind in ("tri", "quad"):
        e1 = x[:, 2, :2] - x[:, 1, :2]
        e0 = x[:, 0, :2] - x[:, 1, :2]
        ok = e1[:, 0] * e0[:, 1] - e1[:, 1] * e0[:, 0] > 0
        if kind == "tri":
            check(np.all(np.abs(ours_s[~ok] + g_sicn[~ok])
                         <= 5e-6 * np.abs(g_sicn[~ok]) + 1e-12),
                  f"{label}: clockwise triangles: getme's SICN = -Gmsh's")
    else:
        ok = np.ones(len(x), bool)
    tol = lambda g: 5e-6 * np.abs(g) + 1e-12  # noqa: E731
    ds = np.abs(ours_s - g_sicn)[ok]
    bad = np.count_nonzero(ds > tol(g_sicn[ok]))
    check(bad == 0, f"{label}: SICN equals Gmsh's ({bad} of {ok.sum()} differ)")
    if kind in ("hex", "pyramid"):
        check(np.all(g_gamma == 0) and np.all(np.isnan(ours_g)),
              f"{label}: Gmsh 4.8.4 has no gamma for it (0), getme NaN")
        dg = np.zeros(1)
    else:
        dg = np.abs(ours_g - g_gamma)[ok]
        bad = np.count_nonzero(dg > tol(g_gamma[ok]))
        check(bad == 0, f"{label}: gamma equals Gmsh's ({bad} of {ok.sum()} differ)")
    neg = np.count_nonzero(g_sicn < 0)
    return ds.max(), dg.max(), int(ok.sum()), neg


# ---- Gmsh-generated meshes -------------------------------------------------

def generate(kind):
    gmsh.model.add(kind)
    occ, gm = gmsh.model.occ, gmsh.model
    if kind == "tet":
        occ.addBox(0, 0, 0, 1, 1, 1)
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2)
        gm.mesh.generate(3)
    elif kind in ("hex", "prism"):
        r = occ.addRectangle(0, 0, 0, 1, 1)
        occ.extrude([(2, r)], 0, 0, 0.5, numElements=[3], recombine=True)
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15)
        gmsh.option.setNumber("Mesh.RecombineAll", 1 if kind == "hex" else 0)
        gm.mesh.generate(3)
    elif kind == "pyramid":
        # a transfinite hex box next to a tet box: pyramids in between
        two_unit_boxes()
        structured_hex_volume(1, 5)
        gm.mesh.generate(3)
    else:
        r = occ.addRectangle(0, 0, 0, 2, 1)
        d = occ.addDisk(0.7, 0.5, 0, 0.2, 0.2)
        occ.cut([(2, r)], [(2, d)])
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.1)
        gmsh.option.setNumber("Mesh.RecombineAll", 1 if kind == "quad" else 0)
        gm.mesh.generate(2)
    gmsh.option.setNumber("Mesh.RecombineAll", 0)


def mesh_case(kind):
    generate(kind)
    moved = getme.gmsh.distort(seed=5, amount=0.45, rounds=6)
    check(moved > 0, f"{kind}: distort moved nodes")
    etags, x, _, _ = model_elements(kind)
    check(len(etags) > 10, f"{kind}: Gmsh made {len(etags)} {kind} elements")
    # mesh-level statistics of the whole model (plugin path)
    q = getme.quality()["measures"][kind]
    gs, gg = gmsh_values(kind, x)
    ms, mg, n, _ = compare(kind, f"{kind} mesh", x, gs, gg)
    if kind not in ("tri", "quad"):
        check(abs(q["sicn"]["min"] - gs.min()) <= 5e-6 * abs(gs.min()) + 1e-12,
              f"{kind}: getme.quality() SICN min {q['sicn']['min']} = Gmsh's {gs.min()}")
        check(abs(q["sicn"]["mean"] - gs.mean()) <= 5e-6,
              f"{kind}: getme.quality() SICN mean = mean of Gmsh's")
        check(q["sicn"]["num_elements"] == len(etags), f"{kind}: every element counted")
    if "gamma" in q:
        check(abs(q["gamma"]["min"] - gg.min()) <= 5e-6 * abs(gg.min()) + 1e-12,
              f"{kind}: getme.quality() gamma min = Gmsh's")
    gmsh.model.remove()
    return ms, mg, n, len(etags)


# ---- single random elements, many inverted ---------------------------------

def random_case(kind, rng):
    reg = np.array(REGULAR[kind], float)
    x = []
    for amount in (0.3, 0.5):
        for _ in range(200):
            p = reg + amount * rng.standard_normal(reg.shape)
            if kind in ("tri", "quad"):
                p[:, 2] = 0.0
            x.append(p)
    x = np.array(x)
    gs, gg = gmsh_values(kind, x)
    return compare(kind, f"{kind} random", x, gs, gg)


# ---- dihedral angles against face normals (independent of Gmsh) ----------

def normal_dihedrals(x, faces):
    """min, max interior dihedral angle (degrees) of an element with planar
    faces (local node lists), from the faces' normals: at an edge shared by
    faces f and g, the angle between the half-planes = arccos of the normals
    taken towards the element's inside."""
    centre = x.mean(axis=0)
    normals = []
    for f in faces:
        n = np.cross(x[f[1]] - x[f[0]], x[f[2]] - x[f[0]])
        if np.dot(n, centre - x[f[0]]) < 0:
            n = -n
        normals.append(n / np.linalg.norm(n))
    angles = []
    for i, f in enumerate(faces):
        for j in range(i + 1, len(faces)):
            if len(set(f) & set(faces[j])) == 2:
                c = np.clip(np.dot(normals[i], normals[j]), -1, 1)
                angles.append(180.0 - np.degrees(np.arccos(c)))
    return min(angles), max(angles)


def dihedral_case(rng):
    faces = {"tet": [(0, 1, 2), (0, 1, 3), (1, 2, 3), (0, 2, 3)],
             "hex": [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5),
                     (2, 3, 7, 6), (3, 0, 4, 7)],
             "prism": [(0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4),
                       (2, 0, 3, 5)]}
    for kind, fl in faces.items():
        worst = 0.0
        for _ in range(300):
            # tets: any nodes; hex and prism: affine images of the regular
            # element (planar faces)
            if kind == "tet":
                x = rng.standard_normal((4, 3))
            else:
                a = rng.standard_normal((3, 3))
                if np.linalg.det(a) < 0:
                    a[:, 0] = -a[:, 0]
                x = np.array(REGULAR[kind]) @ a.T
            lo, hi = normal_dihedrals(x, fl)
            worst = max(worst, abs(lo - getme.element_measure(kind, "min_dihedral", x)),
                        abs(hi - getme.element_measure(kind, "max_dihedral", x)))
        check(worst < 1e-8, f"{kind}: dihedral angles equal the face-normal ones ({worst:.2g} deg)")
        print(f"{kind}: dihedral angles vs face normals, max difference {worst:.2g} degrees")


def main():
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    rng = np.random.default_rng(2024)
    print("%-8s %-22s %-22s %s" % ("type", "mesh: max|d| SICN/gamma",
                                   "random: max|d| SICN/gamma", "compared"))
    for kind in ("tet", "hex", "prism", "pyramid", "tri", "quad"):
        ms, mg, n, total = mesh_case(kind)
        rs, rg, rn, neg = random_case(kind, rng)
        check(neg > 20 or kind == "tri", f"{kind}: the random set has inverted elements ({neg})")
        print("%-8s %9.2g %9.2g     %9.2g %9.2g     mesh %d/%d, random %d/400 (%d inverted)"
              % (kind, ms, mg, rs, rg, n, total, rn, neg), flush=True)
    gmsh.finalize()
    dihedral_case(rng)
    print(f"{PASSED[0]} passed, {len(FAILS)} failed")
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
