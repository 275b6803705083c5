/*
 * kernels.c -- micro-benchmark of the per-element kernels alone (issue
 * #13): ns per element of the tet and hex mean ratio and transformation,
 * one element at a time and GETME_LANES at a time, on a pool of random
 * perturbed regular elements that fits the L2 cache (the smoother's block
 * kernel also works on L1/L2-resident data).  No gather, no scatter: only
 * the arithmetic the kernels execute.  Built from the core's sources with
 * the library's flags (bench/kernels.sh), one thread.
 *
 *     bench/kernels.sh [evaluations per kernel, default 4000000]
 */
#include "internal.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { POOL = 2048 }; /* elements: 2048 hexes = 384 KiB of coordinates */

static uint64_t rng = 0x5eed1234abcdULL;

static double srand1(void) /* in [-1, 1) */
{
    uint64_t z = (rng += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return 2.0 * (double)(z >> 11) * (1.0 / 9007199254740992.0) - 1.0;
}

static const double reg_tet[12] = {0, 0, 0, 1, 0, 0, 0.5, 0.86602540378443864676, 0,
                                   0.5, 0.28867513459481288225, 0.81649658092772603273};
static const double reg_hex[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                   0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts); /* CPU time: the machine is shared */
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static volatile double sink;

/* The lane kernels must give the one-element kernels' bits on the pool
   (core_lanes asserts it on its own elements): a time for a kernel that
   computes something else would mean nothing.  Exits 1 on a difference. */
static void check(int t, const double *x, const double (*xl)[GETME_LANES])
{
    int nv = getme__nv[t];
    double y[3 * GETME_MAX_NV], yl[3 * GETME_MAX_NV][GETME_LANES], q[GETME_LANES];
    for (int b = 0; b < POOL / GETME_LANES; b++) {
        const double(*xb)[GETME_LANES] = xl + 3 * nv * b;
        getme__quality_lanes(t, xb, q);
        if (t == GETME_TET)
            getme__transform_tet_lanes(xb, 0.3, yl);
        else
            getme__transform_hex_lanes(xb, 0.3, yl);
        for (int l = 0; l < GETME_LANES; l++) {
            const double *xe = x + 3 * nv * (b * GETME_LANES + l);
            double qe = getme__quality(t, xe);
            int same = memcmp(&qe, &q[l], sizeof qe) == 0;
            getme__transform(t, xe, 0.3, y);
            for (int i = 0; i < 3 * nv; i++)
                same &= memcmp(&y[i], &yl[i][l], sizeof y[i]) == 0;
            if (!same) {
                fprintf(stderr, "kernels: %s element %d: the lane kernels "
                        "differ from the one-element ones\n",
                        t == GETME_TET ? "tet" : "hex", b * GETME_LANES + l);
                exit(1);
            }
        }
    }
}

/* x: POOL elements one after the other; xl: the same in lanes, POOL /
   GETME_LANES batches of [3 nv][GETME_LANES]. */
static void run(int t, long evals)
{
    int nv = getme__nv[t];
    const double *r = t == GETME_TET ? reg_tet : reg_hex;
    double *x = malloc(sizeof(double) * 3 * (size_t)nv * POOL);
    double(*xl)[GETME_LANES] = malloc(sizeof(double) * 3 * (size_t)nv * POOL);
    double y[3 * GETME_MAX_NV], yl[3 * GETME_MAX_NV][GETME_LANES], q[GETME_LANES];
    if (x == NULL || xl == NULL)
        exit(1);
    for (int e = 0; e < POOL; e++)
        for (int i = 0; i < 3 * nv; i++) {
            double v = r[i] + 0.15 * srand1();
            x[3 * nv * e + i] = v;
            xl[(e / GETME_LANES) * 3 * nv + i][e % GETME_LANES] = v;
        }
    long reps = evals / POOL;
    const char *name = t == GETME_TET ? "tet" : "hex";
    check(t, x, xl);
    double best[5] = {1e30, 1e30, 1e30, 1e30, 1e30}, acc = 0.0;
    for (int trial = 0; trial < 5; trial++) {
        double t0 = now();
        for (long k = 0; k < reps; k++)
            for (int e = 0; e < POOL; e++)
                acc += getme__quality(t, x + 3 * nv * e);
        double t1 = now();
        for (long k = 0; k < reps; k++)
            for (int b = 0; b < POOL / GETME_LANES; b++) {
                getme__quality_lanes(t, (const double(*)[GETME_LANES])(xl + 3 * nv * b), q);
                acc += q[0];
            }
        double t2 = now();
        for (long k = 0; k < reps; k++)
            for (int e = 0; e < POOL; e++) {
                getme__transform(t, x + 3 * nv * e, 0.3, y);
                acc += y[0];
            }
        double t3 = now();
        for (long k = 0; k < reps; k++)
            for (int b = 0; b < POOL / GETME_LANES; b++) {
                const double(*xb)[GETME_LANES] = (const double(*)[GETME_LANES])(xl + 3 * nv * b);
                if (t == GETME_TET)
                    getme__transform_tet_lanes(xb, 0.3, yl);
                else
                    getme__transform_hex_lanes(xb, 0.3, yl);
                acc += yl[0][0];
            }
        double t4 = now();
        if (t == GETME_HEX) /* the worst-corner guard of the relaxation */
            for (long k = 0; k < reps; k++)
                for (int e = 0; e < POOL; e++)
                    acc += getme__corner_sj(t, x + 3 * nv * e);
        double t5 = now();
        double d[5] = {t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4};
        for (int i = 0; i < 5; i++)
            if (d[i] < best[i])
                best[i] = d[i];
    }
    sink = acc;
    double n = (double)reps * POOL;
    printf("%s quality   one: %6.1f ns/el   lanes: %6.1f ns/el\n", name,
           1e9 * best[0] / n, 1e9 * best[1] / n);
    printf("%s transform one: %6.1f ns/el   lanes: %6.1f ns/el\n", name,
           1e9 * best[2] / n, 1e9 * best[3] / n);
    if (t == GETME_HEX)
        printf("%s corner_sj one: %6.1f ns/el\n", name, 1e9 * best[4] / n);
    free(x);
    free(xl);
}

int main(int argc, char **argv)
{
    long evals = argc > 1 ? atol(argv[1]) : 4000000;
    if (evals < POOL)
        evals = POOL;
    printf("%ld evaluations per kernel, best of 5, pool of %d elements\n", evals, POOL);
    run(GETME_TET, evals);
    run(GETME_HEX, evals);
    return 0;
}
