/*
 * block_edges.c -- the blocks' own edge lists (block_edges.h says why).
 *
 * Two parallel passes over the blocks, each block writing only its own
 * entries.  The first numbers each block's distinct edges in the order its
 * tets first use them (a small hash table per thread, emptied slot by slot
 * after each block) and writes every tet edge's index; the second, once
 * the lists' offsets are known, writes each list from those indices.
 */
#include "block_edges.h"
#include "internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define EMPTY INT32_MIN /* edge ids are >= -1 */

void getme__blocks_free_edges(getme_blocks *blk)
{
    free(blk->eptr);
    free(blk->edges);
    free(blk->ledge);
    free(blk->esl);
    blk->eptr = NULL;
    blk->edges = NULL;
    blk->ledge = NULL;
    blk->esl = NULL;
    blk->estride = 0;
}

/* Block b's edges numbered into ledge, with a hash table of cap slots
   (key -> index; all EMPTY before and after) and used (room for the
   block's 6 x tets entries); returns how many distinct edges. */
static int32_t number_block(getme_blocks *blk, const getme_adj *adj,
                            const getme_ws *ws, int32_t b, int32_t *key,
                            uint16_t *val, int32_t *used, uint32_t cap)
{
    uint32_t mask = cap - 1;
    int shift = 32 - __builtin_ctz(cap);
    int32_t n = 0;
    for (int32_t e = ws->block_start[b]; e < ws->block_start[b + 1]; e++) {
        int32_t id[12];
        getme__adj_edge_ids(adj, getme__ws_nodes(ws, GETME_TET, e), GETME_TET,
                            getme__adj_slots(adj, ws, GETME_TET, e), id);
        uint16_t *le = blk->ledge + 6 * (int64_t)e;
        for (int j = 0; j < 6; j++) {
            uint32_t h = ((uint32_t)id[j] * 2654435761u) >> shift;
            int32_t old = key[h];
            /* another edge in the slot: rare (the table is at most a
               sixth full), so the only branch; whether the edge was seen
               is a coin toss, so that takes none */
            if (__builtin_expect((old != id[j]) & (old != EMPTY), 0))
                while ((old = key[h = (h + 1) & mask]) != id[j] && old != EMPTY)
                    ;
            int fresh = old == EMPTY;
            key[h] = id[j];
            val[h] = fresh ? (uint16_t)n : val[h];
            used[n] = (int32_t)h;
            n += fresh;
            le[j] = val[h];
        }
    }
    for (int32_t k = 0; k < n; k++)
        key[used[k]] = EMPTY;
    return n;
}

void getme__blocks_edges(getme_blocks *blk, const getme_adj *adj,
                         const getme_ws *ws)
{
    getme__blocks_free_edges(blk);
    int nt = ws->nt;
    int32_t nb = ws->num_blocks, ne = ws->ne;
    /* tets alone (the workspace puts each type's elements together, tets
       first), and every block's 6 x 512 entries fit the 16-bit indices */
    if (ws->dim != 3 || ne == 0 || ws->tstart[GETME_TET] != 0 ||
        ws->tstart[GETME_TET + 1] != ne || adj->esum == NULL ||
        (int64_t)6 * blk->bsize > UINT16_MAX)
        return;
    int64_t most = (int64_t)6 * blk->bsize; /* a block's entries */
    uint32_t cap = 64;
    while (cap < 2 * most) /* at most half full */
        cap *= 2;
    blk->eptr = getme__malloc(((size_t)nb + 1) * sizeof *blk->eptr);
    blk->ledge = getme__malloc((size_t)ne * 6 * sizeof *blk->ledge);
    size_t per = cap * (sizeof(int32_t) + sizeof(uint16_t)) +
                 (size_t)most * sizeof(int32_t);
    char *tables = getme__malloc((size_t)nt * per);
    if (!blk->eptr || !blk->ledge || !tables)
        goto fail;
    blk->eptr[0] = 0;
#pragma omp parallel num_threads(nt)
    {
        char *p = tables + per * (size_t)omp_get_thread_num();
        int32_t *key = (int32_t *)(void *)p;
        int32_t *used = (int32_t *)(void *)(p + cap * sizeof(int32_t));
        uint16_t *val = (uint16_t *)(void *)(p + cap * sizeof(int32_t) +
                                             (size_t)most * sizeof(int32_t));
        for (uint32_t h = 0; h < cap; h++)
            key[h] = EMPTY;
#pragma omp for schedule(dynamic, 16)
        for (int32_t b = 0; b < nb; b++)
            blk->eptr[b + 1] = number_block(blk, adj, ws, b, key, val, used, cap);
    }
    free(tables), tables = NULL;
    int64_t big = 0;
    for (int32_t b = 0; b < nb; b++) {
        big = blk->eptr[b + 1] > big ? blk->eptr[b + 1] : big;
        blk->eptr[b + 1] += blk->eptr[b];
    }
    blk->estride = (int32_t)((big + 7) & ~(int64_t)7); /* 64-byte apart */
    blk->edges = getme__malloc((size_t)(blk->eptr[nb] ? blk->eptr[nb] : 1) *
                               sizeof *blk->edges);
    blk->esl = getme__aligned_alloc(64, (size_t)nt * (size_t)blk->estride *
                                            sizeof *blk->esl + 64);
    if (!blk->edges || !blk->esl)
        goto fail;
#pragma omp parallel for schedule(dynamic, 16) num_threads(nt)
    for (int32_t b = 0; b < nb; b++) {
        int32_t *list = blk->edges + blk->eptr[b];
        for (int32_t e = ws->block_start[b]; e < ws->block_start[b + 1]; e++) {
            int32_t id[12];
            getme__adj_edge_ids(adj, getme__ws_nodes(ws, GETME_TET, e),
                                GETME_TET,
                                getme__adj_slots(adj, ws, GETME_TET, e), id);
            const uint16_t *le = blk->ledge + 6 * (int64_t)e;
            for (int j = 0; j < 6; j++)
                list[le[j]] = id[j];
        }
    }
    return;
fail:
    free(tables);
    getme__blocks_free_edges(blk);
}
