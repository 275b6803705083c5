/*
 * transform_tet.c -- the opposite face normals transformation of a
 * tetrahedron (Vartziotis et al., paper ref. [26]; docs/design.md §2).
 *
 * Every node is pushed along the normal of the face opposite to it:
 *
 *     p_i' = p_i + sigma * n_i / sqrt|n_i|,
 *
 * n_i = the cross product of two edges of that face (|n_i| = twice its
 * area), oriented towards p_i.  Dividing by sqrt|n_i| makes the push scale
 * like a length, so the map commutes with similarities; large faces push
 * their opposite node further, which is what evens out a flat or needle
 * tetrahedron.  The result is then scaled about its centroid so that the sum
 * of the six edge lengths is unchanged, and put back on the input centroid
 * (transform_scale.h says why).  The regular tetrahedron is a fixed
 * point (all four pushes are equal and radial); every valid tetrahedron
 * converges to it (docs/kernels.md has the measurements).
 */
/* Compiled with -fno-trapping-math (core/CMakeLists.txt says why): the
   square roots and the division of each normal's scale factor, sunk by
   gcc into the two sides of getme__at_least's select, kept the whole lane
   loop scalar on AVX2.  gcc does not inline across differing
   trapping-math settings, so the header kernels inlined here are compiled
   with it too, and the lane kernels are called out of line from the other
   files. */

#include "internal.h"
#include "transform_scale.h"

static const unsigned char tet_edges[6][2] = {
    {0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/* Face opposite node i, ordered so that (b - a) x (c - a) points towards
   node i in a valid tet (0,1,2 counter-clockwise seen from 3). */
static const unsigned char tet_opposite[4][3] = {
    {1, 3, 2}, {0, 2, 3}, {0, 3, 1}, {0, 1, 2}};

void getme__transform_tet(const double *x, double sigma, double *out)
{
    /* Normals first, then the four scale factors in one loop (vector
       square roots and divisions), then the moves. */
    double n[4][3], f[4];
    for (int i = 0; i < 4; i++) {
        const double *a = x + 3 * tet_opposite[i][0];
        const double *b = x + 3 * tet_opposite[i][1];
        const double *c = x + 3 * tet_opposite[i][2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        n[i][0] = u[1] * v[2] - u[2] * v[1];
        n[i][1] = u[2] * v[0] - u[0] * v[2];
        n[i][2] = u[0] * v[1] - u[1] * v[0];
    }
    for (int i = 0; i < 4; i++)
        f[i] = sigma * getme__inv_sqrt_norm(n[i]);
    for (int i = 0; i < 4; i++)
        for (int d = 0; d < 3; d++)
            out[3 * i + d] = x[3 * i + d] + f[i] * n[i][d];
    getme__rescale3(out, x, 4, 6, tet_edges);
}

/* The same operations as getme__transform_tet, in the same order per
   lane, as loops over GETME_LANES tets (vector instructions). */
GETME_LANES_TARGETS
void getme__transform_tet_lanes(const double (*x)[GETME_LANES], double sigma,
                                double (*out)[GETME_LANES])
{
    for (int i = 0; i < 4; i++) {
        int a = 3 * tet_opposite[i][0], b = 3 * tet_opposite[i][1],
            c = 3 * tet_opposite[i][2];
#pragma omp simd
        for (int l = 0; l < GETME_LANES; l++) {
            double u0 = x[b][l] - x[a][l], u1 = x[b + 1][l] - x[a + 1][l],
                   u2 = x[b + 2][l] - x[a + 2][l];
            double v0 = x[c][l] - x[a][l], v1 = x[c + 1][l] - x[a + 1][l],
                   v2 = x[c + 2][l] - x[a + 2][l];
            double n0 = u1 * v2 - u2 * v1, n1 = u2 * v0 - u0 * v2,
                   n2 = u0 * v1 - u1 * v0;
            double nn = n0 * n0 + n1 * n1 + n2 * n2;
            /* = sigma * getme__inv_sqrt_norm(n) */
            double f = sigma * (1.0 / sqrt(sqrt(getme__at_least(nn, DBL_MIN))));
            out[3 * i][l] = x[3 * i][l] + f * n0;
            out[3 * i + 1][l] = x[3 * i + 1][l] + f * n1;
            out[3 * i + 2][l] = x[3 * i + 2][l] + f * n2;
        }
    }
    getme__rescale3_lanes(out, x, 4, 6, tet_edges);
}
