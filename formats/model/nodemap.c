/*
 * gmsh_nodemap.c -- Gmsh node tag -> our zero-based node index.
 *
 * Gmsh numbers nodes densely after meshing (tags 1..N), but a mesh read
 * from a file may use any positive tags.  A direct table is the fastest
 * lookup and costs 4 bytes per possible tag, so it is used whenever the
 * largest tag is within a small multiple of the node count; otherwise the
 * tags are sorted once and looked up by bisection.
 */
#include "gmsh_internal.h"

#include <stdlib.h>
#include <string.h>

typedef struct tag_index {
    size_t tag;
    int32_t idx;
} tag_index;

static int cmp_tag_index(const void *a, const void *b)
{
    size_t x = ((const tag_index *)a)->tag, y = ((const tag_index *)b)->tag;
    return x < y ? -1 : x > y;
}

static getme_status build_dense(gg_nodemap *map, const size_t *tags, size_t n,
                                gg_msg *msg)
{
    map->dense = malloc((map->max_tag + 1) * sizeof *map->dense);
    if (!map->dense)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory (node table)");
    memset(map->dense, 0xff, (map->max_tag + 1) * sizeof *map->dense);
    for (size_t i = 0; i < n; i++)
        map->dense[tags[i]] = (int32_t)i;
    return GETME_OK;
}

static getme_status build_sorted(gg_nodemap *map, const size_t *tags,
                                 size_t n, gg_msg *msg)
{
    tag_index *ti = malloc((n ? n : 1) * sizeof *ti);
    map->sorted_tag = malloc((n ? n : 1) * sizeof *map->sorted_tag);
    map->sorted_idx = malloc((n ? n : 1) * sizeof *map->sorted_idx);
    if (!ti || !map->sorted_tag || !map->sorted_idx) {
        free(ti);
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory (node table)");
    }
    for (size_t i = 0; i < n; i++) {
        ti[i].tag = tags[i];
        ti[i].idx = (int32_t)i;
    }
    qsort(ti, n, sizeof *ti, cmp_tag_index);
    for (size_t i = 0; i < n; i++) {
        map->sorted_tag[i] = ti[i].tag;
        map->sorted_idx[i] = ti[i].idx;
    }
    free(ti);
    return GETME_OK;
}

getme_status gg_nodemap_build(gg_nodemap *map, const size_t *tags, size_t n,
                              gg_msg *msg)
{
    memset(map, 0, sizeof *map);
    if (n > (size_t)INT32_MAX)
        return gg_fail(msg, GETME_ERR_ARGUMENT,
                       "%zu nodes: more than 2^31-1 are not supported", n);
    map->n = n;
    for (size_t i = 0; i < n; i++)
        if (tags[i] > map->max_tag)
            map->max_tag = tags[i];
    if (map->max_tag <= 4 * n + 1024)
        return build_dense(map, tags, n, msg);
    return build_sorted(map, tags, n, msg);
}

int32_t gg_nodemap_find(const gg_nodemap *map, size_t tag)
{
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

void gg_nodemap_free(gg_nodemap *map)
{
    free(map->dense);
    free(map->sorted_tag);
    free(map->sorted_idx);
    memset(map, 0, sizeof *map);
}
