/*
 * msh41_build.c -- hand what msh41_reader.c parsed to the model builder
 * (formats/model: the same builder the Gmsh-SDK path feeds, so both paths
 * give the core the same mesh): the blocks in Gmsh's order (entity by
 * entity, type by type, file order inside), the node blocks in Gmsh's node
 * order (points, curves, surfaces, volumes, each by tag), the physical tags
 * of the smoothed entities; then the --fix names and the one-line summary.
 * Planar meshes not in a plane z = const (the Gmsh path rotates them into a
 * frame, which the native writer does not undo) are declined.
 */
#include "msh41_internal.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

static getme_formats_status oom(msh41_reader *r)
{
    return getme_doc_fail(r->doc, GETME_FORMATS_ERR_INTERNAL,
                          "'%s': out of memory", r->doc->path);
}

/* ---- node tag map ------------------------------------------------------- */

getme_formats_status msh41_map_build(msh41_reader *r, msh41_nodemap *map,
                                const uint64_t *tags, size_t n)
{
    memset(map, 0, sizeof *map);
    for (size_t i = 0; i < n; i++)
        if (tags[i] == 0)
            return getme_doc_fail(r->doc, GETME_FORMATS_ERR_PARSE,
                                  "'%s': node tag 0 in $Nodes (tags start "
                                  "at 1)",
                                  r->doc->path);
    uint64_t repeated = 0;
    getme_status st = getme__nodemap_build(map, tags, n, &repeated);
    if (st == GETME_ERR_ARGUMENT)
        return getme_doc_fail(r->doc, GETME_FORMATS_ERR_PARSE,
                              "'%s': node %llu appears twice in $Nodes",
                              r->doc->path, (unsigned long long)repeated);
    return st == GETME_OK ? GETME_FORMATS_OK : oom(r);
}

/* ---- block order and type checks ---------------------------------------- */

/* qsort is not stable: sort (tag, type, position) keys so that blocks of
   one (entity, type) keep their file order. */
typedef struct block_key {
    int tag, type;
    size_t pos;
} block_key;

/* Lexicographic order of two key triples. */
static int cmp3(long long a0, long long a1, long long a2, long long b0,
                long long b1, long long b2)
{
    return a0 != b0 ? (a0 > b0) - (a0 < b0)
           : a1 != b1 ? (a1 > b1) - (a1 < b1)
                      : (a2 > b2) - (a2 < b2);
}

static int cmp_key(const void *a, const void *b)
{
    const block_key *x = a, *y = b;
    return cmp3(x->tag, x->type, (long long)x->pos, y->tag, y->type,
                (long long)y->pos);
}

static getme_formats_status sort_blocks(msh41_reader *r)
{
    size_t n = r->neb;
    block_key *key = getme__malloc((n ? n : 1) * sizeof *key);
    msh41_eblock *sorted = getme__malloc((n ? n : 1) * sizeof *sorted);
    if (!key || !sorted) {
        free(key);
        free(sorted);
        return oom(r);
    }
    for (size_t i = 0; i < n; i++)
        key[i] = (block_key){r->eb[i].tag, r->eb[i].type, i};
    qsort(key, n, sizeof *key, cmp_key);
    for (size_t i = 0; i < n; i++)
        sorted[i] = r->eb[key[i].pos];
    memcpy(r->eb, sorted, n * sizeof *sorted);
    free(key);
    free(sorted);
    return GETME_FORMATS_OK;
}

/* ---- nodes -------------------------------------------------------------- */

/* Gmsh's node order: by dimension, then tag, then file order. */
static int cmp_nblock(const void *a, const void *b)
{
    const msh41_nblock *x = a, *y = b;
    return cmp3(x->dim, x->tag, (long long)x->first, y->dim, y->tag,
                (long long)y->first);
}

