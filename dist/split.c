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
 * The finishing step (getme_smooth_finish) still runs on rank 0 on the
 * whole mesh, which rank 0 gathers for it (split_whole); only that step
 * changes when the finishing step runs on gathered patches instead.
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

static void *xmalloc(size_t n) { return malloc(n ? n : 1); }

/* A failure inside the set-up's exchanges (out of memory, limits) stops
   the run: other ranks may be inside a collective call; there is no
   output yet. */
static void stop(const char *why)
{
    fprintf(stderr, "Error   : %s setting up the parts; no output "
                    "written\n", why);
    MPI_Abort(MPI_COMM_WORLD, 1);
}

static void *xalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p)
        stop("out of memory");
    return p;
}

static int home(uint64_t key, int p)
{
    key ^= key >> 33; /* splitmix64's finaliser: tags are often dense */
    key *= 0xff51afd7ed558ccdull;
    key ^= key >> 33;
    key *= 0xc4ceb9fe1a85ec53ull;
    key ^= key >> 33;
    return (int)(key % (uint64_t)p);
}

static int cmp_node(const void *a, const void *b)
{
    const node_rec *x = a, *y = b;
    return (x->tag > y->tag) - (x->tag < y->tag);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Index of tag in the sorted node table, -1 if absent. */
static int32_t find_node(const dist_split *s, uint64_t tag)
{
    int32_t lo = 0, hi = s->nn;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (s->node[mid].tag < tag)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < s->nn && s->node[lo].tag == tag ? lo : -1;
}

/* Sort the node table by tag and merge the copies of a node (the fixed
   marks ORed; copies must have the same coordinates).  0 or -1 (msg). */
static int merge_nodes(dist_split *s, char *msg, size_t size)
{
    qsort(s->node, (size_t)s->nn, sizeof *s->node, cmp_node);
    int32_t k = 0;
    for (int32_t i = 0; i < s->nn; i++) {
        if (k > 0 && s->node[k - 1].tag == s->node[i].tag) {
            if (memcmp(s->node[k - 1].x, s->node[i].x, sizeof s->node[i].x)) {
                snprintf(msg, size, "node %llu has different coordinates "
                         "in two parts", (unsigned long long)s->node[i].tag);
                return -1;
            }
            s->node[k - 1].fixed |= s->node[i].fixed;
        } else {
            s->node[k++] = s->node[i];
        }
    }
    s->nn = k;
    return 0;
}

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
    s->node = xmalloc((size_t)nn * sizeof *s->node);
    s->elem = xmalloc((size_t)ne * sizeof *s->elem);
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
        uint8_t *fx = xmalloc((size_t)n);
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
    return merge_nodes(s, msg, size);
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

/* ---- records to their ranks ---------------------------------------------- */

/* n records of variable width (data[ptr[i] .. ptr[i+1]), to rank dest[i])
   are exchanged; *recv / *rcount as dist_a2a; order[k] = the record that
   was k-th in the send buffer (grouped by rank, record order inside), so
   that an answer coming back in the same order is matched to its record.
   -1 (every rank) if an exchange could not be set up. */
static int exchange(dist_ctx *c, int64_t n, const int *dest,
                    const int64_t *ptr, const int64_t *data, int64_t **recv,
                    int **rcount, int64_t **order)
{
    int p = c->size;
    int64_t *pos = xalloc(((size_t)p + 1) * sizeof *pos);
    int64_t *rpos = xalloc(((size_t)p + 1) * sizeof *rpos);
    int *scount = xalloc((size_t)p * sizeof *scount);
    int64_t *send = xalloc((size_t)ptr[n] * sizeof *send);
    *order = xalloc((size_t)n * sizeof **order);
    memset(pos, 0, ((size_t)p + 1) * sizeof *pos);
    memset(rpos, 0, ((size_t)p + 1) * sizeof *rpos);
    for (int64_t i = 0; i < n; i++) {
        pos[dest[i] + 1] += ptr[i + 1] - ptr[i];
        rpos[dest[i] + 1]++;
    }
    int too_big = 0;
    for (int q = 0; q < p; q++) {
        too_big |= pos[q + 1] > INT32_MAX;
        scount[q] = (int)pos[q + 1];
        pos[q + 1] += pos[q];
        rpos[q + 1] += rpos[q];
    }
    for (int64_t i = 0; i < n; i++) {
        int q = dest[i];
        int64_t w = ptr[i + 1] - ptr[i];
        memcpy(send + pos[q], data + ptr[i], (size_t)w * sizeof *data);
        pos[q] += w;
        (*order)[rpos[q]++] = i;
    }
    if (too_big)
        memset(scount, 0, (size_t)p * sizeof *scount);
    int rc = dist_a2a(c, send, scount, recv, rcount);
    int bad = too_big, any = 0;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, c->comm);
    free(pos), free(rpos), free(scount), free(send);
    return rc == 0 && !any ? 0 : -1;
}

