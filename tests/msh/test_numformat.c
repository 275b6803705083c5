/*
 * test_numformat.c -- numformat_g (formats/numformat.c) against snprintf
 * "%.*g" and strtod, for every precision 1..17, on millions of doubles:
 * random bit patterns (every exponent), short decimals as meshes hold
 * them (k / 10^j), values next to powers of ten and of two, and values
 * with few mantissa bits (exact decimal ties, where rounding half to even
 * shows).  The text must be byte-identical and the round-trip flag must
 * say whether strtod gives the value back.
 */
#include "check.h"
#include "numformat.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t state = 12345;
static uint64_t next(void)
{
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
}

static long failures;

static void one(double v, int prec)
{
    char want[64], got[64];
    int rt = -1;
    int nw = snprintf(want, sizeof want, "%.*g", prec, v);
    int ng = numformat_g(v, prec, got, &rt);
    int want_rt = strtod(want, NULL) == v; /* never for a NaN */
    if (nw != ng || strcmp(want, got) != 0 || rt != want_rt) {
        if (failures++ < 10)
            fprintf(stderr, "%.17g prec %d: want '%s' (%d) got '%s' (%d)\n", v,
                    prec, want, want_rt, got, rt);
    }
}

static void all_prec(double v)
{
    for (int p = 1; p <= 17; p++)
        one(v, p);
}

int main(void)
{
    long n = 0;
    for (long i = 0; i < 100000; i++, n++) { /* any bit pattern */
        uint64_t b = next();
        double v;
        memcpy(&v, &b, sizeof v);
        all_prec(v);
    }
    for (long i = 0; i < 100000; i++, n++) { /* mesh-like decimals */
        double v = (double)(int64_t)(next() % 2000000001) - 1e9;
        v /= pow(10, (double)(next() % 19));
        all_prec(v);
        all_prec(nextafter(v, INFINITY));
        all_prec(v * (1 + 1e-3 * (double)(next() % 1000)));
    }
    for (int x = -30; x <= 30; x++) { /* next to powers of ten and two */
        double p = pow(10, x), q = ldexp(1, x * 3);
        double vs[6] = {p, nextafter(p, 0), nextafter(p, INFINITY),
                        q, nextafter(q, 0), nextafter(q, INFINITY)};
        for (int k = 0; k < 6; k++, n++) {
            all_prec(vs[k]);
            all_prec(-vs[k]);
        }
    }
    for (long i = 0; i < 100000; i++, n++) { /* few mantissa bits: ties */
        double v = ldexp((double)(next() % 4096 + 1), (int)(next() % 80) - 60);
        all_prec(v);
    }
    double special[] = {0.0, -0.0, INFINITY, -INFINITY, NAN, 5e-324, 1e308,
                        0.5, 1.5, 2.5, 0.125, 1e15, 1e16, 1e17, 123456789012345678.0};
    for (size_t i = 0; i < sizeof special / sizeof *special; i++)
        all_prec(special[i]);
    CHECK(failures == 0);
    printf("%ld values x 17 precisions, %ld differences\n", n, failures);
    return check_summary("test_numformat");
}
