/*
 * dist.c -- the library's side of distributed smoothing (getme_comm in
 * getme.h, docs/distributed.md): thin wrappers that call the caller's
 * hooks, or do the local operation in a single-process run.
 *
 * A hook failure is recorded in run->comm_failed and the wrapper returns
 * the local value; the loop checks the flag after every iteration and
 * stops with GETME_ERR_COMM (every process sees its own failure, and the
 * caller's hooks make the others fail too, see dist/).
 */
#include "smooth_internal.h"

#include <string.h>

int getme__dist_any(getme_run *run, int local)
{
    if (!run->comm)
        return local != 0;
    int64_t v = local != 0;
    if (run->comm->sum_i64(run->comm->ctx, &v, 1) != 0)
        run->comm_failed = 1;
    return v != 0;
}

void getme__dist_node_or(getme_run *run, uint8_t *flags)
{
    if (run->comm && run->comm->node_or(run->comm->ctx, flags) != 0)
        run->comm_failed = 1;
}

void getme__dist_node_sum(getme_run *run, getme_fx *v, int per_node)
{
    if (run->comm && run->comm->node_sum(run->comm->ctx, v, per_node) != 0)
        run->comm_failed = 1;
}

void getme__dist_sum_i64(getme_run *run, int64_t *v, int n)
{
    if (run->comm && run->comm->sum_i64(run->comm->ctx, v, n) != 0)
        run->comm_failed = 1;
}

void getme__dist_min(getme_run *run, double *v, int n)
{
    if (run->comm && run->comm->min(run->comm->ctx, v, n) != 0)
        run->comm_failed = 1;
}

void getme__summary(getme_run *run, double *q_mean, double *q_min_star,
                    double *q_min)
{
    const getme_ws *ws = run->ws;
    if (!run->comm) {
        getme__ws_summary(ws, run->q, q_mean, q_min_star, q_min);
        return;
    }
    /* The same exact sum as getme__det_sum (exact.h), over owned elements,
       then over processes. */
    getme_ufx s = 0;
    int64_t n = 0;
    double m[2] = {1.0, 1.0}; /* q_min, q*_min */
    for (int32_t e = 0; e < ws->ne; e++) {
        double v = run->q[e];
        if (run->owned[e]) {
            s += (getme_ufx)getme__fx_q(v);
            n++;
        }
        m[0] = v < m[0] ? v : m[0];
        if (ws->free_elem[e])
            m[1] = v < m[1] ? v : m[1];
    }
    getme_fx sum = (getme_fx)s;
    if (run->comm->sum_i128(run->comm->ctx, &sum, 1) != 0 ||
        run->comm->sum_i64(run->comm->ctx, &n, 1) != 0 ||
        run->comm->min(run->comm->ctx, m, 2) != 0)
        run->comm_failed = 1;
    *q_mean = n ? getme__fx_double(sum, GETME_FX_QINV) / (double)n : 1.0;
    *q_min_star = m[1];
    if (q_min)
        *q_min = m[0];
}

int32_t getme__dist_step_list(getme_run *run, int nR)
{
    getme__dist_node_or(run, run->flag);
    int32_t m = 0;
    for (int32_t k = 0; k < run->num_nodes; k++) {
        int32_t i = run->nodes[k];
        if (run->flag[i] && run->in_t[i] && run->ridx[i] + 1 < nR)
            run->list[m++] = i;
        else
            run->flag[i] = 0;
    }
    return m;
}
