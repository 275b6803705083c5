/*
 * numformat.c -- "%.*g" of a double, exactly, with 128-bit integers where
 * that can be proven exact, and snprintf for everything else.
 *
 * A finite normal double is v = m * 2^e with an integer 2^52 <= m < 2^53.
 * Its first P significant digits are D = round(|v| * 10^s) with
 * s = P - 1 - floor(log10 |v|).  For 0 <= s <= 31 and e + s < 0,
 * |v| * 10^s = m * 5^s / 2^k with k = -(e + s): N = m * 5^s < 2^53 * 5^31 <
 * 2^126 is an exact 128-bit integer, and D is N >> k rounded by the bits
 * shifted out -- half to even on an exact tie, as glibc's printf rounds in
 * the default rounding mode.  floor(log10 |v|) is estimated from the binary
 * exponent and corrected until 10^(P-1) <= N >> k < 10^P, which is exact.  The text is
 * then laid out as %g does: %e style if the decimal exponent X is below -4
 * or at least P, else %f style, trailing zeros (and a bare '.') removed.
 *
 * Whether the text reads back to v is decided on the same integers: the
 * doubles nearest v are half an ulp away, 2^(e-1) (2^(e-2) below a power of
 * two), i.e. 5^s / 2^(k+1) in units of 10^-s, so D reads back to v iff
 * |D * 2^(k+1) - 2N| < 5^s (5^s / 2 below a power of two), or equals it
 * and m is even (strtod rounds ties to even).  That needs D * 2^(k+1) < 2^128:
 * k <= 64, i.e. |v| above about 1e-12.  Outside these ranges (zero,
 * subnormals, |v| >= 10^P or tiny, infinities, NaN) snprintf and strtod
 * are used, so every result is the same as theirs.
 */
#include "numformat.h"
#include "numparse.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

__extension__ typedef unsigned __int128 u128;

static const uint64_t pow10_u64[20] = {1ULL,
                                       10ULL,
                                       100ULL,
                                       1000ULL,
                                       10000ULL,
                                       100000ULL,
                                       1000000ULL,
                                       10000000ULL,
                                       100000000ULL,
                                       1000000000ULL,
                                       10000000000ULL,
                                       100000000000ULL,
                                       1000000000000ULL,
                                       10000000000000ULL,
                                       100000000000000ULL,
                                       1000000000000000ULL,
                                       10000000000000000ULL,
                                       100000000000000000ULL,
                                       1000000000000000000ULL,
                                       10000000000000000000ULL};

/* 5^s for 0 <= s <= 31 (5^27 is the largest power below 2^64). */
static const uint64_t pow5_u64[28] = {
    1ULL, 5ULL, 25ULL, 125ULL, 625ULL, 3125ULL, 15625ULL, 78125ULL,
    390625ULL, 1953125ULL, 9765625ULL, 48828125ULL, 244140625ULL,
    1220703125ULL, 6103515625ULL, 30517578125ULL, 152587890625ULL,
    762939453125ULL, 3814697265625ULL, 19073486328125ULL, 95367431640625ULL,
    476837158203125ULL, 2384185791015625ULL, 11920928955078125ULL,
    59604644775390625ULL, 298023223876953125ULL, 1490116119384765625ULL,
    7450580596923828125ULL};

static u128 pow5(int s)
{
    return s > 27 ? (u128)pow5_u64[27] * pow5_u64[s - 27] : pow5_u64[s];
}

static int slow(double v, int prec, char *buf, int *roundtrip)
{
    int n = snprintf(buf, 32, "%.*g", prec, v);
    if (roundtrip)
        *roundtrip = numparse_strtod(buf, NULL) == v;
    return n;
}

/* Lay out the prec digits of d (10^(prec-1) <= d < 10^prec) with decimal
   exponent x as %g does. */
static int layout(int neg, uint64_t d, int prec, int x, char *buf)
{
    char dig[20];
    for (int i = prec - 1; i >= 0; i--) {
        dig[i] = (char)('0' + d % 10);
        d /= 10;
    }
    int nd = prec; /* significant digits left once trailing zeros go */
    while (nd > 1 && dig[nd - 1] == '0')
        nd--;
    int n = 0;
    if (neg)
        buf[n++] = '-';
    if (x < -4 || x >= prec) {
        buf[n++] = dig[0];
        if (nd > 1) {
            buf[n++] = '.';
            memcpy(buf + n, dig + 1, (size_t)(nd - 1));
            n += nd - 1;
        }
        buf[n++] = 'e';
        buf[n++] = x < 0 ? '-' : '+';
        int ax = x < 0 ? -x : x;
        if (ax >= 100)
            buf[n++] = (char)('0' + ax / 100);
        buf[n++] = (char)('0' + ax / 10 % 10);
        buf[n++] = (char)('0' + ax % 10);
    } else if (x >= 0) {
        memcpy(buf + n, dig, (size_t)(x + 1)); /* x + 1 <= prec digits */
        n += x + 1;
        if (nd > x + 1) {
            buf[n++] = '.';
            memcpy(buf + n, dig + x + 1, (size_t)(nd - x - 1));
            n += nd - x - 1;
        }
    } else {
        buf[n++] = '0';
        buf[n++] = '.';
        for (int i = 0; i < -x - 1; i++)
            buf[n++] = '0';
        memcpy(buf + n, dig, (size_t)nd);
        n += nd;
    }
    buf[n] = 0;
    return n;
}

int numformat_g(double v, int prec, char *buf, int *roundtrip)
{
    if (prec < 1 || prec > 17 || !isnormal(v))
        return slow(v, prec, buf, roundtrip);
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    int neg = (int)(bits >> 63);
    int be = (int)(bits >> 52 & 0x7ff);
    uint64_t m = (bits & ((1ULL << 52) - 1)) | (1ULL << 52);
    int e = be - 1075; /* v = m * 2^e */
    /* floor(log10 |v|) from the binary exponent: off by at most one,
       which the loop below corrects */
    int x = (int)floor((double)(be - 1023) * 0.30102999566398120);
    for (int tries = 0; tries < 3; tries++) {
        int s = prec - 1 - x, k = -(e + s);
        if (s < 0 || s > 31 || k < 1 || k > 64)
            return slow(v, prec, buf, roundtrip);
        u128 p5 = pow5(s), n = (u128)m * p5;
        u128 q = n >> k, r = n & (((u128)1 << k) - 1), half = (u128)1 << (k - 1);
        if (q < pow10_u64[prec - 1]) {
            x--;
            continue;
        }
        if (q >= pow10_u64[prec]) {
            x++;
            continue;
        }
        uint64_t d = (uint64_t)q;
        if (r > half || (r == half && (d & 1)))
            d++;
        if (roundtrip) {
            /* |d * 2^(k+1) - 2n| against 5^s, halved below a power of 2 */
            u128 a = (u128)d << (k + 1), b = n << 1;
            int above = a >= b;
            u128 dist = above ? a - b : b - a;
            if (!above && m == (1ULL << 52)) /* 5^s odd: never a tie */
                *roundtrip = dist << 1 < p5;
            else
                *roundtrip = dist < p5 || (dist == p5 && (m & 1) == 0);
        }
        if (d == pow10_u64[prec]) { /* rounded up to 10^prec */
            d = pow10_u64[prec - 1];
            x++;
        }
        return layout(neg, d, prec, x, buf);
    }
    return slow(v, prec, buf, roundtrip);
}
