/*
 * test_measures.c -- the analysts' quality measures (getme_element_measure,
 * getme_mesh_measure_stats) on elements whose values are worked out by hand
 * in the comments: regular elements, a right-corner tet, a sheared hex, a
 * hex with an inverted corner, prisms, pyramids, triangles and quads
 * (including inverted and non-convex ones).  The Gmsh values quoted were
 * also read back from Gmsh 4.8.4 (tests/plugin/test_measures_gmsh.py
 * compares whole meshes).
 */
#include "check.h"

#include <getme.h>
#include <omp.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define TOL 1e-12
#define PI 3.14159265358979323846
#define DEG (180.0 / PI)

enum { MR = GETME_MEASURE_MEAN_RATIO, DMIN = GETME_MEASURE_MIN_DIHEDRAL,
       DMAX = GETME_MEASURE_MAX_DIHEDRAL, SJ = GETME_MEASURE_SCALED_JACOBIAN,
       GAMMA = GETME_MEASURE_GAMMA, SICN = GETME_MEASURE_SICN };

static double m(getme_elem_type t, int measure, const double *x)
{
    return getme_element_measure(t, (getme_measure)measure, x);
}

#include "regular_elements.h"

static void test_regular(void)
{
    const double *const *reg = regular;
    /* dihedral angles: tet acos(1/3); prism 60 (sides) and 90; pyramid
       base-side atan(sqrt2) = 54.7356, side-side acos(-1/3) = 109.4712;
       hex and quad 90; tri 60 */
    const double dmin[] = {acos(1.0 / 3.0) * DEG, 90, 60, atan(sqrt(2.0)) * DEG, 60, 90};
    const double dmax[] = {acos(1.0 / 3.0) * DEG, 90, 90, acos(-1.0 / 3.0) * DEG, 60, 90};
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        getme_elem_type ty = (getme_elem_type)t;
        CHECK_NEAR(m(ty, MR, reg[t]), 1.0, TOL);
        CHECK_NEAR(m(ty, SJ, reg[t]), 1.0, TOL);
        CHECK_NEAR(m(ty, SICN, reg[t]), 1.0, TOL);
        CHECK_NEAR(m(ty, DMIN, reg[t]), dmin[t], 1e-10);
        CHECK_NEAR(m(ty, DMAX, reg[t]), dmax[t], 1e-10);
        if (t == GETME_HEX || t == GETME_PYRAMID) {
            CHECK(isnan(m(ty, GAMMA, reg[t])));
            CHECK_EQ_INT(getme_measure_defined(ty, GETME_MEASURE_GAMMA), 0);
        } else {
            CHECK_NEAR(m(ty, GAMMA, reg[t]), 1.0, TOL);
            CHECK_EQ_INT(getme_measure_defined(ty, GETME_MEASURE_GAMMA), 1);
        }
    }
    CHECK_NEAR(acos(1.0 / 3.0) * DEG, 70.528779365509308, 1e-12);
    /* scale, translation and rotation invariance (90 degrees about z) */
    double x[12];
    for (int i = 0; i < 4; i++) {
        x[3 * i] = -7.0 * reg_tet[3 * i + 1] + 3.0;
        x[3 * i + 1] = 7.0 * reg_tet[3 * i] - 1.0;
        x[3 * i + 2] = 7.0 * reg_tet[3 * i + 2] + 2.0;
    }
    for (int k = 0; k < GETME_NUM_MEASURES; k++)
        CHECK_NEAR(m(GETME_TET, k, x), m(GETME_TET, k, reg_tet), 1e-10);
}

/* ---- tets --------------------------------------------------------------- */

