/*
 * test_untangle_kernel.c -- the untangling objective's analytic gradient and
 * Hessian (core/src/untangle.c, included here for its static functions)
 * against central differences, on random affine corners in 2-D and 3-D,
 * with a small and a large delta; and eta = 1 / mean ratio for a valid
 * corner with delta = 0.
 */
#include "check.h"

#include "untangle.c"

static double rnd(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return ((*seed >> 8) % 2000) / 1000.0 - 1.0;
}

int main(void)
{
    unsigned seed = 12345;
    double worst_g = 0.0, worst_h = 0.0;
    int tried = 0;
    for (int d = 2; d <= 3; d++)
        for (int trial = 0; trial < 200; trial++) {
            corner_lin cl[5];
            for (int q = 0; q < 5; q++)
                for (int a = 0; a < 3; a++) {
                    for (int b = 0; b < 3; b++)
                        cl[q].s0[a][b] = a < d && b < d ? rnd(&seed) : 0.0;
                    cl[q].r[a] = a < d ? rnd(&seed) : 0.0;
                }
            node_ctx c = {cl, 5, d, trial % 2 ? 0.3 : 0.01};
            double p[3] = {0.1, -0.2, d == 3 ? 0.3 : 0.0}, g[3], H[3][3];
            double f = node_objective(&c, p, g, H);
            if (!isfinite(f))
                continue;
            tried++;
            const double e = 1e-5;
            for (int m = 0; m < d; m++) {
                double pp[3] = {p[0], p[1], p[2]}, pm[3] = {p[0], p[1], p[2]};
                double gp[3], gm[3];
                pp[m] += e;
                pm[m] -= e;
                double fd = (node_objective(&c, pp, gp, NULL) -
                             node_objective(&c, pm, gm, NULL)) / (2.0 * e);
                double scale = 1e-3 * fabs(f) + 1e-12;
                double rg = fabs(fd - g[m]) / (fabs(g[m]) + scale);
                worst_g = rg > worst_g ? rg : worst_g;
                for (int n = 0; n < d; n++) {
                    double hd = (gp[n] - gm[n]) / (2.0 * e);
                    double rh = fabs(hd - H[n][m]) / (fabs(H[n][m]) + scale);
                    worst_h = rh > worst_h ? rh : worst_h;
                }
            }
        }
    printf("%d corner sets: worst relative error gradient %.2g, Hessian %.2g\n",
           tried, worst_g, worst_h);
    CHECK(tried > 300);
    CHECK(worst_g < 1e-6);
    CHECK(worst_h < 1e-5);

    /* delta = 0, a valid regular tet corner and a sheared one: eta is the
       inverse of the corner's mean ratio (1 for the regular corner) */
    corner_lin t = {{{0}}, {0}};
    for (int a = 0; a < 3; a++)
        t.s0[a][a] = 1.0; /* S = I: regular */
    node_ctx c1 = {&t, 1, 3, 0.0};
    double origin[3] = {0.0, 0.0, 0.0};
    CHECK_NEAR(node_objective(&c1, origin, NULL, NULL), 1.0, 1e-15);
    t.s0[1][0] = 0.5; /* shear: det 1, |S|^2 = 3.25 */
    CHECK_NEAR(node_objective(&c1, origin, NULL, NULL), 3.25 / 3.0, 1e-15);
    /* inverted with delta = 0: +inf; with delta > 0: finite */
    t.s0[2][2] = -1.0;
    CHECK(isinf(node_objective(&c1, origin, NULL, NULL)));
    c1.delta2 = 1e-4;
    CHECK(isfinite(node_objective(&c1, origin, NULL, NULL)));
    return check_summary("test_untangle_kernel");
}
