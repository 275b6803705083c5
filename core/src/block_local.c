/*
 * block_local.c -- the blocks' node lists and local connectivity
 * (block_local.h says why).
 *
 * Two parallel passes over the blocks, each block writing only its own
 * entries: count each block's distinct nodes, then list them in the order
 * its elements first use them (the local connectivity, the elements'
 * nodes renumbered into that list, is rebuilt when a block runs:
 * getme__blocks_localise).  A per-thread mark array (the block's number
 * + 1 per node seen)
 * finds the distinct nodes, so the result does not depend on the threads.
 */
#include "block_local.h"
#include "block_edges.h"
#include "internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

void getme__blocks_free(getme_blocks *blk)
{
    if (blk->scratch)
        free(blk->scratch[0].acc); /* one allocation for all threads */
    free(blk->scratch);
    free(blk->nptr);
    free(blk->nodes);
    free(blk->local);
    free(blk->order);
    free(blk->part_ptr);
    free(blk->col_ptr);
    free(blk->group.ptr);
    free(blk->group.cnt);
    free(blk->group.pos);
    if (blk->fb)
        free(blk->fb->weight); /* one allocation for the arrays */
    free(blk->fb);
    getme__blocks_free_edges(blk);
    memset(blk, 0, sizeof *blk);
}

void getme__blocks_free_local(getme_blocks *blk)
{
    getme__blocks_free_edges(blk);
    free(blk->nptr);
    free(blk->nodes);
    free(blk->local);
    blk->nptr = NULL;
    blk->nodes = NULL;
    blk->local = NULL;
}

/* Block b's distinct nodes: with list == NULL only counted; else listed
   into list. */
static int32_t block_nodes(const getme_ws *ws, int32_t b, int32_t *mark,
                           int32_t *list)
{
    int32_t e0 = ws->block_start[b], e1 = ws->block_start[b + 1];
    if (e1 <= e0)
        return 0;
    int t = getme__ws_type(ws, e0), nv = getme__nv[t];
    const int32_t *c = getme__ws_nodes(ws, t, e0);
    int32_t m = 0;
    for (int64_t k = 0; k < (int64_t)(e1 - e0) * nv; k++) {
        int32_t n = c[k];
        if (mark[n] != b + 1) {
            mark[n] = b + 1;
            if (list)
                list[m] = n;
            m++;
        }
    }
    return m;
}

/* Each thread's scratch, in one 64-byte aligned allocation: a block's
   exact sums start on a cache line, and the four of a node fill one. */
static getme_status alloc_scratch(getme_blocks *blk, int nt)
{
    /* + 1: the slot after a block's nodes takes its fixed nodes'
       contributions (transform_block: an index select instead of a
       branch per element node) */
    size_t m = (size_t)blk->max_nodes + 1;
    m = (m + 7) & ~(size_t)7; /* every part a multiple of 64 bytes */
    size_t me = (size_t)(blk->max_elems ? blk->max_elems : 1);
    size_t per = m * (4 * sizeof(getme_fx) + 3 * sizeof(double) +
                      sizeof(int64_t) + sizeof(int32_t) + 1) +
                 me * (sizeof(int64_t) + sizeof(int32_t) +
                       GETME_MAX_NV * sizeof(uint16_t));
    per = (per + 63) & ~(size_t)63;
    blk->scratch = getme__calloc((size_t)nt, sizeof *blk->scratch);
    char *p = getme__aligned_alloc(64, per * (size_t)nt);
    if (!blk->scratch || !p) {
        free(p);
        return GETME_ERR_NOMEM;
    }
    for (int k = 0; k < nt; k++) {
        char *q = p + per * (size_t)k;
        blk->scratch[k].acc = (getme_fx *)(void *)q;
        q += m * 4 * sizeof(getme_fx);
        blk->scratch[k].x = (double *)(void *)q;
        q += m * 3 * sizeof(double);
        blk->scratch[k].nsum = (int64_t *)(void *)q;
        q += m * sizeof(int64_t);
        blk->scratch[k].slot = (int32_t *)(void *)q;
        q += m * sizeof(int32_t);
        blk->scratch[k].wf = (int64_t *)(void *)q;
        q += me * sizeof(int64_t);
        blk->scratch[k].list = (int32_t *)(void *)q;
        q += me * sizeof(int32_t);
        blk->scratch[k].lconn = (uint16_t *)(void *)q;
        q += me * GETME_MAX_NV * sizeof(uint16_t);
        blk->scratch[k].flag = (uint8_t *)q;
    }
    return GETME_OK;
}

