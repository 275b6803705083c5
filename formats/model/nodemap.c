/*
 * nodemap.c -- Gmsh node tag -> zero-based node index.
 *
 * Gmsh numbers nodes densely after meshing (tags 1..N), but a mesh read
 * from a file may use any positive tags.  A direct table is the fastest
 * lookup and costs 4 bytes per possible tag, so it is used while the tags
 * are dense enough (the largest within about twice the node count);
 * otherwise the tags are sorted once and looked up by bisection.  When the
 * table says tag t is node t - 1 for every t once the nodes are numbered
 * (getme__nodemap_relabel; Gmsh's own numbering read back), it is dropped
 * and the index computed: it would stay alive, 4 B per node, through the
 * whole smoothing run.
 */
#include "model.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

typedef struct tag_index {
    uint64_t tag;
    int32_t idx;
} tag_index;

static int cmp_tag_index(const void *a, const void *b)
{
    uint64_t x = ((const tag_index *)a)->tag, y = ((const tag_index *)b)->tag;
    return (x > y) - (x < y);
}

static getme_status build_sorted(getme__nodemap *map, const uint64_t *tags,
                                 size_t n, uint64_t *repeated)
{
    tag_index *ti = getme__malloc((n ? n : 1) * sizeof *ti);
    map->sorted_tag = getme__malloc((n ? n : 1) * sizeof *map->sorted_tag);
    map->sorted_idx = getme__malloc((n ? n : 1) * sizeof *map->sorted_idx);
    if (!ti || !map->sorted_tag || !map->sorted_idx) {
        free(ti);
        return GETME_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++) {
        ti[i].tag = tags[i];
        ti[i].idx = (int32_t)i;
    }
    qsort(ti, n, sizeof *ti, cmp_tag_index);
    getme_status st = GETME_OK;
    for (size_t i = 0; i < n; i++) {
        if (i && ti[i].tag == ti[i - 1].tag && st == GETME_OK) {
            *repeated = ti[i].tag;
            st = GETME_ERR_ARGUMENT;
        }
        map->sorted_tag[i] = ti[i].tag;
        map->sorted_idx[i] = ti[i].idx;
    }
    free(ti);
    return st;
}

/* Drop a dense table that maps every tag t in 1..n to t - 1. */
static void drop_if_ordered(getme__nodemap *map)
{
    if (!map->dense || map->max_tag != map->n || map->dense[0] != -1)
        return;
    for (uint64_t t = 1; t <= map->max_tag; t++)
        if (map->dense[t] != (int32_t)(t - 1))
            return;
    free(map->dense);
    map->dense = NULL;
    map->ordered = 1;
}

getme_status getme__nodemap_build(getme__nodemap *map, const uint64_t *tags,
                                  size_t n, uint64_t *repeated)
{
    memset(map, 0, sizeof *map);
    map->n = n;
    for (size_t i = 0; i < n; i++)
        if (tags[i] > map->max_tag)
            map->max_tag = tags[i];
    if (map->max_tag > 2 * (uint64_t)n + 1024)
        return build_sorted(map, tags, n, repeated);
    map->dense = getme__malloc((size_t)(map->max_tag + 1) * sizeof *map->dense);
    if (!map->dense)
        return GETME_ERR_NOMEM;
    memset(map->dense, 0xff, (size_t)(map->max_tag + 1) * sizeof *map->dense);
    for (size_t i = 0; i < n; i++) {
        if (map->dense[tags[i]] >= 0) {
            *repeated = tags[i];
            return GETME_ERR_ARGUMENT;
        }
        map->dense[tags[i]] = (int32_t)i;
    }
    return GETME_OK;
}

int32_t getme__nodemap_find(const getme__nodemap *map, uint64_t tag)
{
    if (map->ordered)
        return tag >= 1 && tag <= map->max_tag ? (int32_t)(tag - 1) : -1;
    if (map->dense)
        return tag <= map->max_tag ? map->dense[tag] : -1;
    size_t lo = 0, hi = map->n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (map->sorted_tag[mid] < tag)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < map->n && map->sorted_tag[lo] == tag ? map->sorted_idx[lo]
                                                      : -1;
}

void getme__nodemap_relabel(getme__nodemap *map, const int32_t *loc)
{
    if (map->dense) {
        for (uint64_t t = 0; t <= map->max_tag; t++)
            if (map->dense[t] >= 0)
                map->dense[t] = loc[map->dense[t]];
        drop_if_ordered(map);
        return;
    }
    for (size_t i = 0; i < map->n; i++)
        map->sorted_idx[i] = loc[map->sorted_idx[i]];
}

void getme__nodemap_free(getme__nodemap *map)
{
    free(map->dense);
    free(map->sorted_tag);
    free(map->sorted_idx);
    memset(map, 0, sizeof *map);
}
