/*
 * gmsh_report.c -- report values by name, so bindings (ctypes) need not
 * mirror the C struct layout.
 */
#include "gmsh_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

size_t getme_gmsh_report_sizeof(void) { return sizeof(getme_gmsh_report); }

const getme_measure_stats *getme_gmsh_report_measure(const getme_gmsh_report *r,
                                                     int after, int type,
                                                     int measure)
{
    if (!r || type < 0 || type >= GETME_NUM_TYPES || measure < 0 ||
        measure >= GETME_NUM_MEASURES)
        return NULL;
    return after ? &r->measures_after[type][measure]
                 : &r->measures_before[type][measure];
}

const char *getme_gmsh_report_message(const getme_gmsh_report *r)
{
    return r ? r->message : "";
}

static double stats_value(const getme_quality_stats *s, const char *name)
{
    int bin;
    char rest;
    if (sscanf(name, "hist%d%c", &bin, &rest) == 1 && bin >= 0 &&
        bin < GETME_HIST_BINS)
        return (double)s->histogram[bin];
    static const char *const names[] = {
        "q_min_star", "q_min", "q_mean", "q_max", "num_invalid",
        "num_below_04", "num_below_01", "num_elements", "num_free"};
    const double values[] = {s->q_min_star,
                             s->q_min,
                             s->q_mean,
                             s->q_max,
                             (double)s->num_invalid,
                             (double)s->num_below_04,
                             (double)s->num_below_01,
                             (double)s->num_elements,
                             (double)s->num_free};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++)
        if (strcmp(name, names[i]) == 0)
            return values[i];
    return NAN;
}

/* "worst3_quality" and the like: entry i of one of the worst lists. */
static double worst_value(const getme_gmsh_report *r, const char *name)
{
    int free_only = strncmp(name, "worst_free", 10) == 0;
    const char *p = name + (free_only ? 10 : 5);
    char *end;
    long i = strtol(p, &end, 10);
    int32_t n = free_only ? r->num_worst_free : r->num_worst;
    if (end == p || *end != '_' || i < 0 || i >= n)
        return NAN;
    const getme_worst_element *w = free_only ? &r->worst_free[i] : &r->worst[i];
    size_t tag = free_only ? r->worst_free_tag[i] : r->worst_tag[i];
    static const char *const names[] = {"tag", "index", "type", "quality",
                                        "corner_sj", "num_free", "num_nodes",
                                        "reason"};
    const double values[] = {(double)tag, w->element, w->type, w->quality,
                             w->corner_sj, w->num_free, w->num_nodes,
                             w->reason};
    for (size_t k = 0; k < sizeof names / sizeof *names; k++)
        if (strcmp(end + 1, names[k]) == 0)
            return values[k];
    return NAN;
}

double getme_gmsh_report_value(const getme_gmsh_report *r, const char *name)
{
    if (!r || !name)
        return NAN;
    if (strncmp(name, "worst", 5) == 0 && name[5] != 0 &&
        (isdigit((unsigned char)name[5]) || strncmp(name, "worst_free", 10) == 0) &&
        strcmp(name, "worst_free") != 0)
        return worst_value(r, name);
    if (strncmp(name, "before_", 7) == 0)
        return stats_value(&r->before, name + 7);
    if (strncmp(name, "after_", 6) == 0)
        return stats_value(&r->after, name + 6);
    const getme_result *res = &r->result;
    static const char *const names[] = {
        "dim", "num_entities", "num_nodes", "num_elements", "num_fixed",
        "num_moved", "wall", "cpu", "iterations", "iterations_mean",
        "iterations_min", "cycles_min", "stop_reason", "threshold",
        "seconds", "passes_finish", "moved_finish", "corner_sj_before",
        "corner_sj_after", "topology_ran", "topology_changed",
        "topology_elements_before", "topology_elements_after", "num_worst",
        "num_worst_free", "untangle_invalid_before", "untangle_invalid_after",
        "untangle_sweeps", "untangle_moved", "untangle_seconds",
        "num_second_order", "jacobian_ratio_before", "jacobian_ratio_after",
        "jacobian_ratio_tag_before", "jacobian_ratio_tag_after",
        "untangle_ho_repaired", "untangle_ho_moved", "reverted_nodes",
        "untangle_ho_invalid"};
    const getme_untangle_result *u = &r->untangle;
    const double values[] = {r->dim,
                             r->num_entities,
                             r->num_nodes,
                             r->num_elements,
                             r->num_fixed,
                             r->num_moved,
                             r->wall,
                             r->cpu,
                             res->iterations,
                             res->iterations_mean,
                             res->iterations_min,
                             res->cycles_min,
                             (double)res->stop_reason,
                             res->threshold,
                             res->seconds,
                             res->passes_finish,
                             res->moved_finish,
                             res->corner_sj_initial,
                             res->corner_sj,
                             r->topology_ran,
                             r->topology_changed,
                             r->topology_elements_before,
                             r->topology_elements_after,
                             r->num_worst,
                             r->num_worst_free,

                             (double)u->num_invalid_before,
                             (double)u->num_invalid_after,
                             u->sweeps,
                             u->num_moved,
                             u->seconds,
                             r->num_second_order,
                             r->jacobian_ratio_before,
                             r->jacobian_ratio_after,
                             (double)r->jacobian_ratio_tag_before,
                             (double)r->jacobian_ratio_tag_after,
                             u->num_ho_repaired,
                             u->num_ho_moved,
                             res->reverted_nodes,
                             u->num_ho_invalid};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++)
        if (strcmp(name, names[i]) == 0)
            return values[i];
    return NAN;
}
