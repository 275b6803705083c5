/*
 * split.c -- every rank reads its own part(s) of a Gmsh-partitioned mesh
 * (split files NAME_1.msh .. NAME_N.msh, or one file with N partitions)
 * and the ranks build the distributed parts among themselves
 * (docs/distributed.md §3, "Per-rank input and output").
 *
 * Global identity is the node tag: partition-boundary nodes appear in
 * every part that touches them.  Nothing is sent to rank 0 to set up the
 * parts; three rounds of personalised all-to-all exchanges (dist_a2a) do
 * it, each node or face going to a "home" rank chosen by hashing its
 * tags:
 *   1. faces: the faces a rank's elements have once (its part's skin) go
 *      home; a face seen once in the whole mesh is the model's skin, one
 *      seen twice with different region keys an interface between regions
 *      (interfaces inside a part are found locally);
 *   2. nodes: the fixed marks of every copy are ORed at home, which also
 *      tells every holder the other ranks holding the node; each rank then
 *      sends each element of its own that touches a shared node to the
 *      other holders of that node: the one ghost layer;
 *   3. nodes again (now with the ghosts' nodes): their holders, from which
 *      come the neighbour lists (shared nodes in ascending tag on both
 *      sides) and the counted copy (the lowest holder).
 * Fixed nodes thus follow getme smooth's rules on the whole mesh: nodes
 * the reader fixes (not classified on a volume or one of its partition
 * pieces; --fix groups), the whole mesh's skin, region interfaces.
 *
 * The finishing step runs on the worst elements' patches (finish_sub.c),
 * keyed by the node ids and element indices of split_finish.c: no rank
 * holds the whole mesh.
 *
 * This file: finding the parts, reading them, writing the output parts;
 * split_setup.c: the three exchange rounds; split_finish.c: ids, element
 * indices and statistics for the finishing step and the log.
 */
#include "dist.h"
#include "cli.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef dist_node node_rec;

enum { MAXV = 8 };

static void *malloc1(size_t n) { return malloc(n ? n : 1); }

/* ---- reading ------------------------------------------------------------ */

void dist_split_path(const dist_split *s, int k, char *buf, size_t size)
{
    if (s->mode == DIST_SPLIT_FILES)
        snprintf(buf, size, "%.4000s_%d.msh", s->stem, k);
    else
        snprintf(buf, size, "%s", s->input);
}

/* "$PartitionedEntities" before "$Nodes": the number of partitions (0 if
   none).  Reads the file's head only. */
static int count_partitions(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    char line[256];
    int binary = -1, n = 0; /* -1: not MSH 4.1, not scanned */
    if (fgets(line, sizeof line, f) && !strncmp(line, "$MeshFormat", 11) &&
        fgets(line, sizeof line, f)) {
        double v = 0;
        sscanf(line, "%lf %d", &v, &binary);
        if (v != 4.1)
            binary = -1;
    }
    int c, at_line_start = 1;
    size_t len = 0;
    while (binary >= 0 && (c = fgetc(f)) != EOF) {
        if (at_line_start && c == '$')
            len = 0;
        if (len < sizeof line - 1)
            line[len++] = (char)c;
        at_line_start = c == '\n';
        if (!at_line_start || line[0] != '$') {
            if (at_line_start)
                len = 0;
            continue;
        }
        line[len] = 0;
        line[strcspn(line, "\r\n")] = 0; /* "\n" or "\r\n" */
        len = 0;
        if (!strcmp(line, "$Nodes"))
            break;
        if (strcmp(line, "$PartitionedEntities"))
            continue;
        if (binary) {
            unsigned char b[8];
            uint64_t x = 0;
            if (fread(b, 1, 8, f) == 8)
                for (int i = 7; i >= 0; i--)
                    x = x << 8 | b[i];
            n = x < 1u << 30 ? (int)x : 0;
        } else {
            unsigned long long x = 0;
            n = fscanf(f, "%llu", &x) == 1 && x < 1u << 30 ? (int)x : 0;
        }
        break;
    }
    fclose(f);
    return n;
}

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

