/*
 * adjacency.c -- edge ids, face neighbours, exact neighbour counts and the
 * per-node / per-edge quality sums behind the Eq. 9 weights (adjacency.h
 * says why and proves the formula).
 *
 * Everything is built from the node stars the workspace already has, in
 * parallel loops where each iteration writes only what it owns (a node's
 * edges, an element's rows), so the result is the same for any number of
 * threads.
 */
#include "adjacency.h"
#include "smooth_internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

void getme__adj_free(getme_adj *adj)
{
    free(adj->eptr);
    free(adj->eslot);
    free(adj->fnb);
    free(adj->count);
    free(adj->irregular);
    free(adj->nsum);
    free(adj->esum);
    getme__blocks_free(&adj->blk);
    memset(adj, 0, sizeof *adj);
}

/* The check value of element n: a fixed pseudo-random 64-bit integer
   (splitmix64), so that sum(formula) == sum(union) over such values means
   every element was counted exactly once, with overwhelming probability. */
static inline uint64_t check_value(int32_t n)
{
    uint64_t z = (uint64_t)(uint32_t)n + 0x9e3779b97f4a7c15u;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* Other end of local edge j of a type-t element at local node li, or -1 if
   the edge does not touch li. */
static inline int edge_other(int t, int j, int li)
{
    const getme_edge_table *et = &getme__edges[t];
    return et->node[j][0] == li   ? et->node[j][1]
           : et->node[j][1] == li ? et->node[j][0]
                                  : -1;
}

/* Slot of w in the list buf[0..*m) of node u's upper neighbours (the
   other ends w > u of the edges at u), appended if new.  The lists are
   short (~7 in a tet mesh), so a linear search beats sorting them. */
static inline int slot_of(int32_t *buf, int *m, int32_t w)
{
    for (int i = 0; i < *m; i++)
        if (buf[i] == w)
            return i;
    buf[*m] = w;
    return (*m)++;
}

/* Every edge belongs to its lower node.  Visit the edges that node u owns,
   element by element along its star: f(ctx, element, local edge, slot of
   the edge in u's list).  Returns the length of u's list (its edges). */
static int upper_edges(const getme_ws *ws, int32_t u, int32_t *buf,
                       void (*f)(void *, int32_t, int, int, int), void *ctx)
{
    int m = 0;
    for (int64_t k = ws->star_ptr[u]; k < ws->star_ptr[u + 1]; k++) {
        int32_t n = ws->star[k];
        int t = getme__ws_type(ws, n), nv = getme__nv[t];
        const int32_t *c = getme__ws_nodes(ws, t, n);
        int li = getme__local_index(c, nv, u);
        for (int j = 0; j < getme__edges[t].num_edges; j++) {
            int o = edge_other(t, j, li);
            if (o >= 0 && c[o] > u) {
                int slot = slot_of(buf, &m, c[o]);
                if (f)
                    f(ctx, n, t, j, slot);
            }
        }
    }
    return m;
}

/* What the second pass over a node's edges fills in. */
typedef struct edge_pass {
    getme_adj *adj;
    const getme_ws *ws;
    int64_t first;  /* id of the node's first edge */
    int32_t *edeg;
    uint64_t *re;
} edge_pass;

static void assign_edge(void *ctx, int32_t n, int t, int j, int slot)
{
    edge_pass *p = ctx;
    int32_t id = (int32_t)(p->first + slot);
    getme__adj_slots(p->adj, p->ws, t, n)[j] =
        (uint8_t)(slot < GETME_NO_SLOT ? slot : GETME_NO_SLOT);
    p->edeg[id]++;
    if (p->re)
        p->re[id] += check_value(n);
}

/* Edge ids of every element edge (3-D), numbered node by node (a node's
   edges in the order its star meets them), how many elements have each
   edge (edeg), and if checks is set the check-value sums of every edge
   (re).  Each node writes only its own edges' entries. */
static getme_status build_edges(getme_adj *adj, const getme_ws *ws,
                                int32_t **edeg_out, int checks,
                                uint64_t **re_out)
{
    int64_t total = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        adj->eoff[t] = total;
        total += (int64_t)(ws->tstart[t + 1] - ws->tstart[t]) *
                 getme__edges[t].num_edges;
    }
    int64_t *eptr = malloc(((size_t)ws->nn + 1) * sizeof *eptr);
    adj->eptr = malloc(((size_t)ws->nn + 1) * sizeof *adj->eptr);
    adj->eslot = malloc((size_t)(total ? total : 1));
    size_t bufsize = (size_t)ws->max_star * 4 + 1;
    int32_t *bufs = malloc((size_t)ws->nt * bufsize * sizeof *bufs);
    if (!eptr || !adj->eptr || !adj->eslot || !bufs) {
        free(eptr), free(bufs);
        return GETME_ERR_NOMEM;
    }
    eptr[0] = 0;
#pragma omp parallel for schedule(dynamic, 1024) num_threads(ws->nt)
    for (int32_t u = 0; u < ws->nn; u++)
        eptr[u + 1] = upper_edges(ws, u, bufs + omp_get_thread_num() * bufsize,
                                  NULL, NULL);
    for (int32_t u = 0; u < ws->nn; u++)
        eptr[u + 1] += eptr[u];
    if (eptr[ws->nn] > INT32_MAX) {
        free(eptr), free(bufs);
        return GETME_ERR_NOMEM;
    }
    adj->num_edges = (int32_t)eptr[ws->nn];
    for (int32_t u = 0; u <= ws->nn; u++)
        adj->eptr[u] = (int32_t)eptr[u];
    size_t nedge = (size_t)(adj->num_edges ? adj->num_edges : 1);
    int32_t *edeg = calloc(nedge, sizeof *edeg);
    uint64_t *re = checks ? calloc(nedge, sizeof *re) : NULL;
    if (!edeg || (checks && !re)) {
        free(eptr), free(bufs), free(edeg), free(re);
        return GETME_ERR_NOMEM;
    }
#pragma omp parallel for schedule(dynamic, 1024) num_threads(ws->nt)
    for (int32_t u = 0; u < ws->nn; u++) {
        edge_pass p = {adj, ws, eptr[u], edeg, re};
        upper_edges(ws, u, bufs + omp_get_thread_num() * bufsize, assign_edge, &p);
    }
    free(eptr), free(bufs);
    *edeg_out = edeg;
    *re_out = re;
    return GETME_OK;
}

