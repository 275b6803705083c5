/*
 * smooth.c -- getme_smooth(): check the input, build the workspace, run a
 * method, write the coordinates back, fill the result.
 */
#include "adjacency.h"
#include "smooth_internal.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

getme_status getme__run_alloc(getme_run *run)
{
    const getme_ws *ws = run->ws;
    size_t nn = (size_t)(ws->nn ? ws->nn : 1), ne = (size_t)(ws->ne ? ws->ne : 1);
    run->q = getme__malloc(ne * sizeof *run->q);
    run->in_t = getme__calloc(nn, 1);
    run->flag = getme__calloc(nn, 1);
    run->ridx = getme__calloc(nn, 1);
    run->eflag = getme__calloc(ne, 1);
    run->nodes = getme__malloc(nn * sizeof *run->nodes);
    run->elems = getme__malloc(ne * sizeof *run->elems);
    run->list = getme__malloc(nn * sizeof *run->list);
    if (!run->q || !run->in_t || !run->flag ||
        !run->ridx || !run->eflag || !run->nodes || !run->elems || !run->list)
        return GETME_ERR_NOMEM;
    return GETME_OK;
}

void getme__run_free(getme_run *run)
{
    free(run->q);
    free(run->in_t);
    free(run->flag);
    free(run->ridx);
    free(run->eflag);
    free(run->nodes);
    free(run->elems);
    free(run->list);
    run->q = NULL, run->in_t = run->flag = run->ridx = run->eflag = NULL;
    run->nodes = run->elems = run->list = NULL;
}

/* Chunked, order-preserving compaction: the same list for any thread
   count. */
#define COLLECT_CHUNK 16384

static int32_t compact(const uint8_t *flag, int32_t n, int32_t *out, int nt)
{
    int32_t nc = (n + COLLECT_CHUNK - 1) / COLLECT_CHUNK;
    int32_t *cnt = getme__malloc(((size_t)nc + 1) * sizeof *cnt);
    if (!cnt) { /* serial fallback gives the same list */
        int32_t m = 0;
        for (int32_t i = 0; i < n; i++)
            if (flag[i])
                out[m++] = i;
        return m;
    }
#pragma omp parallel for schedule(static) num_threads(nt)
    for (int32_t c = 0; c < nc; c++) {
        int32_t end = (c + 1) * COLLECT_CHUNK < n ? (c + 1) * COLLECT_CHUNK : n;
        int32_t m = 0;
        for (int32_t i = c * COLLECT_CHUNK; i < end; i++)
            m += flag[i] != 0;
        cnt[c + 1] = m;
    }
    cnt[0] = 0;
    for (int32_t c = 0; c < nc; c++)
        cnt[c + 1] += cnt[c];
#pragma omp parallel for schedule(static) num_threads(nt)
    for (int32_t c = 0; c < nc; c++) {
        int32_t end = (c + 1) * COLLECT_CHUNK < n ? (c + 1) * COLLECT_CHUNK : n;
        int32_t m = cnt[c];
        for (int32_t i = c * COLLECT_CHUNK; i < end; i++)
            if (flag[i])
                out[m++] = i;
    }
    int32_t total = cnt[nc];
    free(cnt);
    return total;
}

void getme__collect(getme_run *run)
{
    const getme_ws *ws = run->ws;
    run->num_nodes = compact(run->in_t, ws->nn, run->nodes, ws->nt);
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t e = 0; e < ws->ne; e++) {
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        uint8_t f = 0;
        for (int i = 0; i < getme__nv[t]; i++)
            f |= run->in_t[c[i]];
        run->eflag[e] = f;
    }
    run->num_elems = compact(run->eflag, ws->ne, run->elems, ws->nt);
}

void getme__reset_nodes(getme_run *run)
{
    if (run->slot)
        getme__pool_reset(run);
    const int sums = run->facc && !run->slot;
    int32_t end = getme__run_nodes_end(run);
#pragma omp parallel for schedule(static) num_threads(run->ws->nt) \
    if (end > GETME_PAR_MIN)
    for (int32_t k = 0; k < end; k++) {
        int32_t i = getme__run_node(run, k);
        if (i < 0)
            continue;
        run->in_t[i] = 0;
        if (sums) { /* stored as sums again: zero as sums */
            getme_fx *f = run->facc + 4 * (int64_t)i;
            f[0] = f[1] = f[2] = f[3] = 0;
        }
    }
}

