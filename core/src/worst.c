/*
 * worst.c -- getme_mesh_worst_elements(): the worst elements of a mesh and
 * why each one cannot get better by moving nodes (docs/method.md §5).
 *
 * The reasons, tested in this order:
 *  - every node fixed, at least one of them only because it lies on a
 *    region interface: freeing interfaces would let it move;
 *  - every node fixed (skin, fixed sets): no node move can change it; a
 *    topological optimiser (edge and face swaps) can;
 *  - each free node, and all of them together, sits at a local optimum of
 *    the finishing step's max-min problem (patch.h): no small move raises
 *    the worst quality among the elements around them;
 *  - otherwise a move exists that the smoother did not make (it stopped on
 *    its iteration or pass limits).
 */
#include "patch.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

const char *getme_worst_reason_string(getme_worst_reason r)
{
    switch (r) {
    case GETME_WORST_IMPROVABLE: return "a node move can still raise it";
    case GETME_WORST_ALL_FIXED: return "all nodes fixed";
    case GETME_WORST_INTERFACE: return "all nodes fixed, on a region interface";
    case GETME_WORST_LOCAL_OPTIMUM:
        return "free nodes at a local optimum of their elements";
    }
    return "unknown";
}

static const int32_t *nodes_of(const getme_mesh *mesh, int32_t e, int *type)
{
    int32_t local;
    const getme_block *b = getme__find_block(mesh, e, &local);
    *type = b->type;
    return b->conn + (int64_t)local * getme__nv[b->type];
}

/* Insert (q, e) into the ascending list w of at most max entries. */
static void keep_worst(getme_worst_element *w, int32_t *n, int32_t max,
                       double q, int32_t e)
{
    if (*n == max && !(q < w[max - 1].quality))
        return; /* ties keep the lower index, which came first */
    int32_t i = *n < max ? (*n)++ : max - 1;
    while (i > 0 && q < w[i - 1].quality) {
        w[i] = w[i - 1];
        i--;
    }
    memset(&w[i], 0, sizeof w[i]);
    w[i].quality = q;
    w[i].element = e;
}

/* One thread's elements with a marked node, in element order. */
typedef struct hits {
    int32_t *e;
    int32_t n;
    int64_t cap;
    int failed; /* a push found no room: the scan's result is lost */
} hits;

static void hits_push(hits *h, int32_t e)
{
    if (!h->failed && getme__push_i32(&h->e, &h->n, &h->cap, e))
        h->failed = 1;
}

/* The elements of block bl with a marked node, appended to *list (*m of
   them) in element order, in one parallel scan: each thread keeps the
   hits of its contiguous range (few: the elements around a few nodes),
   appended in thread order.  0, or -1 if out of memory. */
static int marked(const getme_block *bl, const uint8_t *mark, hits *part,
                  int nt, int32_t **list, int32_t *m)
{
    int nv = getme__nv[bl->type];
    for (int k = 0; k < nt; k++)
        part[k].n = 0; /* also for a thread the runtime does not start */
#pragma omp parallel num_threads(nt)
    {
        hits h = part[omp_get_thread_num()];
#pragma omp for schedule(static)
        for (int32_t e = 0; e < bl->count; e++) {
            const int32_t *c = bl->conn + (int64_t)e * nv;
            int hit = 0;
            for (int i = 0; i < nv; i++)
                hit |= mark[c[i]];
            if (hit)
                hits_push(&h, bl->first + e);
        }
        part[omp_get_thread_num()] = h;
    }
    int32_t add = 0;
    for (int k = 0; k < nt; k++) {
        if (part[k].failed)
            return -1;
        add += part[k].n;
    }
    int32_t *grown =
        getme__realloc(*list, ((size_t)*m + add + 1) * sizeof *grown);
    if (!grown)
        return -1;
    *list = grown;
    for (int k = 0; k < nt; k++) {
        if (part[k].n)
            memcpy(grown + *m, part[k].e, (size_t)part[k].n * sizeof *grown);
        *m += part[k].n;
    }
    return 0;
}

