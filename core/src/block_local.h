/*
 * block_local.h -- each colour block's own node list and local
 * connectivity, so the stage-1 kernels can work on a block's nodes in
 * small block-local arrays instead of at scattered places of the global
 * per-node arrays.
 *
 * Why: a block is 512 consecutive (Morton-ordered) elements; a tet block
 * has ~150-250 distinct nodes, each in ~10 of its elements.  Summing the
 * block's contributions into block-local accumulators (in L1) and adding
 * each local sum to its node once replaces ~2000 read-modify-writes of
 * 64-byte node sums at scattered addresses by ~200; the same for the
 * coordinates the block reads and the S_v sums of its weights.  Blocks of
 * one colour share no node (nor do blocks run at the same time in the
 * order below), so the per-node additions need no atomics, and
 * the sums are exact integers (exact.h), so their order does not matter:
 * the result stays the same bits for any thread count.
 *
 * Built once per smoothing run from the workspace (getme__blocks_build).
 * Memory: 4 bytes per (block, node) pair (~1.5 B per tet, ~9 B per hex)
 * and 2 bytes per node, plus per-thread scratch for the largest block.
 * The local connectivity itself is not kept: a block's is rebuilt in its
 * thread's scratch when the block runs (getme__blocks_localise), from
 * ws->conn, which the kernels read anyway.  Kept, it was 2 bytes per
 * element node (tets 8 B, hexes 16 B per element) at the peak of memory;
 * rebuilding it costs a pass over the block's node list and its
 * connectivity, both in cache for the block's work right after.
 *
 * The order the sweeps visit the blocks in (getme__blocks_run): the
 * colours alone are race-free, but a colour's blocks are spread over the
 * whole mesh, so each sweep went over the mesh once per colour and every
 * block found its nodes' data (coordinates, sums, neighbours' q) out of
 * cache: element order cost ~25 % less in the scatter (perf, 1M tets, one
 * thread).  So the blocks are cut into one contiguous part per thread,
 * and each thread runs its part's blocks in element order, except those
 * that share a node with another part's that run: the parts in order,
 * each keeps its side of the interfaces with the parts after it
 * (block_local.c, level_runs), and the cut is placed so that the parts
 * run equal shares (recut).  The blocks left (one side of each
 * interface) are dealt into parts again by position across the
 * interfaces (deal_next), twice, and the few left after that run colour
 * by colour as before.  Any race-free order gives the same bits: the
 * sums are exact integers (exact.h) and every other result is per
 * element.
 */
#ifndef GETME_BLOCK_LOCAL_H
#define GETME_BLOCK_LOCAL_H

#include "exact.h"
#include "workspace.h"

/* Rounds of parts before the colours take the rest (build_order). */
#define GETME_ORDER_LEVELS 3

