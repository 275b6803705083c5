/*
 * patch.h -- local max-min optimisation of a few nodes over the elements
 * around them (docs/method.md, "The finishing step").
 *
 * A patch is the set of elements that contain at least one of the moving
 * nodes.  Its objective is the smallest mean ratio among them; a move is
 * accepted only when that minimum strictly rises, so no element of the
 * patch ends below the patch's old minimum and the mesh's q*_min can never
 * decrease.  The search direction is the steepest ascent of the nonsmooth
 * max-min problem: the minimum-norm point of the convex hull of the
 * gradients of the nearly active elements (Freitag and Ollivier-Gooch's
 * active-set idea), found by a fixed number of Frank-Wolfe steps; the step
 * length is found by halving.  Everything is serial and in a fixed order,
 * so results do not depend on the thread count.
 *
 * Both the smoother's finishing step (finish.c, on the workspace) and the
 * worst-element report (worst.c, on the caller's mesh) use it, which is
 * why a patch element is described by a type and a pointer to its node
 * indices rather than by a workspace element id.
 */
#ifndef GETME_PATCH_H
#define GETME_PATCH_H

#include "internal.h"

#define GETME_PATCH_MAX_MOVE 8 /* moving nodes at most (one hex) */

/* The finishing step's getme_patch.loss (see there and docs/method.md). */
#define GETME_PATCH_LOSS 1.0

typedef struct getme_patch {
    double *x;       /* coordinates, 3 per node; trial moves write here and
                        are undone bit for bit when rejected              */
    int mirror;      /* planar mesh stored clockwise: negate y on gather  */
    int guard;       /* corner guard on: a corner (getme__corner_sj) may
                        not end below min(its old value, floor)           */
    double floor;
    double skip_q[GETME_NUM_TYPES]; /* per type, a quality from which on the
                        worst corner is provably >= floor (getme_run's
                        guard_skip_q), so it is not computed: it could
                        not reject a move (2: always computed)            */
    double loss;     /* a move may lower the patch's total quality by at
                        most loss times the rise of its minimum ...        */
    double budget;   /* ... and by at most this: the total quality that
                        kept moves gained so far, less what they spent (0
                        at the start: q_mean never ends lower)            */
    double change;   /* scratch: the last trial's change of the total    */
    double allowed_max; /* the largest loss * gain of a trial that got as
                        far as the total's test (the caller resets it);
                        the finishing step's memo of failed climbs uses it */
    double *log;     /* the change of every accepted move, in order, while
                        nlog < cap_log (nlog counts on beyond it), or
                        NULL: a levelled finishing sweep (finish.c) runs
                        with an unbounded budget and replays these in the
                        list's order against the serial budget           */
    int32_t nlog, cap_log;
    /* the elements (filled by the caller with getme__patch_add) */
    int32_t n, cap;
    int8_t *type;
    const int32_t **conn;
    int32_t *id;     /* caller's element id, for writing qualities back   */
    double *q;       /* quality at the accepted coordinates               */
    double *sj;      /* worst corner at the start of the optimisation     */
    double *qt;      /* scratch: trial qualities                          */
    const struct getme_ws *ws; /* finishing step: x is ws->x and ids are
                        workspace elements, checked at second-order nodes */
    /* Trials move only the moving nodes, so during one climb or toward
       call the other coordinates of every lane group are gathered once
       (patch.c, lane_cache) and each trial writes just the moving ones:
       per group of GETME_LANES elements its lane-major coordinates
       (3 GETME_MAX_NV rows of GETME_LANES), NULL without memory. */
    double *lx;
    int8_t *lok;     /* per group: 1 if lx holds it (one type with lanes) */
    int32_t *mpos;   /* the moving nodes' places in lx (their x row) ...  */
    uint8_t *midx;   /* ... and which moving node each is                 */
    int32_t nmpos;
    int cached;      /* lx is current (inside a climb or toward call)     */
    /* Curved second-order elements: the same for their dependent nodes.
       Per element, GETME_HO_MAX_DEP slots (getme__ho_dep_split): those
       that do not follow a moving node placed once per call (hdep, 3 per
       slot), the others (hmov 1) placed per trial.  hok: the element has
       them (0: checked as before); NULL without memory. */
    double *hdep;
    uint8_t *hmov, *hok;
    int32_t hcap;
    int hcached;
} getme_patch;

/* Room for cap elements; GETME_OK or GETME_ERR_NOMEM. */
getme_status getme__patch_init(getme_patch *p, int32_t cap);
void getme__patch_free(getme_patch *p);

/* Empty the element list (keeps x, mirror, guard, floor). */
static inline void getme__patch_clear(getme_patch *p) { p->n = 0; }

/* Add one element (type, node indices, caller's id); GETME_ERR_NOMEM if the
   patch is full after growing failed. */
getme_status getme__patch_add(getme_patch *p, int type, const int32_t *conn,
                              int32_t id);

/* Quality and worst corner of every patch element at p->x; returns the
   patch's minimum quality. */
double getme__patch_eval(getme_patch *p);

/* The same, but the quality of an element of a first-order patch that
   needs no corner is known[its id] (the finishing step: run->q holds those
   bits already); lane groups with a guarded corner are computed. */
double getme__patch_eval_known(getme_patch *p, const double *known);

/*
 * Raise the patch minimum by moving the k nodes mv[] (free nodes the
 * caller chose; every patch element must contain at least one of them):
 * up to max_steps accepted steps.  With apply = 0 nothing is kept: it
 * returns 1 if an improving step exists (the report's "local optimum"
 * test).  With apply = 1 returns the number of accepted steps and leaves
 * p->x, p->q at the improved state.  getme__patch_eval must have run.
 */
int getme__patch_climb(getme_patch *p, const int32_t *mv, int k,
                       int max_steps, int apply);

/*
 * Try moving the k nodes mv[] toward target positions tg (3 per node)
 * with the relaxation factors 1/2, 1/4, ..., 1/64; keep the first that
 * raises the patch minimum.  Returns 1 if one was kept.
 */
int getme__patch_toward(getme_patch *p, const int32_t *mv, int k,
                        const double *tg);

#endif /* GETME_PATCH_H */
