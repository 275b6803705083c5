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
#include "model.h"

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
/* 1 if the current model has partition entities (gmsh -part). */
int gg_model_partitioned(void);

/* ---- entity selection (gmsh_select.c) ----------------------------------- */

/* Choose the (dim, tag) pairs to smooth: *pairs (malloc'd, 2 ints each),
   *count entities, *dim.  Explicit dim_tags are checked (existence, one
   dimension 2 or 3, elements present). */
getme_status gg_select_entities(const int *dim_tags, size_t dim_tags_n,
                                int **pairs, int *count, int *dim,
                                gg_msg *msg);

/* ---- physical groups of entities (gmsh_regions.c) ---------------------- */

/* Each selected entity's physical tags (*phys[i]: gmsh-allocated, may be
   NULL; *phys and *num_phys: count entries, malloc'd). */
getme_status gg_entity_phys(const int *pairs, int count, int ***phys,
                            size_t **num_phys, gg_msg *msg);

/* ---- the model (gmsh_model.c) ------------------------------------------- */

/* Elements read from one entity and one Gmsh element type. */
typedef struct gg_block {
    int gmsh_type;
    int type;           /* getme type */
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
    getme__frame frame;
    getme_mesh *mesh;
};

/* ---- fixed nodes (gmsh_fixed.c) ----------------------------------------- */

/* Flag (per node of the model, all: tag -> index) the nodes classified on
   the selected entities (GETME__NODE_OWN), and those of the named groups
   (GETME__NODE_FIXGRP); the builder fixes all but the first kind. */
getme_status gg_fix_classified(const getme_gmsh_model *model,
                               const getme__nodemap *all, uint8_t *flags,
                               gg_msg *msg);
getme_status gg_fix_groups(const getme_gmsh_options *opt,
                           const getme__nodemap *all, uint8_t *flags,
                           gg_msg *msg);

/* ---- model accessors (gmsh_model_access.c) ------------------------------ */

getme_mesh *gg_model_take_mesh(getme_gmsh_model *model);
/* Describe mesh element e for messages: "tetrahedron 1234 in volume 2". */
void gg_describe_element(const getme_gmsh_model *model, int32_t e, char *buf,
                         size_t size);

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