/* Entry j of the blocks' node lists as a node index: a GETMe adaptive
   run marks entries with the sign bit (mark_last) before
   getme__blocks_reorder deals the blocks again. */
static inline int32_t list_node(const getme_blocks *blk, int64_t j)
{
    return blk->nodes[j] & INT32_MAX;
}

/* The balance's shares and feedback for np parts (equal weights); left
   NULL without memory (the shares then stay equal). */
static void alloc_feedback(getme_blocks *blk, int np)
{
    struct getme_block_feedback *fb = getme__calloc(1, sizeof *fb);
    /* weight, prev_weight, busy, work and last (8 bytes each), then perm,
       prev_perm and getme__blocks_rebalance's 3 np of scratch (4 each) */
    int64_t *a = getme__calloc((size_t)np * 8, sizeof(int64_t));
    if (!fb || !a) {
        free(fb), free(a);
        return;
    }
    fb->weight = a;
    fb->prev_weight = a + np;
    fb->busy = (double *)(void *)(a + 2 * np);
    fb->work = fb->busy + np;
    fb->last = fb->work + np;
    fb->perm = (int32_t *)(void *)(a + 5 * np);
    fb->prev_perm = fb->perm + np;
    fb->deal = fb->prev_perm + np;
    for (int p = 0; p < np; p++)
        a[p] = 1, fb->perm[p] = p;
    blk->fb = fb;
}

/* The parts' weights and their sum (NULL: all 1). */
static int64_t weight_of(const getme_blocks *blk, int p)
{
    return blk->fb ? blk->fb->weight[p] : 1;
}

static int64_t weight_sum(const getme_blocks *blk, int np)
{
    int64_t w = 0;
    for (int p = 0; p < np; p++)
        w += weight_of(blk, p);
    return w;
}

/* Where part p's share of n ranked things starts when they are cut in
   proportion to the weights: ceil(n c / W), c the weights before p, W
   all of them.  With equal weights, rank k is in part floor(k np / n). */
static int32_t cut_at(int64_t n, int64_t c, int64_t w)
{
    return (int32_t)((n * c + w - 1) / w);
}

/* Into bpart[rank[k]] for k in [0, n): the part of rank k, cutting in
   proportion to the weights. */
static void cut_ranks(const getme_blocks *blk, int np, const int32_t *rank,
                      const getme_ranked *keys, int32_t n, int32_t *bpart)
{
    int64_t w = weight_sum(blk, np), c = 0;
    int32_t k = 0;
    for (int p = 0; p < np; p++) {
        c += weight_of(blk, p);
        int32_t end = p == np - 1 ? n : cut_at(n, c, w);
        for (; k < end; k++)
            bpart[rank ? rank[k] : keys[k].e] = p;
    }
}

/* The axis along which the blocks cur[0..n) spread most (a block's
   position: its first node's). */
static int spread_axis(const getme_blocks *blk, const getme_ws *ws,
                       const int32_t *cur, int32_t n)
{
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int32_t k = 0; k < n; k++)
        for (int d = 0; d < 3; d++) {
            double v = ws->x[3 * (int64_t)list_node(blk, blk->nptr[cur[k]]) + d];
            lo[d] = v < lo[d] ? v : lo[d];
            hi[d] = v > hi[d] ? v : hi[d];
        }
    int a = 0;
    for (int d = 1; d < 3; d++)
        if (hi[d] - lo[d] > hi[a] - lo[a])
            a = d;
    return a;
}

/* Deal the blocks cur[0..n) into np parts by position along axis a, in
   proportion to the parts' weights: the blocks left after a level lie
   along the parts' interfaces, so this cuts across them, and the next
   level can run most of them in parts. */
