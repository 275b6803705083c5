/*
 * smooth_part.c -- distributed GETMe adaptive (getme.h: getme_comm,
 * getme_smooth_part, getme_smooth_finish; docs/distributed.md).
 *
 * getme_smooth_part() runs the same loop as getme_smooth() on one
 * process's part; the loop (getme_adaptive.c, relax.c) calls the hooks
 * through dist.c wherever a value of the whole mesh is needed.  Results
 * are the single-process ones bit for bit because every sum is exact
 * (exact.h) and every other decision is a minimum, an OR or a count.
 * getme_smooth_finish() runs the serial finishing step on the gathered
 * mesh, on a workspace built from the input coordinates exactly as
 * getme_smooth() builds it (so element order, hence its worst-first
 * order, is the same).
 */
#include "adjacency.h"
#include "smooth_internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Every process learns whether any failed: a collective call, so no
   process waits in a hook for one that has already returned. */
static getme_status agree(const getme_comm *comm, getme_mesh *mesh,
                          getme_status st)
{
    int64_t bad = st != GETME_OK;
    if (comm->sum_i64(comm->ctx, &bad, 1) != 0)
        return getme__fail(mesh, GETME_ERR_COMM, "communication failed");
    if (st == GETME_OK && bad)
        return getme__fail(mesh, GETME_ERR_STATE,
                           "another process failed to set up its part");
    return st;
}

static int comm_complete(const getme_comm *c)
{
    return c && c->owned && c->counted && c->node_order && c->node_sum &&
           c->node_or && c->sum_i64 && c->sum_i128 && c->min;
}

getme_status getme_smooth_part(getme_mesh *mesh, const getme_params *params,
                               const getme_comm *comm, getme_result *result)
{
    getme_params defaults;
    getme_result local;
    if (!mesh || !comm_complete(comm))
        return GETME_ERR_ARGUMENT;
    if (!result)
        result = &local;
    double t0;
    getme_ws ws;
    /* a failure here is agreed on below, with every process */
    getme_status st = getme__enter(mesh, &params, &defaults, &ws, result,
                                   sizeof *result, &t0, 1);
    int have_ws = st == GETME_OK;
    getme_run run;
    memset(&run, 0, sizeof run);
    getme_adj adj;
    memset(&adj, 0, sizeof adj);
    if (st == GETME_OK && (st = getme__adj_build(&adj, &ws)) != GETME_OK)
        getme__fail(mesh, st, "out of memory for the neighbour sums");
    run.ws = &ws;
    run.adj = &adj;
    run.params = params;
    run.result = result;
    run.t0 = t0;
    run.comm = comm;
    if (st == GETME_OK) {
        run.owned = getme__malloc((size_t)(ws.ne ? ws.ne : 1));
        run.counted = getme__malloc((size_t)(ws.nn ? ws.nn : 1));
        if ((st = getme__run_alloc(&run)) != GETME_OK || !run.owned ||
            !run.counted)
            st = getme__fail(mesh, GETME_ERR_NOMEM, "out of memory for %d "
                             "nodes, %d elements", (int)ws.nn, (int)ws.ne);
    }
    if (st == GETME_OK) {
        for (int32_t e = 0; e < ws.ne; e++)
            run.owned[e] = comm->owned[ws.elem_orig[e]] != 0;
        for (int32_t i = 0; i < ws.nn; i++)
            run.counted[i] = comm->counted[ws.node_orig[i]] != 0;
        if (comm->node_order(comm->ctx, ws.nn, ws.node_orig) != 0)
            st = getme__fail(mesh, GETME_ERR_COMM, "communication failed");
    }
    if ((st = agree(comm, mesh, st)) != GETME_OK)
        goto done;

    getme__ws_qualities(&ws, run.q);
    int64_t bad = 0;
    for (int32_t e = 0; e < ws.ne; e++)
        bad += run.owned[e] && !(run.q[e] > 0.0);
    getme__dist_sum_i64(&run, &bad, 1);
    if (run.comm_failed) {
        st = getme__fail(mesh, GETME_ERR_COMM, "communication failed");
        goto done;
    }
    if (bad) {
        st = getme__fail(mesh, GETME_ERR_INVALID_MESH,
                         "%lld invalid (inverted or degenerate) element%s in "
                         "the input: distributed smoothing needs a valid "
                         "mesh (untangle it first)",
                         (long long)bad, bad == 1 ? "" : "s");
        goto done;
    }
    getme__summary(&run, &result->q_mean_initial,
                   &result->q_min_star_initial, NULL);
    double c = getme__ws_corner_min(&ws);
    getme__dist_min(&run, &c, 1);
    result->corner_sj_initial = result->corner_sj = c;
    if (!getme__dist_any(&run, ws.num_free_nodes > 0)) {
        getme__summary(&run, &result->q_mean, &result->q_min_star,
                       &result->q_min);
        result->stop_reason = GETME_STOP_NOTHING_TO_DO;
        st = run.comm_failed ? GETME_ERR_COMM : GETME_OK;
        goto done;
    }
    st = getme__ho_floor_start(&ws); /* second order: ratio floors */
    if (st != GETME_OK)
        getme__fail(mesh, st, "out of memory for second-order elements");
    else
        st = getme__adaptive(&run);
    if (st == GETME_OK || st == GETME_ERR_CANCELLED) {
        c = getme__ws_corner_min(&ws);
        getme__dist_min(&run, &c, 1);
        result->corner_sj = c;
        getme__ws_store(&ws, mesh);
    }
    if (st == GETME_OK && run.comm_failed)
        st = GETME_ERR_COMM;
    if (st != GETME_OK)
        getme__fail(mesh, st, "%s", getme_status_string(st));
done:
    free(run.owned);
    free(run.counted);
    getme__run_free(&run);
    getme__adj_free(&adj);
    if (have_ws)
        getme__ws_free(&ws);
    result->seconds = omp_get_wtime() - t0;
    return st;
}

