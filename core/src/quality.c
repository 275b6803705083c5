/*
 * quality.c -- element type tables and the mean ratio quality kernels.
 *
 * Mean ratio (paper Eq. 3-5, docs/design.md §1): every node simplex k of
 * an element has the matrix D_k of its three spanning edges; with the target
 * matrix W of the type (columns: the same edges in the regular element),
 * S_k = D_k W^-1 and
 *
 *     q_k = 3 det(S_k)^(2/3) / tr(S_k^T S_k),     q = mean of the q_k,
 *
 * and the element is invalid (q = 0) as soon as one det(S_k) <= 0.  The 2-D
 * analogue for planar corners is q_k = 2 det(S_k) / tr(S_k^T S_k).
 *
 * These are the hot path of the smoother (hundreds of millions of calls), so
 * W^-1 is applied as precomputed constants, det^(2/3) is c^2 with c the cube
 * root of det (no pow), and every kernel is straight-line code whose only
 * decision is validity.  The cube root is our own (cube_root() below):
 * glibc's cbrt() took two thirds of the time of a hex quality.
 * Non-finite coordinates give a NaN det or q, which fails the "> 0" tests
 * and so also yields 0.
 */
/* Compiled with -fno-trapping-math (core/CMakeLists.txt says why): the
   mean ratio and corner lane loops, whose selects have a division or a
   square root on a side. */

#include "div3.h"
#include "internal.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

const int getme__nv[GETME_NUM_TYPES] = {4, 8, 6, 5, 3, 4};

static const int type_dim[GETME_NUM_TYPES] = {3, 3, 3, 3, 2, 2};

static const char *const type_name[GETME_NUM_TYPES] = {
    "tet", "hex", "prism", "pyramid", "tri", "quad"};

static int known_type(getme_elem_type type)
{
    /* unsigned compare also rejects negative values cast to the enum */
    return (unsigned)type < (unsigned)GETME_NUM_TYPES;
}

int getme_type_num_nodes(getme_elem_type type)
{
    return known_type(type) ? getme__nv[type] : 0;
}

int getme_type_dim(getme_elem_type type)
{
    return known_type(type) ? type_dim[type] : 0;
}

const char *getme_type_name(getme_elem_type type)
{
    return known_type(type) ? type_name[type] : "unknown";
}

/* ---- small vector helpers (inlined) ------------------------------------- */

/* e = x[b] - x[a] for nodes a, b of the element */
static inline void edge(const double *x, int a, int b, double e[3])
{
    e[0] = x[3 * b + 0] - x[3 * a + 0];
    e[1] = x[3 * b + 1] - x[3 * a + 1];
    e[2] = x[3 * b + 2] - x[3 * a + 2];
}

