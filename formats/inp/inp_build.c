/*
 * inp_build.c -- from the deck as read to the getme_mesh: ids -> indices,
 * sections -> regions, fixed nodes, and the state the writer keeps.
 *
 * Regions (interfaces between them are fixed unless --free-interfaces):
 *  - an element in a *SOLID SECTION belongs to that section's region;
 *  - an element in no section belongs to the region of the ELSET= named on
 *    its *ELEMENT line (Gmsh writes one per geometric volume or surface,
 *    so interfaces between Gmsh volumes stay fixed, as Gmsh itself keeps
 *    nodes on lower-dimensional entities);
 *  - elements with neither share region 0.
 * Nodes of elements that are not smoothed (beams, shells or membranes in a
 * solid deck, springs, rigid and surface elements...) are always fixed.
 */
#include "inp_internal.h"
#include "getme_alloc.h"
#include "model.h"

#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

typedef struct builder {
    inp_deck *d;
    getme_doc *doc;
    inp_kind smooth;       /* INP_KIND_SOLID or INP_KIND_PLANAR            */
    inp_ids nodes, elems;
    int32_t *sfirst;       /* per element block: first smoothed index      */
    int32_t nsmooth;
    uint8_t *fixed;
    int threads;           /* the options' thread count, resolved          */
    uint32_t *stamp[2];    /* per set: traversal that visited it, per depth */
    uint32_t now[2];
    int32_t *stack[2];
} builder;

static const char *where(const inp_deck *d, int file, uint32_t line,
                         char *buf, size_t sz)
{
    snprintf(buf, sz, "%s:%u", inp_file_name(d, file), line);
    return buf;
}

/* Index of the last of n blocks (stride bytes apart, each with its first
   index as an int32_t at byte offset off, in increasing order) whose
   first index is at most i: the block holding i. */