getme_status getme_smooth_finish(getme_mesh *mesh, const getme_params *params,
                                 const double *xyz, getme_result *result)
{
    getme_params defaults;
    if (!mesh || !xyz || !result)
        return GETME_ERR_ARGUMENT;
    double t0 = omp_get_wtime();
    getme_ws ws;
    getme_status st = getme__start(mesh, &params, &defaults, &ws);
    if (st != GETME_OK)
        return st;
    getme_run run;
    memset(&run, 0, sizeof run);
    run.ws = &ws;
    run.params = params;
    run.result = result;
    run.t0 = t0 - result->seconds;
    /* The input's corner floor, as getme_smooth() measures it. */
    result->corner_sj_initial = getme__ws_corner_min(&ws);
    double ysign = mesh->mirror == 1 ? -1.0 : 1.0;
    for (int32_t i = 0; i < ws.nn; i++) {
        const double *p = xyz + 3 * (int64_t)ws.node_orig[i];
        double *x = ws.x + 3 * (int64_t)i;
        if (ws.fixed[i])
            continue; /* fixed nodes stay as read, bit for bit */
        x[0] = p[0];
        x[1] = ysign * p[1];
        x[2] = p[2];
    }
    if ((st = getme__run_alloc(&run)) != GETME_OK) {
        getme__fail(mesh, st, "out of memory for %d nodes, %d elements",
                    (int)ws.nn, (int)ws.ne);
        goto done;
    }
    getme__ws_qualities(&ws, run.q);
    st = getme__adaptive_finish(&run);
    if (st == GETME_OK || st == GETME_ERR_CANCELLED) {
        result->corner_sj = getme__ws_corner_min(&ws);
        getme__ws_store(&ws, mesh);
    }
    if (st != GETME_OK)
        getme__fail(mesh, st, "%s", getme_status_string(st));
done:
    getme__run_free(&run);
    getme__ws_free(&ws);
    result->seconds += omp_get_wtime() - t0;
    return st;
}
