"""Reading the benchmark's meshes with meshio (a reader independent of both
Gmsh's SDK, which libgetme's MSH adapter uses, and of our own code).

A mesh here is points (N x 3 float64), blocks [(type, conn)] of the elements
of the highest dimension present, and one region id per element (Gmsh
physical tag, else elementary entity tag), block by block.
"""

import contextlib
import io
from dataclasses import dataclass, field

import numpy as np

MESHIO_TYPES = {"tetra": "tet", "hexahedron": "hex", "wedge": "prism",
                "pyramid": "pyramid", "triangle": "tri", "quad": "quad"}
VOLUME = ("tet", "hex", "prism", "pyramid")
PLANAR = ("tri", "quad")


@dataclass
class Mesh:
    points: np.ndarray
    blocks: list = field(default_factory=list)   # [(type, conn)]
    regions: list = field(default_factory=list)  # [region id per element]

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
        return Mesh(self.points, out_blocks, out_regions)


def _region_of(cell_data, index, count):
    for key in ("gmsh:physical", "gmsh:geometrical", "medit:ref"):
        if key in cell_data:
            return np.asarray(cell_data[key][index], dtype=np.int64)
    return np.zeros(count, dtype=np.int64)


def read_mesh(path):
    """Read a mesh file meshio understands; keep only the elements of the
    highest dimension and merge blocks by type."""
    import meshio  # imported late: quality.py/skin.py work without it

    # meshio 5 prints a stray empty line to stdout while reading MSH 4.1:
    # keep the benchmark's stdout for its tables
    with contextlib.redirect_stdout(io.StringIO()):
        m = meshio.read(path)
    blocks, regions = [], []
    for i, cells in enumerate(m.cells):
        etype = MESHIO_TYPES.get(cells.type)
        if etype is None:
            continue
        conn = np.asarray(cells.data, dtype=np.int64)
        blocks.append((etype, conn))
        regions.append(_region_of(m.cell_data, i, len(conn)))
    mesh = Mesh(np.asarray(m.points, dtype=np.float64), blocks, regions)
    top = [t for t in VOLUME] if mesh.dim == 3 else list(PLANAR)
    keep = [i for i, (t, _) in enumerate(blocks) if t in top]
    return Mesh(mesh.points, [blocks[i] for i in keep],
                [regions[i] for i in keep]).merged()
