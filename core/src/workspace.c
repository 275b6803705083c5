/*
 * workspace.c -- build the smoother's working copy of a mesh: locality
 * order, node stars, blocks (see workspace.h for why).
 */
#include "exact.h"
#include "workspace.h"

#include "facenb.h"
#include "tally.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Elements per block.  Small enough that a block's nodes stay in cache
   and there are many blocks per thread; large enough that the per-block
   overhead vanishes.  Fixed: results must not depend on it changing with
   the thread count. */
#define BLOCK_SIZE 512
/* How far ahead the scattered gathers of the build fetch (rows, keys). */
#define ROW_AHEAD 16

void getme__ws_free(getme_ws *ws)
{
    free(ws->conn);
    free(ws->elem_orig);
    if (ws->maps_packed != 2) /* else inside elem_orig's block */
        free(ws->node_orig);
    free(ws->x);
    free(ws->x_spare);
    free(ws->fixed);
    free(ws->free_elem);
    free(ws->star_ptr);
    getme__offs_free(&ws->star_offs);
    free(ws->star);
    free(ws->block_start);
    getme__facenb_free(&ws->faces);
    getme__packed_free(&ws->elem_packed);
    getme__packed_free(&ws->node_packed);
    getme__ho_free(ws->ho);
    memset(ws, 0, sizeof *ws);
}

void getme__ws_keep(getme_ws *ws, getme_mesh *mesh)
{
    getme__mesh_drop_ws(mesh);
    mesh->ws_cache = getme__malloc(sizeof *mesh->ws_cache);
    if (mesh->ws_cache)
        *mesh->ws_cache = *ws;
    else
        getme__ws_free(ws);
    memset(ws, 0, sizeof *ws);
}

void getme__mesh_drop_ws(getme_mesh *mesh)
{
    if (mesh->ws_cache) {
        getme__ws_free(mesh->ws_cache);
        free(mesh->ws_cache);
        mesh->ws_cache = NULL;
    }
}

/* Spread the low 10 bits of v to every third bit. */
static uint32_t spread3(uint32_t v)
{
    v &= 0x3ff;
    v = (v | (v << 16)) & 0x030000ff;
    v = (v | (v << 8)) & 0x0300f00f;
    v = (v | (v << 4)) & 0x030c30c3;
    v = (v | (v << 2)) & 0x09249249;
    return v;
}

uint32_t getme__morton(const double *x, const double lo[3],
                       const double scale[3])
{
    uint32_t code = 0;
    for (int d = 0; d < 3; d++) {
        double s = (x[d] - lo[d]) * scale[d];
        uint32_t q = s <= 0.0 ? 0u : s >= 1023.0 ? 1023u : (uint32_t)s;
        code |= spread3(q) << d;
    }
    return code;
}

/* Stable LSD radix sort of idx[0..n) by key (key is left scrambled:
   its callers only need the order): three passes of 11, 11 and
   10 bits.  Two 16-bit passes scattered each key to one of 65536 places
   (4M tets: most of the workspace build's serial time in cache and TLB
   misses); 2048 write streams stay in cache.  On nt threads: each pass,
   every thread counts the digits of its own range of the array, then
   scatters that range after the keys of the same digit in the ranges
   before it, so the order is that of a serial stable sort for any thread
   count (and the same as any stable sort by key).  k2 and i2: n entries
   of scratch each. */
