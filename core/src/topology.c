/*
 * topology.c -- which nodes are fixed by default (DESIGN.md §5): nodes on
 * the skin (faces of volume elements, edges of planar elements, with one
 * incident element) and on interfaces between regions; nodes used by no
 * element.
 *
 * A face is matched by looking for another element that contains all its
 * nodes among the elements around its first node, so no face table is
 * built: memory stays at one node->element CSR.
 */
#include "internal.h"

#include <stdlib.h>
#include <string.h>

/* Faces (volume types) / edges (planar types) as local node lists. */
typedef struct face_table {
    int num_faces;
    int size[6];
    int8_t node[6][4];
} face_table;

static const face_table FACES[GETME_NUM_TYPES] = {
    /* tet */ {4, {3, 3, 3, 3}, {{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {0, 2, 3}}},
    /* hex */ {6, {4, 4, 4, 4, 4, 4},
               {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4},
                {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}},
    /* prism */ {5, {3, 3, 4, 4, 4},
                 {{0, 1, 2}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}}},
    /* pyramid */ {5, {4, 3, 3, 3, 3},
                   {{0, 1, 2, 3}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}},
    /* tri */ {3, {2, 2, 2}, {{0, 1}, {1, 2}, {2, 0}}},
    /* quad */ {4, {2, 2, 2, 2}, {{0, 1}, {1, 2}, {2, 3}, {3, 0}}},
};

typedef struct elem_ref {
    const int32_t *conn;
    int nv;
    int32_t region;
} elem_ref;

static elem_ref element(const getme_mesh *mesh, int32_t e)
{
    int32_t local;
    const getme_block *b = getme__find_block(mesh, e, &local);
    elem_ref r;
    r.nv = getme__nv[b->type];
    r.conn = b->conn + (int64_t)local * r.nv;
    r.region = b->region ? b->region[local] : 0;
    return r;
}

static int contains(const elem_ref *r, int32_t node)
{
    for (int i = 0; i < r->nv; i++)
        if (r->conn[i] == node)
            return 1;
    return 0;
}

/* Bit f of the result: face f of element e must be fixed. */
static unsigned faces_to_fix(const getme_mesh *mesh, const int64_t *ptr,
                             const int32_t *star, int32_t e, int type,
                             unsigned flags)
{
    const face_table *ft = &FACES[type];
    elem_ref me = element(mesh, e);
    unsigned bits = 0;
    for (int f = 0; f < ft->num_faces; f++) {
        int32_t n0 = me.conn[ft->node[f][0]];
        int shared = 0, interface = 0;
        for (int64_t k = ptr[n0]; k < ptr[n0 + 1]; k++) {
            if (star[k] == e)
                continue;
            elem_ref other = element(mesh, star[k]);
            int all = 1;
            for (int j = 1; j < ft->size[f] && all; j++)
                all = contains(&other, me.conn[ft->node[f][j]]);
            if (all) {
                shared = 1;
                interface |= other.region != me.region;
            }
        }
        if (((flags & GETME_FIX_SKIN) && !shared) ||
            ((flags & GETME_FIX_INTERFACES) && interface))
            bits |= 1u << f;
    }
    return bits;
}

getme_status getme_mesh_fix_boundary(getme_mesh *mesh, unsigned flags,
                                     int32_t *num_fixed)
{
    if (!mesh)
        return GETME_ERR_ARGUMENT;
    int32_t nn = mesh->num_nodes, ne = mesh->num_elements;
    int64_t *ptr = calloc((size_t)nn + 1, sizeof *ptr);
    int64_t corners = 0;
    for (int b = 0; b < mesh->num_blocks; b++)
        corners += (int64_t)mesh->blocks[b].count * getme__nv[mesh->blocks[b].type];
    int32_t *star = malloc((size_t)(corners ? corners : 1) * sizeof *star);
    uint8_t *mark = malloc((size_t)(ne ? ne : 1));
    if (!ptr || !star || !mark) {
        free(ptr), free(star), free(mark);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        int64_t n = (int64_t)bl->count * getme__nv[bl->type];
        for (int64_t k = 0; k < n; k++)
            ptr[bl->conn[k] + 1]++;
    }
    for (int32_t i = 0; i < nn; i++)
        ptr[i + 1] += ptr[i];
    int64_t *pos = malloc((size_t)(nn ? nn : 1) * sizeof *pos);
    if (!pos) {
        free(ptr), free(star), free(mark);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    memcpy(pos, ptr, (size_t)nn * sizeof *pos);
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        int nv = getme__nv[bl->type];
        for (int32_t e = 0; e < bl->count; e++)
            for (int i = 0; i < nv; i++)
                star[pos[bl->conn[(int64_t)e * nv + i]]++] = bl->first + e;
    }
    free(pos);

    /* Find faces in parallel (each element writes its own mark), fix their
       nodes serially (many elements share a node). */
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
#pragma omp parallel for schedule(dynamic, 4096)
        for (int32_t e = 0; e < bl->count; e++)
            mark[bl->first + e] = (uint8_t)faces_to_fix(
                mesh, ptr, star, bl->first + e, bl->type, flags);
    }
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        const face_table *ft = &FACES[bl->type];
        int nv = getme__nv[bl->type];
        for (int32_t e = 0; e < bl->count; e++) {
            unsigned bits = mark[bl->first + e];
            for (int f = 0; bits && f < ft->num_faces; f++)
                if (bits & (1u << f))
                    for (int j = 0; j < ft->size[f]; j++)
                        mesh->fixed[bl->conn[(int64_t)e * nv + ft->node[f][j]]] = 1;
        }
    }
    for (int32_t i = 0; i < nn; i++)
        if (ptr[i + 1] == ptr[i])
            mesh->fixed[i] = 1; /* used by no element */
    free(ptr), free(star), free(mark);
    if (num_fixed)
        *num_fixed = getme_mesh_num_fixed(mesh);
    return GETME_OK;
}