static int smoothed_entity(const msh41_reader *r, int dim, int tag)
{
    if (r->partitioned) { /* a piece of a volume: a cut moves with it */
        const msh41_entity *e = msh41_find_entity(r, dim, tag);
        if (e && e->parent_dim == r->top_dim)
            return 1;
    }
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
    int *pairs = getme__malloc((r->nphys ? r->nphys : 1) * 2 * sizeof *pairs);
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

static getme_formats_status check_fix_names(msh41_reader *r)
{
    int nfix = r->opts ? r->opts->num_fix : 0;
    int nfree = r->opts ? r->opts->num_free : 0;
    for (int w = 0; w < nfix + nfree; w++) {
        if (r->fix_found && r->fix_found[w])
            continue;
        char known[300];
        describe_groups(r, known, sizeof known);
        return getme_doc_fail(r->doc, GETME_FORMATS_ERR_ARGUMENT,
                              "'%s': Unknown physical group '%s' to %s (%s)",
                              r->doc->path,
                              w < nfix ? r->opts->fix[w]
                                       : r->opts->free_sets[w - nfix],
                              w < nfix ? "fix" : "free", known);
    }
    return GETME_FORMATS_OK;
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
    size_t n = strlen(r->doc->info);
    if (r->repeated22 > 0 && n < sizeof r->doc->info)
        snprintf(r->doc->info + n, sizeof r->doc->info - n,
                 "; %lld elements listed again under another physical group "
                 "(MSH 2.2) read once",
                 (long long)r->repeated22);
}


/* ---- build -------------------------------------------------------------- */

static getme_formats_status model_fail(msh41_reader *r, getme_status st,
                                  const char *msg)
{
    /* the Gmsh path's mapping (plugin/src/gmsh_format.c) */
    getme_formats_status io = st == GETME_ERR_ARGUMENT ? GETME_FORMATS_ERR_ARGUMENT
                         : st == GETME_ERR_TOPOLOGY || st == GETME_ERR_STATE
                             ? GETME_FORMATS_ERR_UNSUPPORTED
                         : st == GETME_ERR_INVALID_MESH ? GETME_FORMATS_ERR_INVALID
                                                        : GETME_FORMATS_ERR_INTERNAL;
    return getme_doc_fail(r->doc, io, "'%s': %s", r->doc->path, msg);
}

/* The builder's input: entities (distinct block tags) with their physical
   tags, node blocks in Gmsh's order with the classification flag. */
static getme_formats_status make_input(msh41_reader *r, getme__model_in *in,
                                  getme__node_range **ranges, int ***phys,
                                  size_t **nphys)
{
    qsort(r->nb, r->nnb, sizeof *r->nb, cmp_nblock);
    *ranges = getme__malloc((r->nnb ? r->nnb : 1) * sizeof **ranges);
    *phys = getme__malloc((r->neb ? r->neb : 1) * sizeof **phys);
    *nphys = getme__malloc((r->neb ? r->neb : 1) * sizeof **nphys);
    if (!*ranges || !*phys || !*nphys)
        return oom(r);
    for (size_t b = 0; b < r->nnb; b++) {
        const msh41_nblock *nb = &r->nb[b];
        (*ranges)[b] = (getme__node_range){nb->first, nb->count};
        if (smoothed_entity(r, nb->dim, nb->tag))
            for (size_t i = nb->first; i < nb->first + nb->count; i++)
                r->flag[i] |= GETME__NODE_OWN;
    }
    size_t ne = 0;
    for (size_t b = 0; b < r->neb; b++) {
        if (b && r->eb[b].tag == r->eb[b - 1].tag)
            continue;
        msh41_entity *e = msh41_find_entity(r, r->top_dim, r->eb[b].tag);
        (*phys)[ne] = e ? r->phys + e->phys_first : NULL;
        (*nphys)[ne++] = e ? e->phys_count : 0;
    }
    const getme_doc_options *o = r->opts;
    *in = (getme__model_in){
        .dim = r->top_dim,
        .num_nodes = r->nnodes,
        .xyz = r->xyz,
        .xyz_give = r->xyz,
        .flags = r->flag,
        .ranges = *ranges,
        .num_ranges = r->nnb,
        .blocks = r->eb,
        .num_blocks = r->neb,
        .num_entities = ne,
        .phys = *phys,
        .num_phys = *nphys,
        .z_plane_only = 1,
        /* msh41_store_element refused every kept element with a node
           twice, naming the element and the node */
        .nodes_distinct = 1,
        /* MSH 2.2: the faces between elementary volumes are interfaces */
        .regions_by_entity = r->v22,
        .fix_flags = r->partitioned ? 0u /* the caller's, across parts */
                     : (o && !o->fix_skin ? 0u : GETME_FIX_SKIN) |
                       (o && !o->fix_interfaces ? 0u : GETME_FIX_INTERFACES)};
    return GETME_FORMATS_OK;
}

/* One part of a partitioned file: the node tags per mesh node and the
   region key per mesh element (blocks in mesh order), for the caller that
   stitches the parts (getme_doc_node_id, getme_doc_element_region). */
static getme_formats_status part_ids(msh41_reader *r,
                                     const getme__model_out *out)
{
    getme_doc *doc = r->doc;
    size_t ne = 0;
    for (size_t b = 0; b < r->neb; b++)
        ne += (size_t)r->eb[b].count;
    doc->node_ids =
        getme__malloc((out->num_nodes ? (size_t)out->num_nodes : 1) *
                      sizeof *doc->node_ids);
    doc->elem_region = getme__malloc((ne ? ne : 1) * sizeof *doc->elem_region);
    if (!doc->node_ids || !doc->elem_region)
        return oom(r);
    for (size_t i = 0; i < r->nnodes; i++)
        if (out->loc[i] >= 0)
            doc->node_ids[out->loc[i]] = r->tags[i];
    size_t k = 0;
    for (size_t b = 0; b < r->neb; b++) {
        const msh41_entity *e =
            msh41_find_entity(r, r->top_dim, r->eb[b].tag);
        int32_t key = e ? e->region : -1;
        for (int32_t j = 0; j < r->eb[b].count; j++)
            doc->elem_region[k++] = key;
    }
    doc->num_partitions = r->num_partitions;
    return GETME_FORMATS_OK;
}

getme_formats_status msh41_build(msh41_reader *r, msh41_doc *m)
{
    if (r->top_dim < 2 || !r->neb)
        return getme_doc_fail(r->doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "'%s': No volume or surface mesh in the "
                              "current model: generate the mesh or open a "
                              "mesh file first",
                              r->doc->path);
    getme__model_in in;
    getme__model_out out;
    getme__node_range *ranges = NULL;
    int **phys = NULL;
    size_t *nphys = NULL;
    memset(&out, 0, sizeof out);
    getme_formats_status st = sort_blocks(r);
    if (st == GETME_FORMATS_OK)
        st = make_input(r, &in, &ranges, &phys, &nphys);
    getme_status gs = GETME_OK;
    if (st == GETME_FORMATS_OK) {
        gs = getme__model_number(&in, &out);
        if (!in.xyz_give) /* out's now (freed with it on failure) */
            r->xyz = NULL;
        if (gs != GETME_OK)
            st = model_fail(r, gs, out.msg);
    }
    if (st == GETME_FORMATS_OK && r->partitioned)
        st = part_ids(r, &out);
    if (st == GETME_FORMATS_OK) {
        getme__nodemap_relabel(&r->map, out.loc);
        /* The file-order arrays are no longer needed: free them before the
           mesh copies the coordinates. */
        free(r->xyz);
        free(r->tags);
        free(out.loc);
        r->xyz = NULL;
        r->tags = NULL;
        out.loc = NULL;
        gs = getme__model_finish(&in, &out);
        if (gs != GETME_OK)
            st = model_fail(r, gs, out.msg);
        else if (out.declined)
            st = msh41_decline(r, "planar mesh not in a plane z = const");
    }
    if (st == GETME_FORMATS_OK)
        st = check_fix_names(r);
    if (st == GETME_FORMATS_OK) {
        r->doc->mesh = out.mesh;
        r->doc->elem_ids = out.elem_ids;
        out.mesh = NULL;
        out.elem_ids = NULL;
        describe(r, in.num_entities);
        m->map = r->map; /* the writer's tag -> mesh node table */
        memset(&r->map, 0, sizeof r->map);
    }
    getme__model_out_free(&out);
    free(ranges);
    free(phys);
    free(nphys);
    return st;
}
