/*
 * model_build.c -- entities, nodes and elements of a Gmsh model -> the core
 * mesh (see model.h for the rules).  The native MSH reader and the Gmsh-SDK
 * path both feed it, so one file gives the core the same input by either
 * path, and smoothing gives bit-identical results.
 */
#include "model.h"
#include "getme_alloc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static getme_status oom(getme__model_out *out)
{
    snprintf(out->msg, sizeof out->msg, "Out of memory");
    return GETME_ERR_NOMEM;
}

getme_status getme__model_type_error(int dim, int tag, int msh_type,
                                     char *msg, size_t size)
{
    char name[64];
    int order = 0;
    getme__msh_type_nodes(msh_type, &order);
    getme__msh_type_name(msh_type, name, sizeof name);
    if (order > 1)
        snprintf(msg, size,
                 "%s %d has elements of order %d (%s): GETMe smooths "
                 "linear and second-order elements (set the element order "
                 "to 1 or 2 first)",
                 getme__dim_word(dim, 1), tag, order, name);
    else
        snprintf(msg, size,
                 "%s %d has elements of a type GETMe cannot smooth (%s); "
                 "supported: %s",
                 getme__dim_word(dim, 1), tag, name,
                 dim == 3 ? "tetrahedra, hexahedra, prisms, pyramids"
                          : "triangles, quadrangles");
    return GETME_ERR_TOPOLOGY;
}

static size_t block_len(const getme__model_block *b)
{
    return (size_t)b->count * (size_t)getme__msh_type_nodes(b->type, NULL);
}

/* ---- step 1: numbering -------------------------------------------------- */

static getme_status check_blocks(const getme__model_in *in,
                                 getme__model_out *out)
{
    int64_t total = 0;
    for (size_t b = 0; b < in->num_blocks; b++) {
        const getme__model_block *blk = &in->blocks[b];
        int type = getme__msh_type_corners(blk->type, in->dim);
        if (!blk->conn || type < 0 ||
            getme_type_dim((getme_elem_type)type) != in->dim)
            return getme__model_type_error(in->dim, blk->tag, blk->type,
                                           out->msg, sizeof out->msg);
        total += blk->count;
    }
    if (total > INT32_MAX) {
        snprintf(out->msg, sizeof out->msg,
                 "More than 2^31-1 elements are not supported");
        return GETME_ERR_ARGUMENT;
    }
    out->num_elements = (int32_t)total;
    return GETME_OK;
}

/* Does the numbering below keep every caller's node in place (mesh node
   k = caller's node k)?  When all n nodes are used and the ranges are
   [0, num_nodes) in order: a Gmsh volume mesh's file, typically. */
static int in_place(const getme__model_in *in, int32_t n)
{
    if ((size_t)n != in->num_nodes)
        return 0;
    size_t at = 0;
    for (size_t r = 0; r < in->num_ranges; r++) {
        if (in->ranges[r].first != at)
            return 0;
        at += in->ranges[r].count;
    }
    return at == in->num_nodes;
}

getme_status getme__model_number(getme__model_in *in, getme__model_out *out)
{
    memset(out, 0, sizeof *out);
    getme_status st = check_blocks(in, out);
    if (st != GETME_OK)
        return st;
    for (size_t b = 0; b < in->num_blocks; b++) {
        size_t len = block_len(&in->blocks[b]);
        for (size_t i = 0; i < len; i++)
            in->flags[in->blocks[b].conn[i]] |= GETME__NODE_USED;
    }
    int32_t n = 0;
    for (size_t i = 0; i < in->num_nodes; i++)
        n += (in->flags[i] & GETME__NODE_USED) != 0;
    out->num_nodes = n;
    out->loc =
        getme__malloc((in->num_nodes ? in->num_nodes : 1) * sizeof *out->loc);
    if (in->xyz_give && in_place(in, n)) { /* no copy */
        out->xyz = in->xyz_give;
        in->xyz_give = NULL;
    } else {
        out->xyz = getme__malloc((n ? (size_t)n : 1) * 3 * sizeof *out->xyz);
    }
    out->fixed = getme__malloc(n ? (size_t)n : 1);
    if (!out->loc || !out->xyz || !out->fixed)
        return oom(out);
    /* Gmsh's node order: the ranges in turn, each in the caller's order. */
    int32_t k = 0;
    for (size_t r = 0; r < in->num_ranges; r++) {
        const getme__node_range *nr = &in->ranges[r];
        for (size_t i = nr->first; i < nr->first + nr->count; i++) {
            out->loc[i] = -1;
            uint8_t f = in->flags[i];
            if (!(f & GETME__NODE_USED))
                continue;
            if (out->xyz != in->xyz) /* else k == i: in place */
                memcpy(out->xyz + 3 * (size_t)k, in->xyz + 3 * i,
                       3 * sizeof *out->xyz);
            out->fixed[k] = !(f & GETME__NODE_OWN) || (f & GETME__NODE_FIXGRP);
            out->loc[i] = k++;
        }
    }
    /* file indices -> mesh nodes: independent entries, in parallel */
    for (size_t b = 0; b < in->num_blocks; b++) {
        size_t len = block_len(&in->blocks[b]);
        int32_t *c = in->blocks[b].conn;
        const int32_t *loc = out->loc;
#pragma omp parallel for schedule(static) if (len >= 65536)
        for (size_t i = 0; i < len; i++)
            c[i] = loc[c[i]];
    }
    return GETME_OK;
}

