/*
 * angle.h -- atan2(y, x) for y >= 0, in a form that vectorises: the angle
 * in [0, pi] between two vectors, given |u x v| (y) and u . v (x).
 *
 * Why not the C library's atan2: the dihedral-angle measure takes two of
 * them per element (its extreme ends), and as calls they stayed scalar in
 * the otherwise vectorised measure lanes: on the 4M-tet benchmark they
 * were about 5 % of `getme quality` and 3 % of `getme smooth` (perf, one
 * thread), more than the rest of the dihedral measure.  Written as plain
 * arithmetic, gcc evaluates them GETME_LANES at a time.
 *
 * How: t = min(y, |x|) / max(y, |x|) in [0, 1]; two half-angle steps,
 * atan t = 2 atan(t / (1 + sqrt(1 + t^2))), bring it to |t| <= tan(pi/16)
 * = 0.1989, where 12 terms of the Taylor series t (1 - t^2/3 + t^4/5 -
 * ... - t^22/23) leave a truncation error below 2e-17 of the result; then
 * pi/2 - a when y > |x| and pi - a when x < 0 (or -0, as atan2).  Each
 * step rounds a few times, so the result is within a few ulp of the
 * correctly rounded angle (test_angle compares 1.2e6 random pairs with
 * the C library's atan2 in six regimes: at most 8 ulp; 2e7 pairs gave
 * at most 5).  NaN in, NaN out; y = +inf gives pi/2 and y = |x| = inf
 * pi/4 or 3 pi/4, as atan2; a subnormal result keeps only its absolute
 * accuracy (below 1e-323).
 *
 * Only sqrt, division and the four operations: the same bits in a vector
 * lane as in a scalar call (no fused multiply-adds under -std=c11), so the
 * one-element measures and the lanes agree bit for bit.
 */
#ifndef GETME_ANGLE_H
#define GETME_ANGLE_H

#include <math.h>

#define GETME_PI 3.14159265358979323846
#define GETME_PI_2 1.57079632679489661923

#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline double getme__angle(double y, double x)
{
    /* selects on doubles only: an int condition kept gcc from
       vectorising the callers' loops ("no vectype") */
    double ax = fabs(x);
    double num = y > ax ? ax : y, den = y > ax ? y : ax;
    /* 0/0 (a zero vector) is angle 0 as in atan2; inf/inf is 1 */
    double t = num == den ? (den > 0.0 ? 1.0 : 0.0) : num / den;
    t = t / (1.0 + sqrt(1.0 + t * t));
    t = t / (1.0 + sqrt(1.0 + t * t));
    double s = t * t;
    /* sum_k (-s)^k / (2k + 1), k = 0..11, by Horner */
    double p = 1.0 / 21.0 - s * (1.0 / 23.0);
    p = 1.0 / 19.0 - s * p;
    p = 1.0 / 17.0 - s * p;
    p = 1.0 / 15.0 - s * p;
    p = 1.0 / 13.0 - s * p;
    p = 1.0 / 11.0 - s * p;
    p = 1.0 / 9.0 - s * p;
    p = 1.0 / 7.0 - s * p;
    p = 1.0 / 5.0 - s * p;
    p = 1.0 / 3.0 - s * p;
    double a = 4.0 * (t - t * (s * p)); /* atan(num / den), in [0, pi/4] */
    a = y > ax ? GETME_PI_2 - a : a;
    /* x < 0, or -0 (copysign, not signbit: it vectorises) */
    a = copysign(1.0, x) < 0.0 ? GETME_PI - a : a;
    return y != y || x != x ? y + x : a;
}

#endif /* GETME_ANGLE_H */