/* The elements around the free nodes of the n reported elements, found in
   one parallel scan of the mesh (the mesh has no node stars), in element
   order, into *cand. */
static getme_status candidates(const getme_mesh *mesh,
                               const getme_worst_element *w, int32_t n,
                               int32_t **cand, int32_t *num)
{
    int nt = omp_get_max_threads();
    uint8_t *mark = getme__calloc((size_t)mesh->num_nodes, 1);
    hits *part = getme__calloc((size_t)nt, sizeof *part);
    int32_t *list = getme__malloc(sizeof *list), m = 0;
    for (int32_t i = 0; mark && i < n; i++) {
        int t;
        const int32_t *c = nodes_of(mesh, w[i].element, &t);
        for (int j = 0; j < getme__nv[t]; j++)
            mark[c[j]] = !mesh->fixed[c[j]];
    }
    int ok = mark && part && list;
    for (int b = 0; b < mesh->num_blocks && ok; b++)
        ok = marked(&mesh->blocks[b], mark, part, nt, &list, &m) == 0;
    if (!ok) {
        free(list);
        list = NULL;
    }
    for (int k = 0; part && k < nt; k++)
        free(part[k].e);
    free(mark);
    free(part);
    *cand = list, *num = m;
    return list ? GETME_OK : GETME_ERR_NOMEM;
}

/* The patch of the candidate elements containing any of the k nodes mv. */
static getme_status fill(const getme_mesh *mesh, getme_patch *p,
                         const int32_t *cand, int32_t num, const int32_t *mv,
                         int k)
{
    getme__patch_clear(p);
    for (int32_t i = 0; i < num; i++) {
        int t;
        const int32_t *c = nodes_of(mesh, cand[i], &t);
        int hit = 0;
        for (int v = 0; v < getme__nv[t]; v++)
            for (int j = 0; j < k; j++)
                hit |= c[v] == mv[j];
        if (hit && getme__patch_add(p, t, c, cand[i]) != GETME_OK)
            return GETME_ERR_NOMEM;
    }
    getme__patch_eval(p);
    return GETME_OK;
}

/* Is there a move of the free nodes mv (each alone, then all together)
   that raises the worst quality around them?  1 yes, 0 no, -1 no memory.
   Probes move coordinates and put them back bit for bit. */
static int can_improve(const getme_mesh *mesh, getme_patch *p,
                       const int32_t *cand, int32_t num, const int32_t *mv,
                       int k)
{
    for (int j = 0; j <= k; j++) {
        const int32_t *set = j < k ? &mv[j] : mv;
        int n = j < k ? 1 : k;
        if (j == k && k < 2)
            break;
        if (fill(mesh, p, cand, num, set, n) != GETME_OK)
            return -1;
        if (getme__patch_climb(p, set, n, 1, 0))
            return 1;
    }
    return 0;
}

/* The max worst elements (only those with a free node if free_only) of
   qualities q into out, *n of them, ascending, ties by index.  Each thread
   keeps the worst of its contiguous range of a block; fed into one list in
   thread order, they give what one serial sweep gives, since keep_worst
   keeps the smallest (quality, arrival) pairs and equal qualities arrive
   in index order either way. */
static getme_status worst_sweep(const getme_mesh *mesh, const double *q,
                                int free_only, int32_t max,
                                getme_worst_element *out, int32_t *n)
{
    int nt = omp_get_max_threads();
    getme_worst_element *part = getme__malloc((size_t)nt * max * sizeof *part);
    int32_t *cnt = getme__malloc((size_t)nt * sizeof *cnt);
    if (!part || !cnt) {
        free(part);
        free(cnt);
        return GETME_ERR_NOMEM;
    }
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        for (int k = 0; k < nt; k++)
            cnt[k] = 0;
#pragma omp parallel num_threads(nt)
        {
            int k = omp_get_thread_num();
            getme_worst_element *w = part + (int64_t)k * max;
#pragma omp for schedule(static)
            for (int32_t e = 0; e < bl->count; e++) {
                double qe = q[bl->first + e];
                /* keep_worst's own test first: most elements fail it,
                   and then need not have their nodes' flags read */
                if (cnt[k] == max && !(qe < w[max - 1].quality))
                    continue;
                if (!free_only || getme__local_has_free(mesh, bl, e))
                    keep_worst(w, &cnt[k], max, qe, bl->first + e);
            }
        }
        for (int k = 0; k < nt; k++)
            for (int32_t i = 0; i < cnt[k]; i++)
                keep_worst(out, n, max, part[(int64_t)k * max + i].quality,
                           part[(int64_t)k * max + i].element);
    }
    free(part);
    free(cnt);
    return GETME_OK;
}