int dist_split_detect(dist_split *s, const char *input)
{
    memset(s, 0, sizeof *s);
    snprintf(s->input, sizeof s->input, "%s", input);
    size_t n = strlen(input);
    if (n > 6 && !strcmp(input + n - 6, "_1.msh") &&
        n - 6 < sizeof s->stem) {
        memcpy(s->stem, input, n - 6);
        s->stem[n - 6] = 0;
        int np = count_partitions(input);
        if (np > 0) { /* the files are NAME_1 .. NAME_np: a missing one
                         is an error of the rank that reads it */
            s->mode = DIST_SPLIT_FILES;
            s->nparts = np;
            return s->mode;
        }
    }
    int np = count_partitions(input);
    if (np > 0) {
        s->mode = DIST_SPLIT_ONE;
        s->nparts = np;
    }
    return s->mode;
}

void dist_split_range(dist_split *s, int rank, int size)
{
    /* contiguous ranges of parts, the first ranks taking one more */
    int base = s->nparts / size, extra = s->nparts % size;
    s->count = base + (rank < extra);
    s->first = 1 + rank * base + (rank < extra ? rank : extra);
}

/* The rank's parts as read: the node table (sorted by tag) and its own
   elements. */
static int take_docs(dist_split *s, char *msg, size_t size)
{
    int64_t nn = 0, ne = 0;
    for (int d = 0; d < s->count; d++) {
        getme_mesh *m = getme_doc_mesh(s->docs[d]);
        nn += getme_mesh_num_nodes(m);
        ne += getme_mesh_num_elements(m);
    }
    if (nn > INT32_MAX || ne > INT32_MAX) {
        snprintf(msg, size, "its parts have more than 2^31 nodes or elements");
        return -1;
    }
    s->node = malloc1((size_t)nn * sizeof *s->node);
    s->elem = malloc1((size_t)ne * sizeof *s->elem);
    if (!s->node || !s->elem) {
        snprintf(msg, size, "out of memory");
        return -1;
    }
    s->nn = 0, s->ne = 0;
    for (int d = 0; d < s->count; d++) {
        getme_doc *doc = s->docs[d];
        getme_mesh *m = getme_doc_mesh(doc);
        int32_t n = getme_mesh_num_nodes(m);
        const double *x = getme_mesh_coords(m);
        uint8_t *fx = malloc1((size_t)n);
        if (!fx) {
            snprintf(msg, size, "out of memory");
            return -1;
        }
        getme_mesh_get_fixed_mask(m, fx);
        for (int32_t i = 0; i < n; i++) {
            node_rec *r = &s->node[s->nn++];
            r->tag = getme_doc_node_id(doc, i);
            memcpy(r->x, x + 3 * (size_t)i, sizeof r->x);
            r->fixed = fx[i];
        }
        free(fx);
        for (int32_t e = 0; e < getme_mesh_num_elements(m); e++) {
            dist_elem *el = &s->elem[s->ne++];
            getme_elem_type t;
            int32_t v[MAXV];
            int nv = getme_mesh_get_element(m, e, &t, v);
            el->type = (int)t;
            el->nv = nv;
            el->tag = getme_doc_element_id(doc, e);
            el->region = getme_doc_element_region(doc, e);
            for (int j = 0; j < nv; j++)
                el->node[j] = getme_doc_node_id(doc, v[j]);
        }
    }
    s->own_ne = s->ne;
    return dist_merge_nodes(s, msg, size);
}

int dist_split_read(dist_split *s, const getme_doc_options *base, char *msg,
                    size_t size, int *code)
{
    getme_doc_options o = *base;
    o.one_part = 1;
    o.adapters = NULL; /* a part the native reader declines is an error,
                          not a whole-model read through Gmsh */
    s->opts = o;
    s->docs = calloc((size_t)(s->count ? s->count : 1), sizeof *s->docs);
    if (!s->docs) {
        snprintf(msg, size, "out of memory");
        *code = 1;
        return -1;
    }
    for (int d = 0; d < s->count; d++) {
        char path[DIST_PATH];
        int k = s->first + d;
        dist_split_path(s, k, path, sizeof path);
        o.partition = s->mode == DIST_SPLIT_ONE ? k : 0;
        getme_formats_status st = getme_doc_open(&s->docs[d], path, &o);
        if (st != GETME_FORMATS_OK) {
            const char *e = s->docs[d] ? getme_doc_error(s->docs[d])
                                       : "out of memory";
            snprintf(msg, size, "%s%s", e,
                     st == GETME_FORMATS_ERR_INVALID
                         ? " (getme-mpi reads valid parts only: untangle "
                           "with getme smooth)"
                         : "");
            *code = cli_exit_code(st);
            return -1;
        }
        getme_mesh *m = getme_doc_mesh(s->docs[d]);
        if (!getme_doc_num_partitions(s->docs[d]) ||
            getme_mesh_dim(m) != 3 || getme_mesh_num_elements_ho(m) > 0) {
            snprintf(msg, size, "%s: not a part of a partitioned volume "
                     "mesh of linear elements as getme-mpi reads it per "
                     "rank (MSH 4.1 with $PartitionedEntities)", path);
            *code = CLI_EXIT_UNSUPPORTED;
            return -1;
        }
    }
    *code = 1;
    int rc = take_docs(s, msg, size);
    /* the documents are opened again to be written: not kept through the
       smoothing (a second copy of the part) */
    for (int d = 0; d < s->count; d++) {
        getme_doc_close(s->docs[d]);
        s->docs[d] = NULL;
    }
    return rc;
}

