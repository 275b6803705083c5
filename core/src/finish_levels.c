/*
 * finish_levels.c -- conflict levels of a finishing pass (finish_levels.h).
 */
#include "finish_levels.h"

#include <stdlib.h>
#include <string.h>

void getme__levels_free(getme_levels *lv)
{
    free(lv->level);
    free(lv->order);
    free(lv->ptr);
    free(lv->key);
    free(lv->mark);
    free(lv->slot);
    free(lv->cfirst);
    memset(lv, 0, sizeof *lv);
}

static uint32_t probe(const getme_levels *lv, int32_t e)
{
    uint32_t mask = lv->mcap - 1, i = ((uint32_t)e * 2654435761u) & mask;
    while (lv->key[i] >= 0 && lv->key[i] != e)
        i = (i + 1) & mask;
    return i;
}

/* Marks with room for cap (a power of two) keeping the old ones; 0 or -1
   (then lv is as it was). */
static int marks_grow(getme_levels *lv, uint32_t cap)
{
    int32_t *key = getme__malloc((size_t)cap * sizeof *key);
    int32_t *mark = getme__malloc((size_t)cap * sizeof *mark);
    if (!key || !mark) {
        free(key), free(mark);
        return -1;
    }
    for (uint32_t i = 0; i < cap; i++)
        key[i] = -1;
    getme_levels old = *lv;
    lv->key = key, lv->mark = mark, lv->mcap = cap;
    for (uint32_t k = 0; k < old.mcap; k++)
        if (old.key[k] >= 0) {
            uint32_t j = probe(lv, old.key[k]);
            lv->key[j] = old.key[k];
            lv->mark[j] = old.mark[k];
        }
    free(old.key), free(old.mark);
    return 0;
}

/* Room in lv->slot for one patch, in the marks for its elements to be
   added (at most half full after); 0 or -1. */
static int reserve(getme_levels *lv, int64_t refs)
{
    if (refs > lv->cap_s) {
        uint32_t *s = getme__realloc(lv->slot, (size_t)refs * sizeof *s);
        if (!s)
            return -1;
        lv->slot = s, lv->cap_s = refs;
    }
    uint32_t cap = lv->mcap ? lv->mcap : 1024;
    while (2 * ((uint64_t)lv->used + (uint64_t)refs) > cap)
        cap *= 2;
    return cap > lv->mcap ? marks_grow(lv, cap) : 0;
}

/* The slot of element e, created with mark 0 (room reserved). */
static uint32_t slot_of(getme_levels *lv, int32_t e)
{
    uint32_t i = probe(lv, e);
    if (lv->key[i] < 0) {
        lv->key[i] = e, lv->mark[i] = 0;
        lv->used++;
    }
    return i;
}

/* Element e's patch (free nodes w[0..k)) as slots in lv->slot; their
   count, or -1 without memory. */
static int64_t patch_slots(getme_levels *lv, const getme_ws *ws, int32_t e,
                           const int32_t *w, int k)
{
    int64_t refs = 1;
    for (int j = 0; j < k; j++)
        refs += getme__star_size(ws, w[j]);
    if (reserve(lv, refs) != 0)
        return -1;
    int64_t m = 0;
    if (k == 0) /* it only reads its own quality */
        lv->slot[m++] = slot_of(lv, e);
    for (int j = 0; j < k; j++)
#ifdef GETME_FINISH_MUTANT /* test builds: a broken rule must be caught */
        if (j == 0)
#endif
        {
            getme_star_it it = getme__star_open(ws, w[j]);
            for (int32_t e; getme__star_next(&it, &e);)
                lv->slot[m++] = slot_of(lv, e);
        }
    return m;
}

getme_status getme__levels_build(getme_levels *lv, const getme_ws *ws,
                                 const getme_ranked *list, int32_t n,
                                 int32_t chunk)
{
    int32_t nc = n ? (n - 1) / chunk + 1 : 0;
    if (nc + 1 > lv->cap_c) {
        int32_t *f = getme__realloc(lv->cfirst, (size_t)(nc + 1) * sizeof *f);
        if (!f)
            return GETME_ERR_NOMEM;
        lv->cfirst = f, lv->cap_c = nc + 1;
    }
    lv->chunk = chunk, lv->num_chunks = nc;
    if (n > lv->cap) {
        int32_t *a = getme__realloc(lv->level, (size_t)n * sizeof *a);
        if (a)
            lv->level = a;
        int32_t *b =
            a ? getme__realloc(lv->order, (size_t)n * sizeof *b) : NULL;
        if (!b)
            return GETME_ERR_NOMEM;
        lv->order = b, lv->cap = n;
    }
    for (uint32_t i = 0; i < lv->mcap; i++)
        lv->key[i] = -1;
    lv->used = 0;
    int32_t num = 0;
    for (int32_t i = 0; i < n; i++) {
        int32_t e = list[i].e, w[GETME_MAX_NV];
        int t = getme__ws_type(ws, e), k = 0;
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int j = 0; j < getme__nv[t]; j++)
            if (!ws->fixed[c[j]])
                w[k++] = c[j];
        int64_t m = patch_slots(lv, ws, e, w, k);
        if (m < 0)
            return GETME_ERR_NOMEM;
        if (i % chunk == 0) /* a chunk starts above every earlier level */
            lv->cfirst[i / chunk] = num;
        /* marks are 1 + a level: L is the new level (earlier chunks'
           marks are at most num, their chunk's start) */
        int32_t L = lv->cfirst[i / chunk];
        for (int64_t r = 0; r < m; r++)
            L = lv->mark[lv->slot[r]] > L ? lv->mark[lv->slot[r]] : L;
        for (int64_t r = 0; r < m; r++)
            lv->mark[lv->slot[r]] = L + 1;
        lv->level[i] = L;
        num = L + 1 > num ? L + 1 : num;
    }
    lv->cfirst[nc] = num;
    if (num + 1 > lv->cap_ptr) {
        int32_t *p = getme__realloc(lv->ptr, (size_t)(num + 1) * sizeof *p);
        if (!p)
            return GETME_ERR_NOMEM;
        lv->ptr = p, lv->cap_ptr = num + 1;
    }
    /* counting sort: within a level, list order */
    memset(lv->ptr, 0, (size_t)(num + 1) * sizeof *lv->ptr);
    for (int32_t i = 0; i < n; i++)
        lv->ptr[lv->level[i] + 1]++;
    for (int32_t L = 0; L < num; L++)
        lv->ptr[L + 1] += lv->ptr[L];
    for (int32_t i = 0; i < n; i++)
        lv->order[lv->ptr[lv->level[i]]++] = i;
    for (int32_t L = num; L > 0; L--)
        lv->ptr[L] = lv->ptr[L - 1];
    lv->ptr[0] = 0;
    lv->num = num;
    return GETME_OK;
}