static size_t block_holding(const void *blocks, size_t n, size_t stride,
                            size_t off, int32_t i)
{
    const char *b = blocks;
    size_t lo = 0, hi = n;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        int32_t first;
        memcpy(&first, b + mid * stride + off, sizeof first);
        if (first <= i)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* Block holding element e / node n (read order). */
static size_t block_of(const inp_deck *d, int32_t e)
{
    return block_holding(d->eblocks, d->neblocks, sizeof *d->eblocks,
                         offsetof(inp_elem_block, first), e);
}

static size_t nblock_of(const inp_deck *d, int32_t n)
{
    return block_holding(d->nblocks, d->nnblocks, sizeof *d->nblocks,
                         offsetof(inp_node_block, first), n);
}

/* ---- id maps -------------------------------------------------------------- */

static getme_formats_status build_maps(builder *b)
{
    inp_deck *d = b->d;
    size_t nr = d->nnblocks > d->neblocks ? d->nnblocks : d->neblocks;
    inp_run *runs = getme__malloc((nr ? nr : 1) * sizeof *runs);
    if (!runs)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    for (size_t i = 0; i < d->nnblocks; i++)
        runs[i] = (inp_run){d->nblocks[i].scope, d->nblocks[i].first,
                            d->nblocks[i].count};
    int32_t a, c;
    char w1[600], w2[600];
    int rc = inp_ids_build(&b->nodes, d->nscopes, d->node_id, runs,
                           d->nnblocks, &a, &c);
    if (rc == 1) {
        free(runs);
        return getme_doc_fail(
            b->doc, GETME_FORMATS_ERR_PARSE, "%s: node %d defined twice (first at %s)",
            where(d, d->nblocks[nblock_of(d, c)].file, d->node_line[c], w1,
                  sizeof w1),
            d->node_id[c],
            where(d, d->nblocks[nblock_of(d, a)].file, d->node_line[a], w2,
                  sizeof w2));
    }
    for (size_t i = 0; rc == 0 && i < d->neblocks; i++)
        runs[i] = (inp_run){d->eblocks[i].scope, d->eblocks[i].first,
                            d->eblocks[i].count};
    if (rc == 0)
        rc = inp_ids_build(&b->elems, d->nscopes, d->elem_id, runs,
                           d->neblocks, &a, &c);
    free(runs);
    if (rc == 1)
        return getme_doc_fail(
            b->doc, GETME_FORMATS_ERR_PARSE,
            "%s: element %d defined twice (first at %s)",
            where(d, d->eblocks[block_of(d, c)].file, d->elem_line[c], w1,
                  sizeof w1),
            d->elem_id[c],
            where(d, d->eblocks[block_of(d, a)].file, d->elem_line[a], w2,
                  sizeof w2));
    if (rc < 0)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    return GETME_FORMATS_OK;
}

/* Element e of block k whose conn starts at p references a missing node. */
static getme_formats_status undefined_node(builder *b, size_t k, int32_t e,
                                      int32_t node)
{
    char w[600];
    return getme_doc_fail(b->doc, GETME_FORMATS_ERR_PARSE,
                          "%s: element %d (%s) references undefined node %d",
                          where(b->d, b->d->eblocks[k].file,
                                b->d->elem_line[e], w, sizeof w),
                          b->d->elem_id[e], b->d->eblocks[k].type, node);
}

/* Raw node ids in conn -> node indices, in place.  A block of one
   element type (nv nodes each) is looked up in parallel: each entry is
   written only by its own iteration, and a missing node is the first in
   conn order (a minimum over the threads), so the message is the one a
   serial pass gives, for any thread count.  On 4M tets the serial
   lookups were ~0.2 s of the read. */
static getme_formats_status resolve_conn(builder *b, int threads)
{
    inp_deck *d = b->d;
    for (size_t k = 0; k < d->neblocks; k++) {
        const inp_elem_block *eb = &d->eblocks[k];
        int64_t p = eb->conn_beg;
        if (eb->nv) {
            int64_t n = (int64_t)eb->count * eb->nv, bad = n;
            int32_t *conn = d->conn + p;
#pragma omp parallel for schedule(static) num_threads(threads) \
    reduction(min : bad) if (threads > 1 && n >= 65536)
            for (int64_t i = 0; i < n; i++) {
                int32_t idx = inp_ids_get(&b->nodes, eb->scope, conn[i]);
                if (idx < 0)
                    bad = i < bad ? i : bad; /* conn[i] stays the id */
                else
                    conn[i] = idx;
            }
            if (bad < n)
                return undefined_node(b, k, eb->first + (int32_t)(bad / eb->nv),
                                      conn[bad]);
            continue;
        }
        for (int32_t e = eb->first; e < eb->first + eb->count; e++) {
            int32_t n = d->conn[p++];
            for (int32_t j = 0; j < n; j++, p++) {
                int32_t idx = inp_ids_get(&b->nodes, eb->scope, d->conn[p]);
                if (idx < 0)
                    return undefined_node(b, k, e, d->conn[p]);
                d->conn[p] = idx;
            }
        }
    }
    return GETME_FORMATS_OK;
}

/* ---- dimension ------------------------------------------------------------ */

static getme_formats_status choose_kind(builder *b)
{
    inp_deck *d = b->d;
    char w[600];
    if (d->nnodes == 0)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_PARSE,
                              "%s: no *NODE data: not a mesh",
                              inp_file_name(d, 0));
    if (d->count_kind[INP_KIND_SOLID] > 0) {
        b->smooth = INP_KIND_SOLID;
        return GETME_FORMATS_OK;
    }
    if (d->planar2_line)
        return getme_doc_fail(
            b->doc, GETME_FORMATS_ERR_UNSUPPORTED,
            "%s: element type %s is second order: getme smooths linear "
            "elements only",
            where(d, d->planar2_file, d->planar2_line, w, sizeof w),
            d->planar2_type);
    if (d->count_kind[INP_KIND_PLANAR] > 0) {
        b->smooth = INP_KIND_PLANAR;
        return GETME_FORMATS_OK;
    }
    return getme_doc_fail(b->doc, GETME_FORMATS_ERR_UNSUPPORTED,
                          "%s: no linear solid (C3D4/C3D5/C3D6/C3D8) or planar "
                          "(CPS3/CPS4/CPE3/CPE4/S3/S4...) elements to smooth "
                          "(%d other elements)",
                          inp_file_name(d, 0), d->nelems);
}

/* Planar meshes are smoothed in the xy plane: all their nodes need the
   same z. */
