/*
 * relax.c -- adaptive per-node relaxation (paper Eq. 10), the step that
 * guarantees a valid mesh after every iteration of both methods.
 *
 * All loops are gathers (each iteration writes only its own node or
 * element), so they need no atomics and give the same result for any
 * number of threads.
 */
#include "adjacency.h"
#include "block_edges.h"
#include "gather_lanes.h"
#include "smooth_internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* A later placement of node i, from its saved old coordinates. */
static inline void place(getme_run *run, int32_t i, double rho)
{
    double x[3], ph[3], xn[3];
    memcpy(x, getme__xold(run, i), sizeof x);
    memcpy(ph, getme__phat(run, i), sizeof ph);
    getme__eq10(rho, x, ph, xn);
    memcpy(run->ws->x + 3 * (int64_t)i, xn, sizeof xn);
}

/* Quality of element e (type t) at the trial coordinates (ws->x), given
   its mean ratio q there: 0 if it is invalid there or if the corner guard
   rejects it: its worst corner fell below both its old value and the
   floor.  An element at its old shape is never rejected, so the
   relaxation's reset argument holds. */
static inline double guard_check(const getme_run *run, int32_t e, int t,
                                 double q);

static inline double trial_check(const getme_run *run, int32_t e, int t,
                                 double q)
{
    const getme_ws *ws = run->ws;
    if (q > 0.0 && ws->ho &&
        !(run->ho_tab_on ? getme__ho_accept_tab(ws, ws->x, run->ho_tab, e)
                         : getme__ho_accept(ws, ws->x, e)))
        return 0.0; /* second order: det J > 0 at every node, ratio floor */
    return guard_check(run, e, t, q);
}

/* trial_check after its second-order test: the corner guard. */
static inline double guard_check(const getme_run *run, int32_t e, int t,
                                 double q)
{
    const getme_ws *ws = run->ws;
    if (!run->guard || !getme__has_corners(t) || !(q > 0.0) ||
        q >= run->guard_skip_q[t])
        return q;
    double x[3 * GETME_MAX_NV];
    getme__ws_gather(ws, ws->x, t, e, x);
    double sj = getme__corner_sj(t, x);
    if (sj >= run->corner_floor)
        return q;
    const int32_t *c = getme__ws_nodes(ws, t, e); /* the old shape */
    for (int i = 0; i < getme__nv[t]; i++)
        if (run->in_t[c[i]])
            memcpy(x + 3 * i, getme__xold(run, c[i]), 3 * sizeof *x);
    return sj < getme__corner_sj(t, x) ? 0.0 : q;
}

static inline double trial_quality(const getme_run *run, int32_t e)
{
    double x[3 * GETME_MAX_NV];
    int t = getme__ws_type(run->ws, e);
    getme__ws_gather(run->ws, run->ws->x, t, e, x);
    return trial_check(run, e, t, getme__quality(t, x));
}

/* run->q[e] = v, and in the q_mean stage (run->live) the element's S_v
   and S_e moved by the difference of its fixed-point qualities: exact
   integers, so the sums stay the bits a recomputation at run->q gives. */
__attribute__((always_inline)) /* as getme__adj_add: LTO outlined it */
static inline void set_q(getme_run *run, int t, int32_t e, double v)
{
    getme_adj *adj = run->live;
    if (adj) {
        uint64_t d = (uint64_t)getme__fx64(v, adj->qscale) -
                     (uint64_t)getme__fx64(run->q[e], adj->qscale);
        if (d)
            getme__adj_add(adj, run->ws, t, e,
                           getme__ws_nodes(run->ws, t, e), d);
    }
    run->q[e] = v;
}

/* set_q of the n <= GETME_LANES elements elems[0..n) (all of type t), given
   their mean ratios q: as n calls of set_q, in phases across the batch
   (checks, then the fixed-point differences, then the sums' updates), so
   the lanes' conversions and loads are independent of the previous
   element's scattered read-modify-writes.  No phase reads what a later
   one writes (trial_check reads the coordinates only). */