static void test_tet(void)
{
    /* right corner: dihedral 90 at the 3 edges at the origin, acos(1/sqrt3)
       = 54.7356 between a coordinate face and x + y + z = 1.
       SJ: det 1, length products 1 (node 0) and 1*sqrt2*sqrt2 = 2 (others):
       sqrt2 / 2.
       gamma: r = 3V / A = (1/2) / (3/2 + sqrt3/2) = 1 / (3 + sqrt3),
       R = sqrt3 / 2: 3 r / R = sqrt3 - 1 (Gmsh 0.732051).
       SICN: S = W^-1, cond(W^-1) = cond(W): |W|^2 = 3, |W^-1|^2 = 9/2,
       3 / sqrt(3 * 9/2) = sqrt(2/3) (Gmsh 0.816497). */
    double t[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    CHECK_NEAR(m(GETME_TET, DMIN, t), acos(1.0 / sqrt(3.0)) * DEG, 1e-10);
    CHECK_NEAR(m(GETME_TET, DMAX, t), 90.0, 1e-10);
    CHECK_NEAR(m(GETME_TET, SJ, t), sqrt(2.0) / 2.0, TOL);
    CHECK_NEAR(m(GETME_TET, GAMMA, t), sqrt(3.0) - 1.0, TOL);
    CHECK_NEAR(m(GETME_TET, SICN, t), sqrt(2.0 / 3.0), TOL);
    /* inverted (nodes 1 and 2 swapped): SJ and SICN change sign, gamma and
       the angles (those of the mirror image) do not, mean ratio is 0 */
    double inv[] = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
    CHECK_NEAR(m(GETME_TET, SJ, inv), -sqrt(2.0) / 2.0, TOL);
    CHECK_NEAR(m(GETME_TET, SICN, inv), -sqrt(2.0 / 3.0), TOL);
    CHECK_NEAR(m(GETME_TET, GAMMA, inv), sqrt(3.0) - 1.0, TOL);
    CHECK_NEAR(m(GETME_TET, DMIN, inv), acos(1.0 / sqrt(3.0)) * DEG, 1e-10);
    CHECK_NEAR(m(GETME_TET, MR, inv), 0.0, 0.0);
    /* flat (apex in the base plane): dihedral 0 and 180, SJ/SICN/gamma 0 */
    double flat[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 0};
    CHECK_NEAR(m(GETME_TET, DMIN, flat), 0.0, 1e-10);
    CHECK_NEAR(m(GETME_TET, DMAX, flat), 180.0, 1e-10);
    CHECK_NEAR(m(GETME_TET, SJ, flat), 0.0, TOL);
    CHECK_NEAR(m(GETME_TET, SICN, flat), 0.0, TOL);
    CHECK_NEAR(m(GETME_TET, GAMMA, flat), 0.0, TOL);
    /* all nodes equal: 0, not NaN */
    double point[12] = {0};
    CHECK_NEAR(m(GETME_TET, SJ, point), 0.0, 0.0);
    CHECK_NEAR(m(GETME_TET, SICN, point), 0.0, 0.0);
    CHECK_NEAR(m(GETME_TET, GAMMA, point), 0.0, 0.0);
    CHECK_NEAR(m(GETME_TET, DMIN, point), 0.0, 0.0);
}

/* ---- hexes -------------------------------------------------------------- */

static void test_hex(void)
{
    /* unit cube with the top face shifted by 0.5 in x: every corner and the
       centre see one vertical edge (0.5, 0, 1) / sqrt(5/4) against x and y:
       unit det 2/sqrt5.  SICN at every corner: S = [x, y, (0.5, 0, 1)],
       det 1, |S|^2 = |cof S|^2 = 13/4: 3 / (13/4) = 12/13 (Gmsh 0.923077).
       Dihedral: the x = z/2 faces meet the bottom at atan2(1, 0.5) =
       63.4349 and 180 minus that; all other edges 90. */
    double h[24];
    memcpy(h, reg_hex, sizeof h);
    for (int i = 4; i < 8; i++)
        h[3 * i] += 0.5;
    CHECK_NEAR(m(GETME_HEX, SJ, h), 2.0 / sqrt(5.0), TOL);
    CHECK_NEAR(m(GETME_HEX, SICN, h), 12.0 / 13.0, TOL);
    CHECK_NEAR(m(GETME_HEX, DMIN, h), atan2(1.0, 0.5) * DEG, 1e-10);
    CHECK_NEAR(m(GETME_HEX, DMAX, h), 180.0 - atan2(1.0, 0.5) * DEG, 1e-10);
    CHECK(isnan(m(GETME_HEX, GAMMA, h)));

    /* a 2 x 1 x 1 box: SJ 1 (right angles), SICN of diag(2, 1, 1):
       3 * 2 / (sqrt6 * 3) = sqrt(2/3) (Gmsh 0.816497) */
    double box[24];
    memcpy(box, reg_hex, sizeof box);
    for (int i = 0; i < 8; i++)
        box[3 * i] *= 2.0;
    CHECK_NEAR(m(GETME_HEX, SJ, box), 1.0, TOL);
    CHECK_NEAR(m(GETME_HEX, SICN, box), sqrt(2.0 / 3.0), TOL);

    /* node 0 pushed inside to (0.6, 0.6, 0.6): corner 0 has the edges
       a = (0.4, -0.6, -0.6), b = (-0.6, 0.4, -0.6), c = (-0.6, -0.6, 0.4)
       (to nodes 1, 3, 4), det -0.8, each |.|^2 = 0.88: unit det
       -0.8 / 0.88^1.5; |S|^2 = 2.64, each cross product |b x c|^2 = 0.76,
       |cof|^2 = 2.28: SICN -2.4 / sqrt(2.64 * 2.28).  The other corners
       are positive (corner 1: det(y, (-0.4, 0.6, 0.6), z) = 0.4). */
    double inv[24];
    memcpy(inv, reg_hex, sizeof inv);
    inv[0] = inv[1] = inv[2] = 0.6;
    CHECK_NEAR(m(GETME_HEX, SJ, inv), -0.8 / pow(0.88, 1.5), TOL);
    CHECK_NEAR(m(GETME_HEX, SICN, inv), -2.4 / sqrt(2.64 * 2.28), TOL);
    CHECK(m(GETME_HEX, SJ, inv) < -0.96);
    CHECK_NEAR(m(GETME_HEX, MR, inv), 0.0, 0.0);
}

/* ---- prisms and pyramids ------------------------------------------------ */

static void test_prism_pyramid(void)
{
    /* right-triangle prism of height 1: corners at the 45-degree nodes have
       unit det sin45, so SJ = gamma = 2/sqrt3 * sqrt2/2 = sqrt(2/3); the
       corner at the right angle has S = W^-1: SICN = cond(W)^-1 =
       3 / sqrt(|W|^2 |W^-1|^2) = 3 / sqrt(3 * 11/3) = 3/sqrt11 (Gmsh
       0.904534).  Dihedral: 45 and 90. */
    double p[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1};
    CHECK_NEAR(m(GETME_PRISM, SJ, p), sqrt(2.0 / 3.0), TOL);
    CHECK_NEAR(m(GETME_PRISM, GAMMA, p), sqrt(2.0 / 3.0), TOL);
    CHECK_NEAR(m(GETME_PRISM, SICN, p), 3.0 / sqrt(11.0), TOL);
    CHECK_NEAR(m(GETME_PRISM, DMIN, p), 45.0, 1e-10);
    CHECK_NEAR(m(GETME_PRISM, DMAX, p), 90.0, 1e-10);
    /* upside down (top and bottom swapped): SJ and SICN negative, gamma is
       unsigned in Gmsh.  SJ's minimum is now the right-angle corner,
       -2/sqrt3 (below -1: the prism's range is [-2/sqrt3, 1]) */
    double q[18];
    memcpy(q, p + 9, 9 * sizeof *q);
    memcpy(q + 9, p, 9 * sizeof *q);
    CHECK_NEAR(m(GETME_PRISM, SJ, q), -2.0 / sqrt(3.0), TOL);
    CHECK_NEAR(m(GETME_PRISM, SICN, q), -3.0 / sqrt(11.0), TOL);
    CHECK_NEAR(m(GETME_PRISM, GAMMA, q), sqrt(2.0 / 3.0), TOL);

    /* pyramid over the unit square, apex at height 1/2: base corners
       e1 = x, e2 = y, e3 = (1/2, 1/2, 1/2): unit det (1/2) / (sqrt3/2) =
       1/sqrt3, SJ sqrt(2/3).  SICN: S = diag(1, 1, sqrt2/2), det sqrt2/2,
       |S|^2 = 5/2, |cof|^2 = 2: 3 (sqrt2/2) / sqrt5 = 3/sqrt10.  Dihedral:
       base-side 45; side-side: outward normals (0, -1, 1) and (1, 0, 1)
       meet at 60, so 120. */
    double y[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0.5};
    CHECK_NEAR(m(GETME_PYRAMID, SJ, y), sqrt(2.0 / 3.0), TOL);
    CHECK_NEAR(m(GETME_PYRAMID, SICN, y), 3.0 / sqrt(10.0), TOL);
    CHECK_NEAR(m(GETME_PYRAMID, DMIN, y), 45.0, 1e-10);
    CHECK_NEAR(m(GETME_PYRAMID, DMAX, y), 120.0, 1e-10);
    CHECK(isnan(m(GETME_PYRAMID, GAMMA, y)));
    /* apex at height 1: sqrt2 * 1/sqrt(3/2) = 1.1547 is capped at 1; SICN
       of diag(1, 1, sqrt2) is again 3/sqrt10 (Gmsh 0.948683) */
    y[14] = 1.0;
    CHECK_NEAR(m(GETME_PYRAMID, SJ, y), 1.0, 0.0);
    CHECK_NEAR(m(GETME_PYRAMID, SICN, y), 3.0 / sqrt(10.0), TOL);
    /* apex below the base: every base corner inverted */
    y[14] = -0.5;
    CHECK_NEAR(m(GETME_PYRAMID, SJ, y), -sqrt(2.0 / 3.0), TOL);
    CHECK_NEAR(m(GETME_PYRAMID, SICN, y), -3.0 / sqrt(10.0), TOL);
}

/* ---- planar ------------------------------------------------------------- */

static void test_planar(void)
{
    /* right isosceles triangle: SJ 2/sqrt3 / max(1, sqrt2, sqrt2) =
       sqrt(2/3); gamma 2 r / R with r = (2 - sqrt2)/2, R = sqrt2/2:
       2 sqrt2 - 2 (Gmsh 0.828427); SICN 2 det(W^-1) / |W^-1|^2 =
       (4/sqrt3) / (8/3) = sqrt3/2 (Gmsh 0.866025); angles 45 and 90 */
    double t[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    CHECK_NEAR(m(GETME_TRI, SJ, t), sqrt(2.0 / 3.0), TOL);
    CHECK_NEAR(m(GETME_TRI, GAMMA, t), 2.0 * sqrt(2.0) - 2.0, TOL);
    CHECK_NEAR(m(GETME_TRI, SICN, t), S3_2, TOL);
    CHECK_NEAR(m(GETME_TRI, DMIN, t), 45.0, 1e-10);
    CHECK_NEAR(m(GETME_TRI, DMAX, t), 90.0, 1e-10);
    /* clockwise: inverted for getme (SJ, SICN < 0); gamma unsigned */
    double cw[] = {0, 0, 0, 0, 1, 0, 1, 0, 0};
    CHECK_NEAR(m(GETME_TRI, SJ, cw), -sqrt(2.0 / 3.0), TOL);
    CHECK_NEAR(m(GETME_TRI, SICN, cw), -S3_2, TOL);
    CHECK_NEAR(m(GETME_TRI, GAMMA, cw), 2.0 * sqrt(2.0) - 2.0, TOL);

    /* 2 x 1 rectangle: SJ 1, gamma 1 (right angles), SICN 2*2/5 = 0.8 */
    double r[] = {0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0};
    CHECK_NEAR(m(GETME_QUAD, SJ, r), 1.0, TOL);
    CHECK_NEAR(m(GETME_QUAD, GAMMA, r), 1.0, TOL);
    CHECK_NEAR(m(GETME_QUAD, SICN, r), 0.8, TOL);
    /* parallelogram with edges (1, 0) and (1/2, 1): angles atan(2) =
       63.4349 and its supplement, SJ sin = 2/sqrt5, gamma
       1 - (90 - 63.4349)/90 = 1 - atan(1/2)/(pi/2), SICN 2 / (1 + 5/4) */
    double pg[] = {0, 0, 0, 1, 0, 0, 1.5, 1, 0, 0.5, 1, 0};
    CHECK_NEAR(m(GETME_QUAD, SJ, pg), 2.0 / sqrt(5.0), TOL);
    CHECK_NEAR(m(GETME_QUAD, GAMMA, pg), 1.0 - atan(0.5) / (PI / 2), TOL);
    CHECK_NEAR(m(GETME_QUAD, SICN, pg), 8.0 / 9.0, TOL);
    CHECK_NEAR(m(GETME_QUAD, DMIN, pg), atan(2.0) * DEG, 1e-10);
    CHECK_NEAR(m(GETME_QUAD, DMAX, pg), 180.0 - atan(2.0) * DEG, 1e-10);
    /* dart: node 3 at (0.7, 0.3) inside triangle 0 1 2.  Corner 3 has
       edges (-0.7, -0.3) and (0.3, 0.7): cross -0.4, both lengths^2 0.58:
       SJ = SICN = -0.4/0.58 (Gmsh -0.689655); interior angle 360 -
       acos(-0.42/0.58) = 223.6; smallest angle atan(3/7) at node 0 (and
       node 2), so gamma = -(1 - (90 - 23.2)/90) = -atan(3/7)/(pi/2)
       (Gmsh -0.257762). */
    double d[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0.7, 0.3, 0};
    CHECK_NEAR(m(GETME_QUAD, SJ, d), -0.4 / 0.58, TOL);
    CHECK_NEAR(m(GETME_QUAD, SICN, d), -0.4 / 0.58, TOL);
    CHECK_NEAR(m(GETME_QUAD, GAMMA, d), -atan(3.0 / 7.0) / (PI / 2), TOL);
    CHECK_NEAR(m(GETME_QUAD, DMAX, d), 360.0 - acos(-0.42 / 0.58) * DEG, 1e-10);
    CHECK_NEAR(m(GETME_QUAD, DMIN, d), atan(3.0 / 7.0) * DEG, 1e-10);
}

/* ---- arguments ---------------------------------------------------------- */

static void test_arguments(void)
{
    CHECK(isnan(getme_element_measure(GETME_TET, GETME_MEASURE_SICN, NULL)));
    CHECK(isnan(getme_element_measure((getme_elem_type)6, GETME_MEASURE_SICN, reg_tet)));
    CHECK(isnan(getme_element_measure(GETME_TET, (getme_measure)6, reg_tet)));
    CHECK(isnan(getme_element_measure(GETME_TET, (getme_measure)-1, reg_tet)));
    CHECK(strcmp(getme_measure_name(GETME_MEASURE_SCALED_JACOBIAN), "scaled_jacobian") == 0);
    CHECK(strcmp(getme_measure_name(GETME_MEASURE_SICN), "sicn") == 0);
    CHECK(strcmp(getme_measure_name((getme_measure)9), "unknown") == 0);
    double lo = -1, hi = -1;
    CHECK_EQ_INT(getme_measure_range(GETME_MEASURE_MAX_DIHEDRAL, &lo, &hi), GETME_OK);
    CHECK(lo == 0.0 && hi == 180.0);
    CHECK_EQ_INT(getme_measure_range(GETME_MEASURE_GAMMA, &lo, &hi), GETME_OK);
    CHECK(lo == 0.0 && hi == 1.0);
    CHECK_EQ_INT(getme_measure_range((getme_measure)6, &lo, &hi), GETME_ERR_ARGUMENT);
    getme_measure_stats s;
    CHECK_EQ_INT(getme_mesh_measure_stats(NULL, -1, GETME_MEASURE_SICN, &s), GETME_ERR_ARGUMENT);
}

/* ---- mesh statistics ---------------------------------------------------- */

static void test_mesh_stats(void)
{
    /* two tets sharing the face 0 1 2: the regular one above and a flat-ish
       right-corner one below (nodes 0 1 2 of the regular tet, apex 4) plus
       a third, inverted, tet (apex 5 on the wrong side) */
    double xyz[] = {0, 0, 0, 1, 0, 0, 0.5, S3_2, 0, 0.5, 0.28867513459481288225,
                    0.81649658092772603273, 0.5, 0.28867513459481288225, -0.1,
                    0.5, 0.28867513459481288225, 0.3};
    int32_t conn[] = {0, 1, 2, 3, 0, 2, 1, 4, 0, 2, 1, 5};
    getme_mesh *mesh;
    CHECK_EQ_INT(getme_mesh_create(&mesh, 3, 6, xyz), GETME_OK);
    CHECK_EQ_INT(getme_mesh_add_elements(mesh, GETME_TET, 3, conn, NULL), GETME_OK);
    double v[3];
    CHECK_EQ_INT(getme_mesh_element_measures(mesh, GETME_MEASURE_SICN, v), GETME_OK);
    double e1[12], e2[12];
    for (int i = 0; i < 4; i++)
        for (int c = 0; c < 3; c++) {
            e1[3 * i + c] = xyz[3 * conn[4 + i] + c];
            e2[3 * i + c] = xyz[3 * conn[8 + i] + c];
        }
    CHECK_NEAR(v[0], 1.0, TOL);
    CHECK_NEAR(v[1], m(GETME_TET, SICN, e1), 0.0);
    CHECK_NEAR(v[2], m(GETME_TET, SICN, e2), 0.0);
    CHECK(v[1] > 0.0 && v[1] < 1.0 && v[2] < 0.0);

    getme_measure_stats s;
    CHECK_EQ_INT(getme_mesh_measure_stats(mesh, GETME_TET, GETME_MEASURE_SICN, &s), GETME_OK);
    CHECK_EQ_INT(s.num_elements, 3);
    CHECK_EQ_INT(s.num_negative, 1);
    CHECK_EQ_INT(s.num_below, 1);
    CHECK_NEAR(s.min, v[2], 0.0);
    CHECK_NEAR(s.max, 1.0, TOL);
    CHECK_NEAR(s.mean, (v[0] + v[1] + v[2]) / 3.0, 1e-15);
    CHECK_EQ_INT(s.min_element, 2);
    CHECK_EQ_INT(s.max_element, 0);
    /* regular tet in the last bin, the other valid one in bin floor(10 v) */
    int64_t total = 0;
    for (int b = 0; b < GETME_HIST_BINS; b++)
        total += s.histogram[b];
    CHECK_EQ_INT(total, 2);
    CHECK_EQ_INT(s.histogram[GETME_HIST_BINS - 1], 1);
    CHECK_EQ_INT(s.histogram[(int)(v[1] * 10)], 1 + ((int)(v[1] * 10) == 9));
    /* dihedral histogram over [0, 180]: 70.53 in bin 3 (54..72) */
    CHECK_EQ_INT(getme_mesh_measure_stats(mesh, -1, GETME_MEASURE_MIN_DIHEDRAL, &s), GETME_OK);
    CHECK(s.hist_hi == 180.0);
    CHECK(s.histogram[3] >= 1);
    CHECK_NEAR(s.max, acos(1.0 / 3.0) * DEG, 1e-10);
    /* no hex: nothing counted; gamma of hexes is never defined */
    CHECK_EQ_INT(getme_mesh_measure_stats(mesh, GETME_HEX, GETME_MEASURE_SICN, &s), GETME_OK);
    CHECK_EQ_INT(s.num_elements, 0);
    CHECK_EQ_INT(s.min_element, -1);
    CHECK_EQ_INT(getme_mesh_measure_stats(mesh, 6, GETME_MEASURE_SICN, &s), GETME_ERR_ARGUMENT);
    CHECK_EQ_INT(getme_mesh_measure_stats(mesh, -1, (getme_measure)7, &s), GETME_ERR_ARGUMENT);
    /* all at once: the same as one by one */
    getme_measure_stats all[GETME_NUM_TYPES * GETME_NUM_MEASURES];
    CHECK_EQ_INT(getme_mesh_measure_all(mesh, all), GETME_OK);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        for (int k = 0; k < GETME_NUM_MEASURES; k++) {
            CHECK_EQ_INT(getme_mesh_measure_stats(mesh, t, (getme_measure)k, &s), GETME_OK);
            CHECK(memcmp(&s, &all[t * GETME_NUM_MEASURES + k], sizeof s) == 0);
        }
    CHECK_EQ_INT(all[GETME_TET * GETME_NUM_MEASURES + GETME_MEASURE_SICN].num_elements, 3);
    CHECK_EQ_INT(getme_mesh_measure_all(mesh, NULL), GETME_ERR_ARGUMENT);
    getme_mesh_free(mesh);

    /* the log summary of one regular tet, and of the three tets above */
    CHECK_EQ_INT(getme_mesh_create(&mesh, 3, 4, reg_tet), GETME_OK);
    CHECK_EQ_INT(getme_mesh_add_elements(mesh, GETME_TET, 1, conn, NULL), GETME_OK);
    CHECK_EQ_INT(getme_mesh_measure_all(mesh, all), GETME_OK);
    char line[256];
    const char *want = "dihedral 70.53 to 70.53 deg, scaled Jacobian min 1.0000 "
                       "mean 1.0000, gamma min 1.0000 mean 1.0000, SICN min "
                       "1.0000 mean 1.0000";
    int n = getme_measure_summary(GETME_TET, all, line, sizeof line);
    CHECK(strcmp(line, want) == 0);
    CHECK_EQ_INT(n, (int)strlen(want));
    /* truncated: still terminated, the full length returned */
    char shortbuf[12];
    CHECK_EQ_INT(getme_measure_summary(GETME_TET, all, shortbuf, sizeof shortbuf), n);
    CHECK(strcmp(shortbuf, "dihedral 70") == 0);
    /* no hex: empty */
    CHECK_EQ_INT(getme_measure_summary(GETME_HEX, all + GETME_NUM_MEASURES, line, sizeof line), 0);
    CHECK(line[0] == '\0');
    getme_mesh_free(mesh);
}

/* A clockwise planar mesh is measured as its mirror image (positive), like
   the mean ratio; a single folded element in a counter-clockwise mesh is
   negative. */
static void test_planar_orientation(void)
{
    /* two unit squares side by side, clockwise */
    double xyz[] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0};
    int32_t cw[] = {0, 3, 4, 1, 1, 4, 5, 2};
    getme_mesh *mesh;
    CHECK_EQ_INT(getme_mesh_create(&mesh, 2, 6, xyz), GETME_OK);
    CHECK_EQ_INT(getme_mesh_add_elements(mesh, GETME_QUAD, 2, cw, NULL), GETME_OK);
    getme_measure_stats s;
    CHECK_EQ_INT(getme_mesh_measure_stats(mesh, GETME_QUAD, GETME_MEASURE_SCALED_JACOBIAN, &s), GETME_OK);
    CHECK_NEAR(s.min, 1.0, TOL);
    CHECK_EQ_INT(getme_mesh_measure_stats(mesh, -1, GETME_MEASURE_SICN, &s), GETME_OK);
    CHECK_NEAR(s.min, 1.0, TOL);
    CHECK_EQ_INT(s.num_elements, 2);
    getme_mesh_free(mesh);

    /* three counter-clockwise triangles and one clockwise one */
    double t[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0, 2, 1, 0};
    int32_t c[] = {0, 1, 2, 1, 3, 2, 1, 4, 3, 4, 3, 5};
    CHECK_EQ_INT(getme_mesh_create(&mesh, 2, 6, t), GETME_OK);
    CHECK_EQ_INT(getme_mesh_add_elements(mesh, GETME_TRI, 4, c, NULL), GETME_OK);
    CHECK_EQ_INT(getme_mesh_measure_stats(mesh, GETME_TRI, GETME_MEASURE_SICN, &s), GETME_OK);
    CHECK_EQ_INT(s.num_negative, 1);
    CHECK_EQ_INT(s.min_element, 3);
    CHECK_NEAR(s.min, -S3_2, TOL);
    getme_mesh_free(mesh);
}

/* Statistics of a distorted 8^3 hex grid (and its tets): the same bits
   with 1 and 2 threads. */
static void test_threads(void)
{
    enum { N = 8, P = N + 1 };
    double *xyz = malloc(3 * P * P * P * sizeof *xyz);
    int32_t *conn = malloc(8 * N * N * N * sizeof *conn);
    for (int k = 0; k < P; k++)
        for (int j = 0; j < P; j++)
            for (int i = 0; i < P; i++) {
                double *p = xyz + 3 * ((k * P + j) * P + i);
                p[0] = i;
                p[1] = j;
                p[2] = k;
            }
    int n = 0;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                int b = (k * P + j) * P + i;
                int32_t h[8] = {b, b + 1, b + P + 1, b + P,
                                b + P * P, b + P * P + 1, b + P * P + P + 1, b + P * P + P};
                memcpy(conn + 8 * n++, h, sizeof h);
            }
    getme_mesh *mesh;
    CHECK_EQ_INT(getme_mesh_create(&mesh, 3, P * P * P, xyz), GETME_OK);
    CHECK_EQ_INT(getme_mesh_add_elements(mesh, GETME_HEX, n, conn, NULL), GETME_OK);
    CHECK_EQ_INT(getme_mesh_fix_boundary(mesh, GETME_FIX_SKIN, NULL), GETME_OK);
    CHECK_EQ_INT(getme_mesh_distort(mesh, 7, 0.4, 0.0, 5), GETME_OK);
    for (int k = 0; k < GETME_NUM_MEASURES; k++) {
        getme_measure_stats s1, s2;
        omp_set_num_threads(1);
        CHECK_EQ_INT(getme_mesh_measure_stats(mesh, -1, (getme_measure)k, &s1), GETME_OK);
        omp_set_num_threads(2);
        CHECK_EQ_INT(getme_mesh_measure_stats(mesh, -1, (getme_measure)k, &s2), GETME_OK);
        CHECK(memcmp(&s1, &s2, sizeof s1) == 0);
        CHECK_EQ_INT(s1.num_elements, k == GETME_MEASURE_GAMMA ? 0 : n);
        /* the histogram is the values' bins by the documented formula
           (v - lo) / (hi - lo) * bins, the division by a width of 1
           included: in the one-measure and in the all-measures sweep */
        double *v = malloc((size_t)n * sizeof *v), lo, hi;
        CHECK_EQ_INT(getme_mesh_element_measures(mesh, (getme_measure)k, v), GETME_OK);
        CHECK_EQ_INT(getme_measure_range((getme_measure)k, &lo, &hi), GETME_OK);
        int64_t hist[GETME_HIST_BINS] = {0}, below = 0;
        for (int e = 0; e < n; e++) {
            if (isnan(v[e]))
                continue;
            if (v[e] < lo) {
                below++;
                continue;
            }
            int b = (int)((v[e] - lo) / (hi - lo) * GETME_HIST_BINS);
            hist[b >= GETME_HIST_BINS ? GETME_HIST_BINS - 1 : b]++;
        }
        free(v);
        getme_measure_stats all[GETME_NUM_TYPES * GETME_NUM_MEASURES];
        CHECK_EQ_INT(getme_mesh_measure_all(mesh, all), GETME_OK);
        CHECK(memcmp(s1.histogram, hist, sizeof hist) == 0);
        CHECK_EQ_INT(s1.num_below, below);
        CHECK(memcmp(all[GETME_HEX * GETME_NUM_MEASURES + k].histogram, hist,
                     sizeof hist) == 0);
        /* distorted: away from the regular value */
        if (k == DMAX)
            CHECK(s1.max > 90.0);
        else if (k != GETME_MEASURE_GAMMA)
            CHECK(s1.min < (k == DMIN ? 90.0 : 1.0));
    }
    getme_mesh_free(mesh);
    free(xyz);
    free(conn);
}

int main(void)
{
    test_regular();
    test_tet();
    test_hex();
    test_prism_pyramid();
    test_planar();
    test_arguments();
    test_mesh_stats();
    test_planar_orientation();
    test_threads();
    return check_summary("test_measures");
}
