/*
 * block_edges.c -- the blocks' own edge lists (block_edges.h says why).
 *
 * One parallel pass over contiguous ranges of blocks: each block's
 * distinct edges are numbered in the order its tets first use them (a
 * small hash table per thread, emptied slot by slot after each block),
 * every tet edge's index written, and the block's list appended to its
 * thread's buffer; the buffers, in range order, are the list array.
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

/* Block b's edges numbered into ledge and listed into list (room for 6
   per tet), with a hash table of cap slots (key -> index; all EMPTY
   before and after) and used (as much room as list); returns how many
   distinct edges. */
static int32_t number_block(getme_blocks *blk, const getme_adj *adj,
                            const getme_ws *ws, int32_t b, int32_t *key,
                            uint16_t *val, int32_t *used, uint32_t cap,
                            int32_t *list)
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
            /* another edge in the slot: rare (a tet block's ~1000 edges
               in 8192 slots), so the only branch; whether the edge was
               seen is a coin toss, so that takes none */
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
    for (int32_t k = 0; k < n; k++) {
        list[k] = key[used[k]];
        key[used[k]] = EMPTY;
    }
    return n;
}

/* One thread's share of the blocks, [b0, b1), numbered in order, their
   lists appended to *buf (grown as needed, *room its room, *len its
   entries), the table's arrays in tab.  0, or -1 without memory. */
static int number_range(getme_blocks *blk, const getme_adj *adj,
                        const getme_ws *ws, int32_t b0, int32_t b1,
                        char *tab, uint32_t cap, int64_t most, int32_t **buf,
                        int64_t *room, int64_t *len)
{
    int32_t *key = (int32_t *)(void *)tab;
    int32_t *used = (int32_t *)(void *)(tab + cap * sizeof(int32_t));
    uint16_t *val = (uint16_t *)(void *)(tab + cap * sizeof(int32_t) +
                                         (size_t)most * sizeof(int32_t));
    for (uint32_t h = 0; h < cap; h++)
        key[h] = EMPTY;
    for (int32_t b = b0; b < b1; b++) {
        if (*len + most > *room) {
            int64_t r = *room + *room / 2 + most;
            int32_t *p = getme__realloc(*buf, (size_t)r * sizeof *p);
            if (!p)
                return -1;
            *buf = p, *room = r;
        }
        int32_t n = number_block(blk, adj, ws, b, key, val, used, cap,
                                 *buf + *len);
        blk->eptr[b + 1] = n;
        *len += n;
    }
    return 0;
}

void getme__blocks_edges(getme_blocks *blk, const getme_adj *adj,
                         const getme_ws *ws)
{
    getme__blocks_free_edges(blk);
    int nt = ws->nt;
    int32_t nb = ws->num_blocks, ne = ws->ne;
    /* tets alone (the workspace puts each type's elements together, tets
       first), and every block's 6 x 512 entries fit the 16-bit indices */
    if (ws->dim != 3 || ne == 0 || nb == 0 || ws->tstart[GETME_TET] != 0 ||
        ws->tstart[GETME_TET + 1] != ne || adj->esum == NULL ||
        (int64_t)6 * blk->bsize > UINT16_MAX)
        return;
    int64_t most = (int64_t)6 * blk->bsize; /* a block's entries */
    uint32_t cap = 64;
    while (cap < 2 * most) /* at most half full */
        cap *= 2;
    size_t per = cap * (sizeof(int32_t) + sizeof(uint16_t)) +
                 (size_t)most * sizeof(int32_t);
    blk->eptr = getme__malloc(((size_t)nb + 1) * sizeof *blk->eptr);
    blk->ledge = getme__malloc((size_t)ne * 6 * sizeof *blk->ledge);
    char *tables = getme__malloc((size_t)nt * per);
    int32_t **bufs = getme__calloc((size_t)nt, sizeof *bufs);
    int64_t *lens = getme__calloc((size_t)nt, sizeof *lens);
    int ok = blk->eptr && blk->ledge && tables && bufs && lens, team = 1;
    if (!ok)
        goto done;
    blk->eptr[0] = 0;
    /* One pass: each thread numbers a contiguous range of blocks in order
       and keeps their lists back to back, so its buffer is its range's
       part of the final list array (blocks are alike: static ranges
       balance).  The ranges depend on the threads, the lists do not. */
#pragma omp parallel num_threads(nt) reduction(&& : ok)
    {
        int th = omp_get_thread_num(), n = omp_get_num_threads();
        if (th == 0)
            team = n;
        int32_t b0 = (int32_t)((int64_t)nb * th / n);
        int32_t b1 = (int32_t)((int64_t)nb * (th + 1) / n);
        /* room for ~2.25 entries per tet (2.1 on the benchmark tets) */
        int64_t room = (int64_t)(ws->block_start[b1] - ws->block_start[b0]) *
                       9 / 4 + most;
        /* the buffer and its length on the thread's stack while it
           works: adjacent in bufs[] and lens[], the threads' entries
           share a cache line */
        int32_t *buf = getme__malloc((size_t)room * sizeof *buf);
        int64_t len = 0;
        ok = buf != NULL;
        ok = ok && number_range(blk, adj, ws, b0, b1,
                                tables + per * (size_t)th, cap, most, &buf,
                                &room, &len) == 0;
        bufs[th] = buf, lens[th] = len;
    }
    if (!ok)
        goto done;
    int64_t big = 0;
    for (int32_t b = 0; b < nb; b++) {
        big = blk->eptr[b + 1] > big ? blk->eptr[b + 1] : big;
        blk->eptr[b + 1] += blk->eptr[b];
    }
    blk->estride = (int32_t)((big + 7) & ~(int64_t)7); /* 64-byte apart */
    blk->esl = getme__aligned_alloc(64, (size_t)nt * (size_t)blk->estride *
                                            sizeof *blk->esl + 64);
    /* thread 0's buffer is the array's start: grown in place, the other
       threads' parts copied after it */
    blk->edges = getme__realloc(bufs[0], (size_t)(blk->eptr[nb] ? blk->eptr[nb]
                                                                : 1) *
                                             sizeof *blk->edges);
    ok = blk->esl && blk->edges;
    if (!ok)
        goto done;
    bufs[0] = NULL;
    for (int th = 1; th < team; th++) {
        int32_t b0 = (int32_t)((int64_t)nb * th / team);
        getme__copy(blk->edges + blk->eptr[b0], bufs[th],
                    (size_t)lens[th] * sizeof *blk->edges, team);
    }
done:
    for (int th = 0; bufs && th < nt; th++)
        free(bufs[th]);
    free(bufs), free(lens), free(tables);
    if (!ok)
        getme__blocks_free_edges(blk);
}
