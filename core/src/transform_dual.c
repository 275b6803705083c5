/*
 * transform_dual.c -- the dual element transformation of hexahedra, prisms
 * and pyramids (paper ref. [28, 32]; docs/design.md §2), with the
 * per-type calibration that makes prisms and pyramids converge to their
 * regular element (docs/kernels.md explains and measures it).
 *
 * For node p_i: the centroids c_1..c_k of its k incident faces, ordered
 * around p_i, span a small "dual" polygon with mean m_i and vector area
 *
 *     n_i = 1/2 sum_j (c_j - m_i) x (c_{j+1} - m_i),
 *
 * oriented away from the element, towards p_i.  The new node is
 *
 *     p_i' = m_i + sigma * n_i / sqrt|n_i|,
 *
 * then the element is scaled about its centroid to keep its edge-length sum
 * and put back on the input centroid (transform_scale.h says why).
 *
 * Calibration.  For hexahedra the iteration converges to the cube.  For
 * prisms and pyramids the plain construction converges to a flattened prism
 * (q ~ 0.93) and a too tall pyramid (q ~ 0.84): it has no reason to know the
 * height of the regular element.  On the symmetric elements of these types
 * a step changes only the ratio height : edge, so one scalar per type fixes
 * the fixed point, derived in closed form below:
 *  - prism: after the dual step the element is stretched along its axis
 *    (the mean triangle normal), about its centroid, by kappa(sigma), the
 *    factor that maps the step's image of the regular prism back onto it.
 *    The stretch is affine with kappa > 0, so it never inverts a simplex.
 *  - pyramid: the apex is moved with its own parameter sigma_apex = 1/6
 *    instead of sigma.  That makes the regular pyramid a fixed point for
 *    every sigma (the base nodes' part cancels exactly, see below) and,
 *    unlike an axial stretch, keeps the step well contracting up to
 *    sigma = 2 (docs/kernels.md has the measurements of both variants).
 * The regular element is an exact fixed point up to similarity.
 */
/* Compiled with -fno-trapping-math (core/CMakeLists.txt says why): the
   hex, prism and pyramid transformation lanes, whose selects have a
   division or a square root on a side. */

#include "internal.h"
#include "transform_scale.h"

#include <math.h>

/* Topology of one type: faces (outward, Gmsh order), and for every node its
   incident faces in the order that orients n_i towards the node. */
typedef struct dual_topology {
    int nv, nf, ne;
    unsigned char face_size[6];
    unsigned char face[6][4];
    unsigned char node_faces[8];   /* k of every node */
    unsigned char around[8][4];    /* its faces, ordered */
    unsigned char edges[12][2];
} dual_topology;

static const dual_topology hex_topo = {
    8, 6, 12,
    {4, 4, 4, 4, 4, 4},
    {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6},
     {0, 4, 7, 3}},
    {3, 3, 3, 3, 3, 3, 3, 3},
    {{0, 2, 5}, {0, 3, 2}, {0, 4, 3}, {0, 5, 4}, {1, 5, 2}, {1, 2, 3},
     {1, 3, 4}, {1, 4, 5}},
    {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4},
     {1, 5}, {2, 6}, {3, 7}}};

static const dual_topology prism_topo = {
    6, 5, 9,
    {3, 3, 4, 4, 4},
    {{0, 2, 1}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}},
    {3, 3, 3, 3, 3, 3},
    {{0, 2, 4}, {0, 3, 2}, {0, 4, 3}, {1, 4, 2}, {1, 2, 3}, {1, 3, 4}},
    {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}}};

static const dual_topology pyramid_topo = {
    5, 5, 8,
    {4, 3, 3, 3, 3},
    {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}},
    {3, 3, 3, 3, 4},
    {{0, 1, 4}, {0, 2, 1}, {0, 3, 2}, {0, 4, 3}, {1, 2, 3, 4}},
    {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}}};

static inline void face_centroids(const dual_topology *t, const double *x,
                                  double c[6][3])
{
    for (int f = 0; f < t->nf; f++) {
        double s[3] = {0.0, 0.0, 0.0};
        for (int j = 0; j < t->face_size[f]; j++)
            for (int d = 0; d < 3; d++)
                s[d] += x[3 * t->face[f][j] + d];
        for (int d = 0; d < 3; d++)
            c[f][d] = s[d] / t->face_size[f];
    }
}

