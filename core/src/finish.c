/*
 * finish.c -- the finishing step after GETMe adaptive's q*_min stage
 * (params.finish; docs/method.md, "The finishing step").
 *
 * Why it exists: the q*_min stage moves nodes by weighted averaging and
 * Eq. 10 relaxation.  Where every averaged move of an element's nodes
 * inverts a neighbour (a flattened ring of tets around an edge, a hex whose
 * neighbours have one collapsed corner), the relaxation resets those nodes
 * in every iteration, and the stage oscillates or stalls while a small,
 * well-chosen move would still raise the worst element.  The finisher
 * makes exactly such moves, in the spirit of GETMe sequential:
 *
 *   a pass takes the free elements below the quality at position
 *   finish_fraction (at least 64), worst first; for each one still below
 *   that bound it climbs every free node on its own (local max-min over
 *   the node's star, patch.h), and when that did not raise the element, it
 *   moves all its free nodes together: first toward the element's GETMe
 *   transform with relaxation 1/2 .. 1/64, then along the max-min ascent
 *   direction of the union of their stars.
 *
 * A move is kept only when the minimum quality of the elements it touches
 * strictly rises, so q*_min never decreases and the mesh stays valid (and
 * the corner guard holds).  Passes end when one raises q*_min by no more
 * than min_tol, or after finish_max_passes.  Serial and in a fixed order:
 * the output is the same for any thread count.
 *
 * On a sub-mesh (getme_smooth_finish_sub, run->sub) the same passes run
 * with the whole mesh's values: the bound, q*_min and q_mean add the
 * constant rest of the mesh, and each pass first checks that everything
 * it can touch is inside (else GETME_ERR_INCOMPLETE).
 */
#include "patch.h"
#include "smooth_internal.h"
#include "tally.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/*
 * A memo of failed single-node climbs.  A climb that keeps no step leaves
 * everything as it was (trial moves are undone bit for bit), and whether
 * it keeps one depends only on the coordinates of the nodes of the node's
 * star, on the patch's loss, and on its budget through -min(loss * gain,
 * budget) (patch.c, trial): with the same loss, no node of the star moved
 * since, and either a budget no larger than then or every trial's
 * loss * gain below the budget then (the budget did not matter), the same
 * climb fails again, so it is skipped.  Later passes and the second sweep
 * of the next pass revisit many unchanged stars; the moves made, and so
 * the output, are exactly those without the memo.
 */
typedef struct fail_record {
    uint32_t stamp; /* moves kept before the failure */
    double loss, budget, allowed_max;
} fail_record;

/* A node's entry: only nodes that moved or failed have one, a few per
   listed element, so an open-addressing table instead of arrays over all
   nodes (the step runs when the mesh's memory is at its peak). */
typedef struct memo_slot {
    int32_t node;   /* -1: empty */
    uint32_t moved; /* stamp of its last kept move, 0: none */
    uint32_t rec;   /* 1 + its failure's index in rec, 0: none */
} memo_slot;

typedef struct climb_memo {
    uint32_t stamp; /* moves kept so far */
    memo_slot *slot;
    uint32_t cap, used; /* cap a power of two, used <= cap / 2 */
    fail_record *rec;
    uint32_t num_rec, cap_rec;
} climb_memo;

static void memo_free(climb_memo *m)
{
    free(m->slot);
    free(m->rec);
}

static int memo_alloc(climb_memo *m, uint32_t cap)
{
    m->slot = malloc((size_t)cap * sizeof *m->slot);
    if (!m->slot)
        return -1;
    for (uint32_t i = 0; i < cap; i++)
        m->slot[i] = (memo_slot){-1, 0, 0};
    m->cap = cap, m->used = 0;
    return 0;
}

/* 0, or -1 without memory (then no memo is used). */
static int memo_init(climb_memo *m)
{
    memset(m, 0, sizeof *m);
    return memo_alloc(m, 4096);
}

