/*
 * cmd_smooth.c -- `getme smooth IN -o OUT ...`: read, smooth, write.
 */
#include "cli.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

static const char SMOOTH_HELP_HEAD[] =
    "usage: getme smooth IN -o OUT [options]\n"
    "\n"
    "Smooth the mesh in IN by moving free nodes and write the same file with\n"
    "only node coordinates changed to OUT (same format as IN; IN is never\n"
    "modified). Formats: Gmsh .msh (2.2/4.1), Abaqus .inp, CGNS .cgns.\n"
    "Elements: linear tet, hex, prism, pyramid (mixed), or tri, quad in a\n"
    "plane; second order tet10, hex20, hex27, prism15, prism18, pyramid13,\n"
    "pyramid14, tri6, quad8, quad9 (docs/highorder.md).\n"
    "\n"
    "Fixed nodes: the mesh skin, interfaces between regions (physical\n"
    "volumes, sections, zones), Gmsh nodes on lower-dimensional entities,\n"
    "CGNS BC patches, plus the sets named with --fix.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE      output file (required; the input's format and\n"
    "                         extension; a regular file or a new one)\n"
    "  --worst N              list the N worst elements after smoothing and\n"
    "                         why each stays bad (default 10; printed with -v,\n"
    "                         always in --report)\n";

static const char SMOOTH_HELP_TAIL[] =
    "\n"
    "An input with invalid elements is untangled first (free nodes near them\n"
    "move until every element is valid, docs/untangle.md), with a warning\n"
    "saying how many were invalid and how many remain, then smoothed; a\n"
    "second-order element invalid only at a curved mid-node has that node\n"
    "pulled toward its straight position first.\n"
    "\n"
    "exit codes: 0 ok, 1 internal error, 2 usage, 3 cannot read input,\n"
    "4 malformed input, 5 unsupported content, 6 invalid elements in input\n"
    "(--no-untangle) or degenerate ones (a node twice), 7 cannot write output,\n"
    "8 invalid elements that could not be untangled (named by their ids in\n"
    "the file; no output unless --allow-invalid)\n";

typedef cli_smooth_args smooth_args;

static int parse(int argc, char **argv, smooth_args *a)
{
    a->worst = 10;
    if (cli_smooth_opts_init(&a->o, argc) != 0)
        return 1;
    static const cli_smooth_usage usage = {
        "getme smooth", "getme smooth", SMOOTH_HELP_HEAD, SMOOTH_HELP_TAIL};
    return cli_smooth_parse_args(a, argc, argv, 1, &usage);
}

/* Writing the output (termination signals held). */
static int run(smooth_args *a)
{
    cli_smooth_opts *so = &a->o;
    const cli_log *log = &so->log;
    getme_doc_options opts;
    cli_smooth_doc_options(so, &opts);

    cli_paths paths = {a->input, a->output, so->report, "", ""};
    int code = cli_check_paths(&paths);
    if (code)
        return code;
    /* the read's validity check with the measures before (below), the
       statistics and worst lists before and after smoothing run on the
       OpenMP default team: make it --threads (the reader's and the
       smoother's own count), not every core */
    omp_set_num_threads(opts.num_threads);
    double t0 = omp_get_wtime();
    cli_info(log, "Reading '%s'...", a->input);
    /* the measures before come from the sweep of the read's validity
       check: every element evaluated once before smoothing */
    cli_measured mb;
    getme_doc *doc = cli_open_measured(a->input, &opts, so->params.untangle,
                                       &code, log, &mb);
    if (!doc)
        return code;
    free(mb.q); /* the statistics are kept by the document */
    if ((code = cli_check_read_files(&paths, doc)) != 0) {
        getme_doc_close(doc);
        return code;
    }
    getme_mesh *mesh = getme_doc_mesh(doc);
    char desc[256];
    cli_describe_mesh(mesh, desc, sizeof desc);
    cli_info(log, "Done reading '%s' (%s, %.2f s): %s", a->input,
             getme_format_name(getme_doc_format(doc)), omp_get_wtime() - t0, desc);
    if (getme_doc_info(doc)[0])
        cli_info(log, "%s", getme_doc_info(doc));

    getme_quality_stats before = *getme_doc_stats(doc);
    cli_print_stats(log, "Quality before", &before);
    cli_measures mbefore = mb.m;
    if (mb.ok) {
        cli_print_measures(log, "Measures before", &mbefore);
    } else {
        cli_warning(log, "%s: %s", "Measures before", getme_mesh_error(mesh));
        memset(&mbefore, 0, sizeof mbefore);
    }
    cli_ho_ratio ho_before = {0};
    cli_ho_log(log, doc, "before", &ho_before);
    getme_untangle_result ur;
    memset(&ur, 0, sizeof ur);
    code = 0;
    /* a second-order element invalid only at a mid-node has valid corners,
       so the statistics count it valid: untangling repairs it */
    int ho_invalid = ho_before.n > 0 && ho_before.ratio <= 0.0 &&
                     so->params.untangle;
    if ((before.num_invalid > 0 || ho_invalid) &&
        (code = cli_untangle(&a->o, a->input, doc, &ur)) != 0) {
        if (code == CLI_EXIT_TANGLED && so->allow_invalid) {
            cli_guard guard = {0};
            cli_write_guard(&guard, 1);
            cli_write_doc(log, doc, &paths, a->output,
                          "partly untangled, not smoothed, ");
            cli_write_guard(&guard, 0);
        }
        goto out;
    }
    cli_smooth_begin(so, NULL);
    getme_result res;
    /* nothing is written if smoothing fails: the smoother may work in the
       mesh's own coordinate array (24 B per node less) */
    getme_mesh_lend_coords(mesh, 1);
    getme_status st = getme_smooth(mesh, &so->params, &res);
    res.num_invalid_initial = ur.num_invalid_before;
    res.untangle_sweeps = ur.sweeps;
    res.untangle_seconds = ur.seconds;
    if (st != GETME_OK) {
        cli_error("%s: %s", a->input, getme_mesh_error(mesh));
        code = st == GETME_ERR_INVALID_MESH ? CLI_EXIT_INVALID
               : st == GETME_ERR_TOPOLOGY   ? CLI_EXIT_UNSUPPORTED
                                            : CLI_EXIT_INTERNAL;
        goto out;
    }
    cli_smooth_end end = {a->input, a->output, &paths,   doc,
                          &before,  &mbefore,  &ho_before, (int32_t)a->worst};
    code = cli_smooth_end_run(so, &end, &res);
out:
    getme_doc_close(doc);
    return code;
}

int cli_smooth(int argc, char **argv)
{
    smooth_args a;
    memset(&a, 0, sizeof a);
    int code = parse(argc, argv, &a);
    if (code == 0)
        code = run(&a);
    else if (code < 0)
        code = 0; /* --help */
    cli_smooth_opts_free(&a.o);
    return code;
}
