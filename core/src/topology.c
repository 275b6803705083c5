/*
 * topology.c -- which nodes are fixed by default (docs/design.md §5): nodes on
 * the skin (faces of volume elements, edges of planar elements, with one
 * incident element) and on interfaces between regions; nodes used by no
 * element.
 *
 * Faces are matched by getme__ws_faces (faces.c) on the smoother's
 * workspace: Morton-ordered, so a 1M-tet mesh is done in a fraction of a
 * second where the earlier walk in the caller's order took 4.4 s.  The
 * workspace and the face table are then kept on the mesh (getme__ws_keep),
 * and getme_smooth() takes both over instead of building them again.
 */
#include "facenb.h"
#include "workspace.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

static int32_t region_of(const getme_mesh *mesh, int32_t e)
{
    int32_t local;
    const getme_block *b = getme__find_block(mesh, e, &local);
    return b->region ? b->region[local] : b->region_all;
}

/* Do all elements lie in one region?  Then no face is an interface, and
   the per-face region lookups (two cache misses each, through the
   caller's order) can be skipped; one streaming pass decides. */
static int one_region(const getme_mesh *mesh)
{
    int32_t r0 = mesh->num_elements ? region_of(mesh, 0) : 0;
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        for (int32_t e = 0; e < bl->count; e++)
            if ((bl->region ? bl->region[e] : bl->region_all) != r0)
                return 0;
    }
    return 1;
}

/* Must face f of workspace element e be fixed, given the element across
   it (fnb)?  0, or the GETME__FIXED_* reason.  A face shared by three or
   more elements is fixed too: it is no skin, but such a mesh is not a
   manifold there and moving its nodes has no clear meaning.  regions: 0
   when one_region() holds, so no face is an interface. */
static int face_fixed(const getme_mesh *mesh, const getme_ws *ws, int32_t e,
                      int32_t nb, unsigned flags, int regions)
{
    if (nb == -1)
        return flags & GETME_FIX_SKIN ? GETME__FIXED_SKIN : 0;
    if (nb == GETME_FACE_IRREGULAR)
        return flags & (GETME_FIX_SKIN | GETME_FIX_INTERFACES)
                   ? GETME__FIXED_SKIN : 0;
    return regions &&
                   region_of(mesh, ws->elem_orig[e]) !=
                       region_of(mesh, ws->elem_orig[nb])
               ? GETME__FIXED_INTERFACE : 0;
}

getme_status getme_mesh_fix_boundary(getme_mesh *mesh, unsigned flags,
                                     int32_t *num_fixed)
{
    if (!mesh)
        return GETME_ERR_ARGUMENT;
    /* The smoother's workspace gives the node stars in a cache-friendly
       order, and the face search works on it (faces.c). */
    getme_ws ws;
    if (getme__ws_build(&ws, mesh, 1, omp_get_max_threads()) != GETME_OK)
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    int64_t foff[GETME_NUM_TYPES];
    int64_t total = getme__ws_face_offsets(&ws, foff);
    /* Packed at once (facenb.h), in place: this reads it packed, and the
       smoother takes it over.  A cached workspace has it already. */
    if (!ws.faces.d) {
        int32_t *table =
            getme__malloc((size_t)(total ? total : 1) * sizeof *table);
        getme_status st = GETME_ERR_NOMEM;
        if (!table || (st = getme__ws_faces(&ws, foff, table)) != GETME_OK)
            free(table);
        else /* takes table, also on failure */
            st = getme__facenb_pack(&ws.faces, &ws, foff, table);
        if (st != GETME_OK) {
            getme__ws_free(&ws);
            return getme__fail(mesh, st, "out of memory");
        }
    }
    const getme_facenb *fnb = &ws.faces;
    int regions = (flags & GETME_FIX_INTERFACES) && !one_region(mesh);
    /* Which elements have a face to fix: a read-only scan of the whole
       face table, in parallel; the marking below (its writes to shared
       nodes serial) then visits only those, the few on the skin and the
       interfaces. */
    uint8_t *touch = getme__malloc((size_t)(ws.ne ? ws.ne : 1));
    if (!touch) {
        getme__ws_free(&ws);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nf = getme__faces[t].num_faces;
#pragma omp parallel for schedule(static) num_threads(ws.nt)
        for (int32_t e = ws.tstart[t]; e < ws.tstart[t + 1]; e++) {
            int32_t f[6];
            getme__facenb_elem(fnb, &ws, foff, t, e, f);
            int any = 0;
            for (int k = 0; k < nf; k++)
                any |= face_fixed(mesh, &ws, e, f[k], flags, regions) != 0;
            touch[e] = (uint8_t)any;
        }
    }
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        const getme_face_table *ft = &getme__faces[t];
        for (int32_t e = ws.tstart[t]; e < ws.tstart[t + 1]; e++) {
            if (!touch[e])
                continue;
            const int32_t *c = getme__ws_nodes(&ws, t, e);
            int32_t f[6];
            getme__facenb_elem(fnb, &ws, foff, t, e, f);
            for (int k = 0; k < ft->num_faces; k++) {
                int why = face_fixed(mesh, &ws, e, f[k], flags, regions);
                for (int j = 0; why && j < ft->size[k]; j++)
                    mesh->fixed[ws.node_orig[c[ft->node[k][j]]]] |= (uint8_t)why;
            }
        }
    }
    free(touch);
    for (int32_t i = 0; i < ws.nn; i++)
        if (ws.star_ptr[i + 1] == ws.star_ptr[i])
            mesh->fixed[ws.node_orig[i]] |= GETME__FIXED_UNUSED;
    /* The smoother will need the same workspace and face table. */
    getme__ws_keep(&ws, mesh);
    if (num_fixed)
        *num_fixed = getme_mesh_num_fixed(mesh);
    return GETME_OK;
}