static void deal_across(const getme_blocks *blk, const getme_ws *ws,
                        const int32_t *cur, int32_t n, int np, int32_t *bpart,
                        getme_ranked *keys, int a)
{
    for (int32_t k = 0; k < n; k++) {
        keys[k].e = cur[k];
        keys[k].q = ws->x[3 * (int64_t)list_node(blk, blk->nptr[cur[k]]) + a];
    }
    qsort(keys, (size_t)n, sizeof *keys, getme__cmp_ranked);
    cut_ranks(blk, np, NULL, keys, n, bpart);
}

/* Which of the blocks cur[0..n), dealt as bpart says, run at this level
   (run[k] for cur[k]) and how many of each part (count[p]): the parts in
   order, each one's blocks in list order, a block runs unless one of its
   nodes is used by a block of another part that runs, so the parts that
   run side by side share no node.  Why not each part's interior blocks
   (those whose nodes no other part uses at all): that left the blocks on
   both sides of every interface for the next level; this leaves one side
   (a part keeps its blocks along the interfaces with the parts after
   it).  part: scratch over the nodes. */
static void level_runs(const getme_blocks *blk, const int32_t *cur,
                       int32_t n, const int32_t *bpart, int32_t *part, int np,
                       uint8_t *run, int32_t *count)
{
    for (int32_t k = 0; k < n; k++)
        for (int64_t j = blk->nptr[cur[k]]; j < blk->nptr[cur[k] + 1]; j++)
            part[list_node(blk, j)] = -1;
    memset(count, 0, (size_t)np * sizeof *count);
    for (int p = 0; p < np; p++)
        for (int32_t k = 0; k < n; k++) {
            int32_t b = cur[k];
            if (bpart[b] != p)
                continue;
            int ok = 1;
            for (int64_t j = blk->nptr[b]; j < blk->nptr[b + 1] && ok; j++) {
                int32_t v = part[list_node(blk, j)];
                ok = v < 0 || v == p;
            }
            run[k] = (uint8_t)ok;
            count[p] += ok;
            for (int64_t j = blk->nptr[b]; ok && j < blk->nptr[b + 1]; j++)
                part[list_node(blk, j)] = p;
        }
}

/* The part with the fewest blocks to run for its weight (the least
   count[p] / weight, the first of equals). */
static int poorest(const getme_blocks *blk, const int32_t *count, int np)
{
    int poor = 0;
    for (int p = 1; p < np; p++)
        if ((int64_t)count[p] * weight_of(blk, poor) <
            (int64_t)count[poor] * weight_of(blk, p))
            poor = p;
    return poor;
}

/* The poorest part's blocks that run (level_runs), scaled to an equal
   weight (count W / (np w): the count itself with equal weights). */
static int32_t least_runs(const getme_blocks *blk, const int32_t *count,
                          int np)
{
    int poor = poorest(blk, count, np);
    return (int32_t)(count[poor] * weight_sum(blk, np) /
                     (np * weight_of(blk, poor)));
}

/* Deal the blocks left, cur[0..n), for the next level: across the axis
   they spread most along, unless that leaves a part with few blocks to
   run (level_runs) while another axis gives the poorest part at least
   twice as many.  The spread axis alone left one part of the full hexes'
   third level with no interior block, 20 in the other (their 299 blocks left,
   on 2 threads, then ran colour by colour); always taking the axis with
   the most in its poorest part gave the hexes' stage 1 -1.5 % but the
   tets' +2 % (more blocks at the second level, farther apart). */
static void deal_next(const getme_blocks *blk, const getme_ws *ws,
                      const int32_t *cur, int32_t n, int np, int32_t *bpart,
                      getme_ranked *keys, int32_t *part, int32_t *count,
                      uint8_t *run)
{
    int first = spread_axis(blk, ws, cur, n), best = first;
    int32_t base = 0, most = 0;
    for (int i = 0; i < 3 && np > 1; i++) {
        int a = (first + i) % 3;
        deal_across(blk, ws, cur, n, np, bpart, keys, a);
        level_runs(blk, cur, n, bpart, part, np, run, count);
        int32_t least = least_runs(blk, count, np);
        if (i == 0)
            base = most = least;
        else if (least > most)
            most = least, best = a;
    }
    if (most < 2 * base)
        best = first;
    deal_across(blk, ws, cur, n, np, bpart, keys, best);
}

