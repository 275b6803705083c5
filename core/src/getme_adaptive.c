/*
 * getme_adaptive.c -- GETMe adaptive smoothing, paper Fig. 3 / Sec. 2.2-2.3.
 *
 * One loop, two stages:
 *  - q_mean stage: every element is transformed (q_t = 1), relaxation table
 *    R_mean, until an iteration gains less than tol in q_mean;
 *  - q*_min stage, in cycles: each cycle sets q_t to the quality found at
 *    position threshold_fraction of the sorted qualities of free elements
 *    and transforms only elements with q <= q_t (table R_min); a cycle ends
 *    after max_no_min_improve iterations without q*_min gain; smoothing ends
 *    after a cycle that did not raise q*_min.  A "gain" must exceed min_tol:
 *    the paper compares exactly, which in floating point lets a nearly
 *    regular mesh creep on by 1e-9 per iteration up to max_iter.
 * New node positions are Eq. 9-weighted means of the transformed nodes of
 * the transformed elements and the untransformed nodes of the other
 * elements around I_T; Eq. 10 relaxation keeps every element valid.
 *
 * Our choices where the paper is silent (docs/design.md §3):
 *  - N(j) in Eq. 9 contains E_j itself;
 *  - elements without a free node are never transformed (they could not
 *    move anything);
 *  - keep_best: the mesh returned is the one with the best q*_min seen from
 *    the end of the q_mean stage on (the q*_min stage may lose a little
 *    q*_min in its last, unsuccessful cycle).
 */
#include "adjacency.h"
#include "block_edges.h"
#include "best.h"
#include "gather_lanes.h"
#include "revert.h"
#include "smooth_internal.h"
#include "tally.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

enum { MEAN_RUNNING, MIN_START, MIN_RUNNING };

/* How many elements ahead transform_block prefetches (see there). */
#define PREFETCH_AHEAD 8

/* Eq. 9 weight of element e (type t) at the qualities run->q: from the
   inclusion-exclusion sums (adjacency.h), inlined here because it runs
   once per element and iteration, or by the union walk for the few
   elements where that formula is not exact (weights.c). */
static inline double weight(const getme_run *run, int t, int32_t e)
{
    const getme_adj *adj = run->adj;
    if (adj->irregular[e])
        return getme__weight_union(run, t, e);
    const double *q = run->q;
    return sqrt(getme__adj_nsum(adj, run->ws, q, t, e) /
                ((double)adj->count[e] * q[e]));
}

/* A node's contribution w x (3 coordinates) and w, added to its exact
   fixed-point sums a (set_scales): wf = trunc(w wscale) is the element's
   weight as an integer, each coordinate becomes trunc(x pscale), and their
   product is exact in 128 bits, so sum w x and sum w are exact sums of the
   same integer weights.  Returns 1 if a coordinate is beyond run->xbound,
   where the bound would not hold (nothing is added; the caller redoes the
   scatter with a larger bound). */
static inline void add_fixed(getme_fx *a, int64_t wf, int64_t x0,
                             int64_t x1, int64_t x2)
{
    /* In wrapping unsigned arithmetic: the lanes' loop (transform_block)
       adds every fixed node's terms into one spare slot whose sum no
       bound covers; a real node's sums are the bits of the signed sums
       (representable by the bounds), so every caller gets the same. */
    getme_ufx *u = (getme_ufx *)a;
    u[0] += (getme_ufx)((getme_fx)wf * x0);
    u[1] += (getme_ufx)((getme_fx)wf * x1);
    u[2] += (getme_ufx)((getme_fx)wf * x2);
    u[3] += (getme_ufx)(getme_fx)wf;
}

static inline int add_sum(const getme_run *run, getme_fx *a, int64_t wf,
                          const double *x)
{
    double b = run->xbound;
    if (!(fabs(x[0]) < b && fabs(x[1]) < b && fabs(x[2]) < b))
        return 1;
    double ps = run->pscale;
    add_fixed(a, wf, getme__fx64(x[0], ps), getme__fx64(x[1], ps),
              getme__fx64(x[2], ps));
    return 0;
}

/* add_sum's bound test and scaling for the nv nodes of a batch of
   GETME_LANES transformed elements (y as the lane kernels write it), in
   vector instructions: yd = y pscale, and out = 1 where a coordinate is
   out of bounds (add_sum would add nothing there).  The caller converts
   yd to the integers add_sum adds, trunc(y pscale), only for the nodes it
   adds (never where out is set): AVX2 has no vector double -> int64
   conversion, and with the conversion in this loop gcc 12 left the whole
   loop scalar there (round 10: bound tests as compare-and-branch). */
__attribute__((always_inline)) static inline int
fixed_lanes(const getme_run *run, int nv, const double (*y)[GETME_LANES],
            double (*yd)[GETME_LANES], int64_t (*out)[GETME_LANES])
{
    double b = run->xbound, ps = run->pscale;
    for (int i = 0; i < nv; i++) {
#pragma omp simd
        for (int l = 0; l < GETME_LANES; l++) {
            double y0 = y[3 * i][l], y1 = y[3 * i + 1][l], y2 = y[3 * i + 2][l];
            /* int64_t like the doubles: with 8-bit flags gcc found no
               vector type for the loop */
            int64_t in = (fabs(y0) < b) & (fabs(y1) < b) & (fabs(y2) < b);
            out[i][l] = !in;
            yd[3 * i][l] = y0 * ps;
            yd[3 * i + 1][l] = y1 * ps;
            yd[3 * i + 2][l] = y2 * ps;
        }
    }
    /* a separate loop: as a reduction in the one above (or with yd
       selected by the test), gcc 12 left the bound tests scalar
       compare-and-branch */
    int64_t any = 0;
    for (int i = 0; i < nv; i++)
        for (int l = 0; l < GETME_LANES; l++)
            any |= out[i][l];
    return any != 0;
}

/* add_sum into node n's global sums. */
static inline int add_node(const getme_run *run, int32_t n, int64_t wf,
                           const double *x)
{
    return add_sum(run, run->facc + 4 * getme__slot(run, n), wf, x);
}

/* AddTransformedElementNodesAndWeights for element e (type t); returns 1
   on a bound overflow (add_node). */
static inline int add_transformed(getme_run *run, int t, int32_t e,
                                  double sigma)
{
    const getme_ws *ws = run->ws;
    double x[3 * GETME_MAX_NV], y[3 * GETME_MAX_NV];
    int64_t w = getme__fx64(weight(run, t, e), run->wscale);
    getme__ws_gather(ws, ws->x, t, e, x);
    getme__transform(t, x, sigma, y);
    const int32_t *c = getme__ws_nodes(ws, t, e);
    int ovf = 0;
    for (int i = 0; i < getme__nv[t]; i++) {
        int32_t n = c[i];
        if (ws->fixed[n])
            continue;
        ovf |= add_node(run, n, w, y + 3 * i); /* n is in I_T already */
    }
    return ovf;
}

/* AddUntransformedElementNodesAndWeights for element e (type t). */
static inline int add_untransformed(getme_run *run, int t, int32_t e)
{
    const getme_ws *ws = run->ws;
    int64_t w = getme__fx64(weight(run, t, e), run->wscale);
    const int32_t *c = getme__ws_nodes(ws, t, e);
    int ovf = 0;
    for (int i = 0; i < getme__nv[t]; i++) {
        int32_t n = c[i];
        if (run->in_t[n])
            ovf |= add_node(run, n, w, ws->x + 3 * (int64_t)n);
    }
    return ovf;
}

/* Elements per chunk of weights_3d. */
#define WEIGHT_CHUNK 32

/* The integer Eq. 9 weights wfs[e - e0] of the elements [e0, e1) of a
   block of 3-D elements of type t (-1: not transformed), ls the S_v of
   the block's nodes (block-local indices): the same integers as
   getme__adj_nsum_sv gives, in two passes over chunks of WEIGHT_CHUNK
   elements.  The first computes each regular element's edge ids and
   prefetches their S_e and the face neighbours' q; the second sums them.
   perf annotate: in one pass, the loads of S_e and of the face
   neighbours' q stalled the sums (most of the block's time went to them),
   and prefetching them needs the edge ids, which the first pass keeps. */
__attribute__((always_inline)) static inline void
weights_3d(int t, const getme_run *run, int32_t e0, int32_t e1,
           const struct getme_block_scratch *scr, const int64_t *ls,
           int64_t *wfs)
{
    const getme_ws *ws = run->ws;
    const getme_adj *adj = run->adj;
    const double *q = run->q;
    const int nv = getme__nv[t], ned = getme__edges[t].num_edges;
    const int nf = getme__faces[t].num_faces;
    const double qs = adj->qscale;
    /* tets: the block's S_e gathered once into the thread's local array,
       read through the tets' list indices (block_edges.h) */
    const int64_t *esl = NULL;
    if (t == GETME_TET && adj->blk.ledge) {
        const getme_blocks *blk = &adj->blk;
        int64_t *l = getme__blocks_esl(blk, omp_get_thread_num());
        int32_t b = getme__blocks_of(blk, ws, t, e0);
        const int32_t *be = blk->edges + blk->eptr[b];
        int32_t nbe = (int32_t)(blk->eptr[b + 1] - blk->eptr[b]);
        for (int32_t k = 0; k < nbe; k++) {
            if (k + PREFETCH_AHEAD < nbe && be[k + PREFETCH_AHEAD] >= 0)
                __builtin_prefetch(adj->esum + be[k + PREFETCH_AHEAD], 0, 3);
            l[k] = be[k] >= 0 ? adj->esum[be[k]] : 0;
        }
        esl = l;
    }
    for (int32_t c0 = e0; c0 < e1; c0 += WEIGHT_CHUNK) {
        int32_t c1 = c0 + WEIGHT_CHUNK < e1 ? c0 + WEIGHT_CHUNK : e1;
        int32_t eid[WEIGHT_CHUNK][12], fnb[WEIGHT_CHUNK][6];
        uint8_t kind[WEIGHT_CHUNK]; /* 0 none, 1 regular, 2 irregular */
        for (int32_t e = c0; e < c1; e++) {
            int k = !(ws->free_elem[e] && getme__owned(run, e)) ? 0
                  : adj->irregular[e]                            ? 2
                                                                 : 1;
            kind[e - c0] = (uint8_t)k;
            if (k != 1)
                continue;
            if (!esl) {
                getme__adj_edge_ids(adj, getme__ws_nodes(ws, t, e), t,
                                    getme__adj_slots(adj, ws, t, e),
                                    eid[e - c0]);
                for (int j = 0; j < ned; j++)
                    __builtin_prefetch(adj->esum + eid[e - c0][j], 0, 3);
            }
            int32_t *f = fnb[e - c0];
            getme__adj_faces(adj, ws, t, e, f);
            for (int j = 0; j < nf; j++) /* no neighbour (-1): e itself */
                __builtin_prefetch(q + (f[j] >= 0 ? f[j] : e), 0, 3);
        }
        /* the sums (loads now mostly cached), then the divisions and
           square roots of the chunk in vector instructions (the same
           correctly rounded operations as one at a time) */
        double num[WEIGHT_CHUNK], den[WEIGHT_CHUNK];
        for (int i = 0; i < WEIGHT_CHUNK; i++)
            num[i] = 0.0, den[i] = 1.0;
        for (int32_t e = c0; e < c1; e++) {
            if (kind[e - c0] != 1)
                continue;
            const uint16_t *lc = getme__blocks_lnodes(scr, nv, e - e0);
            const int32_t *f = fnb[e - c0];
            uint64_t sv = 0, se = 0;
            for (int i = 0; i < nv; i++)
                sv += (uint64_t)ls[lc[i]];
            if (esl) {
                const uint16_t *le = getme__blocks_ledge(&adj->blk, e);
                for (int j = 0; j < ned; j++)
                    se += (uint64_t)esl[le[j]];
            } else {
                for (int j = 0; j < ned; j++)
                    se += (uint64_t)adj->esum[eid[e - c0][j]];
            }
            /* getme__adj_nsum_sv's wrapping sum, from the same pieces */
            num[e - c0] = getme__adj_nsum_3d(
                adj, sv, se, getme__adj_face_q(adj, q, f, nf),
                (uint64_t)getme__fx64(q[e], qs), nf);
            den[e - c0] = (double)adj->count[e] * q[e];
        }
        /* getme__fx64(w, wscale) in two steps: AVX2 has no vector
           double -> int64 conversion, and with it in the loop gcc left the
           divisions and square roots scalar too (as in fixed_lanes) */
        double wv[WEIGHT_CHUNK];
        const double wscale = run->wscale;
#pragma omp simd
        for (int i = 0; i < WEIGHT_CHUNK; i++)
            wv[i] = sqrt(num[i] / den[i]) * wscale;
        for (int32_t e = c0; e < c1; e++) {
            int k = kind[e - c0];
            wfs[e - e0] = k == 1 ? (int64_t)wv[e - c0]
                        : k == 2 ? getme__fx64(getme__weight_union(run, t, e),
                                               run->wscale)
                                 : -1;
        }
    }
}

