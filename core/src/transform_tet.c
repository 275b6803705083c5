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
