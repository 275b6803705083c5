/*
 * weights.c -- the node-averaging weight of paper Eq. 9,
 *   w_j = sqrt( mean_{n in N(j)} q_n / q_j ),
 * N(j) = the elements sharing at least one node with E_j, E_j included
 * (it shares all its nodes with itself; the paper's "direct neighbours").
 *
 * The paper stores a neighbour-element table (~80 entries per tet).  We
 * compute the same sum exactly from the node stars alone: N(j) is the union
 * of the stars of E_j's nodes, and since every star is sorted by element
 * index, a k-way merge visits each element of the union exactly once.
 * Memory stays at the node->element CSR the smoother needs anyway.
 */
#include "smooth_internal.h"

#include <math.h>
#include <stdint.h>

double getme__weight(const getme_ws *ws, const double *q, int t, int32_t e)
{
    const int32_t *c = getme__ws_nodes(ws, t, e);
    int nv = getme__nv[t];
    const int32_t *p[GETME_MAX_NV], *end[GETME_MAX_NV];
    for (int i = 0; i < nv; i++) {
        p[i] = ws->star + ws->star_ptr[c[i]];
        end[i] = ws->star + ws->star_ptr[c[i] + 1];
    }
    double sum = 0.0;
    int32_t count = 0;
    for (;;) {
        int32_t m = INT32_MAX;
        for (int i = 0; i < nv; i++)
            if (p[i] < end[i] && *p[i] < m)
                m = *p[i];
        if (m == INT32_MAX)
            break;
        sum += q[m];
        count++;
        for (int i = 0; i < nv; i++)
            if (p[i] < end[i] && *p[i] == m)
                p[i]++;
    }
    return sqrt(sum / ((double)count * q[e]));
}