static int radix_sort(uint32_t *key, int32_t *idx, int32_t n, int nt,
                      uint32_t *k2, int32_t *i2)
{
    enum { BITS = 11, DIGITS = 1 << BITS };
    int64_t *cnt = getme__malloc((size_t)nt * DIGITS * sizeof *cnt);
    if (!cnt)
        return -1;
    uint32_t *kbuf[2] = {key, k2};
    int32_t *ibuf[2] = {idx, i2};
#pragma omp parallel num_threads(nt)
    {
        int th = omp_get_thread_num(), team = omp_get_num_threads();
        int32_t lo = (int32_t)((int64_t)n * th / team);
        int32_t hi = (int32_t)((int64_t)n * (th + 1) / team);
        int64_t *c = cnt + (size_t)th * DIGITS;
        for (int p = 0; p < 3; p++) {
            const uint32_t *ks = kbuf[p & 1];
            const int32_t *is = ibuf[p & 1];
            uint32_t *kd = kbuf[(p + 1) & 1];
            int32_t *id = ibuf[(p + 1) & 1];
            int shift = p * BITS;
            memset(c, 0, DIGITS * sizeof *c);
            for (int32_t i = lo; i < hi; i++)
                c[(ks[i] >> shift) & (DIGITS - 1)]++;
#pragma omp barrier
#pragma omp single
            { /* counts -> first positions: by digit, then by thread */
                int64_t at = 0;
                for (int d = 0; d < DIGITS; d++)
                    for (int t = 0; t < team; t++) {
                        int64_t v = cnt[(size_t)t * DIGITS + d];
                        cnt[(size_t)t * DIGITS + d] = at;
                        at += v;
                    }
            }
            for (int32_t i = lo; i < hi; i++) {
                uint32_t k = ks[i];
                int64_t pos = c[(k >> shift) & (DIGITS - 1)]++;
                kd[pos] = k;
                id[pos] = is[i];
            }
#pragma omp barrier
        }
        /* three passes: the order is in i2, copied back by each thread's
           range (a serial copy was ~10 ms of one thread on 4M tets); the
           sorted keys are not needed after the sort */
        memcpy(idx + lo, i2 + lo, (size_t)(hi - lo) * sizeof *idx);
    }
    free(cnt);
    return 0;
}

/* Entries in ws->conn and in ws->star: one per element corner (ws->coff
   set). */
static int64_t star_total(const getme_ws *ws)
{
    return ws->coff[GETME_NUM_TYPES - 1] +
           (int64_t)(ws->tstart[GETME_NUM_TYPES] -
                     ws->tstart[GETME_NUM_TYPES - 1]) *
               getme__nv[GETME_NUM_TYPES - 1];
}

/* The workspace's connectivity array (corners only, types in order),
   unfilled; ws->coff set.  GETME_OK or GETME_ERR_NOMEM. */
static getme_status alloc_conn(getme_ws *ws)
{
    int64_t total = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        ws->coff[t] = total;
        total += (int64_t)(ws->tstart[t + 1] - ws->tstart[t]) * getme__nv[t];
    }
    ws->conn = getme__malloc((size_t)(total ? total : 1) * sizeof *ws->conn);
    return ws->conn ? GETME_OK : GETME_ERR_NOMEM;
}

/* Fill ws->elem_orig: internal element order (grouped by type, Morton order
   inside a type when renumber is set). */
