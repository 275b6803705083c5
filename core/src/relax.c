/*
 * relax.c -- adaptive per-node relaxation (paper Eq. 10), the step that
 * guarantees a valid mesh after every iteration of both methods.
 *
 * All loops are gathers (each iteration writes only its own node or
 * element), so they need no atomics and give the same result for any
 * number of threads.
 */
#include "smooth_internal.h"

/* Eq. 10 for node i with table entry rho.  rho = 0 and rho = 1 are taken
   literally so that a reset node gets its old coordinates bit for bit. */
static inline void place(getme_run *run, int32_t i, double rho)
{
    const double *x = run->ws->x + 3 * (int64_t)i;
    const double *ph = run->acc + 4 * (int64_t)i;
    double *xn = run->xnew + 3 * (int64_t)i;
    for (int d = 0; d < 3; d++)
        xn[d] = rho == 0.0 ? x[d]
              : rho == 1.0 ? ph[d]
                           : (1.0 - rho) * x[d] + rho * ph[d];
}

/* Quality of element e at the trial coordinates xnew, 0 if it is invalid
   there or if the corner guard rejects it: its worst corner fell below
   both its old value (at ws->x) and the floor.  An element at its old
   shape is never rejected, so the relaxation's reset argument holds. */
static inline double trial_quality(const getme_run *run, int32_t e)
{
    const getme_ws *ws = run->ws;
    double x[3 * GETME_MAX_NV];
    int t = getme__ws_type(ws, e);
    getme__ws_gather(ws, run->xnew, t, e, x);
    double q = getme__quality(t, x);
    if (q > 0.0 && ws->ho && !getme__ho_valid(ws, run->xnew, e))
        return 0.0; /* second order: det J > 0 at every node */
    if (!run->guard || !getme__has_corners(t) || !(q > 0.0) ||
        q >= run->guard_skip_q[t])
        return q;
    double sj = getme__corner_sj(t, x);
    if (sj >= run->corner_floor)
        return q;
    getme__ws_gather(ws, ws->x, t, e, x);
    return sj < getme__corner_sj(t, x) ? 0.0 : q;
}

/* How many elements of the list are invalid at xnew (parallel count). */
static int32_t count_invalid(const getme_run *run)
{
    const double *q = run->q;
    const int32_t *elems = run->elems;
    int32_t n = run->num_elems, bad = 0;
#pragma omp parallel for schedule(static) num_threads(run->ws->nt) \
    reduction(+ : bad) if (n > GETME_PAR_MIN)
    for (int32_t k = 0; k < n; k++)
        bad += !(q[elems[k]] > 0.0);
    return bad;
}

/* The moving nodes of invalid elements that can still step down the table,
   each once, into run->list (serial: few elements are invalid, and the
   list order must not depend on the thread count). */
static int32_t nodes_to_step(getme_run *run, int nR)
{
    const getme_ws *ws = run->ws;
    int32_t m = 0;
    for (int32_t k = 0; k < run->num_elems; k++) {
        int32_t e = run->elems[k];
        if (run->q[e] > 0.0)
            continue;
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int i = 0; i < getme__nv[t]; i++) {
            int32_t n = c[i];
            if (run->in_t[n] && !run->flag[n] && run->ridx[n] + 1 < nR) {
                run->flag[n] = 1;
                run->list[m++] = n;
            }
        }
    }
    return m;
}

int32_t getme__relax(getme_run *run, const double *R, int nR)
{
    getme_ws *ws = run->ws;
    double *q = run->q;
    const int32_t *nodes = run->nodes, *elems = run->elems;
    const int32_t nn = run->num_nodes, ne = run->num_elems;
    int nt = ws->nt;

#pragma omp parallel for schedule(static) num_threads(nt) if (nn > GETME_PAR_MIN)
    for (int32_t k = 0; k < nn; k++) {
        run->ridx[nodes[k]] = 0;
        place(run, nodes[k], R[0]);
    }
#pragma omp parallel for schedule(static) num_threads(nt) if (ne > GETME_PAR_MIN)
    for (int32_t k = 0; k < ne; k++)
        q[elems[k]] = trial_quality(run, elems[k]);

    /* Step the nodes of invalid elements down the table until none is
       invalid.  Only elements around a stepped node change, so only they
       are re-evaluated.  An invalid element always has a node that can
       still step: with all its moving nodes at R's last entry 0 it would
       be back at its old, valid shape. */
    while (getme__dist_any(run, count_invalid(run) > 0)) {
        int32_t m = nodes_to_step(run, nR);
        if (run->comm) /* a node steps if any copy has an invalid element */
            m = getme__dist_step_list(run, nR);
        if (!getme__dist_any(run, m > 0))
            break; /* unreachable for a valid input, see above */
        for (int32_t j = 0; j < m; j++) {
            int32_t i = run->list[j];
            run->ridx[i]++;
            place(run, i, R[run->ridx[i]]);
            run->flag[i] = 0;
        }
        for (int32_t j = 0; j < m; j++) {
            int32_t i = run->list[j];
            for (int64_t k = ws->star_ptr[i]; k < ws->star_ptr[i + 1]; k++)
                q[ws->star[k]] = trial_quality(run, ws->star[k]);
        }
    }

    int32_t relaxed = 0;
#pragma omp parallel for schedule(static) num_threads(nt) \
    reduction(+ : relaxed) if (nn > GETME_PAR_MIN)
    for (int32_t k = 0; k < nn; k++) {
        int32_t i = nodes[k];
        double *x = ws->x + 3 * (int64_t)i;
        const double *xn = run->xnew + 3 * (int64_t)i;
        x[0] = xn[0], x[1] = xn[1], x[2] = xn[2];
        relaxed += run->ridx[i] > 0;
    }
    return relaxed;
}