/* The blocks left after the levels, cur[0..n) in ascending order, into
   order[m..], colour by colour (ascending within a colour): coloured
   greedily in that order, among themselves only, so that no two blocks
   of a colour share a node; at most 32 colours (a bit each in a 32-bit
   mask per node), and a block that finds them all taken runs in the
   serial colour, last.  They are a few percent of the blocks, along the
   parts' interfaces.  The workspace used to colour all blocks, serially,
   for these few; among themselves they form one connected sheet and
   still take 16 colours on the full tets (18 before, docs/bench.md
   session 31).  mask: room for ws->nn entries, colour: for n (scratch).
   GETME_OK or GETME_ERR_NOMEM. */
static getme_status colour_left(getme_blocks *blk, const int32_t *cur,
                                int32_t n, uint32_t *mask, int32_t *colour,
                                int32_t m)
{
    for (int32_t k = 0; k < n; k++)
        for (int64_t j = blk->nptr[cur[k]]; j < blk->nptr[cur[k] + 1]; j++)
            mask[list_node(blk, j)] = 0;
    int ncol = 0, serial = 0;
    for (int32_t k = 0; k < n; k++) {
        int64_t j0 = blk->nptr[cur[k]], j1 = blk->nptr[cur[k] + 1];
        uint32_t taken = 0;
        for (int64_t j = j0; j < j1; j++)
            taken |= mask[list_node(blk, j)];
        if (taken == UINT32_MAX) {
            colour[k] = -1; /* the serial colour */
            serial = 1;
            continue;
        }
        int c = __builtin_ctz(~taken);
        colour[k] = c;
        ncol = c + 1 > ncol ? c + 1 : ncol;
        for (int64_t j = j0; j < j1; j++)
            mask[list_node(blk, j)] |= (uint32_t)1 << c;
    }
    blk->num_colours = ncol + serial;
    blk->serial_colour = serial ? ncol : -1;
    blk->col_ptr =
        getme__malloc(((size_t)blk->num_colours + 1) * sizeof *blk->col_ptr);
    if (!blk->col_ptr)
        return GETME_ERR_NOMEM;
    for (int c = 0; c < blk->num_colours; c++) {
        int want = c == blk->serial_colour ? -1 : c;
        blk->col_ptr[c] = m;
        for (int32_t k = 0; k < n; k++)
            if (colour[k] == want)
                blk->order[m++] = cur[k];
    }
    blk->col_ptr[blk->num_colours] = m;
    return GETME_OK;
}

/* Level 0 cut again (bpart) so that the blocks that run, rather than
   the parts, come out in proportion to the shares: each part is what it
   lost to the first cut's interfaces (its blocks that did not run,
   count[] the ones that did) plus its share of the rest.  Otherwise the
   parts that keep their blocks along the interfaces would have more to
   run, and trimming them back would leave those for the next level again
   (lost: np entries of scratch). */
static void recut(const getme_blocks *blk, int32_t nb, int np,
                  int32_t *bpart, const int32_t *count, int64_t *lost)
{
    memset(lost, 0, (size_t)np * sizeof *lost);
    for (int32_t b = 0; b < nb; b++)
        lost[bpart[b]]++;
    int64_t rest = nb;
    for (int p = 0; p < np; p++) {
        lost[p] -= count[p];
        rest -= lost[p];
    }
    int64_t w = weight_sum(blk, np), c = 0, base = 0;
    int32_t b = 0;
    for (int p = 0; p < np; p++) {
        c += weight_of(blk, p);
        base += lost[p];
        int64_t end = p == np - 1 ? nb : base + cut_at(rest, c, w);
        end = end < b ? b : end > nb ? nb : end;
        for (; b < end; b++)
            bpart[b] = p;
    }
}

/* The visiting order (block_local.h), from the blocks' node lists; part[]
   has room for ws->nn entries (scratch).  Level 0: the blocks in order,
   cut into parts in proportion to the weights (equal: block b is in part
   b * num_parts / num_blocks); the blocks left after a level are dealt
   out again across the interfaces (deal_across). */
