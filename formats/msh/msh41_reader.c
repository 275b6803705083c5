/*
 * msh41_reader.c -- native streaming reader of Gmsh MSH 4.1 files (ASCII
 * and binary): $MeshFormat, $PhysicalNames, $Entities, $Nodes, $Elements;
 * every other section is skipped by scanning to its $End line.
 *
 * One pass, flat arrays only: node tags and coordinates in file order, one
 * flag byte per node, and the connectivity of the blocks of the highest
 * element dimension seen so far (lower-dimensional elements are checked
 * and dropped: they stay in the file, which the writer copies).  What the
 * mesh becomes is decided in msh41_build.c once the file is read.
 *
 * Binary numbers are little-endian with 8-byte size_t (data-size 8); they
 * are decoded byte by byte so that the host's byte order does not matter.
 */
#define _POSIX_C_SOURCE 200809L
#include "msh41_internal.h"
#include "getme_alloc.h"
#include "numparse.h"

#include <errno.h>
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define TOK 128

/* ---- messages ----------------------------------------------------------- */

getme_formats_status msh41_fail(msh41_reader *r, getme_formats_status st,
                           const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (r->binary)
        return getme_doc_fail(r->doc, st, "'%s': %s (byte %lld)",
                              r->doc->path, msg,
                              (long long)(r->msg_offset_set
                                              ? r->msg_offset
                                              : msh41_in_offset(&r->in)));
    return getme_doc_fail(r->doc, st, "'%s', line %ld: %s", r->doc->path,
                          r->in.line, msg);
}

getme_formats_status msh41_decline(msh41_reader *r, const char *why)
{
    snprintf(r->why, sizeof r->why, "%s", why);
    return MSH41_DECLINED;
}

/* For checks made after a whole line was read: name that line, not the
   next one. */
static getme_formats_status line_fail(msh41_reader *r, getme_formats_status st,
                                 const char *msg)
{
    long saved = r->in.line;
    r->in.line -= r->in.line > 1;
    msh41_fail(r, st, "%s", msg);
    r->in.line = saved;
    return st;
}

static getme_formats_status eof_error(msh41_reader *r)
{
    return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                      "unexpected end of file in $%s (truncated file?)",
                      r->section);
}

static getme_formats_status oom(msh41_reader *r)
{
    return getme_doc_fail(r->doc, GETME_FORMATS_ERR_INTERNAL,
                          "'%s': out of memory", r->doc->path);
}

/* ---- numbers ------------------------------------------------------------ */

static uint64_t le64(const unsigned char *b)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | b[i];
    return v;
}

static int32_t le32(const unsigned char *b)
{
    uint32_t v = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                 (uint32_t)b[3] << 24;
    return (int32_t)v; /* two's complement on every host gcc targets */
}

/* The next ASCII token, or an error naming what was expected. */
static getme_formats_status token(msh41_reader *r, char *tok, const char *what)
{
    int n = msh41_in_token(&r->in, tok, TOK);
    if (n == 0)
        return eof_error(r);
    if (n < 0)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE, "%s too long in $%s", what,
                          r->section);
    return GETME_FORMATS_OK;
}

static int parse_u64(const char *s, uint64_t *v)
{
    uint64_t x = 0;
    if (*s == '+')
        s++;
    if (!*s)
        return -1;
    for (; *s; s++) {
        if (*s < '0' || *s > '9' || x > (UINT64_MAX - 9) / 10)
            return -1;
        x = 10 * x + (uint64_t)(*s - '0');
    }
    *v = x;
    return 0;
}

static getme_formats_status read_u64(msh41_reader *r, uint64_t *v,
                                const char *what)
{
    if (r->binary) {
        unsigned char b[8];
        if (msh41_in_read(&r->in, b, 8))
            return eof_error(r);
        *v = le64(b);
        return GETME_FORMATS_OK;
    }
    char tok[TOK];
    getme_formats_status st = token(r, tok, what);
    if (st == GETME_FORMATS_OK && parse_u64(tok, v))
        st = msh41_fail(r, GETME_FORMATS_ERR_PARSE, "bad %s '%s' in $%s", what,
                        tok, r->section);
    return st;
}

static getme_formats_status read_int(msh41_reader *r, int *v, const char *what)
{
    if (r->binary) {
        unsigned char b[4];
        if (msh41_in_read(&r->in, b, 4))
            return eof_error(r);
        *v = le32(b);
        return GETME_FORMATS_OK;
    }
    char tok[TOK];
    getme_formats_status st = token(r, tok, what);
    if (st != GETME_FORMATS_OK)
        return st;
    uint64_t x;
    int neg = tok[0] == '-';
    if (parse_u64(tok + neg, &x) || x > (uint64_t)INT32_MAX)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE, "bad %s '%s' in $%s", what,
                          tok, r->section);
    *v = neg ? -(int)x : (int)x;
    return GETME_FORMATS_OK;
}

static getme_formats_status read_double(msh41_reader *r, double *v)
{
    if (r->binary) {
        unsigned char b[8];
        if (msh41_in_read(&r->in, b, 8))
            return eof_error(r);
        uint64_t bits = le64(b);
        memcpy(v, &bits, sizeof *v);
        return GETME_FORMATS_OK;
    }
    char tok[TOK], *end;
    getme_formats_status st = token(r, tok, "number");
    if (st != GETME_FORMATS_OK)
        return st;
    errno = 0;
    *v = numparse_strtod(tok, &end);
    if (*end || end == tok)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE, "bad number '%s' in $%s",
                          tok, r->section);
    return GETME_FORMATS_OK;
}

/* A count that must fit in the file (each item takes at least min_bytes):
   refuses absurd counts before anything is allocated for them. */
static getme_formats_status read_count(msh41_reader *r, uint64_t *v,
                                  const char *what, uint64_t min_bytes)
{
    getme_formats_status st = read_u64(r, v, what);
    if (st == GETME_FORMATS_OK && *v > (uint64_t)r->file_size / min_bytes)
        st = msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                        "%s %llu is more than the file can hold", what,
                        (unsigned long long)*v);
    return st;
}

/* ---- section frame ------------------------------------------------------ */

/* After a section's data: the "$End<name>" line (binary data ends with a
   newline before it). */
static getme_formats_status expect_end(msh41_reader *r)
{
    char line[TOK], want[64];
    snprintf(want, sizeof want, "$End%s", r->section);
    msh41_in_skip_space(&r->in);
    if (msh41_in_line(&r->in, line, sizeof line) || strcmp(line, want) != 0) {
        char msg[160];
        snprintf(msg, sizeof msg,
                 "expected %s (wrong count or truncated data in $%s)", want,
                 r->section);
        return line_fail(r, GETME_FORMATS_ERR_PARSE, msg);
    }
    return GETME_FORMATS_OK;
}

/* Sections we do not need ($Periodic, $NodeData, $GhostElements...): scan
   their lines to "$End<name>".  Binary payloads are scanned as lines too;
   a payload holding exactly "\n$EndName\n" is not a concern in practice,
   and computing the size of every kind of section would tie this reader
   to each of their layouts. */
static getme_formats_status skip_section(msh41_reader *r, const char *name)
{
    char line[TOK], want[TOK + 8];
    snprintf(want, sizeof want, "$End%s", name);
    while (msh41_in_line(&r->in, line, sizeof line) == 0)
        if (strcmp(line, want) == 0)
            return GETME_FORMATS_OK;
    return msh41_fail(r, GETME_FORMATS_ERR_PARSE, "no %s before the end of the file",
                      want);
}

/* ---- $MeshFormat -------------------------------------------------------- */

