/*
 * getme.h -- GETMe adaptive mesh smoothing (libgetme), the one public header.
 *
 * libgetme improves the shape of the elements of a volume mesh (tetrahedra,
 * hexahedra, prisms, pyramids, mixed) or a planar mesh (triangles, quads) by
 * moving free nodes only; it never changes the topology.  The method is
 * "GETMe adaptive" (Vartziotis & Wipper): geometric element transformations
 * that make each element more regular, combined by quality-weighted node
 * averaging and per-node relaxation that keeps every element valid.  Smart
 * Laplace is provided as the classic baseline.
 *
 * Conventions
 *  - All names are prefixed getme_ / GETME_.  No global mutable state: every
 *    function works on the handles and buffers passed to it and is safe to
 *    call from several threads on different handles.
 *  - Every fallible function returns a getme_status.  Functions taking a mesh
 *    also leave a one-line human readable message, retrievable with
 *    getme_mesh_error(), that names the element or node concerned.  The
 *    library never prints and never exits.
 *  - Node and element indices are zero-based int32_t in the order the caller
 *    supplied them.  Elements are numbered in the order of the
 *    getme_mesh_add_elements() calls, then in order within a call.
 *  - Node order inside an element is Gmsh's for the linear types (which is
 *    also Abaqus' C3D4/C3D6/C3D8 and CGNS' TETRA_4/PENTA_6/HEXA_8/PYRA_5):
 *      tet      0,1,2 counter-clockwise seen from 3
 *      hex      0-3 bottom face, 4-7 top face (4 above 0)
 *      prism    0,1,2 bottom triangle, 3,4,5 top (3 above 0)
 *      pyramid  0-3 base quad, 4 apex
 *      tri/quad counter-clockwise in the xy plane (a mesh whose elements are
 *               all clockwise is accepted and handled as mirrored)
 *  - Coordinates are always 3 doubles per node.  Planar meshes (dim 2) use x
 *    and y; z is carried through untouched.
 *  - Element quality is the mean ratio, in (0, 1] for a valid element, 1 for
 *    the regular element; an invalid (inverted or degenerate) element has
 *    quality 0.
 *  - Results are bit-identical for any number of OpenMP threads.
 */
#ifndef GETME_H
#define GETME_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define GETME_VERSION_MAJOR 0
#define GETME_VERSION_MINOR 1
#define GETME_VERSION_PATCH 0
#define GETME_VERSION_STRING "0.1.0"

#if defined(__GNUC__) && !defined(GETME_STATIC)
#define GETME_API __attribute__((visibility("default")))
#else
#define GETME_API
#endif

/* ------------------------------------------------------------------------ */
/* Status codes                                                             */
/* ------------------------------------------------------------------------ */

typedef enum getme_status {
    GETME_OK = 0,
    GETME_ERR_ARGUMENT = 1,     /* NULL pointer, out-of-range value, bad name */
    GETME_ERR_NOMEM = 2,        /* an allocation failed                       */
    GETME_ERR_INVALID_MESH = 3, /* the input has invalid (inverted) elements  */
    GETME_ERR_TOPOLOGY = 4,     /* node index out of range, repeated node ... */
    GETME_ERR_STATE = 5,        /* call out of order (e.g. no elements yet)   */
    GETME_ERR_CANCELLED = 6,    /* the progress callback asked to stop        */
    GETME_ERR_COMM = 7,         /* a getme_comm hook reported a failure       */
    GETME_ERR_INCOMPLETE = 8    /* getme_smooth_finish_sub(): grow the sub-mesh */
} getme_status;

/* A static English description of a status code ("invalid mesh", ...). */
GETME_API const char *getme_status_string(getme_status status);

/* Library version string, e.g. "0.1.0". */
GETME_API const char *getme_version(void);

/* ------------------------------------------------------------------------ */
/* Element types and single-element functions                               */
/* ------------------------------------------------------------------------ */

typedef enum getme_elem_type {
    GETME_TET = 0,
    GETME_HEX = 1,
    GETME_PRISM = 2,
    GETME_PYRAMID = 3,
    GETME_TRI = 4,
    GETME_QUAD = 5,
    GETME_NUM_TYPES = 6
} getme_elem_type;

/* Nodes per element (4, 8, 6, 5, 3, 4); 0 for an unknown type. */
GETME_API int getme_type_num_nodes(getme_elem_type type);
/* Topological dimension (3 for volume types, 2 for tri/quad); 0 if unknown. */
GETME_API int getme_type_dim(getme_elem_type type);
/* Lower-case name: "tet", "hex", "prism", "pyramid", "tri", "quad". */
GETME_API const char *getme_type_name(getme_elem_type type);

/*
 * Mean ratio quality of one element with nodes xyz[3*i..3*i+2] in the node
 * order above.  Returns a value in (0, 1] for a valid element and 0 for an
 * invalid one (any node simplex with a non-positive determinant, or a
 * non-finite coordinate).  Planar types read x and y only.
 */
GETME_API double getme_element_quality(getme_elem_type type, const double *xyz);

/*
 * One regularizing GETMe transformation of one element with parameter sigma
 * (the paper uses 1.5), followed by scaling about the centroid so that the
 * sum of edge lengths is preserved.  Writes the transformed nodes to out
 * (same layout as xyz; z of planar types is copied).  Iterating it converges
 * to the regular element of the type.  out may not alias xyz.
 */
GETME_API getme_status getme_element_transform(getme_elem_type type,
                                               const double *xyz, double sigma,
                                               double *out);

/* ------------------------------------------------------------------------ */
/* Mesh handle                                                              */
/* ------------------------------------------------------------------------ */

typedef struct getme_mesh getme_mesh;

/*
 * Create a mesh of dimension dim (3: volume types only, 2: tri/quad only)
 * with num_nodes nodes.  The coordinates (3 doubles per node) are copied.
 */
GETME_API getme_status getme_mesh_create(getme_mesh **mesh, int dim,
                                         int32_t num_nodes,
                                         const double *coords);

/*
 * As getme_mesh_create(), but the mesh takes coords instead of a copy of
 * it: coords must come from malloc() (or calloc/realloc), and belongs to
 * the mesh from the call on, which frees it with free() -- at once if the
 * call fails or num_nodes is 0.  For callers that build the coordinates
 * only to hand them over (libgetme_formats' readers): one copy of the
 * coordinates less, and its fresh pages (docs/bench.md, session 23).
 */