/* Fixed-width records: ptr = w * i. */
static int64_t *widths(int64_t n, int w)
{
    int64_t *ptr = xalloc(((size_t)n + 1) * sizeof *ptr);
    for (int64_t i = 0; i <= n; i++)
        ptr[i] = w * i;
    return ptr;
}

/* ---- 1. faces: skin and interfaces -------------------------------------- */

typedef struct face {
    uint64_t k[4];  /* sorted node tags, 0-padded */
    int64_t region; /* at home: the record's index */
} face;

static int cmp_face(const void *a, const void *b)
{
    const face *x = a, *y = b;
    for (int i = 0; i < 4; i++)
        if (x->k[i] != y->k[i])
            return x->k[i] < y->k[i] ? -1 : 1;
    return (x->region > y->region) - (x->region < y->region);
}

static int same_key(const face *x, const face *y)
{
    return !memcmp(x->k, y->k, sizeof x->k);
}

/* The faces of the linear volume types as corner lists (-1 ends; the same
   in Gmsh's and getme's numbering). */
static const int8_t FACES[4][6][5] = {
    /* tet */ {{0, 1, 2, -1}, {0, 1, 3, -1}, {0, 2, 3, -1}, {1, 2, 3, -1},
               {-1}, {-1}},
    /* hex */ {{0, 1, 2, 3, -1}, {4, 5, 6, 7, -1}, {0, 1, 5, 4, -1},
               {1, 2, 6, 5, -1}, {2, 3, 7, 6, -1}, {3, 0, 4, 7, -1}},
    /* prism */ {{0, 1, 2, -1}, {3, 4, 5, -1}, {0, 1, 4, 3, -1},
                 {1, 2, 5, 4, -1}, {2, 0, 3, 5, -1}, {-1}},
    /* pyramid */ {{0, 1, 2, 3, -1}, {0, 1, 4, -1}, {1, 2, 4, -1},
                   {2, 3, 4, -1}, {3, 0, 4, -1}, {-1}}};

static void fix_face(dist_split *s, const face *f)
{
    for (int i = 0; i < 4 && f->k[i]; i++)
        s->node[find_node(s, f->k[i])].fixed = 1;
}

/* The flag of every face record received at home: 1 skin (once in the
   mesh), 2 interface (twice, different regions), else 0. */
static int64_t *face_flags(const face *hf, int64_t nr)
{
    face *t = xalloc((size_t)nr * sizeof *t);
    int64_t *flag = xalloc((size_t)nr * sizeof *flag);
    for (int64_t i = 0; i < nr; i++) {
        t[i] = hf[i];
        t[i].region = i;
    }
    qsort(t, (size_t)nr, sizeof *t, cmp_face);
    for (int64_t i = 0, j; i < nr; i = j) {
        int diff = 0;
        for (j = i + 1; j < nr && same_key(&t[i], &t[j]); j++)
            diff |= hf[t[j].region].region != hf[t[i].region].region;
        for (int64_t k = i; k < j; k++)
            flag[t[k].region] = j - i == 1 ? 1 : diff ? 2 : 0;
    }
    free(t);
    return flag;
}