static getme_status build_order(getme_blocks *blk, const getme_ws *ws,
                                int32_t *part)
{
    int np = ws->nt > 0 ? ws->nt : 1;
    int32_t nb = ws->num_blocks;
    size_t nbs = (size_t)(nb ? nb : 1);
    blk->num_parts = np;
    blk->order = getme__malloc(nbs * sizeof *blk->order);
    blk->part_ptr = getme__calloc((size_t)GETME_ORDER_LEVELS * np + 1,
                                  sizeof *blk->part_ptr);
    int32_t *cur = getme__malloc(nbs * sizeof *cur);
    int32_t *bpart = getme__malloc(nbs * sizeof *bpart);
    getme_ranked *keys = getme__malloc(nbs * sizeof *keys);
    uint8_t *left = getme__malloc(nbs), *run = getme__malloc(nbs);
    int32_t *count = getme__malloc((size_t)np * sizeof *count);
    int64_t *lost = getme__malloc((size_t)np * sizeof *lost);
    getme_status st = GETME_ERR_NOMEM;
    if (!blk->order || !blk->part_ptr || !cur || !bpart ||
        !keys || !left || !run || !count || !lost)
        goto done;
    for (int32_t b = 0; b < nb; b++) {
        cur[b] = b;
        left[b] = 1;
    }
    cut_ranks(blk, np, cur, NULL, nb, bpart);
    int32_t ncur = nb, m = 0;
    for (int l = 0; l < GETME_ORDER_LEVELS; l++) {
        level_runs(blk, cur, ncur, bpart, part, np, run, count);
        if (l == 0 && np > 1) {
            recut(blk, nb, np, bpart, count, lost);
            level_runs(blk, cur, ncur, bpart, part, np, run, count);
        }
        /* A level's parts run side by side and end together, so a part
           with more blocks that run than its share of the poorest one's
           (the least one's count with equal weights) keeps its excess
           (its last ones) for the next level, or the colours: the thread
           with the smaller part would wait for it (full tets, 2 threads:
           423 against 273 blocks at level 1). */
        for (int p = 0; p < np; p++) { /* count[p] each */
            for (int32_t k = 0; k < ncur; k++)
                if (bpart[cur[k]] == p && run[k])
                    blk->order[m++] = cur[k];
            blk->part_ptr[l * np + p + 1] = m;
        }
        int poor = poorest(blk, count, np);
        int64_t cpoor = count[poor];
        int32_t next = blk->part_ptr[l * np];
        m = next;
        for (int p = 0; p < np; p++) {
            int32_t k0 = next;
            next = blk->part_ptr[l * np + p + 1];
            int64_t keep = cpoor * weight_of(blk, p) / weight_of(blk, poor);
            keep = keep < next - k0 ? keep : next - k0;
            for (int32_t k = k0; k < k0 + keep; k++) {
                blk->order[m++] = blk->order[k];
                left[blk->order[k]] = 0;
            }
            blk->part_ptr[l * np + p + 1] = m;
        }
        int32_t n = 0;
        for (int32_t k = 0; k < ncur; k++)
            if (left[cur[k]])
                cur[n++] = cur[k];
        ncur = n;
        if (l + 1 < GETME_ORDER_LEVELS)
            deal_next(blk, ws, cur, ncur, np, bpart, keys, part, count, run);
    }
    /* bpart is free now: the last level deals no further */
    st = colour_left(blk, cur, ncur, (uint32_t *)part, bpart, m);
done:
    free(cur), free(bpart), free(keys), free(left), free(run), free(count);
    free(lost);
    return st;
}

/* A level's times per thread (fb->last) into the feedback: each
   thread's time and blocks, and how long the level waited for its
   slowest thread beyond the threads' mean (what perfect balance would
   have saved). */
