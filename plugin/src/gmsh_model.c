/*
 * gmsh_model.c -- read the current Gmsh model into a getme_mesh.
 *
 * Gmsh gives us the selected entities, their elements per element type, all
 * nodes in its own order, the nodes classified on each entity and those of
 * each physical group.  That is what the native MSH reader finds in a file,
 * and both hand it to the one model builder (formats/model), which numbers
 * the nodes, fixes, orients and builds the mesh.  Each element keeps its
 * Gmsh tag for messages.  Nothing in the model is modified here.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Everything Gmsh gave us about all nodes, plus the builder's input. */
typedef struct gg_read {
    size_t *gtags;     /* all nodes of the model (gmsh-allocated) */
    double *gcoords;
    size_t gn;
    getme__nodemap gmap; /* tag -> index into gtags */
    uint8_t *flags;    /* GETME__NODE_* per node of gtags */
    getme__model_block *blocks;
    size_t num_blocks, cap_blocks;
    int **phys;        /* per entity, gmsh-allocated */
    size_t *num_phys;
} gg_read;

static void read_free(gg_read *r, int num_entities)
{
    gmshFree(r->gtags);
    gmshFree(r->gcoords);
    getme__nodemap_free(&r->gmap);
    free(r->flags);
    for (size_t b = 0; r->blocks && b < r->num_blocks; b++) {
        free(r->blocks[b].conn);
        free(r->blocks[b].ids);
    }
    free(r->blocks);
    for (int e = 0; r->phys && e < num_entities; e++)
        gmshFree(r->phys[e]);
    free(r->phys);
    free(r->num_phys);
}

typedef struct tag_at {
    size_t tag, at;
} tag_at;

static int cmp_tag_at(const void *a, const void *b)
{
    const tag_at *x = a, *y = b;
    if (x->tag != y->tag)
        return x->tag < y->tag ? -1 : 1;
    return (x->at > y->at) - (x->at < y->at);
}

/* Split partition files merged into one model (gmsh_format.c) each carry
   the nodes of the partition boundaries they touch, so Gmsh lists such a
   node once per file: keep its first occurrence, in Gmsh's order.  The
   copies must have the same coordinates bit for bit; returns 0, or -1 with
   *bad = a tag whose copies differ, or -2 when out of memory. */
static int drop_repeated_nodes(gg_read *r, uint64_t *bad)
{
    tag_at *s = malloc((r->gn ? r->gn : 1) * sizeof *s);
    uint8_t *drop = calloc(r->gn ? r->gn : 1, 1);
    if (!s || !drop) {
        free(s);
        free(drop);
        return -2;
    }
    for (size_t i = 0; i < r->gn; i++)
        s[i].tag = r->gtags[i], s[i].at = i;
    qsort(s, r->gn, sizeof *s, cmp_tag_at);
    int rc = 0;
    for (size_t i = 1; i < r->gn && rc == 0; i++) {
        if (s[i].tag != s[i - 1].tag)
            continue;
        size_t k = s[i].at, first = s[i].at;
        for (size_t j = i; j > 0 && s[j - 1].tag == s[i].tag; j--)
            first = s[j - 1].at;
        if (memcmp(r->gcoords + 3 * k, r->gcoords + 3 * first,
                   3 * sizeof *r->gcoords) != 0)
            rc = -1, *bad = s[i].tag;
        drop[k] = 1;
    }
    size_t n = 0;
    for (size_t i = 0; i < r->gn && rc == 0; i++)
        if (!drop[i]) {
            r->gtags[n] = r->gtags[i];
            memmove(r->gcoords + 3 * n, r->gcoords + 3 * i,
                    3 * sizeof *r->gcoords);
            n++;
        }
    if (rc == 0)
        r->gn = n;
    free(s);
    free(drop);
    return rc;
}

static getme_status read_all_nodes(gg_read *r, gg_msg *msg)
{
    size_t nc = 0, np = 0;
    double *param = NULL;
    int ierr = 0;
    gmshModelMeshGetNodes(&r->gtags, &r->gn, &r->gcoords, &nc, &param, &np,
                          -1, -1, 0, 0, &ierr);
    gmshFree(param);
    if (ierr || nc != 3 * r->gn)
        return gg_fail(msg, GETME_ERR_STATE, "Could not read the mesh nodes");
    if (r->gn > (size_t)INT32_MAX)
        return gg_fail(msg, GETME_ERR_ARGUMENT,
                       "%zu nodes: more than 2^31-1 are not supported", r->gn);
    r->flags = calloc(r->gn ? r->gn : 1, 1);
    if (!r->flags)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    uint64_t repeated = 0;
    if (gg_model_partitioned()) {
        int rc = drop_repeated_nodes(r, &repeated);
        if (rc == -2)
            return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
        if (rc == -1)
            return gg_fail(msg, GETME_ERR_STATE,
                           "Node %llu appears twice with different "
                           "coordinates", (unsigned long long)repeated);
    }
    getme_status st = getme__nodemap_build(&r->gmap, (const uint64_t *)r->gtags,
                                           r->gn, &repeated);
    if (st == GETME_ERR_ARGUMENT)
        return gg_fail(msg, GETME_ERR_STATE, "Node %llu appears twice",
                       (unsigned long long)repeated);
    return st == GETME_OK ? GETME_OK
                          : gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
}

