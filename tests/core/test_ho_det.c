/*
 * test_ho_det.c -- getme__ho_det_range, which sums only the nonzero shape
 * function derivatives (highorder_basis.c), gives the bits of the dense
 * sums over all of them, for every second-order type: on random
 * elements, on elements with small-integer and signed-zero coordinates
 * (sums that cancel to zero, where a -0 could appear), and with an
 * infinite or NaN coordinate (the dense path's NaN: -infinity out for the
 * volume types).  The
 * dense reference below is the function as it was before the sparse
 * table (session 35).  getme__ho_det_range_lanes (session 36) must give
 * the one-element function's bits in every lane.
 */
#define RANDOM_GEOMETRY_SEED 0x4f5e6d7c8b9aULL
#include "check.h"
#include "highorder.h"
#include "random_geometry.h"

#include <string.h>

static void dense(const getme_ho_info *info, const double *x, double *dmin,
                  double *dmax)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < info->nv; k++) {
        double j[3][3] = {{0}};
        for (int n = 0; n < info->nv; n++)
            for (int a = 0; a < 3; a++)
                for (int d = 0; d < 3; d++)
                    j[a][d] += x[3 * n + a] * info->dn[k][n][d];
        double det = info->dim == 2
                         ? j[0][0] * j[1][1] - j[0][1] * j[1][0]
                         : j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) -
                               j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) +
                               j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
        if (!(det == det))
            det = -INFINITY;
        lo = det < lo ? det : lo;
        hi = det > hi ? det : hi;
    }
    *dmin = lo;
    *dmax = hi;
}

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* x: 3 nv coordinates of one kind: 0 random, 1 small integers and signed
   zeros, 2 random with one infinite, 3 random with one NaN */
static void fill(int kind, int nv, double *x)
{
    for (int i = 0; i < 3 * nv; i++) {
        if (kind == 1) {
            int r = (int)(urand() * 5.0);
            x[i] = r == 0 ? 0.0 : r == 1 ? -0.0 : (double)(r - 3);
        } else {
            x[i] = srand1();
        }
    }
    if (kind >= 2)
        x[(int)(urand() * 3 * nv)] = kind == 2 ? -INFINITY : NAN;
}

int main(void)
{
    int zeros_seen = 0;
    for (int t = 0; t < GETME_NUM_HO_TYPES; t++) {
        getme_ho_info info;
        CHECK(getme__ho_info_init(t, &info) == 0);
        /* the table holds exactly dn's nonzero entries */
        int nz = 0;
        for (int k = 0; k < info.nv; k++)
            for (int n = 0; n < info.nv; n++)
                for (int d = 0; d < 3; d++)
                    nz += info.dn[k][n][d] != 0.0;
        CHECK(info.sp_ptr[3 * info.nv] == nz);
        CHECK(nz < info.nv * info.nv * 3); /* sparse at all */
        for (int kind = 0; kind < 4; kind++)
            for (int rep = 0; rep < 2000; rep++) {
                double x[3 * GETME_HO_MAX_NV], a0, a1, b0, b1;
                fill(kind, info.nv, x);
                getme__ho_det_range(&info, x, &a0, &a1);
                dense(&info, x, &b0, &b1);
                CHECK(same_bits(a0, b0) && same_bits(a1, b1));
                zeros_seen += kind == 1 && (b0 == 0.0 || b1 == 0.0);
                /* planar types: a z coordinate is not in their 2 x 2
                   determinants */
                if (kind >= 2 && info.dim == 3)
                    CHECK(a0 == -INFINITY);
            }
    }
    CHECK(zeros_seen > 0); /* the signed-zero case really ran */
    /* getme__ho_det_range_lanes: per lane the one-element function's
       bits; 0 when a lane is not finite */
    int lanes_checked = 0;
    for (int t = 0; t < GETME_NUM_HO_TYPES; t++) {
        getme_ho_info info;
        CHECK(getme__ho_info_init(t, &info) == 0);
        for (int kind = 0; kind < 4; kind++)
            for (int rep = 0; rep < 200; rep++) {
                enum { L = GETME_LANES };
                double xs[L][3 * GETME_HO_MAX_NV], x[3 * GETME_HO_MAX_NV][L];
                double lo[L], hi[L];
                for (int l = 0; l < L; l++) {
                    /* one lane of the kind, the others random */
                    fill(l == rep % L ? kind : rep % 3 ? 0 : 1, info.nv, xs[l]);
                    for (int i = 0; i < 3 * info.nv; i++)
                        x[i][l] = xs[l][i];
                }
                int r = getme__ho_det_range_lanes(
                    &info, (const double(*)[L])x, lo, hi);
                CHECK_EQ_INT(r, kind < 2);
                if (!r)
                    continue;
                for (int l = 0; l < L; l++) {
                    double a0, a1;
                    getme__ho_det_range(&info, xs[l], &a0, &a1);
                    CHECK(same_bits(lo[l], a0) && same_bits(hi[l], a1));
                    lanes_checked++;
                }
            }
    }
    CHECK(lanes_checked > 0);
    return check_summary("core_ho_det");
}
