/*
 * test_angle.c -- getme__angle (core/src/angle.h), the vectorisable
 * atan2(y, x) for y >= 0 behind the dihedral-angle measures: against the
 * C library's atan2 on random pairs in the regimes where a reduction
 * step could lose accuracy (angles near 0, pi/4, pi/2, 3 pi/4, pi, tiny
 * and huge magnitudes), and exactly on atan2's special cases.
 */
#include "check.h"

#include "angle.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ulps between two finite doubles of the same sign or zero */
static int64_t ulps(double a, double b)
{
    int64_t i, j;
    memcpy(&i, &a, sizeof i);
    memcpy(&j, &b, sizeof j);
    return i > j ? i - j : j - i;
}

static uint64_t rng_state = 0x853c49e6748fea9bu;

static double uniform(void) /* [0, 1) */
{
    uint64_t x = rng_state;
    x ^= x << 13, x ^= x >> 7, x ^= x << 17;
    rng_state = x;
    return (double)(x >> 11) * 0x1p-53;
}

/* The largest ulp distance from atan2 over n pairs of regime r. */
static int64_t worst_ulps(int r, int n)
{
    int64_t worst = 0;
    for (int k = 0; k < n; k++) {
        double u = uniform(), v = 2.0 * uniform() - 1.0, y, x;
        switch (r) {
        case 0: y = u, x = v; break;                     /* anywhere   */
        case 1: y = u * 1e-9, x = v; break;              /* near 0, pi */
        case 2: y = u, x = v * 1e-9; break;              /* near pi/2  */
        case 3: y = u, x = (v < 0 ? -u : u) * (1 + v * 1e-7); break; /* pi/4, 3pi/4 */
        case 4: y = u * 1e-200, x = v * 1e-200; break;   /* tiny       */
        default: y = u * 1e200, x = v * 1e200; break;    /* huge       */
        }
        int64_t d = ulps(getme__angle(y, x), atan2(y, x));
        if (d > worst)
            worst = d;
    }
    return worst;
}

int main(void)
{
    /* 2e7 pairs gave at most 5 ulp; a wrong series coefficient or
       reduction constant gives thousands or more */
    for (int r = 0; r < 6; r++) {
        int64_t w = worst_ulps(r, 200000);
        if (w > 8)
            fprintf(stderr, "regime %d: %lld ulp\n", r, (long long)w);
        CHECK(w <= 8);
    }
    const double pi = 3.14159265358979323846, inf = INFINITY;
    /* atan2's special cases, bit for bit */
    CHECK(getme__angle(0.0, 0.0) == 0.0 && !signbit(getme__angle(0.0, 0.0)));
    CHECK(getme__angle(0.0, -0.0) == pi);
    CHECK(getme__angle(0.0, 1.0) == 0.0);
    CHECK(getme__angle(0.0, -1.0) == pi);
    CHECK(getme__angle(1.0, 0.0) == pi / 2);
    CHECK(getme__angle(1.0, -0.0) == pi / 2);
    CHECK(getme__angle(inf, 1.0) == pi / 2);
    CHECK(getme__angle(1.0, inf) == 0.0);
    CHECK(getme__angle(1.0, -inf) == pi);
    CHECK(ulps(getme__angle(inf, inf), pi / 4) <= 1);
    CHECK(ulps(getme__angle(inf, -inf), 3 * pi / 4) <= 1);
    CHECK(isnan(getme__angle(NAN, 1.0)));
    CHECK(isnan(getme__angle(1.0, NAN)));
    CHECK(getme__angle(1e-300, 1.0) == 1e-300);
    /* subnormal results keep only their absolute accuracy (the half-angle
       steps halve them) */
    CHECK(fabs(getme__angle(4.9e-324, 1.0) - 4.9e-324) <= 1e-323);
    /* known angles */
    CHECK(ulps(getme__angle(1.0, 1.0), pi / 4) <= 1);
    CHECK(ulps(getme__angle(1.0, -1.0), 3 * pi / 4) <= 1);
    CHECK(ulps(getme__angle(sqrt(3.0), 1.0), pi / 3) <= 4);
    CHECK(ulps(getme__angle(1.0, sqrt(3.0)), pi / 6) <= 4);
    CHECK(ulps(getme__angle(2.0 * sqrt(2.0), 1.0), acos(1.0 / 3.0)) <= 4);
    return check_summary("core_angle");
}
