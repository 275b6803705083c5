/*
 * distort.c -- validity-preserving random node moves, to make test and
 * benchmark meshes like the paper's distorted inputs.  Serial on purpose:
 * each move is checked against the moves before it, and the sequence of
 * random numbers must not depend on threads.
 */
#include "workspace.h"

#include <math.h>
#include <stdlib.h>

/* splitmix64: small, fast, good enough for test distortions. */
static uint64_t next_u64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double uniform(uint64_t *s) /* in [-1, 1) */
{
    return (double)(next_u64(s) >> 11) * 0x1.0p-52 - 1.0;
}

/* Below this quality a move is refused: other tools' arithmetic could call
   such a sliver inverted, and the benchmark wants hard but valid input. */
#define MIN_QUALITY 1e-4

static double shortest_edge(const getme_ws *ws, int32_t i)
{
    const double *p = ws->x + 3 * (int64_t)i;
    double h2 = INFINITY;
    for (int64_t k = ws->star_ptr[i]; k < ws->star_ptr[i + 1]; k++) {
        int32_t e = ws->star[k];
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int j = 0; j < getme__nv[t]; j++) {
            if (c[j] == i)
                continue;
            const double *o = ws->x + 3 * (int64_t)c[j];
            double d2 = (o[0] - p[0]) * (o[0] - p[0]) +
                        (o[1] - p[1]) * (o[1] - p[1]) +
                        (o[2] - p[2]) * (o[2] - p[2]);
            h2 = d2 < h2 ? d2 : h2;
        }
    }
    return sqrt(h2);
}

static int star_ok(const getme_ws *ws, int32_t i)
{
    for (int64_t k = ws->star_ptr[i]; k < ws->star_ptr[i + 1]; k++)
        if (!(getme__ws_quality(ws, ws->x, ws->star[k]) > MIN_QUALITY))
            return 0;
    return 1;
}

static void move_node(getme_ws *ws, int32_t i, double amount, uint64_t *rng)
{
    double *p = ws->x + 3 * (int64_t)i;
    double v[3], r2;
    int planar = ws->dim == 2;
    do { /* uniform in the unit ball (disk for planar meshes) */
        v[0] = uniform(rng);
        v[1] = uniform(rng);
        v[2] = planar ? 0.0 : uniform(rng);
        r2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    } while (r2 > 1.0 || r2 == 0.0);
    double h = amount * shortest_edge(ws, i);
    double old[3] = {p[0], p[1], p[2]};
    for (int attempt = 0; attempt < 4; attempt++, h *= 0.5) {
        for (int d = 0; d < 3; d++)
            p[d] = old[d] + h * v[d];
        if (star_ok(ws, i))
            return;
    }
    p[0] = old[0], p[1] = old[1], p[2] = old[2];
}

getme_status getme_mesh_distort(getme_mesh *mesh, uint64_t seed, double amount,
                                double target_q_mean, int max_rounds)
{
    if (!mesh || !(amount > 0.0) || !isfinite(amount) || max_rounds < 0)
        return GETME_ERR_ARGUMENT;
    getme_ws ws;
    getme_status st = getme__ws_build(&ws, mesh, 0, 1);
    if (st != GETME_OK)
        return getme__fail(mesh, st, "out of memory");
    if ((st = getme__ho_attach(&ws, mesh)) != GETME_OK) {
        getme__ws_free(&ws);
        return st;
    }
    double *q = getme__malloc((size_t)(ws.ne ? ws.ne : 1) * sizeof *q);
    if (!q) {
        getme__ws_free(&ws);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    getme__ws_qualities(&ws, q);
    for (int32_t e = 0; e < ws.ne; e++)
        if (!(q[e] > 0.0)) {
            /* the caller's index, read before the workspace is freed */
            int32_t orig = ws.elem_orig[e];
            free(q);
            getme__ws_free(&ws);
            return getme__fail(mesh, GETME_ERR_INVALID_MESH,
                               "element %d is invalid before distortion",
                               (int)orig);
        }
    uint64_t rng = seed;
    for (int round = 0; round < max_rounds; round++) {
        double q_mean, q_min;
        getme__ws_summary(&ws, q, &q_mean, &q_min, NULL);
        if (target_q_mean > 0.0 && q_mean <= target_q_mean)
            break;
        for (int32_t i = 0; i < ws.nn; i++)
            if (getme__ws_moves(&ws, i))
                move_node(&ws, i, amount, &rng);
        getme__ws_qualities(&ws, q);
    }
    getme__ws_store(&ws, mesh);
    free(q);
    getme__ws_free(&ws);
    return GETME_OK;
}