static int mark_faces(dist_split *s, dist_ctx *c, unsigned flags)
{
    int64_t nf = 0;
    for (int32_t e = 0; e < s->own_ne; e++)
        for (int f = 0; f < 6 && FACES[s->elem[e].type][f][0] >= 0; f++)
            nf++;
    face *fs = xalloc((size_t)nf * sizeof *fs);
    nf = 0;
    for (int32_t e = 0; e < s->own_ne; e++) {
        const dist_elem *el = &s->elem[e];
        for (int f = 0; f < 6 && FACES[el->type][f][0] >= 0; f++) {
            face *x = &fs[nf++];
            int n = 0;
            for (; n < 4 && FACES[el->type][f][n] >= 0; n++)
                x->k[n] = el->node[FACES[el->type][f][n]];
            for (int i = n; i < 4; i++)
                x->k[i] = 0;
            qsort(x->k, (size_t)n, sizeof *x->k, cmp_u64);
            x->region = el->region;
        }
    }
    qsort(fs, (size_t)nf, sizeof *fs, cmp_face);
    /* faces twice in the rank's parts: interfaces if the regions differ;
       faces once go home */
    int64_t nsend = 0;
    for (int64_t i = 0, j; i < nf; i = j) {
        for (j = i + 1; j < nf && same_key(&fs[i], &fs[j]); j++)
            ;
        if (j - i == 1)
            fs[nsend++] = fs[i];
        else if ((flags & GETME_FIX_INTERFACES) &&
                 fs[i].region != fs[j - 1].region)
            fix_face(s, &fs[i]);
    }
    int *dest = xalloc((size_t)nsend * sizeof *dest);
    for (int64_t i = 0; i < nsend; i++)
        dest[i] = home(fs[i].k[0] ^ fs[i].k[1] * 0x9e3779b97f4a7c15ull ^
                           fs[i].k[2] * 0xbf58476d1ce4e5b9ull ^
                           fs[i].k[3] * 0x94d049bb133111ebull,
                       c->size);
    int64_t *ptr = widths(nsend, 5), *recv = NULL, *order = NULL;
    int *rcount = NULL;
    int rc = exchange(c, nsend, dest, ptr, (const int64_t *)(void *)fs, &recv,
                      &rcount, &order);
    if (rc == 0) {
        int64_t nr = 0;
        for (int q = 0; q < c->size; q++)
            nr += rcount[q] / 5;
        int64_t *flag = face_flags((const face *)(void *)recv, nr);
        /* answers go back in the order the records came */
        int *bdest = xalloc((size_t)nr * sizeof *bdest);
        for (int q = 0, k = 0; q < c->size; q++)
            for (int i = 0; i < rcount[q] / 5; i++)
                bdest[k++] = q;
        int64_t *bptr = widths(nr, 1), *ans = NULL, *border = NULL;
        int *acount = NULL;
        rc = exchange(c, nr, bdest, bptr, flag, &ans, &acount, &border);
        for (int64_t k = 0; rc == 0 && k < nsend; k++)
            if ((ans[k] == 1 && (flags & GETME_FIX_SKIN)) ||
                (ans[k] == 2 && (flags & GETME_FIX_INTERFACES)))
                fix_face(s, &fs[order[k]]);
        free(flag), free(bdest), free(bptr), free(ans), free(acount);
        free(border);
    }
    free(fs), free(dest), free(ptr), free(recv), free(rcount), free(order);
    return rc;
}

/* ---- 2. and 3. node directory ------------------------------------------- */

/* Every node of the table goes home as (tag, fixed); home ORs the fixed
   marks of its copies and answers each copy with (fixed, number of other
   holders, their ranks).  The answers land in s->node[].fixed and the CSR
   s->optr / s->orank (other holders per node). */