/* ---- step 2: the mesh --------------------------------------------------- */

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Region id per entity: the index of the first entity with the same
   non-empty sorted set of physical tags.  Faces between regions are fixed
   (GETME_FIX_INTERFACES), in addition to the nodes classified on lower
   dimensions.  With regions_by_entity every entity is its own region: an
   MSH 2.2 file has no node classification of its own (a node is put on
   the lowest entity among its elements), so when only volumes were saved
   the surfaces between two volumes of one physical group have no
   elements and their nodes would move, off the CAD's internal faces (an
   embedded sphere's surface moved by 1.27 in a measured case); MSH 4.1
   and INP keep them. */
static void entity_regions(const getme__model_in *in, int32_t *region)
{
    for (size_t i = 0; i < in->num_entities; i++) {
        size_t ni = in->num_phys[i];
        if (ni > 1)
            qsort(in->phys[i], ni, sizeof(int), cmp_int);
        region[i] = (int32_t)i;
        for (size_t j = 0; ni && !in->regions_by_entity && j < i; j++)
            if (in->num_phys[j] == ni &&
                memcmp(in->phys[j], in->phys[i], ni * sizeof(int)) == 0) {
                region[i] = region[j];
                break;
            }
    }
}

/* First element of a block that has a node twice, -1 if none: the least
   of the threads' first ones, so the same for any thread count. */
static int32_t repeated_node(const int32_t *conn, int32_t count, int nv)
{
    int32_t first = count;
#pragma omp parallel for schedule(static) reduction(min : first) \
    if (count >= 16384)
    for (int32_t e = 0; e < count; e++) {
        int rep = 0;
        for (int i = 1; i < nv; i++)
            for (int j = 0; j < i; j++)
                rep |= conn[(size_t)e * nv + i] == conn[(size_t)e * nv + j];
        if (rep && e < first)
            first = e;
    }
    return first < count ? first : -1;
}

static void free_block(getme__model_block *b)
{
    free(b->conn);
    free(b->ids);
    b->conn = NULL;
    b->ids = NULL;
}

static getme_status mesh_error(getme__model_out *out, getme_status st)
{
    snprintf(out->msg, sizeof out->msg, "%s", getme_mesh_error(out->mesh));
    return st;
}

/* Blocks [b0, b1) of one (entity, type) become one element block. */
static getme_status add_run(getme__model_in *in, getme__model_out *out,
                            size_t b0, size_t b1, int32_t region_id,
                            int32_t *first)
{
    getme__model_block *b = &in->blocks[b0];
    int nv = getme__msh_type_nodes(b->type, NULL);
    size_t count = 0, len = 0;
    for (size_t i = b0; i < b1; i++) {
        count += (size_t)in->blocks[i].count;
        len += block_len(&in->blocks[i]);
    }
    int32_t *conn = b1 - b0 == 1 ? b->conn
                                 : getme__malloc((len ? len : 1) * sizeof *conn);
    int32_t *region = getme__malloc((count ? count : 1) * sizeof *region);
    getme_status st = conn && region ? GETME_OK : oom(out);
    for (size_t i = b0, at = 0; st == GETME_OK && i < b1; i++) {
        const getme__model_block *bi = &in->blocks[i];
        /* the renumbering maps distinct caller's nodes to distinct mesh
           nodes, so the caller's check still holds */
        int32_t bad =
            in->nodes_distinct ? -1 : repeated_node(bi->conn, bi->count, nv);
        if (bad >= 0) {
            snprintf(out->msg, sizeof out->msg,
                     "element %lld is degenerate: a node appears twice in "
                     "it; getme smooths valid meshes only",
                     (long long)bi->ids[bad]);
            st = GETME_ERR_INVALID_MESH;
            break;
        }
        if (conn != b->conn)
            memcpy(conn + at, bi->conn, block_len(bi) * sizeof *conn);
        at += block_len(bi);
        if (bi->ids) /* else add_blocks took them: in place already */
            memcpy(out->elem_ids + *first, bi->ids,
                   (size_t)bi->count * sizeof *out->elem_ids);
        *first += bi->count;
    }
    for (size_t i = 0; st == GETME_OK && i < count; i++)
        region[i] = region_id;
    if (st == GETME_OK) {
        int ho = getme__msh_type_ho(b->type, in->dim);
        getme_status gs =
            ho >= 0 ? getme_mesh_add_elements_ho(out->mesh, (getme_ho_type)ho,
                                                 (int32_t)count, conn, region)
                    : getme_mesh_take_elements(
                          out->mesh,
                          (getme_elem_type)getme__msh_type_getme(b->type),
                          (int32_t)count, conn, region);
        /* the mesh took (or freed) conn: no copy of the largest array */
        if (ho < 0) {
            if (conn == b->conn)
                b->conn = NULL;
            conn = NULL;
        }
        if (gs != GETME_OK)
            st = mesh_error(out, gs);
    }
    if (conn != b->conn)
        free(conn);
    free(region);
    for (size_t i = b0; i < b1; i++) /* free as we go: lower peak memory */
        free_block(&in->blocks[i]);
    return st;
}