static getme_status grow_blocks(gg_read *r, gg_msg *msg)
{
    if (r->num_blocks < r->cap_blocks)
        return GETME_OK;
    size_t cap = r->cap_blocks ? 2 * r->cap_blocks : 8;
    getme__model_block *nb = realloc(r->blocks, cap * sizeof *nb);
    if (!nb)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    r->blocks = nb;
    r->cap_blocks = cap;
    return GETME_OK;
}

/* Append one (entity, type) block: Gmsh node tags -> indices of gtags.  A
   type GETMe cannot smooth is kept without connectivity: the builder
   names it. */
static getme_status add_block(gg_read *r, int dim, int tag, int gmsh_type,
                              const size_t *etags, size_t ne,
                              const size_t *ntags, gg_msg *msg)
{
    getme_status st = grow_blocks(r, msg);
    if (st != GETME_OK)
        return st;
    getme__model_block *b = &r->blocks[r->num_blocks++];
    memset(b, 0, sizeof *b);
    b->tag = tag;
    b->type = gmsh_type;
    int type = getme__msh_type_corners(gmsh_type, dim);
    if (type < 0 || getme_type_dim((getme_elem_type)type) != dim)
        return GETME_OK;
    if (ne > (size_t)INT32_MAX)
        return gg_fail(msg, GETME_ERR_ARGUMENT,
                       "More than 2^31-1 elements are not supported");
    int nv = getme__msh_type_nodes(gmsh_type, NULL);
    b->conn = malloc((ne ? ne : 1) * (size_t)nv * sizeof *b->conn);
    b->ids = malloc((ne ? ne : 1) * sizeof *b->ids);
    if (!b->conn || !b->ids)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    b->count = (int32_t)ne;
    for (size_t i = 0; i < ne * (size_t)nv; i++) {
        int32_t g = getme__nodemap_find(&r->gmap, ntags[i]);
        if (g < 0)
            return gg_fail(msg, GETME_ERR_TOPOLOGY,
                           "Element %zu of %s %d uses node %zu, which does "
                           "not exist",
                           etags[i / (size_t)nv], gg_dim_word(dim), tag,
                           ntags[i]);
        b->conn[i] = g;
    }
    for (size_t i = 0; i < ne; i++)
        b->ids[i] = (int64_t)etags[i];
    return GETME_OK;
}

static getme_status read_entity(gg_read *r, int dim, int tag, gg_msg *msg)
{
    int *types = NULL, ierr = 0;
    size_t ntypes = 0, **etags = NULL, *etags_n = NULL, etags_nn = 0;
    size_t **ntags = NULL, *ntags_n = NULL, ntags_nn = 0;
    gmshModelMeshGetElements(&types, &ntypes, &etags, &etags_n, &etags_nn,
                             &ntags, &ntags_n, &ntags_nn, dim, tag, &ierr);
    getme_status st = ierr ? gg_fail(msg, GETME_ERR_STATE,
                                     "Could not read the elements of %s %d",
                                     gg_dim_word(dim), tag)
                           : GETME_OK;
    for (size_t t = 0; t < ntypes && st == GETME_OK; t++)
        if (etags_n[t])
            st = add_block(r, dim, tag, types[t], etags[t], etags_n[t],
                           ntags[t], msg);
    for (size_t t = 0; t < ntypes; t++) {
        gmshFree(etags ? etags[t] : NULL);
        gmshFree(ntags ? ntags[t] : NULL);
    }
    gmshFree(types);
    gmshFree(etags);
    gmshFree(etags_n);
    gmshFree(ntags);
    gmshFree(ntags_n);
    return st;
}

/* The blocks' summary kept for messages (gg_describe_element). */
static getme_status keep_blocks(getme_gmsh_model *m, const gg_read *r,
                                gg_msg *msg)
{
    m->blocks = malloc((r->num_blocks ? r->num_blocks : 1) * sizeof *m->blocks);
    if (!m->blocks)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    int32_t first = 0;
    for (size_t b = 0; b < r->num_blocks; b++) {
        const getme__model_block *rb = &r->blocks[b];
        m->blocks[b] = (gg_block){rb->type, getme__msh_type_corners(rb->type, m->dim),
                                  m->dim, rb->tag, first, rb->count};
        first += rb->count;
    }
    m->num_blocks = (int)r->num_blocks;
    return GETME_OK;
}