static int directory(dist_split *s, dist_ctx *c)
{
    int64_t n = s->nn;
    int *dest = xalloc((size_t)n * sizeof *dest);
    int64_t *data = xalloc((size_t)n * 2 * sizeof *data);
    for (int64_t i = 0; i < n; i++) {
        dest[i] = home(s->node[i].tag, c->size);
        data[2 * i] = (int64_t)s->node[i].tag;
        data[2 * i + 1] = s->node[i].fixed;
    }
    int64_t *ptr = widths(n, 2), *recv = NULL, *order = NULL;
    int *rcount = NULL;
    int rc = exchange(c, n, dest, ptr, data, &recv, &rcount, &order);
    free(data), free(ptr);
    if (rc != 0) {
        free(dest);
        return -1;
    }
    /* at home: (tag, source rank, record) sorted */
    int64_t nr = 0;
    for (int q = 0; q < c->size; q++)
        nr += rcount[q] / 2;
    int64_t (*t)[3] = xalloc((size_t)nr * sizeof *t);
    int *src = xalloc((size_t)nr * sizeof *src);
    for (int q = 0, k = 0; q < c->size; q++)
        for (int i = 0; i < rcount[q] / 2; i++, k++) {
            t[k][0] = recv[2 * k];
            t[k][1] = q;
            t[k][2] = k;
            src[k] = q;
        }
    qsort(t, (size_t)nr, sizeof *t, cmp_u64); /* by tag (first word) */
    /* stable by source within a tag: sort each tag's run by rank */
    int64_t *aptr = xalloc(((size_t)nr + 1) * sizeof *aptr);
    int64_t *gfirst = xalloc((size_t)nr * sizeof *gfirst);
    int64_t *glen = xalloc((size_t)nr * sizeof *glen);
    int64_t *gfix = xalloc((size_t)nr * sizeof *gfix);
    for (int64_t i = 0, j; i < nr; i = j) {
        int64_t fx = 0;
        for (j = i; j < nr && t[j][0] == t[i][0]; j++)
            fx |= recv[2 * t[j][2] + 1];
        for (int64_t a = i + 1; a < j; a++) /* few copies: insertion */
            for (int64_t b = a; b > i && t[b][1] < t[b - 1][1]; b--) {
                int64_t tmp[3];
                memcpy(tmp, t[b], sizeof tmp);
                memcpy(t[b], t[b - 1], sizeof tmp);
                memcpy(t[b - 1], tmp, sizeof tmp);
            }
        for (int64_t k = i; k < j; k++) {
            gfirst[t[k][2]] = i;
            glen[t[k][2]] = j - i;
            gfix[t[k][2]] = fx;
        }
    }
    aptr[0] = 0;
    for (int64_t k = 0; k < nr; k++)
        aptr[k + 1] = aptr[k] + 1 + glen[k];
    int64_t *ans = xalloc((size_t)aptr[nr] * sizeof *ans);
    for (int64_t k = 0; k < nr; k++) {
        int64_t *a = ans + aptr[k], m = 0;
        a[0] = gfix[k];
        a[1] = glen[k] - 1;
        for (int64_t g = gfirst[k]; g < gfirst[k] + glen[k]; g++)
            if (t[g][2] != k)
                a[2 + m++] = t[g][1];
    }
    free(t), free(gfirst), free(glen), free(gfix), free(recv), free(rcount);
    int64_t *back = NULL, *border = NULL;
    int *bcount = NULL;
    rc = exchange(c, nr, src, aptr, ans, &back, &bcount, &border);
    free(src), free(aptr), free(ans), free(border);
    if (rc == 0) {
        /* answers come grouped by home rank in the order sent: order[] */
        free(s->optr), free(s->orank);
        s->optr = xalloc(((size_t)n + 1) * sizeof *s->optr);
        int64_t total = 0, at = 0;
        for (int64_t k = 0; k < n; k++) {
            total += back[at + 1];
            at += 2 + back[at + 1];
        }
        s->orank = xalloc((size_t)total * sizeof *s->orank);
        int64_t *cnt = xalloc((size_t)n * sizeof *cnt), *pos = NULL;
        at = 0;
        for (int64_t k = 0; k < n; k++) {
            cnt[order[k]] = at;
            at += 2 + back[at + 1];
        }
        s->optr[0] = 0;
        for (int64_t i = 0; i < n; i++) {
            const int64_t *a = back + cnt[i];
            s->node[i].fixed = a[0];
            s->optr[i + 1] = s->optr[i] + a[1];
            for (int64_t m = 0; m < a[1]; m++)
                s->orank[s->optr[i] + m] = (int)a[2 + m];
        }
        free(cnt), free(pos);
    }
    free(back), free(bcount), free(order), free(dest);
    return rc;
}

/* ---- the ghost layer ---------------------------------------------------- */

/* Each own element touching a node other ranks hold goes to them (once
   per rank): (tag, type, region, nv, then per node tag, x, y, z, fixed). */
