/*
 * worst.c -- the worst elements of a document and why they stay bad:
 * log lines (smooth -v, quality --worst N) and the report's JSON array.
 */
#include "cli.h"

#include <stdlib.h>

/* The element's id in the file (tag, Abaqus id, CGNS element number), or
   its 1-based position when the adapter keeps none. */
long long cli_element_tag(const getme_doc *doc, int32_t e)
{
    return (long long)getme_doc_element_id(doc, e);
}

int cli_worst(getme_doc *doc, int32_t max_count, unsigned flags,
              cli_worst_list *w)
{
    w->items = NULL;
    w->count = 0;
    if (max_count <= 0)
        return 0;
    w->items = malloc((size_t)max_count * sizeof *w->items);
    if (!w->items)
        return -1;
    getme_mesh *mesh = getme_doc_mesh(doc);
    if (getme_mesh_worst_elements(mesh, max_count, flags, w->items,
                                  &w->count) !=
        GETME_OK) {
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
    cli_info(log, "Worst %d element%s%s (tag, type, quality, worst corner, "
                  "free nodes: why it stays):",
             (int)w->count, w->count == 1 ? "" : "s", which);
    for (int32_t i = 0; i < w->count; i++) {
        const getme_worst_element *x = &w->items[i];
        cli_info(log, "  %lld %s q %.4f sj %.4f, %d/%d free: %s",
                 cli_element_tag(doc, x->element), getme_type_name(x->type),
                 x->quality, x->corner_sj, x->num_free, x->num_nodes,
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