static inline double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* det of the 3x3 matrix with columns a, b, c = a . (b x c) */
static inline double det3(const double a[3], const double b[3],
                          const double c[3])
{
    return a[0] * (b[1] * c[2] - b[2] * c[1]) +
           a[1] * (b[2] * c[0] - b[0] * c[2]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/*
 * Cube root of x > 0, branch-free, within 4 ulp (6.7e-16 relative, measured
 * against cbrt() on 2e7 random x in 2^-1000..2^1000) and exact for cubes of
 * small integers (1 and 8 give 1 and 2, so regular elements give q = 1):
 * an initial guess from the exponent bits (bits/3 + a bias that makes the
 * guess good to a few per cent), two Halley steps (error cubed each) and a
 * Newton step (error squared, and it cleans the last rounding).  The
 * Halley steps divide before multiplying so nothing overflows below
 * x ~ 1e307.  Valid range: normal x up to 1e307, i.e. element edges between
 * ~1e-100 and ~1e100; x <= 0 or non-finite gives garbage or NaN, which the
 * callers' validity tests discard.  2-3x faster than glibc's cbrt().
 */
static inline double cube_root(double x)
{
    uint64_t bits;
    double y;
    memcpy(&bits, &x, sizeof bits);
    bits = bits / 3u + UINT64_C(0x2A9F7893782DA1CE);
    memcpy(&y, &bits, sizeof y);
    double y3 = y * y * y;
    y += y * ((x - y3) / (2.0 * y3 + x));
    y3 = y * y * y;
    y += y * ((x - y3) / (2.0 * y3 + x));
    return y + (x / (y * y) - y) * (1.0 / 3.0);
}

double getme__cube_root(double x)
{
    return cube_root(x);
}

/* cube_root() of n <= 8 GETME_LANES values at once (x and y do not
   overlap).  The same operations in the same order per value, so the
   results are bit-identical to cube_root(); the Halley and Newton steps
   are one loop over all the values, so every step is a vector instruction
   and the n independent chains overlap instead of waiting on each other's
   divisions.  The initial guess's bits / 3 is getme__div3_u64 (div3.h),
   the same integer in vector instructions (there is no 64-bit vector
   multiply-high); as scalar divisions through a memcpy'd array it cost
   the hex mean ratio 12 % (bench/kernels.sh 24.3 -> 21.4 ns).  gcc 12
   left this loop scalar with the bits memcpy'd as a whole array, and
   with a floor() in div3 (it becomes lfloor, which has no vector form).
   Without AVX-512 DQ (the portable build's dispatched copies) the 64-bit
   integer <-> double conversions have no vector instruction either, and
   div3 measured 5 % slower there than bits / 3u: that build keeps it.
   A native AVX2 build (Zen 3: no AVX-512) uses getme__div3_u64_bits, the
   same integer from bit tricks and a vector floor: bits / 3u kept this
   loop scalar there, 40 % of the hex mean ratio's samples (round 10).
   Only for the lane kernels (lanes, a constant where it is inlined): one
   hex's 8 values measured 10-15 % slower with it (bench/kernels.sh). */
static inline void cube_root_n(const double *restrict x, double *restrict y,
                               int n, int lanes)
{
    (void)lanes; /* used only in the AVX2 branch below */
#pragma omp simd
    for (int i = 0; i < n; i++) {
        union { double d; uint64_t u; } v = {x[i]};
#ifdef __AVX512DQ__
        v.u = getme__div3_u64(v.u) + UINT64_C(0x2A9F7893782DA1CE);
#elif defined(__AVX2__)
        v.u = (lanes ? getme__div3_u64_bits(v.u) : v.u / 3u) +
              UINT64_C(0x2A9F7893782DA1CE);
#else
        v.u = v.u / 3u + UINT64_C(0x2A9F7893782DA1CE);
#endif
        y[i] = v.d;
    }
#pragma omp simd
    for (int i = 0; i < n; i++) {
        double yi = y[i], y3, xi = x[i];
        y3 = yi * yi * yi;
        yi += yi * ((xi - y3) / (2.0 * y3 + xi));
        y3 = yi * yi * yi;
        yi += yi * ((xi - y3) / (2.0 * y3 + xi));
        y[i] = yi + (xi / (yi * yi) - yi) * (1.0 / 3.0);
    }
}

/* 3 det^(2/3) / frob2 for one simplex; its sign is checked by the caller */
static inline double ratio3(double det, double frob2)
{
    double c = cube_root(det);
    return 3.0 * c * c / frob2;
}

/* The element's q if every det was > 0 and q is a number, else 0.  A NaN
   from non-finite input fails "q > 0". */
static inline double valid_or_zero(int all_positive, double q)
{
    return (all_positive && q > 0.0) ? q : 0.0;
}

/* ---- tetrahedron -------------------------------------------------------- */

/*
 * W_tet = [[1, 1/2, 1/2], [0, sqrt3/2, sqrt3/6], [0, 0, sqrt(2/3)]] has
 * W^-1 = [[1, -1/sqrt3, -1/sqrt6], [0, 2/sqrt3, -1/sqrt6], [0, 0, 3/sqrt6]],
 * so the columns of S are e1, (2 e2 - e1)/sqrt3, (3 e3 - e1 - e2)/sqrt6 and
 * det S = det D * det W^-1 = sqrt2 det D.
 */
#define GETME_SQRT2 1.41421356237309504880
#define GETME_INV_SQRT3 0.57735026918962576451
#define GETME_INV_SQRT6 0.40824829046386301637

double getme__quality_tet(const double *x)
{
    double e1[3], e2[3], e3[3], s2[3], s3[3];
    edge(x, 0, 1, e1);
    edge(x, 0, 2, e2);
    edge(x, 0, 3, e3);
    for (int c = 0; c < 3; c++) {
        s2[c] = (2.0 * e2[c] - e1[c]) * GETME_INV_SQRT3;
        s3[c] = (3.0 * e3[c] - e1[c] - e2[c]) * GETME_INV_SQRT6;
    }
    double det = GETME_SQRT2 * det3(e1, e2, e3);
    double frob2 = dot3(e1, e1) + dot3(s2, s2) + dot3(s3, s3);
    return valid_or_zero(det > 0.0, ratio3(det, frob2));
}

/* ---- hexahedron --------------------------------------------------------- */

/* The paper's N^hex, zero-based; det = +1 on the unit cube in Gmsh order.
   W = I: S_k = D_k, the edges from node k to its three neighbours, in the
   order (node; neighbours) = (0; 3 4 1) (1; 0 5 2) (2; 1 6 3) (3; 2 7 0)
   (4; 7 5 0) (5; 4 6 1) (6; 5 7 2) (7; 6 4 3). */

/*
 * The corners' edge vectors are the 12 edges of the hex, each seen from
 * both of its ends: corner k's edge to node j is +E or -E for the stored
 * edge E = x[b] - x[a] between them, and x[j] - x[k] = -(x[k] - x[j])
 * exactly.  So the 12 edges are subtracted once and squared once (|E|^2
 * does not see the sign), and since negating an operand negates a
 * correctly rounded product or sum exactly, det3(+-E1, +-E2, +-E3) is
 * (the product of the signs) * det3(E1, E2, E3) to the bit, up to the sign
 * of a zero det, which no caller can see (only det > 0 counts, and the
 * cube root only of such a det).  For every corner: hex_corner_edges are
 * the edges to its 3 neighbours in N^hex's order; the
 * signs' product is -1 for the bottom corners 0-3, +1 for the top ones.
 */
static const unsigned char hex_edge_nodes[12][2] = {
    {0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
    {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
static const unsigned char hex_corner_edges[8][3] = {
    {3, 8, 0}, {0, 9, 1}, {1, 10, 2}, {2, 11, 3},
    {7, 4, 8}, {4, 5, 9}, {5, 6, 10}, {6, 7, 11}};

/* The mean ratio of L hexes whose coordinates are x[(3 i + d) L + l]
   (node i, coordinate d, element l): L = 1 is one hex, L = GETME_LANES a
   batch in lanes.  The same operations per corner as the textbook
   kernel (edges, det3, sum of squared edge lengths, cube root, 3 c^2 /
   frob2 summed in corner order); the 8 L determinants go through one
   cube_root_n, so every step is a vector instruction over corners or
   lanes and the Halley chains overlap.  always_inline: one copy per L (a
   shared copy with L unknown is not vectorised, measured 3x slower). */
__attribute__((always_inline)) static inline void
quality_hex_n(const double *restrict x, double *restrict q, const int L)
{
    double e[12][3][GETME_LANES], l2[12][GETME_LANES];
    double det[8 * GETME_LANES], frob2[8 * GETME_LANES], c[8 * GETME_LANES];
    for (int k = 0; k < 12; k++) {
        int a = 3 * hex_edge_nodes[k][0], b = 3 * hex_edge_nodes[k][1];
#pragma omp simd
        for (int l = 0; l < L; l++) {
            for (int d = 0; d < 3; d++)
                e[k][d][l] = x[(b + d) * L + l] - x[(a + d) * L + l];
            l2[k][l] = e[k][0][l] * e[k][0][l] + e[k][1][l] * e[k][1][l] +
                       e[k][2][l] * e[k][2][l];
        }
    }
    for (int k = 0; k < 8; k++) {
        double(*e1)[GETME_LANES] = e[hex_corner_edges[k][0]];
        double(*e2)[GETME_LANES] = e[hex_corner_edges[k][1]];
        double(*e3)[GETME_LANES] = e[hex_corner_edges[k][2]];
        double sign = k < 4 ? -1.0 : 1.0;
#pragma omp simd
        for (int l = 0; l < L; l++) {
            double d3 = e1[0][l] * (e2[1][l] * e3[2][l] - e2[2][l] * e3[1][l]) +
                        e1[1][l] * (e2[2][l] * e3[0][l] - e2[0][l] * e3[2][l]) +
                        e1[2][l] * (e2[0][l] * e3[1][l] - e2[1][l] * e3[0][l]);
            det[k * L + l] = sign * d3;
            frob2[k * L + l] = l2[hex_corner_edges[k][0]][l] +
                               l2[hex_corner_edges[k][1]][l] +
                               l2[hex_corner_edges[k][2]][l];
        }
    }
    cube_root_n(det, c, 8 * L, L > 1);
#pragma omp simd
    for (int l = 0; l < L; l++) {
        double s = 0.0;
        int ok = 1;
        for (int k = 0; k < 8; k++) {
            double ck = c[k * L + l];
            s += 3.0 * ck * ck / frob2[k * L + l];
            ok &= det[k * L + l] > 0.0;
        }
        q[l] = valid_or_zero(ok, 0.125 * s);
    }
}

double getme__quality_hex(const double *x)
{
    double q;
    quality_hex_n(x, &q, 1);
    return q;
}

/* ---- GETME_LANES elements at once --------------------------------------- */

/* getme__quality_tet and getme__quality_hex of GETME_LANES elements, x in
   lanes (x[3 i + d][l]: coordinate d of node i of element l).  The same
   operations in the same order per lane as the one-element kernels, and
   cube_root_n is bit-identical to cube_root, so every lane's q is the same
   bits; written as loops over the lanes so that they become vector
   instructions (the relaxation evaluates every element this way). */
__attribute__((always_inline)) static inline void
quality_tet_lanes(const double (*x)[GETME_LANES], double *q)
{
    enum { L = GETME_LANES };
    double det[L], frob2[L], c[L];
    /* getme__quality_tet spelled out per coordinate: with small arrays
       inside the lane loop gcc left it scalar */
#pragma omp simd
    for (int l = 0; l < L; l++) {
        double e1x = x[3][l] - x[0][l], e1y = x[4][l] - x[1][l],
               e1z = x[5][l] - x[2][l];
        double e2x = x[6][l] - x[0][l], e2y = x[7][l] - x[1][l],
               e2z = x[8][l] - x[2][l];
        double e3x = x[9][l] - x[0][l], e3y = x[10][l] - x[1][l],
               e3z = x[11][l] - x[2][l];
        double s2x = (2.0 * e2x - e1x) * GETME_INV_SQRT3,
               s2y = (2.0 * e2y - e1y) * GETME_INV_SQRT3,
               s2z = (2.0 * e2z - e1z) * GETME_INV_SQRT3;
        double s3x = (3.0 * e3x - e1x - e2x) * GETME_INV_SQRT6,
               s3y = (3.0 * e3y - e1y - e2y) * GETME_INV_SQRT6,
               s3z = (3.0 * e3z - e1z - e2z) * GETME_INV_SQRT6;
        det[l] = GETME_SQRT2 * (e1x * (e2y * e3z - e2z * e3y) +
                                e1y * (e2z * e3x - e2x * e3z) +
                                e1z * (e2x * e3y - e2y * e3x));
        frob2[l] = (e1x * e1x + e1y * e1y + e1z * e1z) +
                   (s2x * s2x + s2y * s2y + s2z * s2z) +
                   (s3x * s3x + s3y * s3y + s3z * s3z);
    }
    cube_root_n(det, c, L, 1);
#pragma omp simd
    for (int l = 0; l < L; l++)
        q[l] = valid_or_zero(det[l] > 0.0, 3.0 * c[l] * c[l] / frob2[l]);
}

__attribute__((always_inline)) static inline void
quality_hex_lanes(const double (*x)[GETME_LANES], double *q)
{
    quality_hex_n(&x[0][0], q, GETME_LANES);
}

GETME_LANES_TARGETS
int getme__quality_lanes(int type, const double (*x)[GETME_LANES], double *q)
{
    switch (type) {
    case GETME_TET: quality_tet_lanes(x, q); return 1;
    case GETME_HEX: quality_hex_lanes(x, q); return 1;
    default: return 0;
    }
}

/* n elements of one type, one after the other (x[3 nv e + 3 i + d], the
   layout getme__quality takes one element in), GETME_LANES at a time
   through the lane kernels where the type has one: for callers that
   gather elements themselves and evaluate many (statistics, set-up). */
void getme__qualities(int type, int32_t n, const double *x, double *q)
{
    int nv = (unsigned)type < (unsigned)GETME_NUM_TYPES ? getme__nv[type] : 0;
    int32_t e = 0;
    if (type == GETME_TET || type == GETME_HEX)
        for (; e + GETME_LANES <= n; e += GETME_LANES) {
            double xl[3 * GETME_MAX_NV][GETME_LANES];
            for (int l = 0; l < GETME_LANES; l++)
                for (int i = 0; i < 3 * nv; i++)
                    xl[i][l] = x[3 * nv * (e + l) + i];
            getme__quality_lanes(type, (const double(*)[GETME_LANES])xl, q + e);
        }
    for (; e < n; e++)
        q[e] = getme__quality(type, x + 3 * nv * e);
}

/* ---- prism -------------------------------------------------------------- */

/*
 * W_prism = [[1, 1/2, 0], [0, sqrt3/2, 0], [0, 0, 1]] (two triangle edges and
 * the vertical edge of a corner of the unit regular prism); W^-1 gives the
 * columns e1, (2 e2 - e1)/sqrt3, e3 and det S = (2/sqrt3) det D.
 */
static inline double prism_corner(const double *x, int a, int b, int c, int d,
                                  double *det)
{
    double e1[3], e2[3], e3[3], s2[3];
    edge(x, a, b, e1);
    edge(x, a, c, e2);
    edge(x, a, d, e3);
    for (int k = 0; k < 3; k++)
        s2[k] = (2.0 * e2[k] - e1[k]) * GETME_INV_SQRT3;
    *det = 2.0 * GETME_INV_SQRT3 * det3(e1, e2, e3);
    return ratio3(*det, dot3(e1, e1) + dot3(s2, s2) + dot3(e3, e3));
}

double getme__quality_prism(const double *x)
{
    double d0, d1, d2, d3, d4, d5;
    double s = prism_corner(x, 0, 1, 2, 3, &d0) + prism_corner(x, 1, 2, 0, 4, &d1) +
               prism_corner(x, 2, 0, 1, 5, &d2) + prism_corner(x, 3, 5, 4, 0, &d3) +
               prism_corner(x, 4, 3, 5, 1, &d4) + prism_corner(x, 5, 4, 3, 2, &d5);
    int ok = (d0 > 0.0) & (d1 > 0.0) & (d2 > 0.0) & (d3 > 0.0) & (d4 > 0.0) &
             (d5 > 0.0);
    return valid_or_zero(ok, s * (1.0 / 6.0));
}

/* ---- pyramid ------------------------------------------------------------ */

/*
 * W_pyr = [[1, 0, 1/2], [0, 1, 1/2], [0, 0, 1/sqrt2]] (two base edges and the
 * edge to the apex of the pyramid with all edges 1); W^-1 gives the columns
 * e1, e2, sqrt2 (e3 - (e1 + e2)/2) and det S = sqrt2 det D.  The apex itself
 * has no simplex of its own (its four edges do not span a simplex), as in
 * docs/design.md §1: the four base corners see every edge of the pyramid.
 */
static inline double pyramid_corner(const double *x, int a, int b, int c,
                                    double *det)
{
    double e1[3], e2[3], e3[3], s3[3];
    edge(x, a, b, e1);
    edge(x, a, c, e2);
    edge(x, a, 4, e3);
    for (int k = 0; k < 3; k++)
        s3[k] = GETME_SQRT2 * (e3[k] - 0.5 * (e1[k] + e2[k]));
    *det = GETME_SQRT2 * det3(e1, e2, e3);
    return ratio3(*det, dot3(e1, e1) + dot3(e2, e2) + dot3(s3, s3));
}

double getme__quality_pyramid(const double *x)
{
    double d0, d1, d2, d3;
    double s = pyramid_corner(x, 0, 1, 3, &d0) + pyramid_corner(x, 1, 2, 0, &d1) +
               pyramid_corner(x, 2, 3, 1, &d2) + pyramid_corner(x, 3, 0, 2, &d3);
    int ok = (d0 > 0.0) & (d1 > 0.0) & (d2 > 0.0) & (d3 > 0.0);
    return valid_or_zero(ok, 0.25 * s);
}

/* ---- planar types (x, y only) ------------------------------------------- */

/* z of the cross product of the xy edges a->b and a->c */
static inline double cross2(const double *x, int a, int b, int c)
{
    return (x[3 * b] - x[3 * a]) * (x[3 * c + 1] - x[3 * a + 1]) -
           (x[3 * b + 1] - x[3 * a + 1]) * (x[3 * c] - x[3 * a]);
}

static inline double len2_xy(const double *x, int a, int b)
{
    double dx = x[3 * b] - x[3 * a], dy = x[3 * b + 1] - x[3 * a + 1];
    return dx * dx + dy * dy;
}

/* q = 4 sqrt3 A / sum |e|^2 with 2A = cross2: 1 for the equilateral one. */
double getme__quality_tri(const double *x)
{
    double twice_area = cross2(x, 0, 1, 2);
    double sum = len2_xy(x, 0, 1) + len2_xy(x, 1, 2) + len2_xy(x, 2, 0);
    double q = 2.0 * 1.73205080756887729353 * twice_area / sum;
    return valid_or_zero(twice_area > 0.0, q);
}

/* W = I: corner k with e1 = x_{k+1} - x_k, e2 = x_{k-1} - x_k has
   q_k = 2 det(e1, e2) / (|e1|^2 + |e2|^2). */
static inline double quad_corner(const double *x, int k, int next, int prev,
                                 double *det)
{
    *det = cross2(x, k, next, prev);
    return 2.0 * *det / (len2_xy(x, k, next) + len2_xy(x, k, prev));
}

double getme__quality_quad(const double *x)
{
    double d0, d1, d2, d3;
    double s = quad_corner(x, 0, 1, 3, &d0) + quad_corner(x, 1, 2, 0, &d1) +
               quad_corner(x, 2, 3, 1, &d2) + quad_corner(x, 3, 0, 2, &d3);
    int ok = (d0 > 0.0) & (d1 > 0.0) & (d2 > 0.0) & (d3 > 0.0);
    return valid_or_zero(ok, 0.25 * s);
}

/* ---- dispatch ----------------------------------------------------------- */

double getme__quality(int type, const double *x)
{
    switch (type) {
    case GETME_TET: return getme__quality_tet(x);
    case GETME_HEX: return getme__quality_hex(x);
    case GETME_PRISM: return getme__quality_prism(x);
    case GETME_PYRAMID: return getme__quality_pyramid(x);
    case GETME_TRI: return getme__quality_tri(x);
    case GETME_QUAD: return getme__quality_quad(x);
    default: return 0.0;
    }
}

double getme_element_quality(getme_elem_type type, const double *xyz)
{
    if (xyz == NULL)
        return 0.0;
    return getme__quality((int)type, xyz);
}

/* ---- worst corner (the guard of docs/method.md, "no corner left behind") */

/* det / (|e1| |e2| |e3|) of one corner, times the factor that makes the
   regular element's corner 1; -1 if an edge has length 0 or a value is
   not finite (the caller treats it as the worst possible corner). */
static inline double corner_sj3(const double *x, int a, int b, int c, int d,
                                double scale)
{
    double e1[3], e2[3], e3[3];
    edge(x, a, b, e1);
    edge(x, a, c, e2);
    edge(x, a, d, e3);
    double l = dot3(e1, e1) * dot3(e2, e2) * dot3(e3, e3);
    double s = scale * det3(e1, e2, e3) / sqrt(l);
    return l > 0.0 && isfinite(s) ? s : -1.0;
}

/* fmin(m, v) for numbers (never NaN, as the corner values are), without
   the libm call gcc keeps for fmin: the smaller one, and fmin itself only
   for equal values, where it picks between +0 and -0. */
static inline double min_corner(double m, double v)
{
    return v < m ? v : v == m ? fmin(m, v) : m;
}

/* min_corner of the 8 values v[k * stride], in corner order, from 1.
   One copy (noinline) for the one-hex and the lane kernel: -O3 turned
   the folds of the two into different instructions that disagreed on
   the sign of a zero minimum (fmin's choice between +0 and -0). */
__attribute__((noinline)) static double hex_corner_fold(const double *v,
                                                        int stride)
{
    double m = 1.0;
    for (int k = 0; k < 8; k++)
        m = min_corner(m, v[k * stride]);
    return m;
}

/* corner_sj3 of the 8 hex corners (scale 1), min'd in corner order: the
   12 edges subtracted and squared once (hex_corner_edges), each corner's
   three edge vectors with their signs (negation is exact, so det keeps
   the bits of the textbook corner, the sign of a zero included), then
   the 8 square roots and divisions in one vector loop. */
static double corner_sj_hex(const double *x)
{
    double e[12][3], l2[12], a[3][3][8], l[8], v[8];
    for (int k = 0; k < 12; k++) {
        edge(x, hex_edge_nodes[k][0], hex_edge_nodes[k][1], e[k]);
        l2[k] = dot3(e[k], e[k]);
    }
    for (int k = 0; k < 8; k++) {
        /* the first edge of a corner points into it, the second away,
           the third away from a bottom corner and into a top one */
        double sg[3] = {-1.0, 1.0, k < 4 ? 1.0 : -1.0};
        for (int j = 0; j < 3; j++)
            for (int d = 0; d < 3; d++)
                a[j][d][k] = sg[j] * e[hex_corner_edges[k][j]][d];
        l[k] = l2[hex_corner_edges[k][0]] * l2[hex_corner_edges[k][1]] *
               l2[hex_corner_edges[k][2]];
    }
#pragma omp simd
    for (int k = 0; k < 8; k++) {
        double det = a[0][0][k] * (a[1][1][k] * a[2][2][k] - a[1][2][k] * a[2][1][k]) +
                     a[0][1][k] * (a[1][2][k] * a[2][0][k] - a[1][0][k] * a[2][2][k]) +
                     a[0][2][k] * (a[1][0][k] * a[2][1][k] - a[1][1][k] * a[2][0][k]);
        double sj = 1.0 * det / sqrt(l[k]);
        v[k] = l[k] > 0.0 && isfinite(sj) ? sj : -1.0;
    }
    return hex_corner_fold(v, 1);
}

/* corner_sj_hex of GETME_CORNER_LANES hexes at once, coordinates
   x[(3 i + d) * GETME_CORNER_LANES + l] (node i, coordinate d, hex l):
   the same operations in the same order per hex (edges, squared lengths,
   signed corner edges, det, square root, division, then the minimum in
   corner order), each a vector instruction over the hexes, so every
   m[l] has the bits corner_sj_hex gives hex l.  The initial corner
   minimum computes every hex's corners (nothing is pruned at a fair
   input's qualities): one at a time, the 12 edges and 12 squared
   lengths were scalar. */
void getme__corner_sj_hex_lanes(const double *restrict x, double *restrict m)
{
    enum { L = GETME_CORNER_LANES };
    double e[12][3][L], l2[12][L], v[8][L];
    for (int k = 0; k < 12; k++) {
        int a = 3 * hex_edge_nodes[k][0], b = 3 * hex_edge_nodes[k][1];
        for (int d = 0; d < 3; d++)
#pragma omp simd
            for (int l = 0; l < L; l++)
                e[k][d][l] = x[(b + d) * L + l] - x[(a + d) * L + l];
#pragma omp simd
        for (int l = 0; l < L; l++)
            l2[k][l] = e[k][0][l] * e[k][0][l] + e[k][1][l] * e[k][1][l] +
                       e[k][2][l] * e[k][2][l];
    }
    for (int k = 0; k < 8; k++) {
        const double s2 = k < 4 ? 1.0 : -1.0;
        const unsigned char *ce = hex_corner_edges[k];
#pragma omp simd
        for (int l = 0; l < L; l++) {
            double a00 = -e[ce[0]][0][l], a01 = -e[ce[0]][1][l], a02 = -e[ce[0]][2][l];
            double a10 = e[ce[1]][0][l], a11 = e[ce[1]][1][l], a12 = e[ce[1]][2][l];
            double a20 = s2 * e[ce[2]][0][l], a21 = s2 * e[ce[2]][1][l],
                   a22 = s2 * e[ce[2]][2][l];
            double len = l2[ce[0]][l] * l2[ce[1]][l] * l2[ce[2]][l];
            double det = a00 * (a11 * a22 - a12 * a21) +
                         a01 * (a12 * a20 - a10 * a22) +
                         a02 * (a10 * a21 - a11 * a20);
            double sj = 1.0 * det / sqrt(len);
            /* & not &&: a branch would stop the vectoriser */
            v[k][l] = (len > 0.0) & (isfinite(sj) != 0) ? sj : -1.0;
        }
    }
    for (int l = 0; l < L; l++)
        m[l] = hex_corner_fold(&v[0][l], L);
}

static inline double corner_sj2(const double *x, int k, int next, int prev)
{
    double l = len2_xy(x, k, next) * len2_xy(x, k, prev);
    double s = cross2(x, k, next, prev) / sqrt(l);
    return l > 0.0 && isfinite(s) ? s : -1.0;
}

double getme__corner_sj(int type, const double *x)
{
    double m = 1.0;
    switch (type) {
    case GETME_HEX:
        return corner_sj_hex(x);
    case GETME_PRISM: {
        /* triangle corners span 60 degrees: 2/sqrt3 makes them 1 */
        static const unsigned char pc[6][4] = {{0, 1, 2, 3}, {1, 2, 0, 4},
                                               {2, 0, 1, 5}, {3, 5, 4, 0},
                                               {4, 3, 5, 1}, {5, 4, 3, 2}};
        for (int k = 0; k < 6; k++)
            m = min_corner(m, corner_sj3(x, pc[k][0], pc[k][1], pc[k][2], pc[k][3],
                                   2.0 * GETME_INV_SQRT3));
        return m;
    }
    case GETME_PYRAMID: {
        /* base corner of the all-edges-1 pyramid: det = 1/sqrt2 */
        static const unsigned char yc[4][3] = {{0, 1, 3}, {1, 2, 0},
                                               {2, 3, 1}, {3, 0, 2}};
        for (int k = 0; k < 4; k++)
            m = min_corner(m, corner_sj3(x, yc[k][0], yc[k][1], yc[k][2], 4,
                                   GETME_SQRT2));
        return m;
    }
    case GETME_QUAD:
        m = min_corner(m, corner_sj2(x, 0, 1, 3));
        m = min_corner(m, corner_sj2(x, 1, 2, 0));
        m = min_corner(m, corner_sj2(x, 2, 3, 1));
        return min_corner(m, corner_sj2(x, 3, 0, 2));
    default:
        return 1.0; /* simplices: their mean ratio is their only corner */
    }
}
