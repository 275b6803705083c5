/*
 * weights.c -- the node-averaging weight of paper Eq. 9,
 *   w_j = sqrt( mean_{n in N(j)} q_n / q_j ),
 * N(j) = the elements sharing at least one node with E_j, E_j included
 * (it shares all its nodes with itself; the paper's "direct neighbours").
 *
 * The paper stores a neighbour-element table (~80 entries per tet, most of
 * its 1.6 GiB).  We need no table: on conforming meshes the sum comes from
 * per-node, per-edge and per-face sums by inclusion-exclusion
 * (adjacency.h), about 15 loads per tet instead of a walk over ~96 star
 * entries (measured on 190k tets, 1 thread: 236 ns -> 50 ns per weight).
 *
 * Elements where that formula is not exact (adjacency.c finds them once)
 * walk the union of the stars of their nodes instead: a per-thread stamp
 * array (one uint32 per element) tells whether an element of that union
 * was already counted.  That loop is branch-free (the stamp test selects q
 * or 0), which matters: an earlier k-way merge of the sorted stars spent
 * 800 ns per tet on mispredicted branches.
 */
#include "adjacency.h"
#include "smooth_internal.h"

#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <string.h>

/* Room for the union on the stack; a union larger than this (a node with
   hundreds of elements) takes the slower single-pass path. */
#define MAX_UNION 1024

static double union_weight(const getme_ws *ws, const getme_adj *adj,
                           const double *q, int t, int32_t e, getme_stamp *st)
{
    const double qs = adj->qscale;
    const int32_t *c = getme__ws_nodes(ws, t, e);
    int nv = getme__nv[t];
    if (++st->now == 0) { /* wrapped after 2^32 elements: start afresh */
        memset(st->mark, 0, (size_t)ws->ne * sizeof *st->mark);
        st->now = 1;
    }
    const uint32_t now = st->now;
    uint32_t *mark = st->mark;
    int64_t total = 0;
    for (int i = 0; i < nv; i++)
        total += getme__star_bound(ws, c[i]);

    if (total > MAX_UNION) {
        uint64_t sum = 0; /* < nv 2^61: see getme__adj_nsum */
        int32_t count = 0;
        for (int i = 0; i < nv; i++) {
            getme_star_it it = getme__star_open(ws, c[i]);
            for (int32_t n; getme__star_next(&it, &n);) {
                int fresh = mark[n] != now;
                mark[n] = now;
                sum += fresh ? (uint64_t)getme__fx64(q[n], qs) : 0;
                count += fresh;
            }
        }
        return sqrt((double)sum * adj->qinv / ((double)count * q[e]));
    }
    /* Pass 1: the union's members, each once (branch-free append).
       Pass 2: their qualities, summed exactly in fixed point (exact.h), so
       the result equals the inclusion-exclusion formula's (adjacency.h)
       and does not depend on the order of the stars. */
    int32_t u[MAX_UNION];
    int32_t count = 0;
    for (int i = 0; i < nv; i++) {
        getme_star_it it = getme__star_open(ws, c[i]);
        for (int32_t n; getme__star_next(&it, &n);) {
            u[count] = n; /* count < total <= MAX_UNION */
            count += mark[n] != now;
            mark[n] = now;
        }
    }
    uint64_t sum = 0; /* < nv 2^61: see getme__adj_nsum */
    for (int32_t k = 0; k < count; k++)
        sum += (uint64_t)getme__fx64(q[u[k]], qs);
    return sqrt((double)sum * adj->qinv / ((double)count * q[e]));
}

double getme__weight_union(const getme_run *run, int t, int32_t e)
{
    return union_weight(run->ws, run->adj, run->q, t, e,
                        &run->stamps[omp_get_thread_num()]);
}
