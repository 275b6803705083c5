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
 */
#include "patch.h"
#include "smooth_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct ranked {
    double q;
    int32_t e;
} ranked;

static int cmp_ranked(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    if (x->q != y->q)
        return x->q < y->q ? -1 : 1;
    return (x->e > y->e) - (x->e < y->e);
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
            if (run->eflag[e])
                continue;
            run->eflag[e] = 1;
            int t = getme__ws_type(ws, e);
            st = getme__patch_add(p, t, getme__ws_nodes(ws, t, e), e);
        }
    for (int32_t i = 0; i < p->n; i++)
        run->eflag[p->id[i]] = 0;
    getme__patch_eval(p);
    return st;
}

/* Copy the patch's qualities back to run->q. */
static void store(getme_run *run, const getme_patch *p)
{
    for (int32_t i = 0; i < p->n; i++)
        run->q[p->id[i]] = p->q[i];
}

/* Work on element e. */
static getme_status improve(getme_run *run, getme_patch *p, int32_t e)
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
        if ((st = fill(run, p, &mv[j], 1)) != GETME_OK)
            return st;
        if (getme__patch_climb(p, &mv[j], 1, 8, 1))
            store(run, p);
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
        if (moved)
            store(run, p);
    }
    return GETME_OK;
}

/* The pass's elements: free ones with q <= bound, worst first. */
static ranked *pass_list(const getme_run *run, double bound, int32_t *count)
{
    const getme_ws *ws = run->ws;
    int32_t n = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        n += ws->free_elem[e] && run->q[e] <= bound;
    ranked *r = malloc((size_t)(n ? n : 1) * sizeof *r);
    if (!r)
        return NULL;
    n = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (ws->free_elem[e] && run->q[e] <= bound)
            r[n].q = run->q[e], r[n++].e = e;
    qsort(r, (size_t)n, sizeof *r, cmp_ranked);
    *count = n;
    return r;
}

getme_status getme__finish(getme_run *run)
{
    getme_ws *ws = run->ws;
    const getme_params *prm = run->params;
    getme_result *res = run->result;
    getme_patch p;
    if (getme__patch_init(&p, 8 * ws->max_star) != GETME_OK)
        return GETME_ERR_NOMEM;
    p.x = ws->x;
    p.ws = ws;
    p.guard = run->guard;
    p.floor = run->corner_floor;
    double q_mean, q_min;
    getme__ws_summary(ws, run->q, &q_mean, &q_min, NULL);
    getme_status st = GETME_OK;
    for (int pass = 1; pass <= prm->finish_max_passes; pass++) {
        double bound = getme__threshold(run, prm->finish_fraction, 64);
        int32_t n, raised = 0;
        ranked *list = bound < 0.0 ? NULL : pass_list(run, bound, &n);
        if (!list) {
            st = GETME_ERR_NOMEM;
            break;
        }
        /* Two sweeps: the first takes only moves that lose no total
           quality (and so earns budget), the second may spend it. */
        for (int sweep = 0; sweep < 2; sweep++) {
            p.loss = sweep ? GETME_PATCH_LOSS : 0.0;
            for (int32_t i = 0; i < n && st == GETME_OK; i++)
                if (run->q[list[i].e] <= bound)
                    st = improve(run, &p, list[i].e);
        }
        /* Raised over the pass, whichever sweep did it (the list keeps
           each element's quality at the pass's start). */
        for (int32_t i = 0; i < n; i++)
            raised += run->q[list[i].e] > list[i].q;
        free(list);
        if (st != GETME_OK)
            break;
        double prev = q_min;
        getme__ws_summary(ws, run->q, &q_mean, &q_min, NULL);
        res->passes_finish = pass;
        res->moved_finish += raised;
        if (getme__report(run, pass, GETME_STAGE_FINISH, res->cycles_min,
                          q_min, q_mean, bound, n, raised)) {
            res->stop_reason = GETME_STOP_CANCELLED;
            st = GETME_ERR_CANCELLED;
            break;
        }
        if (!(q_min > prev + prm->min_tol))
            break;
    }
    getme__patch_free(&p);
    return st;
}
