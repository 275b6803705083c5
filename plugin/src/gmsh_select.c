/*
 * gmsh_select.c -- which entities of the current Gmsh model are smoothed.
 *
 * Mirrors gmshModelMeshOptimize's dimTags argument: empty means every
 * entity of the highest dimension that carries mesh elements; explicit
 * entities must exist, share one dimension (3, or 2 for planar surfaces)
 * and have elements.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdlib.h>

static int count_element_types(int dim, int tag)
{
    int *types = NULL, ierr = 0;
    size_t n = 0;
    gmshModelMeshGetElementTypes(&types, &n, dim, tag, &ierr);
    gmshFree(types);
    return ierr ? 0 : (int)n;
}

static getme_status auto_select(int **pairs, int *count, int *dim, gg_msg *msg)
{
    int d = 3;
    while (d >= 2 && count_element_types(d, -1) == 0)
        d--;
    if (d < 2)
        return gg_fail(msg, GETME_ERR_STATE,
                       "No volume or surface mesh in the current model: "
                       "generate the mesh or open a mesh file first");
    int *ents = NULL, ierr = 0;
    size_t n = 0;
    gmshModelGetEntities(&ents, &n, d, &ierr);
    int *out = malloc((n ? n : 1) * sizeof *out);
    if (ierr || !out) {
        gmshFree(ents);
        free(out);
        return gg_fail(msg, GETME_ERR_NOMEM, "Could not list the %ss",
                       gg_dim_word(d));
    }
    int k = 0;
    for (size_t i = 0; i + 1 < n; i += 2)
        if (count_element_types(d, ents[i + 1]) > 0) {
            out[2 * k] = d;
            out[2 * k + 1] = ents[i + 1];
            k++;
        }
    gmshFree(ents);
    *pairs = out;
    *count = k;
    *dim = d;
    return GETME_OK;
}

static int entity_exists(const int *ents, size_t n, int tag)
{
    for (size_t i = 0; i + 1 < n; i += 2)
        if (ents[i + 1] == tag)
            return 1;
    return 0;
}

static int already_listed(const int *out, int k, int tag)
{
    for (int i = 0; i < k; i++)
        if (out[2 * i + 1] == tag)
            return 1;
    return 0;
}

static getme_status check_dims(const int *dim_tags, size_t n, gg_msg *msg)
{
    if (n % 2)
        return gg_fail(msg, GETME_ERR_ARGUMENT,
                       "dimTags must hold (dim, tag) pairs, got %zu numbers",
                       n);
    for (size_t i = 0; i < n; i += 2) {
        int d = dim_tags[i];
        if (d != 2 && d != 3)
            return gg_fail(msg, GETME_ERR_ARGUMENT,
                           "Entity (%d, %d): only volumes (dim 3) and planar "
                           "surfaces (dim 2) can be smoothed",
                           d, dim_tags[i + 1]);
        if (d != dim_tags[0])
            return gg_fail(msg, GETME_ERR_ARGUMENT,
                           "Entities (%d, %d) and (%d, %d) have different "
                           "dimensions: smooth volumes and surfaces in "
                           "separate calls",
                           dim_tags[0], dim_tags[1], d, dim_tags[i + 1]);
    }
    return GETME_OK;
}

static getme_status explicit_select(const int *dim_tags, size_t n, int **pairs,
                                    int *count, int *dim, gg_msg *msg)
{
    getme_status st = check_dims(dim_tags, n, msg);
    if (st != GETME_OK)
        return st;
    int d = dim_tags[0], *ents = NULL, ierr = 0, k = 0;
    size_t ne = 0;
    gmshModelGetEntities(&ents, &ne, d, &ierr);
    int *out = malloc(n * sizeof *out);
    if (!out) {
        gmshFree(ents);
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    }
    for (size_t i = 0; i < n && st == GETME_OK; i += 2) {
        int tag = dim_tags[i + 1];
        if (!entity_exists(ents, ne, tag))
            st = gg_fail(msg, GETME_ERR_ARGUMENT,
                         "%s %d does not exist in the current model",
                         gg_dim_Word(d), tag);
        else if (count_element_types(d, tag) == 0)
            st = gg_fail(msg, GETME_ERR_STATE,
                         "%s %d has no mesh elements: generate the mesh "
                         "first",
                         gg_dim_Word(d), tag);
        else if (!already_listed(out, k, tag)) {
            out[2 * k] = d;
            out[2 * k + 1] = tag;
            k++;
        }
    }
    gmshFree(ents);
    if (st != GETME_OK) {
        free(out);
        return st;
    }
    *pairs = out;
    *count = k;
    *dim = d;
    return GETME_OK;
}

getme_status gg_select_entities(const int *dim_tags, size_t dim_tags_n,
                                int **pairs, int *count, int *dim,
                                gg_msg *msg)
{
    *pairs = NULL;
    *count = 0;
    *dim = 0;
    if (!dim_tags || dim_tags_n == 0)
        return auto_select(pairs, count, dim, msg);
    return explicit_select(dim_tags, dim_tags_n, pairs, count, dim, msg);
}
