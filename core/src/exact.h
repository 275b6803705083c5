/*
 * exact.h -- order-independent exact sums in fixed point.
 *
 * Why: a floating-point sum depends on the order of its terms.  GETMe
 * adaptive adds element contributions into nodes (Eq. 9 numerators and
 * weights, the per-node and per-edge quality sums behind the weights) and
 * sums all qualities into q_mean; the order of those additions follows the
 * colouring of the workspace, which depends on how the mesh is numbered and
 * split (threads, MPI ranks).  Integers add associatively, so if every term
 * is first rounded to a fixed-point integer (a deterministic function of
 * the term alone) and the sum is exact, the total is the same bits for any
 * order, any thread count and any partition of the mesh (docs/distributed.md).
 *
 * Representation: an integer n standing for n * 2^-s, the scale s chosen
 * per kind of sum from bounds on its terms so that no sum can overflow:
 *  - q_mean: 128 bits at 2^-90 (getme__fx_q, below);
 *  - the Eq. 9 quality sums: int64 terms at 2^(61 - b), 2^b above the
 *    largest star (adjacency.h);
 *  - GETMe's node sums: 128-bit products of an int64 weight and an int64
 *    coordinate (getme_adaptive.c, set_scales).
 * A term v becomes trunc(v * 2^s) (towards zero): error < 2^-s per term.
 * Each user states its bounds (log2 of the term count + of the largest
 * term + s <= 126 for 128 bits, <= 62 or 63 for 64) where it sets its
 * scale; docs/distributed.md collects them with the precision argument.
 * Sums are kept in unsigned arithmetic where partial sums may wrap
 * (wrap-around is defined, and the bounds keep the final value
 * representable).
 */
#ifndef GETME_EXACT_H
#define GETME_EXACT_H

#include <math.h>
#include <stdint.h>
#include <string.h>

__extension__ typedef __int128 getme_fx;
__extension__ typedef unsigned __int128 getme_ufx;

/* Scale of q_mean's sum: q in [-2, 2] (mean ratio <= 1 plus rounding),
   at most 2^31 terms (32-bit element indices): 1 + 31 + 90 < 126.  A term
   keeps 2^-90 absolute precision, finer than a double's 2^-53 relative
   precision of any quality above 2^-37. */
#define GETME_FX_Q 90
#define GETME_FX_QSCALE 0x1p90
#define GETME_FX_QINV 0x1p-90

/* trunc(v * scale) as a fixed-point integer; scale is a power of two and
   |v * scale| < 2^126 (the caller's bound).  Exact: a = |v| * scale is a
   double with an integer part of at most 126 bits; hi = floor(a / 2^63)
   has at most 53 significant bits (a's own), so hi * 2^63 is exact and so
   is the remainder a - hi * 2^63 in [0, 2^63) (it keeps a subset of a's
   mantissa bits); its integer part is lo. */
static inline getme_fx getme__fx(double v, double scale)
{
    double a = fabs(v * scale);
    int64_t hi = (int64_t)(a * 0x1p-63);
    int64_t lo = (int64_t)(a - (double)hi * 0x1p63);
    getme_ufx r = ((getme_ufx)(uint64_t)hi << 63) + (getme_ufx)(uint64_t)lo;
    return v < 0.0 ? (getme_fx)(-r) : (getme_fx)r;
}

/* (double)n, the same correctly rounded (to nearest, ties to even)
   value, without libgcc's soft-float __floattidf (perf: 2.4 % of the
   medium hexes' run, from node_phat's four conversions per node and
   iteration).  |n| < 2^64 converts in one step (int64, or uint64, which gcc
   converts exactly rounded also without AVX-512).  Above, a = |n| =
   hi 2^64 + lo with hi > 0: m = floor(a / 2^sh), sh = 64 - clz(hi) in
   [1, 64], has its top bit at 63, so a double keeps m's bits 63..11 and
   rounds at bit 10.  The bits of a below 2^sh can only decide a tie or
   not: OR-ing "any of them set" into m's bit 0 (below bit 10, never bit 10
   itself) leaves RN(m') = RN(a / 2^sh).  Scaling by 2^sh (sh <= 64,
   |n| <= 2^127) is exact, and RN is odd, so the sign goes on last. */