__attribute__((always_inline))
static inline void set_q_lanes(getme_run *run, int t, const int32_t *elems,
                               int32_t n, double *q, int64_t *esl)
{
    getme_adj *adj = run->live;
    if (run->ho_tab_on) { /* curved second order: the test in lanes */
        uint8_t ok[GETME_LANES];
        getme__ho_accept_tab_lanes(run->ws, run->ws->x, run->ho_tab, elems,
                                   n, q, ok);
        for (int32_t l = 0; l < n; l++)
            q[l] = guard_check(run, elems[l], t, ok[l] ? q[l] : 0.0);
    } else {
        for (int32_t l = 0; l < n; l++)
            q[l] = trial_check(run, elems[l], t, q[l]);
    }
    if (adj) {
        uint64_t d[GETME_LANES];
        for (int32_t l = 0; l < n; l++)
            d[l] = (uint64_t)getme__fx64(q[l], adj->qscale) -
                   (uint64_t)getme__fx64(run->q[elems[l]], adj->qscale);
        if (esl) /* tets: S_e in the block's local array (block_edges.h) */
            for (int32_t l = 0; l < n; l++) {
                const int32_t *c = getme__ws_nodes(run->ws, t, elems[l]);
                const uint16_t *le = getme__blocks_ledge(&adj->blk, elems[l]);
                for (int i = 0; i < getme__nv[t]; i++)
                    adj->nsum[c[i]] = (int64_t)((uint64_t)adj->nsum[c[i]] + d[l]);
                for (int j = 0; j < getme__edges[t].num_edges; j++)
                    esl[le[j]] = (int64_t)((uint64_t)esl[le[j]] + d[l]);
            }
        else
            for (int32_t l = 0; l < n; l++)
                if (d[l])
                    getme__adj_add(adj, run->ws, t, elems[l],
                                   getme__ws_nodes(run->ws, t, elems[l]), d[l]);
    }
    for (int32_t l = 0; l < n; l++)
        run->q[elems[l]] = q[l];
}

/* trial_quality of the n <= GETME_LANES elements elems[0..n) into run->q
   (set_q), their mean ratios in one lane kernel (quality.c) when they are
   all of type t and t has one: the same bits, several times faster.  A
   short batch repeats its first element in the unused lanes.  esl: the
   running block's local S_e (tets, trial_block), or NULL. */
__attribute__((always_inline)) /* t is a constant in trial_block's copies */
static inline void trial_batch(int t, getme_run *run, const int32_t *elems,
                               int32_t n, int64_t *esl)
{
    const getme_ws *ws = run->ws;
    double x[3 * GETME_MAX_NV][GETME_LANES], q[GETME_LANES];
    int same = 1; /* the list need not be sorted (q*_min stage) */
    for (int32_t l = 0; l < n; l++)
        same &= elems[l] >= ws->tstart[t] && elems[l] < ws->tstart[t + 1];
    if (same) {
        const int32_t *c[GETME_LANES];
        for (int l = 0; l < GETME_LANES; l++)
            c[l] = getme__ws_nodes(ws, t, elems[l < n ? l : 0]);
        getme__gather_lanes(ws->x, c, getme__nv[t], x);
        if (getme__quality_lanes(t, (const double(*)[GETME_LANES])x, q)) {
            set_q_lanes(run, t, elems, n, q, esl);
            return;
        }
    }
    for (int32_t l = 0; l < n; l++) {
        int32_t e = elems[l];
        set_q(run, getme__ws_type(ws, e), e, trial_quality(run, e));
    }
}

/* Elements ahead whose node coordinates trial_block prefetches (one
   batch: the gather of the hexes' 8 nodes was 40 % of the pass, perf
   annotate; 8 ahead measured best of 8, 16 and 32, trial pass -12 % on
   the medium hexes, tets no slower). */
#define TRIAL_AHEAD GETME_LANES

/* The q_mean stage's first trial-quality pass over block b (its elements
   all of type t, a constant in each copy, GETME_FOR_TYPE): every free
   element's quality at the trial coordinates, and its S_v / S_e updated (set_q).  Blocks
   that run at the same time share no node, hence no edge
   (block_local.h), so the sums need no atomics. */