/* Check-value sums of every node's star. */
static void node_checks(const getme_ws *ws, uint64_t *rn)
{
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t u = 0; u < ws->nn; u++) {
        uint64_t r = 0;
        for (int64_t k = ws->star_ptr[u]; k < ws->star_ptr[u + 1]; k++)
            r += check_value(ws->star[k]);
        rn[u] = r;
    }
}

/* |N(E)| by the same inclusion-exclusion, with element counts (node and
   edge degrees) in place of qualities; and irregular = a face the formula
   cannot handle. */
static void counts_and_flags(getme_adj *adj, const getme_ws *ws,
                             const int32_t *edeg)
{
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t e = 0; e < ws->ne; e++) {
        int t = getme__ws_type(ws, e), nv = getme__nv[t];
        const int32_t *c = getme__ws_nodes(ws, t, e);
        const getme_face_table *ft = &getme__faces[t];
        const int32_t *f = getme__adj_faces(adj, ws, t, e);
        int64_t cnt = 0, nb = 0, bad = 0;
        for (int i = 0; i < nv; i++)
            cnt += ws->star_ptr[c[i] + 1] - ws->star_ptr[c[i]];
        for (int k = 0; k < ft->num_faces; k++) {
            nb += f[k] >= 0;
            bad |= f[k] == GETME_FACE_IRREGULAR;
        }
        if (ws->dim == 2) {
            cnt -= (nv - 1) + nb;
        } else {
            const uint8_t *slot = getme__adj_slots(adj, ws, t, e);
            for (int j = 0; j < getme__edges[t].num_edges; j++) {
                bad |= slot[j] == GETME_NO_SLOT;
                cnt -= edeg[getme__adj_edge(adj, c, t, j, slot[j])];
            }
            cnt += (ft->num_faces - 1) + nb;
        }
        bad |= cnt > UINT16_MAX;
        adj->count[e] = (uint16_t)(bad ? 0 : cnt);
        if (bad) /* only then: see getme__adj_build */
            adj->irregular[e] = 1;
    }
}

