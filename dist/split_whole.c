/*
 * split_whole.c -- the per-rank input's finishing step, for now on rank 0
 * (docs/distributed.md §3, "Finishing (interim)"): rank 0 gathers the
 * whole mesh (nodes by tag, elements by tag: the unpartitioned file's
 * order), the loop's positions, and sends every rank the final positions
 * of its nodes.  The finishing step on gathered patches replaces this
 * file's three calls.
 */
#include "dist.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef dist_node node_rec;

/* ---- the whole mesh on rank 0, for the finishing step -------------------- */

/* Gather int64 records of every rank on rank 0 (*all, *n words there). */
static void gather(dist_ctx *c, const int64_t *mine, int64_t n, int64_t **all,
                   int64_t *total)
{
    int cnt = (int)n, *counts = NULL, *displs = NULL;
    if (n > INT32_MAX)
        dist_stop("a part too large to gather");
    if (c->rank == 0) {
        counts = dist_xalloc((size_t)c->size * sizeof *counts);
        displs = dist_xalloc((size_t)c->size * sizeof *displs);
    }
    MPI_Gather(&cnt, 1, MPI_INT, counts, 1, MPI_INT, 0, c->comm);
    *total = 0;
    for (int q = 0; c->rank == 0 && q < c->size; q++) {
        displs[q] = (int)*total;
        *total += counts[q];
        if (*total > INT32_MAX)
            dist_stop("a mesh too large to gather on rank 0");
    }
    *all = c->rank == 0 ? dist_xalloc((size_t)*total * sizeof **all) : NULL;
    MPI_Gatherv(mine, cnt, MPI_INT64_T, *all, counts, displs, MPI_INT64_T, 0,
                c->comm);
    free(counts), free(displs);
}

static int cmp_elem(const void *a, const void *b)
{
    const int64_t *x = *(int64_t *const *)a, *y = *(int64_t *const *)b;
    return (x[0] > y[0]) - (x[0] < y[0]);
}

/* Rank 0 builds the whole mesh as getme smooth reads the unpartitioned
   file: nodes in ascending tag, elements in ascending tag (Gmsh numbers
   both in its file order), the fixed marks agreed above.  The other ranks
   send their own elements and the nodes they count. */
int dist_split_whole(dist_split *s, dist_ctx *c, char *msg, size_t size)
{
    int64_t words = 0, nc = 0;
    for (int32_t e = 0; e < s->own_ne; e++)
        words += 3 + s->elem[e].nv;
    for (int32_t i = 0; i < s->nn; i++)
        nc += c->counted[i];
    int64_t *mine = dist_xalloc((size_t)(words + 5 * nc) * sizeof *mine), w = 0;
    for (int32_t i = 0; i < s->nn; i++)
        if (c->counted[i]) {
            mine[w++] = (int64_t)s->node[i].tag;
            memcpy(mine + w, s->node[i].x, 3 * sizeof *mine);
            w += 3;
            mine[w++] = s->node[i].fixed;
        }
    int64_t *nodes = NULL, *elems = NULL, nw = 0, ew = 0;
    gather(c, mine, w, &nodes, &nw);
    w = 0;
    for (int32_t e = 0; e < s->own_ne; e++) {
        const dist_elem *el = &s->elem[e];
        mine[w++] = el->tag;
        mine[w++] = el->type;
        mine[w++] = el->nv;
        for (int j = 0; j < el->nv; j++)
            mine[w++] = (int64_t)el->node[j];
    }
    gather(c, mine, w, &elems, &ew);
    free(mine);
    free(s->elem), free(s->optr), free(s->orank); /* the set-up's tables */
    s->elem = NULL, s->optr = NULL, s->orank = NULL;
    if (c->rank != 0)
        return 0;
    int rc = -1;
    int64_t nn = nw / 5, ne = 0;
    for (int64_t at = 0; at < ew; at += 3 + elems[at + 2])
        ne++;
    node_rec *nd = dist_xalloc((size_t)nn * sizeof *nd);
    int64_t **ep = dist_xalloc((size_t)ne * sizeof *ep);
    for (int64_t i = 0; i < nn; i++) {
        nd[i].tag = (uint64_t)nodes[5 * i];
        memcpy(nd[i].x, nodes + 5 * i + 1, sizeof nd[i].x);
        nd[i].fixed = nodes[5 * i + 4];
    }
    free(nodes);
    qsort(nd, (size_t)nn, sizeof *nd, dist_cmp_node);
    ne = 0;
    for (int64_t at = 0; at < ew; at += 3 + elems[at + 2])
        ep[ne++] = elems + at;
    qsort(ep, (size_t)ne, sizeof *ep, cmp_elem);
    s->whole_nn = (int32_t)nn;
    s->whole_tag = dist_xalloc((size_t)nn * sizeof *s->whole_tag);
    double *xyz = dist_xalloc((size_t)nn * 3 * sizeof *xyz);
    uint8_t *fixed = dist_xalloc((size_t)nn);
    int32_t *conn = dist_xalloc((size_t)(ew ? ew : 1) * sizeof *conn);
    for (int64_t i = 0; i < nn; i++) {
        s->whole_tag[i] = nd[i].tag;
        memcpy(xyz + 3 * i, nd[i].x, 3 * sizeof *xyz);
        fixed[i] = nd[i].fixed != 0;
    }
    free(nd);
    getme_status st = getme_mesh_create(&s->whole, 3, (int32_t)nn, xyz);
    for (int64_t e = 0; e < ne && st == GETME_OK;) {
        int64_t e1 = e, m = 0;
        while (e1 < ne && ep[e1][1] == ep[e][1]) { /* a run of one type */
            for (int j = 0; j < ep[e1][2]; j++)
                conn[m++] = whole_index(s, (uint64_t)ep[e1][3 + j]);
            e1++;
        }
        st = getme_mesh_add_elements(s->whole, (getme_elem_type)ep[e][1],
                                     (int32_t)(e1 - e), conn, NULL);
        e = e1;
    }
    if (st == GETME_OK)
        st = getme_mesh_set_fixed_mask(s->whole, fixed);
    if (st == GETME_OK)
        rc = 0;
    else
        snprintf(msg, size, "the whole mesh for the finishing step: %s",
                 s->whole ? getme_mesh_error(s->whole)
                          : getme_status_string(st));
    free(ep), free(elems), free(xyz), free(fixed), free(conn);
    return rc;
}

