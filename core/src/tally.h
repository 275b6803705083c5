/*
 * tally.h -- q_mean's exact sum kept up to date as a few qualities change.
 *
 * After stage 1 an iteration of the q*_min stage, or a pass of the
 * finishing step, changes the qualities of a few thousand elements; a
 * summary sweeping all of them (getme__ws_summary: 4M tets, ~3 ms on two
 * threads) after each one made that part of the run scale with the mesh.
 * q_mean's sum is exact fixed point (exact.h), so adding the difference of
 * an element's new and old terms gives the same integer, hence the same
 * q_mean bits, as summing again.  The minimum over free elements cannot
 * be kept that way (it may rise); the callers take it from a list known to
 * hold every free element below a bound (getme_adaptive.c, finish.c).
 */
#ifndef GETME_TALLY_H
#define GETME_TALLY_H

#include "exact.h"
#include "workspace.h"

typedef struct getme_tally {
    getme_ufx sum; /* sum of getme__fx_q(q[e]) over the workspace's elements */
} getme_tally;

/* The integer sum of getme__det_sum (workspace.c), before its rounding. */
getme_ufx getme__det_sum_fx(const double *v, int32_t n, int nt);

/* The sum at qualities q (one parallel sweep; the same integer for any
   thread count). */
static inline void getme__tally_start(getme_tally *t, const getme_ws *ws,
                                      const double *q)
{
    t->sum = getme__det_sum_fx(q, ws->ne, ws->nt);
}

/* What the sum moves by when an element's quality old becomes new
   (wrapping: a parallel caller adds these up per thread, then adds the
   threads' totals to the sum, the same integer in any order). */
static inline getme_ufx getme__tally_diff(double old, double new)
{
    return (getme_ufx)getme__fx_q(new) - (getme_ufx)getme__fx_q(old);
}

/* Element quality old became new. */
static inline void getme__tally_change(getme_tally *t, double old, double new)
{
    t->sum += getme__tally_diff(old, new);
}

/* q_mean of ne elements, the bits getme__ws_summary gives. */
static inline double getme__tally_mean(const getme_tally *t, int32_t ne)
{
    return ne ? getme__fx_double((getme_fx)t->sum, GETME_FX_QINV) / ne : 1.0;
}

/* The smallest q of the free elements in list[0..n), and 1.0 if there is
   none smaller (getme__ws_summary's q*_min when list holds every free
   element below the result). */
double getme__tally_min(const double *q, const int32_t *list, int32_t n);

#endif /* GETME_TALLY_H */