/* The entry of node, created if add (NULL if absent, or no memory). */
static memo_slot *memo_at(climb_memo *m, int32_t node, int add)
{
    uint32_t mask = m->cap - 1, i = ((uint32_t)node * 2654435761u) & mask;
    while (m->slot[i].node >= 0 && m->slot[i].node != node)
        i = (i + 1) & mask;
    if (m->slot[i].node == node || !add)
        return m->slot[i].node == node ? &m->slot[i] : NULL;
    if (2 * (m->used + 1) > m->cap) { /* grow: rehash into twice the room */
        climb_memo old = *m;
        if (memo_alloc(m, 2 * old.cap) != 0) {
            *m = old;
            return NULL;
        }
        for (uint32_t k = 0; k < old.cap; k++)
            if (old.slot[k].node >= 0)
                *memo_at(m, old.slot[k].node, 1) = old.slot[k];
        free(old.slot);
        return memo_at(m, node, 1);
    }
    m->used++;
    m->slot[i] = (memo_slot){node, 0, 0};
    return &m->slot[i];
}

/* A kept move of the k nodes mv; 0, or -1 without memory (then the memo
   must no longer be used: it would miss this move). */
static int memo_moved(climb_memo *m, const int32_t *mv, int k)
{
    m->stamp++;
    for (int j = 0; j < k; j++) {
        memo_slot *s = memo_at(m, mv[j], 1);
        if (!s)
            return -1;
        s->moved = m->stamp;
    }
    return 0;
}

static void memo_failed(climb_memo *m, const getme_patch *p, int32_t node)
{
    memo_slot *s = memo_at(m, node, 1);
    if (!s)
        return; /* not remembered: it is climbed again */
    if (!s->rec) {
        if (m->num_rec == m->cap_rec) {
            uint32_t cap = m->cap_rec ? 2 * m->cap_rec : 1024;
            fail_record *r = realloc(m->rec, cap * sizeof *r);
            if (!r)
                return;
            m->rec = r, m->cap_rec = cap;
        }
        s->rec = ++m->num_rec;
    }
    m->rec[s->rec - 1] =
        (fail_record){m->stamp, p->loss, p->budget, p->allowed_max};
}

/* 1 if climbing node alone is known to keep no step (see above). */
static int memo_fails(climb_memo *m, const getme_ws *ws, const getme_patch *p,
                      int32_t node)
{
    const memo_slot *s = m ? memo_at(m, node, 0) : NULL;
    if (!s || !s->rec)
        return 0;
    const fail_record *r = &m->rec[s->rec - 1];
    if (r->loss != p->loss ||
        !(p->budget <= r->budget || r->allowed_max <= r->budget))
        return 0;
    for (int64_t j = ws->star_ptr[node]; j < ws->star_ptr[node + 1]; j++) {
        int32_t e = ws->star[j];
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int i = 0; i < getme__nv[t]; i++) {
            const memo_slot *o = memo_at(m, c[i], 0);
            if (o && o->moved > r->stamp)
                return 0;
        }
    }
    return 1;
}

/* Drop the memo (for good) if c: it missed a move. */
static void forget_if(climb_memo **memo, int c)
{
    if (c) {
        memo_free(*memo);
        *memo = NULL;
    }
}

/*
 * The pass's candidates without a sweep per pass.  A pass works on the few
 * thousand free elements below the quality at position finish_fraction,
 * but finding that bound (getme__threshold), the list and the summary took
 * about seven sweeps over every element per pass (4M tets: ~25 ms on two
 * threads, each pass).  Instead one sweep at the start keeps a pool: every
 * free element with q <= top, top the quality at four times that position,
 * and every element a kept move brings to q <= top later (store()).  So
 * every free element outside the pool is above top, and as long as more
 * than k + 1 pool elements are at or below it, the k-th smallest quality
 * of the whole mesh is the k-th smallest of theirs, the pass's list is
 * theirs below the bound, and q*_min is their minimum, all exactly what
 * the sweeps give (GETME_CHECK_SUMS builds compare).  Otherwise the pool
 * is built again.  q_mean comes from the exact running sum (tally.h).
 * Membership is bit POOLED of run->eflag (fill() uses bit 0).
 */
