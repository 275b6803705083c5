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
#include "finish_levels.h"
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
 * the output, are exactly those without the memo.  A node keeps one
 * failure per loss (the first sweep's 0 and the second's
 * GETME_PATCH_LOSS): with one record, each sweep overwrote the other's,
 * and the next pass's same sweep never found its own.
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
    uint32_t rec[2]; /* per loss (loss_slot): 1 + its failure's index in
                        rec, 0: none */
} memo_slot;

/* Which of a node's two records a climb with this loss uses. */
static int loss_slot(double loss) { return loss != 0.0; }

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
    m->slot = getme__malloc((size_t)cap * sizeof *m->slot);
    if (!m->slot)
        return -1;
    for (uint32_t i = 0; i < cap; i++)
        m->slot[i] = (memo_slot){-1, 0, {0, 0}};
    m->cap = cap, m->used = 0;
    return 0;
}

/* 0, or -1 without memory (then no memo is used). */
static int memo_init(climb_memo *m)
{
    memset(m, 0, sizeof *m);
    return memo_alloc(m, 4096);
}

/* Where node's entry is, or the empty slot where it would go. */
static uint32_t memo_probe(const climb_memo *m, int32_t node)
{
    uint32_t mask = m->cap - 1, i = ((uint32_t)node * 2654435761u) & mask;
    while (m->slot[i].node >= 0 && m->slot[i].node != node)
        i = (i + 1) & mask;
    return i;
}

/* The entry of node, or NULL (read only: a levelled sweep's threads share
   the memo while no one writes it). */
static const memo_slot *memo_find(const climb_memo *m, int32_t node)
{
    const memo_slot *s = &m->slot[memo_probe(m, node)];
    return s->node == node ? s : NULL;
}

/* The entry of node, created if absent (NULL if no memory). */
static memo_slot *memo_at(climb_memo *m, int32_t node)
{
    uint32_t i = memo_probe(m, node);
    if (m->slot[i].node == node)
        return &m->slot[i];
    if (2 * (m->used + 1) > m->cap) { /* grow: rehash into twice the room */
        climb_memo old = *m;
        if (memo_alloc(m, 2 * old.cap) != 0) {
            *m = old;
            return NULL;
        }
        for (uint32_t k = 0; k < old.cap; k++)
            if (old.slot[k].node >= 0)
                *memo_at(m, old.slot[k].node) = old.slot[k];
        free(old.slot);
        return memo_at(m, node);
    }
    m->used++;
    m->slot[i] = (memo_slot){node, 0, {0, 0}};
    return &m->slot[i];
}

/* A kept move of the k nodes mv; 0, or -1 without memory (then the memo
   must no longer be used: it would miss this move). */
static int memo_moved(climb_memo *m, const int32_t *mv, int k)
{
    m->stamp++;
    for (int j = 0; j < k; j++) {
        memo_slot *s = memo_at(m, mv[j]);
        if (!s)
            return -1;
        s->moved = m->stamp;
    }
    return 0;
}

/* A failed climb of node with the patch's loss, budget and allowed_max
   (f.stamp is ignored: it failed after every move kept so far). */
static void memo_failed(climb_memo *m, int32_t node, fail_record f)
{
    memo_slot *s = memo_at(m, node);
    if (!s)
        return; /* not remembered: it is climbed again */
    uint32_t *idx = &s->rec[loss_slot(f.loss)];
    if (!*idx) {
        if (m->num_rec == m->cap_rec) {
            uint32_t cap = m->cap_rec ? 2 * m->cap_rec : 1024;
            fail_record *r = getme__realloc(m->rec, cap * sizeof *r);
            if (!r)
                return;
            m->rec = r, m->cap_rec = cap;
        }
        *idx = ++m->num_rec;
    }
    f.stamp = m->stamp;
    m->rec[*idx - 1] = f;
}

