/*
 * block_edges.h -- each block's own list of the edges its tets use, and
 * every tet edge's index in that list, so the q_mean stage's two sweeps
 * read and update the Eq. 9 edge sums (S_e) in small block-local arrays.
 *
 * Why: in a q_mean iteration every tet reads the S_e of its six edges
 * (the scatter's weights) and adds its quality's change to them (the
 * relaxation's trial pass).  Through the global edge ids that is, per tet
 * and sweep, four packed edge offsets, six slots and six scattered loads
 * or read-modify-writes: measurement builds without the trial pass's S_e
 * update ran a q_mean iteration of the full benchmark tets ~20 % faster
 * (docs/bench.md, session 20).  A block of 512 tets has ~800-1100
 * distinct edges, each in ~3-6 of its tets: with the block's list, the
 * scatter gathers each edge's S_e once per block, and the trial pass sums
 * the changes in the thread's local array and adds each edge's total to
 * S_e once.  Blocks that run at the same time share no node, hence no
 * edge, and the sums are exact integers (exact.h), so the result is the
 * same bits as the global path for any number of threads.
 *
 * Only for meshes of tets alone, built when the q_mean stage starts and
 * freed with the blocks' node lists when it ends (getme__blocks_free_local):
 * 12 bytes per tet for the indices and 4 per list entry (~2 per tet), at
 * the peak of memory.  For hexes (24 bytes per hex) it would lift the
 * peak above the memory target; they keep the global path.
 */
#ifndef GETME_BLOCK_EDGES_H
#define GETME_BLOCK_EDGES_H

#include "adjacency.h"

/* Build blk's edge lists for the run's mesh, or leave blk->ledge NULL
   when the mesh is not tets alone or memory is short (the sweeps then
   take the global path: the same result).  Parallel over blocks; the
   lists do not depend on the threads. */
void getme__blocks_edges(getme_blocks *blk, const getme_adj *adj,
                         const getme_ws *ws);

/* Free the edge lists (part of getme__blocks_free_local). */
void getme__blocks_free_edges(getme_blocks *blk);

/* The edge-list indices of tet e's six edges (blk->ledge != NULL). */
static inline const uint16_t *getme__blocks_ledge(const getme_blocks *blk,
                                                  int32_t e)
{
    return blk->ledge + 6 * (int64_t)e;
}

/* Thread th's local S_e array (blk->estride entries). */
static inline int64_t *getme__blocks_esl(const getme_blocks *blk, int th)
{
    return blk->esl + (int64_t)th * blk->estride;
}

#endif /* GETME_BLOCK_EDGES_H */
