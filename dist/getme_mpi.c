/*
 * getme_mpi.c -- `mpirun -np N getme-mpi smooth IN -o OUT [options]`:
 * distributed GETMe adaptive (docs/distributed.md).
 *
 * The options are `getme smooth`'s, parsed by the same code (cli/,
 * libgetme_cli_common): --fix, --free, --free-interfaces, --param,
 * --max-iter, --threads, --no-untangle, --allow-invalid, --report, --worst,
 * -v, -q.  Rank 0 reads IN through libgetme_formats (fixed nodes by the
 * same rules as `getme smooth`), untangles it if needed as `getme smooth`
 * does, splits it with METIS and sends every rank its part; all ranks run
 * getme_smooth_part(); the finishing step runs on the worst elements'
 * patches (finish_sub.c); rank 0 gathers the positions and writes OUT, the
 * same bytes as `getme smooth IN -o OUT` writes with the same options.  A failure on any
 * rank stops every rank with one error line from rank 0 and no output.
 *
 * Exit codes: those of `getme smooth` (cli.h); 1 also when a rank fails
 * (smoothing, communication).
 */
#include "dist.h"
#include "cli.h"

#include <omp.h>
#include <sys/resource.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef cli_smooth_args args;

typedef struct run_state {
    dist_ctx *c;
    args *a;
    int64_t last_bytes;
    double last_seconds;
} run_state;

static const char HELP_HEAD[] =
    "usage: mpirun -np N getme-mpi smooth IN -o OUT [options]\n"
    "\n"
    "Distributed GETMe adaptive: rank 0 reads IN (.msh, .inp, .cgns), splits\n"
    "it with METIS, every rank smooths its part with one ghost layer, rank 0\n"
    "gathers the positions, runs the finishing step and writes OUT -- the\n"
    "same bytes as `getme smooth IN -o OUT` with the same options, for any N\n"
    "and any thread count. Fixed nodes follow getme smooth's rules.\n"
    "Volume meshes only: a planar mesh (triangles, quads) is refused (exit 5;\n"
    "smooth it with getme smooth).\n"
    "\n"
    "options (as getme smooth's; --threads is per rank, default 1; -v adds\n"
    "the communication volume and time per iteration and per rank;\n"
    "--method laplace is not distributed):\n"
    "  -o, --output FILE      output file (required; the input's format)\n"
    "  --worst N              list the N worst elements after smoothing\n"
    "                         (default 10; printed with -v, always in\n"
    "                         --report)\n";

/* Every rank parses argv the same way; only rank 0 prints.  0 to run, -1
   after --help, else the exit code. */
static int parse(int argc, char **argv, args *a)
{
    a->worst = 10;
    if (cli_smooth_opts_init(&a->o, argc) != 0)
        return CLI_EXIT_INTERNAL;
    if (argc >= 2 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help"))) {
        fputs(HELP_HEAD, stdout);
        fputs(CLI_SMOOTH_OPTIONS_HELP, stdout);
        cli_print_params(stdout);
        return -1;
    }
    if (argc < 2 || strcmp(argv[1], "smooth") != 0) {
        cli_error("usage: mpirun -np N getme-mpi smooth IN -o OUT [options] "
                  "(see getme-mpi --help)");
        return EXIT_USAGE;
    }
    static const cli_smooth_usage usage = {
        "getme-mpi smooth", "getme-mpi", HELP_HEAD, NULL};
    int st = cli_smooth_parse_args(a, argc, argv, 2, &usage);
    if (st != 0)
        return st;
    if (a->o.params.method != GETME_METHOD_ADAPTIVE) {
        cli_error("--method laplace: getme-mpi runs GETMe adaptive only "
                  "(use getme smooth for smart Laplace)");
        return EXIT_USAGE;
    }
    if (!a->o.params.num_threads) /* per rank: ranks already share cores */
        a->o.params.num_threads = 1;
    /* rank 0's measures, statistics and worst lists and every rank's
       part measures run on the OpenMP default team: make it --threads,
       as getme smooth does, not every core of a machine the ranks share */
    omp_set_num_threads(a->o.params.num_threads);
    return 0;
}

