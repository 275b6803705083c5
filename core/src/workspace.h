/*
 * workspace.h -- the smoother's working copy of a mesh.
 *
 * getme_smooth() does not iterate over the caller's arrays directly.  It
 * builds a workspace (docs/design.md §6, §7) with
 *  - elements grouped by type and, inside a type, sorted by the Morton key
 *    (10 bits per axis in the bounding box) of their first node, and nodes
 *    numbered in first-touch order of that element order, so neighbouring
 *    elements and nodes are close in memory (renumber = 1);
 *  - a node -> element CSR ("stars"), each star sorted by element index;
 *  - blocks of 512 consecutive elements (one type each), the unit of the
 *    stage-1 sweeps.  Which blocks run at the same time (none sharing a
 *    node, so the scatter needs no atomics) is block_local.h's visiting
 *    order; the sums are exact integers, so any such order gives the
 *    same bits for any number of threads.
 */
#ifndef GETME_WORKSPACE_H
#define GETME_WORKSPACE_H

#include "highorder.h"
#include "pack.h"

#include <stdint.h>

#include "offsets.h"

/* The face table, 2 bytes per face (facenb.h). */
typedef struct getme_facenb {
    int16_t *d;       /* per entry: 0 skin, an escape's code, else nb - e */
    int32_t *enb;     /* escapes: the neighbour                           */
    int64_t *cptr;    /* chunks + 1: each chunk's first escape            */
    int64_t n;        /* entries                                          */
} getme_facenb;

typedef struct getme_ws {
    int dim;
    int nt;              /* OpenMP threads to use                           */
    int32_t nn, ne;
    int32_t tstart[GETME_NUM_TYPES + 1]; /* elements of type t: [tstart[t],
                                            tstart[t+1])                    */
    int64_t coff[GETME_NUM_TYPES];       /* conn offset of type t's first  */
    int32_t *conn;       /* internal node indices, type-grouped              */
    int32_t *elem_orig;  /* internal -> caller element index                 */
    int32_t *node_orig;  /* internal -> caller node index                    */
    double *x;           /* 3 * nn internal coordinates (y negated if mirrored)
                                                                            */
    uint8_t *fixed;      /* nn, 1 = fixed                                    */
    uint8_t *free_elem;  /* ne, 1 = has at least one free node              */
    int32_t num_free_elem;
    int32_t num_free_nodes; /* free nodes used by at least one element       */
    int32_t *star_ptr;   /* nn + 1; 32-bit: the stars hold every element's
                            nodes, so fewer than 2^31 entries (the build
                            fails with GETME_ERR_NOMEM beyond)              */
    int32_t *star;       /* incident elements of each node, ascending; from
                            the loop on packed (stars.h: star_ptr then
                            holds byte offsets)                             */
    int stars_packed;
    getme_offsets star_offs; /* once packed: star_ptr in 2.25 B per node
                                (offsets.h), star_ptr then NULL; read
                                both through getme__ws_star_at         */
    int32_t max_star;    /* largest star                                     */
    /* blocks */
    int32_t num_blocks;
    int32_t *block_start; /* num_blocks + 1, element ranges (one type each)  */
    getme_ho_ws *ho;      /* second-order elements' dependent nodes, or NULL */
    int conn_lent;        /* the mesh's block lent its connectivity
                             (getme__ws_lend_conn)                          */
    int x_lent;           /* the mesh lent its coordinates (getme__ws_lend_x)
                                                                            */
    double *x_spare;      /* NULL, or 3 * nn doubles (malloc'd) that a run
                             no longer needs: getme__ws_return_x puts the
                             coordinates there instead of in fresh pages  */
    /* elem_orig and node_orig while packed (getme__ws_pack_map), both then
       NULL; maps_packed: 0 never, 1 packed, 2 unpacked into ws->star's
       block (node_orig then points inside it, after elem_orig)            */
    getme_packed elem_packed, node_packed;
    int maps_packed;
    getme_facenb faces;   /* the face table (getme__ws_faces) the boundary
                             search computed, packed, for getme__adj_build
                             to take over; faces.d NULL if none             */
} getme_ws;

/* Walks over the stars (edges, faces) touch each star's elements at
   scattered places: they prefetch the element this many entries ahead. */
#define GETME_STAR_AHEAD 12

/* Build the workspace; renumber: 1 for locality ordering, 0 keeps the
   caller's order.  With renumber 1 it takes over the mesh's cached
   workspace (getme__ws_keep) when there is one: the same arrays a build
   would give, as coordinates and elements have not changed since; only
   the fixed flags are read again.  Returns GETME_OK or GETME_ERR_NOMEM. */
getme_status getme__ws_build(getme_ws *ws, getme_mesh *mesh, int renumber,
                             int num_threads);
void getme__ws_free(getme_ws *ws);

/* Keep ws (built with renumber 1) in mesh->ws_cache for the next
   getme__ws_build; frees it instead if out of memory.  ws is emptied. */
void getme__ws_keep(getme_ws *ws, getme_mesh *mesh);

/* While the smoother runs, the connectivity of a one-block first-order
   mesh is the workspace's in another order: the mesh frees its array
   (16 B per tet, 32 B per hex) and getme__ws_return_conn rebuilds it
   from ws->conn, which it hands over: permuted into a new array when there
   is memory (in parallel; callers free their larger arrays first), in
   place otherwise, so it cannot fail.  Nothing may read the mesh's
   elements in between. */
void getme__ws_lend_conn(getme_ws *ws, getme_mesh *mesh);
void getme__ws_return_conn(getme_ws *ws, getme_mesh *mesh);