static getme_status order_elements(getme_ws *ws, const getme_mesh *mesh,
                                   int renumber)
{
    int32_t count[GETME_NUM_TYPES] = {0};
    for (int b = 0; b < mesh->num_blocks; b++)
        count[mesh->blocks[b].type] += mesh->blocks[b].count;
    ws->tstart[0] = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        ws->tstart[t + 1] = ws->tstart[t] + count[t];
    int32_t fill[GETME_NUM_TYPES];
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        fill[t] = ws->tstart[t];
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        for (int32_t e = 0; e < bl->count; e++)
            ws->elem_orig[fill[bl->type]++] = bl->first + e;
    }
    /* Allocated here, before number_nodes fills it: every type has 3 or
       more corners, so it holds the Morton keys and the sort's two scratch
       arrays (3 * ne entries), whose pages number_nodes then reuses
       instead of fresh ones (46 MiB less to fault in on the full tets). */
    if (alloc_conn(ws) != GETME_OK)
        return GETME_ERR_NOMEM;
    if (!renumber || ws->ne == 0)
        return GETME_OK;

    /* Morton key of every node in the mesh bounding box, then each element
       takes its first node's key.  Keying elements by their centroids
       instead gathered 4-8 coordinate triples per element in the caller's
       order: half of the workspace build on 1M tets, all cache misses. */
    /* minima and maxima are exact: the same for any split */
    double lo0 = INFINITY, lo1 = INFINITY, lo2 = INFINITY;
    double hi0 = -INFINITY, hi1 = -INFINITY, hi2 = -INFINITY;
    const double *xc = mesh->coords;
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    reduction(min : lo0, lo1, lo2) reduction(max : hi0, hi1, hi2)
    for (int32_t i = 0; i < mesh->num_nodes; i++) {
        const double *p = xc + 3 * (int64_t)i;
        lo0 = p[0] < lo0 ? p[0] : lo0, hi0 = p[0] > hi0 ? p[0] : hi0;
        lo1 = p[1] < lo1 ? p[1] : lo1, hi1 = p[1] > hi1 ? p[1] : hi1;
        lo2 = p[2] < lo2 ? p[2] : lo2, hi2 = p[2] > hi2 ? p[2] : hi2;
    }
    double lo[3] = {lo0, lo1, lo2}, hi[3] = {hi0, hi1, hi2};
    double scale[3];
    for (int d = 0; d < 3; d++)
        scale[d] = hi[d] > lo[d] ? 1023.0 / (hi[d] - lo[d]) : 0.0;
    uint32_t *key = (uint32_t *)ws->conn, *k2 = key + ws->ne;
    int32_t *i2 = (int32_t *)(k2 + ws->ne);
    uint32_t *nkey =
        getme__malloc((size_t)(mesh->num_nodes ? mesh->num_nodes : 1) *
                      sizeof *nkey);
    if (!nkey)
        return GETME_ERR_NOMEM;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t i = 0; i < mesh->num_nodes; i++)
        nkey[i] = getme__morton(mesh->coords + 3 * (int64_t)i, lo, scale);
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t k = 0; k < ws->ne; k++) {
        /* the first nodes' keys are scattered loads: fetched ahead */
        if (k + ROW_AHEAD < ws->ne) {
            int32_t la;
            const getme_block *ba =
                getme__find_block(mesh, ws->elem_orig[k + ROW_AHEAD], &la);
            __builtin_prefetch(nkey + ba->conn[(int64_t)la * getme__nv[ba->type]]);
        }
        int32_t local;
        const getme_block *bl = getme__find_block(mesh, ws->elem_orig[k], &local);
        key[k] = nkey[bl->conn[(int64_t)local * getme__nv[bl->type]]];
    }
    free(nkey);
    /* Sort inside each type range; stable, so ties keep the caller order. */
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int32_t a = ws->tstart[t], n = ws->tstart[t + 1] - a;
        if (n > 1 && radix_sort(key + a, ws->elem_orig + a, n, ws->nt,
                                k2 + a, i2 + a) != 0)
            return GETME_ERR_NOMEM;
    }
    return GETME_OK;
}

/* First-touch numbering on ws->nt threads (newid all -1 on entry): the
   same numbers as the serial stream over c[0..total), which was ~60 ms
   of one thread on 4M tets while the other waited.  Each thread lists
   the nodes its own range of c meets first *within that range*, in
   order (a bit per node per thread marks them); the numbers are then
   given serially, range by range and in each list's order, to the
   nodes not numbered by an earlier range -- which is exactly the order
   in which the serial stream meets each node for the first time.  The
   lists are short (a node is listed by each range that touches it: in
   the Morton order ~nn plus the ranges' borders), so the serial part
   is ~nn steps instead of ~total.  Last, every thread renumbers its
   range.  GETME_ERR_NOMEM (newid untouched) sends the caller to the
   serial stream. */
static getme_status first_touch_parallel(const getme_ws *ws, int32_t *c,
                                         int64_t total, int32_t *newid,
                                         int32_t *next)
{
    int nt = ws->nt;
    size_t words = ((size_t)ws->nn + 63) / 64;
    uint64_t *seen =
        getme__calloc((size_t)nt * (words ? words : 1), sizeof *seen);
    int32_t **list = getme__calloc((size_t)nt, sizeof *list);
    int64_t *len = getme__calloc((size_t)nt, sizeof *len);
    int failed = !seen || !list || !len;
    /* A range lists each node at most once, plus one slot that the
       branch-free append may write past the last; the team may be
       smaller than nt (longer ranges), so no tighter bound by range. */
    int64_t cap = (total < ws->nn ? total : ws->nn) + 1;
    if (!failed)
        for (int t = 0; t < nt; t++) {
            list[t] = getme__malloc((size_t)cap * sizeof **list);
            failed |= !list[t];
        }
    if (failed) {
        if (list)
            for (int t = 0; t < nt; t++)
                free(list[t]);
        free(seen), free(list), free(len);
        return GETME_ERR_NOMEM;
    }
#pragma omp parallel num_threads(nt)
    {
        int th = omp_get_thread_num(), team = omp_get_num_threads();
        /* team < nt: the missing threads' lists stay empty; ranges are
           cut by team so that every entry is in one */
        int64_t k0 = total * th / team, k1 = total * (th + 1) / team;
        uint64_t *mine = seen + (size_t)th * words;
        int32_t *l = list[th];
        int64_t n = 0;
        for (int64_t k = k0; k < k1; k++) {
            uint32_t v = (uint32_t)c[k];
            uint64_t bit = (uint64_t)1 << (v & 63), w = mine[v >> 6];
            mine[v >> 6] = w | bit;
            l[n] = (int32_t)v;
            n += !(w & bit); /* new in this range: a coin toss, no branch */
        }
        len[th] = n;
#pragma omp barrier
#pragma omp single
        {
            int32_t nx = 0;
            for (int t = 0; t < team; t++)
                for (int64_t i = 0; i < len[t]; i++) {
                    int32_t v = list[t][i];
                    int fresh = newid[v] < 0;
                    newid[v] = fresh ? nx : newid[v];
                    nx += fresh;
                }
            *next = nx;
        } /* implied barrier: newid complete */
        for (int64_t k = k0; k < k1; k++)
            c[k] = newid[c[k]];
    }
    for (int t = 0; t < nt; t++)
        free(list[t]);
    free(seen), free(list), free(len);
    return GETME_OK;
}

