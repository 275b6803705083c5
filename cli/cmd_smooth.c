/*
 * cmd_smooth.c -- `getme smooth IN -o OUT ...`: read, smooth, write.
 */
#include "cli.h"

#include <errno.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static const char SMOOTH_HELP[] =
    "usage: getme smooth IN -o OUT [options]\n"
    "\n"
    "Smooth the mesh in IN by moving free nodes and write the same file with\n"
    "only node coordinates changed to OUT (same format as IN; IN is never\n"
    "modified). Formats: Gmsh .msh (2.2/4.1), Abaqus .inp, CGNS .cgns.\n"
    "\n"
    "Fixed nodes: the mesh skin, interfaces between regions (physical\n"
    "volumes, sections, zones), Gmsh nodes on lower-dimensional entities,\n"
    "CGNS BC patches, plus the sets named with --fix.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE      output file (required)\n"
    "  --method getme|laplace GETMe adaptive (default) or smart Laplace\n"
    "  --threads N            OpenMP threads (default: all cores); the result\n"
    "                         is bit-identical for any N\n"
    "  --max-iter N           iteration limit over both stages (default 1000)\n"
    "  --fix NAME             also fix a named set: Gmsh physical group name\n"
    "                         (or DIM:TAG), INP NSET/ELSET, CGNS BC/family\n"
    "                         (repeatable)\n"
    "  --free NAME            do not fix this CGNS BC/family (repeatable)\n"
    "  --free-interfaces      let nodes on region interfaces move\n"
    "  --param NAME=VALUE     any smoothing parameter: sigma (1.5), tol (1e-4),\n"
    "                         threshold_fraction (0.005), max_no_min_improve (5),\n"
    "                         keep_best (1), renumber (1)\n"
    "  --report FILE.json     write before/after statistics, iterations and\n"
    "                         the per-iteration history as JSON\n"
    "  -q, --quiet            print errors only\n"
    "  -v, --verbose          print the quality histograms\n"
    "\n"
    "exit codes: 0 ok, 1 internal error, 2 usage, 3 cannot read input,\n"
    "4 malformed input, 5 unsupported content, 6 invalid elements in input,\n"
    "7 cannot write output\n";

typedef struct smooth_args {
    const char *input, *output, *report;
    const char **fix, **free_sets;
    int num_fix, num_free, free_interfaces;
    getme_params params;
    cli_log log;
} smooth_args;

typedef struct progress_state {
    const cli_log *log;
    cli_history *history;
} progress_state;

static int on_progress(const getme_progress *p, void *data)
{
    progress_state *ps = data;
    cli_history *h = ps->history;
    if (h->count == h->cap) {
        int cap = h->cap ? 2 * h->cap : 64;
        getme_progress *items = realloc(h->items, (size_t)cap * sizeof *items);
        if (items) {
            h->items = items;
            h->cap = cap;
        }
    }
    if (h->count < h->cap)
        h->items[h->count++] = *p;
    const char *stage = p->stage == GETME_STAGE_MEAN  ? "qmean stage"
                        : p->stage == GETME_STAGE_MIN ? "q*min stage"
                                                      : "smart Laplace";
    if (p->stage == GETME_STAGE_MIN)
        cli_info(ps->log, "It %4d (%s, cycle %d, q_t %.4f): q*min %.4f, "
                          "qmean %.4f, %d transformed, %d relaxed (%.2f s)",
                 p->iteration, stage, p->cycle, p->threshold, p->q_min_star,
                 p->q_mean, (int)p->num_transformed, (int)p->num_relaxed,
                 p->elapsed);
    else
        cli_info(ps->log, "It %4d (%s): q*min %.4f, qmean %.4f, %d relaxed "
                          "(%.2f s)",
                 p->iteration, stage, p->q_min_star, p->q_mean,
                 (int)p->num_relaxed, p->elapsed);
    return 0;
}

