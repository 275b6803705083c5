/*
 * smooth_opts.c -- the smoothing options and log lines that `getme smooth`
 * and `getme gmsh` share: one parser, one help text, one progress line.
 */
#include "cli.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

const char CLI_SMOOTH_OPTIONS_HELP[] =
    "  --method getme|laplace GETMe adaptive (default) or smart Laplace\n"
    "  --threads N            OpenMP threads (default: all cores); the result\n"
    "                         is bit-identical for any N\n"
    "  --max-iter N           iteration limit over both stages (default 1000)\n"
    "  --fix NAME             also fix a named set: Gmsh physical group name\n"
    "                         (or DIM:TAG), INP NSET/ELSET, CGNS BC/family\n"
    "                         (repeatable)\n"
    "  --free NAME            do not fix this CGNS BC/family; other formats\n"
    "                         fix no set by name, but the name must exist\n"
    "                         (repeatable)\n"
    "  --free-interfaces      let nodes on region interfaces move\n"
    "  --no-untangle          refuse an input with invalid (inverted or\n"
    "                         degenerate) elements (exit 6) instead of\n"
    "                         untangling it first\n"
    "  --allow-invalid        if untangling leaves invalid elements, still\n"
    "                         write the partly untangled (unsmoothed) mesh\n"
    "                         (the exit code stays 8)\n"
    "  --param NAME=VALUE     any smoothing parameter (repeatable; the table\n"
    "                         below)\n"
    "  --report FILE.json     write before/after statistics, iterations,\n"
    "                         the worst elements (smooth) and the\n"
    "                         per-iteration history as JSON\n"
    "  -q, --quiet            print errors only\n"
    "  -v, --verbose          print the quality histograms\n";

int cli_smooth_opts_init(cli_smooth_opts *o, int argc)
{
    memset(o, 0, sizeof *o);
    getme_params_init(&o->params);
    o->fix = calloc((size_t)argc + 1, sizeof *o->fix);
    o->free_sets = calloc((size_t)argc + 1, sizeof *o->free_sets);
    return o->fix && o->free_sets ? 0 : -1;
}