/* Copy connectivity in internal element order and number the nodes. */
static getme_status number_nodes(getme_ws *ws, const getme_mesh *mesh,
                                 int renumber)
{
    int64_t total = star_total(ws);
    /* ws->conn: order_elements' (its scratch until now) */
    int32_t *newid =
        getme__malloc((size_t)(ws->nn ? ws->nn : 1) * sizeof *newid);
    if (!newid)
        return GETME_ERR_NOMEM;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t i = 0; i < ws->nn; i++)
        newid[i] = renumber ? -1 : i;
    /* The caller's rows in the internal order first, in parallel: a
       gather from scattered places of the caller's array, most of the
       cost when it was done in the serial numbering loop below. */
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = getme__nv[t];
        int32_t e1 = ws->tstart[t + 1];
#pragma omp parallel for schedule(static) num_threads(ws->nt)
        for (int32_t e = ws->tstart[t]; e < e1; e++) {
            /* Each row is a cache and TLB miss in the Morton order (4M
               tets: ~60 ns a row, the loads waited on one at a time), so
               the row ROW_AHEAD places on is fetched now. */
            if (e + ROW_AHEAD < e1) {
                int32_t la;
                const getme_block *ba =
                    getme__find_block(mesh, ws->elem_orig[e + ROW_AHEAD], &la);
                __builtin_prefetch(ba->conn + (int64_t)la * nv);
            }
            int32_t local;
            const getme_block *bl =
                getme__find_block(mesh, ws->elem_orig[e], &local);
            int32_t *dst = ws->conn + ws->coff[t] +
                           (int64_t)(e - ws->tstart[t]) * nv;
            const int32_t *src = bl->conn + (int64_t)local * nv;
            /* a constant size: a few moves, not a call per row */
            if (nv == 4)
                memcpy(dst, src, 4 * sizeof *dst);
            else if (nv == 8)
                memcpy(dst, src, 8 * sizeof *dst);
            else
                memcpy(dst, src, (size_t)nv * sizeof *dst);
        }
    }
    int32_t next = 0;
    int32_t *c = ws->conn;
    /* One thread, the caller's numbering (newid is the identity), or no
       memory for the ranges' lists: the serial stream. */
    int parallel = ws->nt > 1 && renumber &&
                   first_touch_parallel(ws, c, total, newid, &next) == GETME_OK;
    if (!parallel) {
        /* First-touch numbering, serial: a stream over the copied rows
           (the node ids it looks up fetched a little ahead). */
        for (int64_t k = 0; k < total; k++) {
            if (k + 16 < total)
                __builtin_prefetch(newid + c[k + 16]);
            int32_t v = c[k];
            if (newid[v] < 0)
                newid[v] = next++;
            c[k] = newid[v];
        }
    }
    if (renumber) /* nodes used by no element go last, in caller order */
        for (int32_t i = 0; i < ws->nn; i++)
            if (newid[i] < 0)
                newid[i] = next++;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t i = 0; i < ws->nn; i++)
        ws->node_orig[newid[i]] = i;
    free(newid);
    return GETME_OK;
}