static int ghosts(dist_split *s, dist_ctx *c)
{
    int64_t n = 0, words = 0;
    int ranks[MAXV * 64];
    for (int pass = 0; pass < 2; pass++) {
        int *dest = pass ? xalloc((size_t)n * sizeof *dest) : NULL;
        int64_t *ptr = pass ? xalloc(((size_t)n + 1) * sizeof *ptr) : NULL;
        int64_t *data = pass ? xalloc((size_t)words * sizeof *data) : NULL;
        int64_t k = 0, w = 0;
        if (pass)
            ptr[0] = 0;
        for (int32_t e = 0; e < s->own_ne; e++) {
            const dist_elem *el = &s->elem[e];
            int nr = 0;
            for (int j = 0; j < el->nv; j++) {
                int32_t i = find_node(s, el->node[j]);
                for (int64_t h = s->optr[i]; h < s->optr[i + 1]; h++) {
                    int q = s->orank[h], seen = 0;
                    for (int m = 0; m < nr && !seen; m++)
                        seen = ranks[m] == q;
                    if (!seen && nr == MAXV * 64)
                        stop("an element's nodes have more than 512 other "
                             "holders");
                    if (!seen)
                        ranks[nr++] = q;
                }
            }
            for (int m = 0; m < nr; m++) {
                int64_t rw = 4 + 5 * (int64_t)el->nv;
                if (pass) {
                    int64_t *r = data + w;
                    dest[k] = ranks[m];
                    r[0] = el->tag, r[1] = el->type, r[2] = el->region;
                    r[3] = el->nv;
                    for (int j = 0; j < el->nv; j++) {
                        const node_rec *nd =
                            &s->node[find_node(s, el->node[j])];
                        int64_t *x = r + 4 + 5 * j;
                        x[0] = (int64_t)nd->tag;
                        memcpy(x + 1, nd->x, 3 * sizeof *x);
                        x[4] = nd->fixed;
                    }
                    ptr[k + 1] = ptr[k] + rw;
                }
                k++;
                w += rw;
            }
        }
        if (!pass) {
            n = k;
            words = w;
            continue;
        }
        int64_t *recv = NULL, *order = NULL;
        int *rcount = NULL;
        int rc = exchange(c, n, dest, ptr, data, &recv, &rcount, &order);
        free(dest), free(ptr), free(data), free(order);
        if (rc != 0)
            return -1;
        int64_t total = 0, ng = 0, nnew = 0;
        for (int q = 0; q < c->size; q++)
            total += rcount[q];
        for (int64_t at = 0; at < total; at += 4 + 5 * recv[at + 3]) {
            ng++;
            nnew += recv[at + 3];
        }
        dist_elem *el = realloc(s->elem, ((size_t)s->ne + (size_t)ng + 1) *
                                             sizeof *el);
        node_rec *nd = realloc(s->node, ((size_t)s->nn + (size_t)nnew + 1) *
                                            sizeof *nd);
        if (!el || !nd)
            stop("out of memory");
        s->elem = el, s->node = nd;
        for (int64_t at = 0; at < total; at += 4 + 5 * recv[at + 3]) {
            dist_elem *g = &s->elem[s->ne++];
            g->tag = recv[at], g->type = (int)recv[at + 1];
            g->region = (int32_t)recv[at + 2], g->nv = (int)recv[at + 3];
            for (int j = 0; j < g->nv; j++) {
                const int64_t *x = recv + at + 4 + 5 * j;
                node_rec *r = &s->node[s->nn++];
                g->node[j] = r->tag = (uint64_t)x[0];
                memcpy(r->x, x + 1, sizeof r->x);
                r->fixed = x[4];
            }
        }
        free(recv), free(rcount);
    }
    char msg[200];
    int bad = merge_nodes(s, msg, sizeof msg) != 0, any = 0;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, c->comm);
    return any ? -1 : 0;
}

/* ---- the part ------------------------------------------------------------ */

/* The rank's part into c (the arrays partition.c fills otherwise). */
static void fill_ctx(const dist_split *s, dist_ctx *c)
{
    c->nn = s->nn;
    c->ne = s->ne;
    c->coords = xalloc((size_t)s->nn * 3 * sizeof *c->coords);
    c->fixed = xalloc((size_t)s->nn);
    c->gid = xalloc((size_t)s->nn * sizeof *c->gid);
    c->counted = xalloc((size_t)s->nn);
    c->etype = xalloc((size_t)s->ne);
    c->owned = xalloc((size_t)s->ne);
    c->nconn = 0;
    for (int32_t e = 0; e < s->ne; e++)
        c->nconn += s->elem[e].nv;
    c->conn = xalloc((size_t)c->nconn * sizeof *c->conn);
    for (int32_t i = 0; i < s->nn; i++) {
        memcpy(c->coords + 3 * (size_t)i, s->node[i].x, 3 * sizeof(double));
        c->fixed[i] = s->node[i].fixed != 0;
        c->gid[i] = i;
        int lowest = 1;
        for (int64_t h = s->optr[i]; h < s->optr[i + 1]; h++)
            lowest &= s->orank[h] > c->rank;
        c->counted[i] = (uint8_t)lowest;
    }
    int64_t m = 0;
    for (int32_t e = 0; e < s->ne; e++) {
        c->etype[e] = (uint8_t)s->elem[e].type;
        c->owned[e] = e < s->own_ne;
        for (int j = 0; j < s->elem[e].nv; j++)
            c->conn[m++] = find_node(s, s->elem[e].node[j]);
    }
    /* neighbours: per rank, the shared nodes in ascending tag */
    int *cnt = xalloc((size_t)c->size * sizeof *cnt);
    memset(cnt, 0, (size_t)c->size * sizeof *cnt);
    for (int64_t h = 0; h < s->optr[s->nn]; h++)
        cnt[s->orank[h]]++;
    c->num_nb = 0;
    for (int q = 0; q < c->size; q++)
        c->num_nb += cnt[q] > 0;
    c->nb_rank = xalloc((size_t)c->num_nb * sizeof *c->nb_rank);
    c->nb_count = xalloc((size_t)c->num_nb * sizeof *c->nb_count);
    c->nb_ptr = xalloc(((size_t)c->num_nb + 1) * sizeof *c->nb_ptr);
    int *slot = xalloc((size_t)c->size * sizeof *slot);
    c->nb_ptr[0] = 0;
    for (int q = 0, k = 0; q < c->size; q++)
        if (cnt[q] > 0) {
            c->nb_rank[k] = q;
            c->nb_count[k] = cnt[q];
            c->nb_ptr[k + 1] = c->nb_ptr[k] + cnt[q];
            slot[q] = k++;
        }
    c->nb_node = xalloc((size_t)c->nb_ptr[c->num_nb] * sizeof *c->nb_node);
    int64_t *pos = xalloc(((size_t)c->num_nb + 1) * sizeof *pos);
    for (int k = 0; k < c->num_nb; k++)
        pos[k] = c->nb_ptr[k];
    for (int32_t i = 0; i < s->nn; i++) /* ascending tag */
        for (int64_t h = s->optr[i]; h < s->optr[i + 1]; h++)
            c->nb_node[pos[slot[s->orank[h]]]++] = i;
    free(pos), free(cnt), free(slot);
}