/* The raw dual step (no scaling) of every node into out; the last node
   uses sigma_last (the pyramid's apex), all others sigma.  Done in phases
   over small arrays so that the 2 square roots and the division of each
   node run side by side instead of as one long dependency chain. */
static inline void dual_step(const dual_topology *t, const double *x,
                             double sigma, double sigma_last, double *out)
{
    double c[6][3], m[8][3], n[8][3], f[8];
    face_centroids(t, x, c);
    for (int i = 0; i < t->nv; i++) {
        int k = t->node_faces[i];
        for (int d = 0; d < 3; d++)
            m[i][d] = n[i][d] = 0.0;
        for (int j = 0; j < k; j++)
            for (int d = 0; d < 3; d++)
                m[i][d] += c[t->around[i][j]][d];
        for (int d = 0; d < 3; d++)
            m[i][d] /= k;
        for (int j = 0; j < k; j++) {
            const double *a = c[t->around[i][j]];
            const double *b = c[t->around[i][(j + 1) % k]];
            double u[3] = {a[0] - m[i][0], a[1] - m[i][1], a[2] - m[i][2]};
            double v[3] = {b[0] - m[i][0], b[1] - m[i][1], b[2] - m[i][2]};
            n[i][0] += 0.5 * (u[1] * v[2] - u[2] * v[1]);
            n[i][1] += 0.5 * (u[2] * v[0] - u[0] * v[2]);
            n[i][2] += 0.5 * (u[0] * v[1] - u[1] * v[0]);
        }
    }
    for (int i = 0; i < t->nv; i++)
        f[i] = (i == t->nv - 1 ? sigma_last : sigma) *
               getme__inv_sqrt_norm(n[i]);
    for (int i = 0; i < t->nv; i++)
        for (int d = 0; d < 3; d++)
            out[3 * i + d] = m[i][d] + f[i] * n[i][d];
}

/* Stretch the nv nodes of out by kappa along the direction axis (any
   length), about their centroid. */
static inline void stretch_along(double *out, int nv, const double axis[3],
                                 double kappa)
{
    double a[3] = {axis[0], axis[1], axis[2]};
    double inv = 1.0 / getme__at_least(
                           sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), DBL_MIN);
    double c[3] = {0.0, 0.0, 0.0};
    for (int d = 0; d < 3; d++)
        a[d] *= inv;
    for (int i = 0; i < nv; i++)
        for (int d = 0; d < 3; d++)
            c[d] += out[3 * i + d];
    for (int d = 0; d < 3; d++)
        c[d] /= nv;
    for (int i = 0; i < nv; i++) {
        double *p = out + 3 * i;
        double h = (kappa - 1.0) * ((p[0] - c[0]) * a[0] +
                                    (p[1] - c[1]) * a[1] +
                                    (p[2] - c[2]) * a[2]);
        for (int d = 0; d < 3; d++)
            p[d] += h * a[d];
    }
}

/* (b - a) x (c - a) for nodes a, b, c of x, added to n */
static inline void add_cross(const double *x, int ia, int ib, int ic,
                             double n[3])
{
    const double *a = x + 3 * ia, *b = x + 3 * ib, *c = x + 3 * ic;
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] += u[1] * v[2] - u[2] * v[1];
    n[1] += u[2] * v[0] - u[0] * v[2];
    n[2] += u[0] * v[1] - u[1] * v[0];
}

/* ---- hexahedron --------------------------------------------------------- */

void getme__transform_hex(const double *x, double sigma, double *out)
{
    const dual_topology *t = &hex_topo;
    dual_step(t, x, sigma, sigma, out);
    getme__rescale3(out, x, t->nv, t->ne, t->edges);
}

