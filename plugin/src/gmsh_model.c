/*
 * gmsh_model.c -- read the current Gmsh model into a getme_mesh.
 *
 * One pass over the selected entities: their elements (per entity and
 * element type, as Gmsh stores them) become blocks of one getme_mesh, the
 * nodes they use become its nodes (in Gmsh's node order), and each element
 * keeps its Gmsh tag for messages.  Nothing in the model is modified here.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Everything Gmsh gave us about all nodes, plus our working arrays. */
typedef struct gg_read {
    size_t *gtags;     /* all nodes of the model (gmsh-allocated) */
    double *gcoords;
    size_t gn;
    gg_nodemap gmap;   /* tag -> index into gtags */
    uint8_t *used;     /* gn: used by a selected element */
    int32_t **conn;    /* per block: global, then local node indices */
    int cap_blocks;
    int32_t *entity_region;
} gg_read;

static void read_free(gg_read *r, int nb)
{
    gmshFree(r->gtags);
    gmshFree(r->gcoords);
    gg_nodemap_free(&r->gmap);
    free(r->used);
    for (int b = 0; r->conn && b < nb; b++)
        free(r->conn[b]);
    free(r->conn);
    free(r->entity_region);
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
    r->used = calloc(r->gn ? r->gn : 1, 1);
    if (!r->used)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    return gg_nodemap_build(&r->gmap, r->gtags, r->gn, msg);
}

static getme_status type_error(int dim, int tag, int gmsh_type, gg_msg *msg)
{
    char name[96];
    gg_gmsh_type_name(gmsh_type, name, sizeof name);
    int order = gg_gmsh_type_order(gmsh_type);
    if (order > 1)
        return gg_fail(msg, GETME_ERR_TOPOLOGY,
                       "%s %d has elements of order %d (%s): GETMe smooths "
                       "linear elements and second-order tetrahedra, "
                       "hexahedra and prisms (set the element order to 1 "
                       "or 2 first)",
                       gg_dim_Word(dim), tag, order, name);
    return gg_fail(msg, GETME_ERR_TOPOLOGY,
                   "%s %d has elements of a type GETMe cannot smooth (%s); "
                   "supported: %s",
                   gg_dim_Word(dim), tag, name,
                   dim == 3 ? "tetrahedra, hexahedra, prisms, pyramids"
                            : "triangles, quadrangles");
}

static getme_status grow_blocks(getme_gmsh_model *m, gg_read *r, gg_msg *msg)
{
    if (m->num_blocks < r->cap_blocks)
        return GETME_OK;
    int cap = r->cap_blocks ? 2 * r->cap_blocks : 8;
    gg_block *nb = realloc(m->blocks, (size_t)cap * sizeof *nb);
    if (nb)
        m->blocks = nb;
    int32_t **nc = realloc(r->conn, (size_t)cap * sizeof *nc);
    if (nc)
        r->conn = nc;
    if (!nb || !nc)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    r->cap_blocks = cap;
    return GETME_OK;
}

/* Append one (entity, type) block: Gmsh node tags -> global indices. */
static getme_status add_block(getme_gmsh_model *m, gg_read *r, int dim,
                              int tag, int gmsh_type, const size_t *etags,
                              size_t ne, const size_t *ntags, gg_msg *msg)
{
    int ho = dim == 3 ? gg_ho_type(gmsh_type) : -1;
    int type = ho >= 0 ? getme_ho_type_linear((getme_ho_type)ho)
                       : gg_getme_type(gmsh_type);
    if (type < 0 || getme_type_dim((getme_elem_type)type) != dim)
        return type_error(dim, tag, gmsh_type, msg);
    if (ne > (size_t)(INT32_MAX - m->num_elements))
        return gg_fail(msg, GETME_ERR_ARGUMENT,
                       "More than 2^31-1 elements are not supported");
    getme_status st = grow_blocks(m, r, msg);
    if (st != GETME_OK)
        return st;
    int nv = ho >= 0 ? getme_ho_type_num_nodes((getme_ho_type)ho)
                     : getme_type_num_nodes((getme_elem_type)type);
    int32_t *conn = malloc((ne ? ne : 1) * (size_t)nv * sizeof *conn);
    size_t *et = realloc(m->elem_tags,
                         ((size_t)m->num_elements + ne) * sizeof *et);
    if (et)
        m->elem_tags = et;
    if (!conn || !et) {
        free(conn);
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    }
    for (size_t i = 0; i < ne * (size_t)nv; i++) {
        int32_t g = gg_nodemap_find(&r->gmap, ntags[i]);
        if (g < 0) {
            free(conn);
            return gg_fail(msg, GETME_ERR_TOPOLOGY,
                           "Element %zu of %s %d uses node %zu, which does "
                           "not exist",
                           etags[i / (size_t)nv], gg_dim_word(dim), tag,
                           ntags[i]);
        }
        conn[i] = g;
        r->used[g] = 1;
    }
    memcpy(m->elem_tags + m->num_elements, etags, ne * sizeof *etags);
    gg_block *b = &m->blocks[m->num_blocks];
    b->gmsh_type = gmsh_type;
    b->type = type;
    b->ho = ho;
    b->nv = nv;
    b->dim = dim;
    b->tag = tag;
    b->first = m->num_elements;
    b->count = (int32_t)ne;
    r->conn[m->num_blocks++] = conn;
    m->num_elements += (int32_t)ne;
    return GETME_OK;
}

