/*
 * worst.c -- the worst elements of a document and why they stay bad:
 * log lines (smooth -v, quality --worst N) and the report's JSON array.
 */
#include "cli.h"

#include <stdio.h>
#include <stdlib.h>

/* The element's id in the file (tag, Abaqus id, CGNS element number), or
   its 1-based position when the adapter keeps none. */
long long cli_element_tag(const getme_doc *doc, int32_t e)
{
    return (long long)getme_doc_element_id(doc, e);
}

int cli_worst(getme_doc *doc, const double *q, int32_t max_count,
              unsigned flags, cli_worst_list *w)
{
    w->items = NULL;
    w->count = 0;
    if (max_count <= 0)
        return 0;
    w->items = malloc((size_t)max_count * sizeof *w->items);
    if (!w->items)
        return -1;
    getme_mesh *mesh = getme_doc_mesh(doc);
    if (getme_mesh_worst_elements_from(mesh, q, max_count, flags, w->items,
                                       &w->count) != GETME_OK) {
        cli_error("%s: %s", getme_doc_path(doc), getme_mesh_error(mesh));
        free(w->items);
        w->items = NULL;
        return -1;
    }
    return 0;
}

void cli_print_worst(const cli_log *log, const getme_doc *doc,
                     const cli_worst_list *w, const char *which)
{
    if (w->count == 0)
        return;
    cli_info(log, "Worst %d element%s%s (tag, type, quality, worst corner "
                  "scaled Jacobian if not a simplex, free nodes: why it stays):",
             (int)w->count, w->count == 1 ? "" : "s", which);
    for (int32_t i = 0; i < w->count; i++) {
        const getme_worst_element *x = &w->items[i];
        /* a simplex's corner_sj is 1 by definition (getme.h): printed, it
           read as the scaled Jacobian of a tet of quality 0.2 */
        char sj[32] = "";
        if (x->type != GETME_TET && x->type != GETME_TRI)
            snprintf(sj, sizeof sj, " sj %.4f", x->corner_sj);
        cli_info(log, "  %lld %s q %.4f%s, %d/%d free: %s",
                 cli_element_tag(doc, x->element), getme_type_name(x->type),
                 x->quality, sj, x->num_free, x->num_nodes,
                 getme_worst_reason_string(x->reason));
    }
}

static const char *reason_key(getme_worst_reason r)
{
    switch (r) {
    case GETME_WORST_IMPROVABLE: return "improvable";
    case GETME_WORST_ALL_FIXED: return "all_nodes_fixed";
    case GETME_WORST_INTERFACE: return "fixed_interface";
    case GETME_WORST_LOCAL_OPTIMUM: return "local_optimum";
    }
    return "unknown";
}

void cli_json_worst(FILE *f, const getme_doc *doc, const cli_worst_list *w)
{
    fputc('[', f);
    for (int32_t i = 0; i < w->count; i++) {
        const getme_worst_element *x = &w->items[i];
        fprintf(f, "%s\n    {\"tag\": %lld, \"index\": %d, \"type\": \"%s\", "
                   "\"quality\": %.17g, \"corner_sj\": %.17g, \"nodes\": %d, "
                   "\"free_nodes\": %d, \"reason\": \"%s\"}",
                i ? "," : "", cli_element_tag(doc, x->element),
                (int)x->element, getme_type_name(x->type), x->quality,
                x->corner_sj, x->num_nodes, x->num_free, reason_key(x->reason));
    }
    fputs(w->count ? "\n  ]" : "]", f);
}

/* What getme smooth and getme-mpi print after smoothing, alike: the worst
   corner line, the warning when the worst elements have no free node, and
   with -v both worst lists.  The lists stay filled for the report (the
   caller frees them).  0, or -1 if out of memory. */
int cli_log_after(const cli_log *log, getme_doc *doc, const double *q,
                  int32_t max_count, const getme_quality_stats *after,
                  const getme_result *res, cli_worst_list *worst,
                  cli_worst_list *worst_free)
{
    if (res->corner_sj_initial < 1.0 || res->corner_sj < 1.0)
        cli_info(log, "Worst corner scaled Jacobian (hex, prism, pyramid, "
                      "quad): %.4f before, %.4f after",
                 res->corner_sj_initial, res->corner_sj);
    if (cli_worst(doc, q, max_count, 0, worst) != 0 ||
        cli_worst(doc, q, max_count, GETME_WORST_FREE_ONLY, worst_free) != 0)
        return -1;
    int fixed_worst = after->num_free > 0 && after->q_min < after->q_min_star;
    if (fixed_worst)
        cli_warning(log, "qmin %.4f is below q*min %.4f: the worst elements "
                         "have no free node, no node move can fix them "
                         "(see --worst, -v)",
                    after->q_min, after->q_min_star);
    if (log->verbose) {
        cli_print_worst(log, doc, worst, "");
        if (fixed_worst)
            cli_print_worst(log, doc, worst_free, " with a free node");
    }
    return 0;
}
