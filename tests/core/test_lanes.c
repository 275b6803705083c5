/*
 * test_lanes.c -- the lane kernels (GETME_LANES elements at once: the tet
 * and hex transformations and mean ratios the smoother's block kernel and
 * relaxation use) give the same bits as the one-element kernels, lane by
 * lane, on random valid, inverted and degenerate elements and on the
 * regular ones.  Results of a smoothing run are only thread-count and
 * build independent if that holds exactly, so the test compares bits, not
 * values within a tolerance.
 *
 * The hex mean ratio is also compared with the textbook kernel below
 * (corner by corner: its three edges, det, squared lengths, the one-value
 * cube root),
 * because the library's one-element and lane kernels share their edges
 * and cube roots across corners and must still give its bits.
 *
 * q_mean's vectorised exact sum (exact.h getme__fx_q_sum, int64 parts)
 * must be the integer the scalar terms getme__fx_q add up to.
 *
 * Built from the core's sources (not libgetme), because it checks private
 * functions.
 */
#define _DEFAULT_SOURCE /* mmap's MAP_ANONYMOUS (check_gather's guard page) */
#include "check.h"
#include "exact.h"
#include "gather_lanes.h"
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include "regular_elements.h"

#define RANDOM_GEOMETRY_SEED 0x1a9e5b10c4ULL
#include "random_geometry.h"