static getme_formats_status read_format(msh41_reader *r)
{
    char line[TOK];
    double version = 0;
    int file_type = -1, data_size = 0;
    /* Sections Gmsh skips ($Comments...) may come first, as may text
       between sections; a mesh section may not. */
    for (;;) {
        r->section = "MeshFormat";
        if (msh41_in_line(&r->in, line, sizeof line) ||
            strcmp(line, "$Nodes") == 0 || strcmp(line, "$Elements") == 0 ||
            strcmp(line, "$Entities") == 0)
            return line_fail(r, GETME_FORMATS_ERR_PARSE,
                             "not a Gmsh MSH file (no $MeshFormat header)");
        if (strcmp(line, "$MeshFormat") == 0)
            break;
        getme_formats_status st;
        if (line[0] == '$' && (st = skip_section(r, line + 1)) != GETME_FORMATS_OK)
            return st;
    }
    if (msh41_in_line(&r->in, line, sizeof line) ||
        sscanf(line, "%lf %d %d", &version, &file_type, &data_size) != 3 ||
        (file_type != 0 && file_type != 1))
        return line_fail(r, GETME_FORMATS_ERR_PARSE,
                         "bad $MeshFormat header (want \"4.1 0|1 8\" or "
                         "\"2.2 0|1 8\")");
    if (version != 4.1 && version != 2.2)
        return msh41_decline(r, "not MSH 4.1 or 2.2");
    r->v22 = version == 2.2;
    r->binary = file_type == 1;
    if (r->binary && data_size != 8)
        return msh41_fail(r, GETME_FORMATS_ERR_UNSUPPORTED,
                          "binary MSH with data size %d: only 8-byte size_t "
                          "is supported",
                          data_size);
    if (r->binary) {
        unsigned char one[4];
        if (msh41_in_read(&r->in, one, 4))
            return eof_error(r);
        if (le32(one) == 0x01000000)
            return msh41_decline(r, "big-endian binary file");
        if (le32(one) != 1)
            return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                              "bad endianness marker in $MeshFormat");
    }
    return expect_end(r);
}

/* ---- $PhysicalNames (ASCII in both flavours) ----------------------------- */

static getme_formats_status read_name(msh41_reader *r, msh41_pname *p)
{
    char line[1024];
    msh41_in_skip_space(&r->in);
    if (msh41_in_line(&r->in, line, sizeof line))
        return eof_error(r);
    int used = 0;
    char *q1 = strchr(line, '"'), *q2 = q1 ? strrchr(line, '"') : NULL;
    if (sscanf(line, "%d %d %n", &p->dim, &p->tag, &used) < 2 || !q1 ||
        q2 == q1)
        return line_fail(r, GETME_FORMATS_ERR_PARSE,
                         "bad physical name line (want: dim tag \"name\")");
    p->name = getme__malloc((size_t)(q2 - q1));
    if (!p->name)
        return oom(r);
    memcpy(p->name, q1 + 1, (size_t)(q2 - q1 - 1));
    p->name[q2 - q1 - 1] = 0;
    return GETME_FORMATS_OK;
}

static getme_formats_status read_physical_names(msh41_reader *r)
{
    char line[TOK];
    unsigned long long n = 0;
    r->section = "PhysicalNames";
    int save = r->binary;
    r->binary = 0; /* text even in binary files */
    getme_formats_status st = GETME_FORMATS_OK;
    msh41_in_skip_space(&r->in);
    if (msh41_in_line(&r->in, line, sizeof line) ||
        sscanf(line, "%llu", &n) != 1 || n > (uint64_t)r->file_size / 6)
        st = line_fail(r, GETME_FORMATS_ERR_PARSE, "bad number of names");
    if (st == GETME_FORMATS_OK && r->names == NULL && n > 0) {
        r->names = getme__calloc((size_t)n, sizeof *r->names);
        if (!r->names)
            st = oom(r);
    } else if (st == GETME_FORMATS_OK && n > 0) {
        st = msh41_fail(r, GETME_FORMATS_ERR_PARSE, "second $PhysicalNames");
    }
    for (size_t i = 0; st == GETME_FORMATS_OK && i < n; i++) {
        st = read_name(r, &r->names[i]);
        r->nnames += st == GETME_FORMATS_OK;
    }
    if (st == GETME_FORMATS_OK)
        st = expect_end(r);
    r->binary = save;
    return st;
}

/* ---- $Entities ---------------------------------------------------------- */

static getme_formats_status add_phys(msh41_reader *r, int tag, size_t *cap)
{
    if (r->nphys == *cap) {
        size_t ncap = *cap ? 2 * *cap : 64;
        int *np = getme__realloc(r->phys, ncap * sizeof *np);
        if (!np)
            return oom(r);
        r->phys = np;
        *cap = ncap;
    }
    r->phys[r->nphys++] = tag;
    return GETME_FORMATS_OK;
}

/* One entity after its tag (and for a partitioned entity its parent and
   partitions): box (a point for dim 0), physical tags, bounding entities
   (skipped). */
static getme_formats_status read_entity_rest(msh41_reader *r, int dim,
                                             msh41_entity *e, size_t *cap)
{
    uint64_t n = 0;
    double skip;
    getme_formats_status st = GETME_FORMATS_OK;
    for (int k = 0; k < (dim ? 6 : 3) && st == GETME_FORMATS_OK; k++)
        st = read_double(r, &skip);
    if (st == GETME_FORMATS_OK)
        st = read_count(r, &n, "number of physical tags", 2);
    e->phys_first = r->nphys;
    e->phys_count = (size_t)n;
    for (uint64_t i = 0; i < n && st == GETME_FORMATS_OK; i++) {
        int tag = 0;
        st = read_int(r, &tag, "physical tag");
        if (st == GETME_FORMATS_OK)
            st = add_phys(r, tag, cap);
    }
    if (dim > 0 && st == GETME_FORMATS_OK)
        st = read_count(r, &n, "number of bounding entities", 2);
    for (uint64_t i = 0; dim > 0 && i < n && st == GETME_FORMATS_OK; i++) {
        int tag = 0;
        st = read_int(r, &tag, "bounding entity tag");
    }
    return st;
}

/* One $Entities entry. */
static getme_formats_status read_entity(msh41_reader *r, int dim,
                                        msh41_entity *e, size_t *cap)
{
    e->dim = dim;
    getme_formats_status st = read_int(r, &e->tag, "entity tag");
    return st == GETME_FORMATS_OK ? read_entity_rest(r, dim, e, cap) : st;
}

static int cmp_entity(const void *a, const void *b)
{
    const msh41_entity *x = a, *y = b;
    if (x->dim != y->dim)
        return x->dim < y->dim ? -1 : 1;
    return (x->tag > y->tag) - (x->tag < y->tag);
}

msh41_entity *msh41_find_entity(const msh41_reader *r, int dim, int tag)
{
    msh41_entity key;
    key.dim = dim;
    key.tag = tag;
    return r->nents ? bsearch(&key, r->ents, r->nents, sizeof key, cmp_entity)
                    : NULL;
}

static getme_formats_status read_entities(msh41_reader *r)
{
    uint64_t count[4], total = 0;
    size_t cap = 0;
    r->section = "Entities";
    if (r->ents || r->have_nodes)
        return msh41_decline(r, "$Entities repeated or after $Nodes");
    getme_formats_status st = GETME_FORMATS_OK;
    for (int d = 0; d < 4 && st == GETME_FORMATS_OK; d++) {
        st = read_count(r, &count[d], "number of entities", 8);
        total += st == GETME_FORMATS_OK ? count[d] : 0;
    }
    if (st == GETME_FORMATS_OK && total > 0) {
        r->ents = getme__calloc((size_t)total, sizeof *r->ents);
        if (!r->ents)
            st = oom(r);
    }
    for (int d = 0; d < 4 && st == GETME_FORMATS_OK; d++)
        for (uint64_t i = 0; i < count[d] && st == GETME_FORMATS_OK; i++) {
            st = read_entity(r, d, &r->ents[r->nents], &cap);
            r->nents += st == GETME_FORMATS_OK;
        }
    if (st == GETME_FORMATS_OK)
        st = expect_end(r);
    if (st == GETME_FORMATS_OK && r->nents) {
        qsort(r->ents, r->nents, sizeof *r->ents, cmp_entity);
        for (size_t i = 1; i < r->nents; i++)
            if (cmp_entity(&r->ents[i - 1], &r->ents[i]) == 0)
                return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                                  "entity (%d, %d) is defined twice",
                                  r->ents[i].dim, r->ents[i].tag);
    }
    return st;
}

/* ---- $PartitionedEntities (one part of a partitioned file) --------------
 * numPartitions, the ghost entities (tag, partition; refused: their
 * elements are copies), then per dimension the partitioned entities: tag,
 * parentDim, parentTag, numPartitions and their tags, then as in
 * $Entities.  Element and node blocks name these entities; the model's
 * own $Entities (read before) stay as model_ents, for region keys. */

/* The region key of a partitioned volume: the index among the model's
   entities of the first entity of its dimension with the same non-empty
   set of physical tags, else of its parent (the same in every part, as
   every part carries the whole model's $Entities). */
