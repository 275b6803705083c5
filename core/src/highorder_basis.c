/*
 * highorder_basis.c -- the second-order reference elements: node positions
 * in Gmsh's order (docs/highorder.md lists them; tests/msh compares them
 * with gmsh.model.mesh.getElementProperties), each type's polynomial space,
 * and from these the shape function derivatives at the nodes.
 *
 * The shape functions are not written out by hand: for a space of
 * monomials m_0..m_{n-1} and reference nodes xi_0..xi_{n-1}, the functions
 * N_j with N_j(xi_k) = delta_jk have coefficients C = V^-1 with
 * V[k][m] = m_m(xi_k).  So each type needs only facts (node positions and
 * the space: P2 for tets and triangles, serendipity for hex20 and quad8,
 * Q2 for hex27 and quad9, P2 x {1, z} plus z^2 {1, x, y} for prism15,
 * P2 x Q2 for prism18), and a wrong table shows as a singular V.
 */
#include "highorder.h"

#include <math.h>
#include <string.h>

const int getme__ho_nv[GETME_NUM_HO_TYPES] = {10, 20, 27, 15, 18, 6, 8, 9,
                                               13, 14};
const int getme__ho_lin[GETME_NUM_HO_TYPES] = {
    GETME_TET, GETME_HEX, GETME_HEX, GETME_PRISM, GETME_PRISM,
    GETME_TRI, GETME_QUAD, GETME_QUAD, GETME_PYRAMID, GETME_PYRAMID};

/* Reference nodes, Gmsh's order (getElementProperties of MSH types 11, 17,
   12, 18, 13, 9, 16, 10). */
