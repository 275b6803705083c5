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

/* Does node i touch an element that is invalid at xnew? */
static inline int touches_invalid(const getme_ws *ws, const double *q,
                                  int32_t i)
{
    for (int64_t k = ws->star_ptr[i]; k < ws->star_ptr[i + 1]; k++)
        if (!(q[ws->star[k]] > 0.0))
            return 1;
    return 0;
}

static inline int touches_flagged(const getme_ws *ws, const uint8_t *flag,
                                  int32_t e)
{
    int t = getme__ws_type(ws, e);
    const int32_t *c = getme__ws_nodes(ws, t, e);
    for (int i = 0; i < getme__nv[t]; i++)
        if (flag[c[i]])
            return 1;
    return 0;
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
        q[elems[k]] = getme__ws_quality(ws, run->xnew, elems[k]);

    for (;;) {
        int32_t changed = 0;
#pragma omp parallel for schedule(static) num_threads(nt) \
    reduction(+ : changed) if (nn > GETME_PAR_MIN)
        for (int32_t k = 0; k < nn; k++) {
            int32_t i = nodes[k];
            run->flag[i] = 0;
            if (run->ridx[i] + 1 < nR && touches_invalid(ws, q, i)) {
                run->ridx[i]++;
                place(run, i, R[run->ridx[i]]);
                run->flag[i] = 1;
                changed++;
            }
        }
        /* No node could move back although an element is invalid cannot
           happen: such an element would have all its nodes at their old,
           valid positions.  So no change means no invalid element. */
        if (changed == 0)
            break;
#pragma omp parallel for schedule(static) num_threads(nt) if (ne > GETME_PAR_MIN)
        for (int32_t k = 0; k < ne; k++)
            if (touches_flagged(ws, run->flag, elems[k]))
                q[elems[k]] = getme__ws_quality(ws, run->xnew, elems[k]);
    }

    int32_t relaxed = 0;
#pragma omp parallel for schedule(static) num_threads(nt) \
    reduction(+ : relaxed) if (nn > GETME_PAR_MIN)
    for (int32_t k = 0; k < nn; k++) {
        int32_t i = nodes[k];
        double *x = ws->x + 3 * (int64_t)i;
        const double *xn = run->xnew + 3 * (int64_t)i;
        x[0] = xn[0], x[1] = xn[1], x[2] = xn[2];
        run->flag[i] = 0;
        relaxed += run->ridx[i] > 0;
    }
    return relaxed;
}
