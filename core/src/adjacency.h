/*
 * adjacency.h -- what the Eq. 9 weights need to be computed from a handful
 * of sums instead of a walk over the whole neighbourhood.
 *
 * Eq. 9 needs, for every element E, the sum and the number of the
 * qualities of N(E) = the elements sharing at least one node with E (E
 * included).  Walking the union of E's node stars costs ~96 star entries
 * per tet every iteration.  Inclusion-exclusion over E's own sub-faces gives
 * the same sum from per-node sums S_v, per-edge sums S_e and per-face sums
 * S_f (each over the elements that have that node, edge or face):
 *
 *     3-D:  sum = sum_v S_v - sum_e S_e + sum_f S_f - q_E
 *     2-D:  sum = sum_v S_v - sum_e S_e + q_E
 *
 * An element n that meets E in a common vertex, edge or face F is counted
 * chi(F) = 1 times (1, 2 - 1, 3 - 3 + 1, 4 - 4 + 1), and E itself
 * V - E + F - 1 = 1 times (Euler: V - E + F = 2 for every polyhedron).  So
 * the formula is exact on conforming meshes.  S_f is q_E plus the quality
 * of the neighbour across f, so faces need no sums of their own; 2-D edges
 * are the "faces" of planar elements the same way.
 *
 * Where the mesh is not conforming around E (a tet edge on a hex face
 * diagonal, duplicate elements, three elements on one face), the formula
 * would miscount.  getme__adj_build proves it for every element once: it
 * evaluates both the formula and the true union with a pseudo-random 64-bit
 * integer per element in place of q (exact integer arithmetic), and marks
 * the elements where they differ "irregular"; those keep the exact union
 * walk (weights.c).  The element counts |N(E)| come from that walk too, so
 * they are exact everywhere.
 */
#ifndef GETME_ADJACENCY_H
#define GETME_ADJACENCY_H

#include "block_local.h"
#include "exact.h"
#include "facenb.h"
#include "offsets.h"
#include "workspace.h"

/* An element edge's slot that does not fit in a byte (a node with more
   than 254 edges): its elements are irregular. */
#define GETME_NO_SLOT 255

typedef struct getme_adj {
    int64_t eoff[GETME_NUM_TYPES]; /* eslot index of type t's 1st element */
    int64_t foff[GETME_NUM_TYPES]; /* fnb index of type t's first element  */
    /* 3-D types: edges are numbered node by node, each by its lower node:
       the id of an element edge (a, b), a < b, is eptr[a] + its slot.  A
       byte per element edge instead of a 4-byte id saves 18 B per tet. */
    getme_offsets eptr; /* nn + 1; packed once built (offsets.h)            */
    uint8_t *eslot;     /* per element edge                                */
    getme_facenb fnb;   /* the element across each face (2-D: edge), -1;
                           2 bytes per face (facenb.h)                     */
    uint16_t *count;    /* ne: |N(E)| (exact for regular elements)         */
    uint8_t *irregular; /* ne: 1 = use the union walk for this element     */
    int32_t num_irregular;
    int32_t num_edges;  /* 3-D only                                        */
    /* Exact fixed-point sums (exact.h): the same bits whatever order the
       elements are added in.  A quality q (|q| < 2) is the integer
       trunc(q * qscale), qscale = 2^(61 - b) with 2^b > the largest star,
       so a term is below 2^(62 - b) and a node's or an edge's sum (at most
       2^b - 1 terms) below 2^62: int64 holds it.  The inclusion-exclusion
       of up to 8 node and 12 edge sums wraps in uint64 (its result fits,
       getme__adj_nsum).  A term's
       truncation is below 2^(b - 61) (docs/distributed.md compares it
       with the double sums this replaced). */
    int64_t *nsum;      /* nn: S_v at the current qualities                */
    int64_t *esum;      /* num_edges: S_e at the current qualities         */
    double qscale, qinv; /* 2^(61 - b) and its inverse                    */
    getme_blocks blk;   /* the blocks' own node lists (block_local.h)      */
} getme_adj;

/* Build everything above for ws (parallel, deterministic); takes over
   ws->faces when the boundary search left it.  GETME_OK or
   GETME_ERR_NOMEM. */
