/*
 * msh41_build.c -- turn what msh41_reader.c parsed into the core mesh,
 * exactly as the Gmsh path (libgetme_gmsh's getme_gmsh_model_read on the
 * model gmshOpen builds) would:
 *
 *  - smoothed entities: every entity of the highest dimension that has
 *    elements, in tag order; their elements in (entity, element type)
 *    order, file order inside, one getme_mesh_add_elements call per
 *    (entity, type) -- how Gmsh stores and returns them;
 *  - nodes: those the smoothed elements use, in Gmsh's node order (entity
 *    by entity: points, curves, surfaces, volumes, each by tag; file order
 *    inside an entity);
 *  - fixed: nodes not classified on a smoothed entity, nodes of the groups
 *    named by --fix, then skin / interfaces through the core;
 *  - regions: entities with the same non-empty set of physical tags share
 *    one (the index of the first), an entity without any is its own;
 *  - planar meshes: every surface whose elements are mostly clockwise gets
 *    its elements reversed.  Planar meshes not in a plane z = const (the
 *    Gmsh path rotates them into a frame) are declined.
 * Bit-identical inputs to the core give bit-identical smoothing results.
 */
#include "msh41_internal.h"

#include <stdlib.h>
#include <string.h>

static getme_io_status oom(msh41_reader *r)
{
    return getme_doc_fail(r->doc, GETME_IO_ERR_INTERNAL,
                          "'%s': out of memory", r->doc->path);
}

/* ---- node tag map ------------------------------------------------------- */

typedef struct tag_idx {
    uint64_t tag;
    int32_t idx;
} tag_idx;

static int cmp_tag_idx(const void *a, const void *b)
{
    uint64_t x = ((const tag_idx *)a)->tag, y = ((const tag_idx *)b)->tag;
    return (x > y) - (x < y);
}

static getme_io_status repeated(msh41_reader *r, uint64_t tag)
{
    return getme_doc_fail(r->doc, GETME_IO_ERR_PARSE,
                          "'%s': node %llu appears twice in $Nodes",
                          r->doc->path, (unsigned long long)tag);
}

/* Sparse tags: sorted (tag, index) pairs, looked up by bisection. */
static getme_io_status build_sorted(msh41_reader *r, msh41_nodemap *map,
                                    const uint64_t *tags, size_t n)
{
    tag_idx *ti = malloc((n ? n : 1) * sizeof *ti);
    map->sorted_tag = malloc((n ? n : 1) * sizeof *map->sorted_tag);
    map->sorted_idx = malloc((n ? n : 1) * sizeof *map->sorted_idx);
    if (!ti || !map->sorted_tag || !map->sorted_idx) {
        free(ti);
        return oom(r);
    }
    for (size_t i = 0; i < n; i++) {
        ti[i].tag = tags[i];
        ti[i].idx = (int32_t)i;
    }
    qsort(ti, n, sizeof *ti, cmp_tag_idx);
    getme_io_status st = GETME_IO_OK;
    for (size_t i = 0; i < n; i++) {
        if (i && ti[i].tag == ti[i - 1].tag && st == GETME_IO_OK)
            st = repeated(r, ti[i].tag);
        map->sorted_tag[i] = ti[i].tag;
        map->sorted_idx[i] = ti[i].idx;
    }
    free(ti);
    return st;
}

getme_io_status msh41_map_build(msh41_reader *r, msh41_nodemap *map,
                                const uint64_t *tags, size_t n)
{
    memset(map, 0, sizeof *map);
    map->n = n;
    for (size_t i = 0; i < n; i++) {
        if (tags[i] == 0)
            return getme_doc_fail(r->doc, GETME_IO_ERR_PARSE,
                                  "'%s': node tag 0 in $Nodes (tags start "
                                  "at 1)",
                                  r->doc->path);
        if (tags[i] > map->max_tag)
            map->max_tag = tags[i];
    }
    /* A direct table costs 4 bytes per possible tag: used while the tags
       are dense enough (the usual 1..N numbering). */
    if (map->max_tag > 2 * (uint64_t)n + 1024)
        return build_sorted(r, map, tags, n);
    map->dense = malloc((size_t)(map->max_tag + 1) * sizeof *map->dense);
    if (!map->dense)
        return oom(r);
    memset(map->dense, 0xff, (size_t)(map->max_tag + 1) * sizeof *map->dense);
    for (size_t i = 0; i < n; i++) {
        if (map->dense[tags[i]] >= 0)
            return repeated(r, tags[i]);
        map->dense[tags[i]] = (int32_t)i;
    }
    return GETME_IO_OK;
}

