/*
 * div3.h -- exact divisions by 3 without a divide instruction, for the
 * hot kernels (quality.c's cube roots, the hex transformation's node
 * means), where the divider is the bottleneck or the 64-bit integer
 * division has no vector instruction.  Each gives the same bits as the
 * division it replaces, for every input (the proofs are beside them;
 * tests/core/test_div3.c checks them against the division).
 */
#ifndef GETME_DIV3_H
#define GETME_DIV3_H

#include <float.h>
#include <math.h>
#include <stdint.h>

/*
 * s / 3 correctly rounded, without a division: the divider is the
 * bottleneck of the hex transformation (40 square roots and 33 divisions
 * per hex on one unit), this form runs on the multiply-add units.
 * With C = RN(1/3) = (1 - 2^-54) / 3:
 *  - q0 = RN(s C) is within one ulp u of s / 3 (s C = s/3 (1 - 2^-54));
 *  - r = s - 3 q0 is exact in one fused multiply-add: s and 3 q0 are
 *    multiples of u (u <= ulp(s) / 2) and |r| < 3 u;
 *  - q0 + r C = s/3 - r (1/3 - C) = s/3 - r 2^-54 / 3, less than u 2^-54
 *    from s / 3, while s / 3 = (k/3) u for an integer k lies at least u/6
 *    from every midpoint between two doubles; so the one rounding of the
 *    second fused multiply-add, RN(q0 + r C), is RN(s / 3).
 * The same holds for subnormal results (u = 2^-1074) and for s = +0 (the
 * callers' sums start with 0.0 +, so s is never -0, where this would give
 * +0).  An infinite s would make r NaN: q0 (= s / 3 there) is kept for a
 * non-finite q0, so NaN and infinities come out as from the division.
 * getme__div3_fma is always this form (the tests compare it with s / 3);
 * getme__div3 is it where the target has fused multiply-adds (fma()
 * would otherwise be a library call) and the division elsewhere: the same
 * bits either way.
 */
static inline double getme__div3_fma(double s)
{
    const double third = 0.333333333333333314829616256247390992939472198486328125;
    double q0 = s * third;
    double r = fma(-3.0, q0, s);
    double q1 = fma(r, third, q0);
    return fabs(q0) <= DBL_MAX ? q1 : q0;
}

static inline double getme__div3(double s)
{
#ifdef __FMA__
    return getme__div3_fma(s);
#else
    return s / 3;
#endif
}

/* b / 3 for any 64-bit b, in operations that have vector instructions
   (AVX-512: 32-bit multiplies and exact integer <-> double conversions;
   there is no 64-bit multiply-high).  With b = h 2^32 + l and 2^32 =
   3 * 0x55555555 + 1: b = 3 h 0x55555555 + (h + l), so b / 3 = h 0x55555555
   + (h + l) / 3 with h + l < 2^33.  That n = h + l is exact in a double,
   and floor(RN(n C)) = n / 3 for C = RN(1/3) = (1 - 2^-54) / 3: n C =
   n/3 - n/3 2^-54; for n = 3k that is k less 2^-54 k, less than half an
   ulp of k below it, which rounds to k (for k a power of 2 it is the
   midpoint below k, and the tie goes to the even k); for n = 3k + 1 or
   3k + 2, n/3 is 1/3 from an integer and the error is below 2^-20. */
static inline uint64_t getme__div3_u64(uint64_t b)
{
    int64_t h = (int64_t)(b >> 32), n = h + (int64_t)(b & UINT64_C(0xffffffff));
    int64_t r = (int64_t)((double)n * (1.0 / 3.0)); /* >= 0: truncation
                                                        is the floor */
    return (uint64_t)(uint32_t)h * UINT64_C(0x55555555) + (uint64_t)r;
}

/* getme__div3_u64 without integer <-> double conversion instructions
   (AVX2 has none for 64-bit integers), for the same bits: n = h + l <
   2^33 < 2^52 becomes a double exactly as the bits of 2^52 + n less 2^52;
   floor(RN(n C)) = n / 3 as above (floor, a vector instruction, instead of
   the truncation, the same for n C >= 0); and that integer k < 2^32 comes
   back as the bits of 2^52 + k (exact) less those of 2^52.  The unions
   rather than memcpy: gcc 12 vectorises them (quality.c). */
static inline uint64_t getme__div3_u64_bits(uint64_t b)
{
    const uint64_t two52 = UINT64_C(0x4330000000000000); /* bits of 2^52 */
    uint64_t h = b >> 32, n = h + (b & UINT64_C(0xffffffff));
    union { uint64_t u; double d; } c = {n | two52}, r;
    r.d = floor((c.d - 0x1p52) * (1.0 / 3.0)) + 0x1p52;
    return h * UINT64_C(0x55555555) + (r.u - two52);
}

#endif /* GETME_DIV3_H */
