/*
 * smooth_end.c -- the end of a smoothing command, after the library's
 * last call: the "after" lines, OUT, then the --report file.  `getme
 * smooth` and getme-mpi's rank 0 end the same way, so they print the same
 * lines and write the same report for the same mesh (tests/cli and
 * dist/test_mpi_options compare them).
 */
#include "cli.h"
#include "getme_alloc.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

int cli_write_doc(const cli_log *log, getme_doc *doc, const cli_paths *paths,
                  const char *output, const char *what)
{
    cli_info(log, "Writing %s'%s'...", what, output);
    getme_formats_status st = getme_doc_write(doc, paths->out);
    if (st != GETME_FORMATS_OK) {
        cli_error("%s", getme_doc_error(doc));
        return cli_exit_code(st);
    }
    cli_info(log, "Done writing '%s'", output);
    return 0;
}

/* The report, once OUT is written: the exit code. */
static int write_report(const cli_smooth_opts *so, const cli_smooth_end *e,
                        const getme_quality_stats *after,
                        const cli_measures *mafter,
                        const cli_ho_ratio *ho_after, const cli_worst_list *w,
                        const cli_worst_list *wf, const getme_result *res)
{
    getme_mesh *mesh = getme_doc_mesh(e->doc);
    cli_mesh_counts counts;
    cli_count_mesh(mesh, &counts);
    cli_report_extra extra = {e->doc,      w,          wf,
                              e->mbefore,  mafter,     e->ho_before,
                              e->ho_before ? ho_after : NULL};
    if (cli_write_report(e->paths->rep, e->input, e->output, &so->params,
                         &counts, e->before, after, res, &so->history,
                         getme_format_name(getme_doc_format(e->doc)),
                         &extra) != 0) {
        cli_error("%s: cannot write the report: %s", so->report,
                  strerror(errno));
        return CLI_EXIT_WRITE;
    }
    return 0;
}

int cli_smooth_end_run(const cli_smooth_opts *so, const cli_smooth_end *e,
                       const getme_result *res)
{
    const cli_log *log = &so->log;
    getme_mesh *mesh = getme_doc_mesh(e->doc);
    getme_quality_stats after;
    cli_measures mafter;
    cli_ho_ratio ho_after = {0};
    cli_smooth_done(so, res);
    cli_worst_list worst = {0}, worst_free = {0};
    int code = 0;
    /* every element evaluated once: the measures' sweep also gives the
       qualities that the statistics and the worst lists rank */
    int32_t ne = getme_mesh_num_elements(mesh);
    double *q = getme__malloc((size_t)(ne ? ne : 1) * sizeof *q); /* as log.c */
    if (!q) {
        cli_error("%s: out of memory", e->input);
        return CLI_EXIT_INTERNAL;
    }
    int measured = cli_measures_compute(mesh, &mafter, q) == 0;
    if (!measured) {
        cli_warning(log, "Measures after : %s", getme_mesh_error(mesh));
        memset(&mafter, 0, sizeof mafter);
    }
    if ((!measured && getme_mesh_element_qualities(mesh, q) != GETME_OK) ||
        getme_mesh_quality_stats_from(mesh, q, -1, &after) != GETME_OK) {
        cli_error("%s: %s", e->input, getme_mesh_error(mesh));
        code = CLI_EXIT_INTERNAL;
        goto out;
    }
    cli_print_stats(log, "Quality after ", &after);
    if (measured)
        cli_print_measures(log, "Measures after ", &mafter);
    cli_ho_log(log, e->doc, "after", &ho_after);
    if (cli_log_after(log, e->doc, q, e->worst, &after, res, &worst,
                      &worst_free) != 0) {
        code = CLI_EXIT_INTERNAL;
        goto out;
    }
    free(q);
    q = NULL;
    cli_guard guard = {0};
    cli_write_guard(&guard, 1);
    cli_file_stamp report_was;
    cli_stamp(e->paths->rep, &report_was);
    if ((code = cli_write_doc(log, e->doc, e->paths, e->output, "")) != 0) {
        /* the message is printed */
    } else if (so->report && cli_replaced(e->paths->rep, &report_was)) {
        /* the report names a file the output wrote (an INP include copy) */
        cli_error("report %s: it is a file the output just wrote; not "
                  "replacing it (choose another report file)", so->report);
        code = EXIT_USAGE;
    } else if (so->report) {
        code = write_report(so, e, &after, &mafter, &ho_after, &worst,
                            &worst_free, res);
    }
    cli_write_guard(&guard, 0);
out:
    free(q);
    free(worst.items);
    free(worst_free.items);
    return code;
}
