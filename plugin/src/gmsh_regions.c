/*
 * gmsh_regions.c -- region ids of the selected entities for
 * getme_mesh_fix_boundary(GETME_FIX_INTERFACES).
 *
 * The region of an entity is its set of physical groups: two volumes of
 * the same physical volume form one region (the face between them may be
 * smoothed across if its nodes are classified on the volumes), two volumes
 * of different materials meet at an interface whose nodes stay fixed.  An
 * entity in no physical group is a region of its own, the conservative
 * choice.  Here: each entity's physical tags, from Gmsh; the model
 * builder (formats/model) turns them into region ids, as for a file read
 * natively.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdlib.h>

getme_status gg_entity_phys(const int *pairs, int count, int ***phys,
                            size_t **num_phys, gg_msg *msg)
{
    *phys = calloc(count ? (size_t)count : 1, sizeof **phys);
    *num_phys = calloc(count ? (size_t)count : 1, sizeof **num_phys);
    if (!*phys || !*num_phys)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    for (int i = 0; i < count; i++) {
        int ierr = 0;
        gmshModelGetPhysicalGroupsForEntity(pairs[2 * i], pairs[2 * i + 1],
                                            &(*phys)[i], &(*num_phys)[i],
                                            &ierr);
        if (ierr)
            (*num_phys)[i] = 0;
    }
    return GETME_OK;
}