int32_t msh41_map_find(const msh41_nodemap *map, uint64_t tag)
{
    if (map->dense)
        return tag <= map->max_tag ? map->dense[tag] : -1;
    size_t lo = 0, hi = map->n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (map->sorted_tag[mid] < tag)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < map->n && map->sorted_tag[lo] == tag ? map->sorted_idx[lo]
                                                      : -1;
}

void msh41_map_free(msh41_nodemap *map)
{
    free(map->dense);
    free(map->sorted_tag);
    free(map->sorted_idx);
    memset(map, 0, sizeof *map);
}

/* File indices -> mesh indices (-1: node not in the mesh). */
static void map_relabel(msh41_nodemap *map, const int32_t *loc)
{
    if (map->dense) {
        for (uint64_t t = 0; t <= map->max_tag; t++)
            if (map->dense[t] >= 0)
                map->dense[t] = loc[map->dense[t]];
        return;
    }
    for (size_t i = 0; i < map->n; i++)
        map->sorted_idx[i] = loc[map->sorted_idx[i]];
}

/* ---- block order and type checks ---------------------------------------- */

static int cmp_eblock(const void *a, const void *b)
{
    const msh41_eblock *x = a, *y = b;
    if (x->tag != y->tag)
        return x->tag < y->tag ? -1 : 1;
    return (x->type > y->type) - (x->type < y->type);
}

/* qsort is not stable: sort an index array with the position as the last
   key so that blocks of one (entity, type) keep their file order. */
static const msh41_eblock *sort_base;

static int cmp_index(const void *a, const void *b)
{
    size_t i = *(const size_t *)a, j = *(const size_t *)b;
    int c = cmp_eblock(&sort_base[i], &sort_base[j]);
    return c ? c : (i > j) - (i < j);
}

static getme_io_status sort_blocks(msh41_reader *r)
{
    size_t n = r->neb;
    size_t *idx = malloc((n ? n : 1) * sizeof *idx);
    msh41_eblock *sorted = malloc((n ? n : 1) * sizeof *sorted);
    if (!idx || !sorted) {
        free(idx);
        free(sorted);
        return oom(r);
    }
    for (size_t i = 0; i < n; i++)
        idx[i] = i;
    sort_base = r->eb;
    qsort(idx, n, sizeof *idx, cmp_index);
    for (size_t i = 0; i < n; i++)
        sorted[i] = r->eb[idx[i]];
    memcpy(r->eb, sorted, n * sizeof *sorted);
    free(idx);
    free(sorted);
    return GETME_IO_OK;
}

static const char *dim_word(int dim, int capital)
{
    static const char *const w[2][4] = {
        {"point", "curve", "surface", "volume"},
        {"Point", "Curve", "Surface", "Volume"}};
    return w[capital][dim & 3];
}

/* The first block (in Gmsh's order) GETMe cannot smooth: the Gmsh path's
   message for it. */
static getme_io_status check_types(msh41_reader *r)
{
    int dim = r->top_dim;
    for (size_t b = 0; b < r->neb; b++) {
        if (r->eb[b].conn)
            continue;
        char name[64];
        int order = 0;
        msh41_type_nodes(r->eb[b].type, &order);
        msh41_type_name(r->eb[b].type, name, sizeof name);
        if (order > 1)
            return getme_doc_fail(
                r->doc, GETME_IO_ERR_UNSUPPORTED,
                "'%s': %s %d has elements of order %d (%s): GETMe smooths "
                "linear elements and second-order tetrahedra, hexahedra and "
                "prisms (set the element order to 1 or 2 first)",
                r->doc->path, dim_word(dim, 1), r->eb[b].tag, order, name);
        return getme_doc_fail(
            r->doc, GETME_IO_ERR_UNSUPPORTED,
            "'%s': %s %d has elements of a type GETMe cannot smooth (%s); "
            "supported: %s",
            r->doc->path, dim_word(dim, 1), r->eb[b].tag, name,
            dim == 3 ? "tetrahedra, hexahedra, prisms, pyramids"
                     : "triangles, quadrangles");
    }
    return GETME_IO_OK;
}

/* ---- nodes -------------------------------------------------------------- */

static int cmp_nblock(const void *a, const void *b)
{
    const msh41_nblock *x = a, *y = b;
    if (x->dim != y->dim)
        return x->dim < y->dim ? -1 : 1;
    if (x->tag != y->tag)
        return x->tag < y->tag ? -1 : 1;
    return (x->first > y->first) - (x->first < y->first); /* file order */
}