static getme_formats_status check_plane(builder *b)
{
    inp_deck *d = b->d;
    int have = 0;
    double z0 = 0;
    for (size_t k = 0; k < d->neblocks; k++) {
        const inp_elem_block *eb = &d->eblocks[k];
        if (eb->kind != INP_KIND_PLANAR)
            continue;
        for (int64_t p = eb->conn_beg; p < eb->conn_end; p++) {
            double z = d->xyz[3 * (size_t)d->conn[p] + 2];
            if (!have) {
                z0 = z;
                have = 1;
            } else if (z != z0) {
                int32_t e = eb->first + (int32_t)((p - eb->conn_beg) / eb->nv);
                char w[600];
                return getme_doc_fail(
                    b->doc, GETME_FORMATS_ERR_UNSUPPORTED,
                    "%s: element %d (%s) is not in the plane z = %g of the "
                    "other planar elements: getme smooths planar meshes in "
                    "the xy plane only",
                    where(d, eb->file, d->elem_line[e], w, sizeof w),
                    d->elem_id[e], eb->type, z0);
            }
        }
    }
    return GETME_FORMATS_OK;
}

/* ---- sets ----------------------------------------------------------------- */

typedef getme_formats_status (*member_fn)(builder *b, int32_t index, void *arg);

static getme_formats_status unknown_member(builder *b, const inp_chunk *c, int kind,
                                      int32_t set, int32_t id)
{
    char w[600];
    return getme_doc_fail(b->doc, GETME_FORMATS_ERR_PARSE,
                          "%s: %s set '%s' lists undefined %s %d",
                          where(b->d, c->file, c->line, w, sizeof w),
                          kind == INP_SET_NODE ? "node" : "element",
                          inp_str(&b->d->names, b->d->sets[set].name),
                          kind == INP_SET_NODE ? "node" : "element", id);
}

static getme_formats_status visit_wide_range(builder *b, int kind, int scope,
                                        int64_t first, int64_t last,
                                        int64_t step, member_fn fn, void *arg)
{
    const inp_deck *d = b->d;
    size_t nb = kind == INP_SET_NODE ? d->nnblocks : d->neblocks;
    getme_formats_status st;
    for (size_t k = 0; k < nb; k++) {
        int sc = kind == INP_SET_NODE ? d->nblocks[k].scope : d->eblocks[k].scope;
        int32_t beg = kind == INP_SET_NODE ? d->nblocks[k].first
                                           : d->eblocks[k].first;
        int32_t cnt = kind == INP_SET_NODE ? d->nblocks[k].count
                                           : d->eblocks[k].count;
        const int32_t *ids = kind == INP_SET_NODE ? d->node_id : d->elem_id;
        if (sc != scope)
            continue;
        for (int32_t i = beg; i < beg + cnt; i++)
            if (ids[i] >= first && ids[i] <= last &&
                (ids[i] - first) % step == 0 && (st = fn(b, i, arg)))
                return st;
    }
    return GETME_FORMATS_OK;
}

static getme_formats_status visit_ids(builder *b, int32_t set, const inp_chunk *c,
                                 member_fn fn, void *arg)
{
    inp_deck *d = b->d;
    int kind = d->sets[set].kind;
    const inp_ids *m = kind == INP_SET_NODE ? &b->nodes : &b->elems;
    getme_formats_status st;
    for (int64_t i = c->beg; i < c->end; i++) {
        if (d->items[i] > 0) {
            int32_t idx = inp_ids_get(m, c->scope, d->items[i]);
            if (idx < 0)
                return unknown_member(b, c, kind, set, d->items[i]);
            if ((st = fn(b, idx, arg)))
                return st;
            continue;
        }
        /* GENERATE range: ids missing from it are skipped, as Abaqus does
           with sparse numbering. */
        int64_t first = -(int64_t)d->items[i], last = d->items[i + 1],
                step = d->items[i + 2];
        i += 2;
        if ((last - first) / step > 2 * (int64_t)(d->nnodes + d->nelems) + 1024) {
            /* A range far wider than the mesh ("1, 2147483647"): test the
               entries of the scope instead of every id of the range. */
            if ((st = visit_wide_range(b, kind, c->scope, first, last, step,
                                       fn, arg)))
                return st;
            continue;
        }
        for (int64_t id = first; id <= last; id += step) {
            int32_t idx = inp_ids_get(m, c->scope, id);
            if (idx >= 0 && (st = fn(b, idx, arg)))
                return st;
        }
    }
    return GETME_FORMATS_OK;
}

