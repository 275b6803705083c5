/*
 * test_quality.c -- the mean ratio kernels through getme_element_quality().
 *
 * Expected values never come from the library's own formula: they are hand
 * computed, or come from a different closed form (edge lengths for tets,
 * the affine image of the regular element, the polygon mean ratio of
 * docs/design.md §1 for planar types).  So a wrong W^-1, a wrong node
 * simplex or a wrong validity test each fail something here.
 */
#include "check.h"

#include <getme.h>

#include <math.h>
#include <stdint.h>
#include <string.h>

#define TOL 1e-12
#define RANDOM_GEOMETRY_SEED 0x5eed1234abcdULL
#include "random_geometry.h"

/* ---- regular elements (all edges 1) ------------------------------------- */

#include "regular_elements.h"

static int is_planar(int t) { return t == GETME_TRI || t == GETME_QUAD; }

/* ---- helpers ------------------------------------------------------------ */

/* A random valid element: every node of the regular one moved by up to amp
   (x, y only for planar types), until the library calls it valid. */
static void random_element(int t, double amp, double *x)
{
    int nv = getme_type_num_nodes((getme_elem_type)t);
    do {
        for (int i = 0; i < nv; i++)
            for (int d = 0; d < 3; d++)
                x[3 * i + d] = regular[t][3 * i + d] +
                               (d < 2 || !is_planar(t) ? amp * srand1() : 0.0);
    } while (getme_element_quality((getme_elem_type)t, x) <= 0.0);
}

static double det3(const double A[9])
{
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}

/* ---- tests -------------------------------------------------------------- */

static void test_type_tables(void)
{
    static const int nv[] = {4, 8, 6, 5, 3, 4}, dim[] = {3, 3, 3, 3, 2, 2};
    static const char *const name[] = {"tet", "hex", "prism", "pyramid", "tri", "quad"};
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        CHECK_EQ_INT(getme_type_num_nodes((getme_elem_type)t), nv[t]);
        CHECK_EQ_INT(getme_type_dim((getme_elem_type)t), dim[t]);
        CHECK(strcmp(getme_type_name((getme_elem_type)t), name[t]) == 0);
    }
    CHECK_EQ_INT(getme_type_num_nodes((getme_elem_type)-1), 0);
    CHECK_EQ_INT(getme_type_num_nodes(GETME_NUM_TYPES), 0);
    CHECK_EQ_INT(getme_type_dim((getme_elem_type)-1), 0);
    CHECK_EQ_INT(getme_type_dim(GETME_NUM_TYPES), 0);
    CHECK(getme_type_name((getme_elem_type)99) != NULL);
    CHECK(getme_element_quality((getme_elem_type)-1, reg_tet) == 0.0);
    CHECK(getme_element_quality(GETME_NUM_TYPES, reg_tet) == 0.0);
    CHECK(getme_element_quality(GETME_TET, NULL) == 0.0);
}

static void test_regular(void)
{
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        CHECK_NEAR(getme_element_quality((getme_elem_type)t, regular[t]), 1.0, TOL);
}

/* q(A x + b) for the regular element = 3 det(A)^(2/3) / |A|_F^2 (3-D) or
   2 det(A) / |A|_F^2 (2-D, A acting in xy), since every node simplex of the
   regular element has S_k = a rotation R_k and |A R_k|_F = |A|_F. */
static void test_affine_images(void)
{
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = getme_type_num_nodes((getme_elem_type)t);
        for (int trial = 0; trial < 200; trial++) {
            double A[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, b[3], y[24];
            int dims = is_planar(t) ? 2 : 3;
            for (int r = 0; r < dims; r++) {
                for (int c = 0; c < dims; c++)
                    A[3 * r + c] = (r == c ? 1.0 : 0.0) + 0.6 * srand1();
                b[r] = 10.0 * srand1();
            }
            b[2] = is_planar(t) ? 0.0 : b[2];
            double det = det3(A), frob = 0.0;
            for (int r = 0; r < dims; r++)
                for (int c = 0; c < dims; c++)
                    frob += A[3 * r + c] * A[3 * r + c];
            double expect = det <= 0.0 ? 0.0
                            : dims == 3 ? 3.0 * pow(det, 2.0 / 3.0) / frob
                                        : 2.0 * det / frob;
            affine(regular[t], nv, A, b, y);
            CHECK_NEAR(getme_element_quality((getme_elem_type)t, y), expect,
                       TOL * fmax(1.0, expect));
        }
    }
}