typedef struct union_scratch {
    uint32_t *stamp; /* ne: element last seen at this stamp value */
    int32_t *list;
    uint32_t now;
} union_scratch;

/* Non-simplex meshes: two elements may share nodes that are not a common
   edge or face of both (a face diagonal), which the formula would
   miscount.  Check every element once against the true union, with
   pseudo-random integers in place of q (exact arithmetic), and take the
   union's exact count where they disagree. */
static void check_element(getme_adj *adj, const getme_ws *ws,
                          const uint64_t *rn, const uint64_t *re, int32_t e,
                          union_scratch *sc)
{
    int t = getme__ws_type(ws, e), nv = getme__nv[t];
    const int32_t *c = getme__ws_nodes(ws, t, e);
    const getme_face_table *ft = &getme__faces[t];
    uint32_t now = ++sc->now;
    int32_t cnt = 0;
    uint64_t truth = 0;
    for (int i = 0; i < nv; i++)
        for (int64_t k = ws->star_ptr[c[i]]; k < ws->star_ptr[c[i] + 1]; k++) {
            int32_t n = ws->star[k];
            if (sc->stamp[n] != now) {
                sc->stamp[n] = now;
                truth += check_value(n);
                cnt++;
            }
        }
    const int32_t *f = getme__adj_faces(adj, ws, t, e);
    uint64_t formula = 0, fs = 0;
    for (int i = 0; i < nv; i++)
        formula += rn[c[i]];
    for (int j = 0; j < ft->num_faces; j++)
        fs += f[j] >= 0 ? check_value(f[j]) : 0;
    uint64_t self = check_value(e);
    if (ws->dim == 2) {
        formula -= (uint64_t)(nv - 1) * self + fs;
    } else {
        const uint8_t *slot = getme__adj_slots(adj, ws, t, e);
        for (int j = 0; j < getme__edges[t].num_edges; j++)
            formula -= re[getme__adj_edge(adj, c, t, j, slot[j])];
        formula += (uint64_t)(ft->num_faces - 1) * self + fs;
    }
    if (formula != truth || cnt > UINT16_MAX)
        adj->irregular[e] = 1;
    adj->count[e] = (uint16_t)(adj->irregular[e] ? 0 : cnt);
}

static getme_status check_all(getme_adj *adj, const getme_ws *ws,
                              const uint64_t *rn, const uint64_t *re)
{
    int nt = ws->nt;
    union_scratch *sc = calloc((size_t)nt, sizeof *sc);
    int ok = sc != NULL;
    size_t ne = (size_t)(ws->ne ? ws->ne : 1);
    for (int k = 0; ok && k < nt; k++) {
        sc[k].stamp = calloc(ne, sizeof *sc[k].stamp);
        ok = sc[k].stamp != NULL;
    }
    if (ok) {
#pragma omp parallel for schedule(dynamic, 2048) num_threads(nt)
        for (int32_t e = 0; e < ws->ne; e++)
            check_element(adj, ws, rn, re, e, &sc[omp_get_thread_num()]);
    }
    for (int k = 0; sc && k < nt; k++)
        free(sc[k].stamp);
    free(sc);
    return ok ? GETME_OK : GETME_ERR_NOMEM;
}

static int simplices_only(const getme_ws *ws)
{
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        if (t != GETME_TET && t != GETME_TRI && ws->tstart[t + 1] > ws->tstart[t])
            return 0;
    return 1;
}

