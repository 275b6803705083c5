/*
 * gmsh_apply.c -- write smoothed coordinates back into the Gmsh model.
 *
 * Only free nodes that actually moved are set, one gmshModelMeshSetNode()
 * each.  They are classified on the smoothed volume or planar surface
 * itself, so no parametric coordinate on a curve or curved surface goes
 * stale; an empty parametricCoord leaves Gmsh's stored one alone.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdio.h>
#include <string.h>

getme_status getme_gmsh_model_apply(const getme_gmsh_model *m,
                                    const double *coords, int32_t *num_moved,
                                    char *message, size_t message_size)
{
    gg_msg msg = {""};
    getme_status st = GETME_OK;
    int32_t moved = 0;
    if (!m || !coords)
        st = gg_fail(&msg, GETME_ERR_ARGUMENT, "model or coords is NULL");
    else if (!gg_gmsh_initialized())
        st = gg_fail(&msg, GETME_ERR_STATE, "Gmsh is not initialized");
    for (int32_t i = 0; st == GETME_OK && i < m->num_nodes; i++) {
        const double *p = coords + 3 * (size_t)i;
        /* fixed nodes never move; second-order mid-nodes are "fixed" in
           the mask (no linear element uses them) but move with their
           corners, so the test is whether the node moved */
        if (memcmp(p, m->coords0 + 3 * (size_t)i, 3 * sizeof *p) == 0)
            continue;
        double xyz[3];
        int ierr = 0;
        getme__frame_to_global(&m->frame, p, xyz);
        gmshModelMeshSetNode(m->node_tags[i], xyz, 3, NULL, 0, &ierr);
        if (ierr) {
            char err[256];
            gg_gmsh_last_error(err, sizeof err);
            st = gg_fail(&msg, GETME_ERR_STATE,
                         "Could not set node %zu: %s", m->node_tags[i], err);
        }
        moved++;
    }
    if (num_moved)
        *num_moved = moved;
    if (message && message_size)
        snprintf(message, message_size, "%s", msg.text);
    return st;
}