__attribute__((always_inline)) /* one copy per type: t is a constant */
static inline void trial_block(int t, getme_run *run, int32_t b,
                               int64_t *bad)
{
    const getme_ws *ws = run->ws;
    getme_adj *adj = run->live;
    const getme_blocks *blk = &adj->blk;
    int th = omp_get_thread_num();
    int32_t *list = blk->scratch[th].list;
    /* tets: the S_e changes summed per block edge, then added once each
       (block_edges.h) */
    int64_t *esl = NULL;
    const int32_t *bedges = NULL;
    int32_t nbe = 0;
    if (t == GETME_TET && blk->ledge) {
        esl = getme__blocks_esl(blk, th);
        bedges = blk->edges + blk->eptr[b];
        nbe = (int32_t)(blk->eptr[b + 1] - blk->eptr[b]);
        memset(esl, 0, (size_t)nbe * sizeof *esl);
    }
    int32_t n = 0;
    for (int32_t e = ws->block_start[b]; e < ws->block_start[b + 1]; e++)
        if (ws->free_elem[e])
            list[n++] = e;
    for (int32_t j = 0; j < n; j += GETME_LANES) {
        for (int32_t k = j + TRIAL_AHEAD; k < j + TRIAL_AHEAD + GETME_LANES && k < n; k++) {
            const int32_t *c = getme__ws_nodes(ws, t, list[k]);
            for (int i = 0; i < getme__nv[t]; i++)
                __builtin_prefetch(ws->x + 3 * (int64_t)c[i], 0, 3);
        }
        trial_batch(t, run, list + j,
                    n - j < GETME_LANES ? n - j : GETME_LANES, esl);
    }
    for (int32_t k = 0; k < nbe; k++) {
        /* the global S_e are scattered (perf: this loop's read-modify-
           writes missed, 17 % of the trial pass of tets on Zen 3) */
        if (k + GETME_PREFETCH_AHEAD < nbe && bedges[k + GETME_PREFETCH_AHEAD] >= 0)
            __builtin_prefetch(adj->esum + bedges[k + GETME_PREFETCH_AHEAD], 1, 3);
        if (bedges[k] >= 0) { /* -1: a missing slot, as getme__adj_add */
            int64_t *sum = &adj->esum[bedges[k]];
            *sum = (int64_t)((uint64_t)*sum + (uint64_t)esl[k]);
        }
    }
    for (int32_t k = 0; k < n; k++)
        *bad += !(run->q[list[k]] > 0.0);
}

/* trial_block of block b; returns how many of its elements are invalid
   at the trial coordinates (their sum saves count_invalid's pass), and
   keeps that count for list_invalid. */
static int64_t trial_block_any(void *ctx, int32_t b)
{
    getme_run *run = ctx;
    int64_t bad = 0;
    GETME_FOR_TYPE(getme__ws_type(run->ws, run->ws->block_start[b]),
                   trial_block, run, b, &bad);
    if (run->block_bad)
        run->block_bad[b] = (int32_t)bad;
    return bad;
}

/* The relaxation's element list: run->elems, or in the q_mean stage
   (run->live) every free element in ascending order, which run->elems
   then does not hold (4 B per element less at stage 1's peak).  Element
   k of the list, for k < list_len(run): */
static inline int32_t list_len(const getme_run *run)
{
    return run->live ? run->ws->ne : run->num_elems;
}

/* -1 for an index of the implicit list that is not a free element. */
static inline int32_t list_elem(const getme_run *run, int32_t k)
{
    if (!run->live)
        return run->elems[k];
    return run->ws->free_elem[k] ? k : -1;
}

/* Element e of the list is invalid at the trial coordinates. */
static inline int is_invalid(const getme_run *run, int32_t e)
{
    return e >= 0 && !(run->q[e] > 0.0);
}

/* How many elements of the list are invalid at the trial coordinates
   (parallel count). */
static int32_t count_invalid(const getme_run *run)
{
    int32_t n = list_len(run), bad = 0;
#pragma omp parallel for schedule(static) num_threads(run->ws->nt) \
    reduction(+ : bad) if (n > GETME_PAR_MIN)
    for (int32_t k = 0; k < n; k++)
        bad += is_invalid(run, list_elem(run, k));
    return bad;
}

/* The n invalid elements of the list (q <= 0 at the trial coordinates), in
   list order, into *bad (grown as needed; *cap its room).  Returns how
   many, or -1 if out of memory.  Few elements are invalid, so after this
   one scan each step of the table re-checks only them and the stars it
   touched, instead of counting over the whole list again. */
