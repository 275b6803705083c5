/*
 * getme_mpi.c -- `mpirun -np N getme-mpi smooth IN -o OUT [-v] [-q]
 * [--threads T]`: distributed GETMe adaptive (docs/distributed.md).
 *
 * Rank 0 reads IN through libgetme_formats (fixed nodes by the same rules
 * as `getme smooth`), untangles it if needed as `getme smooth` does,
 * splits it with METIS and sends every rank its part; all ranks run
 * getme_smooth_part(); rank 0 gathers the positions, runs the finishing
 * step (getme_smooth_finish) and writes OUT, the same bytes as
 * `getme smooth IN -o OUT` writes.  A failure on any rank stops every rank
 * with one error line from rank 0 and no output.
 *
 * Exit codes: 0 ok, 1 a rank failed (smoothing, communication), 2 usage,
 * 3-8 as `getme smooth` (reading and writing, exit_code below).
 */
#include "dist.h"

#ifdef GETME_HAVE_GMSH
#include "getme_gmsh.h"
#endif

#include <omp.h>
#include <stdarg.h>
#include <sys/resource.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* getme smooth's exit codes for libgetme_formats' statuses (cli.h). */
static int exit_code(getme_formats_status st)
{
    switch (st) {
    case GETME_FORMATS_OK: return 0;
    case GETME_FORMATS_ERR_OPEN: return 3;
    case GETME_FORMATS_ERR_PARSE: return 4;
    case GETME_FORMATS_ERR_UNSUPPORTED: return 5;
    case GETME_FORMATS_ERR_INVALID: return 6;
    case GETME_FORMATS_ERR_WRITE: return 7;
    case GETME_FORMATS_ERR_ARGUMENT: return 2;
    case GETME_FORMATS_ERR_INTERNAL: return 1;
    }
    return 1;
}

enum { EXIT_TANGLED = 8 };

typedef struct args {
    const char *input, *output;
    int verbose, quiet, threads;
} args;

typedef struct run_state {
    dist_ctx *c;
    const args *a;
    int64_t last_bytes;
    double last_seconds;
} run_state;

