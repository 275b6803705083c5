/*
 * transform_scale.h -- the step every GETMe transformation ends with: scale
 * the transformed element about its own centroid so that the sum of its
 * edge lengths equals the original one (paper Sec. 2.2).  Without it the
 * transformations blow elements up (they add normals to the nodes), and
 * the smoother's node averaging would drag neighbours outwards.
 *
 * Private to the transform_*.c kernels; static inline so each kernel gets a
 * copy specialised to its constant edge table.
 */
#ifndef GETME_TRANSFORM_SCALE_H
#define GETME_TRANSFORM_SCALE_H

#include "div3.h"

#include <float.h>
#include <math.h>

/* a if a > lo, else lo: like fmax for our non-NaN use, but a single
   instruction (fmax stays a libm call without -ffast-math). */
static inline double getme__at_least(double a, double lo)
{
    return a > lo ? a : lo;
}

/* Sum of the lengths of the ne edges (node pairs) of a volume element.  The
   squared lengths are gathered first so the square roots vectorise. */
static inline double getme__edge_sum3(const double *x, int ne,
                                      const unsigned char (*edges)[2])
{
    double l2[12], sum = 0.0;
    for (int k = 0; k < ne; k++) {
        const double *a = x + 3 * edges[k][0], *b = x + 3 * edges[k][1];
        double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
        l2[k] = dx * dx + dy * dy + dz * dz;
    }
    for (int k = 0; k < ne; k++)
        sum += sqrt(l2[k]);
    return sum;
}

/*
 * Scale the nv nodes of out about their centroid by (the edge sum of x) /
 * (their edge sum) and move that centroid onto x's.  fmax keeps a collapsed
 * output (edge sum 0, only possible from a collapsed input) finite: it then
 * stays collapsed instead of becoming NaN.  The 2 * ne squared lengths are
 * gathered first and their square roots taken in one loop, which the
 * compiler turns into a few vector square roots (they dominate the cost of
 * a transformation); each sum is still added in edge order, so the result
 * is the same as edge by edge.
 */
static inline void getme__rescale3(double *out, const double *x, int nv,
                                   int ne, const unsigned char (*edges)[2])
{
    double c[3] = {0.0, 0.0, 0.0}, c0[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < nv; i++)
        for (int d = 0; d < 3; d++) {
            c[d] += out[3 * i + d];
            c0[d] += x[3 * i + d];
        }
    for (int d = 0; d < 3; d++) {
        c[d] /= nv;
        c0[d] /= nv;
    }
    double l[24];
    for (int k = 0; k < ne; k++) {
        const double *a = x + 3 * edges[k][0], *b = x + 3 * edges[k][1];
        const double *p = out + 3 * edges[k][0], *q = out + 3 * edges[k][1];
        double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
        double ex = q[0] - p[0], ey = q[1] - p[1], ez = q[2] - p[2];
        l[k] = dx * dx + dy * dy + dz * dz;
        l[ne + k] = ex * ex + ey * ey + ez * ez;
    }
    for (int k = 0; k < 2 * ne; k++)
        l[k] = sqrt(l[k]);
    double sum_x = 0.0, sum_out = 0.0;
    for (int k = 0; k < ne; k++) {
        sum_x += l[k];
        sum_out += l[ne + k];
    }
    double f = sum_x / getme__at_least(sum_out, DBL_MIN);
    for (int i = 0; i < nv; i++)
        for (int d = 0; d < 3; d++)
            out[3 * i + d] = c0[d] + f * (out[3 * i + d] - c[d]);
}

/* Centroid c and edge-length sum of GETME_LANES elements p in lanes, in
   node and edge order (getme__rescale3's sums); each edge's square root
   in the loop that squares it. */
static inline void getme__shape3_lanes(const double (*p)[GETME_LANES], int nv, int ne,
                                       const unsigned char (*edges)[2],
                                       double (*c)[GETME_LANES], double *sum)
{
    double len[12][GETME_LANES];
    for (int d = 0; d < 3; d++)
        for (int l = 0; l < GETME_LANES; l++)
            c[d][l] = 0.0;
    for (int i = 0; i < nv; i++)
        for (int d = 0; d < 3; d++)
#pragma omp simd
            for (int l = 0; l < GETME_LANES; l++)
                c[d][l] += p[3 * i + d][l];
    for (int d = 0; d < 3; d++)
#pragma omp simd
        for (int l = 0; l < GETME_LANES; l++)
            c[d][l] /= nv;
    for (int k = 0; k < ne; k++) {
        const double *pa = p[3 * edges[k][0]], *pb = p[3 * edges[k][1]];
#pragma omp simd
        for (int l = 0; l < GETME_LANES; l++) {
            double dx = pb[l] - pa[l], dy = pb[GETME_LANES + l] - pa[GETME_LANES + l],
                   dz = pb[2 * GETME_LANES + l] - pa[2 * GETME_LANES + l];
            len[k][l] = sqrt(dx * dx + dy * dy + dz * dz);
        }
    }
    for (int l = 0; l < GETME_LANES; l++)
        sum[l] = 0.0;
    for (int k = 0; k < ne; k++)
#pragma omp simd
        for (int l = 0; l < GETME_LANES; l++)
            sum[l] += len[k][l];
}

