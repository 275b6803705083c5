/*
 * test_transform.c -- the regularizing transformations through
 * getme_element_transform().
 *
 * Property test per type and sigma: 1000 random valid elements (the regular
 * element with every node moved at random, fixed seed) must reach q > 0.999
 * within 50 steps, stay valid at every step and keep their edge-length sum
 * (perimeter for planar types) and their centroid.  Also: the regular element is a fixed point
 * up to similarity, the map commutes with rotations and translations, and
 * bad arguments are refused.  A summary line per type and sigma (worst q
 * after 50 steps, mean steps to reach 0.999) goes to stdout.
 */
#include "check.h"

#include <getme.h>

#include <math.h>
#include <stdint.h>
#include <string.h>

#define NUM_ELEMENTS 1000
#define NUM_STEPS 50
#define TARGET_Q 0.999

#define RANDOM_GEOMETRY_SEED 0x7a11cafe2024ULL
#include "random_geometry.h"

/* ---- element tables ----------------------------------------------------- */

#include "regular_elements.h"

/* Edges of each type (planar: the boundary cycle). */
static const int num_edges[GETME_NUM_TYPES] = {6, 12, 9, 8, 3, 4};
static const int edges[GETME_NUM_TYPES][12][2] = {
    {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}},
    {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4},
     {0, 4}, {1, 5}, {2, 6}, {3, 7}},
    {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}},
    {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}},
    {{0, 1}, {1, 2}, {2, 0}},
    {{0, 1}, {1, 2}, {2, 3}, {3, 0}}};

static int is_planar(int t) { return t == GETME_TRI || t == GETME_QUAD; }

static int nodes_of(int t) { return getme_type_num_nodes((getme_elem_type)t); }

static double quality(int t, const double *x)
{
    return getme_element_quality((getme_elem_type)t, x);
}

static double edge_sum(int t, const double *x)
{
    double s = 0.0;
    for (int k = 0; k < num_edges[t]; k++) {
        const double *a = x + 3 * edges[t][k][0], *b = x + 3 * edges[t][k][1];
        double dz = is_planar(t) ? 0.0 : b[2] - a[2];
        s += sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                  dz * dz);
    }
    return s;
}

/* A random valid element: the regular one, every node moved by up to amp in
   each coordinate (x, y for planar types, whose z gets a random value that
   the transformation must carry through). */
static void random_element(int t, double amp, double *x)
{
    do {
        for (int i = 0; i < nodes_of(t); i++)
            for (int d = 0; d < 3; d++)
                x[3 * i + d] = regular[t][3 * i + d] +
                               (d < 2 || !is_planar(t) ? amp * srand1() : 0.0);
    } while (quality(t, x) <= 0.0);
    if (is_planar(t))
        for (int i = 0; i < nodes_of(t); i++)
            x[3 * i + 2] = srand1();
}

/* largest coordinate difference between the vertex means of a and b */
static double centroid_shift(const double *a, const double *b, int nv)
{
    double m = 0.0;
    for (int d = 0; d < 3; d++) {
        double sa = 0.0, sb = 0.0;
        for (int i = 0; i < nv; i++) {
            sa += a[3 * i + d];
            sb += b[3 * i + d];
        }
        m = fmax(m, fabs(sa - sb) / nv);
    }
    return m;
}