int getme__report(getme_run *run, int iteration, getme_stage stage, int cycle,
                  double q_min_star, double q_mean, double threshold,
                  int32_t num_transformed, int32_t num_relaxed)
{
    const getme_params *p = run->params;
    if (!p->progress)
        return 0;
    getme_progress info;
    info.iteration = iteration;
    info.stage = stage;
    info.cycle = cycle;
    info.q_min_star = q_min_star;
    info.q_mean = q_mean;
    info.threshold = threshold;
    info.num_transformed = num_transformed;
    info.num_relaxed = num_relaxed;
    info.elapsed = omp_get_wtime() - run->t0;
    return p->progress(&info, p->progress_data);
}

/* A hex of quality q cannot lower the corner minimum m (corner_min). */
static inline int hex_skipped(double q, double m)
{
    double k = 8.0 * q - 7.0 - 1e-12;
    double lb = k > 0.0 ? k * sqrt(k) : 0.0;
    return lb >= m * (1.0 + 1e-9) + 1e-12;
}

/* corner_min's hex loop in lanes: each thread takes the range
   schedule(static) would give it, in the same order, with the same
   running minimum (the reduction's private copy); the next
   GETME_CORNER_LANES hexes its bound does not skip are computed together,
   and each is then taken or skipped by the same test against the minimum
   at its turn (m only falls, so a hex skipped when the batch was formed
   would be skipped at its turn too).  Every thread's sequence of minima,
   and so the value, is the one hex at a time gave. */
static double hex_corner_min(const getme_ws *ws, const double *q, double m)
{
    int32_t h0 = ws->tstart[GETME_HEX], nh = ws->tstart[GETME_HEX + 1] - h0;
#pragma omp parallel num_threads(ws->nt) reduction(min : m)
    {
        /* libgomp's schedule(static) ranges: the first nh % n threads
           one hex more */
        int32_t th = omp_get_thread_num(), n = omp_get_num_threads();
        int32_t len = nh / n, extra = nh % n;
        int32_t e = h0 + th * len + (th < extra ? th : extra);
        int32_t e1 = e + len + (th < extra);
        enum { L = GETME_CORNER_LANES };
        double x[3 * GETME_MAX_NV * L], s[L];
        int32_t id[L];
        while (e < e1) {
            int nb = 0;
            for (; e < e1 && nb < L; e++)
                if (!hex_skipped(q[e], m))
                    id[nb++] = e;
            for (int l = 0; l < L && nb > 0; l++) {
                /* the unused lanes repeat the first hex */
                const int32_t *c = getme__ws_nodes(ws, GETME_HEX,
                                                   id[l < nb ? l : 0]);
                for (int i = 0; i < 8; i++)
                    for (int d = 0; d < 3; d++)
                        x[(3 * i + d) * L + l] = ws->x[3 * (int64_t)c[i] + d];
            }
            if (nb > 0)
                getme__corner_sj_hex_lanes(x, s);
            for (int l = 0; l < nb; l++)
                if (!hex_skipped(q[id[l]], m))
                    m = s[l] < m ? s[l] : m;
        }
    }
    return m;
}

/* The input must be valid: name the first invalid elements if not. */
/*
 * getme__ws_corner_min's value at qualities q (current at ws->x), without
 * computing the corners of elements whose quality proves them no lower
 * than the smallest corner found so far: a hex's corner mean ratios are
 * <= 1 and average to q, so its worst corner's scaled Jacobian is >=
 * (8q - 7)^(3/2), a quad's >= 4q - 3 (getme_adaptive.c, set_corner_floor;
 * the margins cover roundings).  Such an element cannot lower the
 * minimum, so the value is the same bits; on the full hexes most of them
 * are skipped (q > ~0.93), the rest of the sweep is the same.
 */
