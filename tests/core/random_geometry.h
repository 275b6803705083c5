/*
 * random_geometry.h -- the deterministic random numbers and rigid motions
 * that test_quality.c, test_transform.c, test_lanes.c and
 * test_corner_lanes.c draw their elements from.
 *
 * A header of static inline functions (a program may use only some of
 * them), like regular_elements.h: each test program includes it once and
 * gets its own generator.  Define RANDOM_GEOMETRY_SEED
 * before including it; the sequences then are the ones the tests always
 * drew (their expected values do not depend on a seed, their coverage
 * does).
 */
#ifndef GETME_TEST_RANDOM_GEOMETRY_H
#define GETME_TEST_RANDOM_GEOMETRY_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#ifndef RANDOM_GEOMETRY_SEED
#error "define RANDOM_GEOMETRY_SEED before including random_geometry.h"
#endif

#define GETME_TEST_PI 3.14159265358979323846

/* splitmix64: small, fast, and the same numbers on every platform. */
static uint64_t rng_state = RANDOM_GEOMETRY_SEED;

static inline double urand(void) /* in [0, 1) */
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

static inline double srand1(void) { return 2.0 * urand() - 1.0; } /* [-1, 1) */

/* out = A x + b for every node (A row-major 3x3). */
static inline void affine(const double *x, int nv, const double A[9],
                   const double b[3], double *out)
{
    for (int i = 0; i < nv; i++)
        for (int r = 0; r < 3; r++)
            out[3 * i + r] = A[3 * r] * x[3 * i] + A[3 * r + 1] * x[3 * i + 1] +
                             A[3 * r + 2] * x[3 * i + 2] + b[r];
}

/* A random rotation: about z for planar types (which must stay in their
   plane), else from a random unit quaternion (rejection sampling in the
   unit ball, so every orientation is as likely). */
static inline void random_rotation(int planar, double R[9])
{
    if (planar) {
        double a = 2.0 * GETME_TEST_PI * urand(), c = cos(a), s = sin(a);
        double P[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
        memcpy(R, P, sizeof P);
        return;
    }
    double q[4], n;
    do {
        for (int k = 0; k < 4; k++)
            q[k] = srand1();
        n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    } while (n < 0.1 || n > 1.0);
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    double Q[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                   2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    memcpy(R, Q, sizeof Q);
}

#endif