static void info(const args *a, int rank, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void info(const args *a, int rank, const char *fmt, ...)
{
    if (rank != 0 || a->quiet)
        return;
    va_list ap;
    va_start(ap, fmt);
    fputs("Info    : ", stdout);
    vfprintf(stdout, fmt, ap);
    fputc('\n', stdout);
    fflush(stdout);
    va_end(ap);
}

static const char USAGE[] =
    "usage: mpirun -np N getme-mpi smooth IN -o OUT [-v] [-q] [--threads T]\n"
    "\n"
    "Distributed GETMe adaptive: rank 0 reads IN (.msh, .inp, .cgns), splits\n"
    "it with METIS, every rank smooths its part with one ghost layer, rank 0\n"
    "writes OUT -- the same bytes as `getme smooth IN -o OUT` for any N and\n"
    "T. Fixed nodes follow getme smooth's rules. -v adds one line per\n"
    "iteration with the communication volume and time. T: OpenMP threads\n"
    "per rank (default 1).\n";

static int parse(int argc, char **argv, args *a)
{
    memset(a, 0, sizeof *a);
    a->threads = 1;
    if (argc < 2 || strcmp(argv[1], "smooth") != 0)
        return -1;
    for (int i = 2; i < argc; i++) {
        const char *o = argv[i];
        if (!strcmp(o, "-o") && i + 1 < argc)
            a->output = argv[++i];
        else if (!strcmp(o, "-v"))
            a->verbose = 1;
        else if (!strcmp(o, "-q"))
            a->quiet = 1;
        else if (!strcmp(o, "--threads") && i + 1 < argc)
            a->threads = atoi(argv[++i]);
        else if (o[0] != '-' && !a->input)
            a->input = o;
        else
            return -1;
    }
    return a->input && a->output && a->threads > 0 ? 0 : -1;
}

/* Per iteration with -v: called on every rank with the same values, so
   the reduction of the communication counters is collective. */
static int on_progress(const getme_progress *p, void *data)
{
    run_state *s = data;
    dist_ctx *c = s->c;
    if (!s->a->verbose)
        return 0;
    double v[2] = {(double)(c->bytes_sent + c->bytes_reduced), c->comm_seconds};
    double bytes = 0.0, secs = 0.0;
    MPI_Reduce(&v[0], &bytes, 1, MPI_DOUBLE, MPI_SUM, 0, c->comm);
    MPI_Reduce(&v[1], &secs, 1, MPI_DOUBLE, MPI_MAX, 0, c->comm);
    const char *stage = p->stage == GETME_STAGE_MEAN  ? "q_mean"
                        : p->stage == GETME_STAGE_MIN ? "q*_min"
                                                      : "finish";
    info(s->a, c->rank,
         "%4d %-6s q*min %.6f qmean %.6f transformed %d relaxed %d | "
         "comm %.1f KiB, %.2f ms",
         p->iteration, stage, p->q_min_star, p->q_mean,
         (int)p->num_transformed, (int)p->num_relaxed,
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

/* The lowest failing rank's message to rank 0; every rank learns whether
   any failed (returns the failing rank, or -1). */
static int agree(dist_ctx *c, int failed, const char *msg, char *out,
                 size_t size)
{
    int mine = failed ? c->rank : c->size, first = c->size;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, c->comm);
    if (first == c->size)
        return -1;
    if (first != 0) {
        if (c->rank == first)
            MPI_Send(msg, (int)strlen(msg) + 1, MPI_CHAR, 0, 99, c->comm);
        if (c->rank == 0)
            MPI_Recv(out, (int)size, MPI_CHAR, first, 99, c->comm,
                     MPI_STATUS_IGNORE);
    } else if (c->rank == 0) {
        snprintf(out, size, "%s", msg);
    }
    return first;
}

static void print_quality(const args *a, int rank, const char *title,
                          getme_mesh *mesh)
{
    getme_quality_stats s;
    if (rank == 0 && getme_mesh_quality_stats(mesh, -1, &s) == GETME_OK)
        info(a, rank, "%s: q*min %.4f, qmin %.4f, qmean %.4f (%lld elements)",
             title, s.q_min_star, s.q_min, s.q_mean, (long long)s.num_elements);
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
    if (parse(argc, argv, &a) != 0) {
        if (c.rank == 0)
            fputs(USAGE, stderr);
        MPI_Finalize();
        return 2;
    }
    double t0 = MPI_Wtime();
    int code = 0;
    char err[1200] = "", msg[1200] = "";
    getme_doc *doc = NULL;
    getme_mesh *part = NULL;
    double *xyz = NULL;
    getme_result res;
    memset(&res, 0, sizeof res);
    getme_params params;
    getme_params_init(&params);
    params.num_threads = a.threads;

    /* 1. rank 0 reads, checks the output path, untangles if needed */
    if (c.rank == 0) {
        getme_doc_options opts;
        getme_doc_options_init(&opts);
#ifdef GETME_HAVE_GMSH
        /* MSH files the native reader declines: through the Gmsh SDK, as
           getme smooth reads them */
        const getme_format *adapters[] = {getme_gmsh_format(), NULL};
        opts.adapters = adapters;
#endif
        info(&a, 0, "Reading '%s' on rank 0 of %d...", a.input, c.size);
        int ios = 0; /* the exit code */
        const getme_format *f = getme_format_for(a.input);
        if (!f) {
            snprintf(err, sizeof err, "%s: unknown format", a.input);
            ios = 2;
        } else if (!getme_format_has_extension(f, a.output)) {
            snprintf(err, sizeof err, "%s: the output needs the input's "
                     "format and extension (%s)", a.output,
                     getme_format_extensions(f));
            ios = 2;
        } else if (getme_io_same_file(a.input, a.output)) {
            snprintf(err, sizeof err, "%s: the output may not be the input",
                     a.output);
            ios = 2;
        } else if ((ios = exit_code(getme_doc_open(&doc, a.input, &opts))) ==
                   6 && getme_doc_mesh(doc)) {
            /* invalid elements: untangled as getme smooth does */
            ios = 0;
            getme_untangle_result ur;
            getme_status st = getme_mesh_untangle(getme_doc_mesh(doc),
                                                  &params, &ur);
            if (st != GETME_OK) {
                snprintf(err, sizeof err, "%s: %s", a.input,
                         getme_mesh_error(getme_doc_mesh(doc)));
                ios = EXIT_TANGLED;
            } else {
                info(&a, 0, "Untangled %lld invalid elements",
                     (long long)ur.num_invalid_before);
            }
        } else if (ios != 0) {
            snprintf(err, sizeof err, "%s", getme_doc_error(doc));
        }
        if (ios != 0) {
            fprintf(stderr, "Error   : %s\n", err);
            code = ios;
            dist_go(&c, code);
            goto out;
        }
        getme_mesh *mesh = getme_doc_mesh(doc);
        info(&a, 0, "Done reading '%s' (%s): %d elements, %d nodes (%d fixed)",
             a.input, getme_format_name(getme_doc_format(doc)),
             (int)getme_mesh_num_elements(mesh),
             (int)getme_mesh_num_nodes(mesh), (int)getme_mesh_num_fixed(mesh));
        print_quality(&a, 0, "Quality before", mesh);
        double tp = MPI_Wtime();
        if (dist_partition_send(mesh, &c, err, sizeof err) != 0) {
            fprintf(stderr, "Error   : %s: %s\n", a.input, err);
            MPI_Abort(c.comm, 1); /* ranks may be waiting for parts */
        }
        info(&a, 0, "Split into %d parts with METIS in %.2f s: %lld "
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
        int first = agree(&c, msg[0] != 0, msg, err, sizeof err);
        if (first >= 0) {
            if (c.rank == 0)
                fprintf(stderr, "Error   : rank %d of %d: %s; no output "
                        "written\n", first, c.size, err);
            code = 1;
            goto out;
        }
    }

    /* 3. smooth */
    run_state rs = {&c, &a, 0, 0.0};
    params.progress = on_progress;
    params.progress_data = &rs;
    getme_comm hooks;
    dist_comm_hooks(&c, &hooks);
    info(&a, c.rank, "Smoothing with GETMe adaptive (%d ranks, %d thread%s "
         "each)...", c.size, a.threads, a.threads == 1 ? "" : "s");
    double ts = MPI_Wtime();
    getme_status st = getme_smooth_part(part, &params, &hooks, &res);
    if (st != GETME_OK)
        snprintf(msg, sizeof msg, "smoothing: %s", getme_mesh_error(part));
    int first = agree(&c, st != GETME_OK, msg, err, sizeof err);
    if (first >= 0) {
        if (c.rank == 0)
            fprintf(stderr, "Error   : rank %d of %d: %s; no output written\n",
                    first, c.size, err);
        code = 1;
        goto out;
    }
    double loop_seconds = MPI_Wtime() - ts;
    if (a.verbose) { /* per rank: the benchmark's numbers (bench/mpi.py) */
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        int64_t owned = 0;
        for (int32_t e = 0; e < c.ne; e++)
            owned += c.owned[e];
        double mine[9] = {(double)c.ne, (double)owned, (double)c.nn,
                          c.nb_ptr ? (double)c.nb_ptr[c.num_nb] : 0.0,
                          loop_seconds, c.comm_seconds,
                          (double)c.bytes_sent, (double)c.bytes_reduced,
                          (double)ru.ru_maxrss / 1024.0};
        double *all = c.rank == 0 ? malloc((size_t)c.size * sizeof mine) : NULL;
        MPI_Gather(mine, 9, MPI_DOUBLE, all, 9, MPI_DOUBLE, 0, c.comm);
        for (int r = 0; all && r < c.size; r++) {
            const double *v = all + 9 * r;
            info(&a, 0, "Rank %d: %.0f elements (%.0f owned), %.0f nodes "
                 "(%.0f shared copies), loop %.3f s, comm %.3f s, sent "
                 "%.3f MiB, reduced %.3f MiB, max RSS %.1f MiB",
                 r, v[0], v[1], v[2], v[3], v[4], v[5], v[6] / 1048576.0,
                 v[7] / 1048576.0, v[8]);
        }
        free(all);
    }

    /* 4. gather the counted nodes' positions on rank 0 */
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

    /* 5. rank 0: the finishing step on the gathered mesh, then write */
    if (c.rank == 0) {
        getme_mesh *mesh = getme_doc_mesh(doc);
        double tf = MPI_Wtime();
        params.progress = NULL; /* its callback is collective */
        st = getme_smooth_finish(mesh, &params, xyz, &res);
        if (st != GETME_OK) {
            fprintf(stderr, "Error   : %s: %s; no output written\n", a.input,
                    getme_mesh_error(mesh));
            code = 1;
        } else {
            info(&a, 0, "GETMe adaptive: %d iterations (%d q_mean, %d q*_min "
                 "in %d cycles) in %.2f s on %d ranks, finishing %d passes "
                 "in %.2f s",
                 res.iterations, res.iterations_mean, res.iterations_min,
                 res.cycles_min, loop_seconds, c.size, res.passes_finish,
                 MPI_Wtime() - tf);
            print_quality(&a, 0, "Quality after ", mesh);
            info(&a, 0, "Writing '%s'...", a.output);
            getme_formats_status ws = getme_doc_write(doc, a.output);
            if (ws != GETME_FORMATS_OK) {
                fprintf(stderr, "Error   : %s\n", getme_doc_error(doc));
                code = exit_code(ws);
            } else {
                info(&a, 0, "Done writing '%s' (%.2f s in all)", a.output,
                     MPI_Wtime() - t0);
            }
        }
    }
    MPI_Bcast(&code, 1, MPI_INT, 0, c.comm);
out:
    free(xyz);
    getme_mesh_free(part);
    if (doc)
        getme_doc_close(doc);
    dist_comm_free(&c);
    dist_part_free(&c);
    MPI_Finalize();
    return code;
}
