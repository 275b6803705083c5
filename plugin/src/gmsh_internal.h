/*
 * gmsh_internal.h -- private pieces of libgetme_gmsh shared by its files.
 *
 * Naming: gg_ prefix (getme-gmsh), static linkage everywhere else.  Every
 * fallible helper writes a one-line reason into a gg_msg and returns a
 * getme_status; nothing here prints or exits.
 */
#ifndef GETME_GMSH_INTERNAL_H
#define GETME_GMSH_INTERNAL_H

#include "getme_gmsh.h"

#include <stddef.h>
#include <stdint.h>

#define GG_MSG 512

typedef struct gg_msg {
    char text[GG_MSG];
} gg_msg;

/* printf into msg->text and return status. */
getme_status gg_fail(gg_msg *msg, getme_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* ---- options (gmsh_options.c) ------------------------------------------- */

struct getme_gmsh_options {
    getme_params params;
    int log;            /* 0, 1, 2 */
    int fix_skin;
    int fix_interfaces;
    int topology;       /* 0/1: Gmsh's optimize("") first when needed */
    int worst;          /* 0..GETME_GMSH_MAX_WORST                   */
    int allow_invalid;  /* write partly untangled coordinates back */
    int num_fix, cap_fix;
    char **fix;         /* physical group names or "dim:tag" */
    char error[256];
};

/* Defaults into a caller-owned struct (no named groups). */
void gg_options_defaults(getme_gmsh_options *opt);

/* ---- Gmsh helpers (gmsh_util.c) ----------------------------------------- */

/* 1 if gmshInitialize() has been called in this process (quiet probe). */
int gg_gmsh_initialized(void);
/* "point", "curve", "surface", "volume" (Gmsh's words) for dim 0..3. */
const char *gg_dim_word(int dim);
/* Capitalised: "Point", "Curve", "Surface", "Volume". */
const char *gg_dim_Word(int dim);
/* Gmsh's last error as a string (static fallback if none). */
void gg_gmsh_last_error(char *buf, size_t size);
/* getme type of a linear Gmsh element type, or -1. */
int gg_getme_type(int gmsh_type);
/* getme_ho_type of a second-order volume type, -1 if none (gmsh_util.c). */
int gg_ho_type(int gmsh_type);
/* Readable Gmsh element type name: "tetrahedron", "10-node tetrahedron". */
void gg_gmsh_type_name(int gmsh_type, char *buf, size_t size);
/* Order (1, 2, ...) of a Gmsh element type, 0 if unknown. */
int gg_gmsh_type_order(int gmsh_type);

/* ---- entity selection (gmsh_select.c) ----------------------------------- */

/* Choose the (dim, tag) pairs to smooth: *pairs (malloc'd, 2 ints each),
   *count entities, *dim.  Explicit dim_tags are checked (existence, one
   dimension 2 or 3, elements present). */
getme_status gg_select_entities(const int *dim_tags, size_t dim_tags_n,
                                int **pairs, int *count, int *dim,
                                gg_msg *msg);

/* ---- node tag -> index map (gmsh_nodemap.c) ----------------------------- */

typedef struct gg_nodemap {
    size_t max_tag;
    int32_t *dense;     /* max_tag + 1 entries, -1 = absent; or NULL */
    size_t *sorted_tag; /* sorted tags (sparse numbering), with...       */
    int32_t *sorted_idx;/* ... their indices                              */
    size_t n;
} gg_nodemap;

getme_status gg_nodemap_build(gg_nodemap *map, const size_t *tags, size_t n,
                              gg_msg *msg);
/* Index of tag, -1 if absent. */
int32_t gg_nodemap_find(const gg_nodemap *map, size_t tag);
void gg_nodemap_free(gg_nodemap *map);

/* ---- physical-group regions (gmsh_regions.c) ---------------------------- */

/* Region id per selected entity: entities with the same non-empty set of
   physical groups share an id; an entity in no physical group gets its own
   id.  regions has count entries. */
getme_status gg_entity_regions(const int *pairs, int count, int32_t *regions,
                               gg_msg *msg);

/* ---- planar frame (gmsh_planar.c) --------------------------------------- */

typedef struct gg_frame {
    int rotated;        /* 0: identity (all nodes share one z) */
    double origin[3];
    double axis[3][3];  /* rows: e1, e2, normal */
} gg_frame;

/* Choose the frame of a planar mesh (xyz: n nodes; blocks with their
   local connectivity conn[b]) and check that every surface is planar and
   that all lie in one plane.  Then rewrite xyz in the frame and reverse the
   node order of the elements of every surface whose majority is clockwise
   there, so that valid elements are counter-clockwise. */
struct gg_block;
getme_status gg_planar_prepare(gg_frame *frame, double *xyz, int32_t n,
                               const struct gg_block *blocks, int nb,
                               int32_t *const *conn, gg_msg *msg);
/* Local (frame) coordinates of one node back to model coordinates. */
void gg_frame_to_global(const gg_frame *frame, const double *local,
                        double *global);

/* ---- the model (gmsh_model.c) ------------------------------------------- */

/* Elements read from one entity and one Gmsh element type. */
typedef struct gg_block {
    int gmsh_type;
    int type;           /* getme type (of the corners)                    */
    int ho;             /* getme_ho_type, -1 for a linear block            */
    int nv;             /* nodes per element                              */
    int dim, tag;       /* entity */
    int32_t first;      /* first global element index */
    int32_t count;
} gg_block;

struct getme_gmsh_model {
    int dim;
    int num_entities;
    int *entities;      /* 2 * num_entities */
    int32_t num_nodes, num_elements;
    size_t *node_tags;  /* num_nodes */
    double *coords0;    /* 3 * num_nodes, mesh frame, as read */
    uint8_t *fixed;     /* num_nodes, the fixed mask handed to the mesh */
    size_t *elem_tags;  /* num_elements */
    gg_block *blocks;
    int num_blocks;
    gg_frame frame;
    getme_mesh *mesh;
};

/* ---- fixed nodes (gmsh_fixed.c) ----------------------------------------- */

/* Mark in fixed[] (model->num_nodes entries, pre-zeroed) the nodes not
   classified on the selected entities, and those of the named groups. */
getme_status gg_fix_classified(const getme_gmsh_model *model,
                               const gg_nodemap *local, uint8_t *fixed,
                               gg_msg *msg);
getme_status gg_fix_groups(const getme_gmsh_options *opt,
                           const gg_nodemap *local, uint8_t *fixed,
                           gg_msg *msg);

/* ---- logging (gmsh_log.c) ----------------------------------------------- */

void gg_log(const char *level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void gg_log_histogram(const getme_quality_stats *s);
/* One "Measures WHEN (type): ..." line per element type present in m
   (getme_gmsh_report.measures_before/after). */
void gg_log_measures(const char *when,
                     const getme_measure_stats (*m)[GETME_NUM_MEASURES]);
int gg_log_progress(const getme_progress *p, void *user);

#endif /* GETME_GMSH_INTERNAL_H */