static double corner_min(const getme_ws *ws, const double *q)
{
    double m = 1.0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        if (!getme__has_corners(t))
            continue;
        if (t == GETME_HEX) {
            m = hex_corner_min(ws, q, m);
            continue;
        }
        int bounded = t == GETME_QUAD;
        /* m inside the loop is this thread's minimum so far */
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    reduction(min : m)
        for (int32_t e = ws->tstart[t]; e < ws->tstart[t + 1]; e++) {
            if (bounded) {
                double k = 4.0 * q[e] - 3.0 - 1e-12;
                if (k >= m * (1.0 + 1e-9) + 1e-12)
                    continue;
            }
            double x[3 * GETME_MAX_NV];
            getme__ws_gather(ws, ws->x, t, e, x);
            double s = getme__corner_sj(t, x);
            m = s < m ? s : m;
        }
    }
#ifdef GETME_CHECK_SUMS /* test builds: the same as every corner's */
    if (m != getme__ws_corner_min(ws))
        m = NAN;
#endif
    return m;
}

static getme_status check_valid(getme_mesh *mesh, const getme_ws *ws,
                                const double *q)
{
    int64_t bad = 0;
    int32_t first[GETME_MAX_REPORTED_INVALID];
    int nfirst = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (!(q[e] > 0.0))
            bad++;
    if (bad == 0)
        return GETME_OK;
    /* Report in the caller's numbering, smallest indices first (kept
       sorted by insertion; q also counts second-order validity). */
    for (int32_t e = 0; e < ws->ne; e++) {
        if (q[e] > 0.0)
            continue;
        int32_t k = ws->elem_orig[e];
        int i = nfirst < GETME_MAX_REPORTED_INVALID ? nfirst++ : nfirst;
        if (i == GETME_MAX_REPORTED_INVALID && !(k < first[i - 1]))
            continue;
        i = i < GETME_MAX_REPORTED_INVALID ? i : i - 1;
        for (; i > 0 && first[i - 1] > k; i--)
            first[i] = first[i - 1];
        first[i] = k;
    }
    char list[160] = "";
    size_t len = 0;
    for (int i = 0; i < nfirst && len < sizeof list; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%d",
                                i ? ", " : "", (int)first[i]);
    return getme__fail(mesh, GETME_ERR_INVALID_MESH,
                       "%lld invalid (inverted or degenerate) element%s in "
                       "the input, first: %s%s",
                       (long long)bad, bad == 1 ? "" : "s", list,
                       bad > nfirst ? ", ..." : "");
}

/* Untangle an invalid input on the workspace (nothing is stored if some
   element stays invalid: the caller's mesh does not move). */
static getme_status untangle(getme_mesh *mesh, getme_ws *ws, getme_run *run)
{
    getme_untangle_result ur;
    getme_status st = getme__untangle(ws, run->q, &ur);
    run->result->num_invalid_initial = ur.num_invalid_before;
    run->result->untangle_sweeps = ur.sweeps;
    run->result->untangle_seconds = ur.seconds;
    if (st != GETME_OK)
        return getme__fail(mesh, st, "out of memory untangling %d elements",
                           (int)ws->ne);
    return ur.num_invalid_after ? getme__untangle_message(mesh, &ur)
                                : GETME_OK;
}

getme_status getme__start(getme_mesh *mesh, const getme_params **params,
                          getme_params *defaults, getme_ws *ws)
{
    if (!*params) {
        getme_params_init(defaults);
        *params = defaults;
    }
    mesh->error[0] = '\0';
    if (mesh->num_elements == 0)
        return getme__fail(mesh, GETME_ERR_STATE, "the mesh has no elements");
    char problem[160];
    if (getme__params_problem(*params, problem, sizeof problem))
        return getme__fail(mesh, GETME_ERR_ARGUMENT, "parameters: %s", problem);
    int nt = (*params)->num_threads > 0 ? (*params)->num_threads
                                        : omp_get_max_threads();
    getme_status st = getme__ws_build(ws, mesh, (*params)->renumber, nt);
    if (st != GETME_OK)
        return getme__fail(mesh, st, "out of memory building the workspace");
    /* second-order elements: dependent nodes (message on the mesh) */
    if ((st = getme__ho_attach(ws, mesh)) != GETME_OK)
        getme__ws_free(ws);
    return st;
}