static int32_t region_key(const msh41_reader *r, const msh41_entity *e)
{
    const int *p = r->phys + e->phys_first;
    for (size_t i = 0; e->phys_count && i < r->nmodel_ents; i++) {
        const msh41_entity *m = &r->model_ents[i];
        if (m->dim != e->dim || m->phys_count != e->phys_count)
            continue;
        size_t k = 0; /* same set: every tag of e in m (tags distinct) */
        for (; k < e->phys_count; k++) {
            size_t j = 0;
            while (j < m->phys_count && r->phys[m->phys_first + j] != p[k])
                j++;
            if (j == m->phys_count)
                break;
        }
        if (k == e->phys_count)
            return (int32_t)i;
    }
    for (size_t i = 0; i < r->nmodel_ents; i++)
        if (r->model_ents[i].dim == e->parent_dim &&
            r->model_ents[i].tag == e->parent_tag)
            return (int32_t)i;
    return (int32_t)(r->nmodel_ents + (size_t)e->tag); /* no parent listed */
}

static getme_formats_status read_pentity(msh41_reader *r, int dim,
                                         msh41_entity *e, size_t *cap)
{
    uint64_t np = 0;
    int want = r->opts->partition, in = want == 0;
    e->dim = dim;
    getme_formats_status st = read_int(r, &e->tag, "entity tag");
    if (st == GETME_FORMATS_OK)
        st = read_int(r, &e->parent_dim, "parent dimension");
    if (st == GETME_FORMATS_OK)
        st = read_int(r, &e->parent_tag, "parent tag");
    if (st == GETME_FORMATS_OK)
        st = read_count(r, &np, "number of partitions", 4);
    for (uint64_t i = 0; i < np && st == GETME_FORMATS_OK; i++) {
        int p = 0;
        st = read_int(r, &p, "partition tag");
        in |= p == want;
    }
    e->skip = !in;
    return st == GETME_FORMATS_OK ? read_entity_rest(r, dim, e, cap) : st;
}

static getme_formats_status read_partitioned_entities(msh41_reader *r)
{
    r->section = "PartitionedEntities";
    if (!r->opts || !r->opts->one_part)
        return msh41_decline(r, "partitioned mesh");
    if (r->partitioned || r->have_nodes)
        return msh41_decline(r, "$PartitionedEntities repeated or after "
                                "$Nodes");
    uint64_t parts = 0, ghosts = 0, count[4], total = 0;
    size_t cap = r->nphys;
    getme_formats_status st = read_count(r, &parts, "number of partitions", 1);
    if (st == GETME_FORMATS_OK)
        st = read_count(r, &ghosts, "number of ghost entities", 8);
    if (st == GETME_FORMATS_OK && ghosts > 0)
        return msh41_fail(r, GETME_FORMATS_ERR_UNSUPPORTED,
                          "ghost cells (Mesh.PartitionCreateGhostCells) are "
                          "not read: partition without them");
    r->partitioned = 1;
    r->num_partitions = (int)parts;
    r->model_ents = r->ents; /* the model's; element blocks name these: */
    r->nmodel_ents = r->nents;
    r->ents = NULL;
    r->nents = 0;
    for (int d = 0; d < 4 && st == GETME_FORMATS_OK; d++) {
        st = read_count(r, &count[d], "number of entities", 8);
        total += st == GETME_FORMATS_OK ? count[d] : 0;
    }
    if (st == GETME_FORMATS_OK && total > 0 &&
        !(r->ents = getme__calloc((size_t)total, sizeof *r->ents)))
        st = oom(r);
    for (int d = 0; d < 4 && st == GETME_FORMATS_OK; d++)
        for (uint64_t i = 0; i < count[d] && st == GETME_FORMATS_OK; i++) {
            st = read_pentity(r, d, &r->ents[r->nents], &cap);
            r->nents += st == GETME_FORMATS_OK;
        }
    if (st == GETME_FORMATS_OK)
        st = expect_end(r);
    for (size_t i = 0; st == GETME_FORMATS_OK && i < r->nents; i++)
        r->ents[i].region = region_key(r, &r->ents[i]);
    if (st == GETME_FORMATS_OK && r->nents) {
        qsort(r->ents, r->nents, sizeof *r->ents, cmp_entity);
        for (size_t i = 1; i < r->nents; i++)
            if (cmp_entity(&r->ents[i - 1], &r->ents[i]) == 0)
                return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                                  "partitioned entity (%d, %d) is defined "
                                  "twice",
                                  r->ents[i].dim, r->ents[i].tag);
    }
    return st;
}

/* ---- --fix groups ------------------------------------------------------- */

const char *msh41_group_name(const msh41_reader *r, int dim, int tag)
{
    const char *name = NULL; /* the last definition wins, as in Gmsh */
    for (size_t i = 0; i < r->nnames; i++)
        if (r->names[i].dim == dim && r->names[i].tag == tag)
            name = r->names[i].name;
    return name;
}

/* Mark the entities of the groups each --fix word names (groups are
   (dim, physical tag) pairs that some entity carries). */
static getme_formats_status prepare_groups(msh41_reader *r)
{
    int nfix = r->opts ? r->opts->num_fix : 0;
    int nfree = r->opts ? r->opts->num_free : 0;
    if (r->groups_ready || nfix + nfree == 0) {
        r->groups_ready = 1;
        return GETME_FORMATS_OK;
    }
    r->groups_ready = 1;
    /* --fix words first, then --free words (only looked up: no physical
       group is fixed by default, but an unknown name is an error) */
    r->fix_found = getme__calloc((size_t)(nfix + nfree), sizeof *r->fix_found);
    if (!r->fix_found)
        return oom(r);
    for (int w = 0; w < nfix + nfree; w++) {
        const char *word = w < nfix ? r->opts->fix[w]
                                    : r->opts->free_sets[w - nfix];
        int dim, tag, used = 0;
        int by_tag = sscanf(word, "%d:%d%n", &dim, &tag, &used) == 2 &&
                     word[used] == 0;
        /* one part of a partitioned file: its entities are marked, the
           model's (every part has them all) only tell a name exists */
        size_t n = r->nents + r->nmodel_ents;
        for (size_t i = 0; i < n; i++) {
            msh41_entity *e = i < r->nents ? &r->ents[i]
                                           : &r->model_ents[i - r->nents];
            for (size_t k = 0; k < e->phys_count; k++) {
                int p = r->phys[e->phys_first + k];
                const char *name = by_tag ? NULL
                                          : msh41_group_name(r, e->dim, p);
                int match = by_tag ? (e->dim == dim && p == tag)
                                   : (name && strcmp(name, word) == 0);
                if (match && i < r->nents)
                    e->fix |= w < nfix;
                r->fix_found[w] += match;
            }
        }
    }
    return GETME_FORMATS_OK;
}

/* ---- $Nodes ------------------------------------------------------------- */

static getme_formats_status alloc_nodes(msh41_reader *r, uint64_t nblocks,
                                   uint64_t n)
{
    if (n > (uint64_t)INT32_MAX)
        return msh41_fail(r, GETME_FORMATS_ERR_UNSUPPORTED,
                          "%llu nodes: more than 2^31-1 are not supported",
                          (unsigned long long)n);
    size_t k = n ? (size_t)n : 1;
    r->tags = getme__malloc(k * sizeof *r->tags);
    r->xyz = getme__malloc(3 * k * sizeof *r->xyz);
    r->flag = getme__calloc(k, 1);
    r->nb = getme__malloc((nblocks ? (size_t)nblocks : 1) * sizeof *r->nb);
    if (!r->tags || !r->xyz || !r->flag || !r->nb)
        return oom(r);
    return GETME_FORMATS_OK;
}

/* Node tags of one block: binary as one array, decoded in place. */
static getme_formats_status read_node_tags(msh41_reader *r, uint64_t *tags,
                                      size_t n)
{
    if (!r->binary) {
        msh41_fast_job job = {MSH41_FAST_TAGS, tags, NULL, NULL, 0, 0};
        getme_formats_status st = GETME_FORMATS_OK;
        /* the header's newline: every message after it names a later
           token's line anyway */
        int line_start = n ? msh41_in_eol(&r->in) : 1;
        for (size_t i = 0; i < n && st == GETME_FORMATS_OK;) {
            if (line_start)
                i += msh41_fast(r, &job, i, n - i);
            if (i == n)
                break;
            st = read_u64(r, &tags[i++], "node tag");
            line_start = msh41_in_eol(&r->in);
        }
        return st;
    }
    if (msh41_in_read(&r->in, tags, n * 8))
        return eof_error(r);
    for (size_t i = 0; i < n; i++)
        tags[i] = le64((const unsigned char *)&tags[i]);
    return GETME_FORMATS_OK;
}