static int32_t list_invalid(const getme_run *run, int32_t **bad, int64_t *cap,
                            int32_t n)
{
    int32_t m = 0;
    if (n > *cap) {
        int32_t *p = getme__realloc(*bad, (size_t)n * 2 * sizeof *p);
        if (!p)
            return -1;
        *bad = p;
        *cap = 2 * (int64_t)n;
    }
    /* The q_mean stage: only the blocks the first pass found invalid
       elements in (trial_block_any).  Blocks are ascending ranges of
       elements, so the list is the scan's, in element order; the scan
       over every element was 0.07 s of the full tets' stage 1, on one
       thread at any thread count. */
    const getme_ws *ws = run->ws;
    if (run->live && run->block_bad) {
        for (int32_t b = 0; m < n && b < ws->num_blocks; b++) {
            if (run->block_bad[b] == 0)
                continue;
            for (int32_t e = ws->block_start[b]; e < ws->block_start[b + 1]; e++)
                if (is_invalid(run, list_elem(run, e)))
                    (*bad)[m++] = e;
        }
        if (m == n)
            return m;
        m = 0; /* unreachable: the counts are the same elements' */
    }
    for (int32_t k = 0; m < n && k < list_len(run); k++) {
        int32_t e = list_elem(run, k);
        if (is_invalid(run, e))
            (*bad)[m++] = e;
    }
    return m;
}

/* Append element e to the bad list if it is invalid and not yet in it
   (mark: bit 0x80 of eflag, cleared by the caller).  0, or -1 if out of
   memory. */
static int keep_if_invalid(getme_run *run, int32_t e, int32_t **bad,
                           int32_t *n, int64_t *cap)
{
    if (run->q[e] > 0.0 || (run->eflag[e] & 0x80))
        return 0;
    if (getme__push_i32(bad, n, cap, e))
        return -1;
    run->eflag[e] |= 0x80;
    return 0;
}

/* The moving nodes of the invalid elements among bad[0..nbad) (NULL: the
   whole element list, list_elem) that can still step down the table, each
   once, into run->list (serial: few elements are invalid, and the list
   order must not depend on the thread count). */
static int32_t nodes_to_step(getme_run *run, int nR, const int32_t *bad,
                             int32_t nbad)
{
    const getme_ws *ws = run->ws;
    int32_t m = 0;
    if (!bad)
        nbad = list_len(run);
    for (int32_t k = 0; k < nbad; k++) {
        int32_t e = bad ? bad[k] : list_elem(run, k);
        if (!is_invalid(run, e))
            continue; /* the whole element list was passed (no memory) */
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int i = 0; i < getme__nv[t]; i++) {
            int32_t n = c[i];
            if (run->in_t[n] && !run->flag[n] && run->ridx[n] + 1 < nR) {
                run->flag[n] = 1;
                run->list[m++] = n;
            }
        }
    }
    return m;
}

/* Elements per chunk of step_nodes (at least a largest star), and how
   many elements ahead its shared writes prefetch their sums. */
#define STEP_CHUNK 16384
#define STEP_AHEAD 8

/* step_nodes' scratch, one chunk's elements: allocated once per
   relaxation (never per step, node or element), bounded by the chunk. */
typedef struct step_scratch {
    int ready;       /* allocated (step_nodes' first call)          */
    int32_t cap;     /* entries, 0: none (star by star, as before) */
    int32_t *el;     /* the chunk's elements                       */
    double *q;       /* their trial qualities                      */
    uint64_t *d;     /* their fixed-point differences (q_mean stage) */
    int32_t (*id)[12]; /* their edge ids where d != 0 (3-D)        */
} step_scratch;

static void step_scratch_init(const getme_run *run, step_scratch *sc)
{
    int32_t cap = run->ws->max_star > STEP_CHUNK ? run->ws->max_star
                                                  : STEP_CHUNK;
    sc->el = getme__malloc((size_t)cap * sizeof *sc->el);
    sc->q = getme__malloc((size_t)cap * sizeof *sc->q);
    sc->d = getme__malloc((size_t)cap * sizeof *sc->d);
    sc->id = getme__malloc((size_t)cap * sizeof *sc->id);
    sc->cap = sc->el && sc->q && sc->d && sc->id ? cap : 0;
    sc->ready = 1;
}

static void step_scratch_free(step_scratch *sc)
{
    free(sc->el), free(sc->q), free(sc->d), free(sc->id);
}