/* Per iteration, on every rank with the same values: rank 0 logs the line
   of getme smooth and keeps the history (--report); with -v the
   communication counters are reduced (collective) and logged. */
static int on_progress(const getme_progress *p, void *data)
{
    run_state *s = data;
    dist_ctx *c = s->c;
    if (c->rank == 0)
        cli_smooth_progress(p, &s->a->o);
    if (!s->a->o.log.verbose)
        return 0;
    double v[2] = {(double)(c->bytes_sent + c->bytes_reduced), c->comm_seconds};
    double bytes = 0.0, secs = 0.0;
    MPI_Reduce(&v[0], &bytes, 1, MPI_DOUBLE, MPI_SUM, 0, c->comm);
    MPI_Reduce(&v[1], &secs, 1, MPI_DOUBLE, MPI_MAX, 0, c->comm);
    cli_info(&s->a->o.log, "It %4d: comm %.1f KiB, %.2f ms", p->iteration,
             (bytes - (double)s->last_bytes) / 1024.0,
             1e3 * (secs - s->last_seconds));
    s->last_bytes = (int64_t)bytes;
    s->last_seconds = secs;
    return 0;
}

/* The part as a core mesh (nodes and elements in the part's order). */
static getme_status build_part(const dist_ctx *c, getme_mesh **out)
{
    getme_status st = getme_mesh_create(out, 3, c->nn, c->coords);
    if (st != GETME_OK)
        return st;
    int64_t off = 0;
    for (int32_t e = 0; e < c->ne && st == GETME_OK;) {
        int32_t e1 = e; /* a run of one type */
        int64_t end = off;
        while (e1 < c->ne && c->etype[e1] == c->etype[e]) {
            end += getme_type_num_nodes((getme_elem_type)c->etype[e1]);
            e1++;
        }
        st = getme_mesh_add_elements(*out, (getme_elem_type)c->etype[e],
                                     e1 - e, c->conn + off, NULL);
        off = end;
        e = e1;
    }
    if (st == GETME_OK)
        st = getme_mesh_set_fixed_mask(*out, c->fixed);
    return st;
}

/* Every rank runs GETMe adaptive on its part (collective); with -v the
   per-rank numbers bench/mpi.py reads.  0, or 1 after one error line
   from rank 0. */
static int smooth_parts(dist_ctx *c, args *a, getme_mesh *part,
                        const getme_params *base, getme_result *res,
                        double *loop_seconds)
{
    const cli_log *log = &a->o.log;
    getme_params params = *base;
    run_state rs = {c, a, 0, 0.0};
    params.progress = on_progress;
    params.progress_data = &rs;
    getme_comm hooks;
    dist_comm_hooks(c, &hooks);
    c->bytes_sent = c->bytes_reduced = 0; /* the loop's, not the set-up's */
    c->comm_seconds = 0.0;
    int threads = params.num_threads;
    char msg[1200] = "", err[1200] = "";
    cli_info(log, "Optimizing mesh (GETMe adaptive, %d ranks, %d thread%s "
             "each)...", c->size, threads, threads == 1 ? "" : "s");
    double ts = MPI_Wtime();
    getme_status st = getme_smooth_part(part, &params, &hooks, res);
    if (st != GETME_OK)
        snprintf(msg, sizeof msg, "smoothing: %s", getme_mesh_error(part));
    int first = dist_agree(c, st != GETME_OK, msg, err, sizeof err);
    if (first >= 0) {
        if (c->rank == 0)
            cli_error("rank %d of %d: %s; no output written", first, c->size,
                      err);
        return 1;
    }
    *loop_seconds = MPI_Wtime() - ts;
    if (log->verbose) { /* per rank: the benchmark's numbers (bench/mpi.py) */
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        int64_t owned = 0;
        for (int32_t e = 0; e < c->ne; e++)
            owned += c->owned[e];
        double mine[9] = {(double)c->ne, (double)owned, (double)c->nn,
                          c->nb_ptr ? (double)c->nb_ptr[c->num_nb] : 0.0,
                          *loop_seconds, c->comm_seconds,
                          (double)c->bytes_sent, (double)c->bytes_reduced,
                          (double)ru.ru_maxrss / 1024.0};
        double *all = c->rank == 0 ? malloc((size_t)c->size * sizeof mine)
                                   : NULL;
        MPI_Gather(mine, 9, MPI_DOUBLE, all, 9, MPI_DOUBLE, 0, c->comm);
        for (int r = 0; all && r < c->size; r++) {
            const double *v = all + 9 * r;
            cli_info(log, "Rank %d: %.0f elements (%.0f owned), %.0f nodes "
                     "(%.0f shared copies), loop %.3f s, comm %.3f s, sent "
                     "%.3f MiB, reduced %.3f MiB, max RSS %.1f MiB",
                     r, v[0], v[1], v[2], v[3], v[4], v[5], v[6] / 1048576.0,
                     v[7] / 1048576.0, v[8]);
        }
        free(all);
    }
    return 0;
}