static int smoothed_entity(const msh41_reader *r, int dim, int tag)
{
    if (dim != r->top_dim)
        return 0;
    size_t lo = 0, hi = r->neb; /* blocks are sorted by tag */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (r->eb[mid].tag < tag)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < r->neb && r->eb[lo].tag == tag;
}

/* Number the used nodes in Gmsh's order; fill the mesh-order coordinates
   and the fixed mask (not classified on a smoothed entity, or in a --fix
   group).  loc: file index -> mesh index. */
static getme_io_status number_nodes(msh41_reader *r, int32_t *loc,
                                    int32_t *num, double **xyz,
                                    uint8_t **fixed)
{
    qsort(r->nb, r->nnb, sizeof *r->nb, cmp_nblock);
    int32_t n = 0;
    for (size_t i = 0; i < r->nnodes; i++)
        n += (r->flag[i] & MSH41_USED) != 0;
    *num = n;
    *xyz = malloc((n ? (size_t)n : 1) * 3 * sizeof **xyz);
    *fixed = malloc(n ? (size_t)n : 1);
    if (!*xyz || !*fixed)
        return oom(r);
    int32_t k = 0;
    for (size_t b = 0; b < r->nnb; b++) {
        const msh41_nblock *nb = &r->nb[b];
        int own = smoothed_entity(r, nb->dim, nb->tag);
        for (size_t i = nb->first; i < nb->first + nb->count; i++) {
            loc[i] = -1;
            if (!(r->flag[i] & MSH41_USED))
                continue;
            memcpy(*xyz + 3 * (size_t)k, r->xyz + 3 * i, 3 * sizeof **xyz);
            (*fixed)[k] = !own || (r->flag[i] & MSH41_FIXGRP);
            loc[i] = k++;
        }
    }
    return GETME_IO_OK;
}

static size_t block_len(const msh41_eblock *b)
{
    return (size_t)b->count *
           (size_t)msh41_type_nodes(b->type, NULL);
}

/* ---- planar meshes ------------------------------------------------------ */

static int all_same_z(const double *xyz, int32_t n)
{
    for (int32_t i = 1; i < n; i++)
        if (xyz[3 * i + 2] != xyz[2])
            return 0;
    return 1;
}

/* Signed area in the xy plane (same sum as the Gmsh path). */
static double signed_area(const double *xyz, const int32_t *c, int nv)
{
    double s = 0;
    for (int i = 0; i < nv; i++) {
        const double *a = xyz + 3 * c[i], *b = xyz + 3 * c[(i + 1) % nv];
        s += a[0] * b[1] - a[1] * b[0];
    }
    return 0.5 * s;
}

/* Surfaces [b0, b1) whose elements are mostly clockwise: reverse them
   (libgetme wants counter-clockwise; Gmsh may orient surfaces either way). */
static void orient_surfaces(msh41_reader *r, const double *xyz)
{
    size_t b0 = 0;
    while (b0 < r->neb) {
        size_t b1 = b0 + 1;
        while (b1 < r->neb && r->eb[b1].tag == r->eb[b0].tag)
            b1++;
        double total = 0;
        for (size_t b = b0; b < b1; b++) {
            int nv = r->eb[b].type == 2 ? 3 : 4;
            for (int32_t i = 0; i < r->eb[b].count; i++)
                total += signed_area(xyz, r->eb[b].conn + (size_t)nv * i, nv);
        }
        for (size_t b = b0; b < b1 && total < 0; b++) {
            int nv = r->eb[b].type == 2 ? 3 : 4;
            for (int32_t i = 0; i < r->eb[b].count; i++) {
                int32_t *c = r->eb[b].conn + (size_t)nv * i, t = c[1];
                c[1] = c[nv - 1];
                c[nv - 1] = t;
            }
        }
        b0 = b1;
    }
}

/* ---- regions ------------------------------------------------------------ */

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Region id per smoothed entity (tags[0..n)): the index of the first
   entity with the same non-empty sorted set of physical tags. */