/* trial_quality of the n <= GETME_LANES elements elems[0..n) into out,
   through the lane kernel as trial_batch (the same bits), without
   writing to run: batches can run in parallel. */
static void trial_values(const getme_run *run, const int32_t *elems,
                         int32_t n, double *out)
{
    const getme_ws *ws = run->ws;
    int t = getme__ws_type(ws, elems[0]);
    int same = 1;
    for (int32_t l = 1; l < n; l++)
        same &= elems[l] >= ws->tstart[t] && elems[l] < ws->tstart[t + 1];
    if (same) {
        double x[3 * GETME_MAX_NV][GETME_LANES], q[GETME_LANES];
        const int32_t *c[GETME_LANES];
        for (int l = 0; l < GETME_LANES; l++)
            c[l] = getme__ws_nodes(ws, t, elems[l < n ? l : 0]);
        getme__gather_lanes(ws->x, c, getme__nv[t], x);
        if (getme__quality_lanes(t, (const double(*)[GETME_LANES])x, q)) {
            for (int32_t l = 0; l < n; l++)
                out[l] = trial_check(run, elems[l], t, q[l]);
            return;
        }
    }
    for (int32_t l = 0; l < n; l++)
        out[l] = trial_quality(run, elems[l]);
}

/* set_q of the chunk's n elements sc->el: their trial qualities in lane
   batches and, in the q_mean stage, their sums' differences and edge ids,
   in parallel (each element writes only its own entries); then the
   shared writes (run->q, S_v, S_e) on one thread, in chunk order, with
   the entries a few elements ahead prefetched.  The sums are exact
   integers, so this is set_q's result element by element. */
static void step_chunk(getme_run *run, step_scratch *sc, int32_t n)
{
    const getme_ws *ws = run->ws;
    getme_adj *adj = run->live;
    const int32_t *el = sc->el;
    int32_t nbatch = (n + GETME_LANES - 1) / GETME_LANES;
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    if (n >= STEP_CHUNK / 2)
    for (int32_t j = 0; j < nbatch; j++) {
        int32_t k0 = j * GETME_LANES;
        int32_t k1 = n - k0 < GETME_LANES ? n : k0 + GETME_LANES;
        trial_values(run, el + k0, k1 - k0, sc->q + k0);
        for (int32_t k = k0; k < k1; k++) {
            int32_t e = el[k];
            int t = getme__ws_type(ws, e);
            uint64_t d = 0;
            if (adj)
                d = (uint64_t)getme__fx64(sc->q[k], adj->qscale) -
                    (uint64_t)getme__fx64(run->q[e], adj->qscale);
            sc->d[k] = d;
            if (d && ws->dim == 3)
                getme__adj_edge_ids(adj, getme__ws_nodes(ws, t, e), t,
                                    getme__adj_slots(adj, ws, t, e),
                                    sc->id[k]);
        }
    }
    for (int32_t k = 0; k < n; k++) {
        int32_t e = el[k];
        int t = getme__ws_type(ws, e);
        if (k + STEP_AHEAD < n && sc->d[k + STEP_AHEAD]) {
            int32_t f = el[k + STEP_AHEAD];
            int tf = getme__ws_type(ws, f);
            const int32_t *c = getme__ws_nodes(ws, tf, f);
            for (int i = 0; i < getme__nv[tf]; i++)
                __builtin_prefetch(adj->nsum + c[i], 1, 3);
            for (int j = 0; ws->dim == 3 && j < getme__edges[tf].num_edges; j++)
                if (sc->id[k + STEP_AHEAD][j] >= 0)
                    __builtin_prefetch(adj->esum + sc->id[k + STEP_AHEAD][j],
                                       1, 3);
        }
        if (sc->d[k]) /* its edge ids from the parallel pass */
            getme__adj_add_ids(adj, ws, t, getme__ws_nodes(ws, t, e),
                               sc->id[k], sc->d[k]);
        run->q[e] = sc->q[k];
        run->eflag[e] &= 0x7f; /* step_nodes' mark */
    }
}