/* Rank 0 before the split: check the paths, read, untangle.  0 to go on,
   else the exit code (the error printed). */
static int read_input(args *a, cli_paths *paths, int size, getme_doc **doc,
                      getme_quality_stats *before, cli_measures *mbefore,
                      getme_untangle_result *ur)
{
    cli_smooth_opts *so = &a->o;
    const cli_log *log = &so->log;
    int code = cli_check_paths(paths);
    if (code)
        return code;
    getme_doc_options opts;
    cli_smooth_doc_options(so, &opts);
    double t0 = omp_get_wtime();
    cli_info(log, "Reading '%s' on rank 0 of %d...", a->input, size);
    *doc = cli_open(a->input, &opts, so->params.untangle, &code, log);
    if (!*doc)
        return code;
    if ((code = cli_check_read_files(paths, *doc)) != 0)
        return code;
    getme_mesh *mesh = getme_doc_mesh(*doc);
    if (getme_mesh_dim(mesh) != 3) {
        /* a planar mesh's mirror detection (which side of its plane is
           up) is a decision over the whole mesh that the parts do not
           share yet; the split is also built for volumes (METIS dual
           graph over faces, 3 common nodes) */
        cli_error("%s: planar meshes (triangles, quads) are not distributed "
                  "by getme-mpi (their orientation is decided on the whole "
                  "mesh); smooth them with getme smooth", a->input);
        return CLI_EXIT_UNSUPPORTED;
    }
    char desc[256];
    cli_describe_mesh(mesh, desc, sizeof desc);
    cli_info(log, "Done reading '%s' (%s, %.2f s): %s", a->input,
             getme_format_name(getme_doc_format(*doc)), omp_get_wtime() - t0,
             desc);
    if (getme_doc_info(*doc)[0])
        cli_info(log, "%s", getme_doc_info(*doc));
    *before = *getme_doc_stats(*doc);
    cli_print_stats(log, "Quality before", before);
    cli_measures_log(log, mesh, "Measures before", mbefore);
    cli_ho_log(log, *doc, "before", NULL);
    if (before->num_invalid > 0 &&
        (code = cli_untangle(so, a->input, *doc, ur)) != 0) {
        if (code == CLI_EXIT_TANGLED && so->allow_invalid) {
            cli_guard guard = {0};
            cli_write_guard(&guard, 1);
            cli_info(log, "Writing partly untangled, not smoothed, '%s'...",
                     a->output);
            getme_formats_status ws = getme_doc_write(*doc, paths->out);
            if (ws != GETME_FORMATS_OK)
                cli_error("%s", getme_doc_error(*doc));
            cli_write_guard(&guard, 0);
        }
        return code;
    }
    return 0;
}

/* Rank 0 after the finishing step: log, write OUT and the report as
   `getme smooth` does (cli_smooth_end_run).  The exit code. */
static int finish_output(args *a, const cli_paths *paths, getme_doc *doc,
                         const getme_quality_stats *before,
                         const cli_measures *mbefore, const getme_result *res)
{
    cli_smooth_end end = {a->input, a->output, paths, doc,
                          before,   mbefore,   NULL,  (int32_t)a->worst};
    return cli_smooth_end_run(&a->o, &end, res);
}