static getme_status add_blocks(getme__model_in *in, getme__model_out *out)
{
    int32_t *region = getme__malloc((in->num_entities ? in->num_entities : 1) *
                                    sizeof *region);
    /* One block of every element (a Gmsh volume mesh's file): its ids
       are the mesh's, taken instead of copied (8 B per element). */
    if (in->num_blocks == 1 && in->blocks[0].ids &&
        (size_t)in->blocks[0].count == (size_t)out->num_elements) {
        out->elem_ids = in->blocks[0].ids;
        in->blocks[0].ids = NULL;
    } else {
        out->elem_ids = getme__malloc(
            (out->num_elements ? (size_t)out->num_elements : 1) *
            sizeof *out->elem_ids);
    }
    getme_status st = region && out->elem_ids ? GETME_OK : oom(out);
    if (st == GETME_OK)
        entity_regions(in, region);
    int32_t first = 0;
    size_t e = 0;
    for (size_t b0 = 0; st == GETME_OK && b0 < in->num_blocks;) {
        size_t b1 = b0 + 1;
        while (b1 < in->num_blocks &&
               in->blocks[b1].tag == in->blocks[b0].tag &&
               in->blocks[b1].type == in->blocks[b0].type)
            b1++;
        if (b0 > 0 && in->blocks[b0].tag != in->blocks[b0 - 1].tag)
            e++;
        st = add_run(in, out, b0, b1, region[e < in->num_entities ? e : 0],
                     &first);
        b0 = b1;
    }
    free(region);
    return st;
}

static getme_status mark_fixed(const getme__model_in *in,
                               getme__model_out *out)
{
    getme_status st = getme_mesh_set_fixed_mask(out->mesh, out->fixed);
    if (!in->keep_copies) { /* the mesh's now */
        free(out->fixed);
        out->fixed = NULL;
    }
    if (st == GETME_OK && in->fix_flags)
        st = getme_mesh_fix_boundary(out->mesh, in->fix_flags, NULL);
    return st == GETME_OK ? GETME_OK : mesh_error(out, st);
}

getme_status getme__model_finish(getme__model_in *in, getme__model_out *out)
{
    getme_status st = GETME_OK;
    if (in->dim == 2 && in->z_plane_only &&
        !getme__all_same_z(out->xyz, out->num_nodes)) {
        out->declined = 1;
        return GETME_OK;
    }
    if (in->dim == 2)
        st = getme__planar_prepare(&out->frame, out->xyz, out->num_nodes,
                                   in->blocks, in->num_blocks, out->msg,
                                   sizeof out->msg);
    if (st == GETME_OK) {
        /* Unless the caller keeps ours, the mesh takes it: no copy, and
           ours never coexists with the elements and the boundary search
           (24 B per node less at the reading's peak). */
        if (in->keep_copies) {
            st = getme_mesh_create(&out->mesh, in->dim, out->num_nodes,
                                   out->xyz);
        } else {
            st = getme_mesh_create_take(&out->mesh, in->dim, out->num_nodes,
                                        out->xyz);
            out->xyz = NULL; /* the mesh's, or freed */
        }
        if (st != GETME_OK)
            snprintf(out->msg, sizeof out->msg,
                     "Could not create the mesh: %s", getme_status_string(st));
    }
    if (!in->keep_copies) { /* also when the planar frame failed */
        free(out->xyz);
        out->xyz = NULL;
    }
    if (st == GETME_OK)
        st = add_blocks(in, out);
    if (st == GETME_OK)
        st = mark_fixed(in, out);
    return st;
}

void getme__model_out_free(getme__model_out *out)
{
    void *owned[] = {out->loc, out->xyz, out->fixed, out->elem_ids};
    for (size_t i = 0; i < sizeof owned / sizeof *owned; i++)
        free(owned[i]);
    getme_mesh_free(out->mesh);
    memset(out, 0, sizeof *out);
}