/* getme__transform_hex of GETME_LANES hexes at once (internal.h), in two
   forms with the same operations per lane as dual_step and
   getme__rescale3, so every lane's result is bit-identical to the
   one-element kernel's (the differences below change no bit, see there).
   Each step is a loop over the lanes (vector instructions).  Which form
   is faster depends on the vector width (getme__transform_hex_lanes at
   the end chooses).

   getme__transform_hex_lanes_nodes, for AVX-512: the 40 square roots and
   9 divisions per hex run on one unit (zmm: 4.5 and 2.5 ns per
   instruction of 8 lanes, ~25 ns per hex) and the ~900 additions and
   multiplications on others (~25 ns).  Done in phases (all edge lengths,
   then all normals, then all 8 nodes' roots) the unit and the adders took
   turns and the kernel took ~48 ns per hex on the Intel machine of round
   8; perf annotate put half of its samples on waits for square roots.  So
   the work is interleaved in program order, the way the out-of-order core
   can overlap it: 4 of the input's 12 edge lengths with the face
   centroids, then node by node a node's mean and normal (arithmetic)
   followed by its own two roots and division, one more input edge, and,
   two nodes behind (its roots are done by then), the moved node and the
   output edges whose both ends have moved (bench/kernels.sh: 50 -> ~40
   ns per hex; lags of 1 and 3 nodes measured the same). */

/* Node i's mean m, normal n and factor f = sigma / sqrt(sqrt|n|^2) from
   its three face centroids a, b, e (dual_step's triangles (a, b), (b, e),
   (e, a) in its order; each difference c_j - m taken once).  The sums
   start without dual_step's "0.0 +": that only turns a -0 sum into +0,
   and n is only used squared and as f n added to m, which is never -0
   (its own sum starts with 0.0 +): +0 and -0 give the same bits there. */
__attribute__((always_inline)) static inline void
hex_node(const double (*a)[GETME_LANES], const double (*b)[GETME_LANES],
         const double (*e)[GETME_LANES], double sigma, double (*m)[GETME_LANES],
         double (*n)[GETME_LANES], double *f)
{
    enum { L = GETME_LANES };
    for (int d = 0; d < 3; d++)
#pragma omp simd
        for (int l = 0; l < L; l++)
            m[d][l] = getme__div3(0.0 + a[d][l] + b[d][l] + e[d][l]);
#pragma omp simd
    for (int l = 0; l < L; l++) {
        double ax = a[0][l] - m[0][l], ay = a[1][l] - m[1][l], az = a[2][l] - m[2][l];
        double bx = b[0][l] - m[0][l], by = b[1][l] - m[1][l], bz = b[2][l] - m[2][l];
        double ex = e[0][l] - m[0][l], ey = e[1][l] - m[1][l], ez = e[2][l] - m[2][l];
        double n0 = 0.5 * (ay * bz - az * by);
        double n1 = 0.5 * (az * bx - ax * bz);
        double n2 = 0.5 * (ax * by - ay * bx);
        n0 += 0.5 * (by * ez - bz * ey);
        n1 += 0.5 * (bz * ex - bx * ez);
        n2 += 0.5 * (bx * ey - by * ex);
        n0 += 0.5 * (ey * az - ez * ay);
        n1 += 0.5 * (ez * ax - ex * az);
        n2 += 0.5 * (ex * ay - ey * ax);
        n[0][l] = n0, n[1][l] = n1, n[2][l] = n2;
        double nn = n0 * n0 + n1 * n1 + n2 * n2; /* = getme__inv_sqrt_norm */
        f[l] = sigma * (1.0 / sqrt(sqrt(getme__at_least(nn, DBL_MIN))));
    }
}

/* len = |p[b] - p[a]| of every lane (getme__shape3_lanes's edge length) */
__attribute__((always_inline)) static inline void
hex_edge_len(const double (*p)[GETME_LANES], int a, int b, double *len)
{
    const double *pa = p[3 * a], *pb = p[3 * b];
#pragma omp simd
    for (int l = 0; l < GETME_LANES; l++) {
        double dx = pb[l] - pa[l], dy = pb[GETME_LANES + l] - pa[GETME_LANES + l],
               dz = pb[2 * GETME_LANES + l] - pa[2 * GETME_LANES + l];
        len[l] = sqrt(dx * dx + dy * dy + dz * dz);
    }
}

/* The hex's edges (hex_topo.edges, the order their lengths are summed
   in) that step i of the node loop measures: of the input, edge 4 + i
   (edges 0-3 go with the face centroids, where the unit would idle
   otherwise); of the output, once node i - 2 has moved, the edges from it
   to nodes moved before (-1: none). */
static const signed char hex_in_edges[8] = {4, 5, 6, 7, 8, 9, 10, 11};
static const signed char hex_out_edges[8][3] = {
    {-1, -1, -1}, {0, -1, -1}, {1, -1, -1}, {2, 3, -1},
    {8, -1, -1},  {4, 9, -1},  {5, 10, -1}, {6, 7, 11}};