/* What an element order of the whole mesh needs on every rank (the
   finishing step on gathered patches breaks ties by the Morton key of an
   element's first node in the whole mesh's box, then by its index in the
   single-process order): the box, and whether the element tags are one
   dense run (Gmsh numbers a file's volume elements consecutively in its
   order), in which case that index is tag - tag_min. */
static void order_keys(dist_split *s, dist_ctx *c)
{
    double lo[3] = {1e308, 1e308, 1e308}, hi[3] = {-1e308, -1e308, -1e308};
    for (int32_t i = 0; i < s->nn; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = s->node[i].x[k] < lo[k] ? s->node[i].x[k] : lo[k];
            hi[k] = s->node[i].x[k] > hi[k] ? s->node[i].x[k] : hi[k];
        }
    MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPI_DOUBLE, MPI_MIN, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPI_DOUBLE, MPI_MAX, c->comm);
    int64_t tmin = INT64_MAX, tmax = INT64_MIN, n = s->own_ne;
    for (int32_t e = 0; e < s->own_ne; e++) {
        tmin = s->elem[e].tag < tmin ? s->elem[e].tag : tmin;
        tmax = s->elem[e].tag > tmax ? s->elem[e].tag : tmax;
    }
    MPI_Allreduce(MPI_IN_PLACE, &tmin, 1, MPI_INT64_T, MPI_MIN, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, &tmax, 1, MPI_INT64_T, MPI_MAX, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT64_T, MPI_SUM, c->comm);
    for (int k = 0; k < 3; k++) {
        s->box[k] = lo[k];
        s->box[3 + k] = hi[k];
    }
    s->tag_min = tmin;
    s->dense_tags = tmax - tmin + 1 == n; /* tags are distinct */
}

int dist_split_setup(dist_split *s, dist_ctx *c, unsigned fix_flags)
{
    if (mark_faces(s, c, fix_flags) != 0 || directory(s, c) != 0 ||
        ghosts(s, c) != 0 || directory(s, c) != 0)
        return -1;
    fill_ctx(s, c);
    int64_t mine[2] = {0, s->ne - s->own_ne}, all[2];
    for (int32_t i = 0; i < s->nn; i++)
        mine[0] += c->counted[i] && s->optr[i + 1] > s->optr[i];
    MPI_Allreduce(mine, all, 2, MPI_INT64_T, MPI_SUM, c->comm);
    c->interface_nodes = all[0];
    c->ghost_elements = all[1];
    order_keys(s, c);
    return 0;
}

/* ---- the whole mesh on rank 0, for the finishing step -------------------- */

/* Gather int64 records of every rank on rank 0 (*all, *n words there). */
static void gather(dist_ctx *c, const int64_t *mine, int64_t n, int64_t **all,
                   int64_t *total)
{
    int cnt = (int)n, *counts = NULL, *displs = NULL;
    if (n > INT32_MAX)
        stop("a part too large to gather");
    if (c->rank == 0) {
        counts = xalloc((size_t)c->size * sizeof *counts);
        displs = xalloc((size_t)c->size * sizeof *displs);
    }
    MPI_Gather(&cnt, 1, MPI_INT, counts, 1, MPI_INT, 0, c->comm);
    *total = 0;
    for (int q = 0; c->rank == 0 && q < c->size; q++) {
        displs[q] = (int)*total;
        *total += counts[q];
        if (*total > INT32_MAX)
            stop("a mesh too large to gather on rank 0");
    }
    *all = c->rank == 0 ? xalloc((size_t)*total * sizeof **all) : NULL;
    MPI_Gatherv(mine, cnt, MPI_INT64_T, *all, counts, displs, MPI_INT64_T, 0,
                c->comm);
    free(counts), free(displs);
}

