/*
 * cmd_quality.c -- `getme quality IN`: Gmsh-style quality report per
 * element type (with the same fixed-node rules as smooth, for q*min).
 */
#include "cli.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

static const char QUALITY_HELP[] =
    "usage: getme quality IN [--fix NAME]... [--free NAME]... [--free-interfaces]\n"
    "                        [--worst N] [--threads N] [-q]\n"
    "\n"
    "Print the mean ratio quality of the mesh in IN per element type: q*min\n"
    "(worst element with a free node), qmin, qmean, and a histogram like\n"
    "Gmsh's; then, per element type, min, max, mean and a histogram of the\n"
    "min and max dihedral angle (planar: corner angles), the scaled\n"
    "Jacobian (Verdict/CUBIT), Gmsh's gamma and SICN (docs/quality.md).\n"
    "With --worst N, the N worst elements, and the N worst with a free node,\n"
    "each with why it cannot get better by moving nodes (all nodes fixed, on\n"
    "a fixed interface, free nodes at a local optimum, or still improvable).\n"
    "--threads N: OpenMP threads for reading and measuring (default: all\n"
    "cores, or OMP_NUM_THREADS); the report is the same for any number.\n"
    "Exit code 6 if the mesh has invalid (inverted) elements.\n";

/* q: every element's quality (from the measures' sweep) */
static void print_type(const cli_log *log, getme_mesh *mesh, const double *q,
                       int type)
{
    getme_quality_stats s;
    if (getme_mesh_quality_stats_from(mesh, q, type, &s) != GETME_OK ||
        !s.num_elements)
        return;
    const char *name = type < 0 ? "all elements"
                                : getme_type_name((getme_elem_type)type);
    char qs[64];
    cli_info(log, "%s: %lld, q*min %s, qmin %.4f, qmean %.4f, qmax %.4f, "
                  "%lld invalid",
             name, (long long)s.num_elements,
             cli_q_min_star(&s, qs, sizeof qs), s.q_min, s.q_mean,
             s.q_max, (long long)s.num_invalid);
    for (int b = 0; b < GETME_HIST_BINS; b++)
        cli_info(log, "  %.2f < quality < %.2f : %9lld elements",
                 b / (double)GETME_HIST_BINS, (b + 1) / (double)GETME_HIST_BINS,
                 (long long)s.histogram[b]);
}

int cli_quality(int argc, char **argv)
{
    cli_log log = {0, 1};
    const char *input = NULL;
    const char *names[64], *frees[64];
    long worst = 0;
    getme_doc_options opts;
    getme_doc_options_init(&opts);
    opts.fix = names;
    opts.free_sets = frees;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            fputs(QUALITY_HELP, stdout);
            return 0;
        } else if ((!strcmp(o, "--fix") || !strcmp(o, "--free")) && i + 1 < argc) {
            int fix = !strcmp(o, "--fix");
            int *n = fix ? &opts.num_fix : &opts.num_free;
            if (*n == 64) {
                cli_error("too many %s options", o);
                return EXIT_USAGE;
            }
            (fix ? names : frees)[(*n)++] = argv[++i];
        } else if (!strcmp(o, "--free-interfaces")) {
            opts.fix_interfaces = 0;
        } else if (!strcmp(o, "--worst") && i + 1 < argc) {
            if (cli_parse_int(o, argv[++i], 0, 1000000, &worst) != 0)
                return EXIT_USAGE;
        } else if (!strcmp(o, "--threads") && i + 1 < argc) {
            long n;
            if (cli_parse_int(o, argv[++i], 1, 4096, &n) != 0)
                return EXIT_USAGE;
            /* the readers' team and the measures' sweeps (OpenMP's
               default team), as smooth's --threads */
            opts.num_threads = (int)n;
            omp_set_num_threads((int)n);
        } else if (!strcmp(o, "-q") || !strcmp(o, "--quiet")) {
            log.quiet = 1;
        } else if (o[0] == '-' && o[1]) {
            cli_error("unknown or incomplete option '%s' (see getme quality --help)", o);
            return EXIT_USAGE;
        } else if (!input) {
            input = o;
        } else {
            cli_error("unexpected argument '%s': one input file only", o);
            return EXIT_USAGE;
        }
    }
    if (!input) {
        cli_error("getme quality needs an input file (see getme quality --help)");
        return EXIT_USAGE;
    }
    int st;
    /* one sweep evaluates every element: the read's validity check, the
       measures and the qualities the statistics and the worst lists use */
    cli_measured mb;
    getme_doc *doc = cli_open_measured(input, &opts, 1, &st, &log, &mb);
    if (!doc)
        return st;
    getme_mesh *mesh = getme_doc_mesh(doc);
    char desc[256];
    cli_describe_mesh(mesh, desc, sizeof desc);
    cli_info(&log, "%s (%s): %s", input, getme_format_name(getme_doc_format(doc)), desc);
    int types = 0;
    const cli_measures *measures = &mb.m;
    double *q = mb.q;
    if (!q) {
        cli_error("%s: %s", input, mb.ok ? "out of memory" : getme_mesh_error(mesh));
        free(q);
        getme_doc_close(doc);
        return CLI_EXIT_INTERNAL;
    }
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        if (getme_mesh_num_elements_of_type(mesh, (getme_elem_type)t)) {
            print_type(&log, mesh, q, t);
            cli_print_measure_histograms(&log, measures, t);
            types++;
        }
    if (types > 1)
        print_type(&log, mesh, q, -1);
    cli_worst_list w = {0}, wf = {0};
    if (worst > 0 &&
        (cli_worst(doc, q, (int32_t)worst, 0, &w) != 0 ||
         cli_worst(doc, q, (int32_t)worst, GETME_WORST_FREE_ONLY, &wf) != 0))
        st = CLI_EXIT_INTERNAL;
    free(q);
    cli_print_worst(&log, doc, &w, "");
    cli_print_worst(&log, doc, &wf, " with a free node");
    free(w.items);
    free(wf.items);
    if (st == CLI_EXIT_INVALID)
        cli_error("%s", getme_doc_error(doc));
    getme_doc_close(doc);
    return st;
}