/* Coordinates of one block.  ASCII: one node per line, which the writer
   relies on (anything else is declined). */
static getme_formats_status not_finite(msh41_reader *r, uint64_t tag,
                                  const double *x)
{
    return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                      "node %llu has a coordinate that is not a finite "
                      "number (%g %g %g)",
                      (unsigned long long)tag, x[0], x[1], x[2]);
}

static int finite3(const double *x)
{
    return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]);
}

static getme_formats_status read_node_coords(msh41_reader *r, double *xyz,
                                        const uint64_t *tags, size_t n)
{
    if (r->binary) {
        if (msh41_in_read(&r->in, xyz, 3 * n * 8))
            return eof_error(r);
        for (size_t i = 0; i < 3 * n; i++) {
            uint64_t bits = le64((const unsigned char *)&xyz[i]);
            memcpy(&xyz[i], &bits, sizeof bits);
        }
        for (size_t i = 0; i < n; i++)
            if (!finite3(xyz + 3 * i))
                return not_finite(r, tags[i], xyz + 3 * i);
        return GETME_FORMATS_OK;
    }
    msh41_fast_job job = {MSH41_FAST_COORDS, NULL, xyz, NULL, 0, 0};
    getme_formats_status st = GETME_FORMATS_OK;
    for (size_t i = 0; i < n && st == GETME_FORMATS_OK; i++) {
        i += msh41_fast(r, &job, i, n - i); /* every record ends a line */
        if (i == n)
            break;
        for (int k = 0; k < 3 && st == GETME_FORMATS_OK; k++)
            st = read_double(r, &xyz[3 * i + k]);
        if (st == GETME_FORMATS_OK && !finite3(xyz + 3 * i))
            st = not_finite(r, tags[i], xyz + 3 * i);
        if (st == GETME_FORMATS_OK && !msh41_in_eol(&r->in))
            st = msh41_decline(r, "node coordinates not one node per line");
    }
    return st;
}

/* Are the tags n consecutive numbers in order (Gmsh numbers its nodes
   so)?  Then a tag's index is tag - tags[0], without the map's table,
   whose random reads cost more than parsing an element line. */
static int tags_run(const uint64_t *tags, size_t n)
{
    for (size_t i = 1; i < n; i++)
        if (tags[i] != tags[0] + i)
            return 0;
    return n > 0;
}

static getme_formats_status read_node_block(msh41_reader *r, size_t *filled)
{
    msh41_nblock *b = &r->nb[r->nnb];
    int param = 0;
    uint64_t count = 0;
    getme_formats_status st = read_int(r, &b->dim, "entity dimension");
    if (st == GETME_FORMATS_OK)
        st = read_int(r, &b->tag, "entity tag");
    if (st == GETME_FORMATS_OK)
        st = read_int(r, &param, "parametric flag");
    if (st == GETME_FORMATS_OK)
        st = read_u64(r, &count, "number of nodes in block");
    if (st != GETME_FORMATS_OK)
        return st;
    if (b->dim < 0 || b->dim > 3 || param < 0 || param > 1)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                          "bad node block header (dimension %d, parametric "
                          "%d)",
                          b->dim, param);
    if (param)
        return msh41_decline(r, "parametric nodes");
    if (count > r->nnodes - *filled)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                          "node blocks hold more nodes than the %zu declared",
                          r->nnodes);
    b->first = *filled;
    b->count = (size_t)count;
    st = read_node_tags(r, r->tags + b->first, b->count);
    if (st == GETME_FORMATS_OK)
        st = read_node_coords(r, r->xyz + 3 * b->first, r->tags + b->first,
                              b->count);
    /* A point's group fixes the point's node (Gmsh: mesh_vertices[0]). */
    const msh41_entity *e = msh41_find_entity(r, b->dim, b->tag);
    if (st == GETME_FORMATS_OK && b->dim == 0 && e && e->fix && b->count)
        r->flag[b->first] |= MSH41_FIXGRP;
    *filled += b->count;
    r->nnb++;
    return st;
}

static getme_formats_status read_nodes(msh41_reader *r)
{
    uint64_t nblocks = 0, n = 0, lo, hi;
    r->section = "Nodes";
    if (r->have_nodes)
        return msh41_decline(r, "several $Nodes sections");
    r->have_nodes = 1;
    r->nodes_offset = msh41_in_offset(&r->in);
    getme_formats_status st = prepare_groups(r);
    if (st == GETME_FORMATS_OK)
        st = read_count(r, &nblocks, "number of node blocks", 8);
    if (st == GETME_FORMATS_OK)
        st = read_count(r, &n, "number of nodes", 8);
    if (st == GETME_FORMATS_OK)
        st = read_u64(r, &lo, "minimum node tag");
    if (st == GETME_FORMATS_OK)
        st = read_u64(r, &hi, "maximum node tag");
    if (st == GETME_FORMATS_OK)
        st = alloc_nodes(r, nblocks, n);
    r->nnodes = st == GETME_FORMATS_OK ? (size_t)n : 0;
    size_t filled = 0;
    for (uint64_t b = 0; b < nblocks && st == GETME_FORMATS_OK; b++)
        st = read_node_block(r, &filled);
    if (st == GETME_FORMATS_OK && filled != r->nnodes)
        st = msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                        "$Nodes declares %zu nodes, its blocks hold %zu",
                        r->nnodes, filled);
    if (st == GETME_FORMATS_OK)
        st = expect_end(r);
    if (st == GETME_FORMATS_OK)
        st = msh41_map_build(r, &r->map, r->tags, r->nnodes);
    if (st == GETME_FORMATS_OK)
        r->tags_run = tags_run(r->tags, r->nnodes);
    return st;
}

/* ---- $Elements ---------------------------------------------------------- */

static void drop_blocks(msh41_reader *r)
{
    for (size_t i = 0; i < r->neb; i++) {
        free(r->eb[i].conn);
        free(r->eb[i].ids);
    }
    r->neb = 0;
}

/* A block of the (so far) highest dimension, with room for its elements
   if GETMe can smooth its type. */
static getme_formats_status new_eblock(msh41_reader *r, int dim, int tag,
                                  int type, uint64_t count, int nv,
                                  msh41_eblock **out)
{
    if (dim > r->top_dim)
        drop_blocks(r);
    r->top_dim = dim;
    if (r->neb == r->cap_eb) {
        size_t cap = r->cap_eb ? 2 * r->cap_eb : 16;
        msh41_eblock *nb = getme__realloc(r->eb, cap * sizeof *nb);
        if (!nb)
            return oom(r);
        r->eb = nb;
        r->cap_eb = cap;
    }
    if (count > (uint64_t)INT32_MAX)
        return msh41_fail(r, GETME_FORMATS_ERR_UNSUPPORTED,
                          "More than 2^31-1 elements are not supported");
    msh41_eblock *b = &r->eb[r->neb++];
    memset(b, 0, sizeof *b);
    b->tag = tag;
    b->type = type;
    b->count = (int32_t)count;
    int order = 0;
    msh41_type_nodes(type, &order);
    int linear = order == 1 && ((dim == 3 && type >= 4 && type <= 7) ||
                                (dim == 2 && (type == 2 || type == 3)));
    if (linear || getme__msh_type_ho(type, dim) >= 0) {
        b->conn = getme__malloc((size_t)count * (size_t)nv * sizeof *b->conn);
        b->ids = getme__malloc((size_t)count * sizeof *b->ids);
        if (!b->conn || !b->ids)
            return oom(r);
    }
    *out = b;
    return GETME_FORMATS_OK;
}

/* One element: rec = tag + nv node tags.  Nodes must exist (as for Gmsh's
   reader); kept blocks store file indices, --fix groups flag nodes.  0, or
   1 + k if node k repeats an earlier node of a kept element, or -(1 + k)
   if node k is not in $Nodes (nothing is reported: the fast path refuses
   such a line and take_element says what is wrong). */
