/*
 * getme_adaptive.c -- GETMe adaptive smoothing, paper Fig. 3 / Sec. 2.2-2.3.
 *
 * One loop, two stages:
 *  - q_mean stage: every element is transformed (q_t = 1), relaxation table
 *    R_mean, until an iteration gains less than tol in q_mean;
 *  - q*_min stage, in cycles: each cycle sets q_t to the quality found at
 *    position threshold_fraction of the sorted qualities of free elements
 *    and transforms only elements with q <= q_t (table R_min); a cycle ends
 *    after max_no_min_improve iterations without q*_min gain; smoothing ends
 *    after a cycle that did not raise q*_min.  A "gain" must exceed min_tol:
 *    the paper compares exactly, which in floating point lets a nearly
 *    regular mesh creep on by 1e-9 per iteration up to max_iter.
 * New node positions are Eq. 9-weighted means of the transformed nodes of
 * the transformed elements and the untransformed nodes of the other
 * elements around I_T; Eq. 10 relaxation keeps every element valid.
 *
 * Our choices where the paper is silent (README "Method notes"):
 *  - N(j) in Eq. 9 contains E_j itself;
 *  - elements without a free node are never transformed (they could not
 *    move anything);
 *  - keep_best: the mesh returned is the one with the best q*_min seen from
 *    the end of the q_mean stage on (the q*_min stage may lose a little
 *    q*_min in its last, unsuccessful cycle).
 */
#include "smooth_internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

enum { MEAN_RUNNING, MIN_START, MIN_RUNNING };

/* AddTransformedElementNodesAndWeights for the elements of one block. */
static int32_t add_transformed(getme_run *run, int32_t e0, int32_t e1,
                               double qt, double sigma)
{
    getme_stamp *st = &run->stamps[omp_get_thread_num()];
    const getme_ws *ws = run->ws;
    int t = getme__ws_type(ws, e0), nv = getme__nv[t];
    int32_t count = 0;
    for (int32_t e = e0; e < e1; e++) {
        if (!ws->free_elem[e] || run->q[e] > qt)
            continue;
        double x[3 * GETME_MAX_NV], y[3 * GETME_MAX_NV];
        double w = getme__weight(ws, run->q, t, e, st);
        getme__ws_gather(ws, ws->x, t, e, x);
        getme__transform(t, x, sigma, y);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int i = 0; i < nv; i++) {
            int32_t n = c[i];
            if (ws->fixed[n])
                continue;
            double *a = run->acc + 4 * (int64_t)n;
            a[0] += w * y[3 * i];
            a[1] += w * y[3 * i + 1];
            a[2] += w * y[3 * i + 2];
            a[3] += w;
            run->in_t[n] = 1;
        }
        count++;
    }
    return count;
}

/* AddUntransformedElementNodesAndWeights for the elements of one block. */
static void add_untransformed(getme_run *run, int32_t e0, int32_t e1,
                              double qt)
{
    getme_stamp *st = &run->stamps[omp_get_thread_num()];
    const getme_ws *ws = run->ws;
    int t = getme__ws_type(ws, e0), nv = getme__nv[t];
    for (int32_t e = e0; e < e1; e++) {
        if (!ws->free_elem[e] || run->q[e] <= qt)
            continue;
        const int32_t *c = getme__ws_nodes(ws, t, e);
        int any = 0;
        for (int i = 0; i < nv; i++)
            any |= run->in_t[c[i]];
        if (!any)
            continue;
        double w = getme__weight(ws, run->q, t, e, st);
        for (int i = 0; i < nv; i++) {
            int32_t n = c[i];
            if (!run->in_t[n])
                continue;
            const double *x = ws->x + 3 * (int64_t)n;
            double *a = run->acc + 4 * (int64_t)n;
            a[0] += w * x[0];
            a[1] += w * x[1];
            a[2] += w * x[2];
            a[3] += w;
        }
    }
}

/* Run f over all blocks, colour by colour: blocks of one colour share no
   node, so they scatter without atomics, and each node receives its
   contributions in the same order whatever the thread count. */
static int32_t scatter_pass(getme_run *run, int transformed, double qt,
                            double sigma)
{
    const getme_ws *ws = run->ws;
    int32_t total = 0;
    for (int c = 0; c < ws->num_colours; c++) {
        int32_t b0 = ws->colour_ptr[c], b1 = ws->colour_ptr[c + 1];
        int nt = c == ws->serial_colour ? 1 : ws->nt;
        int32_t count = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt) \
    reduction(+ : count)
        for (int32_t k = b0; k < b1; k++) {
            int32_t b = ws->colour_blocks[k];
            int32_t e0 = ws->block_start[b], e1 = ws->block_start[b + 1];
            if (transformed)
                count += add_transformed(run, e0, e1, qt, sigma);
            else
                add_untransformed(run, e0, e1, qt);
        }
        total += count;
    }
    return total;
}

/* ComputeNewNodes: p-hat = weighted sum / weight sum, for I_T. */
static void compute_new_nodes(getme_run *run)
{
#pragma omp parallel for schedule(static) num_threads(run->ws->nt) \
    if (run->num_nodes > GETME_PAR_MIN)
    for (int32_t k = 0; k < run->num_nodes; k++) {
        double *a = run->acc + 4 * (int64_t)run->nodes[k];
        double inv = 1.0 / a[3];
        a[0] *= inv;
        a[1] *= inv;
        a[2] *= inv;
    }
}