GETME_API getme_status getme_mesh_create_take(getme_mesh **mesh, int dim,
                                              int32_t num_nodes,
                                              double *coords);

GETME_API void getme_mesh_free(getme_mesh *mesh);

/* The message of the last failed call on this mesh ("" if none). */
GETME_API const char *getme_mesh_error(const getme_mesh *mesh);

/*
 * Append count elements of one type.  conn holds count * num_nodes(type)
 * zero-based node indices (copied).  region, optional (may be NULL), gives
 * each element a region id (Gmsh physical volume, Abaqus section, CGNS zone
 * or family...): faces between elements of different regions are interfaces
 * for getme_mesh_fix_boundary().  May be called several times, also for the
 * same type; elements are numbered in call order.
 * Fails with GETME_ERR_TOPOLOGY on a node index out of range or repeated
 * inside an element (the message names the element).
 */
GETME_API getme_status getme_mesh_add_elements(getme_mesh *mesh,
                                               getme_elem_type type,
                                               int32_t count,
                                               const int32_t *conn,
                                               const int32_t *region);

/*
 * As getme_mesh_add_elements(), but the mesh takes conn instead of a copy
 * of it: conn must come from malloc() (or calloc/realloc), and belongs to
 * the mesh from the call on, which frees it with free() -- at once if the
 * call fails or count is 0.  For callers that build the connectivity only
 * to hand it over (libgetme_formats' readers): one copy of the largest
 * input array less, and its fresh pages.
 */
GETME_API getme_status getme_mesh_take_elements(getme_mesh *mesh,
                                                getme_elem_type type,
                                                int32_t count, int32_t *conn,
                                                const int32_t *region);

GETME_API int getme_mesh_dim(const getme_mesh *mesh);
GETME_API int32_t getme_mesh_num_nodes(const getme_mesh *mesh);
GETME_API int32_t getme_mesh_num_elements(const getme_mesh *mesh);
/* Number of elements of one type. */
GETME_API int32_t getme_mesh_num_elements_of_type(const getme_mesh *mesh,
                                                  getme_elem_type type);

/* Element e (0-based, in the order of getme_mesh_add_elements): its type
   into *type and its node indices into nodes (room for 8); returns the
   number of nodes, or 0 if e is out of range. */
GETME_API int getme_mesh_get_element(const getme_mesh *mesh, int32_t e,
                                     getme_elem_type *type, int32_t *nodes);

/* Read-only view of the current coordinates (3 per node, caller's order);
   valid until the coordinates are set, or the mesh is smoothed with
   getme_mesh_lend_coords() on. */
GETME_API const double *getme_mesh_coords(const getme_mesh *mesh);
/* Copy the current coordinates into coords (3 * num_nodes doubles). */
GETME_API getme_status getme_mesh_get_coords(const getme_mesh *mesh,
                                             double *coords);
/* Replace all coordinates (3 * num_nodes doubles). */
GETME_API getme_status getme_mesh_set_coords(getme_mesh *mesh,
                                             const double *coords);
/*
 * on = 1: getme_smooth() may take the mesh's coordinate array as its own
 * working copy once the input is checked (24 bytes per node less at the
 * peak; first-order meshes), and gives it back reordered in place.  The
 * price: a failure during the smoothing loop itself (GETME_ERR_NOMEM)
 * then leaves the mesh valid but partly smoothed, as a cancellation does,
 * instead of unchanged.  Failures before the loop (invalid input,
 * arguments, memory for the set-up) still leave it unchanged.  Default 0;
 * the getme command sets it, as it writes nothing when smoothing fails.
 */
GETME_API void getme_mesh_lend_coords(getme_mesh *mesh, int on);

/* ---- second-order elements (docs/highorder.md) ------------------------- */

/* Second-order element types.  Node order is Gmsh's (MSH types 11, 17, 12,
   18, 13, 9, 16, 10, 19, 14): the corners first, in the linear type's
   order, then the mid-edge nodes, then face and body nodes.  The
   pyramids' shape functions are Gmsh's rational ones (docs/highorder.md). */
typedef enum getme_ho_type {
    GETME_TET10 = 0,
    GETME_HEX20 = 1,
    GETME_HEX27 = 2,
    GETME_PRISM15 = 3,
    GETME_PRISM18 = 4,
    GETME_TRI6 = 5,
    GETME_QUAD8 = 6,
    GETME_QUAD9 = 7,
    GETME_PYRAMID13 = 8,
    GETME_PYRAMID14 = 9,
    GETME_NUM_HO_TYPES = 10
} getme_ho_type;

/* Nodes per element (10, 20, 27, 15, 18, 6, 8, 9, 13, 14); 0 for an
   unknown type. */
GETME_API int getme_ho_type_num_nodes(getme_ho_type type);
/* The linear type of its corners (GETME_TET for GETME_TET10 ...), -1 if
   unknown. */
GETME_API int getme_ho_type_linear(getme_ho_type type);
/* Lower-case name: "tet10", "hex20", ... */
GETME_API const char *getme_ho_type_name(getme_ho_type type);

/*
 * Append count second-order elements: conn holds count * num_nodes(type)
 * node indices in Gmsh's order.  The corners become ordinary linear
 * elements (numbered and counted like getme_mesh_add_elements(), which is
 * called with the first corners of each element); the other nodes are
 * dependent: the smoother moves the corners and places the dependent nodes
 * from them (straight-sided elements stay straight-sided, curved ones keep
 * their curvature, docs/highorder.md), and every element must keep a
 * positive Jacobian determinant at all its nodes.  A dependent node is
 * fixed (never moves, bit for bit) when it is fixed itself (fix_nodes,
 * fixed mask) or when all corners of its edge or face are fixed.  Fails
 * with GETME_ERR_TOPOLOGY on indices out of range or repeated; a dependent
 * node shared inconsistently or used as a corner is reported by
 * getme_smooth().
 */
GETME_API getme_status getme_mesh_add_elements_ho(getme_mesh *mesh,
                                                  getme_ho_type type,
                                                  int32_t count,
                                                  const int32_t *conn,
                                                  const int32_t *region);
