/*
 * test_fx_double.c -- exact.h's getme__fx_to_double gives the bits of the
 * C conversion (double)n it replaces (libgcc's __floattidf, correctly
 * rounded to nearest, ties to even): on 128-bit integers of every size and
 * sign, on the values around each power of two, and on the ties and
 * near-ties that decide the rounding (where a wrong sticky bit or a wrong
 * shift shows).  ComputeNewNodes' p-hat (getme_adaptive.c node_phat)
 * converts every node's exact sums with it, so every output depends on it.
 */
#include "check.h"
#include "exact.h"

#include <stdint.h>
#include <string.h>

static uint64_t rng_state = 0x2b7e151628aed2a6ULL;

static uint64_t rand64(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static int same(getme_fx n)
{
    /* volatile: the reference must be the library conversion, not a
       constant the compiler folded with the same code under test */
    volatile getme_fx v = n;
    double want = (double)v, got = getme__fx_to_double(n);
    return memcmp(&want, &got, sizeof want) == 0;
}

/* n and -n (and the neighbours of both) */
static int same4(getme_ufx u)
{
    /* in unsigned arithmetic: wrapping, where n + 1 or -n would
       overflow a signed type */
    return same((getme_fx)u) && same((getme_fx)(0 - u)) &&
           same((getme_fx)(u + 1)) && same((getme_fx)(u - 1));
}

int main(void)
{
    int ok = 1;
    /* every power of two, and the values next to it and to its halves */
    for (int k = 0; k < 127; k++) {
        getme_ufx p = (getme_ufx)1 << k;
        ok &= same4(p) && same4(p + p / 2) && same4(p - p / 2);
    }
    CHECK(ok);
    /* the ties: for a top bit t >= 53, the value 2^t + j 2^(t - 52) +
       2^(t - 53) (halfway between two doubles, even and odd j), a tie
       plus one low bit, and a tie minus one, at every t */
    ok = 1;
    for (int t = 53; t < 127; t++) {
        getme_ufx top = (getme_ufx)1 << t, ulp = (getme_ufx)1 << (t - 52);
        for (int j = 0; j < 4; j++) {
            getme_ufx tie = top + (getme_ufx)j * ulp + ulp / 2;
            ok &= same4(tie) && same4(tie + 2) && same4(tie - 2);
            if (t > 64) /* a set bit far below the rounding position */
                ok &= same4(tie + ((getme_ufx)1 << (t - 64)));
        }
    }
    CHECK(ok);
    /* random integers of every length (1 .. 127 bits) and sign, with
       random runs of zeros in the low bits (the sticky bit's cases) */
    ok = 1;
    for (int i = 0; i < 400000; i++) {
        getme_ufx u = ((getme_ufx)rand64() << 64) | rand64();
        int len = 1 + (int)(rand64() % 127);
        u >>= 128 - len;
        int zeros = (int)(rand64() % (unsigned)len);
        u &= ~(((getme_ufx)1 << zeros) - 1);
        ok &= same4(u);
    }
    CHECK(ok);
    /* the extremes */
    getme_fx max = (getme_fx)(~(getme_ufx)0 >> 1);
    CHECK(same(max) && same(-max) && same(-max - 1));
    CHECK(same(0) && same(INT64_MAX) && same(INT64_MIN) &&
          same((getme_fx)INT64_MIN - 1) && same((getme_fx)UINT64_MAX));
    return check_summary("test_fx_double");
}