getme_status getme__enter(getme_mesh *mesh, const getme_params **params,
                          getme_params *defaults, getme_ws *ws, void *result,
                          size_t size, double *t0, int distributed)
{
    memset(ws, 0, sizeof *ws);
    if (!mesh || !result)
        return GETME_ERR_ARGUMENT;
    memset(result, 0, size);
    *t0 = omp_get_wtime();
    if (distributed && mesh->dim != 3)
        return getme__fail(mesh, GETME_ERR_ARGUMENT,
                           "distributed smoothing needs a volume mesh");
    if (distributed && *params && (*params)->method != GETME_METHOD_ADAPTIVE)
        return getme__fail(mesh, GETME_ERR_ARGUMENT,
                           "distributed smoothing runs GETMe adaptive only");
    return getme__start(mesh, params, defaults, ws);
}

getme_status getme_smooth(getme_mesh *mesh, const getme_params *params,
                          getme_result *result)
{
    getme_params defaults;
    getme_result local;
    double t0;
    getme_ws ws;
    if (!result)
        result = &local;
    getme_status st = getme__enter(mesh, &params, &defaults, &ws, result,
                                   sizeof *result, &t0, 0);
    if (st != GETME_OK)
        return st;
    getme_run run;
    memset(&run, 0, sizeof run);
    getme_adj adj;
    memset(&adj, 0, sizeof adj);
    run.ws = &ws;
    getme__ws_lend_conn(&ws, mesh); /* back at done: */
    if (params->method == GETME_METHOD_ADAPTIVE &&
        (st = getme__adj_build(&adj, &ws)) != GETME_OK) {
        getme__fail(mesh, st, "out of memory for the neighbour sums of %d "
                              "elements", (int)ws.ne);
        goto done;
    }
    run.adj = &adj;
    run.params = params;
    run.result = result;
    run.t0 = t0;
    if ((st = getme__run_alloc(&run)) != GETME_OK) {
        getme__fail(mesh, st, "out of memory for %d nodes, %d elements",
                    (int)ws.nn, (int)ws.ne);
        goto done;
    }
    getme__ws_qualities(&ws, run.q);
    if (params->untangle && (st = untangle(mesh, &ws, &run)) != GETME_OK)
        goto done;
    if ((st = check_valid(mesh, &ws, run.q)) != GETME_OK)
        goto done;
    getme__ws_summary(&ws, run.q, &result->q_mean_initial,
                      &result->q_min_star_initial, NULL);
    result->corner_sj_initial = result->corner_sj = corner_min(&ws, run.q);
    if (ws.num_free_nodes == 0) {
        getme__ws_summary(&ws, run.q, &result->q_mean, &result->q_min_star,
                          &result->q_min);
        result->stop_reason = GETME_STOP_NOTHING_TO_DO;
        goto done;
    }
    getme__ws_lend_x(&ws, mesh); /* the input is checked: back at store */
    getme__ws_pack_map(&ws);     /* unread until the end */
    getme__stars_pack(&ws);      /* read node by node from here on */
    /* second order: each element's node det J ratio floor */
    st = getme__ho_floor_start(&ws);
    if (st != GETME_OK)
        getme__fail(mesh, st, "out of memory for second-order elements");
    else
        st = params->method == GETME_METHOD_SMART_LAPLACE ? getme__laplace(&run)
                                                          : getme__adaptive(&run);
    getme__ws_unpack_map(&ws); /* into the stars' array: no allocation */
    /* run.q is at ws->x after a finished or stopped run */
    if (st == GETME_OK || st == GETME_ERR_CANCELLED)
        result->corner_sj = corner_min(&ws, run.q);
    /* The run's and the sums' arrays are done with: freed before the
       coordinates and the connectivity go back (permuted out of place, so
       below the peak they leave). */
    getme__run_free(&run);
    getme__adj_free(&adj);
    if (st == GETME_OK || st == GETME_ERR_CANCELLED)
        getme__ws_store(&ws, mesh);
    if (st == GETME_ERR_CANCELLED)
        getme__fail(mesh, st, "stopped by the progress callback after "
                              "%d iterations", result->iterations);
    else if (st != GETME_OK)
        getme__fail(mesh, st, "%s", getme_status_string(st));
done:
    getme__ws_unpack_map(&ws);
    getme__ws_return_x(&ws, mesh); /* a failure in the loop: partly smoothed */
    getme__run_free(&run);
    getme__adj_free(&adj);
    getme__ws_return_conn(&ws, mesh); /* after the rest is freed: no peak */
    getme__ws_free(&ws);
    result->seconds = omp_get_wtime() - t0;
    return st;
}
