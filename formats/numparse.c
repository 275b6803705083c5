/*
 * numparse.c -- decimal text to double, exactly, without strtod where that
 * can be proven exact (Clinger's fast path).
 *
 * A decimal w * 10^k with an integer w <= 2^53 and |k| <= 22 has both w and
 * 10^|k| exactly representable as doubles (5^22 < 2^53).  One IEEE
 * multiplication or division of two exact operands is rounded once, to
 * nearest, so w * 10^k (or w / 10^-k) is the correctly rounded value of
 * the decimal: the same double strtod returns.  For k > 22 the fast path
 * still holds when w * 10^(k - 22) is an integer <= 2^53 (then exact), times
 * 1e22.  Anything else (more than 19 significant digits, a larger w, a
 * larger exponent, hexadecimal, inf, nan, a number followed by other
 * characters) is handed to strtod unchanged, so the result is the same for
 * every input; only the cost differs.  Meshes written by Gmsh (%.16g) and
 * by most FE tools mostly fall in the fast path.
 *
 * This needs double arithmetic without excess precision (FLT_EVAL_METHOD
 * 0, as on x86-64 with SSE2 and every 64-bit target we build for); with any
 * other evaluation method every number goes to strtod.
 */
#include "numparse.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>

static const double pow10_exact[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* The characters that may follow a number for the fast path: strtod would
   stop there too, having consumed exactly what we did. */
static int is_stop(char c)
{
    return c == '\0' || c == ' ' || c == '\t' || c == '\n' || c == '\r' ||
           c == '\v' || c == '\f' || c == ',';
}

double numparse_strtod(const char *s, char **end)
{
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
    const char *p = s;
    while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r' ||
           *p == '\v' || *p == '\f')
        p++;
    int neg = *p == '-';
    if (*p == '-' || *p == '+')
        p++;
    uint64_t w = 0;
    int nd = 0, any = 0;    /* significant digits in w, digits seen */
    int64_t k = 0;          /* decimal exponent of w's last digit     */
    for (; is_digit(*p); p++, any = 1) {
        if (w == 0 && *p == '0')
            continue; /* leading zeros are not significant */
        if (nd == 19)
            goto slow;
        w = 10 * w + (uint64_t)(*p - '0'), nd++;
    }
    if (*p == '.') {
        p++;
        for (; is_digit(*p); p++, any = 1) {
            k--;
            if (w == 0 && *p == '0')
                continue;
            if (nd == 19)
                goto slow;
            w = 10 * w + (uint64_t)(*p - '0'), nd++;
        }
    }
    if (!any)
        goto slow;
    if (*p == 'e' || *p == 'E') {
        const char *q = p + 1;
        int eneg = *q == '-';
        if (*q == '-' || *q == '+')
            q++;
        if (!is_digit(*q))
            goto slow; /* "1e" or "1e+": strtod's own business */
        int64_t e = 0;
        for (; is_digit(*q); q++) {
            if (e > 100000)
                goto slow;
            e = 10 * e + (*q - '0');
        }
        k += eneg ? -e : e;
        p = q;
    }
    if (!is_stop(*p))
        goto slow;
    double v;
    if (w == 0) {
        v = 0.0;
    } else if (w > (UINT64_C(1) << 53)) {
        goto slow;
    } else if (k >= 0 && k <= 22) {
        v = (double)w * pow10_exact[k];
    } else if (k < 0 && k >= -22) {
        v = (double)w / pow10_exact[-k];
    } else if (k > 22 && k <= 22 + 15) {
        uint64_t m = w;
        for (int64_t i = 22; i < k; i++) {
            if (m > (UINT64_C(1) << 53) / 10)
                goto slow;
            m *= 10;
        }
        v = (double)m * 1e22;
    } else {
        goto slow;
    }
    if (end)
        *end = (char *)p;
    return neg ? -v : v;
slow:
#endif
    return strtod(s, end);
}
