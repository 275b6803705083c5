/*
 * cmd_smooth.c -- `getme smooth IN -o OUT ...`: read, smooth, write.
 */
#include "cli.h"

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
    "  --param NAME=VALUE     any smoothing parameter (repeatable; the table\n"
    "                         below)\n"
    "  --worst N              list the N worst elements after smoothing and\n"
    "                         why each stays bad (default 10; printed with -v,\n"
    "                         always in --report)\n"
    "  --report FILE.json     write before/after statistics, iterations,\n"
    "                         the worst elements and the per-iteration\n"
    "                         history as JSON\n"
    "  -q, --quiet            print errors only\n"
    "  -v, --verbose          print the quality histograms\n"
    "\n"
    "An input with invalid elements is untangled first (free nodes near them\n"
    "move until every element is valid, docs/untangle.md), with a warning\n"
    "saying how many were invalid and how many remain, then smoothed.\n"
    "\n"
    "exit codes: 0 ok, 1 internal error, 2 usage, 3 cannot read input,\n"
    "4 malformed input, 5 unsupported content, 6 invalid elements in input\n"
    "(--no-untangle), 7 cannot write output, 8 invalid elements that could not\n"
    "be untangled (named by their ids in the file; no output unless\n"
    "--allow-invalid)\n";

typedef struct smooth_args {
    const char *input, *output, *report;
    const char **fix, **free_sets;
    int num_fix, num_free, free_interfaces, allow_invalid;
    long worst;
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
    if (p->stage == GETME_STAGE_FINISH)
        cli_info(ps->log, "Finishing pass %d: q*min %.4f, qmean %.4f, %d "
                          "elements below %.4f worked on, %d raised (%.2f s)",
                 p->iteration, p->q_min_star, p->q_mean,
                 (int)p->num_transformed, p->threshold, (int)p->num_relaxed,
                 p->elapsed);
    else if (p->stage == GETME_STAGE_MIN)
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
    const getme_param_info *info = getme_param_find(name);
    if (!info) {
        cli_error("--param %s: unknown parameter '%s' (getme smooth --help "
                  "lists them)", arg, name);
        return -1;
    }
    if (getme_params_set(p, name, v) != GETME_OK) {
        char range[64];
        cli_param_range(info, range, sizeof range);
        cli_error("--param %s: %s takes %s %s", arg, name,
                  info->type == GETME_PARAM_REAL ? "a number" : "an integer",
                  range);
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
    a->worst = 10;
    a->fix = calloc((size_t)argc, sizeof *a->fix);
    a->free_sets = calloc((size_t)argc, sizeof *a->free_sets);
    if (!a->fix || !a->free_sets)
        return 1;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v;
        long n;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            fputs(SMOOTH_HELP, stdout);
            cli_print_params(stdout);
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
        } else if (!strcmp(o, "--no-untangle")) {
            a->params.untangle = 0;
        } else if (!strcmp(o, "--allow-invalid")) {
            a->allow_invalid = 1;
        } else if (!strcmp(o, "--param")) {
            if (!(v = value(argc, argv, &i)) || set_param(&a->params, v) != 0)
                return EXIT_USAGE;
        } else if (!strcmp(o, "--worst")) {
            if (!(v = value(argc, argv, &i)) ||
                cli_parse_int(o, v, 0, 1000000, &a->worst) != 0)
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

static int write_output(const smooth_args *a, getme_doc *doc,
                        const char *what)
{
    cli_info(&a->log, "Writing %s'%s'...", what, a->output);
    getme_io_status ios = getme_doc_write(doc, a->output);
    if (ios != GETME_IO_OK) {
        cli_error("%s", getme_doc_error(doc));
        return ios;
    }
    cli_info(&a->log, "Done writing '%s'", a->output);
    return 0;
}

/* Elements listed by file id in the error about elements that stay
   invalid. */
#define MAX_NAMED 20

/* Untangle an input with invalid elements: one warning line with the
   counts; the elements that stay invalid named by their file ids.
   Returns 0, GETME_IO_ERR_TANGLED or GETME_IO_ERR_INTERNAL. */
static int untangle(const smooth_args *a, getme_doc *doc,
                    getme_untangle_result *ur)
{
    getme_mesh *mesh = getme_doc_mesh(doc);
    cli_info(&a->log, "Untangling (%d thread%s)...", a->params.num_threads,
             a->params.num_threads == 1 ? "" : "s");
    getme_status st = getme_mesh_untangle(mesh, &a->params, ur);
    if (st != GETME_OK && st != GETME_ERR_INVALID_MESH) {
        cli_error("%s: %s", a->input, getme_mesh_error(mesh));
        return GETME_IO_ERR_INTERNAL;
    }
    long long before = (long long)ur->num_invalid_before,
              after = (long long)ur->num_invalid_after;
    cli_warning(&a->log, "%lld invalid (inverted or degenerate) element%s in "
                         "the input, %lld remain%s after untangling (%d "
                         "sweep%s, %d nodes moved, %.3f s)",
                before, before == 1 ? "" : "s", after,
                after == 1 ? "s" : "", ur->sweeps, ur->sweeps == 1 ? "" : "s",
                (int)ur->num_moved, ur->seconds);
    if (after == 0)
        return 0;
    int32_t ne = getme_mesh_num_elements(mesh);
    double *q = malloc((size_t)ne * sizeof *q);
    char list[MAX_NAMED * 22 + 8] = "";
    size_t len = 0;
    int named = 0;
    if (q && getme_mesh_element_qualities(mesh, q) == GETME_OK)
        for (int32_t e = 0; e < ne && named < MAX_NAMED; e++)
            if (!(q[e] > 0.0))
                len += (size_t)snprintf(list + len, sizeof list - len, "%s%lld",
                                        named++ ? ", " : "",
                                        (long long)getme_doc_element_id(doc, e));
    free(q);
    cli_error("%s: %lld element%s could not be untangled (%lld with every node "
              "fixed): %s%s; %s",
              a->input, after, after == 1 ? "" : "s",
              (long long)ur->num_stuck, list, after > named ? ", ..." : "",
              a->allow_invalid ? "writing the partly untangled mesh as asked"
                               : "no output written (--allow-invalid writes "
                                 "the partly untangled mesh)");
    return GETME_IO_ERR_TANGLED;
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

    if (getme_io_same_file(a->input, a->output)) {
        cli_error("%s: refusing to overwrite the input; choose another output "
                  "file", a->output);
        return EXIT_USAGE;
    }
    double t0 = omp_get_wtime();
    cli_info(log, "Reading '%s'...", a->input);
    int code;
    getme_doc *doc = cli_open(a->input, &opts, a->params.untangle, &code);
    if (!doc)
        return code;
    getme_mesh *mesh = getme_doc_mesh(doc);
    char desc[256];
    cli_describe_mesh(mesh, desc, sizeof desc);
    cli_info(log, "Done reading '%s' (%s, %.2f s): %s", a->input,
             doc->format->name, omp_get_wtime() - t0, desc);
    if (doc->info[0])
        cli_info(log, "%s", doc->info);

    getme_quality_stats before = doc->stats, after;
    cli_print_stats(log, "Quality before", &before);
    cli_measures mbefore, mafter;
    cli_measures_log(log, mesh, "Measures before", &mbefore);

    cli_history history = {0};
    cli_worst_list worst = {0}, worst_free = {0};
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
    getme_untangle_result ur;
    memset(&ur, 0, sizeof ur);
    code = 0;
    if (before.num_invalid > 0 && (code = untangle(a, doc, &ur)) != 0) {
        if (code == GETME_IO_ERR_TANGLED && a->allow_invalid)
            write_output(a, doc, "partly untangled, not smoothed, ");
        goto out;
    }
    int threads = a->params.num_threads;
    cli_info(log, "Optimizing mesh (%s, %d thread%s)...",
             a->params.method == GETME_METHOD_ADAPTIVE ? "GETMe adaptive"
                                                       : "smart Laplace",
             threads, threads == 1 ? "" : "s");
    getme_result res;
    getme_status st = getme_smooth(mesh, &a->params, &res);
    res.num_invalid_initial = ur.num_invalid_before;
    res.untangle_sweeps = ur.sweeps;
    res.untangle_seconds = ur.seconds;
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
    cli_measures_log(log, mesh, "Measures after ", &mafter);
    if (res.corner_sj_initial < 1.0 || res.corner_sj < 1.0)
        cli_info(log, "Worst corner scaled Jacobian (hex, prism, pyramid, "
                      "quad): %.4f before, %.4f after",
                 res.corner_sj_initial, res.corner_sj);
    if (cli_worst(doc, (int32_t)a->worst, 0, &worst) != 0 ||
        cli_worst(doc, (int32_t)a->worst, GETME_WORST_FREE_ONLY,
                  &worst_free) != 0) {
        code = GETME_IO_ERR_INTERNAL;
        goto out;
    }
    if (after.q_min < after.q_min_star)
        cli_warning(log, "qmin %.4f is below q*min %.4f: the worst elements "
                         "have no free node, no node move can fix them "
                         "(see --worst, -v)",
                    after.q_min, after.q_min_star);
    if (log->verbose) {
        cli_print_worst(log, doc, &worst, "");
        if (after.q_min < after.q_min_star)
            cli_print_worst(log, doc, &worst_free, " with a free node");
    }

    if ((code = write_output(a, doc, "")) != 0)
        goto out;
    if (a->report &&
        cli_write_report(a->report, a->input, a->output, &a->params, mesh,
                         &before, &after, &res, &history, doc, &worst,
                         &worst_free, &mbefore, &mafter) != 0) {
        cli_error("%s: cannot write the report", a->report);
        code = GETME_IO_ERR_WRITE;
    }
out:
    free(worst.items);
    free(worst_free.items);
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
