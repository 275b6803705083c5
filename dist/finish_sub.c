/*
 * finish_sub.c -- getme-mpi's finishing step on the worst elements'
 * patches (docs/distributed.md, "The finishing step on a sub-mesh").
 *
 * Why: the finishing step is serial and touches only the worst elements
 * (finish_fraction of the free ones, at least 64) and the stars of their
 * nodes.  Gathering the whole mesh's positions to rank 0 and running it on
 * a whole-mesh workspace there made rank 0 hold the whole mesh twice; here
 * rank 0 receives only the candidates' patches and the constants of the
 * rest of the mesh, and getme_smooth_finish_sub() gives the same bits.
 *
 *  1. Every rank keys its owned elements (getme_element_key: type, Morton
 *     code of the first node at the input coordinates in the whole mesh's
 *     box, global index) and takes their qualities at the loop's end.
 *  2. Candidates: the free elements up to the quality at position
 *     margin * (k + 1) of all free ones (k: the finishing bound's
 *     position), found with four 16-bit histogram levels summed by
 *     MPI_Allreduce (the bits of a positive double sort like its value).
 *     The margin leaves room for the later passes' bounds.
 *  3. Their nodes (global ids) go to rank 0 and back to everyone, sorted:
 *     those nodes get complete stars.  The sub-mesh is every element with
 *     such a node; its owner sends it (key and node ids), with its nodes
 *     (position, fixed mark) and its rank's rest constants.
 *  4. Rank 0 runs getme_smooth_finish_sub().  If it needs more
 *     (GETME_ERR_INCOMPLETE, decided from the data alone), 2-4 repeat:
 *     with twice as many candidates, at least twice the free elements at
 *     or below the pass bound that did not fit, if that bound is above
 *     the candidates' quality (the next passes' bounds are higher still);
 *     else with one more ring of complete nodes around them (a pass
 *     lowered a neighbour of a moved node below the next pass's bound, so
 *     that neighbour's nodes need complete stars).  With every free
 *     element a candidate and enough rings it
 *     cannot fail (GETME_MPI_FINISH_FIRST=N, for tests, starts with N
 *     candidates).  Then rank 0 broadcasts the nodes that moved and every
 *     rank updates its copies.
 */
#include "dist.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MARGIN0 = 2 };

static void *xmalloc(size_t n) { return malloc(n ? n : 1); }

/* A node of the sub-mesh as sent to rank 0. */
typedef struct sub_node {
    double x[3];
    int32_t gid;
    uint8_t fixed, complete;
} sub_node;

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

static int cmp_node(const void *a, const void *b)
{
    return cmp_i32(&((const sub_node *)a)->gid, &((const sub_node *)b)->gid);
}

