/*
 * model.h -- the one model builder of getme's Gmsh inputs (private).
 *
 * A Gmsh model -- read natively from an MSH file (formats/msh) or taken
 * from the Gmsh SDK (plugin/src/gmsh_model.c) -- reaches the core the same
 * way (docs/design.md §5, docs/architecture.md):
 *
 *  - entities: every entity of the smoothed dimension that has elements,
 *    their elements as blocks of one (entity, MSH element type), in the
 *    order Gmsh stores them; a run of blocks of one (entity, type) becomes
 *    one element block of the mesh;
 *  - nodes: those the elements use, in Gmsh's node order (the caller's
 *    ranges), numbered 0..n-1;
 *  - fixed: nodes not classified on a smoothed entity, nodes of the groups
 *    the user named, then skin / interfaces through the core;
 *  - regions: entities with the same non-empty set of physical tags share
 *    one (the index of the first), an entity in no group is its own;
 *  - planar meshes: rotated into the xy plane if they do not lie in a plane
 *    z = const, and every surface whose elements are mostly clockwise has
 *    its elements reversed.
 * Both callers therefore hand the core bit-identical input for one file.
 *
 * Private to libgetme_formats and libgetme_gmsh (built into both from
 * these sources, exported by neither).  Names: getme__ (the project's
 * private prefix), then the part.
 */
#ifndef GETME_MODEL_H
#define GETME_MODEL_H

#include "getme.h"

#include <stddef.h>
#include <stdint.h>

/* ---- the Gmsh element types (msh_types.c): one table for all ----------- */

/* Nodes per element of an MSH element type, 0 if unknown; *order (may be
   NULL) gets its polynomial order (0 for points). */
int getme__msh_type_nodes(int msh_type, int *order);
/* "tetrahedron", "10-node tetrahedron"...; 0 if the type is unknown (buf
   then says "element type N"). */
int getme__msh_type_name(int msh_type, char *buf, size_t size);
/* Dimension of an MSH type (0 point .. 3 volume), -1 if unknown. */
int getme__msh_type_dim(int msh_type);
/* The getme type of a linear MSH type (2 tri .. 7 pyramid), else -1. */
int getme__msh_type_getme(int msh_type);
/* The getme_ho_type of a second-order MSH type smoothed in a mesh of
   dimension dim (11, 17, 12, 18, 13 in 3-D), or -1. */
int getme__msh_type_ho(int msh_type, int dim);
/* The getme type of the corners of a type smoothed in a mesh of dimension
   dim: getme__msh_type_getme for linear types, the corners' linear type
   for getme__msh_type_ho's, else -1. */
int getme__msh_type_corners(int msh_type, int dim);
/* "point", "curve", "surface", "volume" (capital: "Point"...), as Gmsh
   words them; "entity" outside 0..3. */
const char *getme__dim_word(int dim, int capital);

/* ---- MSH files (msh_file.c) ------------------------------------------- */

/* 1 if path ends in .msh or starts with $MeshFormat. */
int getme__msh_probe(const char *path);
/* "$MeshFormat" then "version file-type ...": 0, -1 (cannot open: errno
   tells) or -2 (no such header). */
int getme__msh_header(const char *path, double *version, int *binary);

/* ---- node tag -> index (nodemap.c) ------------------------------------- */

typedef struct getme__nodemap {
    uint64_t max_tag;
    int32_t *dense;       /* max_tag + 1 entries (-1: absent), or NULL  */
    int ordered;          /* tags 1..n in order: tag t is index t - 1 and
                             no table is kept (4 B per node less)          */
    uint64_t *sorted_tag; /* sparse numbering: sorted tags...           */
    int32_t *sorted_idx;  /* ... and their indices                      */
    size_t n;
} getme__nodemap;

/* tags[i] -> i.  0, GETME_ERR_NOMEM, or GETME_ERR_ARGUMENT when a tag
   appears twice (*repeated gets it). */
getme_status getme__nodemap_build(getme__nodemap *map, const uint64_t *tags,
                                  size_t n, uint64_t *repeated);
/* Index of tag, -1 if absent. */
int32_t getme__nodemap_find(const getme__nodemap *map, uint64_t tag);
/* Every stored index i becomes loc[i] (a renumbering); once per map, as
   it may drop the table (ordered). */
void getme__nodemap_relabel(getme__nodemap *map, const int32_t *loc);
void getme__nodemap_free(getme__nodemap *map);

/* ---- the builder (model_build.c, planar.c) ----------------------------- */

enum {
    GETME__NODE_USED = 1,   /* set by the builder: a smoothed element uses it */
    GETME__NODE_FIXGRP = 2, /* in a physical group the user named to fix      */
    GETME__NODE_OWN = 4     /* classified on a smoothed entity                */
};