static getme_formats_status for_each_member(builder *b, int32_t set, member_fn fn,
                                       void *arg, int depth);

typedef struct elem_nodes_arg {
    member_fn fn;
    void *arg;
} elem_nodes_arg;

/* The nodes of smoothed element e (others have all their nodes fixed). */
static getme_formats_status elem_nodes(builder *b, int32_t e, void *varg)
{
    const elem_nodes_arg *a = varg;
    const inp_deck *d = b->d;
    const inp_elem_block *eb = &d->eblocks[block_of(d, e)];
    if (!eb->nv)
        return GETME_FORMATS_OK;
    const int32_t *c = d->conn + eb->conn_beg + (int64_t)(e - eb->first) * eb->nv;
    getme_formats_status st;
    for (int j = 0; j < eb->nv; j++)
        if ((st = a->fn(b, c[j], a->arg)))
            return st;
    return GETME_FORMATS_OK;
}

static getme_formats_status visit_chunk(builder *b, int32_t set,
                                   const inp_chunk *c, member_fn fn, void *arg,
                                   int depth)
{
    const inp_deck *d = b->d;
    getme_formats_status st;
    if (c->nblock >= 0) {
        const inp_node_block *nb = &d->nblocks[c->nblock];
        for (int32_t i = nb->first; i < nb->first + nb->count; i++)
            if ((st = fn(b, i, arg)))
                return st;
    } else if (c->eblock >= 0) {
        const inp_elem_block *eb = &d->eblocks[c->eblock];
        for (int32_t i = eb->first; i < eb->first + eb->count; i++)
            if ((st = fn(b, i, arg)))
                return st;
    } else if (c->elset >= 0) {
        elem_nodes_arg a = {fn, arg};
        if (depth == 0 &&
            (st = for_each_member(b, c->elset, elem_nodes, &a, 1)))
            return st;
    } else if ((st = visit_ids(b, set, c, fn, arg))) {
        return st;
    }
    return GETME_FORMATS_OK;
}

/* Every member of set, following set references; each referenced set is
   visited once (an explicit stack: reference chains can be long). */
static getme_formats_status for_each_member(builder *b, int32_t set, member_fn fn,
                                       void *arg, int depth)
{
    inp_deck *d = b->d;
    if (!b->stamp[depth]) {
        b->stamp[depth] = getme__calloc(d->nsets, sizeof *b->stamp[depth]);
        b->stack[depth] = getme__malloc(d->nsets * sizeof *b->stack[depth]);
        if (!b->stamp[depth] || !b->stack[depth])
            return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL,
                                  "out of memory");
    }
    uint32_t *stamp = b->stamp[depth];
    int32_t *stack = b->stack[depth];
    uint32_t now = ++b->now[depth];
    size_t top = 0;
    stack[top++] = set;
    stamp[set] = now;
    while (top) {
        int32_t s = stack[--top];
        for (int32_t k = d->sets[s].head; k >= 0; k = d->chunks[k].next) {
            const inp_chunk *c = &d->chunks[k];
            if (c->setref >= 0) {
                if (stamp[c->setref] != now) {
                    stamp[c->setref] = now;
                    stack[top++] = c->setref;
                }
                continue;
            }
            getme_formats_status st = visit_chunk(b, s, c, fn, arg, depth);
            if (st)
                return st;
        }
    }
    return GETME_FORMATS_OK;
}

/* ---- regions -------------------------------------------------------------- */

static int32_t smoothed_index(const builder *b, int32_t e)
{
    size_t k = block_of(b->d, e);
    if (b->d->eblocks[k].kind != b->smooth)
        return -1;
    return b->sfirst[k] + (e - b->d->eblocks[k].first);
}

static getme_formats_status set_region(builder *b, int32_t e, void *arg)
{
    int32_t s = smoothed_index(b, e);
    if (s >= 0)
        ((int32_t *)arg)[s] = ((int32_t *)arg)[b->nsmooth];
    return GETME_FORMATS_OK;
}