getme_status getme__adj_build(getme_adj *adj, getme_ws *ws);
void getme__adj_free(getme_adj *adj);

/* S_v and S_e of every node and edge from q, in the blocks' race-free
   order (block_local.h); integer sums, so the order does not matter.
   GETMe adaptive calls it once per run (and at a q*_min cycle's start):
   from then on every change of a quality moves the sums by its exact
   difference (getme__adj_add; relax.c, update_after). */
void getme__adj_sums_all(getme_adj *adj, const getme_ws *ws, const double *q);

/* The edge slots of element e (type t): getme__edges[t].num_edges. */
static inline uint8_t *getme__adj_slots(const getme_adj *adj,
                                        const getme_ws *ws, int t, int32_t e)
{
    return adj->eslot + adj->eoff[t] +
           (int64_t)(e - ws->tstart[t]) * getme__edges[t].num_edges;
}

/* The face neighbours of element e (type t) into f[]:
   getme__faces[t].num_faces of them, at most 6. */
static inline void getme__adj_faces(const getme_adj *adj, const getme_ws *ws,
                                    int t, int32_t e, int32_t *f)
{
    getme__facenb_elem(&adj->fnb, ws, adj->foff, t, e, f);
}

/* Id of local edge j of element e (nodes c, type t), given its slot. */
static inline int32_t getme__adj_edge(const getme_adj *adj, const int32_t *c,
                                      int t, int j, uint8_t slot)
{
    int32_t a = c[getme__edges[t].node[j][0]], b = c[getme__edges[t].node[j][1]];
    return getme__offs_at(&adj->eptr, a < b ? a : b) + slot;
}

/* Edge ids of element e (type t; nodes c, slots slot) into id[]: the
   eptr of every node loaded first, side by side, then each edge takes
   its lower node's (getme__adj_edge, which loads eptr after the
   comparison, once per edge: a chain of two dependent loads per edge
   that perf showed stalling the scatter's weights and the trial pass).
   A missing slot (GETME_NO_SLOT) gives -1. */
__attribute__((always_inline)) static inline void
getme__adj_edge_ids(const getme_adj *adj, const int32_t *c, int t,
                    const uint8_t *slot, int32_t *id)
{
    int32_t ep[GETME_MAX_NV];
    for (int i = 0; i < getme__nv[t]; i++)
        ep[i] = getme__offs_at(&adj->eptr, c[i]);
    for (int j = 0; j < getme__edges[t].num_edges; j++) {
        int a = getme__edges[t].node[j][0], b = getme__edges[t].node[j][1];
        id[j] = slot[j] == GETME_NO_SLOT ? -1
              : (c[a] < c[b] ? ep[a] : ep[b]) + slot[j];
    }
}

/* getme__adj_add with the element's edge ids already worked out (id,
   -1 for a missing slot; read only in 3-D): the sweeps that compute them
   ahead to prefetch the sums (update_block, relax.c's step_chunk). */
__attribute__((always_inline)) static inline void
getme__adj_add_ids(getme_adj *adj, const getme_ws *ws, int t,
                   const int32_t *c, const int32_t *id, uint64_t d)
{
    for (int i = 0; i < getme__nv[t]; i++)
        adj->nsum[c[i]] = (int64_t)((uint64_t)adj->nsum[c[i]] + d);
    if (ws->dim != 3)
        return;
    for (int j = 0; j < getme__edges[t].num_edges; j++)
        if (id[j] >= 0) {
            int64_t *s = &adj->esum[id[j]];
            *s = (int64_t)((uint64_t)*s + d);
        }
}

/* Add d to the S_v of element e's nodes and the S_e of its edges (type
   t; nodes c), in wrapping uint64 arithmetic: d is an element's
   fixed-point quality, or the difference of its new and old ones, which
   gives the same bits as a recomputation (the sums are exact).
   Not written as getme__adj_edge_ids + getme__adj_add_ids: the S_v
   additions first let the edge ids' loads overlap them, and the hexes'
   trial pass (this function's hot caller) took 1.77-1.96 s against
   1.61-1.76 s over 10 iterations the other way round (6 pairs, session
   22). */
__attribute__((always_inline)) /* out of line (LTO), the trial pass
                                  took 60 % longer */