static void feed_level(struct getme_block_feedback *fb, const int32_t *ptr,
                       int np)
{
    double most = 0.0, sum = 0.0;
    for (int i = 0; i < np; i++) {
        int p = fb->perm[i];
        fb->busy[i] += fb->last[i];
        fb->work[i] += ptr[p + 1] - ptr[p];
        most = fb->last[i] > most ? fb->last[i] : most;
        sum += fb->last[i];
    }
    fb->wait += most - sum / np;
}

int64_t getme__blocks_run(const getme_blocks *blk, const getme_ws *ws,
                          int64_t (*f)(void *ctx, int32_t b), void *ctx)
{
    int64_t total = 0;
    int np = blk->num_parts;
    struct getme_block_feedback *fb = np > 1 ? blk->fb : NULL;
    for (int l = 0; l < GETME_ORDER_LEVELS; l++) {
        const int32_t *ptr = blk->part_ptr + l * np;
        int run = np > 1 && ptr[np] > ptr[0];
#pragma omp parallel for schedule(static, 1) num_threads(np) \
    reduction(+ : total) if (run)
        for (int i = 0; i < np; i++) { /* static, 1: thread i */
            int p = fb ? fb->perm[i] : i;
            double t0 = fb ? omp_get_wtime() : 0.0;
            for (int32_t k = ptr[p]; k < ptr[p + 1]; k++)
                total += f(ctx, blk->order[k]);
            if (fb) /* each thread its own entry */
                fb->last[i] = omp_get_wtime() - t0;
        }
        if (fb && run)
            feed_level(fb, ptr, np);
    }
    for (int c = 0; c < blk->num_colours; c++) {
        int32_t k0 = blk->col_ptr[c], k1 = blk->col_ptr[c + 1];
        int nt = c == blk->serial_colour ? 1 : ws->nt;
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt) \
    reduction(+ : total) if (k1 - k0 > 1)
        for (int32_t k = k0; k < k1; k++)
            total += f(ctx, blk->order[k]);
    }
    return total;
}

size_t getme__blocks_scratch_bytes(const getme_ws *ws)
{
    size_t nn = (size_t)(ws->nn ? ws->nn : 1);
    return (size_t)ws->nt * nn * sizeof(int32_t);
}

getme_status getme__blocks_build(getme_blocks *blk, const getme_ws *ws,
                                 void *scratch)
{
    memset(blk, 0, sizeof *blk);
    blk->group.n = -1;
    int nt = ws->nt;
    size_t nn = (size_t)(ws->nn ? ws->nn : 1);
    blk->nptr = getme__malloc(((size_t)ws->num_blocks + 1) * sizeof *blk->nptr);
    blk->local = getme__malloc(nn * sizeof *blk->local);
    /* The marks in the caller's scratch if it lends
       one (getme__adj_build: the same pages serve the inclusion-exclusion
       check next, and a fresh page costs ~3 ms per MiB to fault in on the
       VMs measured), else our own. */
    void *own = scratch ? NULL : getme__malloc(getme__blocks_scratch_bytes(ws));
    void *mem = scratch ? scratch : own;
    int32_t *mark = mem;
    getme_status st = GETME_ERR_NOMEM;
    if (!blk->nptr || !blk->local || !mem)
        goto done;
    memset(mark, 0, (size_t)nt * nn * sizeof *mark);
    blk->nptr[0] = 0;
#pragma omp parallel for schedule(dynamic, 16) num_threads(nt)
    for (int32_t b = 0; b < ws->num_blocks; b++) {
        size_t o = (size_t)omp_get_thread_num() * nn;
        blk->nptr[b + 1] = block_nodes(ws, b, mark + o, NULL);
    }
    int32_t big = 0, bige = 0;
    for (int32_t b = 0; b < ws->num_blocks; b++) {
        int64_t m = blk->nptr[b + 1];
        int32_t me = ws->block_start[b + 1] - ws->block_start[b];
        big = m > big ? (int32_t)m : big;
        bige = me > bige ? me : bige;
        blk->nptr[b + 1] += blk->nptr[b];
    }
    blk->max_nodes = big;
    blk->max_elems = bige;
    blk->bsize = bige > 0 ? bige : 1;
    for (int t = 0, nb = 0; t < GETME_NUM_TYPES; t++) {
        blk->tblock[t] = nb;
        nb += (ws->tstart[t + 1] - ws->tstart[t] + blk->bsize - 1) / blk->bsize;
    }
    if (big > UINT16_MAX + 1) { /* not with the workspace's 512-element
                                   blocks; refuse rather than wrap */
        st = GETME_ERR_NOMEM;
        goto done;
    }
    blk->nodes =
        getme__malloc((size_t)(blk->nptr[ws->num_blocks] ? blk->nptr[ws->num_blocks] : 1) *
                      sizeof *blk->nodes);
    if (!blk->nodes)
        goto done;
    if (alloc_scratch(blk, nt) != GETME_OK)
        goto done;
    memset(mark, 0, (size_t)nt * nn * sizeof *mark);
#pragma omp parallel for schedule(dynamic, 16) num_threads(nt)
    for (int32_t b = 0; b < ws->num_blocks; b++) {
        size_t o = (size_t)omp_get_thread_num() * nn;
        block_nodes(ws, b, mark + o, blk->nodes + blk->nptr[b]);
    }
    if (nt > 1)
        alloc_feedback(blk, nt);
    double t0 = omp_get_wtime();
    st = build_order(blk, ws, mark);
    if (blk->fb)
        blk->fb->cost = omp_get_wtime() - t0;
done:
    free(own);
    if (st != GETME_OK)
        getme__blocks_free(blk);
    return st;
}