/* Number of second-order elements added. */
GETME_API int32_t getme_mesh_num_elements_ho(const getme_mesh *mesh);

/*
 * Second-order validity of element e (caller's index) at the current
 * coordinates: the smallest Jacobian determinant over its nodes divided by
 * the largest, into *ratio (1 for a linear element or a straight-sided
 * parallelepiped; <= 0 means invalid).  Uses the dependent nodes' current
 * coordinates as they are.
 */
GETME_API getme_status getme_mesh_element_jacobian_ratio(getme_mesh *mesh,
                                                         int32_t e,
                                                         double *ratio);
/* The smallest getme_mesh_element_jacobian_ratio() over the second-order
   elements into *ratio (1 if there are none) and that element's index into
   *element (-1 if none; the smallest index on ties). */
GETME_API getme_status getme_mesh_jacobian_ratio_min(getme_mesh *mesh,
                                                     double *ratio,
                                                     int32_t *element);

/* ---- fixed nodes -------------------------------------------------------- */

/* Flags for getme_mesh_fix_boundary(). */
enum {
    GETME_FIX_SKIN = 1,      /* nodes of faces (edges in 2-D) with one element */
    GETME_FIX_INTERFACES = 2 /* nodes of faces between different regions      */
};

/* Mark every node fixed[i] != 0 as fixed (adds to the current set). */
GETME_API getme_status getme_mesh_set_fixed_mask(getme_mesh *mesh,
                                                 const uint8_t *fixed);
/* Mark count nodes (zero-based indices) as fixed (adds). */
GETME_API getme_status getme_mesh_fix_nodes(getme_mesh *mesh, int32_t count,
                                            const int32_t *nodes);
/* Clear all fixed marks. */
GETME_API void getme_mesh_clear_fixed(getme_mesh *mesh);
/*
 * Fix skin and/or interface nodes as requested by flags.  Also fixes every
 * node not used by any element (it has nothing to be smoothed by).
 * *num_fixed (may be NULL) receives the total number of fixed nodes after.
 */
GETME_API getme_status getme_mesh_fix_boundary(getme_mesh *mesh,
                                               unsigned flags,
                                               int32_t *num_fixed);
/* Copy the fixed mask (num_nodes bytes, 1 = fixed) into fixed. */
GETME_API getme_status getme_mesh_get_fixed_mask(const getme_mesh *mesh,
                                                 uint8_t *fixed);
GETME_API int32_t getme_mesh_num_fixed(const getme_mesh *mesh);

/* ------------------------------------------------------------------------ */
/* Quality statistics                                                       */
/* ------------------------------------------------------------------------ */

#define GETME_HIST_BINS 10 /* bins [0,0.1), [0.1,0.2), ... [0.9,1.0]       */
#define GETME_MAX_REPORTED_INVALID 8

typedef struct getme_quality_stats {
    int64_t num_elements;  /* elements counted                               */
    int64_t num_invalid;   /* elements with quality 0 (inverted/degenerate)  */
    int64_t num_free;      /* elements with at least one free node          */
    double q_min;          /* minimum quality over all counted elements      */
    double q_min_star;     /* minimum over elements with a free node (q*min),
                              1 if there is none                             */
    double q_mean;         /* arithmetic mean quality                        */
    double q_max;
    int64_t num_below_04;  /* elements with q <= 0.4                          */
    int64_t num_below_01;  /* elements with q <  0.1                          */
    int64_t histogram[GETME_HIST_BINS]; /* valid elements per 0.1 bin         */
    int32_t num_reported_invalid;       /* entries used in first_invalid     */
    int32_t first_invalid[GETME_MAX_REPORTED_INVALID]; /* element indices   */
} getme_quality_stats;

/*
 * Quality statistics of the elements of one type (type in 0..5), or of all
 * elements (type = -1).  Uses the fixed mask for q_min_star.
 */
GETME_API getme_status getme_mesh_quality_stats(getme_mesh *mesh, int type,
                                                getme_quality_stats *stats);

/* Quality of every element (num_elements doubles) into q. */
GETME_API getme_status getme_mesh_element_qualities(getme_mesh *mesh,
                                                    double *q);

/*
 * getme_mesh_quality_stats() from the caller's qualities q (num_elements
 * doubles, element order, as getme_mesh_element_qualities() or
 * getme_mesh_measure_all_qualities() give them for the mesh's current
 * coordinates): no element is evaluated again, so one array serves the
 * statistics of every type, the measures and the worst lists.  q values
 * <= 0 (or NaN) count as invalid.  GETME_ERR_ARGUMENT for a NULL argument
 * (q may be NULL for a mesh without elements) or a type outside -1..5.
 */
GETME_API getme_status getme_mesh_quality_stats_from(getme_mesh *mesh,
                                                     const double *q,
                                                     int type,
                                                     getme_quality_stats *stats);

/* ---- the worst elements and why they stay bad -------------------------- */

typedef enum getme_worst_reason {
    GETME_WORST_IMPROVABLE = 0,   /* a node move that raises it exists: the
                                     smoother stopped on its limits          */
    GETME_WORST_ALL_FIXED = 1,    /* every node fixed (skin, fixed sets): no
                                     node move can change it; a topological
                                     optimiser (Gmsh's optimize) can         */
    GETME_WORST_INTERFACE = 2,    /* every node fixed, some only because they
                                     lie on a region interface (freeing
                                     interfaces would let it move)          */
    GETME_WORST_LOCAL_OPTIMUM = 3 /* each free node, and all of them
                                     together, at a local optimum: no small
                                     move raises the worst quality of the
                                     elements around them                   */
} getme_worst_reason;

typedef struct getme_worst_element {
    int32_t element;          /* caller's element index                     */
    getme_elem_type type;
    double quality;           /* mean ratio                                  */
    double corner_sj;         /* worst corner scaled Jacobian (hex, prism,
                                 pyramid, quad; 1 for tets and triangles)    */
    int num_nodes, num_free;  /* its nodes, and how many are free            */
    getme_worst_reason reason;
} getme_worst_element;

/* Flags of getme_mesh_worst_elements(). */
enum {
    GETME_WORST_FREE_ONLY = 1 /* only elements with at least one free node */
};