/* Index of gid in the ascending ids[0..n), or -1. */
static int64_t find(const int32_t *ids, int64_t n, int32_t gid)
{
    int64_t lo = 0, hi = n - 1;
    while (lo <= hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (ids[mid] == gid)
            return mid;
        if (ids[mid] < gid)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* Every rank's n items of size bytes, concatenated in rank order on rank 0
   (*total items there); NULL elsewhere.  *ok becomes 0 on rank 0 if it
   has no room (the call is still collective). */
static void *gather(dist_ctx *c, const void *mine, int n, size_t size,
                    int *total, int *ok)
{
    int *cnt = NULL, *off = NULL, nb = (int)((size_t)n * size);
    char *all = NULL;
    if (c->rank == 0) {
        cnt = xmalloc((size_t)c->size * sizeof *cnt);
        off = xmalloc((size_t)c->size * sizeof *off);
    }
    MPI_Gather(&nb, 1, MPI_INT, cnt, 1, MPI_INT, 0, c->comm);
    int64_t bytes = 0;
    if (c->rank == 0 && cnt && off) {
        for (int r = 0; r < c->size; r++) {
            off[r] = (int)bytes;
            bytes += cnt[r];
        }
        all = xmalloc((size_t)bytes);
        *total = (int)(bytes / (int64_t)size);
    }
    int room = c->rank != 0 || (all && bytes < 0x7fffffff);
    MPI_Bcast(&room, 1, MPI_INT, 0, c->comm);
    if (room)
        MPI_Gatherv(mine, nb, MPI_BYTE, all, cnt, off, MPI_BYTE, 0, c->comm);
    else {
        free(all);
        all = NULL;
        *ok = 0;
    }
    c->bytes_reduced += nb;
    free(cnt), free(off);
    return all;
}

/* The m-th smallest (0-based) of the values v[i] with use[i] & 1 of all
   ranks (positive doubles: their bits sort like them): per level, a
   histogram of the next 16 bits among the values matching the prefix,
   summed over ranks. */
static double kth_value(dist_ctx *c, const double *v, const uint8_t *use,
                        int32_t n, int64_t m, int64_t *hist)
{
    uint64_t prefix = 0, mask = 0;
    for (int shift = 48; shift >= 0; shift -= 16) {
        memset(hist, 0, 65536 * sizeof *hist);
        for (int32_t i = 0; i < n; i++) {
            uint64_t b;
            memcpy(&b, &v[i], sizeof b);
            if ((use[i] & 1) && (b & mask) == prefix)
                hist[(b >> shift) & 0xffff]++;
        }
        MPI_Allreduce(MPI_IN_PLACE, hist, 65536, MPI_INT64_T, MPI_SUM,
                      c->comm);
        c->bytes_reduced += 65536 * 8;
        int bin = 0;
        while (bin < 65535 && hist[bin] <= m)
            m -= hist[bin++];
        prefix |= (uint64_t)bin << shift;
        mask |= (uint64_t)0xffff << shift;
    }
    double out;
    memcpy(&out, &prefix, sizeof out);
    return out;
}

enum { FREE_OWNED = 1, REST = 2 };

/* What every rank keeps over the tries: 9 bytes per element, 2 per node. */
typedef struct local {
    double *q;         /* ne: owned elements' qualities at the loop's end */
    uint8_t *kind;     /* ne: FREE_OWNED (owned, a free node), REST (owned,
                          outside the sub-mesh)                          */
    uint8_t *flag;     /* nn: node has a complete star in the sub-mesh   */
    uint8_t *mark;     /* nn: scratch                                    */
    double lo[3], hi[3]; /* the whole mesh's box at the input coordinates */
    int keyed;         /* params->renumber: keys carry the Morton code   */
} local;

static void local_free(local *l)
{
    free(l->q), free(l->kind), free(l->flag), free(l->mark);
}

static int nodes_of(const dist_ctx *c, int32_t e)
{
    return getme_type_num_nodes((getme_elem_type)c->etype[e]);
}

/* Step 1: the box and the owned elements' qualities. */
static int local_init(dist_ctx *c, const getme_mesh *part,
                      const getme_mesh *whole, const getme_params *p,
                      local *l, int64_t *num_free)
{
    memset(l, 0, sizeof *l);
    l->q = xmalloc((size_t)c->ne * sizeof *l->q);
    l->kind = xmalloc((size_t)c->ne);
    l->flag = xmalloc((size_t)c->nn);
    l->mark = xmalloc((size_t)c->nn);
    l->keyed = p->renumber != 0;
    /* the whole mesh's box at the input coordinates: the parts' nodes,
       and on rank 0 every node of the mesh it read (unused ones too) */
    double box[6] = {1e308, 1e308, 1e308, 1e308, 1e308, 1e308};
    for (int s = 0; s < 2; s++) {
        const double *x = s ? (whole ? getme_mesh_coords(whole) : NULL)
                            : c->coords;
        int32_t n = s ? (whole ? getme_mesh_num_nodes(whole) : 0) : c->nn;
        for (int32_t i = 0; x && i < n; i++)
            for (int d = 0; d < 3; d++) {
                double v = x[3 * (int64_t)i + d];
                box[d] = v < box[d] ? v : box[d];
                box[3 + d] = -v < box[3 + d] ? -v : box[3 + d];
            }
    }
    MPI_Allreduce(MPI_IN_PLACE, box, 6, MPI_DOUBLE, MPI_MIN, c->comm);
    for (int d = 0; d < 3; d++)
        l->lo[d] = box[d], l->hi[d] = -box[3 + d];
    if (!l->q || !l->kind || !l->flag || !l->mark)
        return -1;
    const double *x = getme_mesh_coords(part);
    *num_free = 0;
    int64_t off = 0;
    for (int32_t e = 0; e < c->ne; off += nodes_of(c, e), e++) {
        int nv = nodes_of(c, e);
        const int32_t *cn = c->conn + off;
        l->q[e] = 0.0;
        l->kind[e] = 0;
        if (!c->owned[e])
            continue;
        double xe[24];
        int free_e = 0;
        for (int i = 0; i < nv; i++) {
            memcpy(xe + 3 * i, x + 3 * (int64_t)cn[i], 3 * sizeof *xe);
            free_e |= !c->fixed[cn[i]];
        }
        l->q[e] = getme_element_quality((getme_elem_type)c->etype[e], xe);
        l->kind[e] = free_e ? FREE_OWNED : 0;
        *num_free += free_e;
    }
    return 0;
}

/* The nodes marked on any rank (l->mark, part order) become l->flag on
   every rank holding them: their global ids gathered on rank 0, sorted,
   deduplicated and broadcast.  -1 on every rank if out of memory. */
static int agree_nodes(dist_ctx *c, local *l, int *ok)
{
    int n = 0;
    for (int32_t i = 0; i < c->nn; i++)
        n += l->mark[i];
    int32_t *ids = xmalloc((size_t)n * sizeof *ids);
    if (!ids)
        *ok = 0, n = 0;
    for (int32_t i = 0, k = 0; ids && i < c->nn; i++)
        if (l->mark[i])
            ids[k++] = c->gid[i];
    int total = 0;
    int32_t *all = gather(c, ids, n, sizeof *ids, &total, ok);
    free(ids);
    if (c->rank == 0 && all) { /* sort, drop repeats */
        qsort(all, (size_t)total, sizeof *all, cmp_i32);
        int u = 0;
        for (int i = 0; i < total; i++)
            if (u == 0 || all[i] != all[u - 1])
                all[u++] = all[i];
        total = u;
    }
    MPI_Bcast(&total, 1, MPI_INT, 0, c->comm);
    if (c->rank != 0)
        all = xmalloc((size_t)total * sizeof *all);
    int have = all != NULL;
    MPI_Allreduce(MPI_IN_PLACE, &have, 1, MPI_INT, MPI_LAND, c->comm);
    if (!have) {
        free(all);
        *ok = 0;
        return -1;
    }
    MPI_Bcast(all, total, MPI_INT32_T, 0, c->comm);
    c->bytes_reduced += (int64_t)total * 4;
    /* both ascending: one merge */
    for (int32_t i = 0, j = 0; i < c->nn; i++) {
        while (j < total && all[j] < c->gid[i])
            j++;
        l->flag[i] = j < total && all[j] == c->gid[i];
    }
    free(all);
    return 0;
}

/* Steps 2-3 on every rank: the candidates up to position m, their nodes
   and `rings - 1` rings of nodes around them agreed on (complete stars),
   this rank's share of the sub-mesh and of the rest.  The element and
   node arrays are returned for sending. */
static int select_sub(dist_ctx *c, const getme_mesh *part, local *l,
                      int64_t m, int rings, int64_t *hist, uint64_t **skey,
                      int32_t **sconn, int *nse, int *nsc, sub_node **snode,
                      int *nsn, getme_finish_rest *rest, double *taken,
                      int *ok)
{
    double bound = kth_value(c, l->q, l->kind, c->ne, m, hist);
    *taken = bound;
    memset(l->mark, 0, (size_t)c->nn);
    int64_t off = 0;
    for (int32_t e = 0; e < c->ne; off += nodes_of(c, e), e++)
        if ((l->kind[e] & FREE_OWNED) && l->q[e] <= bound)
            for (int i = 0; i < nodes_of(c, e); i++)
                l->mark[c->conn[off + i]] = 1;
    for (int ring = 1;; ring++) {
        if (agree_nodes(c, l, ok) != 0)
            return -1;
        if (ring == rings)
            break;
        /* one more ring: the nodes of owned elements touching one (each
           element's owner holds all its nodes) */
        off = 0;
        for (int32_t e = 0; e < c->ne; off += nodes_of(c, e), e++) {
            int in = 0, nv = nodes_of(c, e);
            for (int i = 0; c->owned[e] && i < nv; i++)
                in |= l->flag[c->conn[off + i]];
            for (int i = 0; in && i < nv; i++)
                l->mark[c->conn[off + i]] = 1;
        }
    }

    /* owned elements touching a candidate node: this rank sends them */
    int ne = 0, nc = 0;
    memset(l->mark, 0, (size_t)c->nn);
    off = 0;
    for (int32_t e = 0; e < c->ne; off += nodes_of(c, e), e++) {
        int in = 0, nv = nodes_of(c, e);
        for (int i = 0; i < nv; i++)
            in |= l->flag[c->conn[off + i]];
        l->kind[e] = (uint8_t)((l->kind[e] & FREE_OWNED) |
                               (c->owned[e] && !in ? REST : 0));
        if (!c->owned[e] || !in)
            continue;
        ne++;
        nc += nv;
        for (int i = 0; i < nv; i++)
            l->mark[c->conn[off + i]] = 1;
    }
    int nn = 0;
    for (int32_t i = 0; i < c->nn; i++)
        nn += l->mark[i];
    *skey = xmalloc((size_t)ne * sizeof **skey);
    *sconn = xmalloc((size_t)nc * sizeof **sconn);
    *snode = xmalloc((size_t)nn * sizeof **snode);
    uint8_t *in_rest = xmalloc((size_t)c->ne);
    if (!*skey || !*sconn || !*snode || !in_rest) {
        *ok = 0;
        ne = nc = nn = 0;
    }
    const double *x = getme_mesh_coords(part);
    off = 0;
    for (int32_t e = 0, k = 0, q = 0; ne && e < c->ne;
         off += nodes_of(c, e), e++) {
        if (!c->owned[e] || (l->kind[e] & REST))
            continue;
        const int32_t *cn = c->conn + off;
        (*skey)[k++] = getme_element_key(
            (getme_elem_type)c->etype[e], c->egid[e],
            c->coords + 3 * (int64_t)cn[0], l->keyed ? l->lo : NULL,
            l->keyed ? l->hi : NULL);
        for (int i = 0; i < nodes_of(c, e); i++)
            (*sconn)[q++] = c->gid[cn[i]];
    }
    for (int32_t i = 0, k = 0; nn && i < c->nn; i++)
        if (l->mark[i]) {
            sub_node *s = &(*snode)[k++];
            memset(s, 0, sizeof *s);
            memcpy(s->x, x + 3 * (int64_t)i, sizeof s->x);
            s->gid = c->gid[i];
            s->fixed = c->fixed[i] != 0;
            s->complete = l->flag[i];
        }
    *nse = ne, *nsc = nc, *nsn = nn;
    getme_finish_rest_init(rest);
    for (int32_t e = 0; in_rest && e < c->ne; e++)
        in_rest[e] = (l->kind[e] & REST) != 0;
    if (!in_rest || getme_finish_rest_add(rest, part, in_rest, l->q) !=
                        GETME_OK)
        *ok = 0;
    free(in_rest);
    return 0;
}

/* Rank 0, step 4: the sub-mesh from the gathered pieces, finished. */
static getme_status finish_on_rank0(uint64_t *key, int32_t *conn, int ne,
                                    sub_node *node, int nn,
                                    const getme_finish_rest *rest,
                                    const getme_params *p, getme_result *res,
                                    int32_t **moved_id, double **moved_x,
                                    int *num_moved, char *err, size_t es)
{
    /* elements in key order (keys are unique: they end in the index) */
    int32_t *order = xmalloc((size_t)ne * sizeof *order);
    int64_t *off = xmalloc(((size_t)ne + 1) * sizeof *off);
    uint64_t *skey = xmalloc((size_t)ne * sizeof *skey);
    int32_t *sconn = xmalloc((size_t)ne * 8 * sizeof *sconn);
    int32_t *ids = xmalloc((size_t)nn * sizeof *ids);
    double *x = xmalloc((size_t)nn * 3 * sizeof *x);
    uint8_t *fixed = xmalloc((size_t)nn), *complete = xmalloc((size_t)nn);
    getme_mesh *sub = NULL;
    getme_status st = GETME_ERR_NOMEM;
    snprintf(err, es, "out of memory for the finishing step's sub-mesh");
    if (!order || !off || !skey || !sconn || !ids || !x || !fixed ||
        !complete)
        goto out;
    off[0] = 0;
    for (int e = 0; e < ne; e++) {
        order[e] = e;
        off[e + 1] = off[e] + getme_type_num_nodes(
                                  (getme_elem_type)(key[e] >> 61));
    }
    {
        /* order[] by key: a bottom-up merge sort (qsort would need the
           keys in a global) */
        int32_t *tmp = xmalloc((size_t)ne * sizeof *tmp);
        if (!tmp)
            goto out;
        for (int w = 1; w < ne; w *= 2)
            for (int lo = 0; lo < ne; lo += 2 * w) {
                int mid = lo + w < ne ? lo + w : ne;
                int hi = lo + 2 * w < ne ? lo + 2 * w : ne;
                int a = lo, b = mid, k = lo;
                while (a < mid || b < hi)
                    tmp[k++] = b >= hi || (a < mid && key[order[a]] <=
                                                          key[order[b]])
                                   ? order[a++]
                                   : order[b++];
                memcpy(order + lo, tmp + lo,
                       (size_t)(hi - lo) * sizeof *order);
            }
        free(tmp);
    }
    qsort(node, (size_t)nn, sizeof *node, cmp_node);
    int u = 0;
    for (int i = 0; i < nn; i++) {
        if (u > 0 && node[i].gid == ids[u - 1]) {
            complete[u - 1] |= node[i].complete;
            continue;
        }
        ids[u] = node[i].gid;
        memcpy(x + 3 * (size_t)u, node[i].x, 3 * sizeof *x);
        fixed[u] = node[i].fixed;
        complete[u++] = node[i].complete;
    }
    if ((st = getme_mesh_create(&sub, 3, u, x)) != GETME_OK)
        goto out;
    int64_t q = 0;
    for (int k = 0; k < ne;) { /* runs of one type, in key order */
        int k1 = k;
        getme_elem_type t = (getme_elem_type)(key[order[k]] >> 61);
        int nv = getme_type_num_nodes(t);
        while (k1 < ne && (getme_elem_type)(key[order[k1]] >> 61) == t) {
            skey[k1] = key[order[k1]];
            for (int i = 0; i < nv; i++)
                sconn[q + (int64_t)(k1 - k) * nv + i] =
                    (int32_t)find(ids, u, conn[off[order[k1]] + i]);
            k1++;
        }
        if ((st = getme_mesh_add_elements(sub, t, k1 - k, sconn + q,
                                          NULL)) != GETME_OK) {
            snprintf(err, es, "the finishing step's sub-mesh: %s",
                     getme_mesh_error(sub));
            goto out;
        }
        q += (int64_t)(k1 - k) * nv;
        k = k1;
    }
    if ((st = getme_mesh_set_fixed_mask(sub, fixed)) != GETME_OK)
        goto out;
    st = getme_smooth_finish_sub(sub, p, skey, complete, rest, res);
    if (st == GETME_ERR_INCOMPLETE)
        goto out;
    if (st != GETME_OK) {
        snprintf(err, es, "the finishing step: %s", getme_mesh_error(sub));
        goto out;
    }
    /* the nodes that moved (only complete ones can) */
    const double *y = getme_mesh_coords(sub);
    int m = 0;
    for (int i = 0; i < u; i++)
        m += memcmp(y + 3 * (size_t)i, x + 3 * (size_t)i, 3 * sizeof *y) != 0;
    *moved_id = xmalloc((size_t)m * sizeof **moved_id);
    *moved_x = xmalloc((size_t)m * 3 * sizeof **moved_x);
    if (!*moved_id || !*moved_x) {
        st = GETME_ERR_NOMEM;
        goto out;
    }
    m = 0;
    for (int i = 0; i < u; i++)
        if (memcmp(y + 3 * (size_t)i, x + 3 * (size_t)i, 3 * sizeof *y)) {
            (*moved_id)[m] = ids[i];
            memcpy(*moved_x + 3 * (size_t)m++, y + 3 * (size_t)i,
                   3 * sizeof *y);
        }
    *num_moved = m;
out:
    getme_mesh_free(sub);
    free(order), free(off), free(skey), free(sconn), free(ids), free(x);
    free(fixed), free(complete);
    return st;
}

int dist_finish(dist_ctx *c, getme_mesh *part, const getme_mesh *whole,
                const getme_params *params, getme_result *res, char *err,
                size_t es)
{
    c->sub_elements = c->sub_nodes = 0;
    c->sub_tries = 0;
    if (!params->finish)
        return 0; /* getme_smooth_part's result is final */
    local l;
    int64_t n = 0;
    int64_t *hist = xmalloc(65536 * sizeof *hist);
    int ok = local_init(c, part, whole, params, &l, &n) == 0 && hist;
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, c->comm);
    int32_t *moved_id = NULL;
    double *moved_x = NULL;
    int num_moved = 0, ret = -1;
    snprintf(err, es, "out of memory for the finishing step");
    if (!ok)
        goto out;
    /* the finishing bound's position k among all free elements (finish.c,
       getme__threshold with at least 64) */
    MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT64_T, MPI_SUM, c->comm);
    if (n == 0) {
        ret = 0;
        goto out;
    }
    double pos = params->finish_fraction * (double)n;
    pos = pos < 63.0 ? 63.0 : pos;
    int64_t k = pos >= (double)(n - 1) ? n - 1 : (int64_t)pos;
    /* tests: GETME_MPI_FINISH_FIRST=N starts with N candidates, so that
       the sub-mesh has to grow */
    const char *first = getenv("GETME_MPI_FINISH_FIRST");
    int64_t count = first && atoll(first) > 0 ? atoll(first)
                                               : (k + 1) * MARGIN0;
    double threshold = c->rank == 0 ? res->threshold : 0.0;
    for (int rings = 1;;) {
        int64_t m = count - 1 > n - 1 ? n - 1 : count - 1;
        c->sub_tries++;
        uint64_t *skey = NULL;
        int32_t *sconn = NULL;
        sub_node *snode = NULL;
        int nse = 0, nsc = 0, nsn = 0;
        getme_finish_rest rest;
        double taken;
        if (select_sub(c, part, &l, m, rings, hist, &skey, &sconn, &nse,
                       &nsc, &snode, &nsn, &rest, &taken, &ok) != 0)
            goto out;
        int te = 0, tc = 0, tn = 0, tr = 0;
        uint64_t *akey = gather(c, skey, nse, sizeof *skey, &te, &ok);
        int32_t *aconn = gather(c, sconn, nsc, sizeof *sconn, &tc, &ok);
        sub_node *anode = gather(c, snode, nsn, sizeof *snode, &tn, &ok);
        getme_finish_rest *arest = gather(c, &rest, 1, sizeof rest, &tr, &ok);
        free(skey), free(sconn), free(snode);
        MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, c->comm);
        int status = GETME_OK;
        if (c->rank == 0) {
            if (!ok || !akey || !aconn || !anode || !arest) {
                status = GETME_ERR_NOMEM;
            } else {
                for (int r = 1; r < tr; r++)
                    getme_finish_rest_merge(&arest[0], &arest[r]);
                c->sub_elements = te;
                c->sub_nodes = tn;
                status = finish_on_rank0(akey, aconn, te, anode, tn,
                                         &arest[0], params, res, &moved_id,
                                         &moved_x, &num_moved, err, es);
            }
        }
        free(akey), free(aconn), free(anode), free(arest);
        MPI_Bcast(&status, 1, MPI_INT, 0, c->comm);
        if (status == GETME_ERR_INCOMPLETE && m < n - 1) {
            /* grow (every rank decides alike).  A bound above the
               candidates' quality may have met an element outside: take
               twice the candidates, at least twice the free elements at or
               below it (later passes' bounds are higher).  A bound within
               it can only have met an element without complete stars (a
               neighbour a move lowered): one more ring. */
            double need = res->threshold;
            MPI_Bcast(&need, 1, MPI_DOUBLE, 0, c->comm);
            if (c->rank == 0)
                res->threshold = threshold;
            if (!(need > taken)) {
                rings++;
                continue;
            }
            int64_t below = 0;
            for (int32_t e = 0; e < c->ne; e++)
                below += (l.kind[e] & FREE_OWNED) && l.q[e] <= need;
            MPI_Allreduce(MPI_IN_PLACE, &below, 1, MPI_INT64_T, MPI_SUM,
                          c->comm);
            count = 2 * below > 2 * (m + 1) ? 2 * below : 2 * (m + 1);
            continue;
        }
        if (status != GETME_OK) {
            if (status == GETME_ERR_INCOMPLETE)
                snprintf(err, es, "the finishing step needs more than every "
                                  "free element's patch");
            goto out;
        }
        break;
    }
    /* every copy of a moved node takes its final position */
    MPI_Bcast(&num_moved, 1, MPI_INT, 0, c->comm);
    if (c->rank != 0) {
        moved_id = xmalloc((size_t)num_moved * sizeof *moved_id);
        moved_x = xmalloc((size_t)num_moved * 3 * sizeof *moved_x);
    }
    ok = moved_id && moved_x;
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, c->comm);
    if (!ok)
        goto out;
    MPI_Bcast(moved_id, num_moved, MPI_INT32_T, 0, c->comm);
    MPI_Bcast(moved_x, 3 * num_moved, MPI_DOUBLE, 0, c->comm);
    c->bytes_reduced += (int64_t)num_moved * 28;
    double *x = xmalloc((size_t)c->nn * 3 * sizeof *x);
    ok = x && getme_mesh_get_coords(part, x) == GETME_OK;
    for (int32_t i = 0, j = 0; ok && i < c->nn; i++) { /* both ascending */
        while (j < num_moved && moved_id[j] < c->gid[i])
            j++;
        if (j < num_moved && moved_id[j] == c->gid[i])
            memcpy(x + 3 * (size_t)i, moved_x + 3 * (size_t)j, 3 * sizeof *x);
    }
    ok = ok && getme_mesh_set_coords(part, x) == GETME_OK;
    free(x);
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, c->comm);
    ret = ok ? 0 : -1;
out:
    free(moved_id), free(moved_x), free(hist);
    local_free(&l);
    return ret;
}