/* The counted nodes' positions (the part's, after getme_smooth_part) into
   xyz on rank 0 (3 per whole-mesh node; the input's for the others). */
void dist_split_gather(dist_split *s, dist_ctx *c, const double *part_xyz,
                       double *xyz)
{
    int64_t n = 0;
    for (int32_t i = 0; i < s->nn; i++)
        n += c->counted[i];
    int64_t *mine = dist_xalloc((size_t)n * 4 * sizeof *mine), w = 0, *all, tw;
    for (int32_t i = 0; i < s->nn; i++)
        if (c->counted[i]) {
            mine[w++] = (int64_t)s->node[i].tag;
            memcpy(mine + w, part_xyz + 3 * (size_t)i, 3 * sizeof *mine);
            w += 3;
        }
    gather(c, mine, w, &all, &tw);
    free(mine);
    for (int64_t k = 0; c->rank == 0 && k < tw; k += 4)
        memcpy(xyz + 3 * (size_t)whole_index(s, (uint64_t)all[k]),
               all + k + 1, 3 * sizeof *xyz);
    free(all);
}

/* ---- writing ------------------------------------------------------------ */

/* Rank 0's final coordinates into every rank's node table (by tag), from
   which its output parts are written. */
void dist_split_scatter(dist_split *s, dist_ctx *c, const double *xyz)
{
    int64_t n = s->nn;
    int64_t *tags = dist_xalloc((size_t)n * sizeof *tags), *all, total;
    for (int32_t i = 0; i < s->nn; i++)
        tags[i] = (int64_t)s->node[i].tag;
    gather(c, tags, n, &all, &total);
    /* rank 0 answers in the same layout: 3 doubles per tag */
    int cnt = (int)(3 * n), *counts = NULL, *displs = NULL;
    double *ans = NULL, *mine = dist_xalloc((size_t)n * 3 * sizeof *mine);
    if (c->rank == 0) {
        counts = dist_xalloc((size_t)c->size * sizeof *counts);
        displs = dist_xalloc((size_t)c->size * sizeof *displs);
        ans = dist_xalloc((size_t)total * 3 * sizeof *ans);
        for (int64_t i = 0; i < total; i++)
            memcpy(ans + 3 * i,
                   xyz + 3 * (size_t)whole_index(s, (uint64_t)all[i]),
                   3 * sizeof *ans);
    }
    MPI_Gather(&cnt, 1, MPI_INT, counts, 1, MPI_INT, 0, c->comm);
    for (int q = 0, at = 0; c->rank == 0 && q < c->size; q++) {
        displs[q] = at;
        at += counts[q];
    }
    MPI_Scatterv(ans, counts, displs, MPI_DOUBLE, mine, cnt, MPI_DOUBLE, 0,
                 c->comm);
    for (int32_t i = 0; i < s->nn; i++)
        memcpy(s->node[i].x, mine + 3 * (size_t)i, sizeof s->node[i].x);
    free(tags), free(all), free(counts), free(displs), free(ans), free(mine);
}