/*
 * The max_count elements of lowest quality (ties by index), worst first,
 * into out[0..*count), each with the reason it cannot improve further
 * (getme_worst_reason): all elements, or with GETME_WORST_FREE_ONLY only
 * those with a free node (the ones behind q*_min).  The probes move no
 * node: the mesh is unchanged bit for bit.
 */
GETME_API getme_status getme_mesh_worst_elements(getme_mesh *mesh,
                                                 int32_t max_count,
                                                 unsigned flags,
                                                 getme_worst_element *out,
                                                 int32_t *count);

/*
 * getme_mesh_worst_elements() ranking the caller's qualities q
 * (num_elements doubles, as for getme_mesh_quality_stats_from()) instead of
 * evaluating every element again; the reasons are probed for the listed
 * elements only.  The same list and reasons when q holds the mesh's
 * qualities.  GETME_ERR_ARGUMENT as getme_mesh_worst_elements(), or q NULL
 * for a mesh with elements and max_count > 0.
 */
GETME_API getme_status getme_mesh_worst_elements_from(
    getme_mesh *mesh, const double *q, int32_t max_count, unsigned flags,
    getme_worst_element *out, int32_t *count);

/* A static English description of a reason ("all nodes fixed", ...). */
GETME_API const char *getme_worst_reason_string(getme_worst_reason reason);

/* ------------------------------------------------------------------------ */
/* Quality measures for analysts (docs/quality.md)                          */
/* ------------------------------------------------------------------------ */

/*
 * The shape measures FE analysts read, besides the smoother's own mean
 * ratio.  Corners are the node simplices of getme_element_quality(): hex
 * every node with its 3 edge neighbours, prism every node with its 2
 * triangle neighbours and its vertical edge, pyramid the 4 base nodes with
 * their 2 base neighbours and the apex, quad every node with its 2
 * neighbours.  Planar types use x and y only and are oriented
 * counter-clockwise in the xy plane (mesh statistics use the mesh's
 * orientation, see getme.h conventions).
 *
 *  MEAN_RATIO       getme_element_quality(): (0, 1], 1 regular, 0 invalid.
 *  MIN_DIHEDRAL,    degrees.  3-D: the interior angle between the two faces
 *  MAX_DIHEDRAL     at each edge, measured at both ends of the edge (faces
 *                   may be non-planar: at end a the half-planes through the
 *                   edge and a's neighbour in each face), in [0, 180];
 *                   regular tet 70.5288, hex 90, prism 60/90, pyramid
 *                   54.7356/109.4712.  2-D: the interior angle at each
 *                   corner, in [0, 360) (> 180 at a reflex corner).
 *                   Unsigned: an inverted tet has the angles of its mirror
 *                   image.
 *  SCALED_JACOBIAN  Verdict / CUBIT corner-based, signed (never clamped at
 *                   0), 1 for the regular element:
 *                   tet  sqrt2 det(e01,e02,e03) / max over the 4 nodes of
 *                        the product of the 3 edge lengths at the node;
 *                   hex  min over the 8 corners and the centre (principal
 *                        axes) of det of the 3 unit edge vectors;
 *                   prism 2/sqrt3 * min over the 6 corners of det of the 3
 *                        unit edge vectors;
 *                   pyramid sqrt2 * min over the 4 base corners of det of
 *                        the 3 unit edge vectors, capped at 1 (a pyramid
 *                        taller than the regular one would reach sqrt2);
 *                   tri  2/sqrt3 cross(e01,e02) / max over the 3 nodes of
 *                        the product of the 2 edge lengths at the node;
 *                   quad min over the 4 corners of cross of the 2 unit
 *                        edge vectors.
 *                   Range [-1, 1]; prism [-2/sqrt3, 1] and pyramid
 *                   [-sqrt2, 1] (a fully inverted element's worst corner
 *                   can be its right-angled one).  0 for a zero-length
 *                   edge.
 *  GAMMA            Gmsh's gamma (its "gamma" element quality, 4.8.4):
 *                   tet 3 r/R (inscribed / circumscribed sphere radius),
 *                   tri 2 r/R (circles), both unsigned in [0, 1];
 *                   prism min over the 6 corners of |det| of the 3 unit
 *                   edge vectors times 2/sqrt3 (unsigned);
 *                   quad s (1 - max |90 - a_k| / 90), a_k the angles
 *                   between consecutive edge vectors in degrees, s = -1 if
 *                   a corner is inverted.  Not defined (NaN, not counted)
 *                   for hex and pyramid: Gmsh 4.8.4 returns 0 for them.
 *  SICN             Gmsh's signed inverse condition number ("minSICN"):
 *                   min over the corners of n det(S) / (|S|_F |cof S|_F)
 *                   (2-D: 2 det(S) / |S|_F^2), S the corner's edge matrix
 *                   times the inverse of the regular element's (the
 *                   mean ratio's W); in [-1, 1], negative if inverted.
 *
 * Values are NaN when the measure is not defined for the type.  A
 * degenerate element gives 0 (SICN, gamma, scaled Jacobian), never NaN,
 * for finite coordinates.
 */
typedef enum getme_measure {
    GETME_MEASURE_MEAN_RATIO = 0,
    GETME_MEASURE_MIN_DIHEDRAL = 1,
    GETME_MEASURE_MAX_DIHEDRAL = 2,
    GETME_MEASURE_SCALED_JACOBIAN = 3,
    GETME_MEASURE_GAMMA = 4,
    GETME_MEASURE_SICN = 5,
    GETME_NUM_MEASURES = 6
} getme_measure;

/* "mean_ratio", "min_dihedral", "max_dihedral", "scaled_jacobian",
   "gamma", "sicn"; "unknown" for anything else. */
GETME_API const char *getme_measure_name(getme_measure measure);
/* 1 if the measure is defined for the type, else 0. */
GETME_API int getme_measure_defined(getme_elem_type type,
                                    getme_measure measure);
/* The histogram range of a measure: [0, 1] for mean ratio, gamma, SICN and
   scaled Jacobian (negative values are counted apart), [0, 180] degrees
   for the dihedral angles.  Returns GETME_ERR_ARGUMENT if unknown. */
GETME_API getme_status getme_measure_range(getme_measure measure,
                                           double *lo, double *hi);

/* One measure of one element (nodes as for getme_element_quality()).
   NaN if the measure is not defined for the type or an argument is bad. */