/* Output node i = m + f n, added to the output centroid's sum; then the
   output edges it completes. */
__attribute__((always_inline)) static inline void
hex_move(int i, const double (*m)[3][GETME_LANES], const double (*n)[3][GETME_LANES],
         const double (*f)[GETME_LANES], double (*out)[GETME_LANES],
         double (*c)[GETME_LANES], double (*lout)[GETME_LANES])
{
    for (int d = 0; d < 3; d++)
#pragma omp simd
        for (int l = 0; l < GETME_LANES; l++) {
            out[3 * i + d][l] = m[i][d][l] + f[i][l] * n[i][d][l];
            c[d][l] += out[3 * i + d][l];
        }
    for (int j = 0; j < 3; j++) {
        int k = hex_out_edges[i][j];
        if (k >= 0)
            hex_edge_len((const double(*)[GETME_LANES])out, hex_topo.edges[k][0],
                         hex_topo.edges[k][1], lout[k]);
    }
}

GETME_LANES_TARGETS
void getme__transform_hex_lanes_nodes(const double (*x)[GETME_LANES], double sigma,
                                      double (*out)[GETME_LANES])
{
    enum { L = GETME_LANES };
    const dual_topology *t = &hex_topo;
    double c[6][3][L], m[8][3][L], n[8][3][L], f[8][L];
    double c0[3][L], c1[3][L], lin[12][L], lout[12][L];
    /* the centroids of the input (getme__shape3_lanes's sums in node
       order, then / 8) and of its 6 faces; the face sums start without
       dual_step's "0.0 +" (a -0 centroid only enters hex_node, see
       there) */
    for (int d = 0; d < 3; d++)
#pragma omp simd
        for (int l = 0; l < L; l++) {
            double s = 0.0;
            for (int i = 0; i < 8; i++)
                s += x[3 * i + d][l];
            c0[d][l] = s / 8;
            c1[d][l] = 0.0;
        }
    for (int k = 0; k < 4; k++)
        hex_edge_len(x, t->edges[k][0], t->edges[k][1], lin[k]);
    for (int fc = 0; fc < 6; fc++)
        for (int d = 0; d < 3; d++) {
            const double *x0 = x[3 * t->face[fc][0] + d], *x1 = x[3 * t->face[fc][1] + d],
                         *x2 = x[3 * t->face[fc][2] + d], *x3 = x[3 * t->face[fc][3] + d];
#pragma omp simd
            for (int l = 0; l < L; l++)
                c[fc][d][l] = (x0[l] + x1[l] + x2[l] + x3[l]) / 4;
        }
#pragma GCC unroll 8
    for (int i = 0; i < 8; i++) {
        hex_node((const double(*)[L])c[t->around[i][0]], (const double(*)[L])c[t->around[i][1]],
                 (const double(*)[L])c[t->around[i][2]], sigma, m[i], n[i], f[i]);
        hex_edge_len(x, t->edges[hex_in_edges[i]][0], t->edges[hex_in_edges[i]][1],
                     lin[hex_in_edges[i]]);
        if (i >= 2)
            hex_move(i - 2, (const double(*)[3][L])m, (const double(*)[3][L])n,
                     (const double(*)[L])f, out, c1, lout);
    }
    hex_move(6, (const double(*)[3][L])m, (const double(*)[3][L])n, (const double(*)[L])f,
             out, c1, lout);
    hex_move(7, (const double(*)[3][L])m, (const double(*)[3][L])n, (const double(*)[L])f,
             out, c1, lout);
    /* getme__rescale3_lanes_out: edge-length sums in edge order */
#pragma omp simd
    for (int l = 0; l < L; l++) {
        double sx = 0.0, so = 0.0;
        for (int k = 0; k < 12; k++) {
            sx += lin[k][l];
            so += lout[k][l];
        }
        double fs = sx / getme__at_least(so, DBL_MIN);
        for (int d = 0; d < 3; d++) {
            double cd = c1[d][l] / 8;
            for (int i = 0; i < 8; i++)
                out[3 * i + d][l] = c0[d][l] + fs * (out[3 * i + d][l] - cd);
        }
    }
}