#define POOLED 0x40

typedef struct pool {
    int32_t *e;
    int32_t n;
    int64_t cap;
    double top;   /* every free element outside e has q > top */
    int lost;     /* an element could not be added: build again */
    double *v;    /* scratch: the pool's qualities */
    int64_t cap_v;
    getme_tally tally;
} pool;

static void pool_clear(getme_run *run, pool *pl)
{
    for (int32_t k = 0; k < pl->n; k++)
        run->eflag[pl->e[k]] &= (uint8_t)~POOLED;
    pl->n = 0;
}

static void pool_free(getme_run *run, pool *pl)
{
    pool_clear(run, pl);
    free(pl->e);
    free(pl->v);
}

/* Element e's quality became new (from old): the sum follows, and e joins
   the pool if it is now at or below top. */
static void pool_change(getme_run *run, pool *pl, int32_t e, double old,
                        double new)
{
    getme__tally_change(&pl->tally, old, new);
    if (new <= pl->top && !(run->eflag[e] & POOLED) && run->ws->free_elem[e]) {
        if (getme__push_i32(&pl->e, &pl->n, &pl->cap, e))
            pl->lost = 1;
        else
            run->eflag[e] |= POOLED;
    }
}

/* The pool of the free elements with q <= top, top at position
   4 fraction n (at least 4 min_count - 1).  GETME_OK or GETME_ERR_NOMEM. */
static getme_status pool_build(getme_run *run, pool *pl, double fraction,
                               int32_t min_count)
{
    const getme_ws *ws = run->ws;
    pool_clear(run, pl);
    pl->lost = 0;
    pl->top = getme__threshold(run, fmin(1.0, 4.0 * fraction), 4 * min_count);
    if (pl->top < 0.0)
        return GETME_ERR_NOMEM;
    for (int32_t e = 0; e < ws->ne; e++)
        if (ws->free_elem[e] && run->q[e] <= pl->top) {
            if (getme__push_i32(&pl->e, &pl->n, &pl->cap, e))
                return GETME_ERR_NOMEM;
            run->eflag[e] |= POOLED;
        }
    return GETME_OK;
}

/* The qualities of the pool at or below top into pl->v; their count, or
   -1 if out of memory. */
static int32_t pool_values(pool *pl, const double *q)
{
    if (pl->n > pl->cap_v) {
        double *v = realloc(pl->v, (size_t)pl->n * 2 * sizeof *v);
        if (!v)
            return -1;
        pl->v = v, pl->cap_v = 2 * (int64_t)pl->n;
    }
    int32_t m = 0;
    for (int32_t k = 0; k < pl->n; k++)
        if (q[pl->e[k]] <= pl->top)
            pl->v[m++] = q[pl->e[k]];
    return m;
}

/* getme__threshold(run, fraction, min_count) from the pool (built again
   when it no longer holds the position); -1 if out of memory. */
static double pool_bound(getme_run *run, pool *pl, double fraction,
                         int32_t min_count)
{
    int64_t n = run->ws->num_free_elem;
    if (n == 0)
        return 0.0;
    int64_t k = getme__quantile_pos(n, fraction, min_count);
    for (int again = 0; again < 2; again++) {
        if (pl->lost && pool_build(run, pl, fraction, min_count) != GETME_OK)
            return -1.0;
        int32_t m = pool_values(pl, run->q);
        if (m < 0)
            return -1.0;
        if (m > k)
            return getme__select_kth(pl->v, m, (int32_t)k);
        pl->lost = 1; /* too few left at or below top */
    }
    return getme__threshold(run, fraction, min_count); /* not reached */
}

/* The pass's elements from the pool: free ones with q <= bound (<= top),
   worst first; NULL if out of memory. */