/* ComputeNewNodes' p-hat of a node from its complete exact sums f: the
   quotient of the two integers' doubles scaled back by back = 1 / pscale,
   a power of two, so the only roundings are the two conversions and the
   division; the same operations wherever it runs (compute_new_nodes,
   transform_block), so the same bits. */
static inline void node_phat(const getme_fx *f, double back, double a[3])
{
    double inv = 1.0 / getme__fx_to_double(f[3]);
    a[0] = getme__fx_to_double(f[0]) * inv * back;
    a[1] = getme__fx_to_double(f[1]) * inv * back;
    a[2] = getme__fx_to_double(f[2]) * inv * back;
}

/* The free elements of block b (all of type t, a constant in each copy,
   GETME_FOR_TYPE) transformed, in three steps on the block's own node
   list (block_local.h): copy its nodes' coordinates, S_v and fixed flags
   into the thread's scratch; weight, transform and sum every element's
   contributions there; add each node's block sum to its global sums once
   and mark it in I_T.  The integer sums are exact, so this gives the same
   bits as adding element by element into the global sums.  With
   run->place_early, a node whose last block this is (mark_last) is then
   complete: its p-hat is computed and the node placed here. */
__attribute__((always_inline)) /* one copy per type: t is a constant */
static inline void transform_block(int t, getme_run *run, int32_t b,
                                   double sigma, int32_t *count, int *ovf)
{
    const getme_ws *ws = run->ws;
    const getme_adj *adj = run->adj;
    const getme_blocks *blk = &adj->blk;
    struct getme_block_scratch *scr = &blk->scratch[omp_get_thread_num()];
    const int32_t *gn = blk->nodes + blk->nptr[b];
    int32_t m = (int32_t)(blk->nptr[b + 1] - blk->nptr[b]);
    double *xl = scr->x;
    getme_fx *acc = scr->acc;
    int64_t *ls = scr->nsum;
    uint8_t *flag = scr->flag;
    const int32_t *pslot = run->slot;
    getme__blocks_localise(blk, ws, b, scr);
    /* The node list is known: prefetch the scattered node data a few
       nodes ahead, here and in the final addition (perf annotate: those
       loads missed). */
    for (int32_t k = 0; k < m; k++) {
        int32_t g = gn[k] & INT32_MAX; /* the sign bit: mark_last */
        if (k + PREFETCH_AHEAD < m) {
            int64_t gp = gn[k + PREFETCH_AHEAD] & INT32_MAX;
            __builtin_prefetch(ws->x + 3 * gp, 0, 3);
            __builtin_prefetch(adj->nsum + gp, 0, 3);
        }
        const double *p = ws->x + 3 * (int64_t)g;
        xl[3 * k] = p[0], xl[3 * k + 1] = p[1], xl[3 * k + 2] = p[2];
        ls[k] = adj->nsum[g];
        flag[k] = ws->fixed[g] != 0;
        if (pslot) {
            /* The slots, kept for the final addition, which prefetches
               their entries from them (its own load of a slot missed:
               6 % of the scatter) */
            if (k + PREFETCH_AHEAD < m)
                __builtin_prefetch(pslot + (gn[k + PREFETCH_AHEAD] & INT32_MAX),
                                   0, 3);
            scr->slot[k] = pslot[g];
        }
        acc[4 * k] = acc[4 * k + 1] = acc[4 * k + 2] = acc[4 * k + 3] = 0;
    }
    /* the spare slot (lanes' loop): never fixed, its sums never read */
    flag[m] = 0;
    acc[4 * m] = acc[4 * m + 1] = acc[4 * m + 2] = acc[4 * m + 3] = 0;
    int nv = getme__nv[t];
    int32_t e0 = ws->block_start[b], e1 = ws->block_start[b + 1];
    /* The weights first, in a loop of loads with little arithmetic, so the
       out-of-order core keeps the scattered ones (face neighbours' q, S_e)
       of several elements in flight; -1 marks an element not transformed
       (a weight is >= 0).  3-D: weights_3d, which prefetches from the edge
       ids it computes anyway (a prefetch 8 elements ahead that loaded
       eptr and fnb again only for it cost 14 % of the scatter). */
    int64_t *wfs = scr->wf;
    if (ws->dim == 3)
        weights_3d(t, run, e0, e1, scr, ls, wfs);
    else
        for (int32_t e = e0; e < e1; e++) {
            int64_t wf = -1;
            if (ws->free_elem[e] && getme__owned(run, e)) {
                double w;
                if (adj->irregular[e]) {
                    w = getme__weight_union(run, t, e);
                } else {
                    const uint16_t *lc = getme__blocks_lnodes(scr, nv, e - e0);
                    uint64_t sv = 0;
                    for (int i = 0; i < nv; i++)
                        sv += (uint64_t)ls[lc[i]];
                    w = sqrt(getme__adj_nsum_sv(adj, ws, run->q, t, e, sv) /
                             ((double)adj->count[e] * run->q[e]));
                }
                wf = getme__fx64(w, run->wscale);
            }
            wfs[e - e0] = wf;
        }
    int o = 0;
    int32_t n = 0;
    if (t == GETME_TET || t == GETME_HEX) { /* GETME_LANES at a time */
        int32_t *list = scr->list;
        for (int32_t e = e0; e < e1; e++)
            if (wfs[e - e0] >= 0)
                list[n++] = e;
        for (int32_t j = 0; j < n; j += GETME_LANES) {
            double x[3 * GETME_MAX_NV][GETME_LANES], y[3 * GETME_MAX_NV][GETME_LANES];
            const uint16_t *lcs[GETME_LANES];
            /* a short last batch repeats its first element */
            for (int l = 0; l < GETME_LANES; l++)
                lcs[l] = getme__blocks_lnodes(scr, nv,
                                              list[j + l < n ? j + l : j] - e0);
            getme__gather_lanes16(xl, lcs, nv, x);
            if (t == GETME_TET)
                getme__transform_tet_lanes((const double(*)[GETME_LANES])x,
                                           sigma, y);
            else
                getme__transform_hex_lanes((const double(*)[GETME_LANES])x,
                                           sigma, y);
            double yd[3 * GETME_MAX_NV][GETME_LANES];
            int64_t out[GETME_MAX_NV][GETME_LANES];
            int bo = fixed_lanes(run, nv, (const double(*)[GETME_LANES])y, yd,
                                 out);
            for (int l = 0; l < GETME_LANES && j + l < n; l++) {
                int32_t e = list[j + l];
                const uint16_t *lc = getme__blocks_lnodes(scr, nv, e - e0);
                int64_t wf = wfs[e - e0];
                if (__builtin_expect(bo, 0)) { /* never seen in practice */
                    for (int i = 0; i < nv; i++) {
                        int k = lc[i];
                        if (flag[k] & 1) /* fixed */
                            continue;
                        if (out[i][l])
                            o = 1;
                        else
                            add_fixed(acc + 4 * k, wf, (int64_t)yd[3 * i][l],
                                      (int64_t)yd[3 * i + 1][l],
                                      (int64_t)yd[3 * i + 2][l]);
                        flag[k] = 2;
                    }
                    continue;
                }
                /* no branch per element node: a fixed node's terms go to
                   the spare slot m (perf annotate of the base: the fixed
                   flag's test-and-branch was this loop's hottest spot) */
                for (int i = 0; i < nv; i++) {
                    int k = lc[i];
                    /* k, or m for a fixed node (gcc made the plain select
                       a branch) */
                    k += (m - k) & -(int)(flag[k] & 1);
                    add_fixed(acc + 4 * k, wf, (int64_t)yd[3 * i][l],
                              (int64_t)yd[3 * i + 1][l],
                              (int64_t)yd[3 * i + 2][l]);
                    flag[k] = 2;
                }
            }
        }
    } else {
        for (int32_t e = e0; e < e1; e++) {
            int64_t wf = wfs[e - e0];
            if (wf < 0)
                continue;
            const uint16_t *lc = getme__blocks_lnodes(scr, nv, e - e0);
            double x[3 * GETME_MAX_NV], y[3 * GETME_MAX_NV];
            for (int i = 0; i < nv; i++) {
                const double *p = xl + 3 * lc[i];
                x[3 * i] = p[0], x[3 * i + 1] = p[1], x[3 * i + 2] = p[2];
            }
            getme__transform(t, x, sigma, y);
            for (int i = 0; i < nv; i++) {
                int k = lc[i];
                if (flag[k] & 1) /* fixed */
                    continue;
                o |= add_sum(run, acc + 4 * k, wf, y + 3 * i);
                flag[k] = 2;
            }
            n++;
        }
    }
    getme_fx *facc = run->facc;
    /* not after a bound overflow: the iteration starts over (iterate) */
    const int early = run->place_early && !o;
    const double back = 1.0 / run->pscale, rho = run->place_rho;
    double *x = ws->x;
    uint8_t *in_t = run->in_t, *ridx = run->ridx;
    const int32_t *slot = run->slot ? scr->slot : NULL; /* block-local */
    for (int32_t k = 0; k < m; k++) {
        if (k + PREFETCH_AHEAD < m) {
            /* with a pool again (its slots block-local): the block's own
               work moved the entries the first loop fetched out to L3
               (perf: 10-11 % of the scatter on their first load) */
            int64_t ga = gn[k + PREFETCH_AHEAD] & INT32_MAX;
            if (slot) {
                if (slot[k + PREFETCH_AHEAD] >= 0)
                    __builtin_prefetch(
                        facc + 4 * (int64_t)slot[k + PREFETCH_AHEAD], 1, 3);
                __builtin_prefetch(run->xold + 3 * ga, 1, 3);
            } else {
                __builtin_prefetch(facc + 4 * ga, 1, 3);
            }
        }
        if (flag[k] == 2) {
            int32_t gk = gn[k];
            int64_t g = gk & INT32_MAX;
            getme_fx *f;
            if (slot && slot[k] < 0) { /* its only block: the block's sums */
                f = acc + 4 * k;
            } else {
                f = facc + 4 * (slot ? (int64_t)slot[k] : g);
                f[0] += acc[4 * k];
                f[1] += acc[4 * k + 1];
                f[2] += acc[4 * k + 2];
                f[3] += acc[4 * k + 3];
            }
            if (early && gk < 0) { /* the node's last block: complete */
                double a[3];
                node_phat(f, back, a);
                if (slot) {
                    getme__place_first(x, (unsigned char *)(run->xold + 3 * g),
                                       ridx, (int32_t)g, rho, a);
                } else {
                    unsigned char *p = (unsigned char *)f; /* as compute_new_nodes */
                    memcpy(p, a, sizeof a);
                    getme__place_first(x, p + GETME_XOLD_OFF, ridx, (int32_t)g,
                                       rho, a);
                }
                in_t[g] = 2;
            } else {
                in_t[g] = 1;
            }
            /* the slot goes to the next node zeroed, also after a bound
               overflow (o: the iteration starts over), or the next node
               sharing it would add onto these sums (a signed overflow) */
            if (slot && gk < 0)
                f[0] = f[1] = f[2] = f[3] = 0;
        }
    }
    *count += n;
    *ovf |= o;
}