static getme_status build_stars(getme_ws *ws)
{
    ws->star_ptr = getme__calloc((size_t)ws->nn + 1, sizeof *ws->star_ptr);
    int64_t total = star_total(ws);
    if (total > INT32_MAX)
        return GETME_ERR_NOMEM; /* star_ptr is 32-bit (workspace.h) */
    ws->star = getme__malloc((size_t)(total ? total : 1) * sizeof *ws->star);
    if (!ws->star_ptr || !ws->star)
        return GETME_ERR_NOMEM;
    /* Each thread owns a range of nodes and walks all the connectivity,
       counting and then filling only its own nodes' stars: no shared
       writes, and each star is filled in ascending element order as by
       one thread.  The node numbers are first-touch in element order
       (number_nodes), so whether an entry is the thread's own is a
       well-predicted branch. */
    const int32_t *conn = ws->conn;
    int32_t *ptr = ws->star_ptr;
#pragma omp parallel num_threads(ws->nt)
    {
        int th = omp_get_thread_num(), team = omp_get_num_threads();
        int32_t n0 = (int32_t)((int64_t)ws->nn * th / team);
        int32_t n1 = (int32_t)((int64_t)ws->nn * (th + 1) / team);
        for (int64_t k = 0; k < total; k++) {
            int32_t v = conn[k];
            if (v >= n0 && v < n1)
                ptr[v + 1]++;
        }
    }
    ws->max_star = 0;
    for (int32_t i = 0; i < ws->nn; i++) {
        int32_t c = ws->star_ptr[i + 1];
        if (c > ws->max_star)
            ws->max_star = c;
        ws->star_ptr[i + 1] += ws->star_ptr[i];
    }
    int32_t *pos = getme__malloc((size_t)(ws->nn ? ws->nn : 1) * sizeof *pos);
    if (!pos)
        return GETME_ERR_NOMEM;
    memcpy(pos, ws->star_ptr, (size_t)ws->nn * sizeof *pos);
    /* Elements in ascending order, so every star comes out sorted. */
#pragma omp parallel num_threads(ws->nt)
    {
        int th = omp_get_thread_num(), team = omp_get_num_threads();
        int32_t n0 = (int32_t)((int64_t)ws->nn * th / team);
        int32_t n1 = (int32_t)((int64_t)ws->nn * (th + 1) / team);
        for (int t = 0; t < GETME_NUM_TYPES; t++) {
            int nv = getme__nv[t];
            for (int32_t e = ws->tstart[t]; e < ws->tstart[t + 1]; e++) {
                const int32_t *c = getme__ws_nodes(ws, t, e);
                for (int i = 0; i < nv; i++)
                    if (c[i] >= n0 && c[i] < n1)
                        ws->star[pos[c[i]]++] = e;
            }
        }
    }
    free(pos);
    return GETME_OK;
}

/* Cut each type range into blocks.  Which blocks may run at the same
   time is the blocks' business (block_local.c: the parts of each level,
   then the blocks left, coloured among themselves). */
static getme_status cut_blocks(getme_ws *ws)
{
    int32_t nb = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int32_t n = ws->tstart[t + 1] - ws->tstart[t];
        nb += (n + BLOCK_SIZE - 1) / BLOCK_SIZE;
    }
    ws->num_blocks = nb;
    ws->block_start = getme__malloc(((size_t)nb + 1) * sizeof *ws->block_start);
    if (!ws->block_start)
        return GETME_ERR_NOMEM;
    int32_t b = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        for (int32_t e = ws->tstart[t]; e < ws->tstart[t + 1]; e += BLOCK_SIZE)
            ws->block_start[b++] = e;
    ws->block_start[nb] = ws->ne;
    return GETME_OK;
}

/* The fixed flags and what follows from them: free elements, free nodes
   (linear, parallel; the counts are sums of integers, so exact). */
static void read_fixed(getme_ws *ws, const getme_mesh *mesh)
{
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t i = 0; i < ws->nn; i++)
        ws->fixed[i] = mesh->fixed[ws->node_orig[i]] != 0;
    int32_t nfe = 0, nfn = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = getme__nv[t];
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    reduction(+ : nfe)
        for (int32_t e = ws->tstart[t]; e < ws->tstart[t + 1]; e++) {
            const int32_t *c = getme__ws_nodes(ws, t, e);
            uint8_t f = 0;
            for (int i = 0; i < nv; i++)
                f |= !ws->fixed[c[i]];
            ws->free_elem[e] = f;
            nfe += f;
        }
    }
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    reduction(+ : nfn)
    for (int32_t i = 0; i < ws->nn; i++)
        nfn += !ws->fixed[i] && ws->star_ptr[i + 1] > ws->star_ptr[i];
    ws->num_free_elem = nfe;
    ws->num_free_nodes = nfn;
}

