/*
 * revert.h -- GETMe adaptive never ends below the input's q*_min
 * (keep_best): the input's coordinates, and putting back the nodes of the
 * elements that ended below it (revert.c says why and how).
 */
#ifndef GETME_REVERT_H
#define GETME_REVERT_H

#include "smooth_internal.h"

typedef struct getme_input {
    double *x;         /* 3 * nn: the input's coordinates, or NULL (off) */
    double q_min_star; /* the input's q*_min                             */
} getme_input;

/* Keep ws->x, the input whose q*_min is q_min_star (getme_result's
   q_min_star_initial), if on; in is zeroed first.  GETME_OK or
   GETME_ERR_NOMEM. */
getme_status getme__input_keep(getme_input *in, const getme_ws *ws,
                               double q_min_star, int on);

/* Put back at their input positions the free nodes of every free element
   below the input's q*_min, and of every element that falls below it
   because of that, until none does; q is kept current.  *count: nodes put
   back.  GETME_OK, or GETME_ERR_NOMEM with a valid mesh (some nodes may be
   back; q is current for them). */
getme_status getme__input_revert(const getme_input *in, getme_ws *ws,
                                 double *q, int64_t *count);

void getme__input_free(getme_input *in);

#endif /* GETME_REVERT_H */