static const double ref_tet10[10][3] = {
    {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {.5, 0, 0},
    {.5, .5, 0}, {0, .5, 0}, {0, 0, .5}, {0, .5, .5}, {.5, 0, .5}};
static const double ref_hex27[27][3] = {
    {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
    {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1},
    {0, -1, -1}, {-1, 0, -1}, {-1, -1, 0}, {1, 0, -1},
    {1, -1, 0}, {0, 1, -1}, {1, 1, 0}, {-1, 1, 0},
    {0, -1, 1}, {-1, 0, 1}, {1, 0, 1}, {0, 1, 1},
    {0, 0, -1}, {0, -1, 0}, {-1, 0, 0}, {1, 0, 0},
    {0, 1, 0}, {0, 0, 1}, {0, 0, 0}};
static const double ref_prism18[18][3] = {
    {0, 0, -1}, {1, 0, -1}, {0, 1, -1}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1},
    {.5, 0, -1}, {0, .5, -1}, {0, 0, 0}, {.5, .5, -1}, {1, 0, 0},
    {0, 1, 0}, {.5, 0, 1}, {0, .5, 1}, {.5, .5, 1},
    {.5, 0, 0}, {0, .5, 0}, {.5, .5, 0}};
static const double ref_tri6[6][3] = {
    {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {.5, 0, 0}, {.5, .5, 0}, {0, .5, 0}};
static const double ref_quad9[9][3] = {
    {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0},
    {0, -1, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, 0, 0}};

/* Gmsh's pyramid: base [-1, 1]^2 at z = 0, apex (0, 0, 1) (types 19, 14). */
static const double ref_pyr14[14][3] = {
    {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1},
    {0, -1, 0}, {-1, 0, 0}, {-.5, -.5, .5}, {1, 0, 0}, {.5, -.5, .5},
    {0, 1, 0}, {.5, .5, .5}, {-.5, .5, .5}, {0, 0, 0}};

/* hex20, prism15, quad8 and pyramid13 are the first nodes of hex27,
   prism18, quad9 and pyramid14. */
static const double (*ref_nodes(int type))[3]
{
    switch (type) {
    case GETME_TET10: return ref_tet10;
    case GETME_HEX20: case GETME_HEX27: return ref_hex27;
    case GETME_PRISM15: case GETME_PRISM18: return ref_prism18;
    case GETME_TRI6: return ref_tri6;
    case GETME_PYRAMID13: case GETME_PYRAMID14: return ref_pyr14;
    default: return ref_quad9;
    }
}

/* Exponents (x, y, z) of the monomials of each type's space. */
typedef struct { int8_t e[27][3]; } space;

static int fill_space(int type, space *s)
{
    int n = 0;
    switch (type) {
    case GETME_TET10: case GETME_TRI6: {
        int dim = type == GETME_TET10 ? 3 : 2;
        for (int a = 0; a <= 2; a++)
            for (int b = 0; a + b <= 2; b++)
                for (int c = 0; a + b + c <= 2 && (dim == 3 || c == 0); c++) {
                    s->e[n][0] = (int8_t)a, s->e[n][1] = (int8_t)b;
                    s->e[n++][2] = (int8_t)c;
                }
        return n;
    }
    case GETME_HEX27: case GETME_QUAD9: case GETME_HEX20: case GETME_QUAD8: {
        int three = type == GETME_HEX27 || type == GETME_HEX20;
        int serendipity = type == GETME_HEX20 || type == GETME_QUAD8;
        for (int a = 0; a <= 2; a++)
            for (int b = 0; b <= 2; b++)
                for (int c = 0; c <= (three ? 2 : 0); c++) {
                    /* serendipity: a square may appear only next to
                       linear factors: (a==2)+(b==2)+(c==2) <= 1 and the
                       total "superlinear degree" as in Q1 + squares */
                    if (serendipity && ((a == 2) + (b == 2) + (c == 2) > 1))
                        continue;
                    s->e[n][0] = (int8_t)a, s->e[n][1] = (int8_t)b;
                    s->e[n++][2] = (int8_t)c;
                }
        return n;
    }
    case GETME_PYRAMID13: case GETME_PYRAMID14:
        /* Gmsh's (Bergot's) rational pyramid space of order 2: with
           w = 1 - z, xh = x / w, yh = y / w, the functions
           xh^a yh^b w^max(a, b) z^c for a, b <= 2, c <= 2 - max(a, b)
           (14); pyramid13 drops xh^2 yh^2 w^2.  e holds (a, b, c); see
           pyr_fn.  tests/highorder/test_highorder_msh.py compares values
           and gradients with gmsh.model.mesh.getBasisFunctions. */
        for (int a = 0; a <= 2; a++)
            for (int b = 0; b <= 2; b++)
                for (int c = 0; c <= 2 - (a > b ? a : b); c++) {
                    if (type == GETME_PYRAMID13 && a == 2 && b == 2)
                        continue;
                    s->e[n][0] = (int8_t)a, s->e[n][1] = (int8_t)b;
                    s->e[n++][2] = (int8_t)c;
                }
        return n;
    default: { /* prisms: P2(x, y) times powers of z */
        for (int a = 0; a <= 2; a++)
            for (int b = 0; a + b <= 2; b++)
                for (int c = 0; c <= 2; c++) {
                    if (type == GETME_PRISM15 && c == 2 && a + b > 1)
                        continue;
                    s->e[n][0] = (int8_t)a, s->e[n][1] = (int8_t)b;
                    s->e[n++][2] = (int8_t)c;
                }
        return n;
    }
    }
}

static double ipow(double x, int k)
{
    return k == 0 ? 1.0 : k == 1 ? x : x * x;
}

/* Value, or derivative along axis d (d >= 0), of monomial e at p. */
static double mono(const int8_t e[3], const double p[3], int d)
{
    double v = 1.0;
    for (int a = 0; a < 3; a++) {
        if (a == d) {
            if (e[a] == 0)
                return 0.0;
            v *= e[a] * ipow(p[a], e[a] - 1);
        } else {
            v *= ipow(p[a], e[a]);
        }
    }
    return v;
}

/* Value, or derivative along axis d, of the pyramid function e at p (see
   fill_space).  At the apex (w = 0) the gradients are 0/0; their limit
   along the axis (xh = yh = 0) is taken, which is what Gmsh 4.8's
   getBasisFunctions returns there (and at z = 1 - 1e-6 on the axis). */
static double pyr_fn(const int8_t e[3], const double p[3], int d)
{
    int a = e[0], b = e[1], c = e[2], m = a > b ? a : b;
    double w = 1.0 - p[2], z = p[2];
    double xh = w != 0.0 ? p[0] / w : 0.0, yh = w != 0.0 ? p[1] / w : 0.0;
    switch (d) {
    case -1:
        return ipow(xh, a) * ipow(yh, b) * ipow(w, m) * ipow(z, c);
    case 0:
        return a ? a * ipow(xh, a - 1) * ipow(yh, b) * ipow(w, m - 1) *
                       ipow(z, c)
                 : 0.0;
    case 1:
        return b ? b * ipow(xh, a) * ipow(yh, b - 1) * ipow(w, m - 1) *
                       ipow(z, c)
                 : 0.0;
    default: {
        /* x^a y^b w^(m-a-b) z^c: d/dz of w^(m-a-b) is (a+b-m) w^(m-a-b-1) */
        double v = 0.0;
        if (a + b > m)
            v += (a + b - m) * ipow(xh, a) * ipow(yh, b) * ipow(w, m - 1) *
                 ipow(z, c);
        if (c)
            v += c * ipow(xh, a) * ipow(yh, b) * ipow(w, m) * ipow(z, c - 1);
        return v;
    }
    }
}

static double basis_fn(int type, const int8_t e[3], const double p[3], int d)
{
    return type == GETME_PYRAMID13 || type == GETME_PYRAMID14
               ? pyr_fn(e, p, d)
               : mono(e, p, d);
}

/* Invert the n x n matrix a (row-major, GETME_HO_MAX_NV stride) into inv by
   Gauss-Jordan elimination with partial pivoting; -1 if singular. */
static int invert(int n, double a[][GETME_HO_MAX_NV],
                  double inv[][GETME_HO_MAX_NV])
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            inv[i][j] = i == j;
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        if (fabs(a[p][c]) < 1e-12)
            return -1;
        for (int j = 0; j < n; j++) {
            double t = a[c][j]; a[c][j] = a[p][j]; a[p][j] = t;
            t = inv[c][j]; inv[c][j] = inv[p][j]; inv[p][j] = t;
        }
        double s = 1.0 / a[c][c];
        for (int j = 0; j < n; j++)
            a[c][j] *= s, inv[c][j] *= s;
        for (int r = 0; r < n; r++) {
            if (r == c || a[r][c] == 0.0)
                continue;
            double f = a[r][c];
            for (int j = 0; j < n; j++)
                a[r][j] -= f * a[c][j], inv[r][j] -= f * inv[c][j];
        }
    }
    return 0;
}