/* The slowest thread's time over the mean when thread i runs part
   perm[i], with the speeds s[] (blocks per second) and the weights. */
static double imbalance(const getme_blocks *blk, const double *s,
                        const int32_t *perm, int np)
{
    double most = 0.0, mean = 0.0;
    for (int i = 0; i < np; i++) {
        double t = (double)blk->fb->weight[perm[i]] / s[i];
        most = t > most ? t : most;
        mean += t / np;
    }
    return most / mean;
}

/* perm[i], the part of thread i: the k-th fastest thread takes the k-th
   heaviest part (insertion sorts, stable: np is the thread count).
   scratch: 2 np entries. */
static void deal_by_speed(const getme_blocks *blk, const double *s, int np,
                          int32_t *perm, int32_t *scratch)
{
    int32_t *thr = scratch, *part = scratch + np;
    const int64_t *w = blk->fb->weight;
    for (int i = 0; i < np; i++) {
        int j = i;
        for (; j > 0 && s[thr[j - 1]] < s[i]; j--)
            thr[j] = thr[j - 1];
        thr[j] = i;
        for (j = i; j > 0 && w[part[j - 1]] < w[i]; j--)
            part[j] = part[j - 1];
        part[j] = i;
    }
    for (int k = 0; k < np; k++)
        perm[thr[k]] = part[k];
}

int getme__blocks_rebalance(getme_blocks *blk)
{
    struct getme_block_feedback *fb = blk->fb;
    int np = blk->num_parts;
    if (!fb || np < 2)
        return 0;
    double *s = fb->last; /* scratch now: the threads' speeds */
    for (int i = 0; i < np; i++) {
        if (!(fb->busy[i] > 0.0 && fb->work[i] > 0.0))
            return 0; /* not measured yet */
        s[i] = fb->work[i] / fb->busy[i];
    }
    int due = 0;
    if (imbalance(blk, s, fb->perm, np) > 1.03) {
        int32_t *perm = fb->deal; /* the new deal, then deal_by_speed's */
        deal_by_speed(blk, s, np, perm, perm + np);
        if (imbalance(blk, s, perm, np) <= 1.03) {
            memcpy(fb->perm, perm, (size_t)np * sizeof *perm);
        } else if (fb->wait < fb->cost) {
            return 0; /* real, but not worth a reorder yet: keep counting */
        } else {
            double sum = 0.0;
            memcpy(fb->prev_weight, fb->weight, (size_t)np * sizeof *fb->weight);
            memcpy(fb->prev_perm, fb->perm, (size_t)np * sizeof *fb->perm);
            for (int i = 0; i < np; i++)
                sum += s[i];
            for (int i = 0; i < np; i++) {
                int64_t v = llround(s[i] / sum * 1048576.0);
                fb->weight[i] = v > 0 ? v : 1;
            }
            due = 1;
        }
    }
    for (int i = 0; i < np; i++)
        fb->busy[i] = fb->work[i] = 0.0;
    fb->wait = 0.0;
    return due;
}