void cli_smooth_opts_free(cli_smooth_opts *o)
{
    free(o->fix);
    free(o->free_sets);
    free(o->history.items);
    memset(o, 0, sizeof *o);
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
        cli_error("--param %s: unknown parameter '%s' (--help lists them)",
                  arg, name);
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

int cli_smooth_option(cli_smooth_opts *o, int argc, char **argv, int *i)
{
    const char *opt = argv[*i];
    static const char *const with_value[] = {
        "--method", "--threads", "--max-iter", "--fix", "--free", "--param",
        "--report"};
    int takes = 0;
    for (size_t k = 0; k < sizeof with_value / sizeof *with_value; k++)
        takes |= !strcmp(opt, with_value[k]);
    if (!takes) {
        if (!strcmp(opt, "--free-interfaces"))
            o->free_interfaces = 1;
        else if (!strcmp(opt, "--no-untangle"))
            o->params.untangle = 0;
        else if (!strcmp(opt, "--allow-invalid"))
            o->allow_invalid = 1;
        else if (!strcmp(opt, "-q") || !strcmp(opt, "--quiet"))
            o->log.quiet = 1;
        else if (!strcmp(opt, "-v") || !strcmp(opt, "--verbose"))
            o->log.verbose = 1;
        else
            return 0;
        return 1;
    }
    if (*i + 1 >= argc) {
        cli_error("%s needs a value", opt);
        return -1;
    }
    const char *v = argv[++*i];
    long n;
    if (!strcmp(opt, "--method")) {
        if (!strcmp(v, "getme") || !strcmp(v, "adaptive"))
            o->params.method = GETME_METHOD_ADAPTIVE;
        else if (!strcmp(v, "laplace"))
            o->params.method = GETME_METHOD_SMART_LAPLACE;
        else {
            cli_error("--method expects getme or laplace, got '%s'", v);
            return -1;
        }
    } else if (!strcmp(opt, "--threads")) {
        if (cli_parse_int(opt, v, 1, 4096, &n) != 0)
            return -1;
        o->params.num_threads = (int)n;
    } else if (!strcmp(opt, "--max-iter")) {
        if (cli_parse_int(opt, v, 0, 1000000000, &n) != 0)
            return -1;
        o->params.max_iter = (int)n;
    } else if (!strcmp(opt, "--fix")) {
        o->fix[o->num_fix++] = v;
    } else if (!strcmp(opt, "--free")) {
        o->free_sets[o->num_free++] = v;
    } else if (!strcmp(opt, "--param")) {
        if (set_param(&o->params, v) != 0)
            return -1;
    } else {
        o->report = v;
    }
    return 1;
}

/* Gmsh's initialisation sets OpenMP's global thread count to 1, so
   "default" must be decided here: OMP_NUM_THREADS if set, else every
   core. */
static int threads_or_default(int requested)
{
    if (requested)
        return requested;
    const char *env = getenv("OMP_NUM_THREADS");
    int n = env ? atoi(env) : 0;
    return n > 0 ? n : omp_get_num_procs();
}

void cli_smooth_doc_options(const cli_smooth_opts *o, getme_doc_options *d)
{
    getme_doc_options_init(d);
    d->fix = o->fix;
    d->num_fix = o->num_fix;
    d->free_sets = o->free_sets;
    d->num_free = o->num_free;
    d->fix_interfaces = !o->free_interfaces;
    d->verbose = o->log.verbose;
    /* the ASCII readers parse with the smoothing's threads */
    d->num_threads = threads_or_default(o->params.num_threads);
}

int cli_smooth_progress(const getme_progress *p, void *data)
{
    cli_smooth_opts *o = data;
    cli_history *h = &o->history;
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
        cli_info(&o->log, "Finishing pass %d: q*min %.4f, qmean %.4f, %d "
                          "elements below %.4f worked on, %d raised (%.2f s)",
                 p->iteration, p->q_min_star, p->q_mean,
                 (int)p->num_transformed, p->threshold, (int)p->num_relaxed,
                 p->elapsed);
    else if (p->stage == GETME_STAGE_MIN)
        cli_info(&o->log, "It %4d (%s, cycle %d, q_t %.4f): q*min %.4f, "
                          "qmean %.4f, %d transformed, %d relaxed (%.2f s)",
                 p->iteration, stage, p->cycle, p->threshold, p->q_min_star,
                 p->q_mean, (int)p->num_transformed, (int)p->num_relaxed,
                 p->elapsed);
    else
        cli_info(&o->log, "It %4d (%s): q*min %.4f, qmean %.4f, %d relaxed "
                          "(%.2f s)",
                 p->iteration, stage, p->q_min_star, p->q_mean,
                 (int)p->num_relaxed, p->elapsed);
    return 0;
}

void cli_smooth_threads(cli_smooth_opts *o)
{
    o->params.num_threads = threads_or_default(o->params.num_threads);
}

void cli_untangle_warning(const cli_log *log, const getme_untangle_result *ur)
{
    long long before = (long long)ur->num_invalid_before,
              after = (long long)ur->num_invalid_after;
    cli_warning(log, "%lld invalid (inverted or degenerate) element%s in "
                     "the input, %lld remain%s after untangling (%d "
                     "sweep%s, %d nodes moved, %.3f s)",
                before, before == 1 ? "" : "s", after,
                after == 1 ? "s" : "", ur->sweeps, ur->sweeps == 1 ? "" : "s",
                (int)ur->num_moved, ur->seconds);
    /* The count is of the elements found; the repair can leave some
       invalid (the smoothing then names them, exit 8). */
    if (ur->num_ho_moved > 0)
        cli_warning(log, "%d second-order element%s invalid only at curved "
                         "mid-nodes: %d mid-node%s pulled toward the straight "
                         "position, %d element%s now valid (docs/highorder.md)",
                    (int)ur->num_ho_invalid,
                    ur->num_ho_invalid == 1 ? " was" : "s were",
                    (int)ur->num_ho_moved, ur->num_ho_moved == 1 ? "" : "s",
                    (int)ur->num_ho_repaired,
                    ur->num_ho_repaired == 1 ? "" : "s");
}

void cli_smooth_begin(cli_smooth_opts *o, getme_params *params)
{
    o->params.progress = cli_smooth_progress;
    o->params.progress_data = o;
    cli_smooth_threads(o);
    /* the parameters actually used (getme gmsh: inside its options) */
    if (params && params != &o->params)
        *params = o->params;
    int threads = o->params.num_threads;
    cli_info(&o->log, "Optimizing mesh (%s, %d thread%s)...",
             o->params.method == GETME_METHOD_ADAPTIVE ? "GETMe adaptive"
                                                       : "smart Laplace",
             threads, threads == 1 ? "" : "s");
}

void cli_smooth_done(const cli_smooth_opts *o, const getme_result *res)
{
    cli_info(&o->log, "Done optimizing mesh (Wall %.3fs): %d + %d iterations "
                      "(%d q*min cycles)",
             res->seconds, res->iterations_mean, res->iterations_min,
             res->cycles_min);
    if (res->reverted_nodes > 0)
        cli_info(&o->log, "%d node%s put back at %s input position%s: "
                          "q*min had ended below the input's %.4f "
                          "(keep_best)",
                 (int)res->reverted_nodes,
                 res->reverted_nodes == 1 ? "" : "s",
                 res->reverted_nodes == 1 ? "its" : "their",
                 res->reverted_nodes == 1 ? "" : "s",
                 res->q_min_star_initial);
}

int cli_smooth_parse_args(cli_smooth_args *a, int argc, char **argv,
                          int first, const cli_smooth_usage *u)
{
    for (int i = first; i < argc; i++) {
        const char *o = argv[i];
        int r = cli_smooth_option(&a->o, argc, argv, &i);
        if (r < 0)
            return EXIT_USAGE;
        if (r > 0)
            continue;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            fputs(u->help_head, stdout);
            fputs(CLI_SMOOTH_OPTIONS_HELP, stdout);
            if (u->help_tail)
                fputs(u->help_tail, stdout);
            cli_print_params(stdout);
            return -1;
        } else if (!strcmp(o, "-o") || !strcmp(o, "--output") ||
                   !strcmp(o, "--worst")) {
            if (i + 1 >= argc) {
                cli_error("%s needs a value (see %s --help)", o, u->help_cmd);
                return EXIT_USAGE;
            }
            if (o[2] != 'w')
                a->output = argv[++i];
            else if (cli_parse_int(o, argv[++i], 0, 1000000, &a->worst) != 0)
                return EXIT_USAGE;
        } else if (o[0] == '-' && o[1]) {
            cli_error("unknown option '%s' (see %s --help)", o, u->help_cmd);
            return EXIT_USAGE;
        } else if (!a->input) {
            a->input = o;
        } else {
            cli_error("unexpected argument '%s': one input file only", o);
            return EXIT_USAGE;
        }
    }
    if (!a->input || !a->output) {
        cli_error("%s needs an input file and -o OUTPUT (see %s --help)",
                  u->name, u->help_cmd);
        return EXIT_USAGE;
    }
    return 0;
}
