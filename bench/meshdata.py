"""Reading the benchmark's meshes into flat numpy arrays.

A mesh here is points (N x 3 float64), blocks [(type, conn)] of the elements
of the highest dimension present, and one region id per element (Gmsh
physical tag, else elementary entity tag), block by block.
"""

from dataclasses import dataclass, field

import os

import numpy as np

VOLUME = ("tet", "hex", "prism", "pyramid")
PLANAR = ("tri", "quad")


@dataclass
class Mesh:
    points: np.ndarray
    blocks: list = field(default_factory=list)   # [(type, conn)]
    regions: list = field(default_factory=list)  # [region id per element]
    tags: np.ndarray = None  # file node tag of each point (None: 1..N)

    @property
    def dim(self):
        return 3 if any(t in VOLUME for t, _ in self.blocks) else 2

    @property
    def num_elements(self):
        return sum(len(c) for _, c in self.blocks)

    def count(self, etype):
        return sum(len(c) for t, c in self.blocks if t == etype)

    def merged(self):
        """One block per type (Gmsh writes one per entity), in type order."""
        out_blocks, out_regions = [], []
        for etype in VOLUME + PLANAR:
            parts = [(c, r) for (t, c), r in zip(self.blocks, self.regions)
                     if t == etype]
            if parts:
                out_blocks.append((etype, np.concatenate([p[0] for p in parts])))
                out_regions.append(np.concatenate([p[1] for p in parts]))
        return Mesh(self.points, out_blocks, out_regions, self.tags)


GMSH_TYPES = {4: ("tet", 4), 5: ("hex", 8), 6: ("prism", 6), 7: ("pyramid", 5),
              2: ("tri", 3), 3: ("quad", 4)}


def _region(gmsh, dim, tag):
    """The element region: the entity's (first) physical group, else the
    entity itself -- what libgetme's fixing rule calls a region."""
    phys = gmsh.model.getPhysicalGroupsForEntity(dim, tag)
    return int(phys[0]) if len(phys) else int(tag)


def read_mesh(path):
    """Read an MSH file (any version Gmsh reads) with the Gmsh API; keep the
    elements of the highest dimension, nodes ordered by their file tags.

    Tags, not file order, define node identity: tools that preserve tags
    (Gmsh, getme) may still write nodes in another order, which must not
    count as a topology change."""
    import gmsh
    gmsh.initialize(["bench-read"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(path)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        order = np.argsort(tags)
        tags = np.asarray(tags)[order]
        points = np.asarray(coords, dtype=np.float64).reshape(-1, 3)[order]
        blocks, regions = [], []
        for dim in (3, 2):
            for _, tag in gmsh.model.getEntities(dim):
                types, _, node_tags = gmsh.model.mesh.getElements(dim, tag)
                for gtype, nt in zip(types, node_tags):
                    if gtype not in GMSH_TYPES:
                        continue
                    etype, nn = GMSH_TYPES[gtype]
                    conn = np.searchsorted(tags, nt).reshape(-1, nn)
                    blocks.append((etype, conn.astype(np.int64)))
                    regions.append(np.full(len(conn), _region(gmsh, dim, tag), np.int64))
            if blocks:
                break
    finally:
        gmsh.finalize()
    return Mesh(points, blocks, regions, tags).merged()


def write_points(src, mesh, points, path, app="bench"):
    """Write src again with new coordinates through Gmsh (as the CLI's MSH
    adapter would): the nodes whose points differ from mesh's are set, so
    entities, classification and tags stay as they were; binary MSH,
    through a temporary file and a rename."""
    import gmsh
    moved = np.flatnonzero(np.any(points != mesh.points, axis=1))
    gmsh.initialize([app])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(src)
        for i in moved:
            gmsh.model.mesh.setNode(int(mesh.tags[i]), points[i].tolist(), [])
        gmsh.option.setNumber("Mesh.Binary", 1)
        tmp = path + ".tmp.msh"
        gmsh.write(tmp)
    finally:
        gmsh.finalize()
    os.replace(tmp, path)