static int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* The hex mean ratio one corner at a time (paper's N^hex, W = I). */
static double ref_quality_hex(const double *x)
{
    static const int corner[8][4] = {{0, 3, 4, 1}, {1, 0, 5, 2}, {2, 1, 6, 3},
                                     {3, 2, 7, 0}, {4, 7, 5, 0}, {5, 4, 6, 1},
                                     {6, 5, 7, 2}, {7, 6, 4, 3}};
    double s = 0.0;
    int ok = 1;
    for (int k = 0; k < 8; k++) {
        double e[3][3];
        for (int j = 0; j < 3; j++)
            for (int d = 0; d < 3; d++)
                e[j][d] = x[3 * corner[k][j + 1] + d] - x[3 * corner[k][0] + d];
        double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) +
                     e[0][1] * (e[1][2] * e[2][0] - e[1][0] * e[2][2]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        double frob2 = 0.0;
        for (int j = 0; j < 3; j++)
            frob2 += e[j][0] * e[j][0] + e[j][1] * e[j][1] + e[j][2] * e[j][2];
        double c = getme__cube_root(det);
        s += 3.0 * c * c / frob2;
        ok &= det > 0.0;
    }
    return ok && 0.125 * s > 0.0 ? 0.125 * s : 0.0;
}

/* The worst corner's scaled Jacobian of a hex, one corner at a time:
   det / sqrt(|e1|^2 |e2|^2 |e3|^2), -1 for a zero edge or a non-finite
   value, min'd with fmin from 1 in corner order. */
static double ref_corner_sj_hex(const double *x)
{
    static const int corner[8][4] = {{0, 3, 4, 1}, {1, 0, 5, 2}, {2, 1, 6, 3},
                                     {3, 2, 7, 0}, {4, 7, 5, 0}, {5, 4, 6, 1},
                                     {6, 5, 7, 2}, {7, 6, 4, 3}};
    double m = 1.0;
    for (int k = 0; k < 8; k++) {
        double e[3][3], len2[3];
        for (int j = 0; j < 3; j++) {
            for (int d = 0; d < 3; d++)
                e[j][d] = x[3 * corner[k][j + 1] + d] - x[3 * corner[k][0] + d];
            len2[j] = e[j][0] * e[j][0] + e[j][1] * e[j][1] + e[j][2] * e[j][2];
        }
        double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) +
                     e[0][1] * (e[1][2] * e[2][0] - e[1][0] * e[2][2]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        double l = len2[0] * len2[1] * len2[2];
        double s = det / sqrt(l);
        m = fmin(m, l > 0.0 && isfinite(s) ? s : -1.0);
    }
    return m;
}

/* Element l of a batch of type t: kind 0 the regular element, 1 moved a
   little, 2 moved a lot (often inverted), 3 two nodes on top of each
   other (degenerate); scaled and shifted far from the origin.  Kind 4 is
   the regular element at the origin, and kind 5 every node there, each
   zero coordinate +0 or -0 at random: the sums whose "0.0 +" the hex
   transformation's lanes leave out see -0 terms there.  Kind 6 is kind 1
   at the origin, unscaled: far from it the last bits of the scaling
   factor vanish in the shift back (a summation order that changed them
   went unseen on kinds 0-3). */
static void element(int t, int kind, double *x)
{
    int nv = getme__nv[t];
    const double *r = regular[t];
    if (kind == 4 || kind == 5) {
        for (int i = 0; i < 3 * nv; i++) {
            double v = kind == 4 ? r[i] : 0.0;
            x[i] = v == 0.0 && srand1() < 0.0 ? -0.0 : v;
        }
        return;
    }
    double s = 1e-3 * (1.0 + 0.5 * srand1()), o = 1e3 * srand1();
    if (kind == 6)
        s = 1.0, o = 0.0, kind = 1;
    for (int i = 0; i < 3 * nv; i++) {
        double d = kind == 1 ? 0.2 * srand1() : kind == 2 ? 1.5 * srand1() : 0.0;
        x[i] = o + s * (r[i] + d);
    }
    if (kind == 3)
        memcpy(x + 3, x, 3 * sizeof *x);
}

static void check_type(int t)
{
    int nv = getme__nv[t], ok_q = 1, ok_t = 1, ok_ref = 1;
    for (int batch = 0; batch < 2000; batch++) {
        double x[GETME_LANES][3 * GETME_MAX_NV], xl[3 * GETME_MAX_NV][GETME_LANES];
        double yl[3 * GETME_MAX_NV][GETME_LANES], ql[GETME_LANES];
        /* the hex transformation's two forms (transform_dual.c), whichever
           getme__transform_hex_lanes chose on this machine */
        double yn[3 * GETME_MAX_NV][GETME_LANES], yp[3 * GETME_MAX_NV][GETME_LANES];
        for (int l = 0; l < GETME_LANES; l++) {
            element(t, batch < 7 ? batch : (batch + l) % 7, x[l]);
            for (int i = 0; i < 3 * nv; i++)
                xl[i][l] = x[l][i];
        }
        /* a large sigma too: the normals' last bits then reach the output */
        double sigma = batch % 3 ? 0.3 : 4.0;
        CHECK(getme__quality_lanes(t, (const double(*)[GETME_LANES])xl, ql));
        if (t == GETME_TET)
            getme__transform_tet_lanes((const double(*)[GETME_LANES])xl, sigma, yl);
        else {
            getme__transform_hex_lanes((const double(*)[GETME_LANES])xl, sigma, yl);
            getme__transform_hex_lanes_nodes((const double(*)[GETME_LANES])xl, sigma, yn);
            getme__transform_hex_lanes_phases((const double(*)[GETME_LANES])xl, sigma, yp);
        }
        for (int l = 0; l < GETME_LANES; l++) {
            double y[3 * GETME_MAX_NV];
            ok_q &= same_bits(ql[l], getme__quality(t, x[l]));
            if (t == GETME_HEX)
                ok_ref &= same_bits(ql[l], ref_quality_hex(x[l])) &
                          same_bits(getme__corner_sj(t, x[l]), ref_corner_sj_hex(x[l]));
            getme__transform(t, x[l], sigma, y);
            for (int i = 0; i < 3 * nv; i++) {
                ok_t &= same_bits(yl[i][l], y[i]);
                if (t == GETME_HEX)
                    ok_t &= same_bits(yn[i][l], y[i]) & same_bits(yp[i][l], y[i]);
            }
        }
    }
    CHECK(ok_q);
    CHECK(ok_t);
    CHECK(ok_ref);
    if (t == GETME_HEX) { /* flat hex: every det is a zero, of either sign */
        double x[3 * GETME_MAX_NV];
        for (int i = 0; i < 3 * nv; i++)
            x[i] = i % 3 == 2 ? 0.0 : regular[t][i] - 0.5;
        CHECK(same_bits(getme__corner_sj(t, x), ref_corner_sj_hex(x)));
        CHECK(same_bits(getme__quality(t, x), ref_quality_hex(x)));
        CHECK(getme__quality(t, x) == 0.0);
    }
}

/* getme__qualities (the batch entry point): 2 full groups of lanes and 3
   more elements, against one getme__quality call each, for every type */
static void check_qualities(int t)
{
    int nv = getme__nv[t], ok = 1;
    double xs[19][3 * GETME_MAX_NV], flat[19 * 3 * GETME_MAX_NV], qs[19];
    for (int e = 0; e < 19; e++) {
        element(t, e % 4, xs[e]);
        memcpy(flat + 3 * nv * e, xs[e], sizeof(double) * 3 * (size_t)nv);
    }
    getme__qualities(t, 19, flat, qs);
    for (int e = 0; e < 19; e++)
        ok &= same_bits(qs[e], getme__quality(t, xs[e]));
    CHECK(ok);
}

/* getme__fx_q_sum against the scalar sum of getme__fx_q, on qualities in
   [-2, 2] (all signs, the bounds, zeros, subnormal and tiny values) and
   every length up to a few vectors (the vector loop's tails). */
static void check_fx_sum(void)
{
    enum { N = 4099 };
    static double v[N];
    for (int i = 0; i < N; i++) {
        double r = srand1();
        switch (i % 11) {
        case 0: v[i] = 2.0 * r; break;
        case 1: v[i] = r * 0x1p-40; break;
        case 2: v[i] = i % 2 ? 2.0 : -2.0; break;
        case 3: v[i] = i % 2 ? 0.0 : -0.0; break;
        case 4: v[i] = r * 0x1p-1060; break; /* subnormal */
        case 5: v[i] = 1.0 - 0x1p-53; break;
        default: v[i] = 0.5 + 0.5 * fabs(r);
        }
    }
    for (int n = 0; n <= N; n += n < 70 ? 1 : 397) {
        getme_ufx ref = 0;
        for (int i = 0; i < n; i++)
            ref += (getme_ufx)getme__fx_q(v[i]);
        getme_fx got = getme__fx_q_sum(v, n);
        CHECK((getme_ufx)got == ref);
    }
    for (int i = 0; i < N; i++) /* all of one sign, the largest terms */
        v[i] = -2.0;
    getme_ufx ref = 0;
    for (int i = 0; i < N; i++)
        ref += (getme_ufx)getme__fx_q(v[i]);
    CHECK((getme_ufx)getme__fx_q_sum(v, N) == ref);
}

/* getme__gather_lanes and _lanes16 (the trial pass's and the scatter's
   lane input; AVX2 transpose in the native build core_lanes_native, the
   plain loop in core_lanes) against the definition x[3 i + d][l] =
   X[3 c[l][i] + d], for node lists that repeat nodes and use the array's
   last node.  On Linux X ends where an inaccessible page begins, so an
   AVX2 load that read the fourth double of the last node (not masked
   off) would fault: intrinsic loads are not seen by ASan. */
static void check_gather(void)
{
    enum { N = 97 };
    size_t bytes = 3 * N * sizeof(double);
    double *X;
#if defined(__linux__)
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    size_t span = (bytes + page - 1) / page * page;
    unsigned char *map = mmap(NULL, span + page, PROT_READ | PROT_WRITE,
                              MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    CHECK(map != MAP_FAILED);
    if (map == MAP_FAILED)
        return;
    CHECK(mprotect(map + span, page, PROT_NONE) == 0);
    X = (double *)(map + span - bytes);
#else
    X = malloc(bytes);
    CHECK(X != NULL);
    if (!X)
        return;
#endif
    for (int k = 0; k < 3 * N; k++)
        X[k] = srand1() * 1e3 + k;
    for (int rep = 0; rep < 200; rep++) {
        int32_t c32[GETME_LANES][GETME_MAX_NV];
        uint16_t c16[GETME_LANES][GETME_MAX_NV];
        const int32_t *p32[GETME_LANES];
        const uint16_t *p16[GETME_LANES];
        int nv = 1 + rep % GETME_MAX_NV;
        for (int l = 0; l < GETME_LANES; l++) {
            for (int i = 0; i < nv; i++) {
                int32_t v = (int32_t)((srand1() + 1.0) * 0.5 * N);
                if (v >= N || (rep + l + i) % 7 == 0)
                    v = N - 1;
                c32[l][i] = v;
                c16[l][i] = (uint16_t)v;
            }
            p32[l] = c32[l];
            p16[l] = c16[l];
        }
        double a[3 * GETME_MAX_NV][GETME_LANES], b[3 * GETME_MAX_NV][GETME_LANES];
        getme__gather_lanes(X, p32, nv, a);
        getme__gather_lanes16(X, p16, nv, b);
        int ok = 1;
        for (int l = 0; l < GETME_LANES; l++)
            for (int i = 0; i < nv; i++)
                for (int d = 0; d < 3; d++) {
                    double want = X[3 * c32[l][i] + d];
                    ok &= same_bits(a[3 * i + d][l], want) &&
                          same_bits(b[3 * i + d][l], want);
                }
        CHECK(ok);
    }
#if defined(__linux__)
    munmap(map, span + page);
#else
    free(X);
#endif
}

int main(void)
{
    check_fx_sum();
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        check_qualities(t);
    check_type(GETME_TET);
    check_type(GETME_HEX);
    double xl[3 * GETME_MAX_NV][GETME_LANES] = {{0.0}}, q[GETME_LANES];
    CHECK(!getme__quality_lanes(GETME_PRISM, (const double(*)[GETME_LANES])xl, q));
    check_gather(); /* last: the checks above keep their random inputs */
    return check_summary("test_lanes");
}