typedef struct getme__model_block { /* elements of one entity, one type */
    int tag;          /* entity tag                                       */
    int type;         /* MSH element type                                 */
    int32_t count;
    int32_t *conn;    /* node indices of the caller's arrays (malloc'd;
                         NULL for a type GETMe cannot smooth); the builder
                         renumbers, then frees                             */
    int64_t *ids;     /* element tags (malloc'd; freed by the builder)    */
} getme__model_block;

typedef struct getme__node_range { /* caller's nodes [first, first+count) */
    size_t first, count;
} getme__node_range;

typedef struct getme__model_in {
    int dim;                       /* 3, or 2 (planar surfaces)            */
    size_t num_nodes;              /* the caller's nodes, any order:       */
    const double *xyz;             /* 3 per node                           */
    double *xyz_give;              /* NULL, or xyz itself (malloc'd) if the
                                      caller gives it up: when the numbering
                                      keeps every node in place, step 1
                                      makes it out->xyz instead of a copy
                                      and sets this to NULL (the caller then
                                      must not free it)                    */
    uint8_t *flags;                /* GETME__NODE_* per node               */
    const getme__node_range *ranges; /* Gmsh's node order over them        */
    size_t num_ranges;
    getme__model_block *blocks;    /* Gmsh's element order                 */
    size_t num_blocks;
    size_t num_entities;           /* distinct block tags, in block order: */
    int *const *phys;              /* their physical tags (sorted here)    */
    const size_t *num_phys;
    int z_plane_only;              /* planar: stop (declined = 1) instead of
                                      rotating a mesh outside z = const    */
    unsigned fix_flags;            /* GETME_FIX_SKIN | GETME_FIX_INTERFACES */
    int regions_by_entity;         /* 1: every entity is its own region
                                      (MSH 2.2: see entity_regions)        */
    int nodes_distinct;            /* 1: the caller refused, with its own
                                      message, every element that has a node
                                      twice; the builder does not look again */
    int keep_copies;               /* 1: the caller takes out->xyz and
                                      out->fixed after step 2; 0: step 2
                                      frees them as soon as the mesh has
                                      its own (a lower peak while reading) */
} getme__model_in;

typedef struct getme__frame {
    int rotated;        /* 0: identity (all nodes share one z)  */
    double origin[3];
    double axis[3][3];  /* rows: e1, e2, normal                  */
} getme__frame;

typedef struct getme__model_out {
    int32_t num_nodes;
    int32_t *loc;       /* caller's node -> mesh node, -1 if unused       */
    double *xyz;        /* 3 per mesh node, in the mesh's frame; freed
                           (NULL) once step 2 has made the mesh, unless
                           getme__model_in.keep_copies                     */
    uint8_t *fixed;     /* fixed by classification / named groups; the
                           same                                           */
    int32_t num_elements;
    int64_t *elem_ids;  /* per mesh element: its tag                      */
    getme_mesh *mesh;
    getme__frame frame;
    int declined;       /* z_plane_only and the mesh is not in z = const  */
    char msg[512];      /* the reason of a failure                        */
} getme__model_out;

/* Step 1: type check, node numbering (loc, xyz, fixed), connectivity in
   mesh numbering.  After it the caller may free its own node arrays. */
getme_status getme__model_number(getme__model_in *in, getme__model_out *out);
/* Step 2: planar frame and orientation, the mesh, its element blocks with
   regions and ids, the fixed nodes.  Frees the blocks' arrays as it goes. */
getme_status getme__model_finish(getme__model_in *in, getme__model_out *out);
/* What the builder allocated (not the mesh once taken: set it NULL). */
void getme__model_out_free(getme__model_out *out);
/* The message for a block of a type GETMe cannot smooth. */
getme_status getme__model_type_error(int dim, int tag, int msh_type,
                                     char *msg, size_t size);

/* Planar meshes (planar.c): choose the frame, check that every surface is
   planar and that all lie in one plane, rewrite xyz in the frame and make
   every surface counter-clockwise there.  conn of the blocks: mesh nodes. */
getme_status getme__planar_prepare(getme__frame *frame, double *xyz,
                                   int32_t n, getme__model_block *blocks,
                                   size_t nb, char *msg, size_t size);
/* Sum of the signed areas (xy plane) of count planar elements, nv corners
   each, stride node ids apart (corners first, then Gmsh's mid-edge order),
   and the same elements made to turn the other way (mid-edge nodes stay
   on their edges): a surface, or an INP element block, that is clockwise
   as a whole is handed to libgetme reversed (its elements keep their
   orientation relative to each other, so a truly inverted one stays
   inverted). */
double getme__planar_area(const double *xyz, const int32_t *conn,
                          int32_t count, int nv, int stride);
void getme__planar_reverse(int32_t *conn, int32_t count, int nv, int stride);
/* 1 if every node has the z of the first. */
int getme__all_same_z(const double *xyz, int32_t n);
/* Local (frame) coordinates of one node back to model coordinates. */
void getme__frame_to_global(const getme__frame *frame, const double *local,
                            double *global);

#endif /* GETME_MODEL_H */
