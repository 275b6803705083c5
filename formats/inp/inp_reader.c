/*
 * inp_reader.c -- one streaming pass over an Abaqus input deck and the
 * files it *INCLUDEs, into the flat arrays of an inp_deck.
 *
 * *INCLUDE is textual insertion, as in Abaqus: an included file may hold
 * only the data lines of the keyword before the *INCLUDE, so the keyword
 * context carries over into and out of included files.  Ids stay raw file
 * ids here; inp_build.c maps them to indices once everything is read
 * (Abaqus lets sets and elements name nodes defined further down).
 */
#define _POSIX_C_SOURCE 200809L
#include "inp_internal.h"
#include "getme_alloc.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

enum { M_NONE, M_SKIP, M_NODE, M_ELEMENT, M_NSET, M_ELSET };

typedef struct reader {
    inp_deck *d;
    getme_doc *doc;
    int file;              /* current file occurrence                      */
    uint32_t line;         /* current line                                 */
    inp_keyword kw;        /* the keyword being read (may continue)        */
    int kw_open;           /* kw's parameter list continues               */
    int mode;
    int ns;                /* scope where sets and nodes are defined        */
    int outer_ns;          /* scope to return to at *END INSTANCE           */
    int nblock, eblock;    /* open blocks, -1 if none                      */
    int32_t set;           /* *NODE NSET= / *ELEMENT ELSET= / *NSET target */
    int set_scope;         /* scope the ids of *NSET / *ELSET refer to      */
    int32_t chunk;         /* open chunk of set, -1 if none                */
    int generate;
    /* *ELEMENT type and the element being read (continuation lines) */
    inp_kind kind;
    int gtype, nv;
    char type[24];
    int32_t elset_name;
    int pending;           /* node ids read so far of an open element, -1 */
    int64_t count_pos;     /* OTHER elements: where their node count goes  */
    /* elements with more node ids on their line than their type has
       (CalculiX ignores them): how many, the first one */
    int64_t extra;
    int extra_file;
    uint32_t extra_line;
    int32_t extra_elem;
    /* data lines before the first keyword (ignored, as CalculiX does: its
       own test deck beamfsh1.inp starts with one) */
    int64_t lead;
    int lead_file;
    uint32_t lead_line;
    int threads;           /* for the fast path (inp_fast.c)             */
    size_t fast_want;      /* its window                                  */
    int depth;
    dev_t dev[INP_MAX_DEPTH + 1];
    ino_t ino[INP_MAX_DEPTH + 1];
} reader;