static int32_t find_section_set(const inp_deck *d, const inp_section *s)
{
    int32_t set = inp_hash_get(
        &d->lookup, inp_lookup_key(INP_LOOKUP_ELSET, s->ns, s->elset));
    if (set < 0)
        set = inp_hash_get(&d->lookup,
                           inp_lookup_key(INP_LOOKUP_ELSET, 0, s->elset));
    return set;
}

/* region[nsmooth] is scratch: the region being assigned. */
static getme_formats_status regions(builder *b, int32_t *region)
{
    inp_deck *d = b->d;
    for (size_t k = 0; k < d->neblocks; k++) {
        const inp_elem_block *eb = &d->eblocks[k];
        if (eb->kind != b->smooth)
            continue;
        int32_t r = eb->elset >= 0 ? 1 + (int32_t)d->nsections + eb->elset : 0;
        for (int32_t i = 0; i < eb->count; i++)
            region[b->sfirst[k] + i] = r;
    }
    for (size_t s = 0; s < d->nsections; s++) {
        int32_t set = find_section_set(d, &d->sections[s]);
        if (set < 0) {
            char w[600];
            return getme_doc_fail(
                b->doc, GETME_FORMATS_ERR_PARSE,
                "%s: *SOLID SECTION refers to unknown element set '%s'",
                where(d, d->sections[s].file, d->sections[s].line, w, sizeof w),
                inp_str(&d->names, d->sections[s].elset));
        }
        region[b->nsmooth] = 1 + (int32_t)s;
        getme_formats_status st = for_each_member(b, set, set_region, region, 0);
        if (st)
            return st;
    }
    return GETME_FORMATS_OK;
}

/* ---- fixed nodes ---------------------------------------------------------- */

static getme_formats_status fix_node(builder *b, int32_t n, void *arg)
{
    (void)arg;
    b->fixed[n] = 1;
    return GETME_FORMATS_OK;
}

static getme_formats_status fix_elem(builder *b, int32_t e, void *arg)
{
    (void)arg;
    elem_nodes_arg a = {fix_node, NULL};
    return elem_nodes(b, e, &a);
}

static void fix_other_elements(builder *b)
{
    const inp_deck *d = b->d;
    for (size_t k = 0; k < d->neblocks; k++) {
        const inp_elem_block *eb = &d->eblocks[k];
        if (eb->kind == b->smooth)
            continue;
        int64_t p = eb->conn_beg;
        while (p < eb->conn_end) {
            int32_t n = eb->nv ? eb->nv : d->conn[p++];
            for (int32_t j = 0; j < n; j++)
                b->fixed[d->conn[p++]] = 1;
        }
    }
}

/* "Available sets: A, B, ..." for the unknown-name message. */
static void list_sets(const inp_deck *d, char *buf, size_t sz)
{
    size_t len = 0;
    buf[0] = '\0';
    for (size_t s = 0; s < d->nsets; s++) {
        int seen = 0;
        for (size_t t = 0; t < s && !seen; t++)
            seen = d->sets[t].name == d->sets[s].name;
        if (seen)
            continue;
        const char *name = inp_str(&d->names, d->sets[s].name);
        if (len + strlen(name) + 8 >= sz) {
            snprintf(buf + len, sz - len, ", ...");
            return;
        }
        len += (size_t)snprintf(buf + len, sz - len, "%s%s", len ? ", " : "",
                                name);
        if (s > 200)
            break;
    }
    if (!len)
        snprintf(buf, sz, "none");
}

/* Fix the sets called name: "Set", or "Part.Set" / "Instance.Set". */
/* The sets called name: their nodes are fixed (fix = 1) or only looked up
   (--free: nothing is fixed by name in a deck, but an unknown name is
   still an error). */