static void out_path(const dist_split *s, const char *output, int k,
                     char *buf, size_t size)
{
    size_t n = strlen(output);
    if (s->mode == DIST_SPLIT_FILES)
        snprintf(buf, size, "%.*s_%d.msh", (int)(n - 4), output, k);
    else
        snprintf(buf, size, "%s", output);
}

int dist_split_check_output(const dist_split *s, const char *output,
                            char *msg, size_t size, char *note,
                            size_t note_size)
{
    size_t n = strlen(output);
    note[0] = 0;
    if (s->mode == DIST_SPLIT_FILES &&
        (n < 5 || strcmp(output + n - 4, ".msh") != 0)) {
        snprintf(msg, size, "%s: split partition files are written as "
                 "OUT_1.msh .. OUT_%d.msh: name the output OUT.msh", output,
                 s->nparts);
        return -1;
    }
    char in[DIST_PATH], out[DIST_PATH], real[DIST_PATH], why[600];
    int nout = s->mode == DIST_SPLIT_FILES ? s->nparts : 1;
    for (int k = 1; k <= nout; k++) {
        out_path(s, output, k, out, sizeof out);
        if (getme_io_output_path(out, real, sizeof real, why, sizeof why) !=
            GETME_FORMATS_OK) {
            snprintf(msg, size, "%s", why);
            return -1;
        }
        for (int j = 1; j <= s->nparts; j++) {
            dist_split_path(s, j, in, sizeof in);
            if (getme_io_same_file(out, in)) {
                snprintf(msg, size, "Cannot write '%s': it is the input "
                         "part '%s'; choose another output name", out, in);
                return -1;
            }
            if (s->mode == DIST_SPLIT_ONE)
                break;
        }
    }
    if (s->mode == DIST_SPLIT_FILES) {
        /* an earlier run's parts beyond N are not this output's */
        out_path(s, output, s->nparts + 1, out, sizeof out);
        if (exists(out))
            snprintf(note, note_size,
                     "'%s' (and any later part) is left from an earlier "
                     "run with more parts: it is not part of this output",
                     out);
    }
    return 0;
}

/* Tests: the environment variable names this rank (a failure to
   inject). */
static int injected(const char *var, int rank)
{
    const char *v = getenv(var);
    return v && *v && atoi(v) == rank;
}

/* Every rank writes its output parts to temporary files; when all are
   written (agreed), every rank renames its own.  One partitioned file:
   rank 0 reads it again again and writes it.  0, or -1 with rank 0's
   message in msg (the failing rank named; after a failed rename, which
   parts are new). */