/* 1 if climbing node alone is known to keep no step (see above); the nl
   nodes local moved since the memo last heard of moves (a levelled sweep's
   element, whose moves reach the memo after its level) count as moved. */
static int memo_fails(const climb_memo *m, const getme_ws *ws,
                      const getme_patch *p, int32_t node,
                      const int32_t *local, int nl)
{
    const memo_slot *s = m ? memo_find(m, node) : NULL;
    uint32_t idx = s ? s->rec[loss_slot(p->loss)] : 0;
    if (!idx)
        return 0;
    const fail_record *r = &m->rec[idx - 1];
    if (r->loss != p->loss ||
        !(p->budget <= r->budget || r->allowed_max <= r->budget))
        return 0;
    getme_star_it it = getme__star_open(ws, node);
    for (int32_t e; getme__star_next(&it, &e);) {
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int i = 0; i < getme__nv[t]; i++) {
            const memo_slot *o = memo_find(m, c[i]);
            if (o && o->moved > r->stamp)
                return 0;
            for (int a = 0; a < nl; a++)
                if (local[a] == c[i])
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

/* 1 if element e, whose quality became new, joins the pool (it is not
   in yet and now at or below top). */
static int pool_wants(const getme_run *run, const pool *pl, int32_t e,
                      double new)
{
    return new <= pl->top && !(run->eflag[e] & POOLED) &&
           run->ws->free_elem[e];
}

/* e joins the pool (or the pool is marked lost). */
static void pool_add(getme_run *run, pool *pl, int32_t e)
{
    if (getme__push_i32(&pl->e, &pl->n, &pl->cap, e))
        pl->lost = 1;
    else
        run->eflag[e] |= POOLED;
}

/* Element e's quality became new (from old): the sum follows, and e joins
   the pool if it is now at or below top. */
static void pool_change(getme_run *run, pool *pl, int32_t e, double old,
                        double new)
{
    getme__tally_change(&pl->tally, old, new);
    if (pool_wants(run, pl, e, new))
        pool_add(run, pl, e);
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
        double *v = getme__realloc(pl->v, (size_t)pl->n * 2 * sizeof *v);
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
    getme_ranked *r = getme__malloc((size_t)(pl->n ? pl->n : 1) * sizeof *r);
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

/*
 * One thread's state.  A serial sweep (one thread, second order, a
 * sub-mesh, or a short list) uses one worker, which writes the memo and
 * the pool as it goes.  In a levelled sweep (see "Levelled sweeps" below)
 * every thread has its own, and what would be written to shared state is
 * logged instead and merged after each level: the memo's events, the
 * pool's sum (an exact integer difference) and candidates, each accepted
 * move's change of the total quality, and the coordinates needed to take
 * a sweep back.
 */
typedef struct memo_event {
    int32_t node;  /* -1: a kept move starts (the memo's stamp counts it) */
    int32_t failed; /* node's climb failed (else node moved in that move) */
    fail_record f;
} memo_event;

typedef struct undo_rec {
    int32_t node;
    double x[3]; /* its coordinates before the element's improve() */
} undo_rec;

/* Accepted moves of one improve() at most: 8 steps per single-node climb
   of up to 8 nodes, one toward move and 4 steps of the joint climb. */
#define LOG_CAP (8 * GETME_PATCH_MAX_MOVE + 8)

typedef struct worker {
    getme_patch p;
    int levelled;
    int32_t mvd[GETME_PATCH_MAX_MOVE]; /* nodes this element moved so far */
    int nmvd;
    memo_event *ev; /* levelled: memo events of this level */
    int64_t nev, cap_ev;
    int memo_lost;  /* an event could not be logged: drop the memo */
    double *cg;     /* levelled: accepted moves' changes, this sweep */
    int64_t ncg, cap_cg;
    undo_rec *un;   /* levelled, second sweep: coordinates to take back */
    int64_t nun, cap_un;
    int32_t *padd;  /* levelled: elements for the pool (repeats allowed) */
    int32_t npadd;
    int64_t cap_padd;
    int lost;       /* one could not be logged: the pool is built again */
    getme_ufx dtally; /* levelled: the pool sum's change */
    getme_status st;
    double log[LOG_CAP];
} worker;

/* Put the elements around the k nodes mv into the patch (each once), with
   their qualities from run->q if known (else evaluated). */
static getme_status fill(getme_run *run, getme_patch *p, const int32_t *mv,
                         int k, int known)
{
    const getme_ws *ws = run->ws;
    getme__patch_clear(p);
    getme_status st = GETME_OK;
    /* bit 0 of eflag: in this patch.  In a levelled sweep the patches of
       one level are disjoint (two that shared an element would conflict:
       it holds a node one of them moves and the other reads) */
    for (int j = 0; j < k && st == GETME_OK; j++) {
        getme_star_it it = getme__star_open(ws, mv[j]);
        for (int32_t e; st == GETME_OK && getme__star_next(&it, &e);) {
            if (run->eflag[e] & 1)
                continue;
            run->eflag[e] |= 1;
            int t = getme__ws_type(ws, e);
            st = getme__patch_add(p, t, getme__ws_nodes(ws, t, e), e);
        }
    }
    for (int32_t i = 0; i < p->n; i++)
        run->eflag[p->id[i]] &= (uint8_t)~1;
    if (!known) {
        getme__patch_eval(p);
        return st;
    }
    /* run->q is current (the smoothing keeps it so, store() too): no need
       to evaluate the elements again */
    getme__patch_eval_known(p, run->q);
#ifdef GETME_CHECK_SUMS
    double *q = getme__malloc((size_t)(p->n ? p->n : 1) * sizeof *q);
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
   NULL; in a levelled sweep through the worker's log). */
static void store(getme_run *run, worker *w, pool *pl)
{
    const getme_patch *p = &w->p;
    for (int32_t i = 0; i < p->n; i++) {
        int32_t e = p->id[i];
        if (pl && !w->levelled) {
            pool_change(run, pl, e, run->q[e], p->q[i]);
        } else if (pl) {
            w->dtally += getme__tally_diff(run->q[e], p->q[i]);
            if (pool_wants(run, pl, e, p->q[i]) &&
                getme__push_i32(&w->padd, &w->npadd, &w->cap_padd, e))
                w->lost = 1;
        }
        run->q[e] = p->q[i];
    }
}

/* Log one memo event (or mark the memo lost). */
static void log_event(worker *w, memo_event ev)
{
    memo_event *b = getme__room(w->ev, &w->cap_ev, w->nev + 1, sizeof *b);
    if (!b) {
        w->memo_lost = 1;
        return;
    }
    w->ev = b;
    w->ev[w->nev++] = ev;
}

/* The k nodes mv moved in a kept move. */
static void kept(worker *w, climb_memo **memo, const int32_t *mv, int k)
{
    if (!w->levelled) {
        forget_if(memo, *memo && memo_moved(*memo, mv, k) != 0);
        return;
    }
    for (int j = 0; j < k; j++) {
        int a = 0;
        while (a < w->nmvd && w->mvd[a] != mv[j])
            a++;
        if (a == w->nmvd) /* the element's free nodes: at most 8 */
            w->mvd[w->nmvd++] = mv[j];
    }
    if (!*memo)
        return;
    log_event(w, (memo_event){-1, 0, {0, 0, 0, 0}});
    for (int j = 0; j < k; j++)
        log_event(w, (memo_event){mv[j], 0, {0, 0, 0, 0}});
}

/* Climbing node alone kept no step. */
static void failed(worker *w, climb_memo *memo, int32_t node)
{
    const getme_patch *p = &w->p;
    fail_record f = {0, p->loss, p->budget, p->allowed_max};
    if (w->levelled)
        log_event(w, (memo_event){node, 1, f});
    else
        memo_failed(memo, node, f);
}

/* Work on element e (*memo: failed climbs, or NULL; in a levelled sweep
   read only). */
static getme_status improve(getme_run *run, worker *w, climb_memo **memo,
                            pool *pl, int32_t e)
{
    const getme_ws *ws = run->ws;
    getme_patch *p = &w->p;
    int t = getme__ws_type(ws, e);
    const int32_t *c = getme__ws_nodes(ws, t, e);
    int32_t mv[GETME_PATCH_MAX_MOVE];
    int k = 0;
    for (int i = 0; i < getme__nv[t]; i++)
        if (!ws->fixed[c[i]])
            mv[k++] = c[i];
    double q0 = run->q[e];
    getme_status st;
    w->nmvd = 0;
    for (int j = 0; j < k; j++) {
        if (memo_fails(*memo, ws, p, mv[j], w->mvd, w->nmvd))
            continue;
        if ((st = fill(run, p, &mv[j], 1, 1)) != GETME_OK)
            return st;
        p->allowed_max = -INFINITY;
        if (getme__patch_climb(p, &mv[j], 1, 8, 1)) {
            store(run, w, pl);
            kept(w, memo, &mv[j], 1);
        } else if (*memo) {
            failed(w, *memo, mv[j]);
        }
    }
    if (k >= 2 && !(run->q[e] > q0)) {
        if ((st = fill(run, p, mv, k, 1)) != GETME_OK)
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
            store(run, w, pl);
            kept(w, memo, mv, k);
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
    double *v = getme__malloc((size_t)ws->num_free_elem * sizeof *v);
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
    getme_ranked *r = getme__malloc((size_t)(n ? n : 1) * sizeof *r);
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

/*
 * Levelled sweeps.  A sweep worked on its list one element after the
 * other, ~50 us per element (climbs of up to 8 steps over a node's star),
 * on one thread.  Elements far apart commute, so on several threads a
 * sweep runs level by level (finish_levels.h): the elements of one level
 * share no node one of them writes, so each sees exactly the coordinates
 * and qualities the serial order gives it, whatever the other threads do.
 * What they would share is made per thread and merged after each level:
 * the pool's sum (exact integers) and candidates, and the memo (read only
 * during a level; each thread logs its moves and failures, and the nodes
 * an element moved count as moved for its own later look-ups).
 *
 * One thing is serial by nature: the budget (getme_patch.budget), the
 * total quality kept moves gained less what they spent, which carries
 * from element to element in list order.  A levelled sweep runs with an
 * unbounded budget and logs every accepted move's change.  With the
 * serial budget b a trial it accepted (change >= -allowed) is accepted
 * too exactly when change >= -b, and one it rejected is rejected either
 * way.  So replaying the changes in list order against the serial budget
 * (b += change, the serial sum's order) proves every move the serial
 * sweep makes, up to the first that the budget would have refused.  In
 * the first sweep of a pass (loss 0: only moves that lose nothing) that
 * never happens.  In the second it needs a budget smaller than one move's
 * loss (the medium tets' second pass: once).  The levels come in chunks
 * of consecutive list positions (finish_levels.h), and the replay runs
 * after each chunk; from a refused move on, the chunk is taken back
 * (coordinates restored in reverse level order, qualities evaluated
 * again, the memo told those nodes moved) and finished serially, and the
 * next chunk starts from the serial budget.  The output is the serial
 * one, bit for bit, for any thread count.
 */

/* Lists shorter than this run serially (a level costs a barrier; test
   builds level any list). */
#ifdef GETME_FINISH_TEST
#define LEVELLED_MIN 2
#else
#define LEVELLED_MIN 256
#endif

/* A levelled sweep checks the budget after every chunk of this many list
   positions, so a move the budget refuses costs at most a chunk's work
   taken back (test builds: small chunks, so tests have several). */
#ifdef GETME_FINISH_TEST
#define LEVELLED_CHUNK 97
#else
#define LEVELLED_CHUNK 256
#endif

typedef struct sweep_rec {
    int32_t worker;      /* which worker's logs hold its entries */
    int32_t ncg, nun;
    int64_t cg, un;      /* first entries */
} sweep_rec;

typedef struct sweep_ctx {
    getme_run *run;
    worker *w;
    int nw;
    climb_memo **memo;
    pool *pl;
    const getme_ranked *list;
    int32_t n;
    double bound;
    getme_levels lv;
    sweep_rec *rec;
    int64_t cap_rec;
    int marks_zero; /* run->elems zeroed for the levels' marks */
} sweep_ctx;

/* Replay a worker's memo events into the memo (merge after a level). */
static void memo_merge(climb_memo **memo, worker *w)
{
    for (int64_t i = 0; i < w->nev && *memo; i++) {
        const memo_event *ev = &w->ev[i];
        if (ev->node < 0) {
            (*memo)->stamp++;
        } else if (ev->failed) {
            memo_failed(*memo, ev->node, ev->f);
        } else {
            memo_slot *sl = memo_at(*memo, ev->node);
            forget_if(memo, !sl);
            if (sl)
                sl->moved = (*memo)->stamp;
        }
    }
    forget_if(memo, *memo && w->memo_lost);
    w->nev = 0, w->memo_lost = 0;
}

/* After a level: the workers' pool changes and memo events. */
static void merge(sweep_ctx *c)
{
    pool *pl = c->pl;
    for (int t = 0; t < c->nw; t++) {
        worker *w = &c->w[t];
        pl->tally.sum += w->dtally;
        w->dtally = 0;
        for (int32_t i = 0; i < w->npadd; i++)
            if (!(c->run->eflag[w->padd[i]] & POOLED))
                pool_add(c->run, pl, w->padd[i]);
        pl->lost |= w->lost;
        w->npadd = 0, w->lost = 0;
        memo_merge(c->memo, w);
    }
}

/* List position i in a levelled sweep, on worker w (undo: log what taking
   it back needs). */
static void process(sweep_ctx *c, worker *w, int32_t i, int undo)
{
    getme_run *run = c->run;
    const getme_ws *ws = run->ws;
    sweep_rec *r = &c->rec[i];
    int32_t e = c->list[i].e;
    r->worker = (int32_t)(w - c->w);
    r->cg = w->ncg, r->un = w->nun;
    r->ncg = r->nun = 0;
    if (w->st != GETME_OK || !(run->q[e] <= c->bound))
        return;
    int t = getme__ws_type(ws, e);
    const int32_t *cn = getme__ws_nodes(ws, t, e);
    undo_rec u[GETME_MAX_NV];
    int k = 0;
    for (int j = 0; j < getme__nv[t]; j++)
        if (!ws->fixed[cn[j]]) {
            u[k].node = cn[j];
            memcpy(u[k++].x, ws->x + 3 * (int64_t)cn[j], sizeof u[0].x);
        }
    w->p.nlog = 0;
    getme_status st = improve(run, w, c->memo, c->pl, e);
    int32_t nl = w->p.nlog;
    if (st == GETME_OK && nl > LOG_CAP)
        st = GETME_ERR_STATE; /* not reached: LOG_CAP bounds improve() */
    if (st != GETME_OK || !nl) { /* nothing kept: nothing to replay */
        w->st = st;
        return;
    }
    double *cg = getme__room(w->cg, &w->cap_cg, w->ncg + nl, sizeof *cg);
    if (cg)
        w->cg = cg;
    undo_rec *un =
        undo ? getme__room(w->un, &w->cap_un, w->nun + k, sizeof *un) : NULL;
    if (un)
        w->un = un;
    if (!cg || (undo && !un)) {
        w->st = GETME_ERR_NOMEM;
        return;
    }
    memcpy(w->cg + w->ncg, w->log, (size_t)nl * sizeof *w->cg);
    w->ncg += nl, r->ncg = nl;
    if (undo) {
        memcpy(w->un + w->nun, u, (size_t)k * sizeof *u);
        w->nun += k, r->nun = k;
    }
}

/* The serial sweep over list positions [from, to), budget *budget. */
static getme_status sweep_serial(sweep_ctx *c, int32_t from, int32_t to,
                                 double *budget)
{
    worker *w = &c->w[0];
    getme_status st = GETME_OK;
    w->levelled = 0;
    w->p.log = NULL;
    w->p.budget = *budget;
    for (int32_t i = from; i < to && st == GETME_OK; i++)
        if (c->run->q[c->list[i].e] <= c->bound)
            st = improve(c->run, w, c->memo, c->pl, c->list[i].e);
    *budget = w->p.budget;
    return st;
}

/* Worker w as a levelled sweep uses it. */
static void levelled_mode(worker *w, double loss)
{
    w->levelled = 1;
    w->p.log = w->log, w->p.cap_log = LOG_CAP;
    w->p.budget = INFINITY;
    w->p.loss = loss;
}

/* Take chunk h of the levelled sweep back from list position from on (in
   reverse level order, so each node gets the value it had before from). */
static getme_status take_back(sweep_ctx *c, int32_t h, int32_t from,
                              int32_t to)
{
    getme_run *run = c->run;
    const getme_levels *lv = &c->lv;
    for (int32_t L = lv->cfirst[h + 1] - 1; L >= lv->cfirst[h]; L--)
        for (int32_t x = lv->ptr[L]; x < lv->ptr[L + 1]; x++) {
            const sweep_rec *r = &c->rec[lv->order[x]];
            if (lv->order[x] < from)
                continue;
            for (int32_t j = 0; j < r->nun; j++) {
                const undo_rec *u = &c->w[r->worker].un[r->un + j];
                memcpy(run->ws->x + 3 * (int64_t)u->node, u->x, sizeof u->x);
            }
        }
    /* their stars' qualities at the restored coordinates (the same bits
       fill() checks run->q against), and the memo hears they moved */
    worker *w = &c->w[0];
    w->levelled = 0;
    for (int32_t i = from; i < to; i++) {
        const sweep_rec *r = &c->rec[i];
        int32_t mv[GETME_MAX_NV];
        if (!r->nun)
            continue;
        for (int32_t j = 0; j < r->nun; j++)
            mv[j] = c->w[r->worker].un[r->un + j].node;
        getme_status st = fill(run, &w->p, mv, r->nun, 0);
        if (st != GETME_OK)
            return st;
        store(run, w, c->pl);
        kept(w, c->memo, mv, r->nun);
    }
    return GETME_OK;
}

/* After chunk h of a levelled sweep: its moves replayed in list order
   against the serial budget *budget (b += change, the serial sum's
   order); from the first move it refuses on, the chunk is taken back and
   redone serially.  Then *budget is the serial budget after the chunk. */
static getme_status chunk_check(sweep_ctx *c, int32_t h, int undo,
                                double *budget)
{
    const getme_levels *lv = &c->lv;
    int32_t c0 = h * lv->chunk;
    int32_t c1 = c0 + lv->chunk < c->n ? c0 + lv->chunk : c->n;
    for (int t = 0; t < c->nw; t++)
        if (c->w[t].st != GETME_OK)
            return c->w[t].st;
    int32_t stop = c1;
    (void)undo;
#ifdef GETME_FINISH_TEST /* test builds: take a second sweep back */
    if (undo && getenv("GETME_FINISH_TAKE_BACK") && c->n / 3 >= c0 &&
        c->n / 3 < c1)
        stop = c->n / 3;
#endif
    double b = *budget;
    int32_t from = c1;
    for (int32_t i = c0; i < c1 && from == c1; i++) {
        const sweep_rec *r = &c->rec[i];
        const double *cg = c->w[r->worker].cg + r->cg;
        if (i == stop)
            from = i;
        for (int32_t j = 0; j < r->ncg && from == c1; j++) {
            if (!(cg[j] >= -b))
                from = i; /* the serial budget refuses this move */
            else
                b += cg[j];
        }
    }
    getme_status st = GETME_OK;
    if (from < c1) { /* the budget at from's start, then serially */
        b = *budget;
        for (int32_t i = c0; i < from; i++)
            for (int32_t j = 0; j < c->rec[i].ncg; j++)
                b += c->w[c->rec[i].worker].cg[c->rec[i].cg + j];
        double loss = c->w[0].p.loss;
        st = take_back(c, h, from, c1);
        if (st == GETME_OK)
            st = sweep_serial(c, from, c1, &b);
        levelled_mode(&c->w[0], loss);
    }
    *budget = b;
    for (int t = 0; t < c->nw; t++)
        c->w[t].ncg = c->w[t].nun = 0; /* the chunk's logs are done */
    return st;
}

/* One levelled sweep (see above); *budget is the serial budget. */
static getme_status sweep_levelled(sweep_ctx *c, int undo, double *budget)
{
    const getme_levels *lv = &c->lv;
    for (int t = 0; t < c->nw; t++) {
        levelled_mode(&c->w[t], c->w[0].p.loss);
        c->w[t].ncg = c->w[t].nun = 0;
        c->w[t].st = GETME_OK;
    }
#ifdef GETME_FINISH_TEST
    /* test builds: each level backwards on one thread, a schedule as good
       as any for right levels, and a sure way to expose wrong ones */
    int reverse = getenv("GETME_FINISH_REVERSE") != NULL;
#else
    const int reverse = 0;
#endif
    getme_status st = GETME_OK;
#pragma omp parallel num_threads(c->nw)
    {
        worker *w = &c->w[omp_get_thread_num()];
        for (int32_t h = 0; h < lv->num_chunks; h++) {
            for (int32_t L = lv->cfirst[h]; L < lv->cfirst[h + 1]; L++) {
                int32_t a = lv->ptr[L], b = lv->ptr[L + 1];
                if (reverse) {
#pragma omp single
                    {
                        for (int32_t x = b - 1; x >= a; x--)
                            process(c, w, lv->order[x], undo);
                        merge(c);
                    }
                } else if (b - a > 1) {
#pragma omp for schedule(dynamic, 1)
                    for (int32_t x = a; x < b; x++)
                        process(c, w, lv->order[x], undo);
#pragma omp single
                    merge(c);
                } else {
#pragma omp single
                    {
                        process(c, w, lv->order[a], undo);
                        merge(c);
                    }
                }
            }
#pragma omp single
            if (st == GETME_OK && (st = chunk_check(c, h, undo, budget)) != GETME_OK)
                for (int t = 0; t < c->nw; t++)
                    c->w[t].st = st; /* the rest does nothing */
        }
    }
    return st;
}

/* Workers for nw threads; GETME_OK or GETME_ERR_NOMEM. */
static getme_status workers_init(sweep_ctx *c, int nw)
{
    const getme_run *run = c->run;
    c->w = getme__calloc((size_t)nw, sizeof *c->w);
    if (!c->w)
        return GETME_ERR_NOMEM;
    c->nw = nw;
    for (int t = 0; t < nw; t++) {
        getme_patch *p = &c->w[t].p;
        if (getme__patch_init(p, 8 * run->ws->max_star) != GETME_OK)
            return GETME_ERR_NOMEM;
        p->x = run->ws->x;
        p->ws = run->ws;
        p->guard = run->guard;
        p->floor = run->corner_floor;
        memcpy(p->skip_q, run->guard_skip_q, sizeof p->skip_q);
    }
    return GETME_OK;
}

static void workers_free(sweep_ctx *c)
{
    for (int t = 0; t < c->nw; t++) {
        worker *w = &c->w[t];
        getme__patch_free(&w->p);
        free(w->ev), free(w->cg), free(w->un), free(w->padd);
    }
    free(c->w);
    free(c->rec);
    getme__levels_free(&c->lv);
}

/* The pass's two sweeps over list[0..n): the first takes only moves that
   lose no total quality (and so earns budget), the second may spend it.
   Levelled on several threads when the list is long and not one chain. */
static getme_status pass_sweeps(sweep_ctx *c, double *budget)
{
    int levelled = c->nw > 1 && c->n >= LEVELLED_MIN;
    if (levelled) {
        if (c->n > c->cap_rec) {
            free(c->rec);
            c->rec = getme__malloc((size_t)c->n * sizeof *c->rec);
            c->cap_rec = c->rec ? c->n : 0;
            if (!c->rec)
                return GETME_ERR_NOMEM;
        }
        /* the run's element list is free after the iterations: zeroed
           once here, and levels_build leaves it zeroed */
        if (!c->marks_zero) {
            memset(c->run->elems, 0,
                   (size_t)c->run->ws->ne * sizeof *c->run->elems);
            c->marks_zero = 1;
        }
        getme_status st = getme__levels_build(&c->lv, c->run->ws, c->list,
                                              c->n, LEVELLED_CHUNK,
                                              c->run->elems);
        if (st != GETME_OK)
            return st;
#ifndef GETME_FINISH_TEST
        levelled = 4 * c->lv.num <= c->n; /* else mostly barriers */
#endif
    }
    getme_status st = GETME_OK;
    for (int sweep = 0; sweep < 2 && st == GETME_OK; sweep++) {
        c->w[0].p.loss = sweep ? GETME_PATCH_LOSS : 0.0;
        st = levelled ? sweep_levelled(c, sweep, budget)
                      : sweep_serial(c, 0, c->n, budget);
    }
    return st;
}

getme_status getme__finish(getme_run *run)
{
    getme_ws *ws = run->ws;
    const getme_params *prm = run->params;
    getme_result *res = run->result;
    pool pl;
    memset(&pl, 0, sizeof pl);
    sweep_ctx c;
    memset(&c, 0, sizeof c);
    c.run = run;
    c.pl = run->sub ? NULL : &pl;
    /* no memo for second-order elements: their validity also reads the
       mid-edge nodes; and no levels (the same reason) or on a sub-mesh */
    climb_memo memo_store, *memo = NULL;
    if (!ws->ho && memo_init(&memo_store) == 0)
        memo = &memo_store;
#ifdef GETME_FINISH_TEST /* test builds: the same moves without it */
    if (memo && getenv("GETME_FINISH_NO_MEMO")) {
        memo_free(memo);
        memo = NULL;
    }
#endif
    c.memo = &memo;
    getme_status st =
        workers_init(&c, ws->nt > 1 && !ws->ho && !run->sub ? ws->nt : 1);
    if (st == GETME_OK && !run->sub) {
        getme__tally_start(&pl.tally, ws, run->q);
        st = pool_build(run, &pl, prm->finish_fraction, 64);
    }
    double q_mean, q_min, budget = 0.0;
    if (st == GETME_OK)
        st = pass_summary(run, &pl, &q_mean, &q_min);
    for (int pass = 1; pass <= prm->finish_max_passes && st == GETME_OK;
         pass++) {
        double bound;
        int32_t n, raised = 0;
        getme_ranked *list = pass_bound_list(run, &pl, &bound, &n, &st);
        if (!list)
            break;
        c.list = list, c.n = n, c.bound = bound;
        st = pass_sweeps(&c, &budget);
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
    workers_free(&c);
    if (memo)
        memo_free(memo);
    return st;
}