GETME_API double getme_element_measure(getme_elem_type type,
                                       getme_measure measure,
                                       const double *xyz);

typedef struct getme_measure_stats {
    int64_t num_elements; /* elements counted (the measure is defined)      */
    int64_t num_negative; /* of them with a value < 0 (inverted corner)     */
    int64_t num_below;    /* value < hist_lo: not in the histogram          */
    double min, max, mean;/* 0 if num_elements is 0; mean in element order  */
    int32_t min_element;  /* global index of the first element with min,    */
    int32_t max_element;  /* ... with max; -1 if none                       */
    double hist_lo, hist_hi;            /* getme_measure_range()            */
    int64_t histogram[GETME_HIST_BINS]; /* values in [lo, hi] per bin, in
                                           equal bins; values above hi in
                                           the last one (mean ratio: invalid
                                           elements, 0, are in the first
                                           bin, unlike getme_quality_stats) */
} getme_measure_stats;

/*
 * Statistics of one measure over the elements of one type (0..5) or of all
 * types (-1; types where the measure is not defined are skipped).  The
 * values are computed in parallel and reduced in element order:
 * bit-identical for any thread count.
 */
GETME_API getme_status getme_mesh_measure_stats(getme_mesh *mesh, int type,
                                                getme_measure measure,
                                                getme_measure_stats *stats);

/*
 * Every measure of every element type at once: stats[type *
 * GETME_NUM_MEASURES + measure] (GETME_NUM_TYPES * GETME_NUM_MEASURES
 * entries) as getme_mesh_measure_stats(mesh, type, measure) gives them,
 * num_elements 0 for absent types and undefined measures.  One pass over
 * the elements for all measures (each element's nodes gathered once);
 * bit-identical for any thread count (the means' sums in element order).
 */
GETME_API getme_status getme_mesh_measure_all(getme_mesh *mesh,
                                              getme_measure_stats *stats);

/*
 * getme_mesh_measure_all(), and every element's mean ratio (the
 * MEAN_RATIO measure, bit for bit getme_mesh_element_qualities()) into q
 * (num_elements doubles; NULL: not kept), from the same sweep: what
 * getme_mesh_quality_stats_from() and getme_mesh_worst_elements_from()
 * take, so a caller needing all three evaluates each element once.
 * Bit-identical for any thread count.  GETME_ERR_ARGUMENT if mesh or stats
 * is NULL, GETME_ERR_NOMEM.
 */
GETME_API getme_status getme_mesh_measure_all_qualities(
    getme_mesh *mesh, getme_measure_stats *stats, double *q);

/*
 * One line summarising the measures of one element type, for logs:
 * "dihedral 12.34 to 160.21 deg, scaled Jacobian min 0.2342 mean 0.7812,
 * gamma min 0.1012 mean 0.8011, SICN min 0.3101 mean 0.8327" ("angles" for
 * planar types; " (N negative)" after a measure with negative values).
 * stats: the type's GETME_NUM_MEASURES entries, e.g.
 * &all[type * GETME_NUM_MEASURES] from getme_mesh_measure_all().  Writes
 * "" if the type has no element.  Returns what snprintf returns.
 */
GETME_API int getme_measure_summary(getme_elem_type type,
                                    const getme_measure_stats *stats,
                                    char *buf, size_t size);

/* One measure of every element (num_elements doubles; NaN where not
   defined) into values. */
GETME_API getme_status getme_mesh_element_measures(getme_mesh *mesh,
                                                   getme_measure measure,
                                                   double *values);

/* ------------------------------------------------------------------------ */
/* Smoothing parameters                                                     */
/* ------------------------------------------------------------------------ */

typedef enum getme_method {
    GETME_METHOD_ADAPTIVE = 0,     /* GETMe adaptive (paper Fig. 3)        */
    GETME_METHOD_SMART_LAPLACE = 1 /* smart Laplace, parallel form          */
} getme_method;

typedef enum getme_stage {
    GETME_STAGE_MEAN = 1,   /* q_mean oriented first stage                    */
    GETME_STAGE_MIN = 2,    /* q*_min oriented cycles                         */
    GETME_STAGE_LAPLACE = 3,/* smart Laplace iteration                        */
    GETME_STAGE_FINISH = 4  /* a pass of the finishing step (params.finish)   */
} getme_stage;

/* What the progress callback sees after every iteration. */
typedef struct getme_progress {
    int iteration;          /* 1-based, over both stages; in the finishing
                               step the pass number                          */
    getme_stage stage;
    int cycle;              /* q*_min cycle number (0 in the first stage)    */
    double q_min_star;      /* after this iteration                          */
    double q_mean;
    double threshold;       /* transformation threshold q_t in force (finish:
                               the quality bound of the pass's elements)     */
    int32_t num_transformed;/* elements transformed this iteration (finish:
                               elements worked on)                           */
    int32_t num_relaxed;    /* nodes that needed more than one relaxation step
                               (finish: elements whose quality rose)         */
    double elapsed;         /* seconds since getme_smooth() started           */
} getme_progress;

/* Return 0 to go on, nonzero to stop (the mesh stays valid).  The callback
   must not call getme functions on the mesh being smoothed: while
   getme_smooth() runs, the mesh's elements are lent to the smoother. */
typedef int (*getme_progress_fn)(const getme_progress *progress,
                                 void *user_data);

#define GETME_MAX_RELAX 16