/* Translation, rotation and uniform scaling leave q unchanged (sizes far
   outside any mesh unit, 1e-60 and 1e60, included: the kernels are meant
   for edges between ~1e-100 and ~1e100). */
static void test_invariance(void)
{
    static const double scales[] = {1e-60, 1e-3, 0.1, 7.5, 1e3, 1e60};
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = getme_type_num_nodes((getme_elem_type)t);
        for (int trial = 0; trial < 50; trial++) {
            double x[24], y[24], R[9], b[3], I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            random_element(t, 0.45, x);
            double q = getme_element_quality((getme_elem_type)t, x);
            for (int d = 0; d < 3; d++)
                b[d] = 100.0 * srand1();
            affine(x, nv, I, b, y); /* translation */
            CHECK_NEAR(getme_element_quality((getme_elem_type)t, y), q, TOL * q);
            double zero[3] = {0, 0, 0};
            random_rotation(is_planar(t), R);
            affine(x, nv, R, zero, y);
            CHECK_NEAR(getme_element_quality((getme_elem_type)t, y), q, TOL * q);
            for (int s = 0; s < 6; s++) {
                double S[9] = {scales[s], 0, 0, 0, scales[s], 0, 0, 0, scales[s]};
                affine(x, nv, S, zero, y);
                CHECK_NEAR(getme_element_quality((getme_elem_type)t, y), q, TOL * q);
            }
        }
    }
}

