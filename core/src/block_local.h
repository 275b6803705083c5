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
 * one colour share no node, so the per-node additions need no atomics, and
 * the sums are exact integers (exact.h), so their order does not matter:
 * the result stays the same bits for any thread count.
 *
 * Built once per smoothing run from the workspace (getme__blocks_build).
 * Memory: 2 bytes per element node (tets 8 B, hexes 16 B per element)
 * plus 4 bytes per (block, node) pair (~1.5 B per tet), plus per-thread
 * scratch for the largest block.
 */
#ifndef GETME_BLOCK_LOCAL_H
#define GETME_BLOCK_LOCAL_H

#include "exact.h"
#include "workspace.h"

typedef struct getme_blocks {
    int64_t *nptr;   /* num_blocks + 1: block b's nodes are
                        nodes[nptr[b] .. nptr[b + 1])                     */
    int32_t *nodes;  /* global node indices, in first-use order           */
    uint16_t *lconn; /* like ws->conn, but each entry the node's index in
                        its block's list (< 8 * 512, fits 16 bits)        */
    int32_t max_nodes; /* the largest block's node count                  */
    int32_t max_elems; /* the largest block's element count               */
    /* Per-thread scratch for one block at a time (max_nodes entries each):
       the block's coordinates, exact sums (exact.h), S_v sums and flags. */
    struct getme_block_scratch {
        double *x;      /* 3 per node                                     */
        getme_fx *acc;  /* 4 per node: sum w x' (3), sum w                */
        int64_t *nsum;  /* S_v                                            */
        uint8_t *flag;  /* 1: fixed node; 2: in I_T                       */
        int64_t *wf;    /* max_elems: the elements' integer weights       */
        int32_t *list;  /* max_elems: the elements transformed            */
    } *scratch;         /* ws->nt                                         */
} getme_blocks;

/* Build it for ws (parallel over blocks, deterministic).  GETME_OK or
   GETME_ERR_NOMEM. */
getme_status getme__blocks_build(getme_blocks *blk, const getme_ws *ws);
void getme__blocks_free(getme_blocks *blk);

/* The local node indices of element e (type t). */
static inline const uint16_t *getme__blocks_lnodes(const getme_blocks *blk,
                                                   const getme_ws *ws, int t,
                                                   int32_t e)
{
    return blk->lconn + ws->coff[t] + (int64_t)(e - ws->tstart[t]) * getme__nv[t];
}

#endif /* GETME_BLOCK_LOCAL_H */