getme_status getme__ws_build(getme_ws *ws, getme_mesh *mesh, int renumber,
                             int num_threads)
{
    memset(ws, 0, sizeof *ws);
    if (renumber && mesh->ws_cache) {
        /* Built by the boundary search on the same coordinates and
           elements (any change drops it): only the fixed flags are new. */
        *ws = *mesh->ws_cache;
        free(mesh->ws_cache);
        mesh->ws_cache = NULL;
        ws->nt = num_threads > 0 ? num_threads : 1;
        read_fixed(ws, mesh);
        return GETME_OK;
    }
    if (mesh->mirror < 0)
        getme__detect_orientation(mesh);
    ws->dim = mesh->dim;
    ws->nt = num_threads > 0 ? num_threads : 1;
    ws->nn = mesh->num_nodes;
    ws->ne = mesh->num_elements;
    size_t nn = (size_t)(ws->nn ? ws->nn : 1), ne = (size_t)(ws->ne ? ws->ne : 1);
    ws->elem_orig = getme__malloc(ne * sizeof *ws->elem_orig);
    ws->node_orig = getme__malloc(nn * sizeof *ws->node_orig);
    getme_status st = GETME_ERR_NOMEM;
    if (!ws->elem_orig || !ws->node_orig)
        goto fail;
    if ((st = order_elements(ws, mesh, renumber)) != GETME_OK)
        goto fail;
    if ((st = number_nodes(ws, mesh, renumber)) != GETME_OK)
        goto fail;
    st = GETME_ERR_NOMEM;
    ws->x = getme__malloc(nn * 3 * sizeof *ws->x);
    ws->fixed = getme__malloc(nn);
    ws->free_elem = getme__malloc(ne);
    if (!ws->x || !ws->fixed || !ws->free_elem)
        goto fail;
    double ysign = mesh->mirror == 1 ? -1.0 : 1.0;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t i = 0; i < ws->nn; i++) {
        const double *p = mesh->coords + 3 * (int64_t)ws->node_orig[i];
        ws->x[3 * (int64_t)i] = p[0];
        ws->x[3 * (int64_t)i + 1] = ysign * p[1];
        ws->x[3 * (int64_t)i + 2] = p[2];
    }
    if ((st = build_stars(ws)) != GETME_OK)
        goto fail;
    read_fixed(ws, mesh);
    if ((st = cut_blocks(ws)) != GETME_OK)
        goto fail;
    return GETME_OK;
fail:
    getme__ws_free(ws);
    return st;
}

void getme__ws_lend_conn(getme_ws *ws, getme_mesh *mesh)
{
    if (mesh->num_blocks != 1 || ws->ho || mesh->ho)
        return;
    free(mesh->blocks[0].conn);
    mesh->blocks[0].conn = NULL;
    ws->conn_lent = 1;
}

/* Rows of size bytes (at most 3 * GETME_MAX_NV * 8) in place: row e goes
   to row dest[e], a permutation of [0, n).  Follows each cycle, marking
   the rows placed as -1 - dest (restored after): no allocation.  Only the
   fallback of permute_rows: the cycles are chains of dependent cache
   misses (4M tets: 0.6 s). */
static void permute_rows_in_place(void *rows, size_t size, int32_t *dest,
                                  int32_t n)
{
    unsigned char *r = rows;
    unsigned char carry[3 * GETME_MAX_NV * 8], tmp[3 * GETME_MAX_NV * 8];
    for (int32_t e = 0; e < n; e++) {
        if (dest[e] < 0)
            continue;
        memcpy(carry, r + (size_t)e * size, size);
        for (int32_t cur = e;;) {
            int32_t d = dest[cur];
            dest[cur] = -1 - d;
            unsigned char *row = r + (size_t)d * size;
            if (d == e) {
                memcpy(row, carry, size);
                break;
            }
            memcpy(tmp, row, size);
            memcpy(row, carry, size);
            memcpy(carry, tmp, size);
            cur = d;
        }
    }
    for (int32_t e = 0; e < n; e++)
        dest[e] = -1 - dest[e];
}

