/*
 * best.c -- keep_best's best mesh as an undo log (best.h says why).
 */
#include "best.h"

#include <stdlib.h>
#include <string.h>

static size_t coord_bytes(const getme_ws *ws)
{
    return (size_t)(ws->nn ? ws->nn : 1) * 3 * sizeof(double);
}

getme_status getme__best_init(getme_best *b, const getme_run *run, int on)
{
    memset(b, 0, sizeof *b);
    b->on = on;
    if (!on)
        return GETME_OK;
    const getme_ws *ws = run->ws;
    if (run->comm) {
        b->whole = getme__malloc(coord_bytes(ws));
        return b->whole ? GETME_OK : GETME_ERR_NOMEM;
    }
    b->seen = getme__calloc(((size_t)ws->nn + 63) / 64 + 1, sizeof *b->seen);
    return b->seen ? GETME_OK : GETME_ERR_NOMEM;
}

void getme__best_take(getme_best *b, const getme_ws *ws)
{
    if (!b->on)
        return;
    if (b->whole) {
        memcpy(b->whole, ws->x, (size_t)ws->nn * 3 * sizeof *b->whole);
        return;
    }
    for (int64_t k = 0; k < b->n; k++) /* the log starts again, empty */
        b->seen[b->node[k] >> 6] &= ~((uint64_t)1 << (b->node[k] & 63));
    b->n = 0;
}

/* The log becomes a whole copy: the current coordinates with the logged
   ones put back.  0, or -1 if out of memory (the log stays). */
static int to_whole(getme_best *b, const getme_ws *ws)
{
    b->whole = getme__malloc(coord_bytes(ws));
    if (!b->whole)
        return -1;
    memcpy(b->whole, ws->x, (size_t)ws->nn * 3 * sizeof *b->whole);
    for (int64_t k = 0; k < b->n; k++)
        memcpy(b->whole + 3 * (int64_t)b->node[k], b->x + 3 * k,
               3 * sizeof *b->x);
    free(b->seen), free(b->node), free(b->x);
    b->seen = NULL, b->node = NULL, b->x = NULL;
    b->n = b->cap = 0;
    return 0;
}

/* Room for n more entries in the log. */
static int reserve(getme_best *b, int64_t more)
{
    if (b->n + more <= b->cap)
        return 0;
    int64_t cap = b->n + more > 2 * b->cap ? b->n + more : 2 * b->cap;
    cap = cap < 1024 ? 1024 : cap;
    int32_t *node = getme__realloc(b->node, (size_t)cap * sizeof *node);
    if (!node)
        return -1;
    b->node = node;
    double *x = getme__realloc(b->x, (size_t)cap * 3 * sizeof *x);
    if (!x)
        return -1;
    b->x = x;
    b->cap = cap;
    return 0;
}

getme_status getme__best_note(getme_best *b, const getme_run *run)
{
    if (!b->on || b->whole)
        return GETME_OK;
    const getme_ws *ws = run->ws;
    for (int32_t k = 0; k < run->num_t; k++) {
        int32_t e = run->tlist[k];
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        int nv = getme__nv[t];
        if (reserve(b, nv) != 0)
            return to_whole(b, ws) == 0 ? GETME_OK : GETME_ERR_NOMEM;
        for (int i = 0; i < nv; i++) {
            int32_t u = c[i];
            uint64_t bit = (uint64_t)1 << (u & 63);
            if (ws->fixed[u] || (b->seen[u >> 6] & bit))
                continue;
            b->seen[u >> 6] |= bit;
            b->node[b->n] = u;
            memcpy(b->x + 3 * b->n, ws->x + 3 * (int64_t)u, 3 * sizeof *b->x);
            b->n++;
        }
        if (b->n > ws->nn / 4) /* no longer smaller than a whole copy */
            return to_whole(b, ws) == 0 ? GETME_OK : GETME_ERR_NOMEM;
    }
    return GETME_OK;
}

/* After a log: the qualities of the elements around the nodes put back,
   each once (run->eflag marks them).  A serial walk: the marks make each
   element's first visit the one that scores it. */
static void rescore(const getme_best *b, getme_run *run)
{
    const getme_ws *ws = run->ws;
    int32_t *done = run->elems; /* scratch here: the iterations are over */
    int32_t m = 0;
    for (int64_t k = 0; k < b->n; k++) {
        int32_t v = b->node[k];
        getme_star_it it = getme__star_open(ws, v);
        for (int32_t e; getme__star_next(&it, &e);) {
            if (run->eflag[e])
                continue;
            run->eflag[e] = 1;
            done[m++] = e;
            run->q[e] = getme__ws_quality(ws, ws->x, e);
        }
    }
    for (int32_t k = 0; k < m; k++)
        run->eflag[done[k]] = 0;
}

/* Whether the log's stars are so large that scoring every element, in
   parallel and in memory order (getme__ws_qualities), beats the serial
   walk.  The walk costs ~80 ns per star entry (a scattered quality for
   most of them), the sweep ~13 ns per element on two threads and ~26 on
   one: on an 11.2M-tet CAD part (bench/big_meshes.py part 0.042) the log
   held 196,800 nodes, whose stars hit 3.6M elements, and the walk took
   0.38 s of the run.  Either way every q is its element's quality at the
   restored coordinates: the same bits. */
static int rescore_all(const getme_best *b, const getme_run *run)
{
    const getme_ws *ws = run->ws;
#ifdef GETME_CHECK_SUMS
    /* Test builds: the sweep on 2 threads, the walk on others, so that
       test_best.c's runs at 1 and 2 threads (the restored q*_min, the
       same coordinates) and the check below cover both. */
    (void)b;
    return ws->nt == 2;
#else
    int64_t entries = 0;
    for (int64_t k = 0; k < b->n; k++)
        entries += getme__star_size(ws, b->node[k]);
    return entries >= (int64_t)ws->ne / 4;
#endif
}

getme_status getme__best_restore(getme_best *b, getme_run *run)
{
    getme_ws *ws = run->ws;
    if (b->whole) {
        memcpy(ws->x, b->whole, (size_t)ws->nn * 3 * sizeof *ws->x);
        getme__ws_qualities(ws, run->q);
        return GETME_OK;
    }
    for (int64_t k = 0; k < b->n; k++)
        memcpy(ws->x + 3 * (int64_t)b->node[k], b->x + 3 * k,
               3 * sizeof *b->x);
    if (rescore_all(b, run))
        getme__ws_qualities(ws, run->q);
    else
        rescore(b, run);
#ifdef GETME_CHECK_SUMS
    double *q = getme__malloc((size_t)(ws->ne ? ws->ne : 1) * sizeof *q);
    if (!q)
        return GETME_ERR_NOMEM;
    getme__ws_qualities(ws, q);
    int same = memcmp(q, run->q, (size_t)ws->ne * sizeof *q) == 0;
    free(q);
    if (!same)
        return GETME_ERR_STATE;
#endif
    return GETME_OK;
}

void getme__best_free(getme_best *b)
{
    free(b->whole), free(b->seen), free(b->node), free(b->x);
    memset(b, 0, sizeof *b);
}