/* Step the m nodes of run->list down the table and re-evaluate the
   elements of their stars.  Each element once (the star walk met an
   element of several stepped nodes several times; the later set_q
   changed nothing), in the walk's first-occurrence order, in chunks of
   at most sc->cap (step_chunk: the qualities in parallel lane batches);
   bit 0x80 of eflag marks the chunk's elements until step_chunk is done
   with them (an element of two chunks is evaluated twice: the same
   value, a zero difference).
   perf: star by star, one element at a time on one thread, this step
   was the first iteration's serial tail (0.2 s of the full tets'
   2-thread run). */
static void step_nodes(getme_run *run, const double *R, int nR, int32_t m,
                       step_scratch *sc)
{
    const getme_ws *ws = run->ws;
    for (int32_t j = 0; j < m; j++) {
        int32_t i = run->list[j];
        /* the count getme__relax returns: every node of I_T starts the
           relaxation at index 0 (getme__place_first) */
        run->first_steps += run->ridx[i] == 0;
        /* The q_mean stage with a slot map: the p-hat is the position at
           R[0] = 1 until the first step keeps it.  If the pool cannot
           grow for it, the node goes straight back to its old position
           (R's last entry, 0, needs no p-hat): still a valid mesh. */
        if (run->save_phat && run->ridx[i] == 0 &&
            getme__save_phat(run, i) != GETME_OK)
            run->ridx[i] = (uint8_t)(nR - 2);
        run->ridx[i]++;
        place(run, i, R[run->ridx[i]]);
        run->flag[i] = 0;
    }
    if (!sc->ready)
        step_scratch_init(run, sc);
    if (!sc->cap) { /* no scratch: star by star */
        for (int32_t j = 0; j < m; j++) {
            getme_star_it it = getme__star_open(ws, run->list[j]);
            for (int32_t e; getme__star_next(&it, &e);)
                set_q(run, getme__ws_type(ws, e), e, trial_quality(run, e));
        }
        return;
    }
    int32_t n = 0;
    for (int32_t j = 0; j < m; j++) {
        int32_t i = run->list[j];
        if (n + getme__star_size(ws, i) > sc->cap) {
            step_chunk(run, sc, n);
            n = 0;
        }
        getme_star_it it = getme__star_open(ws, i);
        for (int32_t e; getme__star_next(&it, &e);)
            if (!(run->eflag[e] & 0x80)) {
                run->eflag[e] |= 0x80;
                sc->el[n++] = e;
            }
    }
    step_chunk(run, sc, n);
}

/* Distributed: every part steps while any part has an invalid element, and
   a node steps when any copy of it has an invalid element (the same steps
   as one process takes, so the same bits).  Each round counts over the
   whole list: the incremental list of steps_local would need the other
   parts' lists too. */
static void steps_dist(getme_run *run, const double *R, int nR)
{
    step_scratch sc;
    memset(&sc, 0, sizeof sc); /* allocated by the first step */
    while (getme__dist_any(run, count_invalid(run) > 0)) {
        nodes_to_step(run, nR, NULL, 0);
        int32_t m = getme__dist_step_list(run, nR);
        if (!getme__dist_any(run, m > 0))
            break; /* unreachable for a valid input, see getme__relax */
        step_nodes(run, R, nR, m, &sc);
    }
    step_scratch_free(&sc);
}

/* One process: the invalid elements are listed once, then each step of
   the table re-checks only them and the stars it re-evaluated. */
static void steps_local(getme_run *run, const double *R, int nR,
                        int32_t invalid)
{
    const getme_ws *ws = run->ws;
    int64_t cap = 0;
    int32_t *bad = NULL, *next = NULL;
    int32_t nbad = invalid ? list_invalid(run, &bad, &cap, invalid) : 0;
    int64_t cap_next = cap;
    step_scratch sc;
    memset(&sc, 0, sizeof sc); /* allocated by the first step */
    if (nbad > 0 && !(next = getme__malloc((size_t)cap * sizeof *next)))
        nbad = -1;
    while (nbad != 0) {
        /* Out of memory for the lists: the whole list is the candidate
           set (slower, same result). */
        int32_t m = nbad > 0 ? nodes_to_step(run, nR, bad, nbad)
                             : nodes_to_step(run, nR, NULL, 0);
        if (m == 0)
            break; /* unreachable for a valid input, see above */
        step_nodes(run, R, nR, m, &sc);
        if (nbad < 0) {
            nbad = count_invalid(run) > 0 ? -1 : 0;
            continue;
        }
        /* Still invalid: some of the old ones, and elements of the stars
           just re-evaluated (no other element changed). */
        int32_t n = 0;
        int fail = 0;
        for (int32_t k = 0; k < nbad; k++)
            fail |= keep_if_invalid(run, bad[k], &next, &n, &cap_next);
        for (int32_t j = 0; j < m; j++) {
            getme_star_it it = getme__star_open(ws, run->list[j]);
            for (int32_t e; getme__star_next(&it, &e);)
                fail |= keep_if_invalid(run, e, &next, &n, &cap_next);
        }
        for (int32_t k = 0; k < n; k++)
            run->eflag[next[k]] &= 0x7f;
        int32_t *tmp = bad;
        int64_t tcap = cap;
        bad = next, cap = cap_next;
        next = tmp, cap_next = tcap;
        nbad = fail ? (count_invalid(run) > 0 ? -1 : 0) : n;
    }
    free(bad);
    free(next);
    step_scratch_free(&sc);
}