static getme_status read_entity(getme_gmsh_model *m, gg_read *r, int dim,
                                int tag, gg_msg *msg)
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
            st = add_block(m, r, dim, tag, types[t], etags[t], etags_n[t],
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

/* Number the used nodes 0.. in Gmsh's order; rewrite block connectivity. */
static getme_status compact_nodes(getme_gmsh_model *m, gg_read *r,
                                  gg_msg *msg)
{
    int32_t *loc = malloc((r->gn ? r->gn : 1) * sizeof *loc);
    if (!loc)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    int32_t n = 0;
    for (size_t g = 0; g < r->gn; g++)
        loc[g] = r->used[g] ? n++ : -1;
    m->num_nodes = n;
    m->node_tags = malloc((n ? (size_t)n : 1) * sizeof *m->node_tags);
    m->coords0 = malloc((n ? (size_t)n : 1) * 3 * sizeof *m->coords0);
    m->fixed = calloc(n ? (size_t)n : 1, 1);
    if (!m->node_tags || !m->coords0 || !m->fixed) {
        free(loc);
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    }
    for (size_t g = 0; g < r->gn; g++)
        if (loc[g] >= 0) {
            m->node_tags[loc[g]] = r->gtags[g];
            memcpy(m->coords0 + 3 * (size_t)loc[g], r->gcoords + 3 * g,
                   3 * sizeof(double));
        }
    for (int b = 0; b < m->num_blocks; b++) {
        size_t len = (size_t)m->blocks[b].count * (size_t)m->blocks[b].nv;
        for (size_t i = 0; i < len; i++)
            r->conn[b][i] = loc[r->conn[b][i]];
    }
    free(loc);
    return GETME_OK;
}

static int entity_index(const getme_gmsh_model *m, int tag)
{
    for (int e = 0; e < m->num_entities; e++)
        if (m->entities[2 * e + 1] == tag)
            return e;
    return 0;
}

/* First element of a block that has a node twice, -1 if none. */
static int32_t repeated_node(const int32_t *conn, int32_t count, int nv)
{
    for (int32_t e = 0; e < count; e++)
        for (int i = 1; i < nv; i++)
            for (int j = 0; j < i; j++)
                if (conn[(size_t)e * nv + i] == conn[(size_t)e * nv + j])
                    return e;
    return -1;
}

static getme_status build_mesh(getme_gmsh_model *m, gg_read *r, gg_msg *msg)
{
    getme_status st = getme_mesh_create(&m->mesh, m->dim, m->num_nodes,
                                        m->coords0);
    if (st != GETME_OK)
        return gg_fail(msg, st, "Could not create the mesh: %s",
                       getme_status_string(st));
    for (int b = 0; b < m->num_blocks && st == GETME_OK; b++) {
        const gg_block *blk = &m->blocks[b];
        int32_t *region = malloc((blk->count ? (size_t)blk->count : 1) *
                                 sizeof *region);
        if (!region)
            return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
        int32_t id = r->entity_region[entity_index(m, blk->tag)];
        for (int32_t i = 0; i < blk->count; i++)
            region[i] = id;
        int32_t bad = repeated_node(r->conn[b], blk->count, blk->nv);
        if (bad >= 0) {
            free(region);
            return gg_fail(msg, GETME_ERR_INVALID_MESH,
                           "element %zu is degenerate: a node appears twice "
                           "in it; getme smooths valid meshes only",
                           m->elem_tags[blk->first + bad]);
        }
        st = blk->ho >= 0
                 ? getme_mesh_add_elements_ho(m->mesh, (getme_ho_type)blk->ho,
                                              blk->count, r->conn[b], region)
                 : getme_mesh_add_elements(m->mesh, (getme_elem_type)blk->type,
                                           blk->count, r->conn[b], region);
        free(region);
        if (st != GETME_OK)
            gg_fail(msg, st, "%s", getme_mesh_error(m->mesh));
    }
    return st;
}

static getme_status mark_fixed(getme_gmsh_model *m,
                               const getme_gmsh_options *opt, gg_msg *msg)
{
    gg_nodemap local;
    getme_status st = gg_nodemap_build(&local, m->node_tags,
                                       (size_t)m->num_nodes, msg);
    if (st == GETME_OK)
        st = gg_fix_classified(m, &local, m->fixed, msg);
    if (st == GETME_OK)
        st = gg_fix_groups(opt, &local, m->fixed, msg);
    gg_nodemap_free(&local);
    if (st != GETME_OK)
        return st;
    unsigned flags = (opt->fix_skin ? GETME_FIX_SKIN : 0u) |
                     (opt->fix_interfaces ? GETME_FIX_INTERFACES : 0u);
    st = getme_mesh_set_fixed_mask(m->mesh, m->fixed);
    if (st == GETME_OK && flags)
        st = getme_mesh_fix_boundary(m->mesh, flags, NULL);
    if (st == GETME_OK)
        st = getme_mesh_get_fixed_mask(m->mesh, m->fixed);
    if (st != GETME_OK)
        return gg_fail(msg, st, "%s", getme_mesh_error(m->mesh));
    return GETME_OK;
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
        st = read_entity(m, r, m->dim, m->entities[2 * e + 1], msg);
    if (st == GETME_OK)
        st = compact_nodes(m, r, msg);
    if (st == GETME_OK && m->dim == 2)
        st = gg_planar_prepare(&m->frame, m->coords0, m->num_nodes,
                               m->blocks, m->num_blocks, r->conn, msg);
    if (st == GETME_OK) {
        r->entity_region = malloc((size_t)m->num_entities *
                                  sizeof *r->entity_region);
        st = r->entity_region
                 ? gg_entity_regions(m->entities, m->num_entities,
                                     r->entity_region, msg)
                 : gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    }
    if (st == GETME_OK)
        st = build_mesh(m, r, msg);
    if (st == GETME_OK)
        st = mark_fixed(m, opt, msg);
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
        read_free(&r, m->num_blocks);
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