/* One block of scatter_all: the number of elements transformed, plus
   2^32 on a bound overflow (add_sum). */
static int64_t scatter_block(void *ctx, int32_t b)
{
    getme_run *run = ctx;
    const getme_ws *ws = run->ws;
    int32_t count = 0;
    int ovf = 0;
    GETME_FOR_TYPE(getme__ws_type(ws, ws->block_start[b]), transform_block,
                   run, b, run->params->sigma, &count, &ovf);
    return count + ((int64_t)(ovf != 0) << 32);
}

/* For the q_mean stage's placement in the blocks (transform_block): the
   sign bit of a node's entry in blk->nodes marks the last block, in
   getme__blocks_run's order, that holds the node (node indices are below
   2^31, so the bit is free; transform_block masks it).  That order runs
   the blocks of blk->order by position, and blocks running at the same
   time share no node, so a node's blocks run one after another and the
   last one is well defined.  One backward walk over the order, in_t (zero
   before and after) as the seen flags; once per run. */
static void mark_last(getme_run *run)
{
    getme_blocks *blk = &run->adj->blk;
    const getme_ws *ws = run->ws;
    uint8_t *seen = run->in_t;
    for (int32_t k = ws->num_blocks - 1; k >= 0; k--) {
        int32_t b = blk->order[k];
        for (int64_t j = blk->nptr[b]; j < blk->nptr[b + 1]; j++) {
            uint32_t g = (uint32_t)blk->nodes[j] & INT32_MAX;
            if (!seen[g]) {
                seen[g] = 1;
                g |= (uint32_t)1 << 31;
            }
            blk->nodes[j] = (int32_t)g;
        }
    }
    memset(seen, 0, (size_t)ws->nn);
}

/* Room for need entries in the pool of sums (run->facc with a slot map):
   a larger zeroed pool, with the leading pool_used entries (p-hats kept
   by getme__save_phat, or the q*_min stage's sums) copied over.  GETME_OK
   or GETME_ERR_NOMEM (the pool as it was). */
static getme_status pool_reserve(getme_run *run, int64_t need)
{
    if (need <= run->pool_cap)
        return GETME_OK;
    int64_t cap = 2 * run->pool_cap > need ? 2 * run->pool_cap : need;
    if (cap > run->ws->nn)
        cap = run->ws->nn > need ? run->ws->nn : need;
    size_t bytes = (size_t)cap * 4 * sizeof *run->facc;
    getme_fx *p = getme__aligned_alloc(64, bytes);
    if (!p)
        return GETME_ERR_NOMEM;
    memset(p, 0, bytes);
    if (run->facc && run->pool_used > 0)
        memcpy(p, run->facc, (size_t)run->pool_used * 4 * sizeof *p);
    free(run->facc);
    run->facc = p;
    run->phat = (unsigned char *)p;
    run->pool_cap = cap;
    return GETME_OK;
}

getme_status getme__save_phat(getme_run *run, int32_t i)
{
    if (pool_reserve(run, (int64_t)run->nsaved + 1) != GETME_OK)
        return GETME_ERR_NOMEM;
    int32_t k = run->nsaved++, own = run->slot[i];
    unsigned char *e = (unsigned char *)(run->facc + 4 * (int64_t)k);
    memcpy(e, run->ws->x + 3 * (int64_t)i, 3 * sizeof(double));
    memcpy(e + 3 * sizeof(double), &i, sizeof i);
    memcpy(e + 3 * sizeof(double) + sizeof i, &own, sizeof own);
    run->slot[i] = k;
    run->pool_used = run->nsaved;
    return GETME_OK;
}

void getme__pool_reset(getme_run *run)
{
    for (int32_t k = 0; k < run->nsaved; k++) { /* getme__save_phat's */
        const unsigned char *e =
            (const unsigned char *)(run->facc + 4 * (int64_t)k);
        int32_t i, own;
        memcpy(&i, e + 3 * sizeof(double), sizeof i);
        memcpy(&own, e + 3 * sizeof(double) + sizeof i, sizeof own);
        run->slot[i] = own;
    }
    memset(run->facc, 0, (size_t)run->pool_used * 4 * sizeof *run->facc);
    run->pool_used = run->nsaved = 0;
}

/* The q_mean stage's slots in the pool of sums (getme_run.slot), once per
   run after mark_last.  A node's sums are open from its first block to
   its last, which places the node and zeroes its slot (transform_block);
   two nodes may share a slot if one's last block surely ends before the
   other's first begins, whatever the threads' timing.  So this walks
   getme__blocks_run's order phase by phase (the parts' levels, then the
   colours), where the lanes of a phase run at the same time and each
   lane's blocks one after another (a part; a block of a colour; the
   serial colour as one lane).  A node is in one lane of a phase (blocks
   running at the same time share no node).  A lane takes a free slot
   from those its own earlier blocks gave back in this phase, else from
   those free when the phase began (which it then owns), else a new one;
   slots given back in a phase are everyone's from the next phase on.
   A node whose first block is also its last (~18 % of the hexes' nodes,
   ~11 % of the tets') gets none (-1): its block's own sums are complete,
   and transform_block places it from them.
   The pool's size is the number of slots made: ~3 % of the nodes on one
   thread, ~8 % on two (full-size tets and hexes), against 64 B for every
   node without it.  Which slot a node gets changes no bit: the sums are
   exact integers.
   Again after a reorder (rebalance), between iterations, when the pool is
   all zero: it keeps the pool if the new slots fit.  scratch: NULL, or
   2 cap entries lent for the free lists (which hold at most as many
   entries as slots are made).  GETME_OK, GETME_ERR_NOMEM, or
   GETME_ERR_STATE when more than cap slots were needed (run->slot is
   then partly new: call again with more). */
static getme_status assign_slots(getme_run *run, int32_t *scratch, size_t cap)
{
    const getme_blocks *blk = &run->adj->blk;
    const getme_ws *ws = run->ws;
    size_t nn = (size_t)(ws->nn ? ws->nn : 1);
    if (!scratch)
        cap = nn;
    /* avail: free at the phase start; back: given back in the phase */
    int32_t *avail = scratch ? scratch : getme__malloc(nn * sizeof *avail);
    int32_t *back = scratch ? scratch + cap : getme__malloc(nn * sizeof *back);
    uint8_t *seen = run->in_t;                   /* zero before and after */
    if (!avail || !back) {
        free(avail), free(back);
        return GETME_ERR_NOMEM;
    }
    /* fixed nodes take no slot: seen already, slot -1 (never read: they
       are not in I_T); one array less for the walk to look up */
    for (int32_t g = 0; g < ws->nn; g++)
        if (ws->fixed[g]) {
            seen[g] = 1;
            run->slot[g] = -1;
        }
    int32_t navail = 0, made = 0;
    int np = blk->num_parts, nph = GETME_ORDER_LEVELS + blk->num_colours;
    for (int ph = 0; ph < nph; ph++) {
        int32_t nback = 0;
        int c = ph - GETME_ORDER_LEVELS;
        /* the phase's lanes: [lo, hi) of blk->order each */
        int32_t k0 = c < 0 ? blk->part_ptr[ph * np] : blk->col_ptr[c];
        int32_t k1 = c < 0 ? blk->part_ptr[(ph + 1) * np] : blk->col_ptr[c + 1];
        int32_t k = k0, p = 0;
        while (k < k1) {
            int32_t lane_end;
            if (c < 0) { /* part p's blocks (possibly none) */
                lane_end = blk->part_ptr[ph * np + p + 1];
                p++;
            } else {
                lane_end = c == blk->serial_colour ? k1 : k + 1;
            }
            int32_t base = nback; /* this lane's free slots: back[base..) */
            for (; k < lane_end; k++) {
                int32_t b = blk->order[k];
                for (int64_t j = blk->nptr[b]; j < blk->nptr[b + 1]; j++) {
                    int32_t g = blk->nodes[j] & INT32_MAX;
                    if (seen[g])
                        continue;
                    seen[g] = 1;
                    if (blk->nodes[j] < 0) { /* its only block: no slot */
                        run->slot[g] = -1;
                        continue;
                    }
                    run->slot[g] = nback > base ? back[--nback]
                                 : navail > 0   ? avail[--navail]
                                                : made++;
                    if ((size_t)made > cap) { /* only with lent scratch */
                        memset(seen, 0, nn);
                        return GETME_ERR_STATE;
                    }
                }
                for (int64_t j = blk->nptr[b]; j < blk->nptr[b + 1]; j++) {
                    int32_t g = blk->nodes[j] & INT32_MAX;
                    if (blk->nodes[j] < 0 && run->slot[g] >= 0)
                        back[nback++] = run->slot[g];
                }
            }
        }
        memcpy(avail + navail, back, (size_t)nback * sizeof *back);
        navail += nback;
    }
    memset(seen, 0, nn);
    if (!scratch)
        free(avail), free(back);
    run->pool_used = 0;
    if (run->facc && made <= run->pool_cap)
        return GETME_OK;
    /* a pool of exactly the slots' size (pool_reserve's doubling is for
       getme__save_phat's growth one entry at a time) */
    free(run->facc);
    run->facc = NULL;
    run->phat = NULL;
    run->pool_cap = 0;
    return pool_reserve(run, made > 0 ? made : 1);
}

#ifdef GETME_CHECK_SUMS
/* Test builds: with 2 threads, after every q_mean iteration either the
   parts change threads (fb->perm) or, the iteration after, the blocks are
   dealt again with shares that change each time (4:9, 11:3, 1:1, ...),
   so that tests/core/test_adjacency.c's comparison of 1, 2 and 3
   threads, bit for bit, covers both. */
static int rebalance_due(getme_blocks *blk, int nt)
{
    if (nt != 2 || !blk->fb)
        return 0;
    struct getme_block_feedback *fb = blk->fb;
    if (fb->perm[0] == 0) { /* a reorder sets perm back to 0, 1 */
        fb->perm[0] = 1, fb->perm[1] = 0;
        return 0;
    }
    static const int64_t share[3][2] = {{1, 3}, {3, 1}, {1, 1}};
    memcpy(fb->prev_weight, fb->weight, 2 * sizeof *fb->weight);
    memcpy(fb->prev_perm, fb->perm, 2 * sizeof *fb->perm);
    int k = (int)(fb->weight[0] % 3); /* the next in the cycle */
    fb->weight[0] = share[k][0] * 3 + (k + 1) % 3;
    fb->weight[1] = share[k][1] * 3;
    return 1;
}
#else
static int rebalance_due(getme_blocks *blk, int nt)
{
    (void)nt;
    return getme__blocks_rebalance(blk);
}
#endif

