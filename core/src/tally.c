/*
 * tally.c -- q_mean's exact sum kept up to date (tally.h).
 */
#include "tally.h"

double getme__tally_min(const double *q, const int32_t *list, int32_t n)
{
    double m = 1.0;
    for (int32_t k = 0; k < n; k++)
        m = q[list[k]] < m ? q[list[k]] : m;
    return m;
}
