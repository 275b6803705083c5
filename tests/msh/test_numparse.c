/*
 * test_numparse.c -- numparse_strtod (formats/numparse.c) must agree with
 * strtod bit for bit, with the same end pointer and errno, on every input:
 * fixed edge cases (fast path, each reason to leave it, strtod-only
 * syntax) and millions of random decimals of every length and exponent.
 */
#include "check.h"
#include "numparse.h"

#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static long mismatches = 0;

/* Same bits, end and errno as strtod? */
static int same(const char *s)
{
    char *e1, *e2;
    errno = 0;
    double a = strtod(s, &e1);
    int err1 = errno;
    errno = 0;
    double b = numparse_strtod(s, &e2);
    int err2 = errno;
    if (memcmp(&a, &b, sizeof a) == 0 && e1 == e2 && err1 == err2)
        return 1;
    if (mismatches++ < 10)
        fprintf(stderr, "'%s': strtod %.17g (end %td, errno %d), numparse "
                        "%.17g (end %td, errno %d)\n", s, a, e1 - s, err1, b,
                e2 - s, err2);
    return 0;
}

static uint64_t rng = 0x243f6a8885a308d3u;
static uint64_t next(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return rng;
}

int main(void)
{
    static const char *fixed[] = {
        "0", "-0", "+0", "0.0", "-0.0e5", "1", "-1", "1.", ".5", "-.5e-3",
        "3.14159", "0.1", "0.3", "1e22", "1e23", "9e37", "9e38", "1e-22",
        "1e-23", "123456789e-30", "9007199254740992", "9007199254740993",
        "9007199254740993e-5", "1234567890123456789", "12345678901234567890",
        "0.000000000000000000000000000001234", "1e", "1e+", "1e-", "1.5e+3x",
        "0x1p3", "0X10", "inf", "-infinity", "nan", "  42", "\t-7.25\n",
        "1.5,2", "1.5abc", "1.5 2", "4.9406564584124654e-324",
        "1.7976931348623157e308", "2.2250738585072011e-308", "1e400",
        "1e-400", "-", "+", ".", "", "e5", "-.e1", "00000000000000000000001",
        "0.00000000000000000000000000000000000000000001e44",
        "1e0000000000000000000000000000022", "179769313486231570000e288",
        "-1.2345678901234567e-12", "6.02214076e23", "1.6021766340e-19"};
    for (size_t i = 0; i < sizeof fixed / sizeof *fixed; i++)
        CHECK(same(fixed[i]));

    /* Random doubles as Gmsh and our writers print them (%.Ng). */
    long bad = 0;
    char buf[64];
    for (int i = 0; i < 2000000; i++) {
        uint64_t bits = next();
        double v;
        memcpy(&v, &bits, sizeof v);
        if (v != v)
            continue;
        if (i & 1) /* mesh-like magnitudes too */
            v = ((double)(next() >> 11) / 9007199254740992.0 - 0.5) *
                (double)(1u << (next() % 20));
        snprintf(buf, sizeof buf, "%.*g", 1 + (int)(next() % 17), v);
        bad += !same(buf);
    }
    CHECK(bad == 0);

    /* Random decimal strings: 1-25 digits, a point anywhere, exponents
       around the fast path's limits. */
    bad = 0;
    for (int i = 0; i < 2000000; i++) {
        int n = 1 + (int)(next() % 25), point = (int)(next() % (n + 2)), k = 0;
        if (next() % 2)
            buf[k++] = next() % 2 ? '-' : '+';
        for (int d = 0; d < n; d++) {
            if (d == point)
                buf[k++] = '.';
            buf[k++] = (char)('0' + next() % 10);
        }
        if (next() % 3)
            k += snprintf(buf + k, sizeof buf - (size_t)k, "e%d",
                          (int)(next() % 90) - 45);
        buf[k] = 0;
        bad += !same(buf);
    }
    CHECK(bad == 0);
    return check_summary("test_numparse");
}