/* Between two q_mean iterations, on one process: deal the blocks again
   when the parts' measured speeds call for it (getme__blocks_rebalance,
   block_local.h says why), and redo what depends on the order: the
   last-block marks and the pool's slots.  Every sum is zero between
   iterations (each node's last block zeroes its slot, getme__reset_nodes
   the rest), so nothing carries over, and the order changes no bit.
   Memory: the q_mean stage is the peak (the full hexes' 559 MiB), so
   - the scratch is the sums' array itself, zeroed again after (8 bytes
     per node more lifted the hexes' peak by 12 MiB); only if it is too
     small is scratch allocated, and without memory for it nothing
     changes;
   - uneven parts need more slots (a 60:40 split of the full hexes 13 %
     more, 4 MiB): an order that needs more than run->pool_limit is
     dropped for the one before, and the blocks are not dealt again in
     this run (the parts may still change threads).
   Only a pool that cannot grow fails the run (GETME_ERR_NOMEM). */
static getme_status rebalance(getme_run *run)
{
    getme_blocks *blk = &run->adj->blk;
    const getme_ws *ws = run->ws;
    if (run->comm || !blk->nodes || !rebalance_due(blk, ws->nt))
        return GETME_OK;
    double t0 = omp_get_wtime();
    size_t nn = (size_t)(ws->nn ? ws->nn : 1);
    size_t have = (size_t)run->pool_cap * 4 * sizeof *run->facc;
    getme_fx *sums = run->facc;
    int32_t *own = NULL, *scratch = (int32_t *)(void *)sums;
    if (have < nn * sizeof *scratch) { /* build_order's part[] */
        scratch = own = getme__malloc(nn * sizeof *own);
        if (!own)
            return GETME_OK;
    }
    /* the free lists' room: both in the scratch */
    size_t room = own ? nn / 2 : have / (2 * sizeof *scratch);
    getme_block_order old;
    getme_status st = getme__blocks_reorder(blk, ws, scratch, &old);
    if (st != GETME_OK) { /* no memory: the old order stays */
        free(own);
        return GETME_OK;
    }
    mark_last(run);
    if (run->slot) {
        size_t limit = (size_t)run->pool_limit;
        st = assign_slots(run, scratch, room < limit ? room : limit);
        if (st == GETME_ERR_STATE) { /* too many slots: the old order */
            getme__blocks_settle(blk, &old, 0);
            mark_last(run);
            st = assign_slots(run, scratch, room);
            if (st == GETME_ERR_STATE) /* its slots did fit the pool */
                st = assign_slots(run, NULL, 0);
            blk->fb->cost = HUGE_VAL; /* no more reorders */
        }
    }
    getme__blocks_settle(blk, &old, 1); /* nothing left to free if reverted */
    if (!own && run->facc == sums) /* the scratch back to zero sums */
        memset(sums, 0, have);
    free(own);
    if (blk->fb->cost != HUGE_VAL)
        blk->fb->cost = omp_get_wtime() - t0;
    return st;
}

/* q_mean stage: every free element is transformed, block by block in the
   blocks' race-free order (block_local.h): blocks that run at the same
   time share no node, so they scatter without atomics; the sums are exact
   (exact.h), so their order does not matter. */
static int32_t scatter_all(getme_run *run)
{
    int64_t r = getme__blocks_run(&run->adj->blk, run->ws, scatter_block, run);
    run->overflow |= (r >> 32) != 0;
    return (int32_t)(r & 0xffffffff);
}

/* The q_mean stage's I_T (every free node in use): the same in every
   iteration.  Both its lists are implicit: the nodes (getme__run_node)
   and every free element (relax.c), so run->nodes and run->elems stay
   untouched, so not resident, until the q*_min stage.  A distributed
   part run lists its nodes (dist.c reads the list). */
static void lists_all(getme_run *run)
{
    const getme_ws *ws = run->ws;
    int32_t m = 0;
    run->nodes_all = !run->comm;
    for (int32_t i = 0; i < ws->nn; i++)
        if (getme__ws_moves(ws, i)) {
            if (run->comm)
                run->nodes[m] = i;
            m++;
        }
    run->num_nodes = m;
    run->num_elems = (int32_t)ws->num_free_elem;
}

/* Below this many elements around I_T, scatter_some and update_after's
   sums run element by element in list order: grouping the list by block
   and the block sweep's parallel regions would cost more than they save.
   Above it the grouped path runs on one thread too, for its chunked
   prefetching (some_chunks, update_block): on the full tets' q*_min stage
   at one thread, scatter_some took 0.32-0.33 s against 0.37-0.63 s
   element by element, update_after 0.21-0.22 s against 0.23-0.30 s
   (docs/bench.md, session 23). */
#ifdef GETME_CHECK_SUMS
/* Test builds: the grouped path on any mesh, except with 3 threads, so
   that tests/core/test_adjacency.c's comparison of 1, 2 and 3 threads
   compares it with the element-by-element path. */
#define SOME_GROUPED(ws, ne) ((ws)->nt != 3 && (ne) >= 1)
#else
#define SOME_GROUPED(ws, ne) ((ne) >= 4096)
#endif

/* What a block of scatter_some's or update_after's parallel sweep needs. */
struct some_ctx {
    getme_run *run;
    double qt, sigma;
    getme_ufx *tally; /* update_after: per thread, 4 apart (a cache line) */
};

/* Ring elements per chunk of some_chunk and update_chunk. */
#define SOME_CHUNK 32

/* The contributions of the ring elements g->pos[j0..j1) of one block (all
   of type t, a constant in each copy; 3-D), as add_transformed and
   add_untransformed add them, in three passes over chunks of SOME_CHUNK
   elements.  perf annotate of the element-at-a-time loop: most of its time
   went to the scattered loads of the Eq. 9 weights (the nodes' S_v, the
   edges' S_e, the face neighbours' q), one element's chain after the
   other's.  So the first pass only loads each element's connectivity and
   edge ids and prefetches those; the second sums them (weights_3d's
   arithmetic: the same integers and the same correctly rounded division
   and square root, hence the same bits as weight()) and prefetches the
   sums of the nodes in I_T; the third adds the contributions. */
__attribute__((always_inline)) /* one copy per type: t is a constant */
static inline void some_chunks(int t, const struct some_ctx *s, int32_t j0,
                               int32_t j1, int *ovf)
{
    getme_run *run = s->run;
    const getme_ws *ws = run->ws;
    const getme_adj *adj = run->adj;
    const int32_t *pos = adj->blk.group.pos;
    const double *q = run->q, qt = s->qt;
    const uint8_t *in_t = run->in_t;
    const int nv = getme__nv[t], ned = getme__edges[t].num_edges;
    const int nf = getme__faces[t].num_faces;
    const double qs = adj->qscale, wscale = run->wscale;
    int o = 0;
    for (int32_t c0 = j0; c0 < j1; c0 += SOME_CHUNK) {
        int32_t n = c0 + SOME_CHUNK < j1 ? SOME_CHUNK : j1 - c0;
        int32_t el[SOME_CHUNK], eid[SOME_CHUNK][12], fnb[SOME_CHUNK][6];
        /* bit 0 transformed, bit 1 untransformed (adds its I_T nodes),
           bit 2 irregular (the union walk's weight) */
        uint8_t kind[SOME_CHUNK];
        for (int32_t i = 0; i < n; i++) {
            int32_t e = run->elems[pos[c0 + i]];
            el[i] = e;
            int k = (run->tflag[e] != 0) |
                    (q[e] > qt && getme__owned(run, e)) << 1;
            if (k && adj->irregular[e])
                k |= 4;
            kind[i] = (uint8_t)k;
            if (k == 0 || (k & 4))
                continue;
            const int32_t *c = getme__ws_nodes(ws, t, e);
            for (int v = 0; v < nv; v++)
                __builtin_prefetch(adj->nsum + c[v], 0, 3);
            getme__adj_edge_ids(adj, c, t, getme__adj_slots(adj, ws, t, e),
                                eid[i]);
            for (int j = 0; j < ned; j++)
                __builtin_prefetch(adj->esum + eid[i][j], 0, 3);
            int32_t *f = fnb[i];
            getme__adj_faces(adj, ws, t, e, f);
            for (int j = 0; j < nf; j++) /* no neighbour (-1): e itself */
                __builtin_prefetch(q + (f[j] >= 0 ? f[j] : e), 0, 3);
        }
        double num[SOME_CHUNK], den[SOME_CHUNK];
        for (int32_t i = 0; i < SOME_CHUNK; i++)
            num[i] = 0.0, den[i] = 1.0;
        for (int32_t i = 0; i < n; i++) {
            if (kind[i] == 0 || (kind[i] & 4))
                continue;
            int32_t e = el[i];
            const int32_t *c = getme__ws_nodes(ws, t, e);
            const int32_t *f = fnb[i];
            uint64_t sv = 0, se = 0;
            for (int v = 0; v < nv; v++) {
                sv += (uint64_t)adj->nsum[c[v]];
                if (in_t[c[v]])
                    __builtin_prefetch(run->facc + 4 * getme__slot(run, c[v]),
                                       1, 3);
            }
            for (int j = 0; j < ned; j++) /* -1: irregular, not here */
                se += (uint64_t)adj->esum[eid[i][j]];
            num[i] = getme__adj_nsum_3d(adj, sv, se,
                                        getme__adj_face_q(adj, q, f, nf),
                                        (uint64_t)getme__fx64(q[e], qs), nf);
            den[i] = (double)adj->count[e] * q[e];
        }
        int64_t wv[SOME_CHUNK];
#pragma omp simd
        for (int32_t i = 0; i < SOME_CHUNK; i++)
            wv[i] = getme__fx64(sqrt(num[i] / den[i]), wscale);
        for (int32_t i = 0; i < n; i++) {
            int k = kind[i];
            if (k == 0)
                continue;
            int32_t e = el[i];
            int64_t wf = k & 4 ? getme__fx64(getme__weight_union(run, t, e),
                                             wscale)
                               : wv[i];
            const int32_t *c = getme__ws_nodes(ws, t, e);
            if (k & 1) { /* add_transformed */
                double x[3 * GETME_MAX_NV], y[3 * GETME_MAX_NV];
                getme__ws_gather(ws, ws->x, t, e, x);
                getme__transform(t, x, s->sigma, y);
                for (int v = 0; v < nv; v++)
                    if (!ws->fixed[c[v]])
                        o |= add_node(run, c[v], wf, y + 3 * v);
            }
            if (k & 2) /* add_untransformed */
                for (int v = 0; v < nv; v++)
                    if (in_t[c[v]])
                        o |= add_node(run, c[v], wf, ws->x + 3 * (int64_t)c[v]);
        }
    }
    *ovf |= o;
}

/* The contributions of the elements of block b that are in run->elems
   (grouped: getme__blocks_group): those in run->tlist (tflag) transformed,
   those above q_t with their nodes in I_T untransformed, as scatter_some
   adds them serially (3-D: some_chunks).  Returns 1 on a bound overflow
   (add_node). */
