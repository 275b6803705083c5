/*
 * cgns_fixture.h -- CGNS test files written with libcgns itself, so that
 * the adapter is tested on files as the reference library writes them.
 *
 * The standard fixture ("two zones") holds
 *   /Base/Block  unstructured, 5x5x5 nodes (125), HEXA_8 section "Hexes"
 *                (64 elements, 1..64), QUAD_4 section "Floor" (z = 0 skin,
 *                16 faces, 65..80), QUAD_4 section "Baffle" (the interior
 *                plane z = 2, 16 faces, 81..96), FamilyName BlockFam,
 *                BCs: "inlet" PointList Vertex (x = 0 nodes, 25),
 *                "floor" PointRange FaceCenter 65..80 with FamilyName
 *                OutFam, "probe" PointList Vertex of two interior nodes
 *                with FamilyName ProbeFam;
 *                FlowSolution "Sol" (Pressure at vertices) and
 *                UserDefinedData "Meta" (a DataArray) that must survive.
 *   /Base/Tets   unstructured (FamilyName TetFam), 4x4x4 nodes (64), one
 *                MIXED section
 *                "TetMix": 162 TETRA_4 (1..162) + 18 TRI_3 (x = x0 face,
 *                163..180).
 * Interior nodes are displaced (deterministically) so there is something to
 * smooth.  Default fixed nodes: skins 98 + 56, probe 2, baffle interior 9
 * = 165 of 189.
 */
#ifndef GETME_CGNS_FIXTURE_H
#define GETME_CGNS_FIXTURE_H

#include <cgnslib.h>

#define FIX_NODES 189
#define FIX_ELEMS (64 + 162)
#define FIX_FIXED_DEFAULT 165

typedef struct fixture_opts {
    int file_type;  /* CG_FILE_HDF5 or CG_FILE_ADF */
    int single;     /* 1: RealSingle coordinates   */
    double distort; /* interior displacement, in cells (0.3 typical) */
} fixture_opts;

/* Write the standard two-zone fixture; 0 on success. */
int fixture_write(const char *path, const fixture_opts *o);

/* A 2-D (cell dim 2, phys dim 3) planar zone at z = 0.5: 4x4 nodes, 9
   quads split as 6 QUAD_4 + 6 TRI_3, BAR_2 boundary. */
int fixture_write_2d(const char *path);

/* Single zone 3x3x3 hex grid with one extra section of the given type and
   connectivity (count elements), for malformed/unsupported cases.  With
   no_coords the zone has no GridCoordinates. */
int fixture_write_custom(const char *path, CGNS_ENUMT(ElementType_t) type,
                         int count, const cgsize_t *conn, int no_coords);

/* A structured zone only (structured_only = 1), or a structured zone next
   to an unstructured hex zone (0). */
int fixture_write_structured(const char *path, int structured_only);

/* The layout meshio's CGNS reader expects: /Base/Zone1 with one TETRA_4
   section "GridElements" (a 4x4x4-node box, 162 tets, interior jittered),
   written by libcgns. */
int fixture_write_meshio_style(const char *path);

#endif