getme_status getme__adj_build(getme_adj *adj, getme_ws *ws)
{
    memset(adj, 0, sizeof *adj);
    size_t nn = (size_t)(ws->nn ? ws->nn : 1), ne = (size_t)(ws->ne ? ws->ne : 1);
    int64_t ftotal = getme__ws_face_offsets(ws, adj->foff);
    /* Simplices meet only in common sub-faces (any 2 or 3 nodes of a tet
       are an edge or a face of it), so the formula can fail only where
       build_faces sees it; other types need the check. */
    int check = !simplices_only(ws);
    int have_faces = ws->faces != NULL; /* the boundary search's table */
    adj->fnb = have_faces ? ws->faces
                          : malloc((size_t)(ftotal ? ftotal : 1) *
                                   sizeof *adj->fnb);
    ws->faces = NULL;
    adj->count = malloc(ne * sizeof *adj->count);
    /* Zeroed, and only irregular elements written: on a mesh with none
       (tets) its pages are never touched, so they take no memory. */
    adj->irregular = calloc(ne, 1);
    adj->nsum = malloc(nn * sizeof *adj->nsum);
    /* The fixed-point scale of the sums (adjacency.h). */
    adj->qscale = 0x1p61 / getme__pow2_ceil((double)ws->max_star + 1.0);
    adj->qinv = 1.0 / adj->qscale;
    uint64_t *rn = check ? malloc(nn * sizeof *rn) : NULL, *re = NULL;
    int32_t *edeg = NULL;
    getme_status st = GETME_ERR_NOMEM;
    if (!adj->fnb || !adj->count || !adj->irregular || !adj->nsum ||
        (check && !rn))
        goto fail;
    if (ws->dim == 3) {
        if ((st = build_edges(adj, ws, &edeg, check, &re)) != GETME_OK)
            goto fail;
        st = GETME_ERR_NOMEM;
        adj->esum = malloc((size_t)(adj->num_edges ? adj->num_edges : 1) *
                           sizeof *adj->esum);
        if (!adj->esum)
            goto fail;
    }
    if (check)
        node_checks(ws, rn);
    if (!have_faces &&
        (st = getme__ws_faces(ws, adj->foff, adj->fnb)) != GETME_OK)
        goto fail;
    counts_and_flags(adj, ws, edeg);
    if ((st = getme__blocks_build(&adj->blk, ws)) != GETME_OK)
        goto fail;
    if (check && (st = check_all(adj, ws, rn, re)) != GETME_OK)
        goto fail;
    for (int32_t e = 0; e < ws->ne; e++)
        adj->num_irregular += adj->irregular[e];
    free(rn), free(re), free(edeg);
    return GETME_OK;
fail:
    free(rn), free(re), free(edeg);
    getme__adj_free(adj);
    return st;
}

/* S_v and S_e contributions of the elements of block b, all of type t (a
   constant in each copy, see GETME_FOR_TYPE). */
static inline void add_block_sums(int t, getme_adj *adj, const getme_ws *ws,
                                  const double *q, int32_t b)
{
    for (int32_t e = ws->block_start[b]; e < ws->block_start[b + 1]; e++)
        getme__adj_add(adj, ws, t, e, getme__ws_nodes(ws, t, e),
                       (uint64_t)getme__fx64(q[e], adj->qscale));
}

typedef struct sums_pass {
    getme_adj *adj;
    const getme_ws *ws;
    const double *q;
} sums_pass;

static int64_t sums_block(void *ctx, int32_t b)
{
    sums_pass *p = ctx;
    GETME_FOR_TYPE(getme__ws_type(p->ws, p->ws->block_start[b]),
                   add_block_sums, p->adj, p->ws, p->q, b);
    return 0;
}

void getme__adj_sums_all(getme_adj *adj, const getme_ws *ws, const double *q)
{
    memset(adj->nsum, 0, (size_t)ws->nn * sizeof *adj->nsum);
    if (adj->esum)
        memset(adj->esum, 0, (size_t)adj->num_edges * sizeof *adj->esum);
    /* In the blocks' race-free order (block_local.h): no atomics, and the
       integer sums are the same whatever the order. */
    sums_pass p = {adj, ws, q};
    getme__blocks_run(&adj->blk, ws, sums_block, &p);
}