static int same_point(const double *a, const double *b)
{
    return fabs(a[0] - b[0]) < 1e-12 && fabs(a[1] - b[1]) < 1e-12 &&
           fabs(a[2] - b[2]) < 1e-12;
}

/* Which corners a dependent node belongs to: the edge whose reference
   midpoint it is, else the quad face whose centre it is, else (hex27's
   last node) the body. */
static int find_entity(getme_ho_info *info, const double (*ref)[3],
                       int k)
{
    int lin = info->lin;
    const getme_edge_table *et = &getme__edges[lin];
    for (int i = 0; i < et->num_edges; i++) {
        const double *a = ref[et->node[i][0]], *b = ref[et->node[i][1]];
        double m[3] = {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]),
                       0.5 * (a[2] + b[2])};
        if (same_point(m, ref[k])) {
            info->ncorner[k] = 2;
            info->corner[k][0] = et->node[i][0];
            info->corner[k][1] = et->node[i][1];
            return 0;
        }
    }
    const getme_face_table *ft = &getme__faces[lin];
    for (int f = 0; f < ft->num_faces && info->dim == 3; f++) {
        if (ft->size[f] != 4)
            continue;
        double m[3] = {0, 0, 0};
        for (int i = 0; i < 4; i++)
            for (int d = 0; d < 3; d++)
                m[d] += 0.25 * ref[ft->node[f][i]][d];
        if (same_point(m, ref[k])) {
            info->ncorner[k] = 4;
            for (int i = 0; i < 4; i++)
                info->corner[k][i] = ft->node[f][i];
            return 0;
        }
    }
    /* the centre of the whole element: quad9's 9th node (a face in the
       plane) or hex27's 27th */
    info->ncorner[k] = (int8_t)info->nlin;
    for (int i = 0; i < info->nlin; i++)
        info->corner[k][i] = (int8_t)i;
    return info->nlin == 4 || info->nlin == 8 ? 0 : -1;
}

