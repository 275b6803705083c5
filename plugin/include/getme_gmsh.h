/*
 * getme_gmsh.h -- GETMe adaptive smoothing of the live Gmsh model
 * (libgetme_gmsh).
 *
 * Works on the current model of the calling process through Gmsh's public C
 * API (gmshc.h): after gmshModelMeshGenerate() or gmshOpen() of a mesh file,
 *
 *   getme_gmsh_options *opt = getme_gmsh_options_new();
 *   getme_gmsh_options_set(opt, "sigma", 1.5);
 *   getme_gmsh_options_add_fixed_group(opt, "clamp");     // physical name
 *   getme_gmsh_report rep;
 *   if (getme_gmsh_optimize(0, NULL, 0, opt, &rep) != GETME_OK)
 *       ... rep.message says why; the model is unchanged ...
 *   getme_gmsh_options_free(opt);
 *
 * The call mirrors gmshModelMeshOptimize(method, force, niter, dimTags): an
 * empty dimTags list means every entity of the highest mesh dimension.
 *
 * What is smoothed: linear tetrahedra, hexahedra, prisms and pyramids of
 * volumes (dim 3, mixed types and several volumes in one call), or linear
 * triangles and quadrangles of planar surfaces (dim 2).  Planar surfaces in
 * any orientation are accepted: they are rotated into the xy plane, smoothed
 * there and rotated back; surfaces that are not planar, or selected surfaces
 * that do not lie in one common plane, are refused.
 *
 * Which nodes move (docs/design.md §5): only nodes classified on the
 * smoothed entities themselves.  Nodes classified on entities of lower
 * dimension (geometric boundaries, interfaces, embedded points, curves and
 * surfaces) are fixed, so are the nodes of the physical groups named in the
 * options, and, defensively, every node on the mesh skin or on a face between
 * entities of different physical groups (a mesh read from MSH 2.2 keeps no
 * classification).  Moved nodes are written back with gmshModelMeshSetNode();
 * node and element tags, topology and every fixed node stay bit-identical.
 *
 * Errors (no mesh, an entity without elements, second-order or unsupported
 * elements, an inverted element, an unknown group name, ...) are logged
 * through Gmsh's logger as "Error   : ..." (when logging is on), returned as
 * a nonzero getme_status with a one-line message in the report, and leave the
 * model unchanged.  The library never prints by itself and never exits.
 *
 * Gmsh is process-global state: every function here acts on the current
 * model of the Gmsh instance loaded in this process (the same libgmsh.so the
 * gmsh Python module loads).  Calls must not run concurrently with other
 * Gmsh API calls.
 */
#ifndef GETME_GMSH_H
#define GETME_GMSH_H

#include "getme.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define GETME_GMSH_API __attribute__((visibility("default")))
#else
#define GETME_GMSH_API
#endif

/* ------------------------------------------------------------------------ */
/* Options                                                                  */
/* ------------------------------------------------------------------------ */

typedef struct getme_gmsh_options getme_gmsh_options;

/* Defaults: GETMe adaptive with getme_params_init() values, log level 2,
   skin and interfaces fixed, no named groups.  NULL if out of memory. */
GETME_GMSH_API getme_gmsh_options *getme_gmsh_options_new(void);
GETME_GMSH_API void getme_gmsh_options_free(getme_gmsh_options *options);

/*
 * Set a number by name: every name of getme_params_set() ("max_iter",
 * "sigma", "threshold_fraction", "num_threads", ...), plus
 *   "log"            0 silent, 1 start/end lines and quality histograms,
 *                    2 (default) also one line per iteration
 *   "fix_skin"       1 (default): also fix every node on the mesh skin
 *   "fix_interfaces" 1 (default): also fix nodes on faces between entities
 *                    of different physical groups
 *   "topology"       0 (default); 1: when some of the worst elements have no
 *                    free node, so that no node move can fix them (a tet
 *                    spanning between boundary nodes), first run Gmsh's own
 *                    topological optimizer (gmshModelMeshOptimize("")),
 *                    which swaps edges and faces, then GETMe adaptive on the
 *                    result.  Tetrahedral meshes only; the log says how many
 *                    elements it changed
 *   "worst"          10 (default, 0..10): worst elements kept in the report
 *                    and logged at log level 2
 *   "untangle"       1 (default): untangle a mesh with invalid (inverted or
 *                    degenerate) elements first (getme_mesh_untangle), with
 *                    a warning giving the counts; 0: refuse it
 *   "allow_invalid"  0 (default): if untangling leaves invalid elements the
 *                    model is unchanged; 1: the partly untangled coordinates
 *                    are written to the model (not smoothed); the call
 *                    returns GETME_ERR_INVALID_MESH either way
 * GETME_ERR_ARGUMENT for an unknown name or a value out of range (the
 * reason is in getme_gmsh_options_error()).
 */
GETME_GMSH_API getme_status getme_gmsh_options_set(getme_gmsh_options *options,
                                                   const char *name,
                                                   double value);
