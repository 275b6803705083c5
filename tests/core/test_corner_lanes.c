/*
 * test_corner_lanes.c -- getme__corner_sj_hex_lanes (the initial corner
 * minimum's hexes, GETME_CORNER_LANES at once) gives, lane by lane, the
 * bits of getme__corner_sj for one hex: on random valid, inverted and
 * degenerate hexes (a collapsed edge, coordinates that overflow, a NaN)
 * and on the regular one.  The corner minimum the smoother reports and
 * its corner guard's floor come from these values, so the comparison is
 * of bits, not within a tolerance.
 *
 * Built from the core's sources (not libgetme): the function is private.
 */
#include "check.h"
#include "internal.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#define RANDOM_GEOMETRY_SEED 0x5eed0c0ffeeULL
#include "random_geometry.h"

static const double unit_hex[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                    0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};

/* A hex of kind k: 0 the unit cube moved by amp, 1 an edge collapsed,
   2 a node or the whole hex far out (products overflow, inf / inf), 3 a NaN coordinate, 4 a node
   pulled through the opposite face (inverted corners). */
static void make_hex(int kind, double amp, double *x)
{
    for (int i = 0; i < 24; i++)
        x[i] = unit_hex[i] + amp * srand1();
    int a = (int)((srand1() + 1.0) * 4.0) & 7;
    switch (kind) {
    case 1:
        memcpy(x + 3 * (a ^ 1), x + 3 * a, 3 * sizeof *x);
        break;
    case 2: /* one node, or the whole hex, far out */
        if (a & 1)
            x[3 * a] = 1e200;
        else
            for (int i = 0; i < 24; i++)
                x[i] *= 1.2e103; /* det inf, its lengths' product inf */
        break;
    case 3:
        x[3 * a + 1] = NAN;
        break;
    case 4:
        x[3 * a + 2] = a < 4 ? 2.5 : -1.5;
        break;
    default:
        break;
    }
}

static int same_bits(double a, double b)
{
    uint64_t u, v;
    memcpy(&u, &a, sizeof u);
    memcpy(&v, &b, sizeof v);
    return u == v;
}

int main(void)
{
    enum { L = GETME_CORNER_LANES };
    int differ = 0, negative = 0, collapsed = 0;
    for (int rep = 0; rep < 20000; rep++) {
        double one[L][24], x[24 * L], m[L];
        for (int l = 0; l < L; l++) {
            int kind = rep % 7 < 3 ? 0 : rep % 7 - 2; /* kinds 0-4 */
            make_hex(l == rep % L ? kind : 0, 0.05 + 0.45 * ((rep / 7) % 3), one[l]);
            for (int k = 0; k < 24; k++)
                x[k * L + l] = one[l][k];
        }
        getme__corner_sj_hex_lanes(x, m);
        for (int l = 0; l < L; l++) {
            double s = getme__corner_sj(GETME_HEX, one[l]);
            differ += !same_bits(s, m[l]);
            negative += s < 0.0 && s > -1.0;
            collapsed += s == -1.0;
        }
    }
    CHECK(differ == 0);
    /* the cases the comparison is meant to cover did occur */
    CHECK(negative > 100);
    CHECK(collapsed > 100);
    /* the regular hex's corners are 1 in every lane */
    double x[24 * L], m[L];
    for (int k = 0; k < 24; k++)
        for (int l = 0; l < L; l++)
            x[k * L + l] = unit_hex[k];
    getme__corner_sj_hex_lanes(x, m);
    for (int l = 0; l < L; l++)
        CHECK(m[l] == 1.0);
    return check_summary("test_corner_lanes");
}
