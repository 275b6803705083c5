"""The benchmark's meshes, generated reproducibly with the Gmsh Python API.

Cases (docs/design.md §9 and the paper's Sec. 3):
  tet    Delaunay tets of a piston-like OpenCASCADE part: crown with a
         combustion bowl, three ring grooves, a hollow skirt with relief
         windows, pin bosses with a through pin hole, oil drain holes.
  hex    a planar flange section with holes, meshed with quads (Blossom
         recombination) and swept along z in layers: all hexahedra.
  mixed  a block whose lower part is swept (quads -> hexes, triangles ->
         prisms) and whose upper part is Delaunay tets; Gmsh puts pyramids on
         the quads the tets meet.  One physical volume per volume (4).
  tri    the flange section, triangles (Frontal-Delaunay).
  quad   the flange section, quads (Blossom recombination).

Sizes: the mesh size h per case and size is calibrated on counts measured
with Debian 12's Gmsh 4.8 (the piston's count grows like h^-2.5 because of
its curvature refinement, the swept hexes' like h^-3).  Measured: tet
190581 (small, h 2.11), 735669 (h 1.22), 1006908 (medium, h 1.08),
4031572 (full, h 0.655; 712950 nodes, 278 s to generate); hex 93632
(small), 577936 (medium), 2594200 (full, h 0.585; 2682513 nodes, 24 s).
Gmsh's meshers are deterministic for a given version and options, so a
(case, size, h) always gives the same mesh; files are cached under a name
holding all three.
"""

import json
import math
import os
import time

GENERATOR_VERSION = 1  # bump when a geometry or option changes
# per-case bumps: mixed 2 = one physical volume per volume, so that region
# interfaces are exactly the geometric interfaces getme's MSH adapter fixes
CASE_VERSION = {"mixed": 2}

# case -> size -> mesh size h (model units: mm).  Targets: tet ~200k / 1M /
# 4.1M, hex ~100k / 650k / 2.6M (the paper's 4.13M tets and 2.65M hexes).
SIZES = {
    "tet":   {"quick": 5.0, "small": 2.11, "medium": 1.08, "full": 0.655},
    "hex":   {"quick": 4.5, "small": 1.83, "medium": 0.98, "full": 0.585},
    "mixed": {"quick": 0.16, "small": 0.075, "medium": 0.044, "full": 0.028},
    "tri":   {"quick": 3.0, "small": 1.0, "medium": 0.45, "full": 0.22},
    "quad":  {"quick": 3.0, "small": 1.0, "medium": 0.45, "full": 0.22},
}
CASES = tuple(SIZES)


def _piston(h):
    import gmsh
    occ = gmsh.model.occ
    R, H = 45.0, 70.0
    body = occ.addCylinder(0, 0, 0, 0, 0, H, R)
    bowl = occ.addSphere(0, 0, H + 14.0, 22.0)  # combustion bowl in the crown
    grooves = []  # ring grooves: tubes cut into the ring belt
    for z, w in ((60.0, 2.0), (54.0, 2.0), (47.0, 3.0)):
        outer = occ.addCylinder(0, 0, z, 0, 0, w, R + 1.0)
        inner = occ.addCylinder(0, 0, z, 0, 0, w, R - 3.5)
        tube, _ = occ.cut([(3, outer)], [(3, inner)])
        grooves += tube
    # hollow underside: what remains of the wall below the crown is the skirt
    cavity = occ.addCylinder(0, 0, -1.0, 0, 0, 41.0, R - 7.0)
    windows = [occ.addBox(s * (R - 12.0), -R, -1.0, s * 20.0, 2 * R, 16.0)
               for s in (-1, 1)]  # skirt relief on the pin sides
    piston, _ = occ.cut([(3, body)], [(3, bowl), (3, cavity)] + grooves
                        + [(3, w) for w in windows])
    bosses = [occ.addBox(18.0, -13.0, 14.0, R - 22.0, 26.0, 28.0),
              occ.addBox(-(R - 4.0), -13.0, 14.0, R - 22.0, 26.0, 28.0)]
    piston, _ = occ.fuse(piston, [(3, b) for b in bosses])
    pin = occ.addCylinder(-R - 2, 0, 28.0, 2 * R + 4, 0, 0, 11.0)
    oil = [occ.addCylinder(0, 0, 48.5, R * math.cos(a), R * math.sin(a), 0, 1.2)
           for a in (math.pi / 2, -math.pi / 2)]
    piston, _ = occ.cut(piston, [(3, pin)] + [(3, o) for o in oil])
    occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [t for _, t in piston], 1)
    gmsh.model.setPhysicalName(3, 1, "piston")
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeMin", h / 4)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay
    gmsh.model.mesh.generate(3)