static getme_ranked *pool_list(const getme_run *run, const pool *pl,
                               double bound, int32_t *count)
{
    getme_ranked *r = malloc((size_t)(pl->n ? pl->n : 1) * sizeof *r);
    if (!r)
        return NULL;
    int32_t n = 0;
    for (int32_t k = 0; k < pl->n; k++) {
        int32_t e = pl->e[k];
        if (run->q[e] <= bound)
            r[n].q = run->q[e], r[n++].e = e;
    }
    qsort(r, (size_t)n, sizeof *r, getme__cmp_ranked);
    *count = n;
    return r;
}

/* q_mean and q*_min from the pool (a sweep for q*_min only if no pool
   element is at or below top). */
static void pool_summary(getme_run *run, const pool *pl, double *q_mean,
                         double *q_min)
{
    const getme_ws *ws = run->ws;
    *q_mean = getme__tally_mean(&pl->tally, ws->ne);
    /* getme__ws_summary's minimum starts at 1.0 too: when the capped
       minimum is above top, so is every pool element's */
    double m = getme__tally_min(run->q, pl->e, pl->n);
    if (m <= pl->top) {
        *q_min = m;
    } else {
        double mean;
        getme__ws_summary(ws, run->q, &mean, q_min, NULL);
    }
}

/* Put the elements around the k nodes mv into the patch (each once). */
static getme_status fill(getme_run *run, getme_patch *p, const int32_t *mv,
                         int k)
{
    const getme_ws *ws = run->ws;
    getme__patch_clear(p);
    getme_status st = GETME_OK;
    for (int j = 0; j < k && st == GETME_OK; j++)
        for (int64_t s = ws->star_ptr[mv[j]];
             s < ws->star_ptr[mv[j] + 1] && st == GETME_OK; s++) {
            int32_t e = ws->star[s];
            if (run->eflag[e] & 1)
                continue;
            run->eflag[e] |= 1;
            int t = getme__ws_type(ws, e);
            st = getme__patch_add(p, t, getme__ws_nodes(ws, t, e), e);
        }
    for (int32_t i = 0; i < p->n; i++)
        run->eflag[p->id[i]] &= (uint8_t)~1;
    /* run->q is current (the smoothing keeps it so, store() too): no need
       to evaluate the elements again */
    getme__patch_eval_known(p, run->q);
#ifdef GETME_CHECK_SUMS
    double *q = malloc((size_t)(p->n ? p->n : 1) * sizeof *q);
    if (!q)
        return GETME_ERR_NOMEM;
    memcpy(q, p->q, (size_t)p->n * sizeof *q);
    getme__patch_eval(p);
    if (st == GETME_OK && memcmp(q, p->q, (size_t)p->n * sizeof *q) != 0)
        st = GETME_ERR_STATE;
    free(q);
#endif
    return st;
}

/* Copy the patch's qualities back to run->q (pl: the pool follows, or
   NULL). */
static void store(getme_run *run, const getme_patch *p, pool *pl)
{
    for (int32_t i = 0; i < p->n; i++) {
        if (pl)
            pool_change(run, pl, p->id[i], run->q[p->id[i]], p->q[i]);
        run->q[p->id[i]] = p->q[i];
    }
}