static void entity_regions(msh41_reader *r, const int *tags, size_t n,
                           int32_t *region)
{
    for (size_t i = 0; i < n; i++) {
        msh41_entity *e = msh41_find_entity(r, r->top_dim, tags[i]);
        if (e && e->phys_count > 1)
            qsort(r->phys + e->phys_first, e->phys_count, sizeof(int),
                  cmp_int);
        region[i] = (int32_t)i;
        for (size_t j = 0; e && e->phys_count && j < i; j++) {
            const msh41_entity *f = msh41_find_entity(r, r->top_dim, tags[j]);
            if (f && f->phys_count == e->phys_count &&
                memcmp(r->phys + f->phys_first, r->phys + e->phys_first,
                       e->phys_count * sizeof(int)) == 0) {
                region[i] = region[j];
                break;
            }
        }
    }
}

/* ---- the mesh ----------------------------------------------------------- */

static getme_io_status mesh_fail(msh41_reader *r, getme_status st)
{
    /* the Gmsh path's mapping (msh_format.c io_status) */
    getme_io_status io = st == GETME_ERR_ARGUMENT ? GETME_IO_ERR_USAGE
                         : st == GETME_ERR_TOPOLOGY || st == GETME_ERR_STATE
                             ? GETME_IO_ERR_UNSUPPORTED
                         : st == GETME_ERR_INVALID_MESH ? GETME_IO_ERR_INVALID
                                                        : GETME_IO_ERR_INTERNAL;
    return getme_doc_fail(r->doc, io, "'%s': %s", r->doc->path,
                          getme_mesh_error(r->doc->mesh));
}

int msh41_ho_type(int msh_type, int dim)
{
    /* Gmsh's node order is getme_mesh_add_elements_ho's (docs/highorder.md) */
    switch (dim == 3 ? msh_type : 0) {
    case 11: return GETME_TET10;
    case 17: return GETME_HEX20;
    case 12: return GETME_HEX27;
    case 18: return GETME_PRISM15;
    case 13: return GETME_PRISM18;
    default: return -1;
    }
}

/* Blocks [b0, b1) of one (entity, type) become one element block. */
static getme_io_status add_run(msh41_reader *r, size_t b0, size_t b1,
                               int32_t region_id, int32_t *first)
{
    msh41_eblock *b = &r->eb[b0];
    size_t count = 0, len = 0;
    for (size_t i = b0; i < b1; i++) {
        count += (size_t)r->eb[i].count;
        len += block_len(&r->eb[i]);
    }
    int32_t *conn = b1 - b0 == 1 ? b->conn : malloc(len * sizeof *conn);
    int32_t *region = malloc(count * sizeof *region);
    getme_io_status st = conn && region ? GETME_IO_OK : oom(r);
    for (size_t i = b0, at = 0; st == GETME_IO_OK && i < b1; i++) {
        if (conn != b->conn)
            memcpy(conn + at, r->eb[i].conn,
                   block_len(&r->eb[i]) * sizeof *conn);
        at += block_len(&r->eb[i]);
        memcpy(r->doc->elem_ids + *first, r->eb[i].ids,
               (size_t)r->eb[i].count * sizeof *r->doc->elem_ids);
        *first += r->eb[i].count;
    }
    for (size_t i = 0; st == GETME_IO_OK && i < count; i++)
        region[i] = region_id;
    static const getme_elem_type by_msh[8] = {
        GETME_TET, GETME_TET, GETME_TRI, GETME_QUAD,
        GETME_TET, GETME_HEX, GETME_PRISM, GETME_PYRAMID};
    getme_status gs = GETME_OK;
    int ho = msh41_ho_type(b->type, r->top_dim);
    if (st == GETME_IO_OK && ho >= 0)
        gs = getme_mesh_add_elements_ho(r->doc->mesh, (getme_ho_type)ho,
                                        (int32_t)count, conn, region);
    else if (st == GETME_IO_OK)
        gs = getme_mesh_add_elements(r->doc->mesh, by_msh[b->type & 7],
                                     (int32_t)count, conn, region);
    if (st == GETME_IO_OK && gs != GETME_OK)
        st = mesh_fail(r, gs);
    if (conn != b->conn)
        free(conn);
    free(region);
    for (size_t i = b0; i < b1; i++) { /* free as we go: lower peak */
        free(r->eb[i].conn);
        free(r->eb[i].ids);
        r->eb[i].conn = NULL;
        r->eb[i].ids = NULL;
    }
    return st;
}

/* Distinct entity tags of the (sorted) blocks. */
static size_t entity_tags(const msh41_reader *r, int *tags)
{
    size_t n = 0;
    for (size_t b = 0; b < r->neb; b++)
        if (n == 0 || tags[n - 1] != r->eb[b].tag)
            tags[n++] = r->eb[b].tag;
    return n;
}