static int cmp_elem(const void *a, const void *b)
{
    const int64_t *x = *(int64_t *const *)a, *y = *(int64_t *const *)b;
    return (x[0] > y[0]) - (x[0] < y[0]);
}

/* Rank 0 builds the whole mesh as getme smooth reads the unpartitioned
   file: nodes in ascending tag, elements in ascending tag (Gmsh numbers
   both in its file order), the fixed marks agreed above.  The other ranks
   send their own elements and the nodes they count. */
int dist_split_whole(dist_split *s, dist_ctx *c, char *msg, size_t size)
{
    int64_t words = 0, nc = 0;
    for (int32_t e = 0; e < s->own_ne; e++)
        words += 3 + s->elem[e].nv;
    for (int32_t i = 0; i < s->nn; i++)
        nc += c->counted[i];
    int64_t *mine = xalloc((size_t)(words + 5 * nc) * sizeof *mine), w = 0;
    for (int32_t i = 0; i < s->nn; i++)
        if (c->counted[i]) {
            mine[w++] = (int64_t)s->node[i].tag;
            memcpy(mine + w, s->node[i].x, 3 * sizeof *mine);
            w += 3;
            mine[w++] = s->node[i].fixed;
        }
    int64_t *nodes = NULL, *elems = NULL, nw = 0, ew = 0;
    gather(c, mine, w, &nodes, &nw);
    w = 0;
    for (int32_t e = 0; e < s->own_ne; e++) {
        const dist_elem *el = &s->elem[e];
        mine[w++] = el->tag;
        mine[w++] = el->type;
        mine[w++] = el->nv;
        for (int j = 0; j < el->nv; j++)
            mine[w++] = (int64_t)el->node[j];
    }
    gather(c, mine, w, &elems, &ew);
    free(mine);
    free(s->elem), free(s->optr), free(s->orank); /* the set-up's tables */
    s->elem = NULL, s->optr = NULL, s->orank = NULL;
    if (c->rank != 0)
        return 0;
    int rc = -1;
    int64_t nn = nw / 5, ne = 0;
    for (int64_t at = 0; at < ew; at += 3 + elems[at + 2])
        ne++;
    node_rec *nd = xalloc((size_t)nn * sizeof *nd);
    int64_t **ep = xalloc((size_t)ne * sizeof *ep);
    for (int64_t i = 0; i < nn; i++) {
        nd[i].tag = (uint64_t)nodes[5 * i];
        memcpy(nd[i].x, nodes + 5 * i + 1, sizeof nd[i].x);
        nd[i].fixed = nodes[5 * i + 4];
    }
    free(nodes);
    qsort(nd, (size_t)nn, sizeof *nd, cmp_node);
    ne = 0;
    for (int64_t at = 0; at < ew; at += 3 + elems[at + 2])
        ep[ne++] = elems + at;
    qsort(ep, (size_t)ne, sizeof *ep, cmp_elem);
    s->whole_nn = (int32_t)nn;
    s->whole_tag = xalloc((size_t)nn * sizeof *s->whole_tag);
    double *xyz = xalloc((size_t)nn * 3 * sizeof *xyz);
    uint8_t *fixed = xalloc((size_t)nn);
    int32_t *conn = xalloc((size_t)(ew ? ew : 1) * sizeof *conn);
    for (int64_t i = 0; i < nn; i++) {
        s->whole_tag[i] = nd[i].tag;
        memcpy(xyz + 3 * i, nd[i].x, 3 * sizeof *xyz);
        fixed[i] = nd[i].fixed != 0;
    }
    free(nd);
    getme_status st = getme_mesh_create(&s->whole, 3, (int32_t)nn, xyz);
    for (int64_t e = 0; e < ne && st == GETME_OK;) {
        int64_t e1 = e, m = 0;
        while (e1 < ne && ep[e1][1] == ep[e][1]) { /* a run of one type */
            for (int j = 0; j < ep[e1][2]; j++)
                conn[m++] = whole_index(s, (uint64_t)ep[e1][3 + j]);
            e1++;
        }
        st = getme_mesh_add_elements(s->whole, (getme_elem_type)ep[e][1],
                                     (int32_t)(e1 - e), conn, NULL);
        e = e1;
    }
    if (st == GETME_OK)
        st = getme_mesh_set_fixed_mask(s->whole, fixed);
    if (st == GETME_OK)
        rc = 0;
    else
        snprintf(msg, size, "the whole mesh for the finishing step: %s",
                 s->whole ? getme_mesh_error(s->whole)
                          : getme_status_string(st));
    free(ep), free(elems), free(xyz), free(fixed), free(conn);
    return rc;
}