int getme__ho_info_init(int type, getme_ho_info *info)
{
    _Static_assert(GETME_NUM_HO_TYPES == 10, "tables cover every type");
    memset(info, 0, sizeof *info);
    info->nv = getme__ho_nv[type];
    info->lin = getme__ho_lin[type];
    info->nlin = getme__nv[info->lin];
    info->dim = getme_type_dim((getme_elem_type)info->lin);
    const double (*ref)[3] = ref_nodes(type);
    space s;
    int n = fill_space(type, &s);
    if (n != info->nv)
        return -1;
    double v[GETME_HO_MAX_NV][GETME_HO_MAX_NV], c[GETME_HO_MAX_NV][GETME_HO_MAX_NV];
    for (int k = 0; k < n; k++)
        for (int m = 0; m < n; m++)
            v[k][m] = basis_fn(type, s.e[m], ref[k], -1);
    if (invert(n, v, c))
        return -1;
    /* N_j = sum_m c[m][j] m_m, so dN_j/dd at node k = sum_m c[m][j] dm_m */
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            for (int d = 0; d < 3; d++) {
                double sum = 0.0;
                for (int m = 0; m < n; m++)
                    sum += c[m][j] * basis_fn(type, s.e[m], ref[k], d);
                info->dn[k][j][d] = sum;
            }
    int m = 0;
    for (int k = 0; k < n; k++)
        for (int d = 0; d < 3; d++) {
            info->sp_ptr[3 * k + d] = (int16_t)m;
            for (int j = 0; j < n; j++) {
                if (info->dn[k][j][d] == 0.0)
                    continue;
                if (m == GETME_HO_MAX_NZ)
                    return -1;
                info->sp_n[m] = (uint8_t)j;
                info->sp_v[m] = info->dn[k][j][d];
                m++;
            }
        }
    info->sp_ptr[3 * n] = (int16_t)m;
    for (int k = info->nlin; k < n; k++)
        if (find_entity(info, ref, k))
            return -1;
    return 0;
}

/* The determinant of node k's Jacobian j (dim 2: its upper 2 x 2 block);
   NaN becomes -infinity, so that it fails every "det > 0". */
static inline double det_at(const getme_ho_info *info, double j[3][3])
{
    double det = info->dim == 2
                     ? j[0][0] * j[1][1] - j[0][1] * j[1][0]
                     : j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) -
                           j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) +
                           j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    return det == det ? det : -INFINITY;
}

/* Why the sparse sums are the dense sums' bits: each J entry is a sum,
   in shape function order, of products p dN starting from +0.  A term
   with dN = 0 is p * 0 = +-0 for a finite p, and adding +-0 changes no
   sum: a nonzero sum stays itself, and a zero sum is +0 (it starts at +0,
   and in round-to-nearest x + (-x) and +0 + -0 are +0), which stays +0.
   Only an infinite or NaN coordinate makes p * 0 a NaN; then the dense
   sums run, so that the NaN reaches the determinants as before. */
