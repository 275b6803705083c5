/*
 * test_div3.c -- the exact divisions by 3 of div3.h give the bits of the
 * division they replace: getme__div3_fma (two fused multiply-adds) against
 * s / 3 on doubles of every exponent (normal, subnormal, the extremes,
 * infinities, NaN), and getme__div3_u64 and getme__div3_u64_bits (32-bit
 * products and a double, from conversion instructions or from bits)
 * against b / 3 on 64-bit integers of every size and on the values next
 * to multiples of 3, of powers of 2 and of the 2^32 boundary its split
 * uses.  The hex transformation's node means and the cube roots' initial
 * guesses use them, and every smoothing output depends on those bits.
 */
#include "check.h"
#include "div3.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

static uint64_t rng_state = 0x5d1b3c0ffee1ULL;

static uint64_t rand64(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static double from_bits(uint64_t b)
{
    double d;
    memcpy(&d, &b, sizeof d);
    return d;
}

static int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Division at run time (volatile: no constant folding). */
static double div3_ref(double s)
{
    volatile double three = 3.0;
    return s / three;
}

static int double_ok(double s)
{
    return same_bits(getme__div3_fma(s), div3_ref(s)) &&
           same_bits(getme__div3(s), div3_ref(s));
}

static void check_double(void)
{
    int ok = 1, n_random = 3000000;
    for (int i = 0; i < n_random; i++) /* every exponent and sign */
        ok &= double_ok(from_bits(rand64() & ~(UINT64_C(1) << 63)) * (i % 2 ? 1.0 : -1.0));
    CHECK(ok);
    ok = 1;
    for (int i = 0; i < n_random; i++) /* the coordinates' range */
        ok &= double_ok((double)(int64_t)(rand64() >> 11) * 0x1p-40 * (i % 2 ? 1.0 : -1.0));
    CHECK(ok);
    ok = 1;
    for (int e = -1074; e <= 1023; e++) /* around 3 k 2^e and 2^e */
        for (int k = 1; k < 64; k++) {
            double p = ldexp(1.0, e), v = 3.0 * k * p;
            ok &= double_ok(p) & double_ok(v) & double_ok(nextafter(v, 0.0)) &
                  double_ok(nextafter(v, INFINITY)) & double_ok(nextafter(p, 0.0)) &
                  double_ok(nextafter(p, INFINITY)) & double_ok(-v);
        }
    CHECK(ok);
    ok = 1;
    for (int i = 0; i < 100000; i++) /* the largest significands */
        ok &= double_ok(from_bits(UINT64_C(0x000fffffffffffff) - (uint64_t)i +
                                  ((rand64() % 2046 + 1) << 52)));
    CHECK(ok);
    const double special[] = {0.0, DBL_MIN, -DBL_MIN, DBL_MAX, -DBL_MAX,
                              DBL_TRUE_MIN, -DBL_TRUE_MIN, 3.0 * DBL_TRUE_MIN,
                              2.0 * DBL_TRUE_MIN, 1.0, 2.0, 3.0, 1e300, 1e-300,
                              INFINITY, -INFINITY};
    for (size_t i = 0; i < sizeof special / sizeof *special; i++)
        CHECK(double_ok(special[i]));
    /* NaN stays NaN; -0 (which the callers never pass) gives a zero */
    CHECK(isnan(getme__div3_fma(NAN)) && isnan(getme__div3(NAN)));
    CHECK(getme__div3_fma(-0.0) == 0.0);
}

static int u64_ok(uint64_t b)
{
    volatile uint64_t three = 3;
    return getme__div3_u64(b) == b / three &&
           getme__div3_u64_bits(b) == b / three;
}

static void check_u64(void)
{
    int ok = 1;
    for (int i = 0; i < 3000000; i++) {
        uint64_t b = rand64();
        ok &= u64_ok(b) & u64_ok(b >> (i % 64)); /* every size */
    }
    CHECK(ok);
    ok = 1;
    for (int s = 0; s < 64; s++) /* around 2^s, 3 2^s and 2^32 multiples */
        for (int64_t d = -8; d <= 8; d++) {
            uint64_t p = UINT64_C(1) << s;
            ok &= u64_ok(p + (uint64_t)d) & u64_ok(3 * p + (uint64_t)d) &
                  u64_ok((p << 32 >> 32) + (uint64_t)d) &
                  u64_ok(UINT64_C(0xffffffff) * (uint64_t)(s + 1) + (uint64_t)d);
        }
    CHECK(ok);
    ok = 1;
    for (uint64_t h = 0; h < 4096; h++) /* h + l across multiples of 3 */
        for (uint64_t l = UINT64_C(0xffffffff) - 8; l <= UINT64_C(0xffffffff); l++)
            ok &= u64_ok(h << 32 | l) & u64_ok(~(h << 32 | l)) &
                  u64_ok((h * UINT64_C(0x0010000100001)) << 20 | (l & 0xff));
    CHECK(ok);
    CHECK(u64_ok(0) && u64_ok(UINT64_MAX) && u64_ok(UINT64_MAX - 1) &&
          u64_ok(UINT64_C(1) << 63));
}

int main(void)
{
    check_double();
    check_u64();
    return check_summary("test_div3");
}
