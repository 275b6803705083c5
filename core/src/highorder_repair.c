/*
 * highorder_repair.c -- repair of second-order elements that are invalid
 * only because of their curved non-corner nodes (docs/highorder.md).
 *
 * Untangling moves corners: it cannot repair an element whose corners are
 * valid but whose det J is <= 0 at a mid-node, because a curved mid-node
 * too far from its edge folds the element whatever the corners do.  Such a
 * node is pulled toward its straight position instead: its offset (in the
 * entity's frame, ho->ref, and in the input coordinates, ho->x0) is halved,
 * round after round: in each element still invalid with valid corners, that
 * of its free curved dependent node farthest (relative to its edge or face)
 * from its straight position, until no such element is left or 64 rounds
 * (2^-64 of the offset: straight to rounding) are done.  An element found
 * invalid is pulled on until the ratio of its smallest to its largest
 * det J at the nodes is GETME_HO_RATIO_FLOOR, 0.1 (Gmsh's default target
 * for its own high-order optimizer, Mesh.HighOrderThresholdMin, and the
 * floor smoothing then keeps, highorder.h) or its free nodes are
 * straight: stopping as soon as it is valid left elements valid by a
 * rounding (ratio 0.0000 on a sphere whose mid-nodes were displaced, five
 * of them below 1e-6 by Gmsh's measure), which no solver accepts.
 * Elements valid in the input are not touched.  Pinned nodes
 * (skin, fixed edges and faces, fixed groups) never move.
 *
 * Only the first round looks at every element (in parallel: the test is
 * read-only); a later round looks only at the elements that hold a node
 * the round before moved.  The others would give the same answer as
 * before: a round moves dependent nodes only, and an element's test
 * reads its corners, which never move here, and its own dependent nodes.
 * An element that needed repair and marked a node is looked at again,
 * since it holds that node; one that needed repair but had no node to
 * pull marks nothing, then as now.  (Every round over all 1M elements of
 * the curved tet10 benchmark took 15 s of serial tests for 16 elements.)
 * The marks are taken in element order and the nodes moved in index
 * order, so the result does not depend on the thread count.
 */
#include "highorder.h"
#include "workspace.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define REPAIR_ROUNDS 64

static int corners_valid(const getme_ws *ws, int32_t e)
{
    double x[3 * GETME_MAX_NV];
    int t = getme__ws_type(ws, e);
    getme__ws_gather(ws, ws->x, t, e, x);
    return getme__quality(t, x) > 0.0;
}

static void straight_of(const getme_ho_ws *ho, int32_t h, double *s)
{
    const int32_t *c = ho->cn + 8 * (int64_t)h;
    s[0] = s[1] = s[2] = 0.0;
    for (int i = 0; i < ho->nc[h]; i++)
        for (int d = 0; d < 3; d++)
            s[d] += ho->x0[3 * (int64_t)c[i] + d];
    for (int d = 0; d < 3; d++)
        s[d] /= ho->nc[h];
}

/* |x0 - S| / |corner 1 - corner 0| of dependent node h. */
static double rel_offset(const getme_ho_ws *ho, int32_t h)
{
    const int32_t *c = ho->cn + 8 * (int64_t)h;
    const double *x = ho->x0 + 3 * (int64_t)ho->node[h];
    const double *a = ho->x0 + 3 * (int64_t)c[0], *b = ho->x0 + 3 * (int64_t)c[1];
    double s[3], o = 0.0, l = 0.0;
    straight_of(ho, h, s);
    for (int d = 0; d < 3; d++)
        o += (x[d] - s[d]) * (x[d] - s[d]), l += (b[d] - a[d]) * (b[d] - a[d]);
    return l > 0.0 ? sqrt(o / l) : 0.0;
}

/* Invalid at a node with valid corners; or found so before (was_bad) and
   not yet GETME_HO_RATIO_FLOOR. */
static int needs_repair(const getme_ws *ws, int32_t e, int was_bad)
{
    return ws->ho->etype[e] >= 0 && corners_valid(ws, e) &&
           (was_bad ? getme__ho_ratio(ws, ws->x, e) < GETME_HO_RATIO_FLOOR
                    : !getme__ho_valid(ws, ws->x, e));
}

getme_status getme__ho_repair(getme_ws *ws, int32_t *num_found,
                              int32_t *num_elements, int32_t *num_nodes)
{
    getme_ho_ws *ho = ws->ho;
    *num_found = 0;
    *num_elements = 0;
    *num_nodes = 0;
    if (!ho)
        return GETME_OK;
    uint8_t *mark = getme__calloc((size_t)ho->nh + 1, 1);
    uint8_t *moved = getme__calloc((size_t)ho->nh + 1, 1);
    uint8_t *bad = getme__calloc((size_t)ws->ne + 1, 1);
    /* look[e]: test element e this round (all in the first) */
    uint8_t *look = getme__malloc((size_t)ws->ne + 1);
    if (!mark || !moved || !bad || !look) {
        free(mark), free(moved), free(bad), free(look);
        return GETME_ERR_NOMEM;
    }
    memset(look, 1, (size_t)ws->ne + 1);
    for (int round = 0; round < REPAIR_ROUNDS; round++) {
        int any = 0;
        /* the tests, in parallel (read-only); look[e] becomes the answer */
#pragma omp parallel for schedule(dynamic, 4096) num_threads(ws->nt)
        for (int32_t e = 0; e < ws->ne; e++)
            if (look[e])
                look[e] = (uint8_t)needs_repair(ws, e, bad[e]);
        memset(mark, 0, (size_t)ho->nh);
        for (int32_t e = 0; e < ws->ne; e++) {
            if (!look[e])
                continue;
            bad[e] = 1;
            /* the free node farthest from its straight position, relative
               to its entity's size: the culprit (a straight node has no
               offset to reduce; nodes a rounding off it are not touched) */
            int32_t best = -1;
            double far = 0.0;
            for (int64_t j = ho->eptr[e]; j < ho->eptr[e + 1]; j++) {
                int32_t h = ho->eho[j];
                double r = rel_offset(ho, h);
                if (!ho->pinned[h] && !ho->straight[h] && r > far)
                    best = h, far = r;
            }
            if (best >= 0 && !mark[best])
                mark[best] = 1, any = 1;
        }
        if (!any)
            break;
        for (int32_t h = 0; h < ho->nh; h++) {
            if (!mark[h])
                continue;
            moved[h] = 1;
            /* the offset is linear in the node's position for fixed
               corners, so halving ref halves x0 - S(x0) */
            double s[3];
            straight_of(ho, h, s);
            int64_t u = ho->node[h];
            for (int d = 0; d < 3; d++) {
                double p = s[d] + 0.5 * (ho->x0[3 * u + d] - s[d]);
                ho->x0[3 * u + d] = p;
                ws->x[3 * u + d] = p;
                ho->ref[3 * (int64_t)h + d] *= 0.5;
            }
        }
        /* next round: the elements that hold a node moved in this one */
#pragma omp parallel for schedule(static) num_threads(ws->nt)
        for (int32_t e = 0; e < ws->ne; e++) {
            uint8_t l = 0;
            for (int64_t j = ho->eptr[e]; j < ho->eptr[e + 1]; j++)
                l |= mark[ho->eho[j]];
            look[e] = l;
        }
    }
    for (int32_t h = 0; h < ho->nh; h++)
        *num_nodes += moved[h];
    for (int32_t e = 0; e < ws->ne; e++) {
        *num_found += bad[e];
        *num_elements += bad[e] && getme__ho_valid(ws, ws->x, e);
    }
    free(mark), free(moved), free(bad), free(look);
    return GETME_OK;
}
