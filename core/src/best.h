/*
 * best.h -- keep_best's copy of the best mesh, as an undo log.
 *
 * GETMe adaptive returns the mesh with the best q*_min seen from the end of
 * the q_mean stage on (getme_adaptive.c).  A whole copy of the coordinates
 * costs 24 B per node (25 B per hex) for the whole run.  But after the
 * q_mean stage only the nodes of the elements being transformed move (the
 * free nodes of run->tlist: I_T), a small part of the mesh.  So the best
 * mesh is kept as the current coordinates plus, for every node that moved
 * since the best iteration, its coordinates then: logged just before the
 * iteration that may move it, once per node (a bit per node says it is
 * logged).  Restoring writes those coordinates back, bit for bit what a
 * whole copy would give.
 *
 * If the log would hold more than a quarter of the nodes (28 B each), it
 * becomes a whole copy (the current coordinates with the log applied) and
 * stays one.  Distributed runs keep a whole copy from the start: their I_T
 * also has nodes of other processes' elements.
 */
#ifndef GETME_BEST_H
#define GETME_BEST_H

#include "smooth_internal.h"

typedef struct getme_best {
    int on;          /* keep_best is set                                  */
    double *whole;   /* 3 * nn: the best coordinates, or NULL (the log)   */
    uint64_t *seen;  /* nn bits: node logged since the best iteration     */
    int32_t *node;   /* logged nodes                                      */
    double *x;       /* 3 per logged node: its coordinates at the best    */
    int64_t n, cap;  /* logged, room                                      */
} getme_best;

/* Start (b zeroed first); on = params->keep_best.  GETME_OK or
   GETME_ERR_NOMEM. */
getme_status getme__best_init(getme_best *b, const getme_run *run, int on);

/* The current coordinates (ws->x) are the best. */
void getme__best_take(getme_best *b, const getme_ws *ws);

/* Before a q*_min iteration: log the nodes it may move (the free nodes of
   run->tlist's elements) not logged yet.  GETME_OK or GETME_ERR_NOMEM. */
getme_status getme__best_note(getme_best *b, const getme_run *run);

/* run->ws->x becomes the best coordinates and run->q their qualities:
   after a log, those of the stars of the nodes put back (no other element
   changed since the best iteration's qualities, which were current then;
   every element's in one parallel sweep when those stars are large),
   after a whole copy every element's.  GETME_OK; GETME_CHECK_SUMS builds
   compare with a recomputation of every element (GETME_ERR_STATE if they
   differ, or GETME_ERR_NOMEM without room for the check). */
getme_status getme__best_restore(getme_best *b, getme_run *run);

void getme__best_free(getme_best *b);

#endif /* GETME_BEST_H */
