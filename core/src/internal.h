/*
 * internal.h -- libgetme's private declarations: the mesh handle layout and
 * the element kernels shared by the core's files.  Not installed.
 *
 * Kernel conventions (quality.c, transform_*.c):
 *  - an element's nodes are passed as nv consecutive xyz triples
 *    (x[3*i+0..2]), in the public node order of getme.h;
 *  - planar types (tri, quad) read and write x, y only and copy z;
 *  - the kernels are pure functions: no allocation, no state, no I/O, so the
 *    smoother can call them from any OpenMP thread.
 */
#ifndef GETME_INTERNAL_H
#define GETME_INTERNAL_H

#include "getme.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "getme_alloc.h"

#define GETME_MAX_NV 8 /* nodes of the largest element type (hex) */

/* ---- element tables (quality.c) ---------------------------------------- */

/* Nodes per type, indexed by getme_elem_type. */
extern const int getme__nv[GETME_NUM_TYPES];

/*
 * Call f(t, args...) with t as a compile-time constant for each element
 * type, so that the hot per-block loops get a specialised copy per type
 * (node, edge and face counts known: loops unrolled, no table lookups).
 */
#define GETME_FOR_TYPE(t, f, ...)                                           \
    do {                                                                    \
        switch (t) {                                                        \
        case GETME_TET: f(GETME_TET, __VA_ARGS__); break;                   \
        case GETME_HEX: f(GETME_HEX, __VA_ARGS__); break;                   \
        case GETME_PRISM: f(GETME_PRISM, __VA_ARGS__); break;               \
        case GETME_PYRAMID: f(GETME_PYRAMID, __VA_ARGS__); break;           \
        case GETME_TRI: f(GETME_TRI, __VA_ARGS__); break;                   \
        default: f(GETME_QUAD, __VA_ARGS__); break;                         \
        }                                                                   \
    } while (0)

/* Faces of volume types and edges of planar types (the (d-1)-dimensional
   sides of an element), as local node lists; and the edges of every type
   (tables.c). */
typedef struct getme_face_table {
    int num_faces;
    int size[6];
    int8_t node[6][4];
} getme_face_table;

typedef struct getme_edge_table {
    int num_edges;
    int8_t node[12][2];
} getme_edge_table;

extern const getme_face_table getme__faces[GETME_NUM_TYPES];
extern const getme_edge_table getme__edges[GETME_NUM_TYPES];

/* ---- kernels (quality.c) ------------------------------------------------ */

/* Mean ratio of one element, 0 when invalid; see getme_element_quality(). */
double getme__quality(int type, const double *x);

/* The element's worst corner: the minimum over its node simplices of
   det(e1, e2, e3) / (|e1| |e2| |e3|), scaled so that the regular element's
   corners give 1 (the corner scaled Jacobian of Verdict/CUBIT for hex,
   prism and pyramid base corners; quad: the 2-D analogue).  Negative for an
   inverted corner, -1 for a collapsed edge.  Simplices return 1: their mean
   ratio already measures their only corner. */
double getme__corner_sj(int type, const double *x);

/* getme__corner_sj of GETME_CORNER_LANES hexes, to the bit: coordinates
   x[(3 i + d) * GETME_CORNER_LANES + l] (node i, coordinate d, hex l),
   results m[l]. */
#define GETME_CORNER_LANES 4
void getme__corner_sj_hex_lanes(const double *x, double *m);

/* A value and the element (or block) it belongs to.  getme__cmp_ranked
   sorts by value, ties by index: a total order, so qsort gives the same
   list whatever it does with equal keys (values are finite: qualities,
   coordinates). */
typedef struct getme_ranked {
    double q;
    int32_t e;
} getme_ranked;

static inline int getme__cmp_ranked(const void *a, const void *b)
{
    const getme_ranked *x = a, *y = b;
    if (x->q != y->q)
        return x->q < y->q ? -1 : 1;
    return (x->e > y->e) - (x->e < y->e);
}

/* buf with room for need >= 1 entries of size bytes (room *cap, at least
   doubled when it grows, so no allocation per entry), or NULL without
   memory (buf and *cap stay valid). */
static inline void *getme__room(void *buf, int64_t *cap, int64_t need,
                                size_t size)
{
    if (need <= *cap)
        return buf;
    int64_t c = *cap ? 2 * *cap : 256;
    c = c < need ? need : c;
    void *b = realloc(buf, (size_t)c * size);
    if (b)
        *cap = c;
    return b;
}

/* Append x to the growing index list *list (*n entries, room *cap).  0,
   or -1 if out of memory (the list as it was). */
static inline int getme__push_i32(int32_t **list, int32_t *n, int64_t *cap,
                                  int32_t x)
{
    int32_t *p = getme__room(*list, cap, (int64_t)*n + 1, sizeof *p);
    if (!p)
        return -1;
    *list = p;
    p[(*n)++] = x;
    return 0;
}