/* The common case of msh41_store_element: a kept linear element (up to 8
   nodes), node tags a run (no table), no --fix.  All nodes are looked up
   and compared without a branch per node (the loop below costs ~200
   instructions per tet); 0 if the element is stored, else -1 and the loop
   below finds which node is wrong (its entries are then rewritten, or the
   read fails). */
static int store_run_element(msh41_reader *r, msh41_eblock *b, size_t i,
                             const uint64_t *rec, int nv)
{
    int32_t *dst = b->conn + i * (size_t)nv;
    uint64_t t0 = r->tags[0], bad = 0;
    for (int k = 0; k < nv; k++) {
        uint64_t d = rec[1 + k] - t0;
        bad |= d >= r->nnodes;
        dst[k] = (int32_t)d;
    }
    for (int k = 1; k < nv; k++)
        for (int j = 0; j < k; j++)
            bad |= rec[1 + j] == rec[1 + k];
    if (bad)
        return -1;
    b->ids[i] = (int64_t)rec[0];
    return 0;
}

int msh41_store_element(msh41_reader *r, msh41_eblock *b, size_t i,
                        const uint64_t *rec, int nv, int fix)
{
    if (r->tags_run && !fix && b && b->conn && nv <= 8 &&
        store_run_element(r, b, i, rec, nv) == 0)
        return 0;
    for (int k = 0; k < nv; k++) {
        for (int j = 0; b && b->conn && j < k; j++)
            if (rec[1 + j] == rec[1 + k])
                return 1 + k;
        int32_t idx;
        if (r->tags_run) { /* tags first, first + 1, ...: no table */
            uint64_t d = rec[1 + k] - r->tags[0];
            idx = d < r->nnodes ? (int32_t)d : -1;
        } else {
            idx = msh41_map_find(&r->map, rec[1 + k]);
        }
        if (idx < 0)
            return -(1 + k);
        if (fix)
            r->flag[idx] |= MSH41_FIXGRP;
        if (b && b->conn)
            b->conn[i * (size_t)nv + (size_t)k] = idx;
    }
    if (b && b->ids)
        b->ids[i] = (int64_t)rec[0];
    return 0;
}

static getme_formats_status take_element(msh41_reader *r, msh41_eblock *b,
                                    size_t i, const uint64_t *rec, int nv,
                                    int fix)
{
    int rc = msh41_store_element(r, b, i, rec, nv, fix);
    if (rc > 0)
        return msh41_fail(r, GETME_FORMATS_ERR_INVALID,
                          "element %llu is degenerate: node %llu "
                          "appears twice; getme smooths valid meshes "
                          "only",
                          (unsigned long long)rec[0],
                          (unsigned long long)rec[rc]);
    if (rc < 0)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                          "element %llu uses node %llu, which is not in "
                          "$Nodes",
                          (unsigned long long)rec[0],
                          (unsigned long long)rec[-rc]);
    return GETME_FORMATS_OK;
}

/* Binary elements are read a chunk of records at a time (BIG_CHUNK, so
   that each thread gets a long run of records to decode and store).  A
   bad record is named with the byte offset the reader reported when it
   read REC_CHUNK records at a time: the end of the REC_CHUNK-record piece
   that holds it, so messages stay what they were. */
#define REC_CHUNK 4096
#define BIG_CHUNK (16 * REC_CHUNK)

/* Records [0, k) of buf, decoded and stored (record j as element i0 + j)
   on up to threads threads; returns the first bad record (take_element
   then says why), or k.  Each record writes only its own entries of the
   block, so the stored arrays are the same for any thread count, and the
   first bad record is a minimum over the threads' first ones. */
static size_t store_records(msh41_reader *r, msh41_eblock *b, uint64_t *buf,
                            size_t k, size_t i0, int nv, int fix, int threads)
{
    size_t rec = (size_t)nv + 1, bad = k;
#pragma omp parallel for schedule(static) num_threads(threads) \
    reduction(min : bad) if (threads > 1 && k >= 1024)
    for (size_t j = 0; j < k; j++) {
        uint64_t *p = buf + j * rec;
        for (size_t q = 0; q < rec; q++)
            p[q] = le64((const unsigned char *)&p[q]);
        if (j < bad && msh41_store_element(r, b, i0 + j, p, nv, fix) != 0)
            bad = j;
    }
    return bad;
}

static getme_formats_status read_binary_elements(msh41_reader *r, msh41_eblock *b,
                                            uint64_t count, int nv, int fix)
{
    size_t rec = (size_t)nv + 1;
    size_t chunk = count < BIG_CHUNK ? (size_t)(count ? count : 1) : BIG_CHUNK;
    uint64_t *buf = getme__malloc(chunk * rec * sizeof *buf);
    if (!buf)
        return oom(r);
    /* --fix flags nodes while storing: one thread, no shared writes */
    int threads = fix ? 1 : r->threads;
    int64_t start = msh41_in_offset(&r->in);
    getme_formats_status st = GETME_FORMATS_OK;
    for (uint64_t i0 = 0; i0 < count && st == GETME_FORMATS_OK; i0 += chunk) {
        size_t k = count - i0 < chunk ? (size_t)(count - i0) : chunk;
        size_t got = msh41_in_read_some(&r->in, buf, k * rec * 8);
        int eof = got < k * rec * 8;
        if (eof) /* the REC_CHUNK reads stored the whole pieces before it */
            k = got / (rec * 8) / REC_CHUNK * REC_CHUNK;
        size_t bad = store_records(r, b, buf, k, (size_t)i0, nv, fix, threads);
        if (bad < k) {
            uint64_t at = i0 + bad, end = (at / REC_CHUNK + 1) * REC_CHUNK;
            end = end < count ? end : count;
            r->msg_offset = start + (int64_t)(end * rec * 8);
            r->msg_offset_set = 1;
            st = take_element(r, b, (size_t)at, buf + bad * rec, nv, fix);
            r->msg_offset_set = 0;
        } else if (eof) {
            st = eof_error(r);
        }
    }
    free(buf);
    return st;
}

/* Records the fast path (msh41_fast.c) refuses are read here, one at a
   time; after one, the fast path goes on if a new line starts. */
static getme_formats_status read_ascii_elements(msh41_reader *r, msh41_eblock *b,
                                           uint64_t count, int nv, int fix)
{
    uint64_t rec[MSH41_MAX_REC];
    msh41_fast_job job = {MSH41_FAST_ELEMENTS, NULL, NULL, b, nv, fix};
    getme_formats_status st = GETME_FORMATS_OK;
    int line_start = count ? msh41_in_eol(&r->in) : 1; /* header's end */
    for (size_t i = 0; i < count && st == GETME_FORMATS_OK;) {
        if (line_start)
            i += msh41_fast(r, &job, i, (size_t)count - i);
        if (i == count)
            break;
        st = read_u64(r, &rec[0], "element tag");
        for (int k = 0; k < nv && st == GETME_FORMATS_OK; k++)
            st = read_u64(r, &rec[1 + k], "node tag");
        if (st == GETME_FORMATS_OK)
            st = take_element(r, b, i++, rec, nv, fix);
        line_start = msh41_in_eol(&r->in);
    }
    return st;
}

/* As Gmsh's reader: an element block needs its entity, from $Entities or
   created by a $Nodes block of the same dimension and tag. */
static int node_block_entity(const msh41_reader *r, int dim, int tag)
{
    for (size_t i = 0; i < r->nnb; i++)
        if (r->nb[i].dim == dim && r->nb[i].tag == tag)
            return 1;
    return 0;
}