static double max_abs_diff(const double *a, const double *b, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

/* ---- the property test -------------------------------------------------- */

/* Iterate one element; returns the step at which q > TARGET_Q first held
   (0 if never) and leaves the final q in *q_end.  Every step must succeed,
   keep the element valid and keep its edge-length sum. */
static int iterate(int t, double sigma, double *x, double *q_end,
                   int *num_invalid, int *num_len_fail)
{
    double out[24];
    int reached = 0;
    for (int s = 1; s <= NUM_STEPS; s++) {
        double len = edge_sum(t, x);
        if (getme_element_transform((getme_elem_type)t, x, sigma, out) != GETME_OK)
            return -1;
        double q = quality(t, out);
        *num_invalid += !(q > 0.0);
        *num_len_fail += !(fabs(edge_sum(t, out) - len) <= 1e-12 * len);
        *num_len_fail += !(centroid_shift(out, x, nodes_of(t)) <= 1e-12 * len);
        if (is_planar(t))
            for (int i = 0; i < nodes_of(t); i++)
                *num_len_fail += out[3 * i + 2] != x[3 * i + 2]; /* z copied */
        memcpy(x, out, sizeof(double) * 3 * (size_t)nodes_of(t));
        if (!reached && q > TARGET_Q)
            reached = s;
        *q_end = q;
    }
    return reached;
}

static void property_test(int t, double sigma, double amp)
{
    double q_worst_start = 1.0, q_worst_end = 1.0, steps = 0.0;
    int never = 0, invalid = 0, len_fail = 0, errors = 0, max_steps = 0;
    for (int e = 0; e < NUM_ELEMENTS; e++) {
        double x[24], q_end = 0.0;
        random_element(t, amp, x);
        q_worst_start = fmin(q_worst_start, quality(t, x));
        int reached = iterate(t, sigma, x, &q_end, &invalid, &len_fail);
        errors += reached < 0;
        never += reached == 0;
        steps += reached > 0 ? reached : 0;
        max_steps = reached > max_steps ? reached : max_steps;
        q_worst_end = fmin(q_worst_end, q_end);
    }
    int ok = NUM_ELEMENTS - never - errors;
    printf("%-8s sigma %.2f: %d elements, worst initial q %.4f, worst q after "
           "%d steps %.9f, steps to q > %.3f: mean %.2f max %d, not reached %d\n",
           getme_type_name((getme_elem_type)t), sigma, NUM_ELEMENTS,
           q_worst_start, NUM_STEPS, q_worst_end, TARGET_Q,
           ok > 0 ? steps / ok : 0.0, max_steps, never);
    CHECK_EQ_INT(errors, 0);
    CHECK_EQ_INT(never, 0);
    CHECK_EQ_INT(invalid, 0);
    CHECK_EQ_INT(len_fail, 0);
    CHECK(q_worst_end > TARGET_Q);
    CHECK(q_worst_start < 0.35); /* the sample really contains bad elements */
}

/* ---- other properties --------------------------------------------------- */

/* The regular element, anywhere, in any orientation and size, is mapped onto
   itself: same nodes to rounding (same edge sum and, by symmetry, same
   centroid), q stays 1 over many steps. */
static void test_regular_fixed_point(void)
{
    static const double sigmas[] = {0.5, 1.0, 1.5, 2.0};
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = nodes_of(t);
        for (int trial = 0; trial < 20; trial++) {
            double R[9], b[3], x[24], out[24], size = pow(10.0, 3.0 * srand1());
            random_rotation(is_planar(t), R);
            for (int r = 0; r < 9; r++)
                R[r] *= (r == 8 && is_planar(t)) ? 1.0 : size;
            for (int d = 0; d < 3; d++)
                b[d] = 10.0 * size * srand1();
            affine(regular[t], nv, R, b, x);
            double sigma = sigmas[trial % 4];
            CHECK(getme_element_transform((getme_elem_type)t, x, sigma, out) == GETME_OK);
            CHECK_NEAR(max_abs_diff(out, x, 3 * nv) / size, 0.0, 1e-12);
            for (int s = 0; s < NUM_STEPS; s++) {
                memcpy(x, out, sizeof(double) * 3 * (size_t)nv);
                getme_element_transform((getme_elem_type)t, x, sigma, out);
            }
            CHECK_NEAR(quality(t, out), 1.0, 1e-12);
        }
    }
}

/* T(R x + b) = R T(x) + b: the transformations know no coordinate system. */
static void test_equivariance(void)
{
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = nodes_of(t);
        for (int trial = 0; trial < 50; trial++) {
            double x[24], y[24], tx[24], ty[24], rtx[24], R[9], b[3];
            random_element(t, 0.45, x);
            random_rotation(is_planar(t), R);
            for (int d = 0; d < 3; d++)
                b[d] = is_planar(t) && d == 2 ? 0.0 : 5.0 * srand1();
            affine(x, nv, R, b, y);
            getme_element_transform((getme_elem_type)t, x, 1.5, tx);
            getme_element_transform((getme_elem_type)t, y, 1.5, ty);
            affine(tx, nv, R, b, rtx);
            CHECK_NEAR(max_abs_diff(ty, rtx, 3 * nv), 0.0, 1e-12);
        }
    }
}

static void test_arguments(void)
{
    double out[24], x[24];
    memcpy(x, reg_hex, sizeof reg_hex);
    CHECK(getme_element_transform((getme_elem_type)-1, x, 1.5, out) == GETME_ERR_ARGUMENT);
    CHECK(getme_element_transform(GETME_NUM_TYPES, x, 1.5, out) == GETME_ERR_ARGUMENT);
    CHECK(getme_element_transform(GETME_HEX, NULL, 1.5, out) == GETME_ERR_ARGUMENT);
    CHECK(getme_element_transform(GETME_HEX, x, 1.5, NULL) == GETME_ERR_ARGUMENT);
    CHECK(getme_element_transform(GETME_HEX, x, NAN, out) == GETME_ERR_ARGUMENT);
    CHECK(getme_element_transform(GETME_HEX, x, INFINITY, out) == GETME_ERR_ARGUMENT);
    CHECK(getme_element_transform(GETME_HEX, x, -1.5, out) == GETME_ERR_ARGUMENT);
    CHECK(getme_element_transform(GETME_HEX, x, 0.0, out) == GETME_ERR_ARGUMENT);
    x[5] = NAN;
    CHECK(getme_element_transform(GETME_HEX, x, 1.5, out) == GETME_ERR_ARGUMENT);
    x[5] = -INFINITY;
    CHECK(getme_element_transform(GETME_HEX, x, 1.5, out) == GETME_ERR_ARGUMENT);
    /* in-place use gives the same result as a separate output */
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        double y[24];
        random_element(t, 0.4, x);
        memcpy(y, x, sizeof x);
        CHECK(getme_element_transform((getme_elem_type)t, x, 1.5, out) == GETME_OK);
        CHECK(getme_element_transform((getme_elem_type)t, y, 1.5, y) == GETME_OK);
        CHECK(memcmp(y, out, sizeof(double) * 3 * (size_t)nodes_of(t)) == 0);
    }
}

int main(void)
{
    static const double sigmas[] = {1.5, 0.5, 2.0};
    for (int s = 0; s < 3; s++)
        for (int t = 0; t < GETME_NUM_TYPES; t++)
            property_test(t, sigmas[s], 0.6);
    test_regular_fixed_point();
    test_equivariance();
    test_arguments();
    return check_summary("test_transform");
}
