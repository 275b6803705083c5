/*
 * transform_polygon.c -- the GETMe polygon transformation for planar
 * triangles and quads (GETMe book, Def. 5.1; docs/design.md §2).
 *
 * With lambda in (0,1), theta in (0, pi/2), c1 = (1 - lambda) tan theta,
 * c2 = lambda (1 - lambda) - c1^2, c3 = 1 - 2 c2 and R(v) = (v_y, -v_x)
 * (a quarter turn clockwise: for a counter-clockwise polygon it points out
 * of the element),
 *
 *     x_i' = c1 R(x_{i+1} - x_{i-1}) + c2 (x_{i-1} + x_{i+1}) + c3 x_i,
 *
 * then the polygon is scaled about its vertex centroid to keep its
 * perimeter.  The map is linear and commutes with rotations, so it acts on
 * the discrete Fourier modes x_k = z w^(jk), w = exp(2 pi i / n), of the
 * polygon by the real factors mu_j = c3 + 2 c2 cos(phi_j) + 2 c1 sin(phi_j),
 * phi_j = 2 pi j / n.  Mode 1 is the counter-clockwise regular polygon and
 * has the largest factor, so every other mode dies out relative to it: the
 * polygon becomes regular at the rate max_{j>1} |mu_j| / mu_1 per step
 * (docs/kernels.md: 0.072 for triangles, 0.27 for quads).  Only x and y
 * move; z is copied.
 */
#include "internal.h"
#include "transform_scale.h"

#include <math.h>

/* lambda = 1/2 and the authors' theta: pi/4 for triangles, pi/6 for quads */
#define POLY_LAMBDA 0.5
#define TAN_PI_4 1.0
#define TAN_PI_6 0.57735026918962576451

static inline void polygon_step(const double *x, int n, double tan_theta,
                                double *out)
{
    const double c1 = (1.0 - POLY_LAMBDA) * tan_theta;
    const double c2 = POLY_LAMBDA * (1.0 - POLY_LAMBDA) - c1 * c1;
    const double c3 = 1.0 - 2.0 * c2;
    for (int i = 0; i < n; i++) {
        const double *prev = x + 3 * ((i + n - 1) % n);
        const double *next = x + 3 * ((i + 1) % n);
        const double *p = x + 3 * i;
        double vx = next[0] - prev[0], vy = next[1] - prev[1];
        out[3 * i + 0] = c1 * vy + c2 * (prev[0] + next[0]) + c3 * p[0];
        out[3 * i + 1] = -c1 * vx + c2 * (prev[1] + next[1]) + c3 * p[1];
        out[3 * i + 2] = p[2];
    }
    getme__rescale_xy(out, x, n);
}

void getme__transform_tri(const double *x, double sigma, double *out)
{
    (void)sigma; /* the polygon transformation has its own fixed parameters */
    polygon_step(x, 3, TAN_PI_4, out);
}

void getme__transform_quad(const double *x, double sigma, double *out)
{
    (void)sigma;
    polygon_step(x, 4, TAN_PI_6, out);
}