getme_status getme__blocks_reorder(getme_blocks *blk, const getme_ws *ws,
                                   int32_t *part, getme_block_order *old)
{
    *old = (getme_block_order){blk->order, blk->part_ptr, blk->col_ptr,
                               blk->num_colours, blk->serial_colour};
    blk->order = blk->part_ptr = blk->col_ptr = NULL;
    getme_status st = build_order(blk, ws, part);
    if (st == GETME_OK) {
        for (int i = 0; i < blk->num_parts; i++)
            blk->fb->perm[i] = i;
        return GETME_OK;
    }
    getme__blocks_settle(blk, old, 0);
    return st;
}

void getme__blocks_settle(getme_blocks *blk, getme_block_order *old,
                          int keep)
{
    if (keep) {
        free(old->order), free(old->part_ptr), free(old->col_ptr);
    } else {
        struct getme_block_feedback *fb = blk->fb;
        int np = blk->num_parts;
        free(blk->order), free(blk->part_ptr), free(blk->col_ptr);
        blk->order = old->order, blk->part_ptr = old->part_ptr;
        blk->col_ptr = old->col_ptr;
        blk->num_colours = old->num_colours;
        blk->serial_colour = old->serial_colour;
        memcpy(fb->weight, fb->prev_weight, (size_t)np * sizeof *fb->weight);
        memcpy(fb->perm, fb->prev_perm, (size_t)np * sizeof *fb->perm);
    }
    memset(old, 0, sizeof *old);
}

getme_status getme__blocks_group(getme_blocks *blk, const getme_ws *ws,
                                 const int32_t *list, int32_t n)
{
    struct getme_block_group *g = &blk->group;
    size_t nb = (size_t)ws->num_blocks;
    if (!g->ptr)
        g->ptr = getme__malloc((nb + 1) * sizeof *g->ptr);
    if (!g->cnt)
        g->cnt = getme__malloc((size_t)ws->nt * (nb ? nb : 1) * sizeof *g->cnt);
    if (n > g->cap) {
        free(g->pos);
        g->cap = 2 * (int64_t)n + 64;
        g->pos = getme__malloc((size_t)g->cap * sizeof *g->pos);
    }
    g->n = -1;
    if (!g->ptr || !g->cnt || !g->pos) {
        g->cap = 0;
        return GETME_ERR_NOMEM;
    }
    int32_t *ptr = g->ptr, *pos = g->pos;
#pragma omp parallel num_threads(ws->nt)
    {
        /* thread p counts and places the entries [k0, k1): the same
           share in both passes, and within a block thread p's entries
           follow thread p - 1's, so every block lists its entries in
           ascending order for any number of threads */
        int np = omp_get_num_threads(), p = omp_get_thread_num();
        int32_t k0 = (int32_t)((int64_t)n * p / np);
        int32_t k1 = (int32_t)((int64_t)n * (p + 1) / np);
        int32_t *cnt = g->cnt + (size_t)p * nb;
        memset(cnt, 0, nb * sizeof *cnt);
        for (int32_t k = k0; k < k1; k++) {
            int32_t e = list[k];
            cnt[getme__blocks_of(blk, ws, getme__ws_type(ws, e), e)]++;
        }
#pragma omp barrier
#pragma omp single
        {
            int32_t at = 0;
            for (size_t b = 0; b < nb; b++) {
                ptr[b] = at;
                for (int q = 0; q < np; q++) {
                    int32_t c = g->cnt[(size_t)q * nb + b];
                    g->cnt[(size_t)q * nb + b] = at;
                    at += c;
                }
            }
            ptr[nb] = at;
        } /* implicit barrier */
        for (int32_t k = k0; k < k1; k++) {
            int32_t e = list[k];
            pos[cnt[getme__blocks_of(blk, ws, getme__ws_type(ws, e), e)]++] = k;
        }
    }
    g->n = n;
    return GETME_OK;
}