static getme_io_status add_blocks(msh41_reader *r, int64_t total)
{
    int *tags = malloc((r->neb ? r->neb : 1) * sizeof *tags);
    int32_t *region = malloc((r->neb ? r->neb : 1) * sizeof *region);
    r->doc->elem_ids = malloc((total ? (size_t)total : 1) *
                              sizeof *r->doc->elem_ids);
    getme_io_status st = tags && region && r->doc->elem_ids ? GETME_IO_OK
                                                           : oom(r);
    size_t ne = st == GETME_IO_OK ? entity_tags(r, tags) : 0, e = 0;
    if (st == GETME_IO_OK)
        entity_regions(r, tags, ne, region);
    int32_t first = 0;
    for (size_t b0 = 0; st == GETME_IO_OK && b0 < r->neb;) {
        size_t b1 = b0 + 1;
        while (b1 < r->neb && r->eb[b1].tag == r->eb[b0].tag &&
               r->eb[b1].type == r->eb[b0].type)
            b1++;
        while (tags[e] != r->eb[b0].tag)
            e++;
        st = add_run(r, b0, b1, region[e], &first);
        b0 = b1;
    }
    free(tags);
    free(region);
    return st;
}

/* ---- --fix names -------------------------------------------------------- */

static int cmp_pair(const void *a, const void *b)
{
    const int *x = a, *y = b;
    return x[0] != y[0] ? (x[0] > y[0]) - (x[0] < y[0])
                        : (x[1] > y[1]) - (x[1] < y[1]);
}

/* '"a" (3:1), "b" (2:5)' as the Gmsh path lists the groups. */
static void describe_groups(const msh41_reader *r, char *buf, size_t size)
{
    int *pairs = malloc((r->nphys ? r->nphys : 1) * 2 * sizeof *pairs);
    size_t n = 0, used = 0;
    for (size_t i = 0; pairs && i < r->nents; i++)
        for (size_t k = 0; k < r->ents[i].phys_count; k++) {
            pairs[2 * n] = r->ents[i].dim;
            pairs[2 * n++ + 1] = r->phys[r->ents[i].phys_first + k];
        }
    if (pairs)
        qsort(pairs, n, 2 * sizeof *pairs, cmp_pair);
    buf[0] = 0;
    for (size_t i = 0; i < n && used + 1 < size; i++) {
        if (i && cmp_pair(pairs + 2 * i, pairs + 2 * i - 2) == 0)
            continue;
        const char *name = msh41_group_name(r, pairs[2 * i], pairs[2 * i + 1]);
        int w = snprintf(buf + used, size - used, "%s\"%s\" (%d:%d)",
                         used ? ", " : "", name ? name : "", pairs[2 * i],
                         pairs[2 * i + 1]);
        if (w < 0)
            break;
        used += (size_t)w;
    }
    if (!n)
        snprintf(buf, size, "the model has no physical groups");
    free(pairs);
}

static getme_io_status check_fix_names(msh41_reader *r)
{
    int nfix = r->opts ? r->opts->num_fix : 0;
    int nfree = r->opts ? r->opts->num_free : 0;
    for (int w = 0; w < nfix + nfree; w++) {
        if (r->fix_found && r->fix_found[w])
            continue;
        char known[300];
        describe_groups(r, known, sizeof known);
        return getme_doc_fail(r->doc, GETME_IO_ERR_USAGE,
                              "'%s': Unknown physical group '%s' to %s (%s)",
                              r->doc->path,
                              w < nfix ? r->opts->fix[w]
                                       : r->opts->free_sets[w - nfix],
                              w < nfix ? "fix" : "free", known);
    }
    return GETME_IO_OK;
}

static getme_io_status mark_fixed(msh41_reader *r, const uint8_t *fixed)
{
    const getme_doc_options *o = r->opts;
    unsigned flags = (o && !o->fix_skin ? 0u : GETME_FIX_SKIN) |
                     (o && !o->fix_interfaces ? 0u : GETME_FIX_INTERFACES);
    getme_status st = getme_mesh_set_fixed_mask(r->doc->mesh, fixed);
    if (st == GETME_OK && flags)
        st = getme_mesh_fix_boundary(r->doc->mesh, flags, NULL);
    return st == GETME_OK ? GETME_IO_OK : mesh_fail(r, st);
}

