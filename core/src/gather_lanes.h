/*
 * gather_lanes.h -- the lane kernels' input: the coordinates of
 * GETME_LANES elements' nodes, transposed to x[3 i + d][l].
 *
 * gcc vectorises the plain loop over the lanes with gathers of the node
 * numbers and then moves every coordinate one by one (perf annotate of
 * the trial pass, round 11: the gather was ~30 % of trial_block_any).
 * On AVX2 each node's (x, y, z) is one masked 4-double load (the fourth
 * double is masked off, so it is never read and cannot fault past the
 * array's end), and four lanes' loads are transposed in registers: 4
 * loads, 7 shuffles and 3 stores per node and 4 lanes.  Pure data
 * movement: the values, hence every result computed from them, are the
 * same bits either way.
 */
#ifndef GETME_GATHER_LANES_H
#define GETME_GATHER_LANES_H

#include "internal.h"

#include <stdint.h>
#if defined(__AVX2__)
#include <immintrin.h>
#endif

/* The body of both gathers below: node i's coordinates of element l
   (node list c[l], i < nv) from the node array X (3 doubles per node)
   into x[3 i + d][l]; the two differ only in the type of c's entries. */
#if defined(__AVX2__)
#define GETME_GATHER_LANES_BODY                                              \
    const __m256i m = _mm256_setr_epi64x(-1, -1, -1, 0);                    \
    for (int i = 0; i < nv; i++)                                             \
        for (int h = 0; h < GETME_LANES; h += 4) {                           \
            __m256d a = _mm256_maskload_pd(X + 3 * (int64_t)c[h][i], m);     \
            __m256d b = _mm256_maskload_pd(X + 3 * (int64_t)c[h + 1][i], m); \
            __m256d p = _mm256_maskload_pd(X + 3 * (int64_t)c[h + 2][i], m); \
            __m256d q = _mm256_maskload_pd(X + 3 * (int64_t)c[h + 3][i], m); \
            __m256d xz01 = _mm256_unpacklo_pd(a, b); /* x0 x1 z0 z1 */       \
            __m256d y01 = _mm256_unpackhi_pd(a, b);  /* y0 y1 0 0   */       \
            __m256d xz23 = _mm256_unpacklo_pd(p, q); /* x2 x3 z2 z3 */       \
            __m256d y23 = _mm256_unpackhi_pd(p, q);  /* y2 y3 0 0   */       \
            _mm256_storeu_pd(&x[3 * i][h],                                   \
                             _mm256_permute2f128_pd(xz01, xz23, 0x20));      \
            _mm256_storeu_pd(&x[3 * i + 1][h],                               \
                             _mm256_permute2f128_pd(y01, y23, 0x20));        \
            _mm256_storeu_pd(&x[3 * i + 2][h],                               \
                             _mm256_permute2f128_pd(xz01, xz23, 0x31));      \
        }
#else
#define GETME_GATHER_LANES_BODY                                              \
    for (int l = 0; l < GETME_LANES; l++)                                    \
        for (int i = 0; i < nv; i++)                                         \
            for (int d = 0; d < 3; d++)                                      \
                x[3 * i + d][l] = X[3 * (int64_t)c[l][i] + d];
#endif

/* Global node numbers (the trial pass: ws->x). */
__attribute__((always_inline)) static inline void
getme__gather_lanes(const double *X, const int32_t *const c[GETME_LANES],
                    int nv, double (*x)[GETME_LANES])
{
    GETME_GATHER_LANES_BODY
}

/* A block's local node numbers (the scatter: its copy of the block's
   coordinates). */
__attribute__((always_inline)) static inline void
getme__gather_lanes16(const double *X, const uint16_t *const c[GETME_LANES],
                      int nv, double (*x)[GETME_LANES])
{
    GETME_GATHER_LANES_BODY
}

#undef GETME_GATHER_LANES_BODY

#endif /* GETME_GATHER_LANES_H */
