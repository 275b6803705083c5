/*
 * gmsh_log.c -- our lines in Gmsh's own logger, so the smoother reads like
 * a native optimizer in the terminal and in the GUI's message window.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdarg.h>
#include <stdio.h>

void gg_log(const char *level, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    int ierr = 0;
    /* With General.AbortOnError = 2 (the API default) an "error" line also
       raises inside Gmsh and comes back as ierr != 0: expected, ignored. */
    gmshLoggerWrite(line, level, &ierr);
}

/* Gmsh's optimizer prints "0.70 < quality < 0.80 :       231 elements". */
void gg_log_histogram(const getme_quality_stats *s)
{
    for (int b = 0; b < GETME_HIST_BINS; b++)
        gg_log("info", "%.2f < quality < %.2f : %9lld elements",
               b / (double)GETME_HIST_BINS, (b + 1) / (double)GETME_HIST_BINS,
               (long long)s->histogram[b]);
    if (s->num_invalid)
        gg_log("info", "invalid (quality 0)    : %9lld elements",
               (long long)s->num_invalid);
}

/* "Measures before (tet): dihedral 12.34 to 160.21 deg, scaled Jacobian
   ...", one line per element type present. */
void gg_log_measures(const char *when,
                     const getme_measure_stats (*m)[GETME_NUM_MEASURES])
{
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        char line[512];
        if (getme_measure_summary((getme_elem_type)t, m[t], line,
                                  sizeof line) > 0)
            gg_log("info", "Measures %s (%s): %s", when,
                   getme_type_name((getme_elem_type)t), line);
    }
}

/* The progress callback: one line per iteration. */

int gg_log_progress(const getme_progress *p, void *user)
{
    (void)user;
    if (p->stage == GETME_STAGE_LAPLACE)
        gg_log("info",
               "Laplace iteration %d: worst = %.6g / average = %.6g "
               "(Wall %.3gs)",
               p->iteration, p->q_min_star, p->q_mean, p->elapsed);
    else if (p->stage == GETME_STAGE_FINISH)
        gg_log("info",
               "GETMe finishing pass %d: worst = %.6g / average = %.6g, %ld "
               "elements below %.4f worked on, %ld raised (Wall %.3gs)",
               p->iteration, p->q_min_star, p->q_mean,
               (long)p->num_transformed, p->threshold, (long)p->num_relaxed,
               p->elapsed);
    else if (p->stage == GETME_STAGE_MEAN)
        gg_log("info",
               "GETMe iteration %d (mean stage): worst = %.6g / average = "
               "%.6g, %ld elements transformed (Wall %.3gs)",
               p->iteration, p->q_min_star, p->q_mean,
               (long)p->num_transformed, p->elapsed);
    else
        gg_log("info",
               "GETMe iteration %d (min stage, cycle %d, q_t = %.4f): worst "
               "= %.6g / average = %.6g, %ld elements transformed (Wall "
               "%.3gs)",
               p->iteration, p->cycle, p->threshold, p->q_min_star, p->q_mean,
               (long)p->num_transformed, p->elapsed);
    return 0;
}