typedef struct getme_params {
    getme_method method;
    int max_iter;              /* 1000: iterations over both stages          */
    double tol;                /* 1e-4: stop stage 1 (and Laplace) when the
                                  q_mean gain of an iteration is below it    */
    double sigma;              /* 1.5: transformation parameter              */
    int num_relax_mean;        /* relaxation table of the q_mean stage       */
    double relax_mean[GETME_MAX_RELAX]; /* (1, 1/4, 1/16, 0)                 */
    int num_relax_min;         /* relaxation table of the q*_min stage       */
    double relax_min[GETME_MAX_RELAX];  /* (1/2, 1/4, 1/10, 1/100, 0)        */
    int max_no_min_improve;    /* 5: iterations without q*_min gain that end
                                  a q*_min cycle                             */
    double min_tol;            /* 1e-5: a q*_min gain counts only if it is
                                  larger than this (without it, a nearly
                                  regular mesh creeps up by 1e-9 per
                                  iteration until max_iter)                  */
    double threshold_fraction; /* position of q_t among the sorted qualities
                                  of free elements (DetermineTransformation-
                                  Threshold), see README for the choice      */
    int keep_best;             /* 1: end on the coordinates with the best
                                  q*_min seen in the q*_min stage, and
                                  never below the input's q*_min (the nodes
                                  of elements below it go back to their
                                  input positions; 24 B per node)           */
    int finish;                /* 1: after the q*_min stage, the finishing
                                  step: worst elements first, local max-min
                                  optimisation of their free nodes; q*_min
                                  never decreases in it (README "Method
                                  notes").  0: the paper's method alone     */
    double finish_fraction;    /* 0.001: each finishing pass works on the
                                  elements below the quality at this
                                  position of the sorted free elements (at
                                  least 64 elements), worst first           */
    int finish_max_passes;     /* 100: at most this many finishing passes;
                                  they stop earlier once a pass raises
                                  q*_min by no more than min_tol            */
    int corner_guard;          /* 1: the corner guard.  A hex, prism,
                                  pyramid or quad whose worst corner scaled
                                  Jacobian would fall below both its old
                                  value and the floor counts as invalid in
                                  the relaxation (and the finishing step),
                                  so the mesh's worst corner never ends
                                  below the floor.  The floor is the
                                  input's worst corner, or corner_floor if
                                  that is higher                            */
    double corner_floor;       /* 0: see corner_guard; in [-1, 1].  Raising
                                  it protects corners more but blocks moves
                                  that pass through a bad corner: on the
                                  benchmark's distorted hexes 0.2 ends at
                                  q*_min 0.12 against 0.85 with 0          */
    int num_threads;           /* 0: OpenMP default                          */
    int renumber;              /* 1: reorder internally for cache locality
                                  (results stay bit-identical for any thread
                                  count; they may differ in the last bits
                                  from renumber = 0)                          */
    int untangle;              /* 1: getme_smooth() first untangles an input
                                  with invalid elements (getme_mesh_untangle)
                                  instead of refusing it; 0: refuse          */
    getme_progress_fn progress;/* optional, called after every iteration     */
    void *progress_data;
} getme_params;

/* Fill params with the paper's defaults (Sec. 3.1) and ours for the rest. */
GETME_API void getme_params_init(getme_params *params);

/* ---- the parameter table ------------------------------------------------ */

typedef enum getme_param_type {
    GETME_PARAM_REAL = 0, /* a double                                     */
    GETME_PARAM_INT = 1,  /* an integer                                   */
    GETME_PARAM_BOOL = 2, /* 0 or 1                                       */
    GETME_PARAM_ENUM = 3  /* an integer code (method: 0 adaptive, 1 laplace)*/
} getme_param_type;

/* One numeric parameter of getme_params: the single definition every
   binding (CLI, Python, Gmsh options and GUI) lists and checks against. */
typedef struct getme_param_info {
    const char *name;      /* "sigma", "threshold_fraction", ...           */
    getme_param_type type;
    double default_value;  /* what getme_params_init() sets               */
    double min, max;       /* allowed range, closed ...                    */
    int open_min;          /* ... except that min is excluded if set       */
    size_t offset;         /* of the field in getme_params (int or double) */
    const char *help;      /* one line                                     */
} getme_param_info;

/* How many parameters the table has; the i-th (NULL outside 0..count-1);
   the one named name (NULL if unknown). */
GETME_API int getme_param_count(void);
GETME_API const getme_param_info *getme_param_at(int i);
GETME_API const getme_param_info *getme_param_find(const char *name);

/*
 * Set a numeric parameter by name (any name of the table above: "method"
 * (0 adaptive, 1 laplace), "max_iter", "tol", "sigma", "max_no_min_improve",
 * "min_tol", "threshold_fraction", "keep_best", "finish", "finish_fraction",
 * "finish_max_passes", "corner_guard", "corner_floor", "num_threads",
 * "renumber", "untangle").  Returns GETME_ERR_ARGUMENT for an unknown name
 * or a value out of range (an integer kind given a fraction included).
 */
GETME_API getme_status getme_params_set(getme_params *params, const char *name,
                                        double value);
/* Read a numeric parameter by name into *value; GETME_ERR_ARGUMENT for an
   unknown name. */
GETME_API getme_status getme_params_get(const getme_params *params,
                                        const char *name, double *value);
/* Set a relaxation table: stage GETME_STAGE_MEAN or GETME_STAGE_MIN; values
   descending in [0,1], n in 1..GETME_MAX_RELAX, last value must be 0. */
GETME_API getme_status getme_params_set_relax(getme_params *params,
                                              getme_stage stage, int n,
                                              const double *values);
/* sizeof(getme_params), for bindings that allocate it themselves. */
GETME_API size_t getme_params_sizeof(void);

/* ------------------------------------------------------------------------ */
/* Smoothing                                                                */
/* ------------------------------------------------------------------------ */

typedef enum getme_stop_reason {
    GETME_STOP_CONVERGED = 0, /* no q*_min gain in a whole cycle / tol hit  */
    GETME_STOP_MAX_ITER = 1,
    GETME_STOP_CANCELLED = 2,
    GETME_STOP_NOTHING_TO_DO = 3 /* no free node                            */
} getme_stop_reason;

typedef struct getme_result {
    int iterations;           /* total                                        */
    int iterations_mean;      /* first (q_mean) stage, or Laplace iterations  */
    int iterations_min;       /* q*_min stage                                 */
    int cycles_min;           /* q*_min cycles                                */
    int passes_finish;        /* finishing passes (params.finish)             */
    int32_t moved_finish;     /* elements the finishing step improved        */
    double corner_sj_initial; /* worst corner scaled Jacobian of the hexes,
                                 prisms, pyramids and quads (1 if none)      */
    double corner_sj;         /* the same after smoothing                    */
    double q_min_star_initial, q_mean_initial;
    double q_min_star, q_mean, q_min;
    double threshold;         /* last transformation threshold q_t           */
    double seconds;           /* wall time of getme_smooth()                  */
    getme_stop_reason stop_reason;
    int64_t num_invalid_initial; /* invalid elements in the input, untangled
                                  before smoothing (params->untangle)        */
    int untangle_sweeps;      /* untangling sweeps (0 if the input was valid)*/
    double untangle_seconds;  /* wall time of the untangling, part of seconds*/
    int32_t reverted_nodes;   /* nodes put back at their input positions so
                                 that q*_min does not end below the input's
                                 (keep_best; 0 if it did not)               */
} getme_result;