def _flange_section():
    """A planar flange (disk + rounded bar) with a bore and six bolt holes."""
    import gmsh
    occ = gmsh.model.occ
    disk = occ.addDisk(0, 0, 0, 60.0, 60.0)
    bar = occ.addRectangle(-85.0, -22.0, 0, 170.0, 44.0, roundedRadius=10.0)
    sec, _ = occ.fuse([(2, disk)], [(2, bar)])
    holes = [occ.addDisk(0, 0, 0, 25.0, 25.0)]
    holes += [occ.addDisk(42 * math.cos(a), 42 * math.sin(a), 0, 6.0, 6.0)
              for a in (math.pi / 4, 3 * math.pi / 4, 5 * math.pi / 4,
                        7 * math.pi / 4)]
    holes += [occ.addDisk(s * 72.0, 0, 0, 5.0, 5.0) for s in (-1, 1)]
    sec, _ = occ.cut(sec, [(2, x) for x in holes])
    return sec


def _quad_options(h):
    import gmsh
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    # Frontal-Delaunay + Blossom gives all quads here; Gmsh 4.8's
    # "Frontal-Delaunay for quads" (8) crashes on this section.
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)


def _swept_hex(h):
    import gmsh
    occ = gmsh.model.occ
    sec = _flange_section()
    occ.synchronize()
    thickness = 40.0
    ex = occ.extrude(sec, 0, 0, thickness,
                     numElements=[max(1, round(thickness / h))], recombine=True)
    occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [t for d, t in ex if d == 3], 1)
    gmsh.model.setPhysicalName(3, 1, "flange")
    _quad_options(h)
    gmsh.model.mesh.generate(3)


def _planar(h, quads):
    import gmsh
    sec = _flange_section()
    gmsh.model.occ.synchronize()
    gmsh.model.addPhysicalGroup(2, [t for _, t in sec], 1)
    gmsh.model.setPhysicalName(2, 1, "section")
    if quads:
        _quad_options(h)
    else:
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.MeshSizeMin", h)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.model.mesh.generate(2)


def _mixed(h):
    """Swept base (left half quads -> hexes, right half triangles -> prisms)
    under a Delaunay tet cap; pyramids where the cap meets the hexes."""
    import gmsh
    g = gmsh.model.geo
    L, W, base, cap = 4.0, 2.0, 1.0, 1.5
    xy = [(0, 0), (L / 2, 0), (L, 0), (L, W), (L / 2, W), (0, W)]
    p = [g.addPoint(x, y, 0, h) for x, y in xy]
    ln = [g.addLine(p[i], p[(i + 1) % 6]) for i in range(6)] + [g.addLine(p[1], p[4])]
    left = g.addPlaneSurface([g.addCurveLoop([ln[0], ln[6], ln[4], ln[5]])])
    right = g.addPlaneSurface([g.addCurveLoop([ln[1], ln[2], ln[3], -ln[6]])])
    g.mesh.setRecombine(2, left)
    layers = max(1, round(base / h))
    ex = g.extrude([(2, left), (2, right)], 0, 0, base,
                   numElements=[layers], recombine=True)
    # extrude() lists, per input surface: top, volume, then the lateral faces
    tops = [ex[0][1], ex[6][1]]
    base_vols = [ex[1][1], ex[7][1]]
    ex2 = g.extrude([(2, t) for t in tops], 0, 0, cap)  # unstructured: tets
    cap_vols = [t for d, t in ex2 if d == 3]
    g.synchronize()
    names = ("base-hex", "base-prism", "cap-over-hex", "cap-over-prism")
    for tag, (vol, name) in enumerate(zip(base_vols + cap_vols, names), start=1):
        gmsh.model.addPhysicalGroup(3, [vol], tag)
        gmsh.model.setPhysicalName(3, tag, name)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    gmsh.model.mesh.generate(3)


