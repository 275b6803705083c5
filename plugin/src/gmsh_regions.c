/*
 * gmsh_regions.c -- region ids of the selected entities for
 * getme_mesh_fix_boundary(GETME_FIX_INTERFACES).
 *
 * The region of an entity is its set of physical groups: two volumes of
 * the same physical volume form one region (the face between them may be
 * smoothed across if its nodes are classified on the volumes), two volumes
 * of different materials meet at an interface whose nodes stay fixed.  An
 * entity in no physical group is a region of its own, the conservative
 * choice.  Region ids are the index of the first entity with that set.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdlib.h>
#include <string.h>

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

typedef struct phys_set {
    int *tags; /* gmsh-allocated, sorted */
    size_t n;
} phys_set;

static int same_set(const phys_set *a, const phys_set *b)
{
    return a->n == b->n && a->n > 0 &&
           memcmp(a->tags, b->tags, a->n * sizeof *a->tags) == 0;
}

getme_status gg_entity_regions(const int *pairs, int count, int32_t *regions,
                               gg_msg *msg)
{
    phys_set *sets = calloc(count ? (size_t)count : 1, sizeof *sets);
    if (!sets)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    for (int i = 0; i < count; i++) {
        int ierr = 0;
        gmshModelGetPhysicalGroupsForEntity(pairs[2 * i], pairs[2 * i + 1],
                                            &sets[i].tags, &sets[i].n, &ierr);
        if (ierr)
            sets[i].n = 0;
        if (sets[i].n > 1)
            qsort(sets[i].tags, sets[i].n, sizeof(int), cmp_int);
        regions[i] = i;
        for (int j = 0; j < i; j++)
            if (same_set(&sets[i], &sets[j])) {
                regions[i] = regions[j];
                break;
            }
    }
    for (int i = 0; i < count; i++)
        gmshFree(sets[i].tags);
    free(sets);
    return GETME_OK;
}