static getme_formats_status fix_named(builder *b, const char *name, int fix)
{
    inp_deck *d = b->d;
    int found = 0;
    getme_formats_status st;
    int32_t id = inp_str_find(&d->names, name);
    const char *dot = strrchr(name, '.');
    int qscope = -1;
    int32_t qid = -1;
    if (dot && (size_t)(dot - name) < INP_MAX_VALUE) {
        char pre[INP_MAX_VALUE];
        memcpy(pre, name, (size_t)(dot - name));
        pre[dot - name] = '\0';
        int32_t pid = inp_str_find(&d->names, pre);
        if (pid >= 0) {
            qscope = inp_hash_get(&d->lookup,
                                  inp_lookup_key(INP_LOOKUP_PART, 0, pid));
            int is = inp_hash_get(&d->lookup,
                                  inp_lookup_key(INP_LOOKUP_INSTANCE, 0, pid));
            if (qscope < 0 && is >= 0)
                qscope = d->scopes[is].node_scope;
        }
        qid = inp_str_find(&d->names, dot + 1);
    }
    for (size_t s = 0; s < d->nsets; s++) {
        const inp_set *set = &d->sets[s];
        int match = (id >= 0 && set->name == id) ||
                    (qscope >= 0 && set->ns == qscope && set->name == qid);
        if (!match)
            continue;
        found = 1;
        if (!fix)
            continue;
        st = for_each_member(b, (int32_t)s,
                             set->kind == INP_SET_NODE ? fix_node : fix_elem,
                             NULL, 0);
        if (st)
            return st;
    }
    if (!found) {
        char avail[700];
        list_sets(d, avail, sizeof avail);
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_ARGUMENT,
                              "%s: no node or element set named '%s' to %s "
                              "(available: %s)",
                              inp_file_name(d, 0), name, fix ? "fix" : "free",
                              avail);
    }
    return GETME_FORMATS_OK;
}

static getme_formats_status fix_nodes(builder *b, const getme_doc_options *opts,
                                 getme_mesh *mesh, int32_t *nfixed)
{
    inp_deck *d = b->d;
    b->fixed = getme__calloc((size_t)d->nnodes, 1);
    if (!b->fixed)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    fix_other_elements(b);
    for (int i = 0; i < opts->num_fix; i++) {
        getme_formats_status st = fix_named(b, opts->fix[i], 1);
        if (st)
            return st;
    }
    for (int i = 0; i < opts->num_free; i++) {
        getme_formats_status st = fix_named(b, opts->free_sets[i], 0);
        if (st)
            return st;
    }
    unsigned flags = (opts->fix_skin ? GETME_FIX_SKIN : 0u) |
                     (opts->fix_interfaces ? GETME_FIX_INTERFACES : 0u);
    getme_status gs = getme_mesh_set_fixed_mask(mesh, b->fixed);
    if (gs == GETME_OK)
        gs = getme_mesh_fix_boundary(mesh, flags, nfixed);
    if (gs != GETME_OK)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "%s: %s",
                              inp_file_name(d, 0), getme_mesh_error(mesh));
    return GETME_FORMATS_OK;
}

/* ---- the mesh --------------------------------------------------------------- */

/* Corners and node ids per element of a block (second order: Abaqus'
   corners come first too). */
static void block_shape(const inp_elem_block *eb, int *ho, int *nv, int *corners)
{
    *ho = eb->gtype >= INP_HO ? eb->gtype - INP_HO : -1;
    *nv = *ho >= 0 ? getme_ho_type_num_nodes((getme_ho_type)*ho)
                   : getme_type_num_nodes((getme_elem_type)eb->gtype);
    *corners = *ho >= 0 ? getme_type_num_nodes((getme_elem_type)getme_ho_type_linear(
                              (getme_ho_type)*ho))
                        : *nv;
}

/* Signed area of a planar block's elements (xy plane). */
static double block_area(const getme_mesh *mesh, const inp_deck *d,
                         const inp_elem_block *eb)
{
    int ho, nv, corners;
    block_shape(eb, &ho, &nv, &corners);
    return getme__planar_area(getme_mesh_coords(mesh), d->conn + eb->conn_beg,
                              eb->count, corners, nv);
}

/* One block of elements to the core: second-order ones from Abaqus' node
   order to Gmsh's, reversed when reverse is set (a planar block that turns
   against the deck's majority: Gmsh writes one block per surface, each
   oriented like its surface, and two surfaces of one plane may turn
   opposite ways; model/planar.c does the same per MSH entity).  Only the
   core's copy changes. */