static getme_formats_status read_element_block(msh41_reader *r)
{
    int dim = 0, tag = 0, type = 0;
    uint64_t count = 0;
    getme_formats_status st = read_int(r, &dim, "entity dimension");
    if (st == GETME_FORMATS_OK)
        st = read_int(r, &tag, "entity tag");
    if (st == GETME_FORMATS_OK)
        st = read_int(r, &type, "element type");
    if (st != GETME_FORMATS_OK)
        return st;
    int nv = msh41_type_nodes(type, NULL);
    if (nv == 0)
        return msh41_decline(r, "an element type this reader does not know");
    st = read_count(r, &count, "number of elements in block",
                    (uint64_t)(nv + 1) * (r->binary ? 8 : 2));
    if (st != GETME_FORMATS_OK)
        return st;
    if (dim < 0 || dim > 3)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                          "bad element block dimension %d", dim);
    const msh41_entity *e = msh41_find_entity(r, dim, tag);
    if (!e && !node_block_entity(r, dim, tag))
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                          "element block of entity %d (dimension %d): no "
                          "such entity in $Entities or $Nodes",
                          tag, dim);
    msh41_eblock *b = NULL; /* partitioned: not the part being read */
    if (dim >= 2 && dim >= r->top_dim && count > 0 && !(e && e->skip))
        st = new_eblock(r, dim, tag, type, count, nv, &b);
    if (st != GETME_FORMATS_OK)
        return st;
    int fix = e && e->fix;
    return r->binary ? read_binary_elements(r, b, count, nv, fix)
                     : read_ascii_elements(r, b, count, nv, fix);
}

/* Entering $Elements (both versions): after $Nodes, only once. */
static getme_formats_status elements_begin(msh41_reader *r)
{
    r->section = "Elements";
    if (!r->have_nodes)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE, "$Elements before $Nodes");
    if (r->have_elements)
        return msh41_decline(r, "several $Elements sections");
    r->have_elements = 1;
    return GETME_FORMATS_OK;
}

static getme_formats_status read_elements(msh41_reader *r)
{
    uint64_t nblocks = 0, n, lo, hi;
    getme_formats_status st = elements_begin(r);
    if (st == GETME_FORMATS_OK)
        st = read_count(r, &nblocks, "number of element blocks", 8);
    if (st == GETME_FORMATS_OK)
        st = read_count(r, &n, "number of elements", 8);
    if (st == GETME_FORMATS_OK)
        st = read_u64(r, &lo, "minimum element tag");
    if (st == GETME_FORMATS_OK)
        st = read_u64(r, &hi, "maximum element tag");
    for (uint64_t b = 0; b < nblocks && st == GETME_FORMATS_OK; b++)
        st = read_element_block(r);
    if (st == GETME_FORMATS_OK)
        st = expect_end(r);
    return st;
}

/* ---- MSH 2.2 ------------------------------------------------------------
 * $Nodes: a count line, then "tag x y z" per line (binary: int32 tag and
 * three doubles per node).  $Elements: a count line, then per element
 * "tag type ntags physical elementary nodes..." (binary: blocks of
 * int32 "type count ntags", then per element int32 tag, tags, nodes).
 * Entities are what the elements' (dimension, elementary tag) name, their
 * physical groups the physical tags of their elements; a node belongs to
 * the entity of lowest dimension (then lowest tag) among the elements
 * using it, and inside an entity nodes go by tag: Gmsh's MSH 2 reader. */

/* The count line of a 2.2 section (text even in binary files). */
static getme_formats_status read_count22(msh41_reader *r, uint64_t *n,
                                    const char *what, uint64_t min_bytes)
{
    int save = r->binary;
    r->binary = 0;
    getme_formats_status st = read_count(r, n, what, min_bytes);
    r->binary = save;
    if (st == GETME_FORMATS_OK && save && !msh41_in_eol(&r->in))
        st = msh41_fail(r, GETME_FORMATS_ERR_PARSE, "bad %s line in $%s", what,
                        r->section);
    return st;
}

static getme_formats_status read_nodes22(msh41_reader *r)
{
    uint64_t n = 0;
    r->section = "Nodes";
    if (r->have_nodes)
        return msh41_decline(r, "several $Nodes sections");
    r->have_nodes = 1;
    r->nodes_offset = msh41_in_offset(&r->in);
    getme_formats_status st = read_count22(r, &n, "number of nodes", 8);
    if (st == GETME_FORMATS_OK)
        st = alloc_nodes(r, 0, n);
    r->nnodes = st == GETME_FORMATS_OK ? (size_t)n : 0;
    if (st == GETME_FORMATS_OK) {
        r->ndim = getme__malloc(r->nnodes ? r->nnodes : 1);
        r->netag =
            getme__malloc((r->nnodes ? r->nnodes : 1) * sizeof *r->netag);
        if (!r->ndim || !r->netag)
            st = oom(r);
        else
            memset(r->ndim, 4, r->nnodes);
    }
    for (size_t i = 0; i < r->nnodes && st == GETME_FORMATS_OK; i++) {
        double *x = r->xyz + 3 * i;
        if (r->binary) {
            int tag = 0;
            st = read_int(r, &tag, "node tag");
            if (st == GETME_FORMATS_OK && tag <= 0)
                st = msh41_fail(r, GETME_FORMATS_ERR_PARSE, "bad node tag %d", tag);
            r->tags[i] = (uint64_t)(tag > 0 ? tag : 0);
        } else {
            st = read_u64(r, &r->tags[i], "node tag");
        }
        for (int k = 0; k < 3 && st == GETME_FORMATS_OK; k++)
            st = read_double(r, &x[k]);
        if (st == GETME_FORMATS_OK && !finite3(x))
            st = not_finite(r, r->tags[i], x);
        if (st == GETME_FORMATS_OK && !r->binary && !msh41_in_eol(&r->in))
            st = msh41_decline(r, "node coordinates not one node per line");
    }
    if (st == GETME_FORMATS_OK)
        st = expect_end(r);
    if (st == GETME_FORMATS_OK)
        st = msh41_map_build(r, &r->map, r->tags, r->nnodes);
    return st;
}

static int type_dim(int msh_type) { return getme__msh_type_dim(msh_type); }

/* Does (dim, physical) belong to a group a --fix (or --free) word names?
   Counts the matches per word for check_fix_names. */
static int fix_group22(msh41_reader *r, int dim, int phys)
{
    int nfix = r->opts ? r->opts->num_fix : 0;
    int nfree = r->opts ? r->opts->num_free : 0, fix = 0;
    for (int w = 0; phys && w < nfix + nfree; w++) {
        const char *word = w < nfix ? r->opts->fix[w]
                                    : r->opts->free_sets[w - nfix];
        int d, t, used = 0;
        int match;
        if (sscanf(word, "%d:%d%n", &d, &t, &used) == 2 && word[used] == 0)
            match = d == dim && t == phys;
        else {
            const char *name = msh41_group_name(r, dim, phys);
            match = name && strcmp(name, word) == 0;
        }
        if (match) {
            r->fix_found[w]++;
            fix |= w < nfix;
        }
    }
    return fix;
}

/* The element block an element of (tag, type) of the top dimension goes
   to: the last one if it is the same (entity, type, physical tag), else a
   new one (a repeat of an entity under another physical group starts its
   own block: drop_repeats22). */
static getme_formats_status block22(msh41_reader *r, int dim, int etag, int type,
                               int phys, int nv, msh41_eblock **out)
{
    msh41_eblock *b = r->neb ? &r->eb[r->neb - 1] : NULL;
    if (!b || dim > r->top_dim || b->tag != etag || b->type != type ||
        r->phys_cur != phys) {
        getme_formats_status st = new_eblock(r, dim, etag, type, 1, nv, &b);
        if (st != GETME_FORMATS_OK)
            return st;
        b->count = 0; /* room for 1, grown below */
        r->cap_cur = 1;
        r->phys_cur = phys;
    }
    if (b->conn && (size_t)b->count == r->cap_cur) {
        size_t cap = r->cap_cur ? 2 * r->cap_cur : 64;
        int32_t *c = getme__realloc(b->conn, cap * (size_t)nv * sizeof *c);
        if (c)
            b->conn = c;
        int64_t *ids = getme__realloc(b->ids, cap * sizeof *ids);
        if (ids)
            b->ids = ids;
        if (!c || !ids)
            return oom(r);
        r->cap_cur = cap;
    }
    if (b->count == INT32_MAX)
        return msh41_fail(r, GETME_FORMATS_ERR_UNSUPPORTED,
                          "More than 2^31-1 elements are not supported");
    *out = b;
    return GETME_FORMATS_OK;
}