/* memcpy(dst, src, n) on up to nt threads, in pieces of 1 MiB: a copy
   into a freshly grown array faults that array's pages in (~3 ms per MiB
   on the VMs measured), and on one thread it kept the others waiting
   (build_edges: 0.11 s of the full hexes' two-thread set-up). */
static inline void getme__copy(void *dst, const void *src, size_t n, int nt)
{
    (void)nt; /* without OpenMP */
    const size_t piece = (size_t)1 << 20;
    int64_t np = (int64_t)((n + piece - 1) / piece);
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1 && np > 1)
    for (int64_t k = 0; k < np; k++) {
        size_t a = (size_t)k * piece, m = n - a < piece ? n - a : piece;
        memcpy((char *)dst + a, (const char *)src + a, m);
    }
}

/* Types whose mean ratio averages several corners, so that one corner can
   collapse while q stays fair: the corner guard applies to them. */
static inline int getme__has_corners(int type)
{
    return type == GETME_HEX || type == GETME_PRISM ||
           type == GETME_PYRAMID || type == GETME_QUAD;
}

/* quality.c's cube root of one value (the one-element kernels'), for the
   tests that check the batched kernels against it */
double getme__cube_root(double x);
double getme__quality_tet(const double *x);
double getme__quality_hex(const double *x);
double getme__quality_prism(const double *x);
double getme__quality_pyramid(const double *x);
double getme__quality_tri(const double *x);
double getme__quality_quad(const double *x);

/* ---- kernels (transform_tet.c, transform_dual.c, transform_polygon.c) --- */

/* Transform + scale about the centroid to keep the sum of edge lengths. */
void getme__transform(int type, const double *x, double sigma, double *out);

void getme__transform_tet(const double *x, double sigma, double *out);
/* Elements per batch of the lane kernels (*_lanes): 8 doubles, one
   AVX-512 register or two AVX2 ones. */
#define GETME_LANES 8
/* A build for any x86-64 CPU (GETME_NATIVE=OFF defines GETME_DISPATCH)
   would run the lane kernels on SSE2, 2 doubles per instruction: they get
   AVX2 and AVX-512 copies, chosen once at load time (ifunc).  Every copy
   does the same IEEE operations (no fused multiply-add: -std=c11 means
   -ffp-contract=off; vector square roots and divisions are correctly
   rounded), so the bits do not depend on the copy (core_lanes runs the
   machine's one against the one-element kernels).  Not in the native
   build: there the kernels are inlined into their callers. */
#if defined(GETME_DISPATCH) && defined(__x86_64__) && defined(__GNUC__) && \
    !defined(__clang__)
#define GETME_LANES_TARGETS __attribute__((target_clones("default", "avx2", "avx512f")))
#else
#define GETME_LANES_TARGETS
#endif
/* getme__transform_tet of GETME_LANES tets at once: x[3 i + d][l] is
   coordinate d of node i of tet l; out likewise.  Bit-identical per lane. */
void getme__transform_tet_lanes(const double (*x)[GETME_LANES], double sigma,
                                double (*out)[GETME_LANES]);
/* The same for hexahedra (transform_dual.c). */
void getme__transform_hex_lanes(const double (*x)[GETME_LANES], double sigma,
                                double (*out)[GETME_LANES]);
/* its two forms (transform_dual.c: node by node for AVX-512, in phases
   for AVX2), both in every build so that core_lanes checks both */
void getme__transform_hex_lanes_nodes(const double (*x)[GETME_LANES], double sigma,
                                      double (*out)[GETME_LANES]);
void getme__transform_hex_lanes_phases(const double (*x)[GETME_LANES], double sigma,
                                       double (*out)[GETME_LANES]);
/* getme__quality of GETME_LANES elements of type type at once (x in
   lanes as above) into q; bit-identical per lane.  Returns 0 (nothing
   done) for a type without a lane kernel (only tets and hexes have one). */
int getme__quality_lanes(int type, const double (*x)[GETME_LANES], double *q);
/* getme__quality of n elements of type type stored one after the other
   (x[3 nv e + 3 i + d]) into q[0..n): the lane kernels for full groups of
   GETME_LANES tets or hexes (about 4x faster than one at a time,
   bench/kernels.c), bit-identical to n calls of getme__quality. */
void getme__qualities(int type, int32_t n, const double *x, double *q);
void getme__transform_hex(const double *x, double sigma, double *out);
void getme__transform_prism(const double *x, double sigma, double *out);
void getme__transform_pyramid(const double *x, double sigma, double *out);
void getme__transform_tri(const double *x, double sigma, double *out);
void getme__transform_quad(const double *x, double sigma, double *out);

/* ---- the mesh handle (mesh.c) ------------------------------------------- */

/* One getme_mesh_add_elements() call: a homogeneous block of elements. */
typedef struct getme_block {
    int type;
    int32_t first;   /* global index of its first element */
    int32_t count;
    int32_t *conn;   /* count * nv node indices */
    int32_t *region; /* count region ids, or NULL: all are region_all */
    int32_t region_all; /* the one region id when region is NULL (0 if the
                           caller gave none); a block read from one volume
                           then costs no 4 bytes per element            */
} getme_block;