static getme_formats_status fail(reader *rd, getme_formats_status st, const char *fmt,
                            ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static getme_formats_status fail(reader *rd, getme_formats_status st, const char *fmt,
                            ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return getme_doc_fail(rd->doc, st, "%s:%u: %s",
                          inp_file_name(rd->d, rd->file), rd->line, msg);
}

static getme_formats_status nomem(reader *rd)
{
    return fail(rd, GETME_FORMATS_ERR_INTERNAL, "out of memory");
}

const char *inp_file_name(const inp_deck *deck, int file)
{
    if (file < 0 || (size_t)file >= deck->nfiles)
        return "?";
    return deck->files[file].path;
}

int64_t inp_lookup_key(int what, int scope, int32_t name)
{
    return ((int64_t)what << 56) | ((int64_t)scope << 32) | (uint32_t)name;
}

/* ---- scopes, sets, chunks ----------------------------------------------- */

static int new_scope(reader *rd, int kind, int32_t name)
{
    inp_deck *d = rd->d;
    if (d->nscopes >= (1 << 20) ||
        INP_RESERVE(d->scopes, d->cap_scopes, d->nscopes + 1))
        return -1;
    inp_scope *s = &d->scopes[d->nscopes];
    s->kind = kind;
    s->name = name;
    s->node_scope = (int)d->nscopes;
    return (int)d->nscopes++;
}

static int32_t find_set(const inp_deck *d, int kind, int ns, int32_t name)
{
    return inp_hash_get(&d->lookup, inp_lookup_key(kind, ns, name));
}

/* The set (kind, ns, name), created empty if new; -1 out of memory. */
static int32_t get_set(reader *rd, int kind, int ns, const char *name)
{
    inp_deck *d = rd->d;
    int32_t id = inp_str_intern(&d->names, name);
    if (id < 0)
        return -1;
    int32_t s = find_set(d, kind, ns, id);
    if (s >= 0)
        return s;
    if (d->nsets >= INT32_MAX / 2 ||
        INP_RESERVE(d->sets, d->cap_sets, d->nsets + 1))
        return -1;
    s = (int32_t)d->nsets;
    if (inp_hash_put(&d->lookup, inp_lookup_key(kind, ns, id), s, NULL) < 0)
        return -1;
    d->sets[s] = (inp_set){kind, ns, id, -1, -1};
    d->nsets++;
    return s;
}

/* Append a chunk to set s; returns its index or -1. */
static int32_t add_chunk(reader *rd, int32_t s, int scope)
{
    inp_deck *d = rd->d;
    /* Sets made of sets copy chunk records: bound their number so that a
       deck nesting set references cannot blow up. */
    if (d->nchunks >= (1u << 26) ||
        INP_RESERVE(d->chunks, d->cap_chunks, d->nchunks + 1))
        return -1;
    int32_t c = (int32_t)d->nchunks++;
    d->chunks[c] = (inp_chunk){scope, rd->file, rd->line, d->nitems,
                               d->nitems, -1, -1, -1, -1, -1};
    if (d->sets[s].tail >= 0)
        d->chunks[d->sets[s].tail].next = c;
    else
        d->sets[s].head = c;
    d->sets[s].tail = c;
    return c;
}

static int push_item(reader *rd, int32_t v)
{
    inp_deck *d = rd->d;
    if (d->nitems >= INT32_MAX ||
        INP_RESERVE(d->items, d->cap_items, (size_t)d->nitems + 1))
        return -1;
    d->items[d->nitems++] = v;
    return 0;
}

/* ---- nodes ---------------------------------------------------------------- */

static getme_formats_status open_node_block(reader *rd, int64_t offset)
{
    inp_deck *d = rd->d;
    if (INP_RESERVE(d->nblocks, d->cap_nblocks, d->nnblocks + 1))
        return nomem(rd);
    rd->nblock = (int)d->nnblocks++;
    d->nblocks[rd->nblock] =
        (inp_node_block){rd->file, rd->ns, offset, d->nnodes, 0};
    if (rd->set >= 0) {
        int32_t c = add_chunk(rd, rd->set, rd->ns);
        if (c < 0)
            return nomem(rd);
        d->chunks[c].nblock = rd->nblock;
    }
    return GETME_FORMATS_OK;
}

int inp_reserve_nodes(inp_deck *d, size_t n)
{
    size_t cap = d->cap_nodes;
    if (n <= cap)
        return 0;
    /* The per-node arrays grow together. */
    size_t c1 = cap, c2 = cap, c3 = cap;
    if (inp_reserve((void **)&d->node_id, &c1, n, sizeof *d->node_id) ||
        inp_reserve((void **)&d->node_line, &c2, n, sizeof *d->node_line) ||
        inp_reserve((void **)&d->xyz, &c3, n, 3 * sizeof *d->xyz))
        return -1;
    d->cap_nodes = c1;
    return c2 != c1 || c3 != c1 ? -1 : 0; /* cannot differ: same doubling */
}

int inp_reserve_elems(inp_deck *d, size_t n)
{
    if (n <= d->cap_elems)
        return 0;
    size_t c1 = d->cap_elems, c2 = d->cap_elems;
    if (inp_reserve((void **)&d->elem_id, &c1, n, sizeof *d->elem_id) ||
        inp_reserve((void **)&d->elem_line, &c2, n, sizeof *d->elem_line))
        return -1;
    d->cap_elems = c1;
    return c2 != c1 ? -1 : 0;
}

static getme_formats_status node_line(reader *rd, const char *text, size_t len,
                                 int64_t offset)
{
    inp_deck *d = rd->d;
    const char *p = text, *end = text + len;
    inp_field f;
    int last;
    int64_t id;
    inp_next_field(&p, end, &f, &last);
    if (inp_parse_int(&f, &id) || id < 1 || id > INT32_MAX)
        return fail(rd, GETME_FORMATS_ERR_PARSE, "bad node number '%.*s'",
                    (int)(f.n > 40 ? 40 : f.n), f.s);
    double x[3] = {0, 0, 0};
    for (int k = 0; k < 3 && !last && inp_next_field(&p, end, &f, &last); k++)
        if (inp_parse_real(&f, &x[k]))
            return fail(rd, GETME_FORMATS_ERR_PARSE,
                        "node %lld: bad coordinate '%.*s'", (long long)id,
                        (int)(f.n > 40 ? 40 : f.n), f.s);
    if (rd->nblock < 0 || d->nblocks[rd->nblock].file != rd->file) {
        getme_formats_status st = open_node_block(rd, offset);
        if (st)
            return st;
    }
    if (d->nnodes >= INT32_MAX / 3 - 1)
        return fail(rd, GETME_FORMATS_ERR_UNSUPPORTED, "more than %d nodes",
                    INT32_MAX / 3 - 1);
    size_t n = (size_t)d->nnodes;
    if (inp_reserve_nodes(d, n + 1))
        return nomem(rd);
    d->node_id[n] = (int32_t)id;
    d->node_line[n] = rd->line;
    memcpy(&d->xyz[3 * n], x, sizeof x);
    d->nnodes++;
    d->nblocks[rd->nblock].count++;
    return GETME_FORMATS_OK;
}

/* ---- elements ------------------------------------------------------------- */

static getme_formats_status open_elem_block(reader *rd)
{
    inp_deck *d = rd->d;
    if (INP_RESERVE(d->eblocks, d->cap_eblocks, d->neblocks + 1))
        return nomem(rd);
    rd->eblock = (int)d->neblocks++;
    inp_elem_block *b = &d->eblocks[rd->eblock];
    memset(b, 0, sizeof *b);
    b->file = rd->file;
    b->scope = rd->ns;
    b->kind = rd->kind;
    b->gtype = rd->gtype;
    b->nv = rd->nv;
    memcpy(b->type, rd->type, sizeof b->type);
    b->elset = rd->elset_name;
    b->first = d->nelems;
    b->conn_beg = b->conn_end = d->nconn;
    if (rd->set >= 0) {
        int32_t c = add_chunk(rd, rd->set, rd->ns);
        if (c < 0)
            return nomem(rd);
        d->chunks[c].eblock = rd->eblock;
    }
    return GETME_FORMATS_OK;
}

static int push_conn(inp_deck *d, int32_t v)
{
    if (d->nconn >= INT32_MAX * 4LL ||
        INP_RESERVE(d->conn, d->cap_conn, (size_t)d->nconn + 1))
        return -1;
    d->conn[d->nconn++] = v;
    return 0;
}

static getme_formats_status start_element(reader *rd, const inp_field *f)
{
    inp_deck *d = rd->d;
    int64_t id;
    if (inp_parse_int(f, &id) || id < 1 || id > INT32_MAX)
        return fail(rd, GETME_FORMATS_ERR_PARSE, "bad element number '%.*s'",
                    (int)(f->n > 40 ? 40 : f->n), f->s);
    if (rd->eblock < 0 || d->eblocks[rd->eblock].file != rd->file) {
        getme_formats_status st = open_elem_block(rd);
        if (st)
            return st;
    }
    if (d->nelems >= INT32_MAX - 1)
        return fail(rd, GETME_FORMATS_ERR_UNSUPPORTED, "too many elements");
    size_t n = (size_t)d->nelems;
    if (inp_reserve_elems(d, n + 1))
        return nomem(rd);
    d->elem_id[n] = (int32_t)id;
    d->elem_line[n] = rd->line;
    d->nelems++;
    d->eblocks[rd->eblock].count++;
    d->count_kind[rd->kind]++;
    rd->pending = 0;
    if (rd->nv == 0) {
        rd->count_pos = d->nconn;
        if (push_conn(d, 0))
            return nomem(rd);
    }
    return GETME_FORMATS_OK;
}

static getme_formats_status finish_element(reader *rd)
{
    inp_deck *d = rd->d;
    if (rd->nv && rd->pending != rd->nv)
        return fail(rd, GETME_FORMATS_ERR_PARSE,
                    "element %d of type %s has %d nodes, %s needs %d",
                    d->elem_id[d->nelems - 1], rd->type, rd->pending, rd->type,
                    rd->nv);
    if (!rd->nv)
        d->conn[rd->count_pos] = rd->pending;
    d->eblocks[rd->eblock].conn_end = d->nconn;
    rd->pending = -1;
    return GETME_FORMATS_OK;
}

static getme_formats_status element_line(reader *rd, const char *text, size_t len)
{
    inp_deck *d = rd->d;
    const char *p = text, *end = text + len;
    inp_field f;
    int last = 0;
    getme_formats_status st;
    if (rd->pending < 0) {
        inp_next_field(&p, end, &f, &last);
        if ((st = start_element(rd, &f)))
            return st;
    }
    int continues = 0;
    while (!last && inp_next_field(&p, end, &f, &last)) {
        if (last && f.n == 0) {
            continues = 1; /* trailing comma: the element goes on */
            break;
        }
        int64_t id;
        if (rd->nv == 0 && (f.n == 0 || memchr(f.s, '.', f.n)))
            continue; /* "instance.node" of an assembly-level element */
        if (inp_parse_int(&f, &id) || id < 0 || id > INT32_MAX)
            return fail(rd, GETME_FORMATS_ERR_PARSE,
                        "element %d: bad node number '%.*s'",
                        d->elem_id[d->nelems - 1],
                        (int)(f.n > 40 ? 40 : f.n), f.s);
        if (rd->nv == 0 && id == 0)
            continue; /* "no node" in connector-like elements */
        if (id == 0)
            return fail(rd, GETME_FORMATS_ERR_PARSE,
                        "element %d: node number 0",
                        d->elem_id[d->nelems - 1]);
        if (rd->nv && rd->pending == rd->nv) {
            /* As CalculiX: an element line with more node ids than the
               type has (decks of ccx's own test suite do this) gives the
               first ones; the rest of the line is ignored (and written
               back as it was), with a warning. */
            if (rd->extra++ == 0) {
                rd->extra_file = rd->file;
                rd->extra_line = rd->line;
                rd->extra_elem = d->elem_id[d->nelems - 1];
            }
            break;
        }
        if (push_conn(d, (int32_t)id))
            return nomem(rd);
        rd->pending++;
    }
    if (continues && !(rd->nv && rd->pending == rd->nv))
        return GETME_FORMATS_OK;
    return finish_element(rd);
}

/* ---- sets ----------------------------------------------------------------- */

/* A set named in a data line: a reference chunk (a set made of sets). */
static getme_formats_status copy_set(reader *rd, int32_t src)
{
    int32_t n = add_chunk(rd, rd->set, rd->d->sets[src].ns);
    if (n < 0)
        return fail(rd, GETME_FORMATS_ERR_UNSUPPORTED, "too many set references");
    rd->d->chunks[n].setref = src;
    rd->chunk = -1;
    return GETME_FORMATS_OK;
}

/* The scope an instance name refers to, or -1. */
static int instance_scope(const inp_deck *d, const char *name)
{
    int32_t id = inp_str_find(&d->names, name);
    if (id < 0)
        return -1;
    return inp_hash_get(&d->lookup, inp_lookup_key(INP_LOOKUP_INSTANCE, 0, id));
}

/* A set name in a data line: "Name" or "instance.Name"; or a qualified
   id "instance.17". */
static getme_formats_status set_reference(reader *rd, const inp_field *f)
{
    inp_deck *d = rd->d;
    int kind = rd->mode == M_NSET ? INP_SET_NODE : INP_SET_ELEM;
    const char *what = kind == INP_SET_NODE ? "node" : "element";
    char name[INP_MAX_VALUE];
    size_t n = f->n < sizeof name ? f->n : sizeof name - 1;
    memcpy(name, f->s, n);
    name[n] = '\0';
    int32_t id = inp_str_find(&d->names, name);
    int32_t s = id < 0 ? -1 : find_set(d, kind, rd->ns, id);
    if (s < 0 && id >= 0)
        s = find_set(d, kind, 0, id);
    char *dot = strrchr(name, '.');
    if (s < 0 && dot) {
        *dot = '\0';
        int is = instance_scope(d, name);
        int ps = is < 0 ? -1 : d->scopes[is].node_scope;
        inp_field rest = {dot + 1, strlen(dot + 1)};
        int64_t num;
        if (ps >= 0 && inp_parse_int(&rest, &num) == 0) {
            if (num < 1 || num > INT32_MAX)
                return fail(rd, GETME_FORMATS_ERR_PARSE, "bad %s number '%.*s'",
                            what, (int)f->n, f->s);
            int32_t c = add_chunk(rd, rd->set, ps);
            if (c < 0 || push_item(rd, (int32_t)num))
                return nomem(rd);
            d->chunks[c].end = d->nitems;
            rd->chunk = -1;
            return GETME_FORMATS_OK;
        }
        int32_t sid = inp_str_find(&d->names, dot + 1);
        if (ps >= 0 && sid >= 0)
            s = find_set(d, kind, ps, sid);
        *dot = '.';
    }
    if (s < 0)
        return fail(rd, GETME_FORMATS_ERR_PARSE, "unknown %s set '%s'", what, name);
    return copy_set(rd, s);
}

static getme_formats_status set_item(reader *rd, int32_t v)
{
    inp_deck *d = rd->d;
    if (rd->chunk < 0 || d->chunks[rd->chunk].file != rd->file) {
        rd->chunk = add_chunk(rd, rd->set, rd->set_scope);
        if (rd->chunk < 0)
            return nomem(rd);
    }
    if (push_item(rd, v))
        return nomem(rd);
    d->chunks[rd->chunk].end = d->nitems;
    return GETME_FORMATS_OK;
}

static getme_formats_status generate_line(reader *rd, const char *text, size_t len)
{
    const char *p = text, *end = text + len;
    inp_field f;
    int last = 0, n = 0;
    int64_t v[3] = {0, 0, 1};
    while (!last && inp_next_field(&p, end, &f, &last)) {
        if (f.n == 0 && last)
            break;
        if (n == 3 || inp_parse_int(&f, &v[n]))
            return fail(rd, GETME_FORMATS_ERR_PARSE,
                        "GENERATE needs 'first, last[, step]'");
        n++;
    }
    if (n < 2 || v[0] < 1 || v[1] < v[0] || v[1] > INT32_MAX || v[2] < 1 ||
        v[2] > INT32_MAX)
        return fail(rd, GETME_FORMATS_ERR_PARSE,
                    "GENERATE needs 'first, last[, step]' with 1 <= first <= "
                    "last and step >= 1");
    getme_formats_status st;
    if ((st = set_item(rd, (int32_t)-v[0])) || (st = set_item(rd, (int32_t)v[1])) ||
        (st = set_item(rd, (int32_t)v[2])))
        return st;
    return GETME_FORMATS_OK;
}

static getme_formats_status set_line(reader *rd, const char *text, size_t len)
{
    if (rd->generate)
        return generate_line(rd, text, len);
    const char *p = text, *end = text + len;
    inp_field f;
    int last = 0;
    getme_formats_status st;
    while (!last && inp_next_field(&p, end, &f, &last)) {
        if (f.n == 0)
            continue;
        if (inp_is_label(&f)) {
            if ((st = set_reference(rd, &f)))
                return st;
            continue;
        }
        int64_t id;
        if (inp_parse_int(&f, &id) || id < 1 || id > INT32_MAX)
            return fail(rd, GETME_FORMATS_ERR_PARSE, "bad %s number '%.*s'",
                        rd->mode == M_NSET ? "node" : "element",
                        (int)(f.n > 40 ? 40 : f.n), f.s);
        if ((st = set_item(rd, (int32_t)id)))
            return st;
    }
    return GETME_FORMATS_OK;
}

/* ---- keywords ------------------------------------------------------------- */

static const char *required(reader *rd, const char *key, getme_formats_status *st)
{
    const char *v = inp_keyword_get(&rd->kw, key);
    if (!v || !v[0]) {
        *st = fail(rd, GETME_FORMATS_ERR_PARSE, "*%s without %s=", rd->kw.name, key);
        return NULL;
    }
    *st = GETME_FORMATS_OK;
    return v;
}

static getme_formats_status kw_node(reader *rd)
{
    const char *sys = inp_keyword_get(&rd->kw, "SYSTEM");
    if (sys && !inp_name_eq(sys, "R"))
        return fail(rd, GETME_FORMATS_ERR_UNSUPPORTED,
                    "*NODE, SYSTEM=%s (non-rectangular coordinates) is not "
                    "supported",
                    sys);
    const char *nset = inp_keyword_get(&rd->kw, "NSET");
    if (nset && nset[0] && (rd->set = get_set(rd, INP_SET_NODE, rd->ns, nset)) < 0)
        return nomem(rd);
    rd->mode = M_NODE;
    return GETME_FORMATS_OK;
}

static getme_formats_status kw_element(reader *rd)
{
    getme_formats_status st;
    const char *type = required(rd, "TYPE", &st);
    if (!type)
        return st;
    char up[24];
    size_t n = strlen(type);
    if (n >= sizeof up)
        return fail(rd, GETME_FORMATS_ERR_UNSUPPORTED, "unknown element type '%s'",
                    type);
    for (size_t i = 0; i <= n; i++)
        up[i] = (char)(type[i] >= 'a' && type[i] <= 'z' ? type[i] - 32 : type[i]);
    rd->kind = inp_element_kind(up, &rd->gtype, &rd->nv);
    memcpy(rd->type, up, sizeof up);
    /* 13 nodes: a second-order pyramid, which neither Abaqus (C3D5 is its
       only pyramid) nor CalculiX defines, so no deck fixes its node order */
    if (rd->kind == INP_KIND_SOLID2)
        return fail(rd, GETME_FORMATS_ERR_UNSUPPORTED,
                    "element type %s is second order (%d nodes)%s: getme "
                    "smooths linear elements (C3D4, C3D5, C3D6, C3D8, CPS3, "
                    "CPS4...) and C3D10, C3D15, C3D20",
                    up, rd->nv,
                    rd->nv == 13 ? ", a pyramid that Abaqus and CalculiX do "
                                   "not define"
                                 : "");
    if (rd->kind == INP_KIND_PLANAR2 && rd->d->planar2_line == 0) {
        rd->d->planar2_file = rd->file;
        rd->d->planar2_line = rd->line;
        memcpy(rd->d->planar2_type, up, sizeof up);
    }
    const char *elset = inp_keyword_get(&rd->kw, "ELSET");
    rd->elset_name = -1;
    if (elset && elset[0]) {
        if ((rd->set = get_set(rd, INP_SET_ELEM, rd->ns, elset)) < 0)
            return nomem(rd);
        rd->elset_name = rd->d->sets[rd->set].name;
    }
    rd->mode = M_ELEMENT;
    return GETME_FORMATS_OK;
}

static getme_formats_status kw_set(reader *rd, int kind)
{
    getme_formats_status st;
    const char *key = kind == INP_SET_NODE ? "NSET" : "ELSET";
    const char *name = required(rd, key, &st);
    if (!name)
        return st;
    if ((rd->set = get_set(rd, kind, rd->ns, name)) < 0)
        return nomem(rd);
    rd->generate = inp_keyword_param(&rd->kw, "GENERATE") != NULL;
    rd->set_scope = rd->d->scopes[rd->ns].node_scope;
    const char *inst = inp_keyword_get(&rd->kw, "INSTANCE");
    if (inst) {
        int is = instance_scope(rd->d, inst);
        if (is < 0)
            return fail(rd, GETME_FORMATS_ERR_PARSE, "unknown instance '%s'", inst);
        rd->set_scope = rd->d->scopes[is].node_scope;
    }
    const char *elset = kind == INP_SET_NODE ? inp_keyword_get(&rd->kw, "ELSET")
                                              : NULL;
    if (elset) { /* *NSET, NSET=n, ELSET=e: the nodes of the elements of e */
        int32_t id = inp_str_find(&rd->d->names, elset);
        int32_t e = id < 0 ? -1 : find_set(rd->d, INP_SET_ELEM, rd->ns, id);
        if (e < 0)
            return fail(rd, GETME_FORMATS_ERR_PARSE, "unknown element set '%s'",
                        elset);
        int32_t c = add_chunk(rd, rd->set, rd->set_scope);
        if (c < 0)
            return nomem(rd);
        rd->d->chunks[c].elset = e;
        rd->mode = M_SKIP;
        return GETME_FORMATS_OK;
    }
    rd->mode = kind == INP_SET_NODE ? M_NSET : M_ELSET;
    return GETME_FORMATS_OK;
}

/* A new part or instance scope named by NAME=; its index, or -1 with *st
   set. */
static int named_scope(reader *rd, int kind, int what, getme_formats_status *st)
{
    const char *name = required(rd, "NAME", st);
    if (!name)
        return -1;
    inp_deck *d = rd->d;
    int32_t id = inp_str_intern(&d->names, name);
    int sc = id < 0 ? -1 : new_scope(rd, kind, id);
    int rc = sc < 0 ? -1
                    : inp_hash_put(&d->lookup, inp_lookup_key(what, 0, id), sc,
                                   NULL);
    if (rc < 0) {
        *st = nomem(rd);
        return -1;
    }
    if (rc == 1) {
        *st = fail(rd, GETME_FORMATS_ERR_PARSE, "%s '%s' defined twice",
                   what == INP_LOOKUP_PART ? "part" : "instance", name);
        return -1;
    }
    return sc;
}

static getme_formats_status kw_instance(reader *rd)
{
    getme_formats_status st;
    int sc = named_scope(rd, INP_SCOPE_INSTANCE, INP_LOOKUP_INSTANCE, &st);
    if (sc < 0)
        return st;
    inp_deck *d = rd->d;
    const char *part = inp_keyword_get(&rd->kw, "PART");
    if (part) {
        int32_t id = inp_str_find(&d->names, part);
        int ps = id < 0 ? -1
                        : inp_hash_get(&d->lookup,
                                       inp_lookup_key(INP_LOOKUP_PART, 0, id));
        if (ps < 0)
            return fail(rd, GETME_FORMATS_ERR_PARSE,
                        "*INSTANCE refers to unknown part '%s'", part);
        /* An instance's node and element ids are those of its part: the
           part is smoothed once, in its own coordinates, and every
           instance gets the result (placement is a rigid motion). */
        d->scopes[sc].node_scope = ps;
    }
    rd->outer_ns = rd->ns;
    rd->ns = sc;
    rd->mode = M_SKIP; /* data lines: translation and rotation */
    return GETME_FORMATS_OK;
}

static getme_formats_status read_file(reader *rd, const char *path, int parent);

static getme_formats_status kw_include(reader *rd, int64_t offset)
{
    getme_formats_status st;
    const char *input = required(rd, "INPUT", &st);
    if (!input)
        return st;
    if (rd->pending >= 0)
        return fail(rd, GETME_FORMATS_ERR_PARSE,
                    "element %d continues into an *INCLUDE",
                    rd->d->elem_id[rd->d->nelems - 1]);
    const inp_param *prm = inp_keyword_param(&rd->kw, "INPUT");
    char path[4096];
    const char *cur = inp_file_name(rd->d, rd->file);
    const char *slash = strrchr(cur, '/');
    int n;
    if (input[0] == '/' || !slash)
        n = snprintf(path, sizeof path, "%s", input);
    else
        n = snprintf(path, sizeof path, "%.*s/%s", (int)(slash - cur), cur,
                     input);
    if (n < 0 || (size_t)n >= sizeof path)
        return fail(rd, GETME_FORMATS_ERR_OPEN, "*INCLUDE path too long");
    if (rd->depth >= INP_MAX_DEPTH)
        return fail(rd, GETME_FORMATS_ERR_PARSE, "*INCLUDE nested more than %d deep",
                    INP_MAX_DEPTH);
    inp_deck *d = rd->d;
    if (INP_RESERVE(d->incs, d->cap_incs, d->nincs + 1))
        return nomem(rd);
    inp_include *inc = &d->incs[d->nincs++];
    inc->file = rd->file;
    /* The INPUT= value may sit on a continuation line of the keyword. */
    inc->offset = prm->line_offset;
    inc->col = prm->val_col;
    inc->len = prm->val_len;
    inc->child = (int)d->nfiles;
    (void)offset;
    /* Blocks never span files: the writer patches one file at a time. */
    rd->nblock = rd->eblock = -1;
    rd->chunk = -1;
    int file = rd->file;
    uint32_t line = rd->line;
    st = read_file(rd, path, file);
    rd->file = file;
    rd->line = line;
    rd->nblock = rd->eblock = -1;
    rd->chunk = -1;
    return st;
}

static getme_formats_status unsupported_keyword(reader *rd)
{
    static const char *const gen[] = {"NGEN", "NFILL", "NCOPY", "NMAP",
                                      "ELGEN", "ELCOPY", "SYSTEM", "NODEINPUT",
                                      NULL};
    for (int i = 0; gen[i]; i++)
        if (strcmp(rd->kw.name, gen[i]) == 0)
            return fail(rd, GETME_FORMATS_ERR_UNSUPPORTED,
                        "*%s is not supported: nodes/elements generated or "
                        "transformed by keywords cannot be written back; "
                        "give them explicitly with *NODE / *ELEMENT",
                        gen[i]);
    return GETME_FORMATS_OK;
}

/* The keyword in rd->kw is complete: act on it. */
static getme_formats_status keyword(reader *rd, int64_t offset)
{
    const char *k = rd->kw.name;
    getme_formats_status st;
    if (strcmp(k, "INCLUDE") == 0)
        return kw_include(rd, offset);
    if (rd->pending >= 0 && (st = finish_element(rd)))
        return st;
    rd->nblock = rd->eblock = -1;
    rd->set = rd->chunk = -1;
    rd->mode = M_SKIP;
    if ((st = unsupported_keyword(rd)))
        return st;
    if ((strcmp(k, "NODE") == 0 || strcmp(k, "ELEMENT") == 0 ||
         strcmp(k, "NSET") == 0 || strcmp(k, "ELSET") == 0) &&
        inp_keyword_get(&rd->kw, "INPUT"))
        return fail(rd, GETME_FORMATS_ERR_UNSUPPORTED,
                    "*%s, INPUT= is not supported: use *INCLUDE, INPUT= "
                    "after the keyword line",
                    k);
    if (strcmp(k, "NODE") == 0)
        return kw_node(rd);
    if (strcmp(k, "ELEMENT") == 0)
        return kw_element(rd);
    if (strcmp(k, "NSET") == 0)
        return kw_set(rd, INP_SET_NODE);
    if (strcmp(k, "ELSET") == 0)
        return kw_set(rd, INP_SET_ELEM);
    if (strcmp(k, "PART") == 0) {
        int sc = named_scope(rd, INP_SCOPE_PART, INP_LOOKUP_PART, &st);
        if (sc < 0)
            return st;
        rd->ns = sc;
        return GETME_FORMATS_OK;
    }
    if (strcmp(k, "ENDPART") == 0 || strcmp(k, "ENDASSEMBLY") == 0) {
        rd->ns = 0;
        return GETME_FORMATS_OK;
    }
    if (strcmp(k, "ASSEMBLY") == 0) {
        int sc = new_scope(rd, INP_SCOPE_ASSEMBLY, -1);
        if (sc < 0)
            return nomem(rd);
        rd->ns = sc;
        return GETME_FORMATS_OK;
    }
    if (strcmp(k, "INSTANCE") == 0)
        return kw_instance(rd);
    if (strcmp(k, "ENDINSTANCE") == 0) {
        rd->ns = rd->outer_ns;
        return GETME_FORMATS_OK;
    }
    if (strcmp(k, "SOLIDSECTION") == 0) {
        const char *elset = required(rd, "ELSET", &st);
        if (!elset)
            return st;
        inp_deck *d = rd->d;
        int32_t id = inp_str_intern(&d->names, elset);
        if (id < 0 || INP_RESERVE(d->sections, d->cap_sections,
                                  d->nsections + 1))
            return nomem(rd);
        d->sections[d->nsections++] =
            (inp_section){rd->ns, id, rd->file, rd->line};
    }
    return GETME_FORMATS_OK;
}

static getme_formats_status data_line(reader *rd, const char *text, size_t len,
                                 int64_t offset)
{
    switch (rd->mode) {
    case M_NONE:
        if (rd->lead++ == 0) {
            rd->lead_file = rd->file;
            rd->lead_line = rd->line;
        }
        return GETME_FORMATS_OK;
    case M_NODE: return node_line(rd, text, len, offset);
    case M_ELEMENT: return element_line(rd, text, len);
    case M_NSET:
    case M_ELSET: return set_line(rd, text, len);
    default: return GETME_FORMATS_OK;
    }
}

static getme_formats_status line(reader *rd, inp_lines *in)
{
    int kind = inp_line_kind(in->text, in->len);
    char err[256];
    if (kind == INP_LINE_BLANK || kind == INP_LINE_COMMENT)
        return GETME_FORMATS_OK;
    if (rd->kw_open) {
        rd->kw_open = 0;
        if (kind == INP_LINE_DATA) {
            if (inp_keyword_parse(&rd->kw, in->text, in->len, in->offset, 0,
                                  err, sizeof err))
                return fail(rd, GETME_FORMATS_ERR_PARSE, "%s", err);
            rd->kw_open = rd->kw.continued;
            return rd->kw_open ? GETME_FORMATS_OK : keyword(rd, in->offset);
        }
        /* A keyword after a trailing comma: the last one was complete. */
        getme_formats_status st = keyword(rd, in->offset);
        if (st)
            return st;
    }
    if (kind == INP_LINE_KEYWORD) {
        if (inp_keyword_parse(&rd->kw, in->text, in->len, in->offset, 1, err,
                              sizeof err))
            return fail(rd, GETME_FORMATS_ERR_PARSE, "%s", err);
        rd->kw_open = rd->kw.continued;
        return rd->kw_open ? GETME_FORMATS_OK : keyword(rd, in->offset);
    }
    if (memchr(in->text, '\0', in->len))
        return fail(rd, GETME_FORMATS_ERR_PARSE, "NUL byte in a data line");
    return data_line(rd, in->text, in->len, in->offset);
}

/* Inside a *NODE block, or an *ELEMENT block of a fixed-size type between
   elements, once its first line opened the block in this file, or a set's
   ids once its first line made the set's chunk in this file: the plain
   data lines that follow go through the fast path, which stops at the
   first other line (read by line() as always). */
static void fast_lines(reader *rd, inp_lines *in)
{
    inp_deck *d = rd->d;
    if (rd->kw_open)
        return;
    if (rd->mode == M_NODE && rd->nblock >= 0 &&
        d->nblocks[rd->nblock].file == rd->file) {
        size_t got = inp_fast_run(d, in, 0, rd->threads, &rd->fast_want);
        d->nblocks[rd->nblock].count += (int32_t)got;
    } else if (rd->mode == M_ELEMENT && rd->eblock >= 0 &&
               d->eblocks[rd->eblock].file == rd->file && rd->pending < 0 &&
               rd->nv > 0) {
        size_t got = inp_fast_run(d, in, rd->nv, rd->threads, &rd->fast_want);
        d->eblocks[rd->eblock].count += (int32_t)got;
        d->eblocks[rd->eblock].conn_end = d->nconn;
        d->count_kind[rd->kind] += (int32_t)got;
    } else if ((rd->mode == M_NSET || rd->mode == M_ELSET) && !rd->generate &&
               rd->chunk >= 0 && d->chunks[rd->chunk].file == rd->file &&
               d->chunks[rd->chunk].end == d->nitems) {
        /* a set's ids after its first line (set_item made the chunk) */
        inp_fast_set(d, in, rd->threads, &rd->fast_want);
        d->chunks[rd->chunk].end = d->nitems;
    }
    rd->line = in->lineno;
}

static getme_formats_status add_file(reader *rd, const char *path, int parent,
                                inp_lines *in)
{
    inp_deck *d = rd->d;
    struct stat sb;
    if (fstat(fileno(in->fp), &sb) != 0 || !S_ISREG(sb.st_mode))
        return fail(rd, GETME_FORMATS_ERR_OPEN, "'%s' is not a regular file", path);
    for (int i = 0; i < rd->depth; i++)
        if (rd->dev[i] == sb.st_dev && rd->ino[i] == sb.st_ino)
            return fail(rd, GETME_FORMATS_ERR_PARSE,
                        "*INCLUDE cycle: '%s' is already being read", path);
    rd->dev[rd->depth] = sb.st_dev;
    rd->ino[rd->depth] = sb.st_ino;
    char *copy = getme__malloc(strlen(path) + 1);
    if (!copy || INP_RESERVE(d->files, d->cap_files, d->nfiles + 1)) {
        free(copy);
        return nomem(rd);
    }
    strcpy(copy, path);
    inp_file *f = &d->files[d->nfiles];
    f->path = copy;
    f->parent = parent;
    f->parent_line = rd->line;
    f->size = (int64_t)sb.st_size;
    f->mtime_sec = (int64_t)sb.st_mtim.tv_sec;
    f->mtime_nsec = (int64_t)sb.st_mtim.tv_nsec;
    rd->file = (int)d->nfiles++;
    rd->line = 0;
    return GETME_FORMATS_OK;
}

static getme_formats_status read_file(reader *rd, const char *path, int parent)
{
    inp_lines in;
    if (inp_lines_open(&in, path) != 0) {
        const char *why = strerror(errno);
        if (parent < 0)
            return getme_doc_fail(rd->doc, GETME_FORMATS_ERR_OPEN,
                                  "cannot open '%s': %s", path, why);
        return fail(rd, GETME_FORMATS_ERR_OPEN, "cannot open *INCLUDE file '%s': %s",
                    path, why);
    }
    getme_formats_status st = add_file(rd, path, parent, &in);
    if (st) {
        inp_lines_close(&in);
        return st;
    }
    rd->depth++;
    int rc;
    for (;;) {
        fast_lines(rd, &in);
        if ((rc = inp_lines_next(&in)) != 1)
            break;
        rd->line = in.lineno;
        if ((st = line(rd, &in)))
            break;
    }
    if (!st && rc == -1)
        st = fail(rd, GETME_FORMATS_ERR_OPEN, "read error: %s", strerror(errno));
    if (!st && rc == -2)
        st = fail(rd, GETME_FORMATS_ERR_PARSE, "line %u longer than %d bytes",
                  in.lineno + 1, INP_MAX_LINE);
    if (!st && rd->pending >= 0)
        st = fail(rd, GETME_FORMATS_ERR_PARSE,
                  "file ends inside element %d (line ended with ',')",
                  rd->d->elem_id[rd->d->nelems - 1]);
    if (!st && rd->kw_open && parent < 0) {
        rd->kw_open = 0;
        st = keyword(rd, in.offset);
    }
    rd->depth--;
    inp_lines_close(&in);
    return st;
}

getme_formats_status inp_read(inp_deck *d, const char *path, getme_doc *doc,
                              int threads)
{
    reader *rd = getme__calloc(1, sizeof *rd);
    if (!rd)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    rd->d = d;
    rd->doc = doc;
    rd->file = -1;
    rd->mode = M_NONE;
    rd->nblock = rd->eblock = -1;
    rd->set = rd->chunk = -1;
    rd->pending = -1;
    rd->threads = threads;
    getme_formats_status st = GETME_FORMATS_OK;
    if (new_scope(rd, INP_SCOPE_MODEL, -1) != 0)
        st = nomem(rd);
    if (!st)
        st = read_file(rd, path, -1);
    size_t w = 0;
    if (!st && rd->extra)
        w += (size_t)snprintf(doc->warning, sizeof doc->warning,
                 "%s:%u: element %d has more node ids than its type needs: "
                 "the extra ids are ignored, as CalculiX does (%lld element%s "
                 "like this)",
                 inp_file_name(d, rd->extra_file), rd->extra_line,
                 (int)rd->extra_elem, (long long)rd->extra,
                 rd->extra == 1 ? "" : "s");
    if (!st && rd->lead && w < sizeof doc->warning)
        snprintf(doc->warning + w, sizeof doc->warning - w,
                 "%s%s:%u: %lld data line%s before the first keyword ignored, "
                 "as CalculiX does (written back as they are)",
                 w ? "; " : "", inp_file_name(d, rd->lead_file), rd->lead_line,
                 (long long)rd->lead, rd->lead == 1 ? "" : "s");
    free(rd);
    return st;
}

void inp_deck_free(inp_deck *d)
{
    for (size_t i = 0; i < d->nfiles; i++)
        free(d->files[i].path);
    free(d->files);
    free(d->incs);
    free(d->xyz);
    free(d->node_id);
    free(d->node_line);
    free(d->nblocks);
    free(d->elem_id);
    free(d->elem_line);
    free(d->conn);
    free(d->eblocks);
    free(d->scopes);
    free(d->sets);
    free(d->chunks);
    free(d->items);
    free(d->sections);
    inp_strtab_free(&d->names);
    inp_hash_free(&d->lookup);
    memset(d, 0, sizeof *d);
}