static inline double getme__fx_to_double(getme_fx n)
{
    int64_t s = (int64_t)n;
    if ((getme_fx)s == n)
        return (double)s;
    getme_ufx a = n < 0 ? -(getme_ufx)n : (getme_ufx)n;
    uint64_t hi = (uint64_t)(a >> 64), lo = (uint64_t)a;
    double d;
    if (hi == 0) {
        d = (double)lo;
    } else {
        int sh = 64 - __builtin_clzll(hi);
        uint64_t m = (uint64_t)(a >> sh);
        uint64_t below = sh == 64 ? lo : lo & ((UINT64_C(1) << sh) - 1u);
        m |= below != 0;
        uint64_t eb = (uint64_t)(1023 + sh) << 52; /* 2^sh */
        double scale;
        memcpy(&scale, &eb, sizeof scale);
        d = (double)m * scale;
    }
    return n < 0 ? -d : d;
}

/* n * 2^-s as the nearest double (inv = 2^-s, a power of two: exact). */
static inline double getme__fx_double(getme_fx n, double inv)
{
    return getme__fx_to_double(n) * inv;
}

/* A quality as a fixed-point term at scale 2^90 (q_mean's sums). */
static inline getme_fx getme__fx_q(double q)
{
    return getme__fx(q, GETME_FX_QSCALE);
}

/* The sum of getme__fx_q(v[i]) over [0, n), n < 2^31, |v[i]| <= 2: the
   same integer, in int64 parts that vector instructions add lane by lane
   (q_mean's sum runs over every element in every iteration).  A term's
   magnitude a = trunc(|v| 2^90) < 2^91 is hi 2^63 + lo as in getme__fx
   (hi < 2^28), and lo = l1 2^32 + l0 (l1 < 2^31, l0 < 2^32); the three
   signed sums of n < 2^31 such parts stay below 2^59, 2^62 and 2^63. */
static inline getme_fx getme__fx_q_sum(const double *v, int64_t n)
{
    int64_t sh = 0, s1 = 0, s0 = 0;
#pragma omp simd reduction(+ : sh, s1, s0)
    for (int64_t i = 0; i < n; i++) {
        double a = fabs(v[i] * GETME_FX_QSCALE);
        int64_t hi = (int64_t)(a * 0x1p-63);
        int64_t lo = (int64_t)(a - (double)hi * 0x1p63);
        int64_t l1 = lo >> 32, l0 = lo & 0xffffffff;
        int neg = v[i] < 0.0;
        sh += neg ? -hi : hi;
        s1 += neg ? -l1 : l1;
        s0 += neg ? -l0 : l0;
    }
    /* wrapping unsigned shifts, then the two's complement value */
    return (getme_fx)(((getme_ufx)sh << 63) + ((getme_ufx)s1 << 32) +
                      (getme_ufx)s0);
}

/* trunc(v * scale) for |v * scale| < 2^63: one conversion instruction.
   The Eq. 9 sums use it (adjacency.h): half the memory of 128 bits, which
   is what their scattered loads cost. */
static inline int64_t getme__fx64(double v, double scale)
{
    return (int64_t)(v * scale);
}

/* The smallest power of two >= v (v > 0, finite); 1 for v <= 0. */
static inline double getme__pow2_ceil(double v)
{
    if (!(v > 0.0))
        return 1.0;
    int ex;
    double m = frexp(v, &ex); /* v = m 2^ex, m in [0.5, 1) */
    return ldexp(1.0, m == 0.5 ? ex - 1 : ex);
}

#endif /* GETME_EXACT_H */