static int64_t scatter_some_block(void *ctx, int32_t b)
{
    const struct some_ctx *s = ctx;
    getme_run *run = s->run;
    const struct getme_block_group *g = &run->adj->blk.group;
    if (g->ptr[b] == g->ptr[b + 1])
        return 0;
    int t = getme__ws_type(run->ws, run->ws->block_start[b]);
    int ovf = 0;
    if (run->ws->dim == 3) {
        GETME_FOR_TYPE(t, some_chunks, s, g->ptr[b], g->ptr[b + 1], &ovf);
        return ovf;
    }
    for (int32_t j = g->ptr[b]; j < g->ptr[b + 1]; j++) {
        int32_t e = run->elems[g->pos[j]];
        if (run->tflag[e])
            ovf |= add_transformed(run, t, e, s->sigma);
        if (run->q[e] > s->qt && getme__owned(run, e))
            ovf |= add_untransformed(run, t, e);
    }
    return ovf;
}

/* A ring whose stars hold at least ne / RING_SWEEP_DIV element entries is
   listed by a sweep over the element flags (ring_sweep) instead of in
   first-occurrence order (a sweep over every element would cost more than
   it saves on a small ring). */
#define RING_SWEEP_DIV 32
#ifdef GETME_CHECK_SUMS
/* Test builds: 2 threads always sweep, other counts never, so that
   tests/core/test_adjacency.c's comparison of 1, 2 and 3 threads compares
   the two orders of run->elems (and the serial and block-grouped sums). */
#define RING_SWEEP(ws, stars) ((ws)->nt == 2)
#else
#define RING_SWEEP(ws, stars) ((stars) >= (ws)->ne / RING_SWEEP_DIV)
#endif
/* Elements per chunk of ring_sweep's parallel count and placement. */
#define RING_CHUNK 16384

/* The elements marked in run->eflag, in ascending order, into run->elems,
   clearing the marks; returns how many.  Why ascending: scatter_some's
   and update_after's block sweeps and the relaxation's first pass then
   walk each block's elements in memory order, so the per-element arrays
   (q, connectivity, face neighbours, edge slots) stream and neighbouring
   elements share their nodes' and edges' cache lines; in first-occurrence
   order (a node's star after another's) nearly every element was a miss.
   The order of run->elems changes no result: the scatter's and the sums'
   integer additions are exact, the relaxation treats each element and
   node alone and its step rounds are sets, and update_after sorts the
   transformation list.  A parallel count per chunk, then each chunk
   places its elements (serial if the counts have no room: the same
   list). */
static int32_t ring_sweep(getme_run *run)
{
    const getme_ws *ws = run->ws;
    uint8_t *eflag = run->eflag;
    int32_t *out = run->elems, n = ws->ne;
    int32_t nc = (n + RING_CHUNK - 1) / RING_CHUNK;
    int32_t *cnt = getme__malloc(((size_t)nc + 1) * sizeof *cnt);
    if (!cnt) {
        int32_t m = 0;
        for (int32_t e = 0; e < n; e++)
            if (eflag[e]) {
                eflag[e] = 0;
                out[m++] = e;
            }
        return m;
    }
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t c = 0; c < nc; c++) {
        int32_t end = c < nc - 1 ? (c + 1) * RING_CHUNK : n, m = 0;
        for (int32_t e = c * RING_CHUNK; e < end; e++)
            m += eflag[e] != 0;
        cnt[c + 1] = m;
    }
    cnt[0] = 0;
    for (int32_t c = 0; c < nc; c++)
        cnt[c + 1] += cnt[c];
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t c = 0; c < nc; c++) {
        int32_t end = c < nc - 1 ? (c + 1) * RING_CHUNK : n, m = cnt[c];
        for (int32_t e = c * RING_CHUNK; e < end; e++)
            if (eflag[e]) {
                eflag[e] = 0;
                out[m++] = e;
            }
    }
    int32_t total = cnt[nc];
    free(cnt);
    return total;
}

/* q*_min stage: only the elements in run->tlist (q <= q_t) are transformed,
   and the untransformed ones around their moving nodes add their nodes.
   I_T and the elements around it are listed on one thread, in list order.
   The sums are exact integers (exact.h), so their order does not matter:
   with enough elements the contributions are added block by block in the
   blocks' race-free order (block_local.h; blocks running at the same time
   share no node, so no atomics), else in list order on one thread; the
   same bits either way.  Returns the number transformed, or -1 if the
   pool of sums (with a slot map) could not grow to I_T. */
static int32_t scatter_some(getme_run *run, double qt, double sigma)
{
    const getme_ws *ws = run->ws;
    int32_t nn = 0, ne = 0;
    run->nodes_all = 0;
    for (int32_t k = 0; k < run->num_t; k++) { /* I_T */
        int32_t e = run->tlist[k];
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int i = 0; i < getme__nv[t]; i++)
            if (!ws->fixed[c[i]] && !run->in_t[c[i]]) {
                run->in_t[c[i]] = 1;
                run->nodes[nn++] = c[i];
            }
    }
    if (run->comm) { /* I_T of the whole mesh: nodes of remote t-elements */
        getme__dist_node_or(run, run->in_t);
        nn = 0;
        for (int32_t i = 0; i < ws->nn; i++)
            if (run->in_t[i])
                run->nodes[nn++] = i;
    }
    if (run->slot) { /* node nodes[k] sums into pool entry k */
        if (pool_reserve(run, nn) != GETME_OK) {
            for (int32_t k = 0; k < nn; k++)
                run->in_t[run->nodes[k]] = 0;
            return -1;
        }
        for (int32_t k = 0; k < nn; k++)
            run->slot[run->nodes[k]] = k;
        run->pool_used = nn;
    }
    int64_t stars = 0; /* the elements around I_T, with repeats */
    for (int32_t k = 0; k < nn; k++)
        stars += getme__star_size(ws, run->nodes[k]);
    if (RING_SWEEP(ws, stars)) { /* marked, then in order */
        for (int32_t k = 0; k < nn; k++) {
            getme_star_it it = getme__star_open(ws, run->nodes[k]);
            for (int32_t e; getme__star_next(&it, &e);)
                run->eflag[e] = 1;
        }
        ne = ring_sweep(run);
    } else {
        for (int32_t k = 0; k < nn; k++) {
            getme_star_it it = getme__star_open(ws, run->nodes[k]);
            for (int32_t e; getme__star_next(&it, &e);)
                if (!run->eflag[e]) {
                    run->eflag[e] = 1;
                    run->elems[ne++] = e;
                }
        }
        for (int32_t k = 0; k < ne; k++)
            run->eflag[run->elems[k]] = 0;
    }
    run->num_nodes = nn;
    run->num_elems = ne;
    run->adj->blk.group.n = -1; /* run->elems changed */
    if (SOME_GROUPED(ws, ne) &&
        getme__blocks_group(&run->adj->blk, ws, run->elems, ne) == GETME_OK) {
        /* update_after's sums use the same grouping (run->elems stays) */
        struct some_ctx s = {run, qt, sigma, NULL};
        run->overflow |= getme__blocks_run(&run->adj->blk, ws,
                                           scatter_some_block, &s) != 0;
        return run->num_t;
    }
    int ovf = 0;
    for (int32_t k = 0; k < run->num_t; k++) {
        int32_t e = run->tlist[k];
        ovf |= add_transformed(run, getme__ws_type(ws, e), e, sigma);
    }
    for (int32_t k = 0; k < ne; k++) {
        int32_t e = run->elems[k];
        if (run->q[e] > qt && getme__owned(run, e))
            ovf |= add_untransformed(run, getme__ws_type(ws, e), e);
    }
    run->overflow |= ovf;
    return run->num_t;
}

static int cmp_int32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* Room for n entries in run->tlist; 0, or -1 if out of memory. */
static int tlist_reserve(getme_run *run, int64_t n)
{
    if (n <= run->cap_t)
        return 0;
    int64_t cap = n > 2 * run->cap_t ? n : 2 * run->cap_t;
    int32_t *p = getme__realloc(run->tlist, (size_t)cap * sizeof *p);
    if (!p)
        return -1;
    run->tlist = p;
    run->cap_t = cap;
    return 0;
}

/* Element run->elems[k] (type t), its quality changed from run->qold[k]:
   its move of the Eq. 9 sums (getme__adj_add) and of q_mean's sum (*tsum
   when there is a tally). */
static inline void sum_change(getme_run *run, int t, int32_t k,
                              getme_ufx *tsum)
{
    getme_adj *adj = run->adj;
    int32_t e = run->elems[k];
    double qo = run->qold[k], qn = run->q[e];
    if (qn == qo)
        return;
    if (run->tally)
        *tsum += getme__tally_diff(qo, qn);
    uint64_t d = (uint64_t)getme__fx64(qn, adj->qscale) -
                 (uint64_t)getme__fx64(qo, adj->qscale);
    getme__adj_add(adj, run->ws, t, e, getme__ws_nodes(run->ws, t, e), d);
}

/* update_after's sums for the elements of block b in run->elems (as
   scatter_some grouped them): a block's elements' nodes and edges are no
   other block's running at the same time; q_mean's sum moves by the
   thread's total.  3-D, in chunks of SOME_CHUNK: the first pass finds each
   element's difference and edge ids and prefetches its S_v and S_e, the
   second adds (sum_change's work; perf annotate of the element-at-a-time
   loop showed it waiting on those scattered read-modify-writes one
   element after the other).  Integer sums, so the same bits. */
static int64_t update_block(void *ctx, int32_t b)
{
    const struct some_ctx *s = ctx;
    getme_run *run = s->run;
    const struct getme_block_group *g = &run->adj->blk.group;
    if (g->ptr[b] == g->ptr[b + 1])
        return 0;
    const getme_ws *ws = run->ws;
    int t = getme__ws_type(ws, ws->block_start[b]);
    getme_ufx *tsum = s->tally + 4 * omp_get_thread_num();
    if (ws->dim != 3) {
        for (int32_t j = g->ptr[b]; j < g->ptr[b + 1]; j++)
            sum_change(run, t, g->pos[j], tsum);
        return 0;
    }
    getme_adj *adj = run->adj;
    const int nv = getme__nv[t], ned = getme__edges[t].num_edges;
    const double qs = adj->qscale;
    getme_ufx ts = 0;
    for (int32_t c0 = g->ptr[b]; c0 < g->ptr[b + 1]; c0 += SOME_CHUNK) {
        int32_t n = c0 + SOME_CHUNK < g->ptr[b + 1] ? SOME_CHUNK
                                                    : g->ptr[b + 1] - c0;
        int32_t el[SOME_CHUNK], eid[SOME_CHUNK][12];
        uint64_t dd[SOME_CHUNK];
        for (int32_t i = 0; i < n; i++) {
            int32_t k = g->pos[c0 + i], e = run->elems[k];
            double qo = run->qold[k], qn = run->q[e];
            el[i] = e;
            dd[i] = 0;
            if (qn == qo)
                continue;
            if (run->tally)
                ts += getme__tally_diff(qo, qn);
            dd[i] = (uint64_t)getme__fx64(qn, qs) - (uint64_t)getme__fx64(qo, qs);
            if (!dd[i])
                continue;
            const int32_t *c = getme__ws_nodes(ws, t, e);
            for (int v = 0; v < nv; v++)
                __builtin_prefetch(adj->nsum + c[v], 1, 3);
            getme__adj_edge_ids(adj, c, t, getme__adj_slots(adj, ws, t, e),
                                eid[i]);
            for (int j = 0; j < ned; j++)
                if (eid[i][j] >= 0)
                    __builtin_prefetch(adj->esum + eid[i][j], 1, 3);
        }
        for (int32_t i = 0; i < n; i++) /* getme__adj_add's sums */
            if (dd[i])
                getme__adj_add_ids(adj, ws, t, getme__ws_nodes(ws, t, el[i]),
                                   eid[i], dd[i]);
    }
    *tsum += ts;
    return 0;
}