typedef struct getme_blocks {
    int64_t *nptr;   /* num_blocks + 1: block b's nodes are
                        nodes[nptr[b] .. nptr[b + 1])                     */
    int32_t *nodes;  /* global node indices, in first-use order; during
                        a GETMe adaptive run the sign bit marks a node's
                        last block (getme_adaptive.c mark_last): read
                        them as nodes[k] & INT32_MAX                      */
    uint16_t *local; /* nn: node n's index in the list of the block that
                        last ran getme__blocks_localise with it (< 8 * 512,
                        fits 16 bits); garbage for a node until then.
                        Shared by the threads: blocks that run at the
                        same time share no node, so they write and read
                        different entries, and the blocks holding a node
                        run one after another (getme__blocks_run)        */
    int32_t max_nodes; /* the largest block's node count                  */
    int32_t max_elems; /* the largest block's element count               */
    /* Per-thread scratch for one block at a time (max_nodes entries each):
       the block's coordinates, exact sums (exact.h), S_v sums and flags. */
    struct getme_block_scratch {
        double *x;      /* 3 per node                                     */
        getme_fx *acc;  /* 4 per node: sum w x' (3), sum w                */
        int64_t *nsum;  /* S_v                                            */
        int32_t *slot;  /* the nodes' entries in a pool of sums
                           (getme_run.slot), if the run has one          */
        uint8_t *flag;  /* 1: fixed node; 2: in I_T                       */
        int64_t *wf;    /* max_elems: the elements' integer weights       */
        int32_t *list;  /* max_elems: the elements transformed            */
        uint16_t *lconn; /* max_elems GETME_MAX_NV: the running block's
                            local connectivity (getme__blocks_localise):
                            like ws->conn from the block's first element,
                            each entry the node's index in its list       */
    } *scratch;         /* ws->nt                                         */
    /* The blocks' own edge lists (block_edges.h), or ledge NULL: block
       b's edges are edges[eptr[b] .. eptr[b + 1]) (global edge ids, -1
       for a missing slot), tet e's edge j is entry ledge[6 e + j] of its
       block's list; esl holds ws->nt local S_e arrays, estride apart. */
    int64_t *eptr;
    int32_t *edges;
    uint16_t *ledge;
    int64_t *esl;
    int32_t estride;
    /* The visiting order (see above): at level l, part p's interior
       blocks are order[part_ptr[l np + p] .. part_ptr[l np + p + 1]); then
       the blocks left, of colour c, order[col_ptr[c] .. col_ptr[c + 1])
       (col_ptr[0] = part_ptr[GETME_ORDER_LEVELS np]). */
    int num_parts;      /* np = ws->nt                                    */
    int32_t *order;     /* num_blocks                                     */
    int32_t *part_ptr;  /* GETME_ORDER_LEVELS np + 1                      */
    int32_t *col_ptr;   /* num_colours + 1                                */
    int num_colours;    /* of the blocks left after the levels            */
    int serial_colour;  /* the colour whose blocks run one by one (no free
                           colour was left for them), or -1              */
    /* The parts' shares and the timing feedback of getme__blocks_rebalance
       (see there); fb NULL: one part, or no memory for it (the shares
       then stay equal).  Only the schedule depends on these times, never
       a result. */
    struct getme_block_feedback {
        int64_t *weight; /* np: part p's share of each level's blocks is
                            weight[p] / (the sum); all equal at the build */
        int32_t *perm;   /* np: thread i runs part perm[i] of each level  */
        int64_t *prev_weight; /* np: weight and perm before the last     */
        int32_t *prev_perm;   /* rebalance that asked for a reorder      */
        int32_t *deal;   /* 3 np: scratch of getme__blocks_rebalance      */
        double *busy;    /* np: seconds thread i's parts ran since the
                            last rebalance (written by getme__blocks_run) */
        double *work;    /* np: blocks those parts hold                   */
        double *last;    /* np: the current level's seconds per thread    */
        double wait;     /* seconds the levels' parts spent waiting for
                            their slowest one since the last rebalance    */
        double cost;     /* seconds the last reorder took, with its
                            caller's work after it (mark_last, slots)     */
    } *fb;
    /* Element e of type t is in block tblock[t] + (e - ws->tstart[t]) /
       bsize (getme__blocks_of): the workspace cuts each type's range into
       blocks of one size, and bsize, the largest block's element count,
       is that size (or, with no full block, above every type's count). */
    int32_t tblock[GETME_NUM_TYPES];
    int32_t bsize;
    /* A list of elements grouped by block (getme__blocks_group), so the
       q*_min stage's scatters over a few elements can run in the race-free
       order too: block b's entries are the positions in the list
       pos[ptr[b] .. ptr[b + 1]), ascending. */
    struct getme_block_group {
        int32_t *ptr;   /* num_blocks + 1                                 */
        int32_t *cnt;   /* ws->nt num_blocks: per-thread counts, scratch  */
        int32_t *pos;   /* cap                                            */
        int64_t cap;
        int32_t n;      /* the list's length, -1 if not grouped (the
                           caller sets it when its list changes)         */
    } group;
} getme_blocks;

/* Build it for ws (parallel over blocks, deterministic).  scratch: NULL,
   or getme__blocks_scratch_bytes(ws) bytes the caller lends for the
   build's temporaries (their contents are garbage after).  GETME_OK or
   GETME_ERR_NOMEM. */
getme_status getme__blocks_build(getme_blocks *blk, const getme_ws *ws,
                                 void *scratch);
size_t getme__blocks_scratch_bytes(const getme_ws *ws);
void getme__blocks_free(getme_blocks *blk);
/* Free only the blocks' node lists and local indices (nptr, nodes,
   local: ~2 B per tet, ~11 B per hex), which only the q_mean stage's
   block kernel reads; the visiting order and the scratch stay for the
   sweeps of the q*_min stage (getme__blocks_run). */
void getme__blocks_free_local(getme_blocks *blk);

/* f(ctx, b) for every block b of ws, in blk's race-free order, on
   ws->nt threads (blocks running at the same time share no node).  Returns
   the sum of f's results. */
int64_t getme__blocks_run(const getme_blocks *blk, const getme_ws *ws,
                          int64_t (*f)(void *ctx, int32_t b), void *ctx);