/* The same for the coordinates, if the caller allowed it
   (getme_mesh_lend_coords; first-order meshes): the mesh frees its array
   (24 B per node) and getme__ws_return_x makes ws->x, put back in the
   caller's order (like getme__ws_return_conn), the mesh's array.  The smoother calls it once
   the input is checked, so only a failure in the loop itself (out of
   memory) leaves the mesh partly smoothed. */
void getme__ws_lend_x(getme_ws *ws, getme_mesh *mesh);
void getme__ws_return_x(getme_ws *ws, getme_mesh *mesh);

/* During getme_smooth's loop nothing reads elem_orig and node_orig: they
   are held packed (pack.h; tets 1.5 B per element and per node less).
   getme__ws_unpack_map writes them back into the stars' array, which must
   no longer be needed (ws->star becomes NULL; no allocation, so it cannot
   fail; packing is skipped unless the stars have room for both). */
void getme__ws_pack_map(getme_ws *ws);
void getme__ws_unpack_map(getme_ws *ws);

/* The 30-bit Morton key the element order uses (renumber = 1): each
   coordinate's (x - lo) * scale clamped to [0, 1023] and truncated, its
   bits spread to every third bit from bit d (scale = 1023 / extent, 0 for
   a flat axis). */
uint32_t getme__morton(const double *x, const double lo[3],
                       const double scale[3]);

/* Write the workspace coordinates back to the mesh (undoing mirror/order);
   lent coordinates are returned (getme__ws_return_x). */
void getme__ws_store(getme_ws *ws, getme_mesh *mesh);

/* star_ptr[v], plain or packed (getme__stars_pack). */
static inline int32_t getme__ws_star_at(const getme_ws *ws, int64_t v)
{
    return ws->star_ptr ? ws->star_ptr[v] : getme__offs_at(&ws->star_offs, v);
}

/* Node i is one the smoother moves: free and in an element (star_ptr's
   difference is 0 exactly for an empty star, plain or packed). */
static inline int getme__ws_moves(const getme_ws *ws, int32_t i)
{
    return !ws->fixed[i] && getme__ws_star_at(ws, i + 1) > getme__ws_star_at(ws, i);
}

static inline int getme__ws_type(const getme_ws *ws, int32_t e)
{
    int t = 0;
    while (e >= ws->tstart[t + 1])
        t++;
    return t;
}

static inline const int32_t *getme__ws_nodes(const getme_ws *ws, int t,
                                             int32_t e)
{
    return ws->conn + ws->coff[t] + (int64_t)(e - ws->tstart[t]) * getme__nv[t];
}

/* The type of all of ws's elements, or -1 if it has several: walks over
   the stars hoist it out of their loops (a constant in each copy). */
static inline int getme__ws_single_type(const getme_ws *ws)
{
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        if (ws->tstart[t + 1] - ws->tstart[t] == ws->ne)
            return t;
    return -1;
}

/* Position of node u among the nv nodes c of an element, or -1. */
static inline int getme__local_index(const int32_t *c, int nv, int32_t u)
{
    for (int i = 0; i < nv; i++)
        if (c[i] == u)
            return i;
    return -1;
}

/* Gather element e (type t) coordinates from coords into x. */
static inline void getme__ws_gather(const getme_ws *ws, const double *coords,
                                    int t, int32_t e, double *x)
{
    const int32_t *c = getme__ws_nodes(ws, t, e);
    int nv = getme__nv[t];
    for (int i = 0; i < nv; i++) {
        const double *p = coords + 3 * (int64_t)c[i];
        x[3 * i] = p[0];
        x[3 * i + 1] = p[1];
        x[3 * i + 2] = p[2];
    }
}

/* Quality of element e at coordinates coords. */
static inline double getme__ws_quality(const getme_ws *ws,
                                       const double *coords, int32_t e)
{
    double x[3 * GETME_MAX_NV];
    int t = getme__ws_type(ws, e);
    getme__ws_gather(ws, coords, t, e, x);
    double q = getme__quality(t, x);
    return q > 0.0 && ws->ho && !getme__ho_valid(ws, coords, e) ? 0.0 : q;
}

/* ---- faces (faces.c) ---------------------------------------------------- */

/* An out entry of getme__ws_faces for a face of three or more elements, or
   of two identical simplices. */
#define GETME_FACE_IRREGULAR (-2)

/* Offsets of each type's first element in a per-face array (face f of
   element e of type t at foff[t] + (e - tstart[t]) * num_faces + f);
   returns the array's length. */
int64_t getme__ws_face_offsets(const getme_ws *ws,
                               int64_t foff[GETME_NUM_TYPES]);

/* For every element face (2-D: edge): the element on its other side, -1
   on the skin, or GETME_FACE_IRREGULAR.  Parallel and deterministic.
   GETME_OK or GETME_ERR_NOMEM. */
getme_status getme__ws_faces(const getme_ws *ws, const int64_t *foff,
                             int32_t *out);

/* Qualities of all elements at ws->x into q (parallel). */
void getme__ws_qualities(const getme_ws *ws, double *q);

/* Sum of v over [0, n), exact in fixed point (exact.h) before its one
   rounding: the same bits for any thread count and any order. */
double getme__det_sum(const double *v, int32_t n, int nt);

/* Count, q_mean and q*_min (over free elements) of q. */
void getme__ws_summary(const getme_ws *ws, const double *q, double *q_mean,
                       double *q_min_star, double *q_min);

#endif /* GETME_WORKSPACE_H */