/* "getme" (or "adaptive") or "laplace" (smart Laplace, the baseline). */
GETME_GMSH_API getme_status
getme_gmsh_options_set_method(getme_gmsh_options *options, const char *method);
/* Add a physical group whose nodes stay fixed: its name, or "dim:tag". */
GETME_GMSH_API getme_status
getme_gmsh_options_add_fixed_group(getme_gmsh_options *options,
                                   const char *group);
/* The GETMe parameters inside (for C callers: relaxation tables, progress
   callback...).  Never NULL for a valid handle. */
GETME_GMSH_API getme_params *
getme_gmsh_options_params(getme_gmsh_options *options);
/* Message of the last failed setter ("" if none). */
GETME_GMSH_API const char *
getme_gmsh_options_error(const getme_gmsh_options *options);

/* ------------------------------------------------------------------------ */
/* Optimizing the current model                                             */
/* ------------------------------------------------------------------------ */

#define GETME_GMSH_MAX_WORST 10 /* worst elements kept in the report */

typedef struct getme_gmsh_report {
    int dim;                    /* 3 or 2: dimension smoothed                */
    int num_entities;           /* entities smoothed together                */
    int32_t num_nodes;          /* nodes of the selected elements            */
    int32_t num_elements;
    int32_t num_fixed;          /* of num_nodes                              */
    int32_t num_moved;          /* nodes written back with SetNode           */
    getme_quality_stats before; /* mean-ratio statistics before and after    */
    getme_quality_stats after;
    getme_result result;        /* iterations per stage, stop reason ...     */
    getme_untangle_result untangle; /* counts of the untangling step (all 0
                                   when the mesh was valid)                  */
    double wall;                /* seconds for the whole call (wall, CPU)    */
    double cpu;
    char message[512];          /* "" on success, else the error             */
    /* The analysts' measures (dihedral angles, scaled Jacobian, gamma,
       SICN; getme.h) per element type, before and after:
       [type][measure] as getme_mesh_measure_all() gives them. */
    getme_measure_stats measures_before[GETME_NUM_TYPES][GETME_NUM_MEASURES];
    getme_measure_stats measures_after[GETME_NUM_TYPES][GETME_NUM_MEASURES];
    /* The worst elements after smoothing and why each stays bad
       (getme_mesh_worst_elements; element = index in the smoothed mesh):
       worst over all elements, worst_free over those with a free node.
       *_tag: their Gmsh element tags. */
    int32_t num_worst, num_worst_free;
    getme_worst_element worst[GETME_GMSH_MAX_WORST];
    getme_worst_element worst_free[GETME_GMSH_MAX_WORST];
    size_t worst_tag[GETME_GMSH_MAX_WORST];
    size_t worst_free_tag[GETME_GMSH_MAX_WORST];
    /* Option "topology": Gmsh's own optimize("") ran first (1), with the
       element count before and after it and how many of the elements
       before it are gone (swapped away). */
    int topology_ran;
    int32_t topology_elements_before, topology_elements_after;
    int32_t topology_changed;
    /* Second-order elements (docs/highorder.md): how many, and the worst
       ratio of the smallest to the largest det J over an element's nodes
       before and after (getme_mesh_jacobian_ratio_min), with the Gmsh tag
       of that element; ratios 1 and tags 0 when there are none. */
    int32_t num_second_order;
    double jacobian_ratio_before, jacobian_ratio_after;
    size_t jacobian_ratio_tag_before, jacobian_ratio_tag_after;
} getme_gmsh_report;

/*
 * Smooth the mesh of the current Gmsh model.
 *   niter      maximum number of GETMe (or Laplace) iterations; <= 0 keeps
 *              the options' max_iter (default 1000)
 *   dim_tags   dim_tags_n / 2 pairs (dim, tag) of entities of one dimension
 *              (3, or 2 for planar surfaces); NULL / 0: all entities of the
 *              highest dimension that has mesh elements
 *   options    NULL: defaults
 *   report     may be NULL
 * Returns GETME_OK, or: GETME_ERR_STATE (Gmsh not initialized, no mesh),
 * GETME_ERR_ARGUMENT (bad entity, unknown group), GETME_ERR_TOPOLOGY
 * (unsupported or second-order elements, non-planar surface),
 * GETME_ERR_INVALID_MESH (inverted elements that untangling could not
 * repair, named with their Gmsh tags in the message, or any inverted element
 * with "untangle" = 0), GETME_ERR_NOMEM.  On error the model is unchanged
 * (except the partly untangled coordinates with "allow_invalid" = 1).
 */
GETME_GMSH_API getme_status getme_gmsh_optimize(
    int niter, const int *dim_tags, size_t dim_tags_n,
    const getme_gmsh_options *options, getme_gmsh_report *report);

/*
 * Mean-ratio statistics of the current model's elements (same selection
 * rules and fixed nodes as getme_gmsh_optimize()) into report->before and
 * the measures into report->measures_before (and copies in ->after,
 * ->measures_after); nothing is smoothed, nothing is logged.
 */