/* out[dest[e]] = rows[e] for rows of S bytes (a constant in each copy, so
   the copy is a few moves, not a call). */
#define SCATTER_ROWS(S)                                                    \
    _Pragma("omp parallel for schedule(static) num_threads(nt)")           \
    for (int32_t e = 0; e < n; e++)                                        \
        memcpy(out + (size_t)dest[e] * (S), r + (size_t)e * (S), (S))

/* Row e of rows (size bytes, at most 3 * GETME_MAX_NV * 8) goes to row
   dest[e], a permutation of [0, n); returns the permuted array, which
   replaces rows (freed).  Out of place, in parallel: the scattered stores
   are independent, where the in-place cycles are one chain of misses
   (4M tets' connectivity: 0.6 -> 0.05 s).  Callers free the run's arrays
   first, so the copy stays below the smoothing's peak; without memory it
   permutes in place (the same result).  into: NULL, or a malloc'd block
   of n rows to permute into (it is then the result). */
static void *permute_rows(void *rows, size_t size, int32_t *dest, int32_t n,
                          int nt, void *into)
{
    unsigned char *out =
        into ? into : getme__malloc((size_t)(n ? n : 1) * size);
    if (!out) {
        permute_rows_in_place(rows, size, dest, n);
        return rows;
    }
    const unsigned char *r = rows;
    switch (size) {
    case 12: SCATTER_ROWS(12); break;
    case 16: SCATTER_ROWS(16); break;
    case 24: SCATTER_ROWS(24); break;
    case 32: SCATTER_ROWS(32); break;
    default: SCATTER_ROWS(size); break;
    }
    free(rows);
    return out;
}

void getme__ws_return_conn(getme_ws *ws, getme_mesh *mesh)
{
    if (!ws->conn_lent)
        return;
    getme_block *bl = &mesh->blocks[0];
    int nv = getme__nv[bl->type];
    int32_t *c = ws->conn;
    int64_t len = (int64_t)ws->ne * nv;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int64_t k = 0; k < len; k++)
        c[k] = ws->node_orig[c[k]];
    bl->conn = permute_rows(c, (size_t)nv * sizeof *c, ws->elem_orig, ws->ne,
                            ws->nt, NULL);
    ws->conn = NULL;
    ws->conn_lent = 0;
}

void getme__ws_pack_map(getme_ws *ws)
{
    if (ws->maps_packed || !ws->star || ws->ho ||
        star_total(ws) < (int64_t)ws->ne + ws->nn)
        return; /* no room to unpack both without allocating */
    if (!getme__pack(&ws->elem_packed, ws->elem_orig, ws->ne))
        return;
    if (!getme__pack(&ws->node_packed, ws->node_orig, ws->nn)) {
        getme__packed_free(&ws->elem_packed);
        return;
    }
    free(ws->elem_orig), free(ws->node_orig);
    ws->elem_orig = ws->node_orig = NULL;
    ws->maps_packed = 1;
}

void getme__ws_unpack_map(getme_ws *ws)
{
    if (ws->maps_packed != 1)
        return;
    getme__unpack(&ws->elem_packed, ws->star);
    getme__unpack(&ws->node_packed, ws->star + ws->ne);
    ws->elem_orig = ws->star; /* one block: getme__ws_free frees it */
    ws->node_orig = ws->star + ws->ne;
    ws->star = NULL;
    ws->maps_packed = 2;
}

void getme__ws_lend_x(getme_ws *ws, getme_mesh *mesh)
{
    if (!mesh->lend_coords || ws->ho || mesh->ho || ws->x_lent)
        return;
    free(mesh->coords);
    mesh->coords = NULL;
    ws->x_lent = 1;
}

void getme__ws_return_x(getme_ws *ws, getme_mesh *mesh)
{
    if (!ws->x_lent)
        return;
    getme__mesh_drop_ws(mesh); /* its order was made for the old coordinates */
    if (mesh->mirror == 1) /* negating twice is exact: fixed nodes keep
                              their bits */
#pragma omp parallel for schedule(static) num_threads(ws->nt)
        for (int32_t i = 0; i < ws->nn; i++)
            ws->x[3 * (int64_t)i + 1] = -ws->x[3 * (int64_t)i + 1];
    /* into a run's spare array if it left one (its pages are in) */
    double *into = ws->x_spare;
    ws->x_spare = NULL;
    mesh->coords = permute_rows(ws->x, 3 * sizeof *ws->x, ws->node_orig,
                                ws->nn, ws->nt, into);
    ws->x = NULL;
    ws->x_lent = 0;
}

