/*
 * finish_levels.h -- conflict levels of a finishing pass's list, so that
 * the list's elements can be worked on in parallel with exactly the
 * serial result (finish.c, "Levelled sweeps"; docs/method.md).
 *
 * improve() on list element i writes the coordinates of its free nodes
 * W_i and the qualities of its patch P_i, the elements around W_i, and it
 * reads the coordinates of every node of P_i (an element without free
 * nodes only reads its own quality: P_i is that element).  Elements i < j
 * conflict when one writes what the other reads.  That is exactly when
 * P_i and P_j share an element: a node a of W_i among P_j's nodes lies in
 * an element E of P_j, and E holds a, so E is in P_i; conversely a shared
 * E holds a free node of i, which j reads.  So a mark per element is
 * enough: level(j) is one more than the highest level of an earlier
 * element whose patch holds an element of P_j, the elements of one level
 * share nothing, and running the levels in order, each level's elements
 * in any order or at once, gives every element exactly the state the
 * serial order gives it.
 */
#ifndef GETME_FINISH_LEVELS_H
#define GETME_FINISH_LEVELS_H

#include "stars.h"
#include "workspace.h"

typedef struct getme_levels {
    int32_t *level;  /* n: the level of list position i                   */
    int32_t *order;  /* n: list positions by level, ascending within one  */
    int32_t *ptr;    /* num + 1: level L is order[ptr[L] .. ptr[L + 1])    */
    int32_t num;
    int64_t cap, cap_ptr;
    /* Chunks of `chunk` consecutive list positions get levels of their
       own, above every earlier chunk's: chunk h is positions
       [h chunk, (h + 1) chunk) and levels [cfirst[h], cfirst[h + 1]) (the
       finishing step checks its budget after each chunk). */
    int32_t chunk, num_chunks;
    int32_t *cfirst;
    int64_t cap_c;
    /* The elements whose marks a build set (cleared before it returns)
       and one patch's elements (repeats allowed): scratch. */
    int32_t *touched;
    int64_t used, cap_t;
    int32_t *patch;
    int64_t cap_p;
} getme_levels;

/* The levels of list[0..n) on ws (free nodes: !ws->fixed), in chunks of
   chunk >= 1 positions.  mark: ws->ne entries, all zero, and zero again
   on return; a build keeps 1 + the highest level whose patch held each
   element there (the finishing step lends the run's element list, free
   after the iterations).  A hash table over the few elements a pass
   touches, used before so that no array over all elements was needed,
   took up to 3x longer: 0.139 against 0.053 s for a first pass of an
   11.2M-tet CAD part on 2 threads.  GETME_OK or GETME_ERR_NOMEM.  lv
   starts zeroed and is reused across passes. */
getme_status getme__levels_build(getme_levels *lv, const getme_ws *ws,
                                 const getme_ranked *list, int32_t n,
                                 int32_t chunk, int32_t *mark);

void getme__levels_free(getme_levels *lv);

#endif /* GETME_FINISH_LEVELS_H */