/*
 * Smooth the mesh in place with params (NULL: defaults).  An input with
 * invalid elements is first untangled as by getme_mesh_untangle() (unless
 * params->untangle is 0); if that leaves invalid elements, or untangling is
 * off, the result is GETME_ERR_INVALID_MESH, with the count and the first
 * invalid elements in the message, and nothing moves.  Fixed nodes never
 * move (bit for bit); the output is valid.  result may be NULL.
 * GETME_ERR_CANCELLED is returned (with a valid, partly smoothed mesh and a
 * filled result) when the progress callback asks to stop.
 */
GETME_API getme_status getme_smooth(getme_mesh *mesh,
                                    const getme_params *params,
                                    getme_result *result);

/* ------------------------------------------------------------------------ */
/* Distributed smoothing (docs/distributed.md)                              */
/* ------------------------------------------------------------------------ */

/*
 * A mesh split over several processes (MPI ranks, say) is smoothed by
 * GETMe adaptive with the same result, bit for bit, as getme_smooth() on
 * the whole mesh, for any number of processes and threads.  Each process
 * calls getme_smooth_part() on its part: the elements it owns plus one
 * ghost layer, every element that shares a node with an owned one (so the
 * Eq. 9 neighbourhoods of owned elements are complete), with the nodes of
 * all of them and the fixed marks of the whole mesh.  The library never
 * talks to other processes itself: it calls the hooks below, which the
 * caller implements (dist/ does it with MPI).  A copy of a node is its
 * occurrence in one process's part; all copies of a node hold the same
 * values at all times.  Every hook returns 0 on success; any other value
 * makes getme_smooth_part() stop with GETME_ERR_COMM.  Every process calls
 * the same hooks in the same order (collective calls).
 *
 * 128-bit integers are passed as 16 bytes, two's complement, in the
 * machine's byte order (on x86-64: the low 64-bit word first); a sum of
 * them must be the exact 128-bit sum (add the low words, carry into the
 * high ones).
 */
typedef struct getme_comm {
    void *ctx;                  /* passed to every hook                      */
    const uint8_t *owned;       /* per element of the part: 1 = owned here,
                                   0 = ghost; every element of the whole
                                   mesh is owned by exactly one process     */
    const uint8_t *counted;     /* per node of the part: 1 = this process
                                   counts the node in reported node counts;
                                   exactly one copy of every node is 1      */
    /* Called once before the node hooks: the library keeps nodes in its
       own order; node i of the arrays the node hooks receive is node
       caller_index[i] of the part (a permutation of 0 .. num_nodes - 1). */
    int (*node_order)(void *ctx, int32_t num_nodes,
                      const int32_t *caller_index);
    /* values: per_node 128-bit integers per node (library order): replace
       those of every copy by the sum over all copies of the node. */
    int (*node_sum)(void *ctx, void *values, int per_node);
    /* flags: one byte per node (library order): set every copy to 1 if any
       copy is nonzero, else 0. */
    int (*node_or)(void *ctx, uint8_t *flags);
    /* Sums over all processes, in place (count values). */
    int (*sum_i64)(void *ctx, int64_t *values, int count);
    int (*sum_i128)(void *ctx, void *values, int count);
    /* Minimum over all processes, in place (count values). */
    int (*min)(void *ctx, double *values, int count);
} getme_comm;

/*
 * GETMe adaptive on this process's part (see getme_comm).  params as for
 * getme_smooth() (method GETME_METHOD_ADAPTIVE only); the finishing step
 * (params->finish) is not run here but by getme_smooth_finish() on the
 * gathered mesh or getme_smooth_finish_sub() on the worst elements'
 * patches.  The input must be valid (every element of every part;
 * untangle the whole mesh first): otherwise every process returns
 * GETME_ERR_INVALID_MESH.  result holds the values of the whole mesh
 * (identical on every process).  The positions of the part's nodes are
 * those getme_smooth() reaches before its finishing step.  The progress
 * callback is called on every process with the same values; its return
 * value is ignored (a stop must be the same on all processes).
 */
GETME_API getme_status getme_smooth_part(getme_mesh *part,
                                         const getme_params *params,
                                         const getme_comm *comm,
                                         getme_result *result);

/*
 * The end of a distributed run, on one process holding the whole mesh as
 * read (mesh at its input coordinates): set the coordinates to xyz (3 per
 * node, the gathered positions getme_smooth_part() reached) and run the
 * finishing step exactly as getme_smooth() does after its loop; result
 * (filled by getme_smooth_part()) is updated (finishing passes, final
 * statistics, seconds added).  The mesh then equals getme_smooth()'s
 * output bit for bit, for any thread count (the finishing step makes the
 * same moves on any number of threads); it touches only the worst
 * elements' neighbourhoods.
 */
GETME_API getme_status getme_smooth_finish(getme_mesh *mesh,
                                           const getme_params *params,
                                           const double *xyz,
                                           getme_result *result);

/*
 * The finishing step on a sub-mesh (docs/distributed.md, "The finishing
 * step on a sub-mesh"): the same moves as getme_smooth_finish() on the
 * whole mesh, without holding it.  The finishing step only moves free
 * nodes of the worst elements; the caller sends one process the elements
 * around them (the sub-mesh) and constants of the rest of the mesh.
 *
 * The whole mesh's element order decides ties and the order of node stars;
 * a sub-mesh reproduces it from one 64-bit key per element:
 *
 *   key = type << 61 | morton << 31 | index
 *
 * type the getme_elem_type (linear), index the element's index in the
 * whole mesh (< 2^31), morton the 30-bit Morton code of the element's first
 * node at the whole mesh's INPUT coordinates in the bounding box lo, hi of
 * all nodes of the whole mesh (used or not): per axis d,
 * s = (x_d - lo_d) * 1023 / (hi_d - lo_d) (0 if hi_d = lo_d), clamped to
 * [0, 1023] and truncated to an integer, its 10 bits spread to every third
 * bit from bit d.  With params->renumber = 0 morton is 0 (lo = hi = NULL).
 * getme_element_key() computes it.
 */
