/*
 * measures.c -- the analysts' quality measures (dihedral angles, scaled
 * Jacobian, Gmsh's gamma and SICN; getme.h, docs/quality.md) in the getme
 * command: per element type statistics, their log lines and their JSON.
 */
#include "cli.h"

#include <string.h>

int cli_measures_compute(getme_mesh *mesh, cli_measures *m, double *q)
{
    return getme_mesh_measure_all_qualities(mesh, &m->stats[0][0], q) ==
                   GETME_OK
               ? 0
               : -1;
}

/* "min dihedral" / "min angle" (planar), "scaled Jacobian", ... */
static const char *label(int type, int k)
{
    int planar = getme_type_dim((getme_elem_type)type) == 2;
    switch (k) {
    case GETME_MEASURE_MEAN_RATIO: return "mean ratio";
    case GETME_MEASURE_MIN_DIHEDRAL: return planar ? "min angle" : "min dihedral";
    case GETME_MEASURE_MAX_DIHEDRAL: return planar ? "max angle" : "max dihedral";
    case GETME_MEASURE_SCALED_JACOBIAN: return "scaled Jacobian";
    case GETME_MEASURE_GAMMA: return "gamma";
    default: return "SICN";
    }
}

static int is_angle(int k)
{
    return k == GETME_MEASURE_MIN_DIHEDRAL || k == GETME_MEASURE_MAX_DIHEDRAL;
}

void cli_print_measures(const cli_log *log, const char *title,
                        const cli_measures *m)
{
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        char line[512];
        if (getme_measure_summary((getme_elem_type)t, m->stats[t], line,
                                  sizeof line) > 0)
            cli_info(log, "%s (%s): %s", title,
                     getme_type_name((getme_elem_type)t), line);
    }
}

void cli_measures_log(const cli_log *log, getme_mesh *mesh, const char *title,
                      cli_measures *m)
{
    if (cli_measures_compute(mesh, m, NULL) != 0) {
        cli_warning(log, "%s: %s", title, getme_mesh_error(mesh));
        memset(m, 0, sizeof *m);
        return;
    }
    cli_print_measures(log, title, m);
}

void cli_print_measure_histograms(const cli_log *log, const cli_measures *m,
                                  int type)
{
    const char *name = getme_type_name((getme_elem_type)type);
    for (int k = GETME_MEASURE_MIN_DIHEDRAL; k < GETME_NUM_MEASURES; k++) {
        const getme_measure_stats *s = &m->stats[type][k];
        if (!s->num_elements)
            continue;
        int angle = is_angle(k);
        const char *what = label(type, k);
        if (angle)
            cli_info(log, "%s %s (degrees): min %.4f, max %.4f, mean %.4f",
                     name, what, s->min, s->max, s->mean);
        else
            cli_info(log, "%s %s: min %.4f, max %.4f, mean %.4f, %lld negative",
                     name, what, s->min, s->max, s->mean,
                     (long long)s->num_negative);
        double w = (s->hist_hi - s->hist_lo) / GETME_HIST_BINS;
        if (s->num_below)
            cli_info(log, "  %s < %g : %9lld elements", what, s->hist_lo,
                     (long long)s->num_below);
        for (int b = 0; b < GETME_HIST_BINS; b++)
            cli_info(log, angle ? "  %5.1f < %s < %5.1f : %9lld elements"
                                : "  %4.2f < %s < %4.2f : %9lld elements",
                     s->hist_lo + b * w, what, s->hist_lo + (b + 1) * w,
                     (long long)s->histogram[b]);
    }
}

void cli_json_measures(FILE *f, const cli_measures *m)
{
    fputc('{', f);
    int first_type = 1;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        const getme_measure_stats *s = m->stats[t];
        if (!s[GETME_MEASURE_MEAN_RATIO].num_elements)
            continue;
        fprintf(f, "%s\"%s\": {", first_type ? "" : ", ",
                getme_type_name((getme_elem_type)t));
        first_type = 0;
        int first = 1;
        for (int k = 0; k < GETME_NUM_MEASURES; k++) {
            if (!s[k].num_elements)
                continue; /* not defined for the type: no NaN in JSON */
            fprintf(f, "%s\"%s\": {\"elements\": %lld, \"min\": %.17g, "
                       "\"max\": %.17g, \"mean\": %.17g, \"negative\": %lld, "
                       "\"histogram_range\": [%g, %g], \"below_range\": %lld, "
                       "\"histogram\": [",
                    first ? "" : ", ", getme_measure_name((getme_measure)k),
                    (long long)s[k].num_elements, s[k].min, s[k].max,
                    s[k].mean, (long long)s[k].num_negative, s[k].hist_lo,
                    s[k].hist_hi, (long long)s[k].num_below);
            first = 0;
            for (int b = 0; b < GETME_HIST_BINS; b++)
                fprintf(f, "%s%lld", b ? ", " : "", (long long)s[k].histogram[b]);
            fputs("]}", f);
        }
        fputc('}', f);
    }
    fputc('}', f);
}
