/*
 * untangle.c -- untangling an input with invalid elements before smoothing,
 * as `getme smooth` and `getme-mpi smooth` do it (one warning with the
 * counts, the elements that stay invalid named by their file ids).
 */
#include "cli.h"

#include <stdio.h>

/* Untangle an input with invalid elements: one warning line with the
   counts; the elements that stay invalid named by their file ids.
   Returns 0, CLI_EXIT_TANGLED or CLI_EXIT_INTERNAL. */
int cli_untangle(cli_smooth_opts *o, const char *input, getme_doc *doc,
                 getme_untangle_result *ur)
{
    getme_mesh *mesh = getme_doc_mesh(doc);
    cli_smooth_threads(o);
    int threads = o->params.num_threads;
    cli_info(&o->log, "Untangling (%d thread%s)...", threads,
             threads == 1 ? "" : "s");
    getme_status st = getme_mesh_untangle(mesh, &o->params, ur);
    if (st != GETME_OK && st != GETME_ERR_INVALID_MESH) {
        cli_error("%s: %s", input, getme_mesh_error(mesh));
        return CLI_EXIT_INTERNAL;
    }
    cli_untangle_warning(&o->log, ur);
    long long after = (long long)ur->num_invalid_after;
    if (after == 0)
        return 0;
    /* The untangler's own list (its validity test: the node Jacobians of
       second-order elements too, which the corner qualities of
       getme_mesh_element_qualities() do not see). */
    char list[GETME_MAX_REPORTED_INVALID * 22 + 8] = "";
    size_t len = 0;
    int named = ur->num_reported;
    for (int i = 0; i < named; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%lld",
                                i ? ", " : "",
                                (long long)getme_doc_element_id(doc, ur->remaining[i]));
    cli_error("%s: %lld element%s could not be untangled (%lld with every node "
              "fixed): %s%s; %s",
              input, after, after == 1 ? "" : "s",
              (long long)ur->num_stuck, list, after > named ? ", ..." : "",
              o->allow_invalid ? "writing the partly untangled mesh as asked"
                                 : "no output written (--allow-invalid writes "
                                   "the partly untangled mesh)");
    return CLI_EXIT_TANGLED;
}