/* getme__transform_hex_lanes_phases, for AVX2 (4 doubles a register, 16
   registers): the same work in phases over all 8 nodes, each a loop over
   the lanes: the input's centroid and edge lengths, the face centroids,
   the 24 node means / 3, the 8 normals, the 8 nodes' square roots and
   divisions side by side (8 independent chains), the moves, the output's
   scaling.  On AMD Zen 3 the node-by-node form above was 45 % slower
   (bench/kernels.sh hex transform lanes ~125 -> ~180 ns; medium hexes,
   perf samples of the kernel 1590 -> 2530 at one thread): its live
   values do not fit 16 ymm registers.  This is the kernel of 1b1fe30
   with getme__div3 for the means (the same bits as / 3; on Zen 3 it and
   the division measured the same). */
GETME_LANES_TARGETS
void getme__transform_hex_lanes_phases(const double (*x)[GETME_LANES], double sigma,
                                       double (*out)[GETME_LANES])
{
    enum { L = GETME_LANES };
    const dual_topology *t = &hex_topo;
    double c[6][3][L], m[8][3][L], n[8][3][L], f[8][L], c0[3][L], sum_x[L];
    /* the input's half of the scaling first: its 12 square roots overlap
       the dual step's arithmetic */
    getme__shape3_lanes(x, 8, 12, t->edges, c0, sum_x);
    for (int fc = 0; fc < 6; fc++)
        for (int d = 0; d < 3; d++) {
            const double *x0 = x[3 * t->face[fc][0] + d], *x1 = x[3 * t->face[fc][1] + d],
                         *x2 = x[3 * t->face[fc][2] + d], *x3 = x[3 * t->face[fc][3] + d];
#pragma omp simd
            for (int l = 0; l < L; l++)
                c[fc][d][l] = (0.0 + x0[l] + x1[l] + x2[l] + x3[l]) / 4;
        }
    for (int i = 0; i < 8; i++)
        for (int d = 0; d < 3; d++) {
            const double *a = c[t->around[i][0]][d], *b = c[t->around[i][1]][d],
                         *e = c[t->around[i][2]][d];
#pragma omp simd
            for (int l = 0; l < L; l++)
                m[i][d][l] = getme__div3(0.0 + a[l] + b[l] + e[l]);
        }
    for (int i = 0; i < 8; i++) {
        double(*a)[L] = c[t->around[i][0]], (*b)[L] = c[t->around[i][1]],
        (*e)[L] = c[t->around[i][2]];
#pragma omp simd
        for (int l = 0; l < L; l++) {
            double ax = a[0][l] - m[i][0][l], ay = a[1][l] - m[i][1][l],
                   az = a[2][l] - m[i][2][l];
            double bx = b[0][l] - m[i][0][l], by = b[1][l] - m[i][1][l],
                   bz = b[2][l] - m[i][2][l];
            double ex = e[0][l] - m[i][0][l], ey = e[1][l] - m[i][1][l],
                   ez = e[2][l] - m[i][2][l];
            /* the triangles (a, b), (b, e), (e, a) in dual_step's order */
            double n0 = 0.0 + 0.5 * (ay * bz - az * by);
            double n1 = 0.0 + 0.5 * (az * bx - ax * bz);
            double n2 = 0.0 + 0.5 * (ax * by - ay * bx);
            n0 += 0.5 * (by * ez - bz * ey);
            n1 += 0.5 * (bz * ex - bx * ez);
            n2 += 0.5 * (bx * ey - by * ex);
            n0 += 0.5 * (ey * az - ez * ay);
            n1 += 0.5 * (ez * ax - ex * az);
            n2 += 0.5 * (ex * ay - ey * ax);
            n[i][0][l] = n0, n[i][1][l] = n1, n[i][2][l] = n2;
            f[i][l] = n0 * n0 + n1 * n1 + n2 * n2;
        }
    }
    for (int i = 0; i < 8; i++)
#pragma omp simd
        for (int l = 0; l < L; l++) /* = sigma * getme__inv_sqrt_norm(n) */
            f[i][l] = sigma * (1.0 / sqrt(sqrt(getme__at_least(f[i][l], DBL_MIN))));
    for (int i = 0; i < 8; i++)
        for (int d = 0; d < 3; d++)
#pragma omp simd
            for (int l = 0; l < L; l++)
                out[3 * i + d][l] = m[i][d][l] + f[i][l] * n[i][d][l];
    getme__rescale3_lanes_out(out, 8, 12, t->edges, (const double(*)[L])c0, sum_x);
}