/* name=value for --param. */
static int set_param(getme_params *p, const char *arg)
{
    const char *eq = strchr(arg, '=');
    char name[64];
    double v;
    if (!eq || eq == arg || (size_t)(eq - arg) >= sizeof name) {
        cli_error("--param expects NAME=VALUE, got '%s'", arg);
        return -1;
    }
    memcpy(name, arg, (size_t)(eq - arg));
    name[eq - arg] = '\0';
    if (cli_parse_double("--param", eq + 1, &v) != 0)
        return -1;
    if (getme_params_set(p, name, v) != GETME_OK) {
        cli_error("--param %s: unknown parameter or value out of range", arg);
        return -1;
    }
    return 0;
}

/* Takes the value of an option: "--opt VALUE". */
static const char *value(int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        cli_error("%s needs a value (see getme smooth --help)", argv[*i]);
        return NULL;
    }
    return argv[++*i];
}

static int parse(int argc, char **argv, smooth_args *a)
{
    getme_params_init(&a->params);
    a->fix = calloc((size_t)argc, sizeof *a->fix);
    a->free_sets = calloc((size_t)argc, sizeof *a->free_sets);
    if (!a->fix || !a->free_sets)
        return 1;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v;
        long n;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            fputs(SMOOTH_HELP, stdout);
            return -1;
        } else if (!strcmp(o, "-o") || !strcmp(o, "--output")) {
            if (!(a->output = value(argc, argv, &i)))
                return EXIT_USAGE;
        } else if (!strcmp(o, "--method")) {
            if (!(v = value(argc, argv, &i)))
                return EXIT_USAGE;
            if (!strcmp(v, "getme") || !strcmp(v, "adaptive"))
                a->params.method = GETME_METHOD_ADAPTIVE;
            else if (!strcmp(v, "laplace"))
                a->params.method = GETME_METHOD_SMART_LAPLACE;
            else {
                cli_error("--method expects getme or laplace, got '%s'", v);
                return EXIT_USAGE;
            }
        } else if (!strcmp(o, "--threads")) {
            if (!(v = value(argc, argv, &i)) ||
                cli_parse_int(o, v, 1, 4096, &n) != 0)
                return EXIT_USAGE;
            a->params.num_threads = (int)n;
        } else if (!strcmp(o, "--max-iter")) {
            if (!(v = value(argc, argv, &i)) ||
                cli_parse_int(o, v, 0, 1000000000, &n) != 0)
                return EXIT_USAGE;
            a->params.max_iter = (int)n;
        } else if (!strcmp(o, "--fix")) {
            if (!(a->fix[a->num_fix++] = value(argc, argv, &i)))
                return EXIT_USAGE;
        } else if (!strcmp(o, "--free")) {
            if (!(a->free_sets[a->num_free++] = value(argc, argv, &i)))
                return EXIT_USAGE;
        } else if (!strcmp(o, "--free-interfaces")) {
            a->free_interfaces = 1;
        } else if (!strcmp(o, "--param")) {
            if (!(v = value(argc, argv, &i)) || set_param(&a->params, v) != 0)
                return EXIT_USAGE;
        } else if (!strcmp(o, "--report")) {
            if (!(a->report = value(argc, argv, &i)))
                return EXIT_USAGE;
        } else if (!strcmp(o, "-q") || !strcmp(o, "--quiet")) {
            a->log.quiet = 1;
        } else if (!strcmp(o, "-v") || !strcmp(o, "--verbose")) {
            a->log.verbose = 1;
        } else if (o[0] == '-' && o[1]) {
            cli_error("unknown option '%s' (see getme smooth --help)", o);
            return EXIT_USAGE;
        } else if (!a->input) {
            a->input = o;
        } else {
            cli_error("unexpected argument '%s': one input file only", o);
            return EXIT_USAGE;
        }
    }
    if (!a->input || !a->output) {
        cli_error("getme smooth needs an input file and -o OUTPUT "
                  "(see getme smooth --help)");
        return EXIT_USAGE;
    }
    return 0;
}

