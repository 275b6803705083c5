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
    free(lv->touched);
    free(lv->patch);
    free(lv->cfirst);
    memset(lv, 0, sizeof *lv);
}

/* Room in lv->patch for one patch of refs entries, and in lv->touched for
   as many elements more; 0 or -1 (then lv is as it was). */
static int reserve(getme_levels *lv, int64_t refs)
{
    if (refs > lv->cap_p) {
        int32_t *p = getme__realloc(lv->patch, (size_t)refs * sizeof *p);
        if (!p)
            return -1;
        lv->patch = p, lv->cap_p = refs;
    }
    if (lv->used + refs > lv->cap_t) {
        int64_t cap = lv->used + refs > 2 * lv->cap_t ? lv->used + refs
                                                      : 2 * lv->cap_t;
        int32_t *t = getme__realloc(lv->touched, (size_t)cap * sizeof *t);
        if (!t)
            return -1;
        lv->touched = t, lv->cap_t = cap;
    }
    return 0;
}

/* Element e's patch (free nodes w[0..k)) into lv->patch, repeats allowed;
   its length, or -1 without memory. */
static int64_t patch_elems(getme_levels *lv, const getme_ws *ws, int32_t e,
                           const int32_t *w, int k)
{
    int64_t refs = 1;
    for (int j = 0; j < k; j++)
        refs += getme__star_size(ws, w[j]);
    if (reserve(lv, refs) != 0)
        return -1;
    int64_t m = 0;
    if (k == 0) /* it only reads its own quality */
        lv->patch[m++] = e;
    for (int j = 0; j < k; j++)
#ifdef GETME_FINISH_MUTANT /* test builds: a broken rule must be caught */
        if (j == 0)
#endif
        {
            getme_star_it it = getme__star_open(ws, w[j]);
            for (int32_t a; getme__star_next(&it, &a);)
                lv->patch[m++] = a;
        }
    return m;
}

/* The marks back to zero (every element lv->touched lists). */
static void clear_marks(getme_levels *lv, int32_t *mark)
{
    for (int64_t i = 0; i < lv->used; i++)
        mark[lv->touched[i]] = 0;
    lv->used = 0;
}

getme_status getme__levels_build(getme_levels *lv, const getme_ws *ws,
                                 const getme_ranked *list, int32_t n,
                                 int32_t chunk, int32_t *mark)
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
    lv->used = 0;
    int32_t num = 0;
    for (int32_t i = 0; i < n; i++) {
        int32_t e = list[i].e, w[GETME_MAX_NV];
        int t = getme__ws_type(ws, e), k = 0;
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int j = 0; j < getme__nv[t]; j++)
            if (!ws->fixed[c[j]])
                w[k++] = c[j];
        int64_t m = patch_elems(lv, ws, e, w, k);
        if (m < 0) {
            clear_marks(lv, mark);
            return GETME_ERR_NOMEM;
        }
        if (i % chunk == 0) /* a chunk starts above every earlier level */
            lv->cfirst[i / chunk] = num;
        /* marks are 1 + a level: L is the new level (earlier chunks'
           marks are at most num, their chunk's start) */
        int32_t L = lv->cfirst[i / chunk];
        const int32_t *sl = lv->patch;
        for (int64_t r = 0; r < m; r++)
            L = mark[sl[r]] > L ? mark[sl[r]] : L;
        for (int64_t r = 0; r < m; r++) {
            if (!mark[sl[r]]) /* first touched: cleared at the end */
                lv->touched[lv->used++] = sl[r];
            mark[sl[r]] = L + 1;
        }
        lv->level[i] = L;
        num = L + 1 > num ? L + 1 : num;
    }
    lv->cfirst[nc] = num;
    clear_marks(lv, mark);
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