/* Balancing the parts to the threads' speeds.  Why: each level's parts
   run side by side and end together, so the level lasts as long as its
   slowest part.  The parts hold equal work, but the threads do not run
   at equal speed: on the 2-vCPU VMs measured one vCPU took 30-55 %
   longer than the other over the same loop for stretches of several
   iterations (another guest on its core, docs/bench.md session 33), and
   hybrid CPUs have fast and slow cores by design; the fast thread then
   waited a quarter to a third of every level.  So
   getme__blocks_run times each part's loops, and between two q_mean
   iterations getme__blocks_rebalance turns the threads' measured speeds
   (blocks per second) into shares: the level-0 cut and every level's
   trimming give each part blocks in proportion to its share.

   The slow vCPU is not always the same thread's: the kernel moves
   threads between CPUs, and then the shares fit the threads the wrong
   way round.  So the parts are first dealt to the threads again (the
   largest part to the fastest thread, fb->perm), which costs nothing;
   only if that cannot balance them are the blocks dealt again, and only
   once the time lost waiting since the last rebalance is at least what a
   reorder costs (fb->cost; the ski-rental rule: never more than twice
   the better choice's cost, whatever the future).

   Returns 1, with the new shares in weight[] (thread i's part i), if the
   blocks should be dealt again; 0 otherwise (the parts perhaps dealt to
   other threads; the feedback then restarts, or keeps accumulating while
   the imbalance is real but has not cost a reorder yet).  Balanced means
   the slowest thread's predicted time within 3 % of the mean. */
int getme__blocks_rebalance(getme_blocks *blk);

/* A visiting order set aside by getme__blocks_reorder. */
typedef struct getme_block_order {
    int32_t *order, *part_ptr, *col_ptr;
    int num_colours, serial_colour;
} getme_block_order;

/* Deal the blocks again with the shares in blk->fb->weight: a new
   visiting order (the node lists must still be there: before
   getme__blocks_free_local); thread i then runs part i.  The old order
   goes to *old until getme__blocks_settle.  part: scratch of ws->nn
   entries.  GETME_OK, or GETME_ERR_NOMEM with the order as it was (and
   nothing to settle).  The caller redoes what depends on the order
   (getme_adaptive.c: mark_last, the pool's slots). */
getme_status getme__blocks_reorder(getme_blocks *blk, const getme_ws *ws,
                                   int32_t *part, getme_block_order *old);

/* After getme__blocks_reorder: keep the new order (keep 1; the old one
   is freed), or go back to the old one, with the shares and the threads'
   parts it had (keep 0; the new one is freed). */
void getme__blocks_settle(getme_blocks *blk, getme_block_order *old,
                          int keep);

/* The block of element e (type t). */
static inline int32_t getme__blocks_of(const getme_blocks *blk,
                                       const getme_ws *ws, int t, int32_t e)
{
    return blk->tblock[t] + (e - ws->tstart[t]) / blk->bsize;
}

/* blk->group for the elements list[0..n): in parallel on ws->nt threads,
   each counting, then placing, the entries of its share of the list; the
   result does not depend on the threads.  GETME_OK or GETME_ERR_NOMEM
   (the group is then empty and the caller goes without it). */
getme_status getme__blocks_group(getme_blocks *blk, const getme_ws *ws,
                                 const int32_t *list, int32_t n);

/* Block b's local connectivity into scr->lconn (the scratch of the
   thread that runs b): each of its nodes' index in its list into
   blk->local, then each element node's through it.  The block's node
   list holds every node of its elements (getme__blocks_build), so every
   entry read was written just before, by this block. */
static inline void getme__blocks_localise(const getme_blocks *blk,
                                          const getme_ws *ws, int32_t b,
                                          struct getme_block_scratch *scr)
{
    const int32_t *gn = blk->nodes + blk->nptr[b];
    int32_t m = (int32_t)(blk->nptr[b + 1] - blk->nptr[b]);
    uint16_t *local = blk->local;
    for (int32_t k = 0; k < m; k++) /* the sign bit: mark_last */
        local[gn[k] & INT32_MAX] = (uint16_t)k;
    int32_t e0 = ws->block_start[b], e1 = ws->block_start[b + 1];
    if (e1 <= e0)
        return;
    int t = getme__ws_type(ws, e0);
    const int32_t *c = getme__ws_nodes(ws, t, e0);
    int64_t len = (int64_t)(e1 - e0) * getme__nv[t];
    uint16_t *lc = scr->lconn;
    for (int64_t k = 0; k < len; k++)
        lc[k] = local[c[k]];
}

/* The local node indices of the j-th element (nv nodes) of the block
   last localised into scr. */
static inline const uint16_t *
getme__blocks_lnodes(const struct getme_block_scratch *scr, int nv, int32_t j)
{
    return scr->lconn + (int64_t)j * nv;
}

#endif /* GETME_BLOCK_LOCAL_H */
