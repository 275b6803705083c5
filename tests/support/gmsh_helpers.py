"""Small Gmsh model recipes shared by the Python tests (tests/cli,
tests/plugin)."""
import gmsh


def two_unit_boxes():
    """Volumes 1 ([0,1]^3) and 2 ([1,2]x[0,1]^2) of the current model,
    sharing the face x = 1 (OCC fragment), synchronized."""
    occ = gmsh.model.occ
    b1 = occ.addBox(0, 0, 0, 1, 1, 1)
    b2 = occ.addBox(1, 0, 0, 1, 1, 1)
    occ.fragment([(3, b1)], [(3, b2)])
    occ.synchronize()


def structured_hex_volume(volume, divisions):
    """Mesh a box-shaped volume of the current model with transfinite hexes
    (divisions nodes on every curve of the model, recombined boundary
    surfaces): next to a tet-meshed volume, Gmsh fills the transition with
    pyramids."""
    gm = gmsh.model
    for _, curve in gm.getEntities(1):
        gm.mesh.setTransfiniteCurve(curve, divisions)
    for _, surface in gm.getBoundary([(3, volume)], oriented=False):
        gm.mesh.setTransfiniteSurface(surface)
        gm.mesh.setRecombine(2, surface)
    gm.mesh.setTransfiniteVolume(volume)


def merged_nodes(paths):
    """{tag: (x, y, z)} of the MSH files opened together (the first opened,
    the others merged: a mesh's parts), and the highest partition number
    of their entities (0 if unpartitioned)."""
    gmsh.initialize(["test"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(paths[0])
        for p in paths[1:]:
            gmsh.merge(p)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        return ({int(t): tuple(xyz[3 * i:3 * i + 3])
                 for i, t in enumerate(tags)},
                max((max(gmsh.model.getPartitions(d, t), default=0)
                     for d, t in gmsh.model.getEntities()), default=0))
    finally:
        gmsh.finalize()