/* One element: rec = tag + nv node tags; tags = physical, elementary. */
static getme_formats_status element22(msh41_reader *r, int type, int ntags,
                                 const int *tags, const uint64_t *rec)
{
    int order = 0, nv = msh41_type_nodes(type, &order), dim = type_dim(type);
    if (nv == 0 || dim < 0)
        return msh41_decline(r, "an element type this reader does not know");
    if (ntags > 2)
        return msh41_decline(r, "partitioned mesh (element with more than "
                                "2 tags)");
    if (ntags < 2 || tags[1] <= 0)
        return msh41_decline(r, "element without an elementary tag");
    int phys = tags[0] > 0 ? tags[0] : 0, etag = tags[1];
    if (!r->nent22 || r->ent22[r->nent22 - 1][0] != dim ||
        r->ent22[r->nent22 - 1][1] != etag ||
        r->ent22[r->nent22 - 1][2] != phys) {
        if (r->nent22 == r->cap_ent22) {
            size_t cap = r->cap_ent22 ? 2 * r->cap_ent22 : 64;
            int(*e)[3] = getme__realloc(r->ent22, cap * sizeof *e);
            if (!e)
                return oom(r);
            r->ent22 = e;
            r->cap_ent22 = cap;
        }
        r->ent22[r->nent22][0] = dim;
        r->ent22[r->nent22][1] = etag;
        r->ent22[r->nent22++][2] = phys;
    }
    msh41_eblock *b = NULL;
    getme_formats_status st = GETME_FORMATS_OK;
    if (dim >= 2 && dim >= r->top_dim)
        st = block22(r, dim, etag, type, phys, nv, &b);
    if (st == GETME_FORMATS_OK)
        st = take_element(r, b, b ? (size_t)b->count : 0, rec, nv,
                          fix_group22(r, dim, phys));
    if (st != GETME_FORMATS_OK)
        return st;
    if (b)
        b->count++;
    for (int k = 0; k < nv; k++) { /* nodes exist: take_element checked */
        int32_t i = msh41_map_find(&r->map, rec[1 + k]);
        if (dim < r->ndim[i] || (dim == r->ndim[i] && etag < r->netag[i])) {
            r->ndim[i] = (uint8_t)dim;
            r->netag[i] = etag;
        }
    }
    return GETME_FORMATS_OK;
}

enum { MAX_TAGS22 = 64, MAX_NODES22 = 128 };

static getme_formats_status ascii_element22(msh41_reader *r)
{
    uint64_t rec[1 + MAX_NODES22];
    int type = 0, ntags = 0, tags[MAX_TAGS22];
    getme_formats_status st = read_u64(r, &rec[0], "element tag");
    if (st == GETME_FORMATS_OK)
        st = read_int(r, &type, "element type");
    if (st == GETME_FORMATS_OK)
        st = read_int(r, &ntags, "number of tags");
    if (st == GETME_FORMATS_OK && (ntags < 0 || ntags > MAX_TAGS22))
        st = msh41_fail(r, GETME_FORMATS_ERR_PARSE, "bad number of tags %d", ntags);
    for (int k = 0; k < ntags && st == GETME_FORMATS_OK; k++)
        st = read_int(r, &tags[k], "element tag");
    int nv = msh41_type_nodes(type, NULL);
    if (st == GETME_FORMATS_OK && (nv == 0 || nv > MAX_NODES22))
        return msh41_decline(r, "an element type this reader does not know");
    for (int k = 0; k < nv && st == GETME_FORMATS_OK; k++)
        st = read_u64(r, &rec[1 + k], "node tag");
    if (st == GETME_FORMATS_OK && !msh41_in_eol(&r->in))
        st = msh41_decline(r, "elements not one per line");
    return st == GETME_FORMATS_OK ? element22(r, type, ntags, tags, rec) : st;
}

static getme_formats_status binary_block22(msh41_reader *r, uint64_t *left)
{
    int head[3], vals[1 + MAX_TAGS22 + MAX_NODES22];
    getme_formats_status st = GETME_FORMATS_OK;
    for (int k = 0; k < 3 && st == GETME_FORMATS_OK; k++)
        st = read_int(r, &head[k], "element block header");
    if (st != GETME_FORMATS_OK)
        return st;
    int type = head[0], nv = msh41_type_nodes(type, NULL), ntags = head[2];
    if (nv == 0 || nv > MAX_NODES22)
        return msh41_decline(r, "an element type this reader does not know");
    if (head[1] < 0 || (uint64_t)head[1] > *left || ntags < 0 ||
        ntags > MAX_TAGS22)
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                          "bad element block header (type %d, %d elements, "
                          "%d tags)",
                          type, head[1], ntags);
    *left -= (uint64_t)head[1];
    for (int e = 0; e < head[1] && st == GETME_FORMATS_OK; e++) {
        for (int k = 0; k < 1 + ntags + nv && st == GETME_FORMATS_OK; k++)
            st = read_int(r, &vals[k], "element data");
        uint64_t rec[1 + MAX_NODES22];
        for (int k = 0; k <= nv && st == GETME_FORMATS_OK; k++) {
            int v = vals[k == 0 ? 0 : ntags + k];
            if (v <= 0)
                return msh41_fail(r, GETME_FORMATS_ERR_PARSE,
                                  "bad %s %d in $Elements",
                                  k ? "node tag" : "element tag", v);
            rec[k] = (uint64_t)v;
        }
        if (st == GETME_FORMATS_OK)
            st = element22(r, type, ntags, vals + 1, rec);
    }
    return st;
}

static getme_formats_status read_elements22(msh41_reader *r)
{
    uint64_t n = 0;
    getme_formats_status st = elements_begin(r);
    if (st != GETME_FORMATS_OK)
        return st;
    int nw = r->opts ? r->opts->num_fix + r->opts->num_free : 0;
    if (nw && !r->fix_found &&
        !(r->fix_found = getme__calloc((size_t)nw, sizeof *r->fix_found)))
        return oom(r);
    st = read_count22(r, &n, "number of elements", 8);
    if (r->binary)
        for (uint64_t left = n; st == GETME_FORMATS_OK && left > 0;)
            st = binary_block22(r, &left);
    else
        for (uint64_t i = 0; st == GETME_FORMATS_OK && i < n; i++)
            st = ascii_element22(r);
    if (st == GETME_FORMATS_OK)
        st = expect_end(r);
    return st;
}