void getme__ws_store(getme_ws *ws, getme_mesh *mesh)
{
    if (ws->x_lent) {
        getme__ws_return_x(ws, mesh);
        return;
    }
    getme__mesh_drop_ws(mesh); /* its order was made for the old coordinates */
    double ysign = mesh->mirror == 1 ? -1.0 : 1.0;
    for (int32_t i = 0; i < ws->nn; i++) {
        if (ws->fixed[i])
            continue; /* fixed nodes are never written: bit-identical */
        double *p = mesh->coords + 3 * (int64_t)ws->node_orig[i];
        p[0] = ws->x[3 * (int64_t)i];
        p[1] = ysign * ws->x[3 * (int64_t)i + 1];
        p[2] = ws->x[3 * (int64_t)i + 2];
    }
    getme__ho_store(ws, mesh);
}

/* GETME_LANES elements at a time through getme__qualities (the lane
   kernels, about 4x faster for hexes) where a group is of one type and the
   mesh is linear; getme__ws_quality one by one otherwise.  The same bits
   either way. */
void getme__ws_qualities(const getme_ws *ws, double *q)
{
    int32_t ngroups = (ws->ne + GETME_LANES - 1) / GETME_LANES;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t j = 0; j < ngroups; j++) {
        int32_t e0 = j * GETME_LANES, e1 = e0 + GETME_LANES;
        int t = getme__ws_type(ws, e0);
        if (!ws->ho && e1 <= ws->tstart[t + 1]) {
            double x[GETME_LANES * 3 * GETME_MAX_NV];
            int nv = getme__nv[t];
            for (int l = 0; l < GETME_LANES; l++)
                getme__ws_gather(ws, ws->x, t, e0 + l, x + 3 * nv * l);
            getme__qualities(t, GETME_LANES, x, q + e0);
        } else {
            for (int32_t e = e0; e < e1 && e < ws->ne; e++)
                q[e] = getme__ws_quality(ws, ws->x, e);
        }
    }
}

/* Exact fixed-point sum (exact.h): the same bits for any thread count and
   any split of the elements; values in [-2, 2], n < 2^31 (its bound). */
getme_ufx getme__det_sum_fx(const double *v, int32_t n, int nt)
{
    getme_ufx s = 0;
    int32_t nb = (n + 4095) / 4096; /* getme__fx_q_sum over 4096 at a time */
#pragma omp parallel num_threads(nt)
    {
        getme_ufx part = 0;
#pragma omp for schedule(static) nowait
        for (int32_t b = 0; b < nb; b++) {
            int32_t i = 4096 * b;
            part += (getme_ufx)getme__fx_q_sum(v + i, n - i < 4096 ? n - i : 4096);
        }
#pragma omp critical(getme_det_sum)
        s += part;
    }
    return s;
}

double getme__det_sum(const double *v, int32_t n, int nt)
{
    return getme__fx_double((getme_fx)getme__det_sum_fx(v, n, nt),
                            GETME_FX_QINV);
}

void getme__ws_summary(const getme_ws *ws, const double *q, double *q_mean,
                       double *q_min_star, double *q_min)
{
    double mn = 1.0, mns = 1.0;
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    reduction(min : mn, mns)
    for (int32_t e = 0; e < ws->ne; e++) {
        double v = q[e];
        mn = v < mn ? v : mn;
        if (ws->free_elem[e])
            mns = v < mns ? v : mns;
    }
    *q_mean = ws->ne ? getme__det_sum(q, ws->ne, ws->nt) / ws->ne : 1.0;
    *q_min_star = mns;
    if (q_min)
        *q_min = mn;
}

double getme__ws_corner_min(const getme_ws *ws)
{
    double m = 1.0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        if (!getme__has_corners(t))
            continue;
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    reduction(min : m)
        for (int32_t e = ws->tstart[t]; e < ws->tstart[t + 1]; e++) {
            double x[3 * GETME_MAX_NV];
            getme__ws_gather(ws, ws->x, t, e, x);
            double s = getme__corner_sj(t, x);
            m = s < m ? s : m;
        }
    }
    return m;
}