int32_t whole_index(const dist_split *s, uint64_t tag)
{
    int32_t lo = 0, hi = s->whole_nn;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (s->whole_tag[mid] < tag)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < s->whole_nn && s->whole_tag[lo] == tag ? lo : -1;
}

/* The counted nodes' positions (the part's, after getme_smooth_part) into
   xyz on rank 0 (3 per whole-mesh node; the input's for the others). */
void dist_split_gather(dist_split *s, dist_ctx *c, const double *part_xyz,
                       double *xyz)
{
    int64_t n = 0;
    for (int32_t i = 0; i < s->nn; i++)
        n += c->counted[i];
    int64_t *mine = xalloc((size_t)n * 4 * sizeof *mine), w = 0, *all, tw;
    for (int32_t i = 0; i < s->nn; i++)
        if (c->counted[i]) {
            mine[w++] = (int64_t)s->node[i].tag;
            memcpy(mine + w, part_xyz + 3 * (size_t)i, 3 * sizeof *mine);
            w += 3;
        }
    gather(c, mine, w, &all, &tw);
    free(mine);
    for (int64_t k = 0; c->rank == 0 && k < tw; k += 4)
        memcpy(xyz + 3 * (size_t)whole_index(s, (uint64_t)all[k]),
               all + k + 1, 3 * sizeof *xyz);
    free(all);
}

/* ---- writing ------------------------------------------------------------ */

/* Rank 0's final coordinates into every rank's node table (by tag), from
   which its output parts are written. */
void dist_split_scatter(dist_split *s, dist_ctx *c, const double *xyz)
{
    int64_t n = s->nn;
    int64_t *tags = xalloc((size_t)n * sizeof *tags), *all, total;
    for (int32_t i = 0; i < s->nn; i++)
        tags[i] = (int64_t)s->node[i].tag;
    gather(c, tags, n, &all, &total);
    /* rank 0 answers in the same layout: 3 doubles per tag */
    int cnt = (int)(3 * n), *counts = NULL, *displs = NULL;
    double *ans = NULL, *mine = xalloc((size_t)n * 3 * sizeof *mine);
    if (c->rank == 0) {
        counts = xalloc((size_t)c->size * sizeof *counts);
        displs = xalloc((size_t)c->size * sizeof *displs);
        ans = xalloc((size_t)total * 3 * sizeof *ans);
        for (int64_t i = 0; i < total; i++)
            memcpy(ans + 3 * i,
                   xyz + 3 * (size_t)whole_index(s, (uint64_t)all[i]),
                   3 * sizeof *ans);
    }
    MPI_Gather(&cnt, 1, MPI_INT, counts, 1, MPI_INT, 0, c->comm);
    for (int q = 0, at = 0; c->rank == 0 && q < c->size; q++) {
        displs[q] = at;
        at += counts[q];
    }
    MPI_Scatterv(ans, counts, displs, MPI_DOUBLE, mine, cnt, MPI_DOUBLE, 0,
                 c->comm);
    for (int32_t i = 0; i < s->nn; i++)
        memcpy(s->node[i].x, mine + 3 * (size_t)i, sizeof s->node[i].x);
    free(tags), free(all), free(counts), free(displs), free(ans), free(mine);
}

void dist_split_free(dist_split *s)
{
    for (int d = 0; s->docs && d < s->count; d++)
        if (s->docs[d])
            getme_doc_close(s->docs[d]);
    free(s->docs);
    free(s->node), free(s->elem), free(s->optr), free(s->orank);
    free(s->whole_tag);
    getme_mesh_free(s->whole);
    s->docs = NULL, s->node = NULL, s->elem = NULL, s->optr = NULL;
    s->orank = NULL, s->whole_tag = NULL, s->whole = NULL;
}

/* Output part k's path: OUT_k.msh for split files (OUT.msh named), OUT
   for one partitioned file. */
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

/* The lowest failing rank's message on rank 0; every rank learns whether
   any failed (the failing rank, or -1). */
int dist_agree(dist_ctx *c, int failed, const char *msg, char *out,
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
    char (*tmp)[DIST_PATH] = xalloc((size_t)(nd ? nd : 1) * sizeof *tmp);
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
        double *x = xalloc((size_t)getme_mesh_num_nodes(m) * 3 * sizeof *x);
        for (int32_t i = 0; i < getme_mesh_num_nodes(m); i++) {
            uint64_t tag = getme_doc_node_id(doc, i);
            memcpy(x + 3 * (size_t)i,
                   s->mode == DIST_SPLIT_FILES
                       ? s->node[find_node(s, tag)].x
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
        renamed = xalloc((size_t)c->size * sizeof *renamed);
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