static int cmp_triple(const void *a, const void *b)
{
    const int *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

/* $Entities as the elements define them. */
static getme_formats_status entities22(msh41_reader *r)
{
    qsort(r->ent22, r->nent22, sizeof *r->ent22, cmp_triple);
    r->ents = getme__malloc((r->nent22 ? r->nent22 : 1) * sizeof *r->ents);
    r->phys = getme__malloc((r->nent22 ? r->nent22 : 1) * sizeof *r->phys);
    if (!r->ents || !r->phys)
        return oom(r);
    for (size_t i = 0; i < r->nent22; i++) {
        const int *t = r->ent22[i];
        if (i && !cmp_triple(t, r->ent22[i - 1]))
            continue;
        msh41_entity *e = r->nents ? &r->ents[r->nents - 1] : NULL;
        if (!e || e->dim != t[0] || e->tag != t[1]) {
            e = &r->ents[r->nents++];
            memset(e, 0, sizeof *e);
            e->dim = t[0];
            e->tag = t[1];
            e->phys_first = r->nphys;
        }
        if (t[2]) {
            r->phys[r->nphys++] = t[2];
            e->phys_count++;
        }
    }
    return GETME_FORMATS_OK;
}

/* Node order by (dimension, entity, tag), one node block per entity. */
static const msh41_reader *order_reader;

static int cmp_node22(const void *a, const void *b)
{
    const msh41_reader *r = order_reader;
    size_t i = *(const size_t *)a, j = *(const size_t *)b;
    if (r->ndim[i] != r->ndim[j])
        return r->ndim[i] < r->ndim[j] ? -1 : 1;
    int ti = r->ndim[i] < 4 ? r->netag[i] : 0;
    int tj = r->ndim[j] < 4 ? r->netag[j] : 0;
    if (ti != tj)
        return ti < tj ? -1 : 1;
    return (r->tags[i] > r->tags[j]) - (r->tags[i] < r->tags[j]);
}

static getme_formats_status nodes22(msh41_reader *r)
{
    size_t n = r->nnodes;
    size_t *order = getme__malloc((n ? n : 1) * sizeof *order);
    int32_t *pos = getme__malloc((n ? n : 1) * sizeof *pos);
    uint64_t *tags = getme__malloc((n ? n : 1) * sizeof *tags);
    double *xyz = getme__malloc((n ? n : 1) * 3 * sizeof *xyz);
    uint8_t *flag = getme__malloc(n ? n : 1);
    msh41_nblock *nb = getme__malloc((n ? n : 1) * sizeof *nb);
    getme_formats_status st =
        order && pos && tags && xyz && flag && nb ? GETME_FORMATS_OK : oom(r);
    if (st == GETME_FORMATS_OK) {
        for (size_t i = 0; i < n; i++)
            order[i] = i;
        order_reader = r; /* qsort has no context argument in C11 */
        qsort(order, n, sizeof *order, cmp_node22);
        size_t nnb = 0;
        for (size_t k = 0; k < n; k++) {
            size_t i = order[k];
            pos[i] = (int32_t)k;
            tags[k] = r->tags[i];
            memcpy(xyz + 3 * k, r->xyz + 3 * i, 3 * sizeof *xyz);
            flag[k] = r->flag[i];
            int dim = r->ndim[i], tag = dim < 4 ? r->netag[i] : 0;
            if (!nnb || nb[nnb - 1].dim != dim || nb[nnb - 1].tag != tag)
                nb[nnb++] = (msh41_nblock){dim, tag, k, 0};
            nb[nnb - 1].count++;
        }
        for (size_t b = 0; b < r->neb; b++)
            for (size_t k = 0; r->eb[b].conn &&
                               k < (size_t)r->eb[b].count *
                                       (size_t)msh41_type_nodes(r->eb[b].type,
                                                                NULL);
                 k++)
                r->eb[b].conn[k] = pos[r->eb[b].conn[k]];
        free(r->tags);
        free(r->xyz);
        free(r->flag);
        free(r->nb);
        r->tags = tags;
        r->xyz = xyz;
        r->flag = flag;
        r->nb = nb;
        r->nnb = nnb;
        tags = NULL;
        xyz = NULL;
        flag = NULL;
        nb = NULL;
        msh41_map_free(&r->map);
        st = msh41_map_build(r, &r->map, r->tags, n);
    }
    free(order);
    free(pos);
    free(tags);
    free(xyz);
    free(flag);
    free(nb);
    return st;
}

/* Gmsh's MSH 2.2 writer lists an element once for every physical group
   that holds it, under a new element tag each time: the elements of an
   entity in groups "Steel" and "All" are in the file twice.  Kept twice,
   every face between the copies is a doubled (irregular) face, every node
   is fixed, and smoothing does nothing, silently (measured on a Gmsh
   assembly with a group over all volumes).  A block that repeats an
   earlier block of the same entity and type element for element (the
   same nodes in the same order) is such a copy: it leaves the mesh (the
   file keeps it; only coordinates are written), and its physical tag
   stays the entity's.  Anything short of an exact repeat is kept, as
   before. */
static void drop_repeats22(msh41_reader *r)
{
    size_t kept = 0;
    for (size_t b = 0; b < r->neb; b++) {
        msh41_eblock *e = &r->eb[b];
        size_t len = (size_t)e->count * (size_t)msh41_type_nodes(e->type, NULL);
        int rep = 0;
        for (size_t a = 0; a < kept && !rep && e->conn && e->count; a++) {
            const msh41_eblock *f = &r->eb[a];
            rep = f->conn && f->tag == e->tag && f->type == e->type &&
                  f->count == e->count &&
                  memcmp(f->conn, e->conn, len * sizeof *e->conn) == 0;
        }
        if (rep) {
            r->repeated22 += e->count;
            free(e->conn);
            free(e->ids);
            continue;
        }
        r->eb[kept++] = *e;
    }
    r->neb = kept;
}

/* After the file: entities and node blocks, as MSH 4.1 would have them. */
static getme_formats_status finish22(msh41_reader *r)
{
    if (!r->have_nodes || !r->have_elements)
        return GETME_FORMATS_OK; /* msh41_build says there is no mesh */
    drop_repeats22(r);
    getme_formats_status st = entities22(r);
    return st == GETME_FORMATS_OK ? nodes22(r) : st;
}

/* ---- the file ----------------------------------------------------------- */

static getme_formats_status read_section(msh41_reader *r, const char *name)
{
    if (strcmp(name, "PhysicalNames") == 0)
        return read_physical_names(r);
    if (strcmp(name, "Entities") == 0 && !r->v22)
        return read_entities(r);
    if (strcmp(name, "Nodes") == 0)
        return r->v22 ? read_nodes22(r) : read_nodes(r);
    if (strcmp(name, "Elements") == 0)
        return r->v22 ? read_elements22(r) : read_elements(r);
    if (strcmp(name, "PartitionedEntities") == 0 && !r->v22)
        return read_partitioned_entities(r);
    if (strcmp(name, "ParametricNodes") == 0) /* MSH 2.2's, for Gmsh */
        return msh41_decline(r, "parametric nodes");
    if (strcmp(name, "MeshFormat") == 0) {
        r->section = "MeshFormat";
        return msh41_fail(r, GETME_FORMATS_ERR_PARSE, "second $MeshFormat");
    }
    return skip_section(r, name);
}

static getme_formats_status read_file(msh41_reader *r)
{
    getme_formats_status st = read_format(r);
    char line[TOK];
    while (st == GETME_FORMATS_OK && msh41_in_line(&r->in, line, sizeof line) == 0)
        if (line[0] == '$') /* Gmsh ignores anything between sections */
            st = read_section(r, line + 1);
    return st;
}

static void reader_free(msh41_reader *r)
{
    msh41_in_close(&r->in);
    for (size_t i = 0; i < r->nnames; i++)
        free(r->names[i].name);
    free(r->names);
    free(r->ents);
    free(r->model_ents);
    free(r->phys);
    free(r->fix_found);
    free(r->tags);
    free(r->xyz);
    free(r->flag);
    free(r->nb);
    msh41_map_free(&r->map);
    drop_blocks(r);
    free(r->eb);
    free(r->ndim);
    free(r->netag);
    free(r->ent22);
}

static void remember_identity(msh41_doc *m, FILE *f)
{
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0)
        return;
    m->size = (int64_t)sb.st_size;
    m->mtime_ns = (int64_t)sb.st_mtim.tv_sec * 1000000000 + sb.st_mtim.tv_nsec;
    m->dev = (uint64_t)sb.st_dev;
    m->ino = (uint64_t)sb.st_ino;
}

/* Undo a partial open so that the Gmsh path starts from a clean doc. */
static void reset_doc(getme_doc *doc)
{
    getme_mesh_free(doc->mesh);
    doc->mesh = NULL;
    free(doc->elem_ids);
    doc->elem_ids = NULL;
    free(doc->node_ids);
    doc->node_ids = NULL;
    free(doc->elem_region);
    doc->elem_region = NULL;
    doc->info[0] = 0;
    doc->error[0] = 0;
}

getme_formats_status msh41_open(getme_doc *doc, const getme_doc_options *opts,
                           msh41_doc **out, int *eligible, char *why,
                           size_t why_size)
{
    msh41_reader r;
    memset(&r, 0, sizeof r);
    r.doc = doc;
    r.opts = opts;
    *out = NULL;
    *eligible = 1;
    msh41_doc *m = getme__calloc(1, sizeof *m);
    if (!m)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "Out of memory");
    if (msh41_in_open(&r.in, doc->path)) {
        free(m);
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "Cannot open '%s': %s",
                              doc->path, strerror(errno));
    }
    r.threads = opts && opts->num_threads > 0 ? opts->num_threads
                                                : omp_get_max_threads();
    remember_identity(m, r.in.f);
    r.file_size = m->size > 0 ? m->size : 1;
    getme_formats_status st = read_file(&r);
    if (st == GETME_FORMATS_OK && r.v22)
        st = finish22(&r);
    if (st == GETME_FORMATS_OK)
        st = msh41_build(&r, m);
    m->binary = r.binary;
    m->v22 = r.v22;
    m->nodes_offset = r.nodes_offset;
    reader_free(&r);
    if (st == MSH41_DECLINED) {
        *eligible = 0;
        snprintf(why, why_size, "%s", r.why);
        reset_doc(doc);
        st = GETME_FORMATS_OK;
    }
    if (st != GETME_FORMATS_OK || !*eligible) {
        msh41_free(m);
        return st;
    }
    *out = m;
    return GETME_FORMATS_OK;
}

void msh41_free(msh41_doc *m)
{
    if (!m)
        return;
    msh41_map_free(&m->map);
    free(m);
}