static getme_status inp_add_block(getme_mesh *mesh, const inp_deck *d,
                                  const inp_elem_block *eb, int reverse,
                                  const int32_t *region)
{
    int ho, nv, corners;
    block_shape(eb, &ho, &nv, &corners);
    const int32_t *conn = d->conn + eb->conn_beg;
    if (ho < 0 && !reverse)
        return getme_mesh_add_elements(mesh, (getme_elem_type)eb->gtype,
                                       eb->count, conn, region);
    int32_t *g = getme__malloc(((size_t)eb->count * nv + 1) * sizeof *g);
    if (!g)
        return GETME_ERR_NOMEM;
    const int8_t *order = ho >= 0 ? inp_ho_order((getme_ho_type)ho) : NULL;
    for (int32_t e = 0; e < eb->count; e++)
        for (int k = 0; k < nv; k++)
            g[(size_t)e * nv + k] = conn[(size_t)e * nv + (order ? order[k] : k)];
    if (reverse)
        getme__planar_reverse(g, eb->count, corners, nv);
    getme_status st =
        ho >= 0 ? getme_mesh_add_elements_ho(mesh, (getme_ho_type)ho, eb->count, g, region)
                : getme_mesh_add_elements(mesh, (getme_elem_type)eb->gtype,
                                          eb->count, g, region);
    free(g);
    return st;
}

static getme_formats_status add_blocks(builder *b, getme_mesh *mesh)
{
    inp_deck *d = b->d;
    int32_t *region = getme__malloc(((size_t)b->nsmooth + 1) * sizeof *region);
    if (!region)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    getme_formats_status st = regions(b, region);
    double planar_area = 0;
    for (size_t k = 0; b->smooth == INP_KIND_PLANAR && k < d->neblocks; k++)
        if (d->eblocks[k].kind == b->smooth)
            planar_area += block_area(mesh, d, &d->eblocks[k]);
    for (size_t k = 0; !st && k < d->neblocks; k++) {
        const inp_elem_block *eb = &d->eblocks[k];
        if (eb->kind != b->smooth || eb->count == 0)
            continue;
        int ho, nv, corners;
        block_shape(eb, &ho, &nv, &corners);
        for (int32_t e = 0; e < eb->count && !st; e++) {
            const int32_t *c = d->conn + eb->conn_beg + (size_t)e * nv;
            for (int i = 1; i < nv && !st; i++)
                for (int j = 0; j < i && !st; j++)
                    if (c[i] == c[j]) {
                        char w[600];
                        st = getme_doc_fail(
                            b->doc, GETME_FORMATS_ERR_INVALID,
                            "%s: element %lld is degenerate: node %lld "
                            "appears twice; getme smooths valid meshes only",
                            where(d, eb->file, d->elem_line[eb->first + e], w,
                                  sizeof w),
                            (long long)d->elem_id[eb->first + e],
                            (long long)d->node_id[c[i]]);
                    }
        }
        if (st)
            break;
        /* the majority's orientation (by area; a tie counts as
           counter-clockwise) stays as it is, since libgetme mirrors an
           all-clockwise mesh itself: only blocks against it turn */
        double area = b->smooth == INP_KIND_PLANAR ? block_area(mesh, d, eb) : 0;
        int reverse = planar_area < 0 ? area > 0 : area < 0;
        getme_status gs = inp_add_block(mesh, d, eb, reverse, region + b->sfirst[k]);
        if (gs != GETME_OK) {
            char w[600];
            st = getme_doc_fail(b->doc, gs == GETME_ERR_NOMEM
                                            ? GETME_FORMATS_ERR_INTERNAL
                                            : GETME_FORMATS_ERR_PARSE,
                                "%s: %s",
                                where(d, eb->file, d->elem_line[eb->first], w,
                                      sizeof w),
                                getme_mesh_error(mesh));
        }
    }
    free(region);
    return st;
}

static getme_formats_status make_ids(builder *b)
{
    inp_deck *d = b->d;
    b->doc->elem_ids =
        getme__malloc(((size_t)b->nsmooth + 1) * sizeof(int64_t));
    if (!b->doc->elem_ids)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    for (size_t k = 0; k < d->neblocks; k++) {
        const inp_elem_block *eb = &d->eblocks[k];
        if (eb->kind != b->smooth)
            continue;
        for (int32_t i = 0; i < eb->count; i++)
            b->doc->elem_ids[b->sfirst[k] + i] = d->elem_id[eb->first + i];
    }
    return GETME_FORMATS_OK;
}