void getme__ho_det_range(const getme_ho_info *info, const double *x,
                         double *dmin, double *dmax)
{
    double lo = INFINITY, hi = -INFINITY, probe = 0.0;
    for (int i = 0; i < 3 * info->nv; i++)
        probe += x[i] * 0.0; /* NaN iff some coordinate is not finite */
    for (int k = 0; k < info->nv; k++) {
        double j[3][3] = {{0}};
        if (probe == probe) {
            /* column d of J in three registers (a sum per entry, in shape
               function order, as the dense loop adds them) */
            for (int d = 0; d < 3; d++) {
                double s0 = 0.0, s1 = 0.0, s2 = 0.0;
                for (int e = info->sp_ptr[3 * k + d]; e < info->sp_ptr[3 * k + d + 1];
                     e++) {
                    const double *p = x + 3 * info->sp_n[e];
                    double g = info->sp_v[e];
                    s0 += p[0] * g;
                    s1 += p[1] * g;
                    s2 += p[2] * g;
                }
                j[0][d] = s0, j[1][d] = s1, j[2][d] = s2;
            }
        } else {
            for (int n = 0; n < info->nv; n++) {
                const double *g = info->dn[k][n];
                const double *p = x + 3 * n;
                for (int a = 0; a < 3; a++)
                    for (int d = 0; d < 3; d++)
                        j[a][d] += p[a] * g[d];
            }
        }
        double det = det_at(info, j);
        lo = det < lo ? det : lo;
        hi = det > hi ? det : hi;
    }
    *dmin = lo;
    *dmax = hi;
}

/* getme__ho_det_range of GETME_LANES elements of one type at once, x in
   lanes (x[3 n + a][l]: coordinate a of node n of element l): for each
   lane the same operations in the same order, so the same bits, as
   vector instructions across the lanes.  Returns 0, with nothing
   written, if some lane has an infinite or NaN coordinate (those take
   the one-element function's dense sums). */
int getme__ho_det_range_lanes(const getme_ho_info *info,
                              const double (*x)[GETME_LANES], double *dmin,
                              double *dmax)
{
    enum { L = GETME_LANES };
    double probe[L] = {0};
    for (int i = 0; i < 3 * info->nv; i++)
#pragma omp simd
        for (int l = 0; l < L; l++)
            probe[l] += x[i][l] * 0.0;
    int finite = 1;
    for (int l = 0; l < L; l++)
        finite &= probe[l] == probe[l];
    if (!finite)
        return 0;
    double lo[L], hi[L];
    for (int l = 0; l < L; l++)
        lo[l] = INFINITY, hi[l] = -INFINITY;
    for (int k = 0; k < info->nv; k++) {
        double j[3][3][L];
        for (int d = 0; d < 3; d++) {
            double s0[L] = {0}, s1[L] = {0}, s2[L] = {0};
            for (int e = info->sp_ptr[3 * k + d]; e < info->sp_ptr[3 * k + d + 1];
                 e++) {
                const double(*p)[L] = x + 3 * info->sp_n[e];
                double g = info->sp_v[e];
#pragma omp simd
                for (int l = 0; l < L; l++) {
                    s0[l] += p[0][l] * g;
                    s1[l] += p[1][l] * g;
                    s2[l] += p[2][l] * g;
                }
            }
            for (int l = 0; l < L; l++)
                j[0][d][l] = s0[l], j[1][d][l] = s1[l], j[2][d][l] = s2[l];
        }
#pragma omp simd
        for (int l = 0; l < L; l++) {
            double det =
                info->dim == 2
                    ? j[0][0][l] * j[1][1][l] - j[0][1][l] * j[1][0][l]
                    : j[0][0][l] * (j[1][1][l] * j[2][2][l] - j[1][2][l] * j[2][1][l]) -
                          j[0][1][l] * (j[1][0][l] * j[2][2][l] - j[1][2][l] * j[2][0][l]) +
                          j[0][2][l] * (j[1][0][l] * j[2][1][l] - j[1][1][l] * j[2][0][l]);
            det = det == det ? det : -INFINITY; /* det_at */
            lo[l] = det < lo[l] ? det : lo[l];
            hi[l] = det > hi[l] ? det : hi[l];
        }
    }
    for (int l = 0; l < L; l++)
        dmin[l] = lo[l], dmax[l] = hi[l];
    return 1;
}