struct getme_mesh {
    int dim;
    int32_t num_nodes;
    int32_t num_elements;
    double *coords;   /* 3 * num_nodes, caller's node order */
    uint8_t *fixed;   /* num_nodes, 0 = free, else why it is fixed (a bit
                         set of GETME__FIXED_*); the public mask is 0/1  */
    getme_block *blocks;
    int num_blocks, cap_blocks;
    int mirror;       /* planar meshes: 1 if all elements are clockwise */
    struct getme_ho_mesh *ho; /* second-order elements (highorder.h), or NULL */
    /* The workspace (and face table) the boundary search built, kept for
       the smoother so that it is built once (workspace.c); dropped when
       coordinates or elements change, as its order depends on both. */
    struct getme_ws *ws_cache;
    int lend_coords;  /* getme_mesh_lend_coords(): getme_smooth() may use
                         coords as its working copy                      */
    char error[512];  /* message of the last failure */
};

/* Free mesh->ws_cache, if any (workspace.c). */
void getme__mesh_drop_ws(getme_mesh *mesh);

/* Why a node is fixed: bits of getme_mesh.fixed.  Only the worst-element
   report (worst.c) asks; everything else tests fixed != 0. */
enum {
    GETME__FIXED_USER = 1,      /* getme_mesh_set_fixed_mask / fix_nodes   */
    GETME__FIXED_SKIN = 2,      /* on the skin (or a non-manifold face)    */
    GETME__FIXED_INTERFACE = 4, /* on a face between two regions           */
    GETME__FIXED_UNUSED = 8     /* used by no element                      */
};

/* Gather element e of block bl (local index) into x (nv triples) with y
   times ysign: -1 for a mirrored planar mesh (mesh->mirror == 1), else 1. */
static inline void getme__gather_local(const getme_mesh *mesh,
                                       const getme_block *bl, int32_t e,
                                       double ysign, double *x)
{
    int nv = getme__nv[bl->type];
    const int32_t *c = bl->conn + (int64_t)e * nv;
    for (int i = 0; i < nv; i++) {
        const double *p = mesh->coords + 3 * (int64_t)c[i];
        x[3 * i] = p[0];
        x[3 * i + 1] = ysign * p[1];
        x[3 * i + 2] = p[2];
    }
}

/* 1 if element e of block bl has a node that is not fixed. */
static inline int getme__local_has_free(const getme_mesh *mesh,
                                        const getme_block *bl, int32_t e)
{
    int nv = getme__nv[bl->type];
    const int32_t *c = bl->conn + (int64_t)e * nv;
    int f = 0;
    for (int i = 0; i < nv; i++)
        f |= !mesh->fixed[c[i]];
    return f;
}

/* How many elements ahead the caller-order sweeps (statistics, measures)
   prefetch the nodes: the caller's element order can be unrelated to its
   node order, so each gather is a handful of independent cache misses,
   and overlapping them is most of what such a sweep can gain. */
#define GETME_PREFETCH_AHEAD 16

/* Prefetch the coordinates of the nodes of elements e .. e + n - 1 of
   block bl (those past its end are skipped).  The empty asm keeps the
   compiler from vectorising the loop: gcc 12 vectorised it and dropped
   the prefetches, so the sweeps loaded their nodes on demand. */
static inline void getme__prefetch_local(const getme_mesh *mesh,
                                         const getme_block *bl, int32_t e,
                                         int32_t n)
{
#if defined(__GNUC__)
    if (e >= bl->count)
        return;
    int nv = getme__nv[bl->type];
    if (n > bl->count - e)
        n = bl->count - e;
    const int32_t *c = bl->conn + (int64_t)e * nv;
    for (int32_t k = 0; k < n * nv; k++) {
        __builtin_prefetch(mesh->coords + 3 * (int64_t)c[k]);
        __asm__ volatile("" ::: "memory");
    }
#else
    (void)mesh, (void)bl, (void)e, (void)n;
#endif
}

/* 1 if one element's nv node indices are in range and pairwise distinct
   (mesh.c; first- and second-order elements are checked alike). */
int getme__element_nodes_ok(const int32_t *c, int nv, int32_t num_nodes);

/* Record a printf-style message on the mesh and return status. */
getme_status getme__fail(getme_mesh *mesh, getme_status status,
                         const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Block holding global element e, and e's offset inside it. */
const getme_block *getme__find_block(const getme_mesh *mesh, int32_t e,
                                     int32_t *local);

/* Gather element e's node coordinates into x (nv triples); planar meshes
   that are mirrored get y negated.  Returns the element type. */
int getme__gather(const getme_mesh *mesh, int32_t e, double *x);

/* 0 if params are usable, else -1 with a description in buf. */
int getme__params_problem(const getme_params *params, char *buf, size_t size);

/* Decide mesh->mirror for planar meshes (majority orientation). */
void getme__detect_orientation(getme_mesh *mesh);

#endif /* GETME_INTERNAL_H */
