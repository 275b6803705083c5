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

#include <omp.h>
#include <stdlib.h>
#include <string.h>

static int32_t region_of(const getme_mesh *mesh, int32_t e)
{
    int32_t local;
    const getme_block *b = getme__find_block(mesh, e, &local);
    return b->region ? b->region[local] : 0;
}

/* Per-thread scratch of the face search: for each neighbour of the element
   at hand, which of its nodes it shares (bit i = local node i). */
typedef struct face_scratch {
    uint32_t *stamp; /* ne: element last seen for this stamp value */
    uint8_t *shared; /* ne: shared-node mask                      */
    int32_t *list;   /* the neighbours of the current element      */
    uint32_t now;
} face_scratch;

/* Bit f of the result: face f of element e must be fixed.  One pass over
   the stars of e's nodes records, for every neighbour, which of e's nodes
   it has; a face is shared with a neighbour whose mask covers the face's
   nodes.  No face table, and only face neighbours need their region. */
static unsigned faces_to_fix(const getme_mesh *mesh, const int64_t *ptr,
                             const int32_t *star, const int32_t *conn,
                             int32_t e, int type, unsigned flags,
                             face_scratch *sc)
{
    const getme_face_table *ft = &getme__faces[type];
    int nv = getme__nv[type];
    uint32_t now = ++sc->now;
    int32_t count = 0;
    for (int i = 0; i < nv; i++)
        for (int64_t k = ptr[conn[i]]; k < ptr[conn[i] + 1]; k++) {
            int32_t n = star[k];
            if (n == e)
                continue;
            if (sc->stamp[n] != now) {
                sc->stamp[n] = now;
                sc->shared[n] = 0;
                sc->list[count++] = n;
            }
            sc->shared[n] |= (uint8_t)(1u << i);
        }
    unsigned face_mask[6], shared = 0, interface = 0;
    for (int f = 0; f < ft->num_faces; f++) {
        face_mask[f] = 0;
        for (int j = 0; j < ft->size[f]; j++)
            face_mask[f] |= 1u << ft->node[f][j];
    }
    int32_t my_region = -1;
    for (int32_t k = 0; k < count; k++) {
        unsigned m = sc->shared[sc->list[k]];
        if ((m & (m - 1)) == 0)
            continue; /* shares at most a node: no face (or 2-D edge) */
        for (int f = 0; f < ft->num_faces; f++) {
            if ((m & face_mask[f]) != face_mask[f])
                continue;
            shared |= 1u << f;
            if (flags & GETME_FIX_INTERFACES) {
                if (my_region == -1)
                    my_region = region_of(mesh, e);
                if (region_of(mesh, sc->list[k]) != my_region)
                    interface |= 1u << f;
            }
        }
    }
    unsigned all = (1u << ft->num_faces) - 1, bits = 0;
    if (flags & GETME_FIX_SKIN)
        bits |= all & ~shared;
    if (flags & GETME_FIX_INTERFACES)
        bits |= interface;
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
    int64_t max_star = 0;
    for (int32_t i = 0; i < nn; i++)
        if (ptr[i + 1] - ptr[i] > max_star)
            max_star = ptr[i + 1] - ptr[i];
    int nt = omp_get_max_threads();
    face_scratch *sc = calloc((size_t)nt, sizeof *sc);
    int ok = sc != NULL;
    for (int t = 0; ok && t < nt; t++) {
        sc[t].stamp = calloc((size_t)(ne ? ne : 1), sizeof *sc[t].stamp);
        sc[t].shared = malloc((size_t)(ne ? ne : 1));
        sc[t].list = malloc((size_t)(8 * max_star + 1) * sizeof *sc[t].list);
        ok = sc[t].stamp && sc[t].shared && sc[t].list;
    }
    if (ok) {
        for (int b = 0; b < mesh->num_blocks; b++) {
            const getme_block *bl = &mesh->blocks[b];
            int nv = getme__nv[bl->type];
#pragma omp parallel for schedule(dynamic, 4096) num_threads(nt)
            for (int32_t e = 0; e < bl->count; e++)
                mark[bl->first + e] = (uint8_t)faces_to_fix(
                    mesh, ptr, star, bl->conn + (int64_t)e * nv, bl->first + e,
                    bl->type, flags, &sc[omp_get_thread_num()]);
        }
    }
    for (int t = 0; sc && t < nt; t++) {
        free(sc[t].stamp);
        free(sc[t].shared);
        free(sc[t].list);
    }
    free(sc);
    if (!ok) {
        free(ptr), free(star), free(mark);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        const getme_face_table *ft = &getme__faces[bl->type];
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
