/*
 * regular_elements.h -- the regular element of each type (all edges 1, node
 * order of getme.h), shared by the core tests.  Include after getme.h.
 */
#ifndef GETME_TEST_REGULAR_ELEMENTS_H
#define GETME_TEST_REGULAR_ELEMENTS_H

#define S3_2 0.86602540378443864676 /* sqrt3/2 */

static const double reg_tet[] = {0, 0, 0, 1, 0, 0, 0.5, S3_2, 0,
                                 0.5, 0.28867513459481288225,
                                 0.81649658092772603273};
static const double reg_hex[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
static const double reg_prism[] = {0, 0, 0, 1, 0, 0, 0.5, S3_2, 0,
                                   0, 0, 1, 1, 0, 1, 0.5, S3_2, 1};
static const double reg_pyramid[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                     0.5, 0.5, 0.70710678118654752440};
static const double reg_tri[] = {0, 0, 0, 1, 0, 0, 0.5, S3_2, 0};
static const double reg_quad[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};

static const double *const regular[GETME_NUM_TYPES] = {
    reg_tet, reg_hex, reg_prism, reg_pyramid, reg_tri, reg_quad};

#endif /* GETME_TEST_REGULAR_ELEMENTS_H */