getme_status getme_mesh_worst_elements(getme_mesh *mesh, int32_t max_count,
                                       unsigned flags,
                                       getme_worst_element *out,
                                       int32_t *count)
{
    if (!mesh || max_count < 0 || (!out && max_count > 0) || !count)
        return GETME_ERR_ARGUMENT;
    *count = 0;
    if (max_count == 0 || mesh->num_elements == 0)
        return GETME_OK;
    double *q = getme__malloc((size_t)mesh->num_elements * sizeof *q);
    if (!q)
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    getme_mesh_element_qualities(mesh, q);
    getme_status st =
        getme_mesh_worst_elements_from(mesh, q, max_count, flags, out, count);
    free(q);
    return st;
}

getme_status getme_mesh_worst_elements_from(getme_mesh *mesh, const double *q,
                                            int32_t max_count, unsigned flags,
                                            getme_worst_element *out,
                                            int32_t *count)
{
    if (!mesh || max_count < 0 || (!out && max_count > 0) || !count ||
        (!q && max_count > 0 && mesh->num_elements))
        return GETME_ERR_ARGUMENT;
    *count = 0;
    if (max_count == 0 || mesh->num_elements == 0)
        return GETME_OK;
    if (mesh->mirror < 0)
        getme__detect_orientation(mesh); /* the probes' patches need it */
    int32_t n = 0;
    if (worst_sweep(mesh, q, flags & GETME_WORST_FREE_ONLY, max_count, out,
                    &n) != GETME_OK)
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    getme_patch p;
    int32_t *cand = NULL, num = 0;
    if (candidates(mesh, out, n, &cand, &num) != GETME_OK ||
        getme__patch_init(&p, 64) != GETME_OK) {
        free(cand);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    p.x = mesh->coords;
    p.mirror = mesh->mirror == 1;
    p.loss = GETME_PATCH_LOSS;
    getme_status st = GETME_OK;
    for (int32_t i = 0; i < n && st == GETME_OK; i++) {
        getme_worst_element *w = &out[i];
        int t;
        const int32_t *c = nodes_of(mesh, w->element, &t);
        double x[3 * GETME_MAX_NV];
        getme__gather(mesh, w->element, x);
        w->type = (getme_elem_type)t;
        w->corner_sj = getme__corner_sj(t, x);
        w->num_nodes = getme__nv[t];
        int32_t mv[GETME_PATCH_MAX_MOVE];
        int k = 0, interface_only = 0;
        for (int j = 0; j < getme__nv[t]; j++) {
            uint8_t f = mesh->fixed[c[j]];
            if (!f)
                mv[k++] = c[j];
            interface_only |= f == GETME__FIXED_INTERFACE;
        }
        w->num_free = k;
        if (k == 0) {
            w->reason = interface_only ? GETME_WORST_INTERFACE
                                       : GETME_WORST_ALL_FIXED;
            continue;
        }
        int r = can_improve(mesh, &p, cand, num, mv, k);
        if (r < 0)
            st = getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
        w->reason = r ? GETME_WORST_IMPROVABLE : GETME_WORST_LOCAL_OPTIMUM;
    }
    getme__patch_free(&p);
    free(cand);
    *count = st == GETME_OK ? n : 0;
    return st;
}