/* With -v, at the end (collective): every rank's peak RSS over the whole
   run, reading and writing included (bench/mpi.py). */
static void log_peak_rss(dist_ctx *c, const cli_log *log)
{
    if (!log->verbose)
        return;
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double mine = (double)ru.ru_maxrss / 1024.0;
    double *all = c->rank == 0 ? malloc((size_t)c->size * sizeof *all) : NULL;
    MPI_Gather(&mine, 1, MPI_DOUBLE, all, 1, MPI_DOUBLE, 0, c->comm);
    if (all) {
        char line[4096];
        size_t used = 0;
        for (int r = 0; r < c->size && used < sizeof line; r++)
            used += (size_t)snprintf(line + used, sizeof line - used, "%s%.1f",
                                     r ? "/" : "", all[r]);
        cli_info(log, "Peak RSS per rank (whole run): %s MiB", line);
    }
    free(all);
}

/* Gmsh-partitioned input read per rank (split.c, docs/distributed.md §3):
   every rank reads its own parts, the ranks build the parts among
   themselves, the finishing step runs on a sub-mesh of the worst
   elements' patches (finish_sub.c), every rank writes its own output
   parts.  The exit code. */
static int run_split(dist_ctx *c, args *a, dist_split *s)
{
    cli_smooth_opts *so = &a->o;
    const cli_log *log = &so->log;
    char msg[1200] = "", err[1200] = "", note[DIST_PATH + 200] = "";
    int code = 0;
    getme_mesh *part = NULL;
    double *xyz = NULL;
    getme_result res;
    memset(&res, 0, sizeof res);
    double t0 = MPI_Wtime();
    if (c->rank == 0) {
        if (so->report) {
            cli_error("--report: not written for Gmsh-partitioned input "
                      "read per rank (getme smooth writes it)");
            code = EXIT_USAGE;
        } else if (dist_split_check_output(s, a->output, msg, sizeof msg,
                                           note, sizeof note) != 0) {
            cli_error("%s", msg);
            code = EXIT_USAGE;
        } else if (note[0]) {
            cli_warning(log, "%s", note);
        }
    }
    MPI_Bcast(&code, 1, MPI_INT, 0, c->comm);
    if (code)
        return code;

    /* 1. every rank reads its own parts; any failure stops all */
    dist_split_range(s, c->rank, c->size);
    getme_doc_options opts;
    cli_smooth_doc_options(so, &opts);
    unsigned flags = (opts.fix_skin ? (unsigned)GETME_FIX_SKIN : 0u) |
                     (opts.fix_interfaces ? (unsigned)GETME_FIX_INTERFACES : 0u);
    char first[DIST_PATH], last[DIST_PATH];
    dist_split_path(s, 1, first, sizeof first);
    dist_split_path(s, s->nparts, last, sizeof last);
    if (s->mode == DIST_SPLIT_FILES)
        cli_info(log, "Reading %d split files '%s' .. '%s' on %d ranks, each "
                 "rank its own...", s->nparts, first, last, c->size);
    else
        cli_info(log, "Reading '%s' (%d partitions) on %d ranks, each rank "
                 "its own partitions...", s->input, s->nparts, c->size);
    int rcode = 0;
    int bad = dist_split_read(s, &opts, msg, sizeof msg, &rcode) != 0;
    const char *fail = getenv("GETME_MPI_FAIL_RANK");
    if (!bad && fail && atoi(fail) == c->rank) {
        snprintf(msg, sizeof msg, "cannot read its part (failure injected by "
                 "GETME_MPI_FAIL_RANK)");
        bad = 1, rcode = 1;
    }
    int who = dist_agree(c, bad, msg, err, sizeof err);
    if (who >= 0) {
        MPI_Bcast(&rcode, 1, MPI_INT, who, c->comm);
        if (c->rank == 0)
            cli_error("rank %d of %d: %s; no output written", who, c->size,
                      err);
        return rcode;
    }

    /* 2. the parts: skin, interfaces, ghost layer, neighbours; node ids
       and element indices for the finishing step's keys */
    double tp = MPI_Wtime();
    if (dist_split_setup(s, c, flags) != 0) {
        if (c->rank == 0)
            cli_error("setting up the parts: an exchange failed; no output "
                      "written");
        return 1;
    }
    code = dist_split_ids(s, c, msg, sizeof msg) != 0;
    if (code) {
        if (c->rank == 0)
            cli_error("%s; no output written", msg);
        return 1;
    }
    getme_status st = build_part(c, &part);
    msg[0] = 0;
    if (st != GETME_OK)
        snprintf(msg, sizeof msg, "building its part: %s",
                 part ? getme_mesh_error(part) : getme_status_string(st));
    if (!msg[0] && dist_comm_init(c) != 0)
        snprintf(msg, sizeof msg, "out of memory for communication");
    who = dist_agree(c, msg[0] != 0, msg, err, sizeof err);
    if (who >= 0) {
        if (c->rank == 0)
            cli_error("rank %d of %d: %s; no output written", who, c->size,
                      err);
        getme_mesh_free(part);
        return 1;
    }
    /* the whole mesh's statistics, reduced over the parts (no mesh on
       rank 0 holds it) */
    getme_quality_stats before, after;
    if (dist_split_stats(c, part, &before) != 0) {
        if (c->rank == 0)
            cli_error("out of memory for the statistics; no output written");
        getme_mesh_free(part);
        return 1;
    }
    int64_t nodes[2] = {0, 0}; /* the whole mesh's nodes, fixed ones */
    for (int32_t i = 0; i < c->nn; i++) {
        nodes[0] += c->counted[i];
        nodes[1] += c->counted[i] && c->fixed[i];
    }
    MPI_Allreduce(MPI_IN_PLACE, nodes, 2, MPI_INT64_T, MPI_SUM, c->comm);
    if (c->rank == 0) {
        cli_info(log, "Parts set up in %.2f s: %lld elements, %lld nodes "
                 "(%lld fixed), %lld interface nodes, %lld ghost elements",
                 MPI_Wtime() - tp, (long long)before.num_elements,
                 (long long)nodes[0], (long long)nodes[1],
                 (long long)c->interface_nodes, (long long)c->ghost_elements);
        cli_print_stats(log, "Quality before", &before);
    }
    dist_split_measures(c, part, log, "Measures before");

    /* 3. smooth; the finishing step on a sub-mesh (finish_sub.c) */
    getme_params params = so->params;
    double loop_seconds = 0.0;
    if (smooth_parts(c, a, part, &params, &res, &loop_seconds) != 0) {
        getme_mesh_free(part);
        return 1;
    }
    double tf = MPI_Wtime();
    params.progress = c->rank == 0 ? cli_smooth_progress : NULL;
    params.progress_data = so; /* rank 0 alone: getme smooth's lines */
    if (dist_finish(c, part, NULL, &params, &res, err, sizeof err) != 0) {
        if (c->rank == 0)
            cli_error("%s: %s; no output written", a->input, err);
        getme_mesh_free(part);
        return 1;
    }
    double finish_seconds = MPI_Wtime() - tf;
    if (c->sub_tries && log->verbose)
        cli_info(log, "Finishing step on rank 0 on a sub-mesh of %lld "
                 "elements (%lld node copies gathered, %d tr%s)",
                 (long long)c->sub_elements, (long long)c->sub_nodes,
                 c->sub_tries, c->sub_tries == 1 ? "y" : "ies");
    if (dist_split_stats(c, part, &after) != 0) {
        if (c->rank == 0)
            cli_error("out of memory for the statistics; no output written");
        getme_mesh_free(part);
        return 1;
    }
    if (c->rank == 0) {
        cli_info(log, "GETMe adaptive: %d iterations (%d q_mean, %d "
                 "q*_min in %d cycles) in %.2f s on %d ranks, finishing "
                 "%d passes in %.2f s",
                 res.iterations, res.iterations_mean, res.iterations_min,
                 res.cycles_min, loop_seconds, c->size, res.passes_finish,
                 finish_seconds);
        cli_smooth_done(so, &res);
        cli_print_stats(log, "Quality after ", &after);
    }
    dist_split_measures(c, part, log, "Measures after ");
    /* the final positions: into the node tables (split files, each rank
       writes its own) or on rank 0 (one file) */
    if (s->mode == DIST_SPLIT_FILES)
        for (int32_t i = 0; i < s->nn; i++)
            memcpy(s->node[i].x, getme_mesh_coords(part) + 3 * (size_t)i,
                   sizeof s->node[i].x);
    else
        dist_split_gather(s, c, getme_mesh_coords(part), &xyz);
    getme_mesh_free(part);

    /* 4. every rank writes its own output parts */
    if (code == 0) {
        cli_guard guard = {0};
        cli_write_guard(&guard, 1);
        cli_info(log, "Writing '%s'%s...", a->output,
                 s->mode == DIST_SPLIT_FILES ? " as parts _1 .. _N, each by "
                                               "its rank" : " on rank 0");
        if (dist_split_write(s, c, a->output, xyz, msg, sizeof msg) != 0) {
            if (c->rank == 0)
                cli_error("%s", msg);
            code = CLI_EXIT_WRITE;
        } else {
            cli_info(log, "Done (%.2f s in all)", MPI_Wtime() - t0);
        }
        cli_write_guard(&guard, 0);
    }
    log_peak_rss(c, log);
    free(xyz);
    return code;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    dist_ctx c;
    memset(&c, 0, sizeof c);
    c.comm = MPI_COMM_WORLD;
    c.t128 = MPI_DATATYPE_NULL;
    c.op128 = MPI_OP_NULL;
    MPI_Comm_rank(c.comm, &c.rank);
    MPI_Comm_size(c.comm, &c.size);
    args a;
    memset(&a, 0, sizeof a);
    /* rank 0 parses (and prints any error or --help) first; the others
       parse the same argv only when it succeeded, silently */
    int code = c.rank == 0 ? parse(argc, argv, &a) : 0;
    MPI_Bcast(&code, 1, MPI_INT, 0, c.comm);
    if (code == 0 && c.rank != 0)
        code = parse(argc, argv, &a);
    if (code != 0) {
        cli_smooth_opts_free(&a.o);
        MPI_Finalize();
        return code < 0 ? 0 : code;
    }
    if (c.rank != 0)
        a.o.log.quiet = 1; /* rank 0 logs; errors reach it (agree) */
    /* Gmsh-partitioned input: every rank reads its own parts when there
       are at least as many parts as ranks; else rank 0 reads and splits */
    dist_split *split = calloc(1, sizeof *split);
    if (!split) {
        cli_error("out of memory");
        MPI_Abort(c.comm, 1);
    }
    if (c.rank == 0)
        dist_split_detect(split, a.input);
    MPI_Bcast(split, (int)sizeof *split, MPI_BYTE, 0, c.comm);
    if (split->mode != DIST_SPLIT_NONE && split->nparts >= c.size) {
        code = run_split(&c, &a, split);
        dist_split_free(split);
        free(split);
        dist_comm_free(&c);
        dist_part_free(&c);
        cli_smooth_opts_free(&a.o);
        MPI_Finalize();
        return code;
    }
    if (split->mode != DIST_SPLIT_NONE)
        cli_info(&a.o.log, "%d partitions for %d ranks: rank 0 reads them "
                 "all and splits the mesh with METIS", split->nparts, c.size);
    free(split);
    cli_smooth_opts *so = &a.o;
    const cli_log *log = &so->log;
    double t0 = MPI_Wtime();
    char err[1200] = "", msg[1200] = "";
    getme_doc *doc = NULL;
    getme_mesh *part = NULL;
    double *xyz = NULL;
    getme_result res;
    memset(&res, 0, sizeof res);
    getme_quality_stats before;
    cli_measures mbefore;
    getme_untangle_result ur;
    memset(&ur, 0, sizeof ur);
    cli_paths paths = {a.input, a.output, so->report, "", ""};

    /* 1. rank 0 reads, checks the paths, untangles if needed, splits */
    if (c.rank == 0) {
        code = read_input(&a, &paths, c.size, &doc, &before, &mbefore, &ur);
        if (code != 0) {
            dist_go(&c, code);
            goto out;
        }
        getme_mesh *mesh = getme_doc_mesh(doc);
        double tp = MPI_Wtime();
        if (dist_partition_send(mesh, &c, err, sizeof err) != 0) {
            cli_error("%s: %s", a.input, err);
            MPI_Abort(c.comm, 1); /* ranks may be waiting for parts */
        }
        cli_info(log, "Split into %d parts with METIS in %.2f s: %lld "
                 "interface nodes, %lld ghost elements",
                 c.size, MPI_Wtime() - tp, (long long)c.interface_nodes,
                 (long long)c.ghost_elements);
    } else {
        int r = dist_partition_recv(&c);
        if (r == -2) { /* rank 0 could not read: it said why */
            code = c.exit_code;
            goto out;
        }
        if (r != 0)
            snprintf(msg, sizeof msg, "cannot receive its part");
    }

    /* 2. every rank builds its part; any failure stops all */
    {
        const char *fail = getenv("GETME_MPI_FAIL_RANK");
        if (!msg[0] && fail && atoi(fail) == c.rank)
            snprintf(msg, sizeof msg, "cannot read its part (failure "
                     "injected by GETME_MPI_FAIL_RANK)");
        getme_status st = GETME_OK;
        if (!msg[0] && (st = build_part(&c, &part)) != GETME_OK)
            snprintf(msg, sizeof msg, "building its part: %s",
                     part ? getme_mesh_error(part) : getme_status_string(st));
        if (!msg[0] && dist_comm_init(&c) != 0)
            snprintf(msg, sizeof msg, "out of memory for communication");
        int first = dist_agree(&c, msg[0] != 0, msg, err, sizeof err);
        if (first >= 0) {
            if (c.rank == 0)
                cli_error("rank %d of %d: %s; no output written", first,
                          c.size, err);
            code = 1;
            goto out;
        }
    }

    /* 3. smooth */
    getme_params params = so->params;
    double loop_seconds = 0.0;
    if (smooth_parts(&c, &a, part, &params, &res, &loop_seconds) != 0) {
        code = 1;
        goto out;
    }
    /* 4. the finishing step on the worst elements' patches (finish_sub.c):
       then every part holds the final positions */
    double tf = MPI_Wtime();
    params.progress = c.rank == 0 ? cli_smooth_progress : NULL;
    params.progress_data = so; /* rank 0 alone: getme smooth's lines */
    if (dist_finish(&c, part, doc ? getme_doc_mesh(doc) : NULL, &params,
                    &res, err, sizeof err) != 0) {
        if (c.rank == 0)
            cli_error("%s: %s; no output written", a.input, err);
        code = 1;
        goto out;
    }
    double finish_seconds = MPI_Wtime() - tf;
    if (c.sub_tries && log->verbose)
        cli_info(log, "Finishing step on rank 0 on a sub-mesh of %lld "
                 "elements (%lld node copies gathered, %d tr%s)",
                 (long long)c.sub_elements, (long long)c.sub_nodes,
                 c.sub_tries, c.sub_tries == 1 ? "y" : "ies");
    /* 5. gather the counted nodes' positions on rank 0 */
    {
        const double *x = getme_mesh_coords(part);
        int n = 0;
        for (int32_t i = 0; i < c.nn; i++)
            n += c.counted[i];
        int32_t *ids = malloc((size_t)(n ? n : 1) * sizeof *ids);
        double *pos = malloc((size_t)(n ? n : 1) * 3 * sizeof *pos);
        int ok = ids && pos;
        for (int32_t i = 0, k = 0; ok && i < c.nn; i++)
            if (c.counted[i]) {
                ids[k] = c.gid[i];
                memcpy(pos + 3 * (size_t)k++, x + 3 * (size_t)i,
                       3 * sizeof *x);
            }
        int *counts = NULL, *displs = NULL, *c3 = NULL, *d3 = NULL;
        int32_t *all_ids = NULL;
        double *all_pos = NULL;
        if (c.rank == 0) {
            counts = calloc((size_t)c.size, sizeof *counts);
            displs = calloc((size_t)c.size, sizeof *displs);
            c3 = calloc((size_t)c.size, sizeof *c3);
            d3 = calloc((size_t)c.size, sizeof *d3);
            ok = ok && counts && displs && c3 && d3;
        }
        int okall = 0;
        MPI_Allreduce(&ok, &okall, 1, MPI_INT, MPI_LAND, c.comm);
        if (!okall) {
            if (c.rank == 0)
                fprintf(stderr, "Error   : out of memory gathering the "
                                "positions; no output written\n");
            free(ids), free(pos), free(counts), free(displs), free(c3),
                free(d3);
            code = 1;
            goto out;
        }
        MPI_Gather(&n, 1, MPI_INT, counts, 1, MPI_INT, 0, c.comm);
        int total = 0;
        if (c.rank == 0) {
            for (int r = 0; r < c.size; r++) {
                displs[r] = total;
                c3[r] = 3 * counts[r];
                d3[r] = 3 * total;
                total += counts[r];
            }
            all_ids = malloc((size_t)(total ? total : 1) * sizeof *all_ids);
            all_pos = malloc((size_t)(total ? total : 1) * 3 * sizeof *all_pos);
            if (!all_ids || !all_pos) {
                fprintf(stderr, "Error   : out of memory gathering\n");
                MPI_Abort(c.comm, 1);
            }
        }
        MPI_Gatherv(ids, n, MPI_INT32_T, all_ids, counts, displs, MPI_INT32_T,
                    0, c.comm);
        MPI_Gatherv(pos, 3 * n, MPI_DOUBLE, all_pos, c3, d3, MPI_DOUBLE, 0,
                    c.comm);
        if (c.rank == 0) {
            getme_mesh *mesh = getme_doc_mesh(doc);
            int32_t gnn = getme_mesh_num_nodes(mesh);
            xyz = malloc((size_t)gnn * 3 * sizeof *xyz);
            if (!xyz) {
                fprintf(stderr, "Error   : out of memory\n");
                MPI_Abort(c.comm, 1);
            }
            getme_mesh_get_coords(mesh, xyz);
            for (int k = 0; k < total; k++)
                memcpy(xyz + 3 * (size_t)all_ids[k], all_pos + 3 * (size_t)k,
                       3 * sizeof *xyz);
        }
        free(ids), free(pos), free(counts), free(displs), free(c3), free(d3);
        free(all_ids), free(all_pos);
    }

    /* 6. rank 0: write */
    if (c.rank == 0) {
        getme_mesh *mesh = getme_doc_mesh(doc);
        getme_status st = getme_mesh_set_coords(mesh, xyz);
        res.num_invalid_initial = ur.num_invalid_before;
        res.untangle_sweeps = ur.sweeps;
        res.untangle_seconds = ur.seconds;
        if (st != GETME_OK) {
            cli_error("%s: %s; no output written", a.input,
                      getme_mesh_error(mesh));
            code = 1;
        } else {
            cli_info(log, "GETMe adaptive: %d iterations (%d q_mean, %d "
                     "q*_min in %d cycles) in %.2f s on %d ranks, finishing "
                     "%d passes in %.2f s",
                     res.iterations, res.iterations_mean, res.iterations_min,
                     res.cycles_min, loop_seconds, c.size, res.passes_finish,
                     finish_seconds);
            code = finish_output(&a, &paths, doc, &before, &mbefore, &res);
            if (code == 0)
                cli_info(log, "Done (%.2f s in all)", MPI_Wtime() - t0);
        }
    }
    MPI_Bcast(&code, 1, MPI_INT, 0, c.comm);
    log_peak_rss(&c, log);
out:
    free(xyz);
    getme_mesh_free(part);
    if (doc)
        getme_doc_close(doc);
    dist_comm_free(&c);
    dist_part_free(&c);
    cli_smooth_opts_free(&a.o);
    MPI_Finalize();
    return code;
}