int32_t getme__relax(getme_run *run, const double *R, int nR)
{
    getme_ws *ws = run->ws;
    double *q = run->q;
    const int32_t *elems = run->elems;
    const int32_t nn = getme__run_nodes_end(run), ne = run->num_elems;
    int nt = ws->nt;
    int32_t invalid; /* elements of the list invalid after the first pass */

    if (!run->placed) {
#pragma omp parallel for schedule(static) num_threads(nt) if (nn > GETME_PAR_MIN)
        for (int32_t k = 0; k < nn; k++) {
            int32_t i = getme__run_node(run, k);
            if (i < 0)
                continue;
            double ph[3];
            memcpy(ph, getme__phat(run, i), sizeof ph);
            getme__place_first(ws->x, getme__xold(run, i), run->ridx, i,
                               R[0], ph);
        }
    }
    run->placed = 0;
    /* The q_mean stage's first pass checks every element at these
       coordinates: the curved elements' dependent nodes placed once (not
       for the q*min stage's short lists: the table is every node's) */
    if (run->ho_tab && run->live) {
        getme__ho_table(ws, ws->x, run->ho_tab);
        run->ho_tab_on = 1;
    }
    if (run->live) { /* the q_mean stage: the list is every free element */
        invalid = (int32_t)getme__blocks_run(&run->adj->blk, ws,
                                             trial_block_any, run);
    } else {
        int32_t nbatch = ne / GETME_LANES;
#pragma omp parallel for schedule(static) num_threads(nt) if (ne > GETME_PAR_MIN)
        for (int32_t j = 0; j < nbatch; j++)
            trial_batch(getme__ws_type(ws, elems[j * GETME_LANES]), run,
                        elems + j * GETME_LANES, GETME_LANES, NULL);
        for (int32_t k = nbatch * GETME_LANES; k < ne; k++)
            q[elems[k]] = trial_quality(run, elems[k]);
        invalid = run->comm ? 0 : count_invalid(run);
    }
    run->ho_tab_on = 0; /* the steps below move nodes */

    /* Step the nodes of invalid elements down the table until none is
       invalid.  Only elements around a stepped node change, so only they
       are re-evaluated.  An invalid element always has a node that can
       still step: with all its moving nodes at R's last entry 0 it would
       be back at its old, valid shape. */
    run->first_steps = 0;
    if (run->comm)
        steps_dist(run, R, nR);
    else
        steps_local(run, R, nR, invalid);
    /* One process: the nodes beyond the table's first entry are those
       step_nodes stepped for the first time, counted as it went (a pass
       over every node of I_T per iteration was 0.16 s of the full hexes'
       stage 1 on one thread); test builds count both ways. */
    int32_t relaxed = run->first_steps;
#ifndef GETME_CHECK_SUMS
    if (!run->comm)
        return relaxed;
#endif
    int32_t scan = 0;
#pragma omp parallel for schedule(static) num_threads(nt) \
    reduction(+ : scan) if (nn > GETME_PAR_MIN)
    for (int32_t k = 0; k < nn; k++) {
        int32_t i = getme__run_node(run, k);
        scan += i >= 0 && run->ridx[i] > 0;
    }
    if (!run->comm && scan != relaxed)
        return -1; /* test builds only: the two counts differ */
    return scan;
}