/* "MSH 4.1 binary, model 'box': 2 volumes, ..." as the Gmsh path says. */
static void describe(msh41_reader *r, size_t num_entities)
{
    const char *base = strrchr(r->doc->path, '/');
    base = base ? base + 1 : r->doc->path;
    const char *dot = strrchr(base, '.');
    int len = dot ? (int)(dot - base) : (int)strlen(base);
    getme_mesh *m = r->doc->mesh;
    snprintf(r->doc->info, sizeof r->doc->info,
             "MSH %s %s, model '%.*s': %zu %s%s, %ld elements, %ld nodes "
             "(%ld fixed)",
             r->v22 ? "2.2" : "4.1", r->binary ? "binary" : "ASCII", len,
             base, num_entities,
             r->top_dim == 3 ? "volume" : "surface",
             num_entities > 1 ? "s" : "", (long)getme_mesh_num_elements(m),
             (long)getme_mesh_num_nodes(m), (long)getme_mesh_num_fixed(m));
}

/* ---- build -------------------------------------------------------------- */

static getme_io_status count_elements(msh41_reader *r, int64_t *total)
{
    *total = 0;
    for (size_t b = 0; b < r->neb; b++) {
        *total += r->eb[b].count;
        size_t len = block_len(&r->eb[b]);
        for (size_t i = 0; i < len; i++)
            r->flag[r->eb[b].conn[i]] |= MSH41_USED;
    }
    if (*total > INT32_MAX)
        return getme_doc_fail(r->doc, GETME_IO_ERR_UNSUPPORTED,
                              "'%s': More than 2^31-1 elements are not "
                              "supported",
                              r->doc->path);
    return GETME_IO_OK;
}

/* Nodes: numbering, coordinates, the mesh; conn and the map relabelled. */
static getme_io_status make_mesh(msh41_reader *r, uint8_t **fixed)
{
    int32_t *loc = malloc((r->nnodes ? r->nnodes : 1) * sizeof *loc);
    double *xyz = NULL;
    int32_t n = 0;
    getme_io_status st = loc ? number_nodes(r, loc, &n, &xyz, fixed) : oom(r);
    for (size_t b = 0; st == GETME_IO_OK && b < r->neb; b++) {
        size_t len = block_len(&r->eb[b]);
        for (size_t i = 0; i < len; i++)
            r->eb[b].conn[i] = loc[r->eb[b].conn[i]];
    }
    if (st == GETME_IO_OK)
        map_relabel(&r->map, loc);
    free(loc);
    /* The file-order arrays are no longer needed: free before the mesh
       copies the coordinates. */
    free(r->xyz);
    free(r->tags);
    r->xyz = NULL;
    r->tags = NULL;
    if (st == GETME_IO_OK && r->top_dim == 2 && !all_same_z(xyz, n))
        st = msh41_decline(r, "planar mesh not in a plane z = const");
    if (st == GETME_IO_OK && r->top_dim == 2)
        orient_surfaces(r, xyz);
    if (st == GETME_IO_OK) {
        getme_status gs = getme_mesh_create(&r->doc->mesh, r->top_dim, n, xyz);
        if (gs != GETME_OK)
            st = getme_doc_fail(r->doc, GETME_IO_ERR_INTERNAL,
                                "'%s': could not create the mesh: %s",
                                r->doc->path, getme_status_string(gs));
    }
    free(xyz);
    return st;
}

getme_io_status msh41_build(msh41_reader *r, msh41_doc *m)
{
    if (r->top_dim < 2 || !r->neb)
        return getme_doc_fail(r->doc, GETME_IO_ERR_UNSUPPORTED,
                              "'%s': No volume or surface mesh in the "
                              "current model: generate the mesh or open a "
                              "mesh file first",
                              r->doc->path);
    int64_t total = 0;
    uint8_t *fixed = NULL;
    getme_io_status st = sort_blocks(r);
    if (st == GETME_IO_OK)
        st = check_types(r);
    if (st == GETME_IO_OK)
        st = count_elements(r, &total);
    if (st == GETME_IO_OK)
        st = make_mesh(r, &fixed);
    size_t num_entities = 0;
    for (size_t b = 0; b < r->neb; b++)
        num_entities += b == 0 || r->eb[b].tag != r->eb[b - 1].tag;
    if (st == GETME_IO_OK)
        st = add_blocks(r, total);
    if (st == GETME_IO_OK)
        st = check_fix_names(r);
    if (st == GETME_IO_OK)
        st = mark_fixed(r, fixed);
    free(fixed);
    if (st == GETME_IO_OK) {
        describe(r, num_entities);
        m->map = r->map; /* the writer's tag -> mesh node table */
        memset(&r->map, 0, sizeof r->map);
    }
    return st;
}