/* What the builder made becomes the model's. */
static getme_status take_output(getme_gmsh_model *m, getme__model_out *out,
                                const gg_read *r, gg_msg *msg)
{
    m->num_nodes = out->num_nodes;
    m->num_elements = out->num_elements;
    m->node_tags = malloc((m->num_nodes ? (size_t)m->num_nodes : 1) *
                          sizeof *m->node_tags);
    m->elem_tags = malloc((m->num_elements ? (size_t)m->num_elements : 1) *
                          sizeof *m->elem_tags);
    if (!m->node_tags || !m->elem_tags)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    for (size_t g = 0; g < r->gn; g++)
        if (out->loc[g] >= 0)
            m->node_tags[out->loc[g]] = r->gtags[g];
    for (int32_t e = 0; e < m->num_elements; e++)
        m->elem_tags[e] = (size_t)out->elem_ids[e];
    m->coords0 = out->xyz;
    m->fixed = out->fixed;
    m->mesh = out->mesh;
    m->frame = out->frame;
    out->xyz = NULL;
    out->fixed = NULL;
    out->mesh = NULL;
    /* the mask after skin and interfaces, for getme_gmsh_model_apply */
    getme_status st = getme_mesh_get_fixed_mask(m->mesh, m->fixed);
    return st == GETME_OK ? GETME_OK
                          : gg_fail(msg, st, "%s", getme_mesh_error(m->mesh));
}

static getme_status build(getme_gmsh_model *m, gg_read *r,
                          const getme_gmsh_options *opt, gg_msg *msg)
{
    getme__node_range all = {0, r->gn};
    getme__model_in in = {
        .dim = m->dim,
        .num_nodes = r->gn,
        .xyz = r->gcoords,
        .flags = r->flags,
        .ranges = &all,
        .num_ranges = 1,
        .blocks = r->blocks,
        .num_blocks = r->num_blocks,
        .num_entities = (size_t)m->num_entities,
        .phys = r->phys,
        .num_phys = r->num_phys,
        .z_plane_only = 0,
        .keep_copies = 1, /* take_output keeps both */
        .fix_flags = (opt->fix_skin ? GETME_FIX_SKIN : 0u) |
                     (opt->fix_interfaces ? GETME_FIX_INTERFACES : 0u)};
    getme__model_out out;
    getme_status st = getme__model_number(&in, &out);
    if (st == GETME_OK)
        st = keep_blocks(m, r, msg);
    else
        gg_fail(msg, st, "%s", out.msg);
    if (st == GETME_OK) {
        st = getme__model_finish(&in, &out);
        if (st != GETME_OK)
            gg_fail(msg, st, "%s", out.msg);
    }
    if (st == GETME_OK)
        st = take_output(m, &out, r, msg);
    getme__model_out_free(&out);
    return st;
}

static getme_status read_model(getme_gmsh_model *m, gg_read *r,
                               const int *dim_tags, size_t n,
                               const getme_gmsh_options *opt, gg_msg *msg)
{
    getme_status st = gg_select_entities(dim_tags, n, &m->entities,
                                         &m->num_entities, &m->dim, msg);
    if (st == GETME_OK)
        st = read_all_nodes(r, msg);
    for (int e = 0; e < m->num_entities && st == GETME_OK; e++)
        st = read_entity(r, m->dim, m->entities[2 * e + 1], msg);
    if (st == GETME_OK)
        st = gg_fix_classified(m, &r->gmap, r->flags, msg);
    if (st == GETME_OK)
        st = gg_fix_groups(opt, &r->gmap, r->flags, msg);
    if (st == GETME_OK)
        st = gg_entity_phys(m->entities, m->num_entities, &r->phys,
                            &r->num_phys, msg);
    if (st == GETME_OK)
        st = build(m, r, opt, msg);
    return st;
}

getme_status getme_gmsh_model_read(getme_gmsh_model **model,
                                   const int *dim_tags, size_t dim_tags_n,
                                   const getme_gmsh_options *options,
                                   char *message, size_t message_size)
{
    gg_msg msg = {""};
    getme_gmsh_options defaults;
    getme_status st = GETME_OK;
    if (model)
        *model = NULL;
    if (!model)
        st = gg_fail(&msg, GETME_ERR_ARGUMENT, "model is NULL");
    else if (!gg_gmsh_initialized())
        st = gg_fail(&msg, GETME_ERR_STATE,
                     "Gmsh is not initialized (call gmshInitialize first)");
    getme_gmsh_model *m = st == GETME_OK ? calloc(1, sizeof *m) : NULL;
    if (st == GETME_OK && !m)
        st = gg_fail(&msg, GETME_ERR_NOMEM, "Out of memory");
    if (st == GETME_OK) {
        if (!options) {
            gg_options_defaults(&defaults);
            options = &defaults;
        }
        gg_read r;
        memset(&r, 0, sizeof r);
        st = read_model(m, &r, dim_tags, dim_tags_n, options, &msg);
        read_free(&r, m->num_entities);
    }
    if (st != GETME_OK) {
        getme_gmsh_model_free(m);
        m = NULL;
    }
    if (model)
        *model = m;
    if (message && message_size)
        snprintf(message, message_size, "%s", msg.text);
    return st;
}

void getme_gmsh_model_free(getme_gmsh_model *m)
{
    if (!m)
        return;
    free(m->entities);
    free(m->node_tags);
    free(m->coords0);
    free(m->fixed);
    free(m->elem_tags);
    free(m->blocks);
    getme_mesh_free(m->mesh);
    free(m);
}