/* The form for this CPU: fixed at compile time in the native build (the
   ISA macros of -march=native), chosen at run time in the portable one
   (GETME_DISPATCH: each form has its own load-time copies, and the
   node-by-node form is taken where the AVX-512 copy will run).  Both give
   the same bits (core_lanes runs both on every build). */
void getme__transform_hex_lanes(const double (*x)[GETME_LANES], double sigma,
                                double (*out)[GETME_LANES])
{
#if defined(GETME_DISPATCH) && defined(__x86_64__) && defined(__GNUC__) && \
    !defined(__clang__)
    if (__builtin_cpu_supports("avx512f"))
        getme__transform_hex_lanes_nodes(x, sigma, out);
    else
        getme__transform_hex_lanes_phases(x, sigma, out);
#elif defined(__AVX512F__)
    getme__transform_hex_lanes_nodes(x, sigma, out);
#else
    getme__transform_hex_lanes_phases(x, sigma, out);
#endif
}

/* ---- prism -------------------------------------------------------------- */

/*
 * kappa for the prism.  On the regular prism (edge 1, height 1) node 0's
 * faces have centroids on the axis at height -1/2 (its triangle) and at the
 * midpoints of its two triangle edges at height 0, at distance r = 1/(2
 * sqrt3) from the axis.  Hence m_0 lies r/3 from the axis at height -1/6,
 * n_0 = (1/8, 0, -r/8) in (radial, axial) parts, |n_0| = sqrt(1 + r^2)/8,
 * and with s = sigma / (8 sqrt|n_0|) the new node is r/3 + s from the axis
 * at height -(1/6 + r s).  The image is a right prism with triangle edge
 * sqrt3 (r/3 + s) and height 2 (1/6 + r s); kappa = edge / height.
 */
static double prism_kappa(double sigma)
{
    const double r = 0.5 / 1.73205080756887729353;
    /* 1 / (8 sqrt|n_0|) with |n_0| = sqrt(13/12) / 8 */
    const double inv8sqrtn = 0.34654886430893894;
    double s = sigma * inv8sqrtn;
    return 1.73205080756887729353 * (r / 3.0 + s) / (2.0 * (1.0 / 6.0 + r * s));
}

void getme__transform_prism(const double *x, double sigma, double *out)
{
    const dual_topology *t = &prism_topo;
    dual_step(t, x, sigma, sigma, out);
    /* axis: the mean of the two triangles' upward normals */
    double axis[3] = {0.0, 0.0, 0.0};
    add_cross(out, 0, 1, 2, axis);
    add_cross(out, 3, 4, 5, axis);
    stretch_along(out, t->nv, axis, prism_kappa(sigma));
    getme__rescale3(out, x, t->nv, t->ne, t->edges);
}

/* ---- pyramid ------------------------------------------------------------ */

/*
 * sigma_apex.  Take the pyramid with unit base centred at the origin and
 * apex height h, h^2 = 1/2 for the regular one (all edges 1).  Base node 0 =
 * (-1/2,-1/2,0) sees the base centroid (0,0,0) and the centroids
 * (0,-1/3,h/3), (-1/3,0,h/3) of its two triangles: m_0 = (-1/9,-1/9,2h/9),
 * n_0 = (-h,-h,-1)/18, so with t = sigma / (18 sqrt|n_0|) it goes to height
 * 2h/9 - t and the base edge becomes 2 (1/9 + t h).  The apex sees the four
 * triangle centroids, a square of area 2/9 at height h/3, and goes to
 * h/3 + sigma_apex sqrt(2)/3.  The image is regular iff
 * height = h * edge:  h/9 + sigma_apex sqrt2/3 + t = 2h/9 + 2 t h^2, and as
 * 2 h^2 = 1 the t terms cancel: sigma_apex = h / (3 sqrt2) = 1/6 whatever
 * sigma is.
 */
#define PYRAMID_APEX_SIGMA (1.0 / 6.0)

void getme__transform_pyramid(const double *x, double sigma, double *out)
{
    const dual_topology *t = &pyramid_topo;
    dual_step(t, x, sigma, PYRAMID_APEX_SIGMA, out);
    getme__rescale3(out, x, t->nv, t->ne, t->edges);
}