/* Each of names[0..n) names a physical group of the current model (its
   name or "dim:tag"): GETME_OK, else GETME_ERR_ARGUMENT and "Unknown
   physical group 'x' to <what> (the groups there are)" in msg. */
GETME_GMSH_API getme_status getme_gmsh_check_groups(const char *const *names,
                                                    int n, const char *what,
                                                    char *msg, size_t size);

GETME_GMSH_API getme_status getme_gmsh_quality(
    const int *dim_tags, size_t dim_tags_n, const getme_gmsh_options *options,
    getme_gmsh_report *report);

/* A report value by name, for bindings: "dim", "num_entities", "num_nodes",
   "num_elements", "num_fixed", "num_moved", "wall", "cpu", "iterations",
   "iterations_mean", "iterations_min", "cycles_min", "stop_reason",
   "threshold", "seconds", "passes_finish", "moved_finish",
   "corner_sj_before", "corner_sj_after", "topology_ran",
   "topology_changed", "topology_elements_before", "topology_elements_after",
   "num_worst", "num_worst_free", "untangle_invalid_before",
   "untangle_invalid_after", "untangle_sweeps", "untangle_moved",
   "num_second_order", "jacobian_ratio_before", "jacobian_ratio_after",
   "jacobian_ratio_tag_before", "jacobian_ratio_tag_after",
   "untangle_ho_repaired", "untangle_ho_moved", "untangle_ho_invalid",
   "reverted_nodes",
   "untangle_seconds", "<worst|worst_free><i>_<tag|index|type|
   quality|corner_sj|num_free|num_nodes|reason>", "<before|after>_<q_min_star|q_min|q_mean|q_max|
   num_invalid|num_below_04|num_below_01|num_elements|num_free>",
   "<before|after>_hist<0..9>".  NaN for an unknown name. */
GETME_GMSH_API double getme_gmsh_report_value(const getme_gmsh_report *report,
                                              const char *name);
GETME_GMSH_API size_t getme_gmsh_report_sizeof(void);
/* &report->measures_before[type][measure] (after != 0: measures_after), for
   bindings; NULL for a bad argument. */
GETME_GMSH_API const getme_measure_stats *
getme_gmsh_report_measure(const getme_gmsh_report *report, int after,
                          int type, int measure);
/* report->message, for bindings. */
GETME_GMSH_API const char *
getme_gmsh_report_message(const getme_gmsh_report *report);

/* ------------------------------------------------------------------------ */
/* Model extraction (the Python package's getme.gmsh uses it)               */
/* ------------------------------------------------------------------------ */

typedef struct getme_gmsh_model getme_gmsh_model;

/*
 * Build a getme_mesh from the current Gmsh model (selection as in
 * getme_gmsh_optimize), with the fixed nodes marked.  On failure *model is
 * NULL and message (if not NULL) receives the reason.  Does not log.
 */
GETME_GMSH_API getme_status getme_gmsh_model_read(
    getme_gmsh_model **model, const int *dim_tags, size_t dim_tags_n,
    const getme_gmsh_options *options, char *message, size_t message_size);
GETME_GMSH_API void getme_gmsh_model_free(getme_gmsh_model *model);

/* The mesh (owned by the model). */
GETME_GMSH_API getme_mesh *getme_gmsh_model_mesh(getme_gmsh_model *model);

/*
 * Write coordinates back into the current Gmsh model: coords holds 3 doubles
 * per mesh node in the mesh's frame (as getme_mesh_coords() gives them).
 * Only free nodes whose coordinates differ from those read are set.
 * *num_moved (may be NULL) receives their number.
 */
GETME_GMSH_API getme_status getme_gmsh_model_apply(
    const getme_gmsh_model *model, const double *coords, int32_t *num_moved,
    char *message, size_t message_size);

/* ------------------------------------------------------------------------ */
/* MSH files through the Gmsh SDK                                           */
/* ------------------------------------------------------------------------ */

/*
 * An adapter for libgetme_formats (getme_formats.h): the MSH files its
 * native reader declines (MSH 4.0, parametric nodes, partitioned meshes,
 * planar meshes outside z = const...) read by Gmsh's own reader, the model
 * handed to the same model builder, and written back by Gmsh (MSH 4) or as
 * a copy of the input with new coordinates (MSH 2.2).  Pass it in
 * getme_doc_options.adapters, as the getme command does:
 *
 *   const getme_format *extra[] = {getme_gmsh_format(), NULL};
 *   opts.adapters = extra;
 *
 * It initializes Gmsh if nobody did (silently: General.Terminal = 0), opens
 * each document as its own Gmsh model and removes that model on close.
 */
struct getme_format;
GETME_GMSH_API const struct getme_format *getme_gmsh_format(void);

#ifdef __cplusplus
}
#endif

#endif /* GETME_GMSH_H */