/* Tet: q = 12 (3V)^(2/3) / sum of squared edge lengths, an edge-based form. */
static void test_tet_edge_formula(void)
{
    static const double corner[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    /* V = 1/6, sum l^2 = 3 + 3*2 = 9: q = 12 (1/2)^(2/3) / 9 */
    CHECK_NEAR(getme_element_quality(GETME_TET, corner),
               12.0 * pow(0.5, 2.0 / 3.0) / 9.0, TOL);
    /* the regular tet stretched by 2 along z: det S = 2, |S|_F^2 = 6 */
    double y[12];
    static const double Z2[9] = {1, 0, 0, 0, 1, 0, 0, 0, 2};
    static const double zero[3] = {0, 0, 0};
    affine(reg_tet, 4, Z2, zero, y);
    CHECK_NEAR(getme_element_quality(GETME_TET, y), pow(2.0, 2.0 / 3.0) / 2.0, TOL);
    for (int trial = 0; trial < 200; trial++) {
        double x[12], e[3][3], l2 = 0.0;
        random_element(GETME_TET, 0.6, x);
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                e[k][d] = x[3 * (k + 1) + d] - x[d];
        double V = (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                    e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                    e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) / 6.0;
        for (int i = 0; i < 4; i++)
            for (int j = i + 1; j < 4; j++)
                for (int d = 0; d < 3; d++)
                    l2 += (x[3 * j + d] - x[3 * i + d]) * (x[3 * j + d] - x[3 * i + d]);
        double expect = 12.0 * pow(3.0 * V, 2.0 / 3.0) / l2;
        CHECK_NEAR(getme_element_quality(GETME_TET, x), expect, TOL);
    }
}

/* Unit cube with node 6 lifted from (1,1,1) to (1,1,2), by hand: the
   corners at nodes 2, 5, 6, 7 have (det, |D|^2) = (2, 6), (1, 4), (2, 8),
   (1, 4); the other four stay 1. */
static void test_hex_moved_vertex(void)
{
    double x[24];
    memcpy(x, reg_hex, sizeof x);
    x[3 * 6 + 2] = 2.0;
    double c = pow(2.0, 2.0 / 3.0);
    double expect = (4.0 + 3.0 * c / 6.0 + 3.0 / 4.0 + 3.0 * c / 8.0 + 3.0 / 4.0) / 8.0;
    CHECK_NEAR(getme_element_quality(GETME_HEX, x), expect, TOL);
    CHECK_NEAR(expect, 0.86112199, 1e-8); /* the hand value itself */
}

/* Right prisms and pyramids of height h (unit triangle / square base):
   prism corners have S = diag(1, 1, h): q = 3 h^(2/3) / (2 + h^2);
   pyramid corners have s3 = sqrt2 (0, 0, h): q = 3 (sqrt2 h)^(2/3) / (2 + 2h^2). */
static void test_prism_pyramid_heights(void)
{
    static const double hs[] = {0.25, 0.5, 1.0, 2.0, 3.5};
    for (int k = 0; k < 5; k++) {
        double h = hs[k], p[18], y[15];
        memcpy(p, reg_prism, sizeof p);
        p[11] = p[14] = p[17] = h;
        CHECK_NEAR(getme_element_quality(GETME_PRISM, p),
                   3.0 * pow(h, 2.0 / 3.0) / (2.0 + h * h), TOL);
        memcpy(y, reg_pyramid, sizeof y);
        y[14] = h;
        CHECK_NEAR(getme_element_quality(GETME_PYRAMID, y),
                   3.0 * pow(sqrt(2.0) * h, 2.0 / 3.0) / (2.0 + 2.0 * h * h), TOL);
    }
}

/* The polygon mean ratio (docs/design.md §1): corner k with
   e1 = x_{k+1} - x_k, e2 = x_{k-1} - x_k, alpha = 1 - cos(2pi/n),
   beta = sin(2pi/n):
   delta = (e1 x e2) / (2 alpha beta), phi = |e1 - e2|^2 / (4 beta^2) +
   |e1 + e2|^2 / (4 alpha^2), q = (2/n) sum delta/phi. */
static double polygon_mean_ratio(const double *x, int n)
{
    double a = 1.0 - cos(2.0 * GETME_TEST_PI / n), b = sin(2.0 * GETME_TEST_PI / n), sum = 0.0;
    for (int k = 0; k < n; k++) {
        const double *p = x + 3 * k, *nx = x + 3 * ((k + 1) % n),
                     *pv = x + 3 * ((k + n - 1) % n);
        double e1x = nx[0] - p[0], e1y = nx[1] - p[1];
        double e2x = pv[0] - p[0], e2y = pv[1] - p[1];
        double delta = (e1x * e2y - e1y * e2x) / (2.0 * a * b);
        if (delta <= 0.0)
            return 0.0;
        double dm = (e1x - e2x) * (e1x - e2x) + (e1y - e2y) * (e1y - e2y);
        double dp = (e1x + e2x) * (e1x + e2x) + (e1y + e2y) * (e1y + e2y);
        sum += delta / (dm / (4.0 * b * b) + dp / (4.0 * a * a));
    }
    return 2.0 / n * sum;
}

static void test_planar(void)
{
    static const double right[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    CHECK_NEAR(getme_element_quality(GETME_TRI, right), sqrt(3.0) / 2.0, TOL);
    static const double rect[] = {0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0};
    CHECK_NEAR(getme_element_quality(GETME_QUAD, rect), 0.8, TOL);
    /* z is ignored */
    static const double tilted[] = {0, 0, 5, 1, 0, -3, 0.5, S3_2, 1e6};
    CHECK_NEAR(getme_element_quality(GETME_TRI, tilted), 1.0, TOL);
    for (int trial = 0; trial < 300; trial++) {
        double x[12];
        random_element(GETME_TRI, 0.6, x);
        CHECK_NEAR(getme_element_quality(GETME_TRI, x), polygon_mean_ratio(x, 3), TOL);
        random_element(GETME_QUAD, 0.6, x);
        CHECK_NEAR(getme_element_quality(GETME_QUAD, x), polygon_mean_ratio(x, 4), TOL);
    }
}

static void test_invalid(void)
{
    double x[24];
    /* inverted tet: two nodes swapped */
    static const double inv_tet[] = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
    CHECK(getme_element_quality(GETME_TET, inv_tet) == 0.0);
    /* flat tet: fourth node in the plane of the others */
    static const double flat_tet[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 0};
    CHECK(getme_element_quality(GETME_TET, flat_tet) == 0.0);
    /* hex with a folded top face: node 6 pulled inside to (0.2, 0.2, 1),
       corner 6 has det = -0.6 (by hand) */
    memcpy(x, reg_hex, sizeof reg_hex);
    x[18] = 0.2;
    x[19] = 0.2;
    CHECK(getme_element_quality(GETME_HEX, x) == 0.0);
    /* collapsed hex: top face on the bottom face */
    memcpy(x, reg_hex, sizeof reg_hex);
    for (int i = 4; i < 8; i++)
        x[3 * i + 2] = 0.0;
    CHECK(getme_element_quality(GETME_HEX, x) == 0.0);
    /* mirrored hex (top and bottom swapped) */
    for (int i = 0; i < 8; i++) {
        memcpy(x + 3 * i, reg_hex + 3 * ((i + 4) % 8), 3 * sizeof(double));
    }
    CHECK(getme_element_quality(GETME_HEX, x) == 0.0);
    /* prism upside down */
    memcpy(x, reg_prism, sizeof reg_prism);
    x[11] = x[14] = x[17] = -1.0;
    CHECK(getme_element_quality(GETME_PRISM, x) == 0.0);
    /* pyramid with the apex below the base, and with the apex in it */
    memcpy(x, reg_pyramid, sizeof reg_pyramid);
    x[14] = -0.7;
    CHECK(getme_element_quality(GETME_PYRAMID, x) == 0.0);
    x[14] = 0.0;
    CHECK(getme_element_quality(GETME_PYRAMID, x) == 0.0);
    /* clockwise triangle and quad; a quad with a reflex corner */
    static const double cw_tri[] = {0, 0, 0, 0.5, S3_2, 0, 1, 0, 0};
    CHECK(getme_element_quality(GETME_TRI, cw_tri) == 0.0);
    static const double cw_quad[] = {0, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0};
    CHECK(getme_element_quality(GETME_QUAD, cw_quad) == 0.0);
    static const double dart[] = {0, 0, 0, 1, 0, 0, 0.2, 0.2, 0, 0, 1, 0};
    CHECK(getme_element_quality(GETME_QUAD, dart) == 0.0);
    static const double line_tri[] = {0, 0, 0, 1, 0, 0, 2, 0, 0};
    CHECK(getme_element_quality(GETME_TRI, line_tri) == 0.0);
    /* non-finite coordinates, in every type and every node */
    const double bad[] = {NAN, INFINITY, -INFINITY};
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = getme_type_num_nodes((getme_elem_type)t);
        for (int i = 0; i < 3 * nv; i++) {
            if (is_planar(t) && i % 3 == 2)
                continue; /* z is not read */
            for (int k = 0; k < 3; k++) {
                memcpy(x, regular[t], sizeof(double) * 3 * (size_t)nv);
                x[i] = bad[k];
                CHECK(getme_element_quality((getme_elem_type)t, x) == 0.0);
            }
        }
    }
}

int main(void)
{
    test_type_tables();
    test_regular();
    test_affine_images();
    test_invariance();
    test_tet_edge_formula();
    test_hex_moved_vertex();
    test_prism_pyramid_heights();
    test_planar();
    test_invalid();
    return check_summary("test_quality");
}