static void info(builder *b, getme_mesh *mesh, int32_t nfixed)
{
    inp_deck *d = b->d;
    char types[256] = "";
    size_t len = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int32_t n = getme_mesh_num_elements_of_type(mesh, (getme_elem_type)t);
        if (n > 0)
            len += (size_t)snprintf(types + len, sizeof types - len, "%s%d %s",
                                    len ? ", " : "", n,
                                    getme_type_name((getme_elem_type)t));
    }
    int parts = 0;
    for (size_t s = 0; s < d->nscopes; s++)
        parts += d->scopes[s].kind == INP_SCOPE_PART;
    snprintf(b->doc->info, sizeof b->doc->info,
             "Abaqus INP: %d nodes, %d elements smoothed (%s), %d other "
             "elements kept, %zu sets, %d parts, %zu included files; %d "
             "nodes fixed",
             d->nnodes, b->nsmooth, types, d->nelems - b->nsmooth, d->nsets,
             parts, d->nfiles - 1, nfixed);
}

/* Hand the writer what it needs and nothing else. */
static getme_formats_status keep_for_writer(builder *b)
{
    inp_deck *d = b->d;
    inp_doc *st = getme__calloc(1, sizeof *st);
    if (!st)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    st->files = d->files;
    st->nfiles = d->nfiles;
    st->incs = d->incs;
    st->nincs = d->nincs;
    st->nblocks = d->nblocks;
    st->nnblocks = d->nnblocks;
    st->node_id = d->node_id;
    st->nnodes = d->nnodes;
    st->threads = b->threads;
    d->files = NULL;
    d->nfiles = 0;
    d->incs = NULL;
    d->nblocks = NULL;
    d->node_id = NULL;
    b->doc->impl = st;
    return GETME_FORMATS_OK;
}

static getme_formats_status build_mesh(builder *b, const getme_doc_options *opts)
{
    inp_deck *d = b->d;
    getme_formats_status st;
    b->threads = opts->num_threads > 0 ? opts->num_threads
                                       : omp_get_max_threads();
    if ((st = choose_kind(b)) || (st = build_maps(b)) ||
        (st = resolve_conn(b, b->threads)))
        return st;
    if (b->smooth == INP_KIND_PLANAR && (st = check_plane(b)))
        return st;
    b->sfirst =
        getme__malloc((d->neblocks ? d->neblocks : 1) * sizeof *b->sfirst);
    if (!b->sfirst)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    for (size_t k = 0; k < d->neblocks; k++) {
        b->sfirst[k] = b->nsmooth;
        if (d->eblocks[k].kind == b->smooth)
            b->nsmooth += d->eblocks[k].count;
    }
    getme_mesh *mesh = NULL;
    /* the mesh takes the coordinates (no copy; freed if it fails) */
    getme_status gs = getme_mesh_create_take(
        &mesh, b->smooth == INP_KIND_SOLID ? 3 : 2, d->nnodes, d->xyz);
    d->xyz = NULL;
    if (gs != GETME_OK)
        return getme_doc_fail(b->doc, GETME_FORMATS_ERR_INTERNAL, "%s: %s",
                              inp_file_name(d, 0), getme_status_string(gs));
    b->doc->mesh = mesh;
    int32_t nfixed = 0;
    if ((st = add_blocks(b, mesh)) || (st = fix_nodes(b, opts, mesh, &nfixed)) ||
        (st = make_ids(b)))
        return st;
    info(b, mesh, nfixed);
    return keep_for_writer(b);
}

getme_formats_status inp_build(inp_deck *d, getme_doc *doc,
                          const getme_doc_options *opts)
{
    builder b;
    memset(&b, 0, sizeof b);
    b.d = d;
    b.doc = doc;
    getme_formats_status st = build_mesh(&b, opts);
    inp_ids_free(&b.nodes);
    inp_ids_free(&b.elems);
    free(b.sfirst);
    free(b.fixed);
    for (int i = 0; i < 2; i++) {
        free(b.stamp[i]);
        free(b.stack[i]);
    }
    return st;
}

void inp_doc_free(inp_doc *st)
{
    if (!st)
        return;
    for (size_t i = 0; i < st->nfiles; i++)
        free(st->files[i].path);
    free(st->files);
    free(st->incs);
    free(st->nblocks);
    free(st->node_id);
    free(st);
}