/* After an iteration of the q*_min stage: bring the Eq. 9 sums up to date
   by the quality changes of the elements that moved (run->elems; their old
   qualities are in run->qold), and the list of elements with q <= q_t
   (only those elements can have entered or left it).  The sums are exact
   fixed point (exact.h): an update by the difference of the old and new
   fixed-point qualities gives the same bits as a recomputation. */
static getme_status update_after(getme_run *run, double qt)
{
    const getme_ws *ws = run->ws;
    getme_adj *adj = run->adj;
    if (!run->qold) /* no room for the old qualities: recompute all sums */
        getme__adj_sums_all(adj, ws, run->q);
    getme_ufx *tsum = NULL;
    if (run->qold && adj->blk.group.n == run->num_elems)
        tsum = getme__aligned_alloc(64, (size_t)ws->nt * 4 * sizeof *tsum);
    if (tsum) { /* in the blocks' race-free order, as scatter_some */
        for (int p = 0; p < ws->nt; p++)
            tsum[4 * p] = 0;
        struct some_ctx s = {run, qt, 0.0, tsum};
        getme__blocks_run(&adj->blk, ws, update_block, &s);
        for (int p = 0; run->tally && p < ws->nt; p++)
            run->tally->sum += tsum[4 * p];
        free(tsum);
    } else {
        getme_ufx d = 0;
        for (int32_t k = 0; run->qold && k < run->num_elems; k++)
            sum_change(run, getme__ws_type(ws, run->elems[k]), k, &d);
        if (run->tally)
            run->tally->sum += d;
    }

    /* distributed: every process stops if one has no room (else the
       others would wait for it in their next hook) */
    if (getme__dist_any(run, tlist_reserve(run, (int64_t)run->num_t +
                                                    run->num_elems) != 0))
        return GETME_ERR_NOMEM;
    int32_t n = 0;
    for (int32_t k = 0; k < run->num_t; k++) {
        int32_t e = run->tlist[k];
        if (run->q[e] <= qt)
            run->tlist[n++] = e;
        else
            run->tflag[e] = 0;
    }
    for (int32_t k = 0; k < run->num_elems; k++) {
        int32_t e = run->elems[k];
        if (run->q[e] <= qt && !run->tflag[e] && getme__owned(run, e)) {
            run->tflag[e] = 1;
            run->tlist[n++] = e;
        }
    }
    if (n > 1) /* a part may have none (and no list yet) */
        qsort(run->tlist, (size_t)n, sizeof *run->tlist, cmp_int32);
    run->num_t = n;
    return GETME_OK;
}

/* A new cycle's transformation list: the free elements with q <= q_t.
   GETME_OK or GETME_ERR_NOMEM. */
static getme_status start_tlist(getme_run *run, double qt)
{
    const getme_ws *ws = run->ws;
    int32_t n = 0;
#pragma omp parallel for schedule(static) num_threads(ws->nt) reduction(+ : n)
    for (int32_t e = 0; e < ws->ne; e++) {
        run->tflag[e] =
            ws->free_elem[e] && getme__owned(run, e) && run->q[e] <= qt;
        n += run->tflag[e];
    }
    if (getme__dist_any(run, tlist_reserve(run, n) != 0)) /* all stop */
        return GETME_ERR_NOMEM;
    n = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (run->tflag[e])
            run->tlist[n++] = e;
    run->num_t = n;
    return GETME_OK;
}

/* ComputeNewNodes: p-hat = weighted sum / weight sum, for I_T, from the
   exact sums (node_phat), written over them (cleared by
   getme__reset_nodes).  In the same pass each node takes the relaxation's
   first position (rho0 = R[0]; getme__place_first), which saves the
   relaxation a pass over the nodes' sums.  Nodes their last block placed
   already (in_t 2, transform_block) are skipped: in the q_mean stage on
   one process that is all of them, and this pass reads only the list and
   the flags. */
static void compute_new_nodes(getme_run *run, double rho0)
{
    double back = 1.0 / run->pscale;
    getme_fx *facc = run->facc;
    double *x = run->ws->x;
    uint8_t *ridx = run->ridx;
    const uint8_t *in_t = run->in_t;
    int32_t nn = getme__run_nodes_end(run);
#pragma omp parallel for schedule(static) num_threads(run->ws->nt) \
    if (nn > GETME_PAR_MIN)
    for (int32_t k = 0; k < nn; k++) {
        int32_t n = getme__run_node(run, k);
        if (n < 0 || in_t[n] == 2)
            continue; /* placed by its last block (transform_block) */
        getme_fx *f = facc + 4 * getme__slot(run, n);
        double a[3];
        node_phat(f, back, a);
        /* p-hat over the node's sums (run->phat): getme__reset_nodes
           zeroes them again before the next scatter. */
        unsigned char *p = (unsigned char *)f;
        memcpy(p, a, sizeof a);
        getme__place_first(x, getme__xold(run, n), ridx, n, rho0, a);
    }
    run->placed = 1;
}

/* Undo a scatter: put back the nodes it placed (in_t 2: their old
   coordinates are after their p-hat), zero the sums and the I_T flags it
   set. */
static void clear_sums(getme_run *run)
{
    int32_t end = getme__run_nodes_end(run);
    for (int32_t k = 0; k < end; k++) {
        int32_t n = getme__run_node(run, k);
        if (n >= 0 && run->in_t[n] == 2)
            memcpy(run->ws->x + 3 * (int64_t)n, getme__xold(run, n),
                   3 * sizeof(double));
    }
    memset(run->facc, 0, (size_t)run->pool_cap * 4 * sizeof *run->facc);
    run->pool_used = run->nsaved = 0;
    for (int32_t k = 0; k < end; k++) {
        int32_t n = getme__run_node(run, k);
        if (n >= 0)
            run->in_t[n] = 0;
    }
}

/* This iteration's fixed-point scales (exact.h), from bounds every term
   obeys, all powers of two (so the scales are exact):
     w = sqrt(mean of q over N(E) / q_E) <= sqrt(2 / q_lo) <= W, where q_lo
       is the lowest quality of a free element (every element that
       contributes has a free node, and q <= 1 up to rounding);
     |x| < xbound for every coordinate contributed (add_node checks it);
     a node sums fewer than star_bound = 2^b terms (its elements).
   wscale = 2^(64 - b) / W makes the integer weight wf < 2^(64 - b);
   pscale = 2^62 / xbound makes a coordinate's integer < 2^62; a product is
   below 2^(126 - b) and a node's sum of fewer than 2^b of them below 2^126:
   no overflow in 128 bits (and sum wf < 2^64).
   Precision: a coordinate's truncation is < 1 / pscale = 2^-62 xbound
   = 2^-58 X (X = 2^ceil(log2 max |x|)), below a double's 2^-52 X ulp at
   the mesh's extent; p-hat is a mean with the integer weights, so their
   truncation (relative < W / (w 2^(64 - b)) <= 2^(b - 62) / q_lo) only
   perturbs the weights, moving p-hat by at most that fraction of the
   spread of the points averaged (an element's size), never by X
   (docs/distributed.md). */
static void set_scales(getme_run *run, double q_lo)
{
    double lo = q_lo > 0x1p-600 ? q_lo : 0x1p-600;
    double W = getme__pow2_ceil(sqrt(2.0 / lo) * (1.0 + 0x1p-40));
    run->wscale = 0x1p64 / run->star_bound / W;
    run->pscale = 0x1p62 / run->xbound;
}

/* xbound: a power of two above 16 |x| for every coordinate x of the mesh
   (a transformed element stays near its own nodes, so its nodes are far
   inside; add_node checks), and star_bound. */
static void set_bounds(getme_run *run)
{
    const getme_ws *ws = run->ws;
    double m = 0.0;
    int64_t big = ws->max_star;
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    reduction(max : m)
    for (int32_t i = 0; i < ws->nn; i++) {
        const double *x = ws->x + 3 * (int64_t)i;
        for (int d = 0; d < 3; d++)
            m = fabs(x[d]) > m ? fabs(x[d]) : m;
    }
    double neg[2] = {-m, -(double)big}; /* maxima of the whole mesh */
    getme__dist_min(run, neg, 2);
    m = -neg[0];
    big = (int64_t)-neg[1];
    run->xbound = 16.0 * getme__pow2_ceil(m > 0x1p-500 ? m : 0x1p-500);
    run->star_bound = getme__pow2_ceil((double)big + 1.0);
    if (run->comm) { /* the Eq. 9 sums' scale from the largest star of the
                        whole mesh, as getme__adj_build sets it for one */
        run->adj->qscale = 0x1p61 / run->star_bound;
        run->adj->qinv = 1.0 / run->adj->qscale;
    }
    if (run->star_bound < 4.0) /* wf < 2^62: an int64 */
        run->star_bound = 4.0;
}

/* Room for the old qualities of run->num_elems elements in run->qold,
   or run->qold = NULL (update_after then recomputes all sums). */
static void qold_reserve(getme_run *run)
{
    if (run->num_elems <= run->cap_qold && run->qold)
        return;
    free(run->qold);
    run->cap_qold = 2 * (int64_t)run->num_elems + 64;
    run->qold = getme__malloc((size_t)run->cap_qold * sizeof *run->qold);
    if (!run->qold)
        run->cap_qold = 0;
}

#ifdef GETME_CHECK_SUMS
/* Test builds (tests/core): are the Eq. 9 sums, kept up to date by exact
   differences as qualities change, the bits a recomputation gives?
   (recomputes them, which gives the same bits when they are) */
static int sums_current(getme_run *run)
{
    getme_adj *adj = run->adj;
    size_t nb = (size_t)run->ws->nn * sizeof *adj->nsum;
    size_t eb = (size_t)adj->num_edges * sizeof *adj->esum;
    int64_t *n = getme__malloc(nb ? nb : 1), *e = getme__malloc(eb ? eb : 1);
    int same = n && e;
    if (same) {
        memcpy(n, adj->nsum, nb);
        if (eb)
            memcpy(e, adj->esum, eb);
        getme__adj_sums_all(adj, run->ws, run->q);
        same = memcmp(n, adj->nsum, nb) == 0 && (!eb || memcmp(e, adj->esum, eb) == 0);
    }
    free(n), free(e);
    return same;
}
#endif

#ifdef GETME_CHECK_SUMS
/* Test builds (tests/core), every q_mean iteration: a scatter with a bound
   32 times smaller first (elements with a coordinate beyond it overflow,
   the other blocks place their nodes: transform_block), undone as after a
   real overflow (clear_sums); the coordinates must be back bit for bit.
   The real scatter follows with the real bound, so outputs are a release
   build's.  A real overflow is never seen in practice, so this is where
   the undo of early placements runs.  GETME_OK, or GETME_ERR_STATE. */