/*
 * getme__rescale3 for GETME_LANES elements at once, in lanes: out[3 i + d]
 * and x[3 i + d] hold coordinate d of node i of every lane's element.  The
 * same operations in the same order per lane as getme__rescale3 (sums in
 * node and edge order, the same divisions and square roots, no fused
 * multiply-adds under -std=c11), so every lane's result is bit-identical
 * to the one-element kernel's; written as loops over the lanes so that
 * they become vector instructions.  getme__rescale3_lanes_out takes the
 * input's half (getme__shape3_lanes of x: centroid c0 and edge-length sum
 * sum_x) from the caller, which can compute it before its own work so that
 * those square roots overlap that work.
 */
static inline void getme__rescale3_lanes_out(double (*out)[GETME_LANES], int nv,
                                             int ne, const unsigned char (*edges)[2],
                                             const double (*c0)[GETME_LANES],
                                             const double *sum_x)
{
    double c[3][GETME_LANES], sum_out[GETME_LANES], f[GETME_LANES];
    getme__shape3_lanes((const double(*)[GETME_LANES])out, nv, ne, edges, c, sum_out);
#pragma omp simd
    for (int l = 0; l < GETME_LANES; l++)
        f[l] = sum_x[l] / getme__at_least(sum_out[l], DBL_MIN);
    for (int i = 0; i < nv; i++)
        for (int d = 0; d < 3; d++)
#pragma omp simd
            for (int l = 0; l < GETME_LANES; l++)
                out[3 * i + d][l] = c0[d][l] + f[l] * (out[3 * i + d][l] - c[d][l]);
}

static inline void getme__rescale3_lanes(double (*out)[GETME_LANES],
                                         const double (*x)[GETME_LANES],
                                         int nv, int ne,
                                         const unsigned char (*edges)[2])
{
    double c0[3][GETME_LANES], sum_x[GETME_LANES];
    getme__shape3_lanes(x, nv, ne, edges, c0, sum_x);
    getme__rescale3_lanes_out(out, nv, ne, edges, (const double(*)[GETME_LANES])c0,
                              sum_x);
}

/* The same for a planar polygon of n nodes: perimeter and centroid in xy;
   z is left as it is. */
static inline double getme__perimeter_xy(const double *x, int n)
{
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        double dx = x[3 * j] - x[3 * i], dy = x[3 * j + 1] - x[3 * i + 1];
        sum += sqrt(dx * dx + dy * dy);
    }
    return sum;
}

static inline void getme__rescale_xy(double *out, const double *x, int n)
{
    double cx = 0.0, cy = 0.0, cx0 = 0.0, cy0 = 0.0;
    for (int i = 0; i < n; i++) {
        cx += out[3 * i];
        cy += out[3 * i + 1];
        cx0 += x[3 * i];
        cy0 += x[3 * i + 1];
    }
    cx /= n;
    cy /= n;
    cx0 /= n;
    cy0 /= n;
    double f = getme__perimeter_xy(x, n) /
               getme__at_least(getme__perimeter_xy(out, n), DBL_MIN);
    for (int i = 0; i < n; i++) {
        out[3 * i] = cx0 + f * (out[3 * i] - cx);
        out[3 * i + 1] = cy0 + f * (out[3 * i + 1] - cy);
    }
}

/* 1 / sqrt|n|: the paper's normal scaling, which makes the displacement
   n / sqrt|n| scale like an edge length.  A zero normal (degenerate face)
   gets a finite factor, so its displacement is 0, not NaN. */
static inline double getme__inv_sqrt_norm(const double n[3])
{
    double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    return 1.0 / sqrt(sqrt(getme__at_least(nn, DBL_MIN)));
}

#endif /* GETME_TRANSFORM_SCALE_H */