/* Work on element e (*memo: failed climbs, or NULL). */
static getme_status improve(getme_run *run, getme_patch *p,
                            climb_memo **memo, pool *pl, int32_t e)
{
    const getme_ws *ws = run->ws;
    int t = getme__ws_type(ws, e);
    const int32_t *c = getme__ws_nodes(ws, t, e);
    int32_t mv[GETME_PATCH_MAX_MOVE];
    int k = 0;
    for (int i = 0; i < getme__nv[t]; i++)
        if (!ws->fixed[c[i]])
            mv[k++] = c[i];
    double q0 = run->q[e];
    getme_status st;
    for (int j = 0; j < k; j++) {
        if (memo_fails(*memo, ws, p, mv[j]))
            continue;
        if ((st = fill(run, p, &mv[j], 1)) != GETME_OK)
            return st;
        p->allowed_max = -INFINITY;
        if (getme__patch_climb(p, &mv[j], 1, 8, 1)) {
            store(run, p, pl);
            forget_if(memo, *memo && memo_moved(*memo, &mv[j], 1) != 0);
        } else if (*memo) {
            memo_failed(*memo, p, mv[j]);
        }
    }
    if (k >= 2 && !(run->q[e] > q0)) {
        if ((st = fill(run, p, mv, k)) != GETME_OK)
            return st;
        double x[3 * GETME_MAX_NV], y[3 * GETME_MAX_NV];
        double tg[3 * GETME_PATCH_MAX_MOVE];
        getme__ws_gather(ws, ws->x, t, e, x);
        getme__transform(t, x, run->params->sigma, y);
        for (int j = 0, m = 0; j < getme__nv[t]; j++)
            if (!ws->fixed[c[j]]) {
                memcpy(tg + 3 * m, y + 3 * j, 3 * sizeof *tg);
                m++;
            }
        int moved = getme__patch_toward(p, mv, k, tg);
        moved += getme__patch_climb(p, mv, k, 4, 1);
        if (moved) {
            store(run, p, pl);
            forget_if(memo, *memo && memo_moved(*memo, mv, k) != 0);
        }
    }
    return GETME_OK;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The pass bound on a sub-mesh: getme__threshold's quantile of the whole
   mesh's free elements.  It is the sub-mesh's own value at the whole
   mesh's position k when that lies below every free element outside
   (those are then all above it, so the k + 1 lowest are inside);
   *incomplete is set when not.  -1 if out of memory. */
static double sub_bound(const getme_run *run, double fraction,
                        int32_t min_count, int *incomplete)
{
    const getme_ws *ws = run->ws;
    const getme_finish_rest *rest = run->sub->rest;
    int64_t n = ws->num_free_elem + rest->num_free_elements;
    if (n == 0)
        return 0.0;
    int64_t k = getme__quantile_pos(n, fraction, min_count);
    if (k >= ws->num_free_elem) {
        *incomplete = 1;
        return 0.0;
    }
    double *v = malloc((size_t)ws->num_free_elem * sizeof *v);
    if (!v)
        return -1.0;
    int32_t m = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (ws->free_elem[e])
            v[m++] = run->q[e];
    qsort(v, (size_t)m, sizeof *v, cmp_double);
    double bound = v[k];
    free(v);
    if (rest->num_free_elements > 0 && !(bound < rest->q_min_free))
        *incomplete = 1;
    return bound;
}

/* On a sub-mesh: 1 if every free node of every listed element has its
   whole star inside (improve() moves them and fills their stars). */
static int stars_inside(const getme_run *run, const getme_ranked *r, int32_t n)
{
    const getme_ws *ws = run->ws;
    for (int32_t i = 0; i < n; i++) {
        int t = getme__ws_type(ws, r[i].e);
        const int32_t *c = getme__ws_nodes(ws, t, r[i].e);
        for (int j = 0; j < getme__nv[t]; j++)
            if (!ws->fixed[c[j]] && !run->sub->complete[c[j]])
                return 0;
    }
    return 1;
}

void getme__finish_summary(const getme_run *run, double *q_mean,
                           double *q_min_star, double *q_min)
{
    const getme_ws *ws = run->ws;
    if (!run->sub) {
        getme__ws_summary(ws, run->q, q_mean, q_min_star, q_min);
        return;
    }
    /* the exact sum of getme__ws_summary (exact.h), plus the rest's */
    const getme_finish_rest *rest = run->sub->rest;
    getme_ufx s = (getme_ufx)rest->q_sum[1] << 64 | rest->q_sum[0];
    double mn = rest->q_min, mns = rest->q_min_free;
    for (int32_t e = 0; e < ws->ne; e++) {
        double v = run->q[e];
        s += (getme_ufx)getme__fx_q(v);
        mn = v < mn ? v : mn;
        if (ws->free_elem[e])
            mns = v < mns ? v : mns;
    }
    int64_t n = ws->ne + rest->num_elements;
    *q_mean = n ? getme__fx_double((getme_fx)s, GETME_FX_QINV) / (double)n
                : 1.0;
    *q_min_star = mns;
    if (q_min)
        *q_min = mn;
}

/* A pass's progress line; on a sub-mesh it is kept for later (the step
   may still turn out to need a bigger sub-mesh). */
static int report(getme_run *run, int pass, double q_min, double q_mean,
                  double bound, int32_t n, int32_t raised)
{
    getme_finish_sub *sub = run->sub;
    if (!sub)
        return getme__report(run, pass, GETME_STAGE_FINISH,
                             run->result->cycles_min, q_min, q_mean, bound,
                             n, raised);
    if (sub->num_log < sub->cap_log) {
        getme_progress *g = &sub->log[sub->num_log++];
        g->iteration = pass;
        g->stage = GETME_STAGE_FINISH;
        g->cycle = run->result->cycles_min;
        g->q_min_star = q_min;
        g->q_mean = q_mean;
        g->threshold = bound;
        g->num_transformed = n;
        g->num_relaxed = raised;
        g->elapsed = omp_get_wtime() - run->t0;
    }
    return 0;
}

/* The pass's elements: free ones with q <= bound, worst first. */
static getme_ranked *pass_list(const getme_run *run, double bound,
                               int32_t *count)
{
    const getme_ws *ws = run->ws;
    int32_t n = 0;
#pragma omp parallel for schedule(static) num_threads(ws->nt) reduction(+ : n)
    for (int32_t e = 0; e < ws->ne; e++)
        n += ws->free_elem[e] && run->q[e] <= bound;
    getme_ranked *r = malloc((size_t)(n ? n : 1) * sizeof *r);
    if (!r)
        return NULL;
    n = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (ws->free_elem[e] && run->q[e] <= bound)
            r[n].q = run->q[e], r[n++].e = e;
    qsort(r, (size_t)n, sizeof *r, getme__cmp_ranked);
    *count = n;
    return r;
}

#ifdef GETME_CHECK_SUMS
/* Test builds: is the pass's bound, list and summary from the pool what
   the sweeps give? */
static int pool_checks(getme_run *run, double fraction, double bound,
                       const getme_ranked *list, int32_t n)
{
    int32_t m;
    int same = bound == getme__threshold(run, fraction, 64);
    getme_ranked *r = pass_list(run, bound, &m);
    same = same && r && m == n;
    for (int32_t i = 0; same && i < n; i++) /* not memcmp: padding */
        same = r[i].q == list[i].q && r[i].e == list[i].e;
    free(r);
    return same;
}

static int summary_checks(getme_run *run, double q_mean, double q_min)
{
    double m, mn;
    getme__ws_summary(run->ws, run->q, &m, &mn, NULL);
    return m == q_mean && mn == q_min;
}
#endif

/* The pass's bound and list: from the pool, or on a sub-mesh by sweeps
   (sub_bound, pass_list).  NULL if out of memory or incomplete (st). */
static getme_ranked *pass_bound_list(getme_run *run, pool *pl, double *bound,
                                     int32_t *n, getme_status *st)
{
    const getme_params *prm = run->params;
    int incomplete = 0;
    getme_ranked *list = NULL;
    *st = GETME_ERR_NOMEM;
    if (run->sub) {
        *bound = sub_bound(run, prm->finish_fraction, 64, &incomplete);
        if (incomplete) {
            run->sub->need = *bound;
            *st = GETME_ERR_INCOMPLETE;
            return NULL;
        }
        list = *bound < 0.0 ? NULL : pass_list(run, *bound, n);
        if (list && !stars_inside(run, list, *n)) {
            run->sub->need = *bound;
            free(list);
            *st = GETME_ERR_INCOMPLETE;
            return NULL;
        }
    } else {
        *bound = pool_bound(run, pl, prm->finish_fraction, 64);
        list = *bound < 0.0 ? NULL : pool_list(run, pl, *bound, n);
#ifdef GETME_CHECK_SUMS
        if (list && !pool_checks(run, prm->finish_fraction, *bound, list, *n)) {
            free(list);
            *st = GETME_ERR_STATE;
            return NULL;
        }
#endif
    }
    if (list)
        *st = GETME_OK;
    return list;
}

/* q_mean and q*_min after a pass (from the pool, or on a sub-mesh by a
   sweep); GETME_OK or, in GETME_CHECK_SUMS builds, GETME_ERR_STATE. */
static getme_status pass_summary(getme_run *run, const pool *pl,
                                 double *q_mean, double *q_min)
{
    if (run->sub) {
        getme__finish_summary(run, q_mean, q_min, NULL);
        return GETME_OK;
    }
    pool_summary(run, pl, q_mean, q_min);
#ifdef GETME_CHECK_SUMS
    if (!summary_checks(run, *q_mean, *q_min))
        return GETME_ERR_STATE;
#endif
    return GETME_OK;
}

getme_status getme__finish(getme_run *run)
{
    getme_ws *ws = run->ws;
    const getme_params *prm = run->params;
    getme_result *res = run->result;
    getme_patch p;
    pool pl;
    memset(&pl, 0, sizeof pl);
    if (getme__patch_init(&p, 8 * ws->max_star) != GETME_OK)
        return GETME_ERR_NOMEM;
    p.x = ws->x;
    p.ws = ws;
    p.guard = run->guard;
    p.floor = run->corner_floor;
    memcpy(p.skip_q, run->guard_skip_q, sizeof p.skip_q);
    /* no memo for second-order elements: their validity also reads the
       mid-edge nodes */
    climb_memo memo_store, *memo = NULL;
    if (!ws->ho && memo_init(&memo_store) == 0)
        memo = &memo_store;
    getme_status st = GETME_OK;
    if (!run->sub) {
        getme__tally_start(&pl.tally, ws, run->q);
        st = pool_build(run, &pl, prm->finish_fraction, 64);
    }
    double q_mean, q_min;
    if (st == GETME_OK)
        st = pass_summary(run, &pl, &q_mean, &q_min);
    for (int pass = 1; pass <= prm->finish_max_passes && st == GETME_OK;
         pass++) {
        double bound;
        int32_t n, raised = 0;
        getme_ranked *list = pass_bound_list(run, &pl, &bound, &n, &st);
        if (!list)
            break;
        /* Two sweeps: the first takes only moves that lose no total
           quality (and so earns budget), the second may spend it. */
        pool *track = run->sub ? NULL : &pl;
        for (int sweep = 0; sweep < 2; sweep++) {
            p.loss = sweep ? GETME_PATCH_LOSS : 0.0;
            for (int32_t i = 0; i < n && st == GETME_OK; i++)
                if (run->q[list[i].e] <= bound)
                    st = improve(run, &p, &memo, track, list[i].e);
        }
        /* Raised over the pass, whichever sweep did it (the list keeps
           each element's quality at the pass's start). */
        for (int32_t i = 0; i < n; i++)
            raised += run->q[list[i].e] > list[i].q;
        free(list);
        double prev = q_min;
        if (st != GETME_OK ||
            (st = pass_summary(run, &pl, &q_mean, &q_min)) != GETME_OK)
            break;
        res->passes_finish = pass;
        res->moved_finish += raised;
        if (report(run, pass, q_min, q_mean, bound, n, raised)) {
            res->stop_reason = GETME_STOP_CANCELLED;
            st = GETME_ERR_CANCELLED;
            break;
        }
        if (!(q_min > prev + prm->min_tol))
            break;
    }
    pool_free(run, &pl);
    getme__patch_free(&p);
    if (memo)
        memo_free(memo);
    return st;
}
