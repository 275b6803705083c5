/*
 * revert.c -- GETMe adaptive never ends below the input's q*_min.
 *
 * The q_mean stage moves every free node toward a better mean, and on a
 * mesh whose worst element is already fair it can lower q*_min (Gmsh's
 * tutorial t18: 0.3931 in, 0.3632 out); the q*_min stage and the finishing
 * step do not always win it back.  keep_best's candidates start at the end
 * of the q_mean stage, so the input was never one.  A user who asks to fix
 * the worst elements must not get a worse one back.
 *
 * Putting the whole input back would throw away the mean's gain.  Instead
 * the nodes of every free element below the input's q*_min go back to their
 * input positions, the qualities of their stars are recomputed, and this
 * repeats until no free element is below it.  It ends: an element whose
 * nodes are all at their input positions has its input quality, which is
 * at least the input's q*_min, so every element still below has a node
 * left to put back, and the nodes are finite.  Each element is then valid
 * and at least the input's q*_min; the finishing step runs after it.
 *
 * The cost is a copy of the coordinates (24 B per node) for the whole run;
 * the walk itself is serial (a few nodes in practice) and its order is
 * fixed, so the result is the same for any thread count.
 */
#include "revert.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

getme_status getme__input_keep(getme_input *in, const getme_ws *ws,
                               double q_min_star, int on)
{
    memset(in, 0, sizeof *in);
    if (!on)
        return GETME_OK;
    in->x = getme__malloc((size_t)ws->nn * 3 * sizeof *in->x);
    if (!in->x)
        return GETME_ERR_NOMEM;
    /* Copied by every thread in its own share: the copy is fresh pages
       (the CLI maps every block of 1 MiB or more afresh), and faulting
       them in was most of its time, on one thread while the other waited. */
#pragma omp parallel num_threads(ws->nt)
    {
        int th = omp_get_thread_num(), n = omp_get_num_threads();
        int64_t a = (int64_t)ws->nn * th / n, b = (int64_t)ws->nn * (th + 1) / n;
        memcpy(in->x + 3 * a, ws->x + 3 * a, (size_t)(b - a) * 3 * sizeof *in->x);
    }
    in->q_min_star = q_min_star;
    return GETME_OK;
}

void getme__input_free(getme_input *in)
{
    free(in->x);
    in->x = NULL;
}

/* A growing list of 32-bit indices (getme__push_i32). */
typedef struct ilist {
    int32_t *v;
    int32_t n;
    int64_t cap;
} ilist;

/* Put back the free nodes of the elements in bad not put back yet, appending
   them to nodes. */
static int put_back(const getme_input *in, getme_ws *ws, const ilist *bad,
                    uint64_t *done, ilist *nodes)
{
    for (int64_t k = 0; k < bad->n; k++) {
        int32_t e = bad->v[k];
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int i = 0; i < getme__nv[t]; i++) {
            int32_t v = c[i];
            if (ws->fixed[v] || (done[v >> 6] >> (v & 63) & 1))
                continue;
            done[v >> 6] |= (uint64_t)1 << (v & 63);
            memcpy(ws->x + 3 * (int64_t)v, in->x + 3 * (int64_t)v,
                   3 * sizeof *ws->x);
            if (getme__push_i32(&nodes->v, &nodes->n, &nodes->cap, v))
                return -1;
        }
    }
    return 0;
}

/* Recompute the qualities of the stars of nodes; the free elements still
   below the input's q*_min go to bad (duplicates are harmless: their nodes
   are found put back). */
static int rescore(const getme_input *in, const getme_ws *ws, double *q,
                   const ilist *nodes, ilist *bad)
{
    for (int64_t k = 0; k < nodes->n; k++) {
        int32_t v = nodes->v[k];
        getme_star_it it = getme__star_open(ws, v);
        for (int32_t e; getme__star_next(&it, &e);) {
            q[e] = getme__ws_quality(ws, ws->x, e);
            if (ws->free_elem[e] && q[e] < in->q_min_star &&
                getme__push_i32(&bad->v, &bad->n, &bad->cap, e))
                return -1;
        }
    }
    return 0;
}

getme_status getme__input_revert(const getme_input *in, getme_ws *ws,
                                 double *q, int64_t *count)
{
    *count = 0;
    if (!in->x)
        return GETME_OK;
    ilist bad = {0}, nodes = {0};
    uint64_t *done = NULL;
    getme_status st = GETME_ERR_NOMEM;
    for (int32_t e = 0; e < ws->ne; e++)
        if (ws->free_elem[e] && q[e] < in->q_min_star &&
            getme__push_i32(&bad.v, &bad.n, &bad.cap, e))
            goto out;
    if (bad.n && !(done = getme__calloc(((size_t)ws->nn + 63) / 64, sizeof *done)))
        goto out;
    while (bad.n) {
        nodes.n = 0;
        if (put_back(in, ws, &bad, done, &nodes))
            goto out;
        *count += nodes.n;
        bad.n = 0;
        if (rescore(in, ws, q, &nodes, &bad))
            goto out;
    }
    st = GETME_OK;
out:
    free(bad.v);
    free(nodes.v);
    free(done);
    return st;
}