static int run(smooth_args *a)
{
    const cli_log *log = &a->log;
    getme_doc_options opts;
    getme_doc_options_init(&opts);
    opts.fix = a->fix;
    opts.num_fix = a->num_fix;
    opts.free_sets = a->free_sets;
    opts.num_free = a->num_free;
    opts.fix_interfaces = !a->free_interfaces;
    opts.verbose = log->verbose;

    cli_paths paths = {a->input, a->output, a->report, "", ""};
    int code = cli_check_paths(&paths);
    if (code)
        return code;
    double t0 = omp_get_wtime();
    cli_info(log, "Reading '%s'...", a->input);
    getme_doc *doc = cli_open(a->input, &opts, 0, &code, log);
    if (!doc)
        return code;
    if ((code = cli_check_read_files(&paths, doc)) != 0) {
        getme_doc_close(doc);
        return code;
    }
    getme_mesh *mesh = getme_doc_mesh(doc);
    char desc[256];
    cli_describe_mesh(mesh, desc, sizeof desc);
    cli_info(log, "Done reading '%s' (%s, %.2f s): %s", a->input,
             doc->format->name, omp_get_wtime() - t0, desc);
    if (doc->info[0])
        cli_info(log, "%s", doc->info);

    getme_quality_stats before = doc->stats, after;
    cli_print_stats(log, "Quality before", &before);

    cli_history history = {0};
    progress_state ps = {log, &history};
    a->params.progress = on_progress;
    a->params.progress_data = &ps;
    /* Gmsh's initialisation sets OpenMP's global thread count to 1, so
       "default" must be decided here: OMP_NUM_THREADS if set, else every
       core. */
    if (!a->params.num_threads) {
        const char *env = getenv("OMP_NUM_THREADS");
        int n = env ? atoi(env) : 0;
        a->params.num_threads = n > 0 ? n : omp_get_num_procs();
    }
    int threads = a->params.num_threads;
    cli_info(log, "Optimizing mesh (%s, %d thread%s)...",
             a->params.method == GETME_METHOD_ADAPTIVE ? "GETMe adaptive"
                                                       : "smart Laplace",
             threads, threads == 1 ? "" : "s");
    getme_result res;
    getme_status st = getme_smooth(mesh, &a->params, &res);
    if (st != GETME_OK) {
        cli_error("%s: %s", a->input, getme_mesh_error(mesh));
        code = st == GETME_ERR_INVALID_MESH ? GETME_IO_ERR_INVALID
                                            : GETME_IO_ERR_INTERNAL;
        goto out;
    }
    cli_info(log, "Done optimizing mesh (Wall %.3fs): %d + %d iterations "
                  "(%d q*min cycles)",
             res.seconds, res.iterations_mean, res.iterations_min,
             res.cycles_min);
    getme_mesh_quality_stats(mesh, -1, &after);
    cli_print_stats(log, "Quality after ", &after);

    cli_info(log, "Writing '%s'...", a->output);
    cli_guard guard = {0};
    cli_write_guard(&guard, 1);
    getme_io_status ios = getme_doc_write(doc, paths.out);
    if (ios != GETME_IO_OK) {
        cli_error("%s", getme_doc_error(doc));
        code = ios;
    } else {
        cli_info(log, "Done writing '%s'", a->output);
        if (a->report &&
            cli_write_report(paths.rep, a->input, a->output, &a->params, mesh,
                             &before, &after, &res, &history,
                             doc->format->name) != 0) {
            cli_error("%s: cannot write the report: %s", a->report,
                      strerror(errno));
            code = GETME_IO_ERR_WRITE;
        }
    }
    cli_write_guard(&guard, 0);
out:
    free(history.items);
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
    free(a.fix);
    free(a.free_sets);
    return code;
}