BUILDERS = {
    "tet": _piston,
    "hex": _swept_hex,
    "mixed": _mixed,
    "tri": lambda h: _planar(h, quads=False),
    "quad": lambda h: _planar(h, quads=True),
}

GMSH_TYPES = {4: "tet", 5: "hex", 6: "prism", 7: "pyramid", 2: "tri", 3: "quad"}


def cache_path(cache_dir, case, size):
    version = CASE_VERSION.get(case, GENERATOR_VERSION)
    h = SIZES[case][size]
    return os.path.join(cache_dir, f"{case}-{size}-g{version}-h{h:g}.msh")


def _element_counts():
    import gmsh
    counts = {}
    for gtype, name in GMSH_TYPES.items():
        tags, _ = gmsh.model.mesh.getElementsByType(gtype)
        if len(tags):
            counts[name] = int(len(tags))
    return counts


def generate(case, size, cache_dir, log=print):
    """Path of the cached mesh of case at size, generating it if needed."""
    import gmsh
    path = cache_path(cache_dir, case, size)
    if os.path.exists(path) and os.path.exists(path + ".json"):
        return path
    os.makedirs(cache_dir, exist_ok=True)
    h = SIZES[case][size]
    log(f"Info    : generating {case} mesh, size {size} (h = {h})")
    gmsh.initialize(["bench"])  # no sys.argv: Gmsh must not parse ours
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add(f"{case}-{size}")
        start = time.time()
        BUILDERS[case](h)
        seconds = time.time() - start
        counts = _element_counts()
        _check_types(case, counts)
        dim_types = (("tet", "hex", "prism", "pyramid") if case in ("tet", "hex", "mixed")
                     else ("tri", "quad"))
        counts = {t: n for t, n in counts.items() if t in dim_types}
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1)
        tmp = path + ".tmp.msh"
        gmsh.write(tmp)
        nodes = len(gmsh.model.mesh.getNodes()[0])
    finally:
        gmsh.finalize()
    os.replace(tmp, path)
    info = {"case": case, "size": size, "h": h, "nodes": nodes,
            "elements": counts, "seconds": round(seconds, 2),
            "generator_version": CASE_VERSION.get(case, GENERATOR_VERSION)}
    with open(path + ".json", "w") as f:
        json.dump(info, f, indent=1)
    log(f"Info    : {case}-{size}: {nodes} nodes, "
        + ", ".join(f"{n} {t}" for t, n in counts.items())
        + f" ({seconds:.1f} s)")
    return path


def _check_types(case, counts):
    """Fail loudly if Gmsh did not give the element types the case is for."""
    volume = {t for t in counts if t in ("tet", "hex", "prism", "pyramid")}
    expect = {"tet": {"tet"}, "hex": {"hex"}, "tri": {"tri"}, "quad": {"quad"},
              "mixed": {"tet", "hex", "prism", "pyramid"}}[case]
    have = set(volume) if case in ("tet", "hex", "mixed") else set(counts) & {"tri", "quad"}
    if have != expect:
        raise RuntimeError(f"{case} mesh has element types {sorted(have)}, "
                           f"expected {sorted(expect)}")