/* One iteration of the main loop (Fig. 3 lines 5-9). */
static void iterate(getme_run *run, double qt, const double *R, int nR,
                    int32_t *num_transformed, int32_t *num_relaxed)
{
    double sigma = run->params->sigma;
    *num_transformed = scatter_pass(run, 1, qt, sigma);
    if (qt < 1.0)
        scatter_pass(run, 0, qt, sigma);
    getme__collect(run);
    compute_new_nodes(run);
    *num_relaxed = getme__relax(run, R, nR);
    getme__reset_nodes(run);
}

/* Swap a <= b for quickselect. */
static inline void order2(double *a, double *b)
{
    if (*b < *a) {
        double t = *a;
        *a = *b;
        *b = t;
    }
}

/* The k-th smallest of v[0..n) (v is permuted); deterministic. */
static double select_kth(double *v, int32_t n, int32_t k)
{
    int32_t lo = 0, hi = n - 1;
    while (hi > lo) {
        int32_t mid = lo + (hi - lo) / 2;
        order2(&v[lo], &v[mid]);
        order2(&v[lo], &v[hi]);
        order2(&v[mid], &v[hi]);
        double pivot = v[mid];
        int32_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i <= j) {
                double t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++, j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return v[k];
    }
    return v[k];
}

/* DetermineTransformationThreshold: the quality at position
   fraction * n of the sorted qualities of the elements with a free node
   (elements without one can never change, so they would only dilute it). */
static double determine_threshold(getme_run *run, double *scratch)
{
    const getme_ws *ws = run->ws;
    int32_t n = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (ws->free_elem[e])
            scratch[n++] = run->q[e];
    if (n == 0)
        return 0.0;
    double pos = run->params->threshold_fraction * (double)n;
    int32_t k = pos >= (double)(n - 1) ? n - 1 : pos <= 0.0 ? 0 : (int32_t)pos;
    return select_kth(scratch, n, k);
}

getme_status getme__adaptive(getme_run *run)
{
    getme_ws *ws = run->ws;
    const getme_params *p = run->params;
    getme_result *res = run->result;
    double *scratch = malloc((size_t)(ws->num_free_elem ? ws->num_free_elem : 1) *
                             sizeof *scratch);
    double *best = p->keep_best ? malloc((size_t)ws->nn * 3 * sizeof *best) : NULL;
    if (!scratch || (p->keep_best && !best)) {
        free(scratch);
        free(best);
        return GETME_ERR_NOMEM;
    }

    double q_mean = res->q_mean_initial, q_min = res->q_min_star_initial;
    /* best_min: best q*_min since the end of the q_mean stage (its mesh is
       kept in best); record: best_min when the current cycle started. */
    double qt = 1.0, best_min = -1.0, record = -1.0;
    const double *R = p->relax_mean;
    int nR = p->num_relax_mean;
    int state = MEAN_RUNNING, counter = 0, have_cycle = 0;
    getme_status st = GETME_OK;
    res->stop_reason = GETME_STOP_MAX_ITER;

    for (int it = 1; it <= p->max_iter; it++) {
        int32_t ntrans, nrelax;
        getme_stage stage = state == MEAN_RUNNING ? GETME_STAGE_MEAN
                                                  : GETME_STAGE_MIN;
        iterate(run, qt, R, nR, &ntrans, &nrelax);
        double prev_mean = q_mean, prev_min = q_min;
        getme__ws_summary(ws, run->q, &q_mean, &q_min, NULL);
        res->iterations = it;
        if (stage == GETME_STAGE_MEAN)
            res->iterations_mean++;
        else
            res->iterations_min++;
        if (stage == GETME_STAGE_MIN && q_min > best_min) {
            best_min = q_min;
            if (best)
                memcpy(best, ws->x, (size_t)ws->nn * 3 * sizeof *best);
        }
        if (getme__report(run, it, stage, res->cycles_min, q_min, q_mean, qt,
                          ntrans, nrelax)) {
            res->stop_reason = GETME_STOP_CANCELLED;
            st = GETME_ERR_CANCELLED;
            break;
        }
        /* Fig. 3 lines 10-27. */
        if (state == MEAN_RUNNING && q_mean - prev_mean < p->tol) {
            state = MIN_START;
            R = p->relax_min;
            nR = p->num_relax_min;
            best_min = q_min; /* the end of stage 1 is the first candidate */
            if (best)
                memcpy(best, ws->x, (size_t)ws->nn * 3 * sizeof *best);
        }
        if (state == MIN_RUNNING) {
            if (!(q_min > prev_min + p->min_tol))
                counter++;
            if (counter >= p->max_no_min_improve)
                state = MIN_START;
        }
        if (state == MIN_START) {
            /* "No q*_min improvement in the last cycle" means: the cycle
               did not beat the best q*_min seen before it.  Comparing with
               the q*_min at the cycle's start instead lets an oscillating
               mesh "improve" on its own dips forever (measured: 988
               iterations with threshold_fraction 0.05). */
            if (have_cycle && !(best_min > record + p->min_tol)) {
                res->stop_reason = GETME_STOP_CONVERGED;
                break;
            }
            record = best_min;
            state = MIN_RUNNING;
            counter = 0;
            qt = determine_threshold(run, scratch);
            have_cycle = 1;
            res->cycles_min++;
        }
    }

    if (best && best_min > q_min) {
        /* Fixed nodes are equal in both copies, so this keeps them exact. */
        memcpy(ws->x, best, (size_t)ws->nn * 3 * sizeof *best);
        getme__ws_qualities(ws, run->q);
        getme__ws_summary(ws, run->q, &q_mean, &q_min, NULL);
    }
    getme__ws_summary(ws, run->q, &res->q_mean, &res->q_min_star, &res->q_min);
    res->threshold = qt;
    free(scratch);
    free(best);
    return st;
}