GETME_API uint64_t getme_element_key(getme_elem_type type, int32_t index,
                                     const double first_node_xyz[3],
                                     const double lo[3], const double hi[3]);

/*
 * Constants of the elements outside a sub-mesh (they do not move): count,
 * count with a free node, the exact fixed-point sum of their mean ratios
 * (128-bit two's complement, q_sum[0] the low 64 bits; order-free, so
 * per-process parts can be merged in any order), the lowest mean ratio,
 * the lowest among elements with a free node, the worst corner scaled
 * Jacobian (1 without corners).  Minima start at 1 (an empty rest).
 */
typedef struct getme_finish_rest {
    int64_t num_elements;
    int64_t num_free_elements;
    uint64_t q_sum[2];
    double q_min, q_min_free, corner_min;
} getme_finish_rest;

/* An empty rest (counts and sum 0, minima 1). */
GETME_API void getme_finish_rest_init(getme_finish_rest *rest);

/* Add the elements e of mesh with include[e] != 0 (NULL: all) at the
   mesh's coordinates and fixed marks (those of the whole mesh).  q: their
   getme_element_quality() values if the caller has them (per element of
   mesh; NULL: computed here).  GETME_ERR_ARGUMENT for planar and
   second-order meshes (not supported). */
GETME_API getme_status getme_finish_rest_add(getme_finish_rest *rest,
                                             const getme_mesh *mesh,
                                             const uint8_t *include,
                                             const double *q);

/* into += from (counts and sum added, minima taken). */
GETME_API void getme_finish_rest_merge(getme_finish_rest *into,
                                       const getme_finish_rest *from);

/*
 * getme_smooth_finish() on a sub-mesh.  sub: elements of the whole mesh
 * (linear volume elements: a planar sub-mesh would decide its orientation
 * alone; GETME_ERR_ARGUMENT) added in ascending key order, nodes at the positions the
 * distributed loop reached, fixed marks of the whole mesh (set with
 * getme_mesh_set_fixed_mask: the sub-mesh's cut is not skin); key: per
 * element (getme_element_key()); complete: per node, 1 when every element
 * of the whole mesh containing it is in sub; rest: the other elements;
 * result as filled by getme_smooth_part() (its corner_sj_initial is the
 * whole input's).  The nodes of sub then hold, bit for bit, what
 * getme_smooth_finish() gives on the whole mesh, and result its values
 * for the whole mesh.
 *
 * Exactness is checked every pass: the pass bound (the quality at
 * finish_fraction of the whole mesh's free elements) must be below
 * rest->q_min_free, and every free node of an element at or below it must
 * be complete.  If not, GETME_ERR_INCOMPLETE: nothing is stored, no
 * progress is reported, result is unchanged but for result->threshold, the
 * pass bound that did not fit (a bigger sub-mesh holds at least every free
 * element at or below it, with complete stars); grow the sub-mesh (or use
 * the whole mesh) and call again.  The checks depend only on the data, so
 * every caller decides alike.  The progress callback is called once per
 * pass after the step succeeded (its return value is ignored: a stop must
 * not depend on where the mesh is held).
 */
GETME_API getme_status getme_smooth_finish_sub(getme_mesh *sub,
                                               const getme_params *params,
                                               const uint64_t *key,
                                               const uint8_t *complete,
                                               const getme_finish_rest *rest,
                                               getme_result *result);

/* ------------------------------------------------------------------------ */
/* Untangling                                                               */
/* ------------------------------------------------------------------------ */

typedef struct getme_untangle_result {
    int64_t num_invalid_before; /* invalid elements at the start           */
    int64_t num_invalid_after;  /* invalid elements at the end (0: success) */
    int64_t num_stuck;          /* of those, elements without a free node   */
    int32_t num_reported;       /* entries used in remaining                */
    int32_t remaining[GETME_MAX_REPORTED_INVALID]; /* smallest indices of
                                   the elements still invalid              */
    int32_t num_moved;          /* nodes that moved                         */
    int sweeps;                 /* sweeps over the moving nodes             */
    int rings;                  /* rings of nodes added around the invalid
                                   elements' nodes (0: only their own)      */
    double seconds;
    int32_t num_ho_repaired;    /* second-order elements invalid only at
                                   their non-corner nodes, repaired by
                                   pulling their free mid-nodes toward the
                                   straight position (docs/highorder.md)   */
    int32_t num_ho_moved;       /* dependent nodes moved to repair them     */
    int32_t num_ho_invalid;     /* second-order elements found invalid only
                                   at their non-corner nodes; those of them
                                   still invalid (num_ho_invalid -
                                   num_ho_repaired) stop the smoothing with
                                   GETME_ERR_INVALID_MESH                   */
} getme_untangle_result;

/*
 * Untangle the mesh in place: move free nodes near invalid (inverted or
 * degenerate) elements until every element is valid in the sense of
 * getme_element_quality() > 0 (docs/untangle.md: Escobar et al.'s modified
 * mean ratio, minimised node by node in colour order).  Only free nodes of
 * invalid elements, and if needed up to three rings of free nodes around
 * them, move; all others stay bit for bit.  Uses params->num_threads and
 * params->renumber (NULL: defaults); the result is bit-identical for any
 * thread count.  Returns GETME_OK when no invalid element is left (a valid
 * input is left unchanged), GETME_ERR_INVALID_MESH when some could not be
 * untangled (for example all their nodes are fixed): the mesh then holds the
 * partly untangled coordinates and the message names the first of them.
 * result may be NULL.
 */
GETME_API getme_status getme_mesh_untangle(getme_mesh *mesh,
                                           const getme_params *params,
                                           getme_untangle_result *result);

/*
 * Distort the mesh for tests and benchmarks: rounds of random moves of free
 * nodes (deterministic for a seed), each move a random vector of length up to
 * amount times the node's shortest incident edge, kept only if every
 * incident element stays valid.  Stops after max_rounds rounds or once
 * q_mean <= target_q_mean (pass 0 to run all rounds).  Never invalidates.
 */
GETME_API getme_status getme_mesh_distort(getme_mesh *mesh, uint64_t seed,
                                          double amount, double target_q_mean,
                                          int max_rounds);

#ifdef __cplusplus
}
#endif

#endif /* GETME_H */
