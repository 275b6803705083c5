/*
 * kuhn_cube.h -- the test mesh of the parallel-parse tests
 * (test_fastpath.c, test_binpar.c): a unit cube of N^3 cells, each cut
 * into 6 Kuhn tets, inner nodes jittered by up to 5 % of a cell (long
 * decimals in text files), every tet positively oriented.  The seed picks
 * the jitter; rnd() is the tests' one pseudo-random stream after it.
 */
#ifndef GETME_TEST_KUHN_CUBE_H
#define GETME_TEST_KUHN_CUBE_H

#include <stdint.h>

#define N 24 /* cubes per side: 25^3 nodes, 6 N^3 = 82,944 tets */
#define NN ((N + 1) * (N + 1) * (N + 1))
#define NE (6 * N * N * N)

static double xyz[3 * NN];
static int32_t tet[NE][4];

static uint64_t rng_state;
static uint32_t rnd(void)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (uint32_t)(rng_state >> 33);
}

static int node_at(int i, int j, int k)
{
    return i + (N + 1) * (j + (N + 1) * k);
}

static double volume6(const int32_t *t)
{
    const double *a = xyz + 3 * t[0], *b = xyz + 3 * t[1], *c = xyz + 3 * t[2],
                 *d = xyz + 3 * t[3];
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) -
           u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

static void make_mesh(uint64_t seed)
{
    rng_state = seed;
    for (int k = 0; k <= N; k++)
        for (int j = 0; j <= N; j++)
            for (int i = 0; i <= N; i++) {
                double *x = xyz + 3 * node_at(i, j, k);
                int c[3] = {i, j, k};
                for (int a = 0; a < 3; a++) {
                    int inner = c[a] > 0 && c[a] < N;
                    x[a] = (c[a] + (inner ? 0.1 * (rnd() / 4294967296.0 - 0.5)
                                          : 0.0)) / N;
                }
            }
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                   {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int e = 0;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++)
                for (int p = 0; p < 6; p++) {
                    int c[3] = {i, j, k};
                    tet[e][0] = node_at(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[perm[p][s]]++;
                        tet[e][s + 1] = node_at(c[0], c[1], c[2]);
                    }
                    if (volume6(tet[e]) < 0) {
                        int32_t t = tet[e][2];
                        tet[e][2] = tet[e][3];
                        tet[e][3] = t;
                    }
                    e++;
                }
}

#endif