static getme_status undo_check(getme_run *run, double q_lo)
{
    size_t xb = (size_t)run->ws->nn * 3 * sizeof(double);
    double *x0 = getme__malloc(xb ? xb : 1), bound = run->xbound;
    if (!x0)
        return GETME_ERR_STATE;
    memcpy(x0, run->ws->x, xb);
    run->xbound = bound / 32.0;
    set_scales(run, q_lo);
    scatter_all(run);
    run->overflow = 0;
    clear_sums(run);
    run->xbound = bound;
    int same = memcmp(x0, run->ws->x, xb) == 0;
    free(x0);
    return same ? GETME_OK : GETME_ERR_STATE;
}
#endif

/* One iteration of the main loop (Fig. 3 lines 5-9).  mean_stage: the
   q_mean stage, where every free element is transformed over the lists
   lists_all() built; otherwise the elements with q <= qt (run->tlist).
   Decided by the stage, not by qt: a q*_min cycle's qt can be 1 on a
   mesh that is mostly perfect, and must still use its own lists. */
static getme_status iterate(getme_run *run, int mean_stage, double qt,
                            double q_lo, const double *R, int nR,
                            int32_t *num_transformed, int32_t *num_relaxed)
{
    double sigma = run->params->sigma;
    /* The q_mean stage's relaxation keeps the Eq. 9 sums at run->q (relax.c);
       in the q*_min stage update_after brings them up to date. */
    run->live = mean_stage ? run->adj : NULL;
    /* the q_mean stage's blocks place their nodes (transform_block); not
       distributed, where a node's sums are complete only once summed over
       the processes */
    run->place_early = mean_stage && !run->comm;
    run->place_rho = R[0];
#ifdef GETME_CHECK_SUMS
    if (run->place_early && undo_check(run, q_lo) != GETME_OK)
        return GETME_ERR_STATE;
#endif
    for (;;) {
        set_scales(run, q_lo);
        run->overflow = 0;
        *num_transformed = mean_stage ? scatter_all(run)
                                      : scatter_some(run, qt, sigma);
        if (*num_transformed < 0) /* no room for the pool's sums */
            return GETME_ERR_NOMEM;
        if (!getme__dist_any(run, run->overflow))
            break;
        /* A transformed node beyond xbound (never seen in practice): clear
           the sums and start over with room for it; deterministic, since
           the bound and the test are. */
        clear_sums(run);
        run->xbound *= 256.0;
    }
    run->place_early = 0;
    if (run->comm) { /* every copy of a node gets the whole mesh's sums */
        if (mean_stage)
            getme__dist_node_or(run, run->in_t);
        getme__dist_node_sum(run, run->facc, 4);
    }
    compute_new_nodes(run, R[0]);
    /* with a slot map, the q_mean stage's p-hats are in ws->x (R[0] = 1)
       until a node steps down the table (getme__save_phat) */
    run->save_phat = mean_stage && run->slot;
    if (!mean_stage) {
        qold_reserve(run);
        for (int32_t k = 0; run->qold && k < run->num_elems; k++)
            run->qold[k] = run->q[run->elems[k]];
    }
    *num_relaxed = getme__relax(run, R, nR);
    run->live = NULL;
    run->save_phat = 0;
    if (*num_relaxed < 0) /* test builds: the relaxed counts differ */
        return GETME_ERR_STATE;
    if (run->comm) { /* counts of the whole mesh, each node once */
        int64_t c[2] = {*num_transformed, 0};
        for (int32_t k = 0; k < run->num_nodes; k++)
            c[1] += run->counted[run->nodes[k]] && run->ridx[run->nodes[k]];
        getme__dist_sum_i64(run, c, 2);
        *num_transformed = (int32_t)c[0];
        *num_relaxed = (int32_t)c[1];
    }
    getme__reset_nodes(run);
    getme_status st = mean_stage ? GETME_OK : update_after(run, qt);
#ifdef GETME_CHECK_SUMS
    if (st == GETME_OK && !sums_current(run))
        st = GETME_ERR_STATE;
#endif
    return st;
}

/* Swap a <= b for quickselect. */
static inline void order2(double *a, double *b)
{
    if (*b < *a) {
        double t = *a;
        *a = *b;
        *b = t;
    }
}

double getme__select_kth(double *v, int32_t n, int32_t k)
{
    int32_t lo = 0, hi = n - 1;
    while (hi > lo) {
        int32_t mid = lo + (hi - lo) / 2;
        order2(&v[lo], &v[mid]);
        order2(&v[lo], &v[hi]);
        order2(&v[mid], &v[hi]);
        double pivot = v[mid];
        int32_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i <= j) {
                double t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++, j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return v[k];
    }
    return v[k];
}