static inline void getme__adj_add(getme_adj *adj, const getme_ws *ws, int t,
                                  int32_t e, const int32_t *c, uint64_t d)
{
    for (int i = 0; i < getme__nv[t]; i++)
        adj->nsum[c[i]] = (int64_t)((uint64_t)adj->nsum[c[i]] + d);
    if (ws->dim != 3)
        return; /* planar: no edge sums (and no edge arrays) */
    int32_t id[12];
    getme__adj_edge_ids(adj, c, t, getme__adj_slots(adj, ws, t, e), id);
    for (int j = 0; j < getme__edges[t].num_edges; j++)
        if (id[j] >= 0) {
            int64_t *s = &adj->esum[id[j]];
            *s = (int64_t)((uint64_t)*s + d);
        }
}

/* The fixed-point qualities of the nf face neighbours f (-1: none) of an
   element, summed in wrapping uint64 arithmetic (getme__adj_nsum_sv). */
static inline uint64_t getme__adj_face_q(const getme_adj *adj,
                                         const double *q, const int32_t *f,
                                         int nf)
{
    uint64_t sf = 0;
    for (int k = 0; k < nf; k++)
        sf += f[k] >= 0 ? (uint64_t)getme__fx64(q[f[k]], adj->qscale) : 0;
    return sf;
}

/* The sum over N(e) of a regular 3-D element with nf faces from its
   pieces (getme__adj_nsum_sv): the S_v of its nodes sv, the S_e of its
   edges se, the face neighbours' qualities sf and its own qe. */
static inline double getme__adj_nsum_3d(const getme_adj *adj, uint64_t sv,
                                        uint64_t se, uint64_t sf, uint64_t qe,
                                        int nf)
{
    return (double)(sv - se + (uint64_t)(nf - 1) * qe + sf) * adj->qinv;
}

/* Sum of q over N(e) for a regular element e of type t (see above), as
   the nearest double to the exact sum of the fixed-point qualities: the
   inclusion-exclusion is exact in integers, so it equals the union walk's
   exact sum (weights.c) bit for bit.  sv: the wrapped sum of the S_v of
   e's nodes (the caller may read them from a block-local copy). */
static inline double getme__adj_nsum_sv(const getme_adj *adj,
                                        const getme_ws *ws, const double *q,
                                        int t, int32_t e, uint64_t sv)
{
    const int32_t *c = getme__ws_nodes(ws, t, e);
    const getme_face_table *ft = &getme__faces[t];
    int32_t f[6];
    getme__adj_faces(adj, ws, t, e, f);
    int nv = getme__nv[t];
    /* In wrapping uint64 arithmetic: the sum over N(e) is a sum of
       non-negative terms (valid qualities, q <= 1 up to rounding), each
       below 2^(61 - b), over fewer than nv 2^b elements (N(e) is inside
       the union of nv stars), so below nv 2^61 <= 2^64: the true value is
       what the wrapped uint64 holds, whatever the partial sums did. */
    uint64_t se = 0, sf = getme__adj_face_q(adj, q, f, ft->num_faces);
    uint64_t qe = (uint64_t)getme__fx64(q[e], adj->qscale);
    if (ws->dim == 2) /* sum_e S_e = nv q_E + sf, plus q_E once */
        return (double)(sv - (uint64_t)(nv - 1) * qe - sf) * adj->qinv;
    const uint8_t *slot = getme__adj_slots(adj, ws, t, e);
    for (int k = 0; k < getme__edges[t].num_edges; k++)
        se += (uint64_t)adj->esum[getme__adj_edge(adj, c, t, k, slot[k])];
    return getme__adj_nsum_3d(adj, sv, se, sf, qe, ft->num_faces);
}

/* The same, with S_v read from the global sums. */
static inline double getme__adj_nsum(const getme_adj *adj,
                                     const getme_ws *ws, const double *q,
                                     int t, int32_t e)
{
    const int32_t *c = getme__ws_nodes(ws, t, e);
    uint64_t sv = 0;
    for (int i = 0; i < getme__nv[t]; i++)
        sv += (uint64_t)adj->nsum[c[i]];
    return getme__adj_nsum_sv(adj, ws, q, t, e, sv);
}

#endif /* GETME_ADJACENCY_H */
