/*
 * laplace.c -- smart Laplace, the paper's baseline (Sec. 3.1), in its
 * parallel, order-independent form: every free node computes the mean of
 * its edge neighbours from the old positions and keeps it only if the mean
 * quality of its incident elements improves (the others staying put); all
 * accepted moves are applied together and nodes of elements that became
 * invalid are reset (relaxation table (1, 0)).  Stops when an iteration
 * gains less than tol in q_mean.
 */
#include "smooth_internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Local edges of each type (pairs of local node indices). */
static const int8_t EDGES_TET[] = {0, 1, 1, 2, 2, 0, 0, 3, 1, 3, 2, 3};
static const int8_t EDGES_HEX[] = {0, 1, 1, 2, 2, 3, 3, 0, 4, 5, 5, 6,
                                   6, 7, 7, 4, 0, 4, 1, 5, 2, 6, 3, 7};
static const int8_t EDGES_PRISM[] = {0, 1, 1, 2, 2, 0, 3, 4, 4,
                                     5, 5, 3, 0, 3, 1, 4, 2, 5};
static const int8_t EDGES_PYR[] = {0, 1, 1, 2, 2, 3, 3, 0,
                                   0, 4, 1, 4, 2, 4, 3, 4};
static const int8_t EDGES_TRI[] = {0, 1, 1, 2, 2, 0};
static const int8_t EDGES_QUAD[] = {0, 1, 1, 2, 2, 3, 3, 0};

static const int8_t *const EDGES[GETME_NUM_TYPES] = {
    EDGES_TET, EDGES_HEX, EDGES_PRISM, EDGES_PYR, EDGES_TRI, EDGES_QUAD};
static const int NUM_EDGES[GETME_NUM_TYPES] = {6, 12, 9, 8, 3, 4};

/* Mean of the distinct edge neighbours of node i into m; buf has room for
   every neighbour entry of the star. */
static void neighbour_mean(const getme_ws *ws, int32_t i, int32_t *buf,
                           double *m)
{
    int32_t n = 0;
    getme_star_it it = getme__star_open(ws, i);
    for (int32_t e; getme__star_next(&it, &e);) {
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int j = 0; j < NUM_EDGES[t]; j++) {
            int32_t a = c[EDGES[t][2 * j]], b = c[EDGES[t][2 * j + 1]];
            int32_t other = a == i ? b : b == i ? a : -1;
            if (other < 0)
                continue;
            int seen = 0;
            for (int32_t s = 0; s < n && !seen; s++)
                seen = buf[s] == other;
            if (!seen)
                buf[n++] = other;
        }
    }
    m[0] = m[1] = m[2] = 0.0;
    for (int32_t s = 0; s < n; s++)
        for (int d = 0; d < 3; d++)
            m[d] += ws->x[3 * (int64_t)buf[s] + d];
    for (int d = 0; d < 3; d++)
        m[d] /= (double)n;
}

/* Mean quality of node i's elements with i placed at p (others fixed). */
static double star_quality_at(const getme_ws *ws, int32_t i, const double *p)
{
    double sum = 0.0;
    int32_t n = 0;
    getme_star_it it = getme__star_open(ws, i);
    for (int32_t e; getme__star_next(&it, &e); n++) {
        int t = getme__ws_type(ws, e);
        double x[3 * GETME_MAX_NV];
        getme__ws_gather(ws, ws->x, t, e, x);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int j = 0; j < getme__nv[t]; j++)
            if (c[j] == i)
                x[3 * j] = p[0], x[3 * j + 1] = p[1], x[3 * j + 2] = p[2];
        sum += getme__quality(t, x);
    }
    return sum / (double)n;
}

/* Candidate moves of all free nodes into phat / in_t; returns the count. */
static int32_t propose(getme_run *run, int32_t *scratch, int32_t per_thread)
{
    const getme_ws *ws = run->ws;
    int32_t accepted = 0;
#pragma omp parallel num_threads(ws->nt) reduction(+ : accepted)
    {
        int32_t *buf = scratch + (int64_t)omp_get_thread_num() * per_thread;
#pragma omp for schedule(static)
        for (int32_t i = 0; i < ws->nn; i++) {
            if (!getme__ws_moves(ws, i))
                continue;
            double m[3];
            neighbour_mean(ws, i, buf, m);
            double before = 0.0;
            int32_t n = 0;
            getme_star_it it = getme__star_open(ws, i);
            for (int32_t e; getme__star_next(&it, &e); n++)
                before += run->q[e];
            before /= (double)n;
            if (star_quality_at(ws, i, m) > before) {
                memcpy(run->phat + i * run->phat_step, m, sizeof m);
                run->in_t[i] = 1;
                accepted++;
            }
        }
    }
    return accepted;
}

getme_status getme__laplace(getme_run *run)
{
    getme_ws *ws = run->ws;
    const getme_params *p = run->params;
    getme_result *res = run->result;
    /* A node has at most 4 edge neighbours per incident element (pyramid
       apex), hence 4 * max_star entries per thread. */
    int32_t per_thread = 4 * (ws->max_star > 0 ? ws->max_star : 1);
    int32_t *scratch =
        getme__malloc((size_t)ws->nt * per_thread * sizeof *scratch);
    run->phat_step = 6 * sizeof(double); /* p-hat, old coordinates */
    run->phat =
        getme__malloc((size_t)(ws->nn ? ws->nn : 1) * (size_t)run->phat_step);
    if (!scratch || !run->phat) {
        free(scratch);
        free(run->phat);
        run->phat = NULL;
        return GETME_ERR_NOMEM;
    }
    static const double R[2] = {1.0, 0.0};
    double q_mean = res->q_mean_initial, q_min = res->q_min_star_initial;
    getme_status st = GETME_OK;
    res->stop_reason = GETME_STOP_MAX_ITER;
    for (int it = 1; it <= p->max_iter; it++) {
        int32_t moved = propose(run, scratch, per_thread);
        getme__collect(run);
        int32_t reset = getme__relax(run, R, 2);
        if (reset < 0) { /* test builds: the relaxed counts differ */
            st = GETME_ERR_STATE;
            break;
        }
        getme__reset_nodes(run);
        double prev_mean = q_mean;
        getme__ws_summary(ws, run->q, &q_mean, &q_min, NULL);
        res->iterations = res->iterations_mean = it;
        if (getme__report(run, it, GETME_STAGE_LAPLACE, 0, q_min, q_mean, 1.0,
                          moved, reset)) {
            res->stop_reason = GETME_STOP_CANCELLED;
            st = GETME_ERR_CANCELLED;
            break;
        }
        if (q_mean - prev_mean < p->tol) {
            res->stop_reason = GETME_STOP_CONVERGED;
            break;
        }
    }
    getme__ws_summary(ws, run->q, &res->q_mean, &res->q_min_star, &res->q_min);
    free(scratch);
    free(run->phat);
    run->phat = NULL;
    return st;
}