static inline uint64_t bits_of(double v)
{
    uint64_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

/* The histogram pass of getme__threshold at bits shift..shift + 15 of the
   free elements whose bits under mask are prefix, into hist: one
   histogram per thread (part, zeroed, 65536 counts per thread), added bin
   by bin; integer counts, so the same for any thread count. */
static void threshold_hist(const getme_run *run, int shift, uint64_t mask,
                           uint64_t prefix, int64_t *hist, int64_t *part)
{
    const getme_ws *ws = run->ws;
    int nt = ws->nt;
    memset(part, 0, (size_t)nt * 65536 * sizeof *part);
#pragma omp parallel num_threads(nt)
    {
        int64_t *h = part + (int64_t)omp_get_thread_num() * 65536;
#pragma omp for schedule(static)
        for (int32_t e = 0; e < ws->ne; e++) {
            uint64_t b = bits_of(run->q[e]);
            if (ws->free_elem[e] && getme__owned(run, e) &&
                (b & mask) == prefix)
                h[(b >> shift) & 0xffff]++;
        }
#pragma omp for schedule(static)
        for (int32_t bin = 0; bin < 65536; bin++) {
            int64_t c = 0;
            for (int k = 0; k < nt; k++)
                c += part[(int64_t)k * 65536 + bin];
            hist[bin] = c;
        }
    }
}

/* DetermineTransformationThreshold: the quality at position
   fraction * n (at least min_count - 1) of the sorted qualities of the
   elements with a free node
   (elements without one can never change, so they would only dilute it).
   Without copying all n qualities: they are positive, so their bit
   patterns sort like their values; a histogram of the top 16 bits, then
   of the next 16 inside the chosen bin, leaves a handful of candidates for
   the quickselect.  Returns -1 if out of memory. */
double getme__threshold(getme_run *run, double fraction, int32_t min_count)
{
    const getme_ws *ws = run->ws;
    int64_t n = ws->num_free_elem;
    if (run->comm) { /* the free elements of the whole mesh */
        n = 0;
        for (int32_t e = 0; e < ws->ne; e++)
            n += ws->free_elem[e] && run->owned[e];
        getme__dist_sum_i64(run, &n, 1);
    }
    if (n == 0)
        return 0.0;
    int64_t k = getme__quantile_pos(n, fraction, min_count);
    /* the histogram (dist/test_fail_alloc.c fails this malloc by its
       size), and one per thread */
    int64_t *hist = getme__malloc(65536 * sizeof *hist);
    int64_t *part = getme__malloc((size_t)ws->nt * 65536 * sizeof *part);
    if (getme__dist_any(run, !hist || !part)) { /* all stop, not only this one */
        free(hist);
        free(part);
        return -1.0;
    }
    uint64_t prefix = 0, mask = 0;
    int64_t in_bin = n;
    /* Distributed: the histograms are summed over processes, and two more
       levels pin all 64 bits, so no process needs the candidates. */
    int last = run->comm ? 0 : 32;
    for (int shift = 48; shift >= last; shift -= 16) {
        threshold_hist(run, shift, mask, prefix, hist, part);
        getme__dist_sum_i64(run, hist, 65536);
        int64_t below = 0;
        int bin = 0;
        while (bin < 65535 && below + hist[bin] <= k)
            below += hist[bin++];
        k -= below;
        in_bin = hist[bin];
        prefix |= (uint64_t)bin << shift;
        mask |= (uint64_t)0xffff << shift;
    }
    free(hist);
    free(part);
    if (run->comm) {
        double qt;
        memcpy(&qt, &prefix, sizeof qt);
        return qt;
    }
    double *cand = getme__malloc((size_t)in_bin * sizeof *cand);
    if (!cand)
        return -1.0;
    int32_t m = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (ws->free_elem[e] && (bits_of(run->q[e]) & mask) == prefix)
            cand[m++] = run->q[e];
    double qt = getme__select_kth(cand, m, (int32_t)k);
    free(cand);
    return qt;
}

/* The per-thread stamps of the union walk, if some element needs it. */
static getme_status alloc_stamps(getme_run *run)
{
    const getme_ws *ws = run->ws;
    size_t ne = (size_t)(ws->ne ? ws->ne : 1);
    if (run->adj->num_irregular == 0)
        return GETME_OK;
    run->stamps = getme__calloc((size_t)ws->nt, sizeof *run->stamps);
    if (!run->stamps)
        return GETME_ERR_NOMEM;
    for (int t = 0; t < ws->nt; t++)
        if (!(run->stamps[t].mark = getme__calloc(ne, sizeof(uint32_t))))
            return GETME_ERR_NOMEM;
    return GETME_OK;
}

/* The method's own scratch: the q*_min stage's element flags (its lists
   grow as needed), and the per-thread stamps of the union walk if some
   element needs it. */
static getme_status alloc_adaptive(getme_run *run)
{
    const getme_ws *ws = run->ws;
    size_t ne = (size_t)(ws->ne ? ws->ne : 1);
    run->tflag = getme__calloc(ne, 1);
    size_t nn = (size_t)(ws->nn ? ws->nn : 1);
    /* without it the relaxation scans every element instead */
    run->block_bad = getme__calloc((size_t)(ws->num_blocks ? ws->num_blocks : 1),
                                   sizeof *run->block_bad);
    /* curved second order: 24 B per dependent node (30 MB for 1M tet10) */
    if (getme__ho_curved(ws) &&
        !(run->ho_tab = getme__malloc((size_t)ws->ho->nh * 3 * sizeof *run->ho_tab)))
        return GETME_ERR_NOMEM;
    /* A pool of sums with a slot map (getme_run.facc, assign_slots), on
       one process (a distributed run sums every node's entry over the
       processes) and with a q_mean table from 1 (the p-hat is then the
       placed position: getme__save_phat). */
    int pool = !run->comm && run->params->relax_mean[0] == 1.0;
    run->phat_step = 4 * (int64_t)sizeof *run->facc;
#ifdef GETME_CHECK_SUMS
    /* Test builds: 3 threads go without, so that the tests' comparison
       of 1, 2 and 3 threads (test_adjacency) compares both, bit for bit. */
    pool = pool && ws->nt != 3;
#endif
    if (pool) { /* the pool itself after mark_last (assign_slots) */
        run->slot = getme__malloc(nn * sizeof *run->slot);
        run->xold = getme__malloc(nn * 3 * sizeof *run->xold);
        if (!run->tflag || !run->slot || !run->xold)
            return GETME_ERR_NOMEM;
        return alloc_stamps(run);
    }
    /* 64-byte aligned: a node's four sums are one cache line. */
    size_t fbytes = nn * 4 * sizeof *run->facc;
    run->facc = getme__aligned_alloc(64, fbytes);
    run->pool_cap = (int64_t)nn;
    /* Zeroed by every thread in its own share of the nodes, not by one
       memset: the array is fresh pages (the CLI maps every block of 1 MiB
       or more afresh), 172 MB on the full hexes, and faulting them in was
       0.15-0.55 s on one thread while the other waited. */
    if (run->facc) {
#pragma omp parallel num_threads(ws->nt)
        {
            int th = omp_get_thread_num(), n = omp_get_num_threads();
            int64_t a = (int64_t)nn * th / n, b = (int64_t)nn * (th + 1) / n;
            memset(run->facc + 4 * a, 0, (size_t)(b - a) * 4 * sizeof *run->facc);
        }
    }
    if (!run->tflag || !run->facc)
        return GETME_ERR_NOMEM;
    run->phat = (unsigned char *)run->facc;
    return alloc_stamps(run);
}


static void free_adaptive(getme_run *run)
{
    free(run->block_bad);
    run->block_bad = NULL;
    free(run->ho_tab);
    run->ho_tab = NULL;
    free(run->tlist);
    free(run->tflag);
    free(run->qold);
    free(run->facc);
    free(run->slot);
    /* The old coordinates' array (3 per node) becomes the workspace's
       spare, which the coordinates go back to the mesh in
       (getme__ws_return_x): its pages are faulted in, a fresh block's
       would be (16 MiB on the full tets, 61 MiB on the full hexes). */
    if (run->xold && run->ws->x_lent && !run->ws->x_spare)
        run->ws->x_spare = run->xold;
    else
        free(run->xold);
    run->facc = NULL;
    run->slot = NULL;
    run->xold = NULL;
    run->pool_cap = run->pool_used = 0;
    run->nsaved = 0;
    run->phat = NULL;
    run->qold = NULL, run->cap_qold = 0, run->cap_t = 0;
    if (run->stamps)
        for (int t = 0; t < run->ws->nt; t++)
            free(run->stamps[t].mark);
    free(run->stamps);
    run->tlist = NULL, run->tflag = NULL, run->stamps = NULL;
}

/* The corner guard's floor and its skip bounds (smooth_internal.h); the
   margins keep a rounding in q or in the bound from skipping an element
   whose computed corner would be just below the floor. */
static void set_corner_floor(getme_run *run, double floor)
{
    run->corner_floor = floor;
    double f = floor > 0.0 ? floor * (1.0 + 1e-9) + 1e-12 : 0.0;
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        run->guard_skip_q[t] = 2.0;
    run->guard_skip_q[GETME_HEX] = (7.0 + cbrt(f * f)) / 8.0 + 1e-12;
    run->guard_skip_q[GETME_QUAD] = (3.0 + f) / 4.0 + 1e-12;
}

/* q_mean and q*_min after an iteration of the q*_min stage, without a
   sweep: q_mean from run->tally; q*_min over run->tlist, which holds
   exactly the free elements with q <= q_t (start_tlist, update_after), so
   every other one is above its minimum (a sweep only when it is empty).
   GETME_CHECK_SUMS builds compare both with the sweep (GETME_ERR_STATE if
   they differ: the bookkeeping missed a change). */
static getme_status min_summary(getme_run *run, double *q_mean,
                                double *q_min)
{
    const getme_ws *ws = run->ws;
    if (!run->qold) /* update_after had no room to follow the changes */
        getme__tally_start(run->tally, ws, run->q);
    *q_mean = getme__tally_mean(run->tally, ws->ne);
    if (run->num_t > 0) {
        *q_min = getme__tally_min(run->q, run->tlist, run->num_t);
    } else {
        double m;
        getme__summary(run, &m, q_min, NULL);
    }
#ifdef GETME_CHECK_SUMS
    double m, mn;
    getme__summary(run, &m, &mn, NULL);
    if (m != *q_mean || mn != *q_min)
        return GETME_ERR_STATE;
#endif
    return GETME_OK;
}

getme_status getme__adaptive(getme_run *run)
{
    getme_ws *ws = run->ws;
    const getme_params *p = run->params;
    getme_result *res = run->result;
    getme_best best; /* best.h: an undo log, not a copy */
    getme_input input; /* revert.h: never below the input's q*_min */
    getme_tally tally; /* the q*_min stage's q_mean (run->tally) */
    getme_status st = alloc_adaptive(run);
    if (getme__best_init(&best, run, p->keep_best) != GETME_OK)
        st = GETME_ERR_NOMEM;
    /* Distributed runs do not keep it: a process cannot tell alone which
       of its nodes to put back (docs/distributed.md). */
    if (getme__input_keep(&input, ws, res->q_min_star_initial,
                          p->keep_best && !run->comm) != GETME_OK)
        st = GETME_ERR_NOMEM;
    /* Distributed: all processes stop if one has no memory (the others
       would wait for it in the first hook). */
    if (getme__dist_any(run, st != GETME_OK)) {
        st = GETME_ERR_NOMEM;
        goto done;
    }
    lists_all(run);
    set_bounds(run);
    /* tets: the q_mean stage's edge sums block by block (block_edges.h;
       without memory for it, the global path: the same result) */
    getme__blocks_edges(&run->adj->blk, run->adj, ws);
    double t_order = omp_get_wtime();
    if (!run->comm)
        mark_last(run);
    if (run->slot && assign_slots(run, NULL, 0) != GETME_OK) {
        st = GETME_ERR_NOMEM;
        goto done;
    }
    run->pool_limit = run->pool_cap + run->pool_cap / 32;
    if (run->adj->blk.fb) /* a reorder's cost: the order's build and these */
        run->adj->blk.fb->cost += omp_get_wtime() - t_order;
    /* The Eq. 9 sums at the input's qualities; from here on every change of
       run->q updates them (the relaxation, update_after). */
    getme__adj_sums_all(run->adj, ws, run->q);
    run->guard = p->corner_guard;
    set_corner_floor(run, p->corner_floor > res->corner_sj_initial
                              ? p->corner_floor
                              : res->corner_sj_initial);

    double q_mean = res->q_mean_initial, q_min = res->q_min_star_initial;
    /* best_min: best q*_min since the end of the q_mean stage (its mesh is
       kept in best); record: best_min when the current cycle started. */
    double qt = 1.0, best_min = -1.0, record = -1.0;
    const double *R = p->relax_mean;
    int nR = p->num_relax_mean;
    int state = MEAN_RUNNING, counter = 0, have_cycle = 0;
    st = GETME_OK;
    res->stop_reason = GETME_STOP_MAX_ITER;

    for (int it = 1; it <= p->max_iter; it++) {
        int32_t ntrans, nrelax;
        getme_stage stage = state == MEAN_RUNNING ? GETME_STAGE_MEAN
                                                  : GETME_STAGE_MIN;
        if (stage == GETME_STAGE_MIN &&
            (st = getme__best_note(&best, run)) != GETME_OK)
            break;
        if ((st = iterate(run, state == MEAN_RUNNING, qt, q_min, R, nR,
                          &ntrans, &nrelax)) != GETME_OK)
            break;
        double prev_mean = q_mean, prev_min = q_min;
        if (stage == GETME_STAGE_MIN && run->tally)
            st = min_summary(run, &q_mean, &q_min);
        else
            getme__summary(run, &q_mean, &q_min, NULL);
        if (st != GETME_OK)
            break;
        if (run->comm_failed) {
            st = GETME_ERR_COMM;
            break;
        }
        res->iterations = it;
        if (stage == GETME_STAGE_MEAN)
            res->iterations_mean++;
        else
            res->iterations_min++;
        if (stage == GETME_STAGE_MIN && q_min > best_min) {
            best_min = q_min;
            getme__best_take(&best, ws);
        }
        if (getme__report(run, it, stage, res->cycles_min, q_min, q_mean, qt,
                          ntrans, nrelax) &&
            !run->comm) { /* distributed: every process must go on alike */
            res->stop_reason = GETME_STOP_CANCELLED;
            st = GETME_ERR_CANCELLED;
            break;
        }
        /* Fig. 3 lines 10-27. */
        if (state == MEAN_RUNNING && q_mean - prev_mean < p->tol) {
            state = MIN_START;
            R = p->relax_min;
            nR = p->num_relax_min;
            best_min = q_min; /* the end of stage 1 is the first candidate */
            getme__best_take(&best, ws);
            if (!run->comm) { /* distributed: summed over processes */
                getme__tally_start(&tally, ws, run->q);
                run->tally = &tally;
            }
            /* Only the q_mean stage's scatter_all uses the block kernel's
               node lists and local connectivity: freed before the q*_min
               stage's lists grow (10 B per tet, 18 B per hex less at the
               peak); the blocks' order stays for the later sweeps. */
            getme__blocks_free_local(&run->adj->blk);
        }
        /* another q_mean iteration follows: the parts to the threads'
           speeds (the blocks' node lists are gone once it ends) */
        if (state == MEAN_RUNNING && (st = rebalance(run)) != GETME_OK)
            break;
        if (state == MIN_RUNNING) {
            if (!(q_min > prev_min + p->min_tol))
                counter++;
            if (counter >= p->max_no_min_improve)
                state = MIN_START;
        }
        if (state == MIN_START) {
            /* "No q*_min improvement in the last cycle" means: the cycle
               did not beat the best q*_min seen before it.  Comparing with
               the q*_min at the cycle's start instead lets an oscillating
               mesh "improve" on its own dips forever (measured: 988
               iterations with threshold_fraction 0.05). */
            if (have_cycle && !(best_min > record + p->min_tol)) {
                res->stop_reason = GETME_STOP_CONVERGED;
                break;
            }
            record = best_min;
            state = MIN_RUNNING;
            counter = 0;
            qt = getme__threshold(run, p->threshold_fraction, 0);
            if (qt < 0.0 || (st = start_tlist(run, qt)) != GETME_OK) {
                st = GETME_ERR_NOMEM;
                break;
            }
            /* The Eq. 9 sums are current: the q_mean stage's relaxation
               (relax.c) and update_after keep them at run->q exactly
               (exact.h; GETME_CHECK_SUMS builds check it every
               iteration), so a cycle needs no recomputation.
               Distributed: always (each process's sums of the nodes it
               shares). */
            if (run->comm)
                getme__adj_sums_all(run->adj, ws, run->q);
            have_cycle = 1;
            res->cycles_min++;
        }
    }

    run->tally = NULL;
    if (best.on && best_min > q_min) {
        /* Fixed nodes never move, so this keeps them exact. */
        getme_status rs = getme__best_restore(&best, run);
        st = st == GETME_OK ? rs : st;
        getme__summary(run, &q_mean, &q_min, NULL);
    }
    if (st == GETME_OK && q_min < input.q_min_star) {
        int64_t n = 0;
        st = getme__input_revert(&input, ws, run->q, &n);
        res->reverted_nodes = (int32_t)n;
    }
    getme__input_free(&input);
    /* Distributed: getme_smooth_finish() runs it on the gathered mesh. */
    if (st == GETME_OK && p->finish && !run->comm)
        st = getme__finish(run);
    getme__summary(run, &res->q_mean, &res->q_min_star, &res->q_min);
    if (st == GETME_OK && run->comm_failed)
        st = GETME_ERR_COMM;
    res->threshold = qt;
done:
    run->tally = NULL;
    getme__input_free(&input);
    getme__best_free(&best);
    free_adaptive(run);
    return st;
}

getme_status getme__adaptive_finish(getme_run *run)
{
    const getme_params *p = run->params;
    getme_result *res = run->result;
    run->guard = p->corner_guard;
    set_corner_floor(run, p->corner_floor > res->corner_sj_initial
                              ? p->corner_floor
                              : res->corner_sj_initial);
    getme_status st = p->finish ? getme__finish(run) : GETME_OK;
    getme__ws_summary(run->ws, run->q, &res->q_mean, &res->q_min_star,
                      &res->q_min);
    return st;
}