int dist_split_write(dist_split *s, dist_ctx *c, const char *output,
                     const double *xyz, char *msg, size_t size)
{
    char err[900] = "", first_err[1000] = "";
    int nd = s->mode == DIST_SPLIT_FILES ? s->count : c->rank == 0;
    char (*tmp)[DIST_PATH] = dist_xalloc((size_t)(nd ? nd : 1) * sizeof *tmp);
    getme_doc *again = NULL;
    int failed = 0, made = 0;
    for (int d = 0; d < nd && !failed; d++) {
        char out[DIST_PATH];
        out_path(s, output, s->first + d, out, sizeof out);
        /* the input part read again (one file: whole, on rank 0), its
           nodes given the final positions by tag */
        char in[DIST_PATH];
        getme_doc_options o = s->opts;
        o.partition = 0;
        dist_split_path(s, s->first + d, in, sizeof in);
        if (getme_doc_open(&again, in, &o) != GETME_FORMATS_OK) {
            snprintf(err, sizeof err, "reading %.300s again to write it: "
                     "%.500s", in, again ? getme_doc_error(again) : "");
            failed = 1;
            break;
        }
        getme_doc *doc = again;
        getme_mesh *m = getme_doc_mesh(doc);
        double *x = dist_xalloc((size_t)getme_mesh_num_nodes(m) * 3 * sizeof *x);
        for (int32_t i = 0; i < getme_mesh_num_nodes(m); i++) {
            uint64_t tag = getme_doc_node_id(doc, i);
            memcpy(x + 3 * (size_t)i,
                   s->mode == DIST_SPLIT_FILES
                       ? s->node[dist_find_node(s, tag)].x
                       : xyz + 3 * (size_t)whole_index(s, tag),
                   3 * sizeof *x);
        }
        getme_mesh_set_coords(m, x);
        free(x);
        if (getme_io_tmp_path(out, tmp[d], sizeof tmp[d]) != 0) {
            snprintf(err, sizeof err, "cannot write '%.700s': %s", out,
                     strerror(errno));
            failed = 1;
        } else if (made++, getme_doc_write(doc, tmp[d]) != GETME_FORMATS_OK) {
            snprintf(err, sizeof err, "%s", getme_doc_error(doc));
            failed = 1;
        } else if (injected("GETME_MPI_FAIL_WRITE", c->rank)) {
            snprintf(err, sizeof err, "cannot write '%.700s' (failure "
                     "injected by GETME_MPI_FAIL_WRITE)", out);
            failed = 1;
        }
        getme_doc_close(again);
        again = NULL;
    }
    if (again)
        getme_doc_close(again);
    int who = dist_agree(c, failed, err, first_err, sizeof first_err);
    if (who >= 0) {
        for (int d = 0; d < made; d++)
            remove(tmp[d]);
        free(tmp);
        snprintf(msg, size, "rank %d of %d: %s", who, c->size, first_err);
        return -1;
    }
    /* all written: rename; a rename failing leaves some parts new */
    int bad = 0;
    for (int d = 0; d < nd; d++) {
        char out[DIST_PATH];
        out_path(s, output, s->first + d, out, sizeof out);
        if (bad) {
            remove(tmp[d]);
        } else if (injected("GETME_MPI_FAIL_RENAME", c->rank)) {
            remove(tmp[d]);
            snprintf(err, sizeof err, "cannot rename to '%.700s' (failure "
                     "injected by GETME_MPI_FAIL_RENAME)", out);
            bad = 1 + d;
        } else if (getme_io_commit(tmp[d], out) != 0) {
            snprintf(err, sizeof err, "cannot rename to '%.700s': %s", out,
                     strerror(errno));
            bad = 1 + d;
        }
    }
    free(tmp);
    /* renamed[k] per rank: how many of its parts are new */
    int mine = bad ? bad - 1 : nd, *renamed = NULL;
    if (c->rank == 0)
        renamed = dist_xalloc((size_t)c->size * sizeof *renamed);
    MPI_Gather(&mine, 1, MPI_INT, renamed, 1, MPI_INT, 0, c->comm);
    who = dist_agree(c, bad != 0, err, first_err, sizeof first_err);
    if (who >= 0 && c->rank == 0) {
        size_t used = (size_t)snprintf(msg, size, "rank %d of %d: %s; new "
                                       "parts:", who, c->size, first_err);
        dist_split range = *s;
        for (int q = 0; q < c->size && used < size; q++) {
            dist_split_range(&range, q, c->size);
            for (int d = 0; d < renamed[q] && used < size; d++) {
                char out[DIST_PATH];
                out_path(s, output, range.first + d, out, sizeof out);
                used += (size_t)snprintf(msg + used, size - used, " %s", out);
            }
        }
        if (used < size)
            snprintf(msg + used, size - used, "; the others are as before");
    }
    free(renamed);
    return who >= 0 ? -1 : 0;
}

void dist_split_free(dist_split *s)
{
    for (int d = 0; s->docs && d < s->count; d++)
        if (s->docs[d])
            getme_doc_close(s->docs[d]);
    free(s->docs);
    free(s->node), free(s->elem), free(s->optr), free(s->orank);
    free(s->whole_tag);
    s->docs = NULL, s->node = NULL, s->elem = NULL, s->optr = NULL;
    s->orank = NULL, s->whole_tag = NULL;
}

/* Output part k's path: OUT_k.msh for split files (OUT.msh named), OUT
   for one partitioned file. */
