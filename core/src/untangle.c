/*
 * untangle.c -- getme_mesh_untangle(): make an input with inverted or
 * degenerate elements valid by moving free nodes, so that smoothing can
 * start.  Method and choices: docs/untangle.md.
 *
 * Objective (Escobar, Rodriguez, Montenegro, Montero, Gonzalez-Yuste,
 * "Simultaneous untangling and smoothing of tetrahedral meshes", CMAME 192,
 * 2003): for every node simplex ("corner") of an element, S = D W^-1 as in
 * quality.c, sigma = det S, and the modified mean-ratio distortion
 *
 *     eta = |S|_F^2 / (d h(sigma)^(2/d)),  h(sigma) = (sigma + sqrt(sigma^2
 *                                                     + 4 delta^2)) / 2
 *
 * (d = 3, or 2 for planar corners).  h > 0 for every sigma, so eta is finite
 * and smooth across sigma = 0 and an inverted corner pulls its nodes back;
 * with delta = 0 and sigma > 0 it is the inverse of the corner's mean ratio.
 * A node's objective is the sum of eta over the corners of its star that
 * contain it; delta is chosen per node visit from the smallest sigma there
 * (delta^2 = eps (eps - sigma_min) while sigma_min < eps, else 0, with eps
 * scaled to the local size), so it shrinks as the mesh untangles.
 *
 * Minimisation: a few Newton steps per node (analytic gradient and
 * Hessian, Levenberg shift when it is not positive definite, Armijo
 * backtracking), node after node; nodes whose neighbourhood did not move
 * since their last visit are skipped.  The moving
 * nodes are coloured so that no two nodes of one colour share an element;
 * the nodes of a colour are optimised in parallel (each writes only its own
 * coordinates and reads only nodes of other colours), colour after colour.
 * So a sweep is a Gauss-Seidel sweep in a fixed order and the result is
 * bit-identical for any thread count, without atomics.
 *
 * Which nodes move: the free nodes of the invalid elements; if some remain
 * invalid after a round of sweeps, one more ring of free nodes around them
 * (up to MAX_RINGS).  Everything else keeps its coordinates bit for bit.
 */
#include "smooth_internal.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Sweeps per ring before the moving set grows by one ring of nodes. */
#define SWEEPS_PER_RING 25
/* Rings of free nodes that may be added around the invalid elements. */
#define MAX_RINGS 3
/* Newton steps per node visit; a visit ends early after a step shorter
   than STEP_TOL local sizes. */
#define NEWTON_STEPS 3
#define STEP_TOL 1e-4
/* A node that moves less than STEP_QUIET local sizes in a visit does not
   make its neighbours be visited again in the next sweep: nodes whose
   neighbourhood did not change are skipped (their optimum did not move). */
#define STEP_QUIET 1e-3
/* eps = EPS_REL * (local size)^d: delta stays positive while a corner of
   the node's star has sigma below it. */
#define EPS_REL 1e-3
/* An element counts as untangled when every corner has mean ratio
   q_k > QK_MARGIN (a margin against round-off, far below any useful
   quality); elements that are valid but thinner keep being optimised
   until the sweeps run out, and are then accepted. */
#define QK_MARGIN 1e-4
/* Loops over fewer nodes or elements than this run on one thread. */
#define PAR_MIN 256

#define INV_SQRT2 0.70710678118654752440
#define INV_SQRT3 0.57735026918962576451
#define INV_SQRT6 0.40824829046386301637

/* The node simplices of each type, as in quality.c: corner node first,
   then the nodes of the spanning edges, and W^-1 (S = D W^-1, upper
   triangular; 2x2 for the planar types). */
typedef struct corner_table {
    int num;
    int8_t node[8][4];
    double winv[3][3];
} corner_table;

static const corner_table CORNERS[GETME_NUM_TYPES] = {
    /* tet */
    {1, {{0, 1, 2, 3}},
     {{1.0, -INV_SQRT3, -INV_SQRT6}, {0.0, 2.0 * INV_SQRT3, -INV_SQRT6},
      {0.0, 0.0, 3.0 * INV_SQRT6}}},
    /* hex: the paper's N^hex, W = I */
    {8, {{0, 3, 4, 1}, {1, 0, 5, 2}, {2, 1, 6, 3}, {3, 2, 7, 0},
         {4, 7, 5, 0}, {5, 4, 6, 1}, {6, 5, 7, 2}, {7, 6, 4, 3}},
     {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}},
    /* prism */
    {6, {{0, 1, 2, 3}, {1, 2, 0, 4}, {2, 0, 1, 5}, {3, 5, 4, 0},
         {4, 3, 5, 1}, {5, 4, 3, 2}},
     {{1.0, -INV_SQRT3, 0.0}, {0.0, 2.0 * INV_SQRT3, 0.0}, {0.0, 0.0, 1.0}}},
    /* pyramid: the four base corners */
    {4, {{0, 1, 3, 4}, {1, 2, 0, 4}, {2, 3, 1, 4}, {3, 0, 2, 4}},
     {{1.0, 0.0, -INV_SQRT2}, {0.0, 1.0, -INV_SQRT2},
      {0.0, 0.0, 2.0 * INV_SQRT2}}},
    /* tri */
    {1, {{0, 1, 2}}, {{1.0, -INV_SQRT3, 0.0}, {0.0, 2.0 * INV_SQRT3, 0.0}}},
    /* quad: corner k with its next and previous node, W = I */
    {4, {{0, 1, 3}, {1, 2, 0}, {2, 3, 1}, {3, 0, 2}},
     {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}}},
};

/* S (columns s[n]) of corner k of an element with coordinates x. */
static inline void corner_s(const double *x, const corner_table *ct, int k,
                            int d, double s[3][3])
{
    const int8_t *c = ct->node[k];
    double e[3][3];
    for (int m = 0; m < d; m++)
        for (int i = 0; i < d; i++)
            e[m][i] = x[3 * c[m + 1] + i] - x[3 * c[0] + i];
    for (int n = 0; n < d; n++)
        for (int i = 0; i < d; i++) {
            double v = 0.0;
            for (int m = 0; m <= n; m++)
                v += e[m][i] * ct->winv[m][n];
            s[n][i] = v;
        }
}

static inline void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* det S and |S|^2; cof (may be NULL) gets d det / d S (columns). */
static inline double corner_det(double s[3][3], int d, double *frob2,
                                double cof[3][3])
{
    double det, f = 0.0;
    for (int n = 0; n < d; n++)
        for (int i = 0; i < d; i++)
            f += s[n][i] * s[n][i];
    *frob2 = f;
    if (d == 3) {
        double c0[3];
        cross(s[1], s[2], c0);
        det = s[0][0] * c0[0] + s[0][1] * c0[1] + s[0][2] * c0[2];
        if (cof) {
            memcpy(cof[0], c0, sizeof c0);
            cross(s[2], s[0], cof[1]);
            cross(s[0], s[1], cof[2]);
        }
    } else {
        det = s[0][0] * s[1][1] - s[0][1] * s[1][0];
        if (cof) {
            cof[0][0] = s[1][1], cof[0][1] = -s[1][0];
            cof[1][0] = -s[0][1], cof[1][1] = s[0][0];
        }
    }
    return det;
}

/* Mean ratio of one corner from det and |S|^2 (any sign of det: <= 0 for
   an invalid one). */
static inline double corner_q(double det, double frob2, int d)
{
    if (!(det > 0.0))
        return 0.0;
    return d == 3 ? 3.0 * cbrt(det) * cbrt(det) / frob2 : 2.0 * det / frob2;
}

/* 1 if every corner of element e has q_k > QK_MARGIN at coordinates x. */
static int element_untangled(const getme_ws *ws, const double *coords,
                             int32_t e)
{
    double x[3 * GETME_MAX_NV];
    int t = getme__ws_type(ws, e);
    const corner_table *ct = &CORNERS[t];
    getme__ws_gather(ws, coords, t, e, x);
    for (int k = 0; k < ct->num; k++) {
        double s[3][3] = {{0}}, f;
        corner_s(x, ct, k, ws->dim, s);
        double det = corner_det(s, ws->dim, &f, NULL);
        if (!(corner_q(det, f, ws->dim) > QK_MARGIN))
            return 0;
    }
    return 1;
}

/* ---- one node's objective ----------------------------------------------- */

/* A corner containing the node being optimised, affine in its position p:
   S(p) = s0 + p r^T (r: the row of W^-1 that multiplies the node, or minus
   their sum for the corner's own node). */
typedef struct corner_lin {
    double s0[3][3]; /* columns of S with the node at the origin */
    double r[3];
} corner_lin;

/* Most corners a node can be in: every element of its star has at most 8. */
#define CORNERS_PER_ELEMENT 8

/* The corners of node i's star that contain it, into out; returns their
   number. */
static int node_corners(const getme_ws *ws, const double *coords, int32_t i,
                        corner_lin *out)
{
    const int d = ws->dim;
    int n = 0;
    for (int64_t k = ws->star_ptr[i]; k < ws->star_ptr[i + 1]; k++) {
        int32_t e = ws->star[k];
        int t = getme__ws_type(ws, e);
        double x[3 * GETME_MAX_NV];
        getme__ws_gather(ws, coords, t, e, x);
        int li = getme__local_index(getme__ws_nodes(ws, t, e), getme__nv[t], i);
        x[3 * li] = x[3 * li + 1] = x[3 * li + 2] = 0.0;
        const corner_table *ct = &CORNERS[t];
        for (int q = 0; q < ct->num; q++) {
            int j = -1;
            for (int m = 0; m <= d; m++)
                if (ct->node[q][m] == li)
                    j = m;
            if (j < 0)
                continue;
            corner_lin *c = &out[n++];
            memset(c, 0, sizeof *c);
            corner_s(x, ct, q, d, c->s0);
            for (int col = 0; col < d; col++) {
                if (j > 0)
                    c->r[col] = ct->winv[j - 1][col];
                else
                    for (int m = 0; m < d; m++)
                        c->r[col] -= ct->winv[m][col];
            }
        }
    }
    return n;
}

typedef struct node_ctx {
    const corner_lin *corners;
    int num, d;
    double delta2;
} node_ctx;

static inline void corner_at(const corner_lin *c, const double *p, int d,
                             double s[3][3])
{
    for (int n = 0; n < d; n++)
        for (int m = 0; m < d; m++)
            s[n][m] = c->s0[n][m] + p[m] * c->r[n];
}

/*
 * Sum of eta over the node's corners with the node placed at p; its
 * gradient into g and Hessian into H (each may be NULL).  +inf where h = 0
 * (delta = 0 and a corner with sigma <= 0).
 *
 * With S = S0 + p r^T: F = |S|^2 is quadratic in p (grad 2 u, u = sum_n
 * r_n s_n; Hessian 2 |r|^2 I) and sigma = det S is affine in p (matrix
 * determinant lemma; grad v = sum_n r_n cof_n).  With phi = h^(-2/d) / d,
 * eta = F phi(sigma), phi' = -(2/d) phi / r, phi'' = -(2/d) (phi' - phi
 * sigma / r^2) / r (r = sqrt(sigma^2 + 4 delta^2), h' = h / r):
 *   grad eta = 2 phi u + F phi' v,
 *   Hess eta = 2 |r|^2 phi I + 2 phi' (u v^T + v u^T) + F phi'' v v^T.
 */
static double node_objective(const node_ctx *c, const double *p, double *g,
                             double H[3][3])
{
    const int d = c->d;
    double sum = 0.0;
    if (g)
        g[0] = g[1] = g[2] = 0.0;
    if (H)
        memset(H, 0, 9 * sizeof **H);
    for (int q = 0; q < c->num; q++) {
        double s[3][3] = {{0}}, cof[3][3], f;
        corner_at(&c->corners[q], p, d, s);
        double sigma = corner_det(s, d, &f, g || H ? cof : NULL);
        double r = sqrt(sigma * sigma + 4.0 * c->delta2);
        /* (sigma + r) / 2 without cancellation for sigma < 0 */
        double h = sigma >= 0.0 ? 0.5 * (sigma + r)
                                : 2.0 * c->delta2 / (r - sigma);
        if (!(h > 0.0))
            return INFINITY;
        double hc = d == 3 ? cbrt(h) : 1.0;
        double phi = 1.0 / ((double)d * (d == 3 ? hc * hc : h));
        sum += f * phi;
        if (!g && !H)
            continue;
        const double *row = c->corners[q].r;
        double u[3] = {0.0, 0.0, 0.0}, v[3] = {0.0, 0.0, 0.0}, r2 = 0.0;
        for (int n = 0; n < d; n++) {
            r2 += row[n] * row[n];
            for (int m = 0; m < d; m++) {
                u[m] += row[n] * s[n][m];
                v[m] += row[n] * cof[n][m];
            }
        }
        double phi1 = -2.0 / (double)d * phi / r;
        if (g)
            for (int m = 0; m < d; m++)
                g[m] += 2.0 * phi * u[m] + f * phi1 * v[m];
        if (!H)
            continue;
        double phi2 = -2.0 / (double)d * (phi1 - phi * sigma / (r * r)) / r;
        for (int m = 0; m < d; m++)
            for (int n = 0; n < d; n++)
                H[m][n] += (m == n ? 2.0 * r2 * phi : 0.0) +
                           2.0 * phi1 * (u[m] * v[n] + v[m] * u[n]) +
                           f * phi2 * v[m] * v[n];
    }
    return sum;
}

/* Solve (H + mu I) y = -g by Cholesky (n = 2 or 3); 0 if not positive
   definite. */
static int solve_shifted(double H[3][3], double mu, const double *g,
                         int n, double *y)
{
    double L[3][3] = {{0}};
    for (int i = 0; i < n; i++)
        for (int j = 0; j <= i; j++) {
            double v = H[i][j] + (i == j ? mu : 0.0);
            for (int k = 0; k < j; k++)
                v -= L[i][k] * L[j][k];
            if (i == j) {
                if (!(v > 0.0))
                    return 0;
                L[i][i] = sqrt(v);
            } else {
                L[i][j] = v / L[j][j];
            }
        }
    double z[3];
    for (int i = 0; i < n; i++) {
        double v = -g[i];
        for (int k = 0; k < i; k++)
            v -= L[i][k] * z[k];
        z[i] = v / L[i][i];
    }
    for (int i = n - 1; i >= 0; i--) {
        double v = z[i];
        for (int k = i + 1; k < n; k++)
            v -= L[k][i] * y[k];
        y[i] = v / L[i][i];
    }
    y[2] = n == 2 ? 0.0 : y[2];
    return 1;
}

/* Smallest sigma and mean |S|^2 / d over the node's corners at p. */
static void node_scales(const node_ctx *c, const double *p, double *sigma_min,
                        double *size2)
{
    double smin = INFINITY, fsum = 0.0;
    for (int q = 0; q < c->num; q++) {
        double s[3][3] = {{0}}, f;
        corner_at(&c->corners[q], p, c->d, s);
        double det = corner_det(s, c->d, &f, NULL);
        smin = det < smin ? det : smin;
        fsum += f;
    }
    *sigma_min = smin;
    *size2 = c->num ? fsum / ((double)c->d * c->num) : 0.0;
}

/* Optimise node i (writes coords[3 i ..] only).  Returns 0 if it did not
   move, 1 if it moved by less than STEP_QUIET local sizes, else 2. */
static int optimise_node(const getme_ws *ws, double *coords, int32_t i,
                         corner_lin *scratch)
{
    const int d = ws->dim;
    node_ctx c = {scratch, node_corners(ws, coords, i, scratch), d, 0.0};
    double p[3], g[3], smin, size2;
    memcpy(p, coords + 3 * (int64_t)i, sizeof p);
    node_scales(&c, p, &smin, &size2);
    if (!(size2 > 0.0) || !isfinite(size2))
        return 0;
    double len = sqrt(size2);
    double eps = EPS_REL * (d == 3 ? size2 * len : size2);
    c.delta2 = smin < eps ? eps * (eps - smin) : 0.0;
    double H[3][3];
    double f = node_objective(&c, p, g, H);
    if (!isfinite(f))
        return 0;
    int moved = 0;
    for (int step = 0; step < NEWTON_STEPS; step++) {
        double gn = 0.0;
        for (int m = 0; m < d; m++)
            gn += g[m] * g[m];
        if (!(gn > 0.0) || !isfinite(gn))
            break;
        int ok = 1;
        for (int m = 0; m < d; m++)
            for (int n = 0; n < d; n++)
                ok &= isfinite(H[m][n]);
        double dir[3] = {0.0, 0.0, 0.0};
        int have = 0;
        if (ok) {
            double tr = 0.0;
            for (int m = 0; m < d; m++)
                tr += fabs(H[m][m]);
            double mu = 0.0;
            for (int tries = 0; tries < 12 && !have; tries++) {
                have = solve_shifted(H, mu, g, d, dir);
                mu = mu == 0.0 ? 1e-6 * tr / d : 10.0 * mu;
            }
        }
        if (!have) { /* steepest descent, one local length long */
            double s = len / sqrt(gn);
            for (int m = 0; m < d; m++)
                dir[m] = -s * g[m];
        }
        /* no step longer than the local size */
        double dn = 0.0, slope = 0.0;
        for (int m = 0; m < d; m++) {
            dn += dir[m] * dir[m];
            slope += dir[m] * g[m];
        }
        if (dn > size2) {
            double s = len / sqrt(dn);
            for (int m = 0; m < d; m++)
                dir[m] *= s;
            slope *= s;
        }
        if (!(slope < 0.0))
            break;
        double alpha = 2.0, pt[3], ft = f;
        int accepted = 0;
        for (int ls = 0; ls < 30 && !accepted; ls++) {
            alpha *= 0.5;
            for (int m = 0; m < 3; m++)
                pt[m] = m < d ? p[m] + alpha * dir[m] : p[m];
            ft = node_objective(&c, pt, NULL, NULL);
            accepted = ft <= f + 1e-4 * alpha * slope;
        }
        if (!accepted)
            break;
        memcpy(p, pt, sizeof p);
        f = node_objective(&c, p, g, H);
        moved = 1;
        if (alpha * alpha * dn < STEP_TOL * STEP_TOL * size2)
            break;
    }
    if (!moved)
        return 0;
    double *x = coords + 3 * (int64_t)i, dist2 = 0.0;
    for (int m = 0; m < d; m++)
        dist2 += (p[m] - x[m]) * (p[m] - x[m]);
    memcpy(x, p, sizeof p);
    return dist2 < STEP_QUIET * STEP_QUIET * size2 ? 1 : 2;
}

/* ---- the driver --------------------------------------------------------- */

typedef struct ut_state {
    getme_ws *ws;
    double *q;          /* ne qualities at ws->x, kept up to date          */
    uint8_t *nflag;     /* nn: bit 1 moving, bit 2 has moved, bit 4 moved
                           more than STEP_QUIET in the previous sweep (or
                           is new), bit 8 in this sweep, bit 16 node of a
                           pending element, bit 32 within one element of
                           one (hot), bit 64 skipped as not hot although
                           its neighbourhood changed (stale)               */
    uint8_t *eflag;     /* ne: bit 1 in the region (touches a moving node),
                           bit 2 pending (not yet untangled)               */
    int32_t *nodes;     /* moving nodes, by colour, ascending inside one   */
    int32_t *colour_ptr;/* num_colours + 1                                 */
    int32_t num_nodes, num_colours;
    int32_t *colour;    /* nn: colour of a moving node (scratch)           */
    int32_t *elems;     /* region elements, ascending                      */
    int32_t num_elems;
    int32_t *stamp;     /* colour marks, max colours entries               */
    int32_t max_colours;
    corner_lin *scratch;/* per thread: the corners of the node in hand    */
    int64_t scratch_per_thread;
} ut_state;

/* Colour the moving nodes greedily in ascending order (serial, so the
   colours do not depend on the thread count) and list them by colour. */
static getme_status colour_nodes(ut_state *u)
{
    const getme_ws *ws = u->ws;
    int32_t n = 0, nc = 0;
    for (int32_t i = 0; i < ws->nn; i++) {
        if (!(u->nflag[i] & 1))
            continue;
        /* mark the colours of the moving nodes sharing an element */
        for (int64_t k = ws->star_ptr[i]; k < ws->star_ptr[i + 1]; k++) {
            int32_t e = ws->star[k];
            int t = getme__ws_type(ws, e);
            const int32_t *c = getme__ws_nodes(ws, t, e);
            for (int v = 0; v < getme__nv[t]; v++)
                if (c[v] < i && (u->nflag[c[v]] & 1))
                    u->stamp[u->colour[c[v]]] = i + 1;
        }
        int32_t col = 0;
        while (u->stamp[col] == i + 1)
            col++;
        u->colour[i] = col;
        nc = col + 1 > nc ? col + 1 : nc;
        n++;
    }
    free(u->colour_ptr);
    u->colour_ptr = getme__calloc((size_t)nc + 2, sizeof *u->colour_ptr);
    if (!u->colour_ptr)
        return GETME_ERR_NOMEM;
    for (int32_t i = 0; i < ws->nn; i++)
        if (u->nflag[i] & 1)
            u->colour_ptr[u->colour[i] + 1]++;
    for (int32_t c = 0; c < nc; c++)
        u->colour_ptr[c + 1] += u->colour_ptr[c];
    for (int32_t i = 0; i < ws->nn; i++)
        if (u->nflag[i] & 1)
            u->nodes[u->colour_ptr[u->colour[i]]++] = i;
    for (int32_t c = nc; c > 0; c--) /* shift back to start offsets */
        u->colour_ptr[c] = u->colour_ptr[c - 1];
    u->colour_ptr[0] = 0;
    u->num_nodes = n;
    u->num_colours = nc;
    return GETME_OK;
}

/* Region = elements touching a moving node, ascending. */
static void collect_region(ut_state *u)
{
    const getme_ws *ws = u->ws;
    for (int32_t k = 0; k < u->num_nodes; k++) {
        int32_t i = u->nodes[k];
        for (int64_t s = ws->star_ptr[i]; s < ws->star_ptr[i + 1]; s++)
            u->eflag[ws->star[s]] |= 1 | 2;
    }
    u->num_elems = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (u->eflag[e] & 1)
            u->elems[u->num_elems++] = e;
}

/* Add the free nodes of every element that shares a node with an element
   that is still invalid (one more ring); returns how many were added. */
static int32_t grow_ring(ut_state *u)
{
    const getme_ws *ws = u->ws;
    int32_t added = 0;
    for (int32_t k = 0; k < u->num_elems; k++) {
        int32_t e = u->elems[k];
        if (u->q[e] > 0.0 || !ws->free_elem[e])
            continue;
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int v = 0; v < getme__nv[t]; v++)
            for (int64_t s = ws->star_ptr[c[v]]; s < ws->star_ptr[c[v] + 1];
                 s++) {
                int32_t f = ws->star[s];
                int tf = getme__ws_type(ws, f);
                const int32_t *cf = getme__ws_nodes(ws, tf, f);
                for (int w = 0; w < getme__nv[tf]; w++)
                    if (!ws->fixed[cf[w]] && !(u->nflag[cf[w]] & 1)) {
                        u->nflag[cf[w]] |= 1 | 8;
                        added++;
                    }
            }
    }
    return added;
}

/* 1 if a node sharing an element with node i (or i itself) moved by more
   than STEP_QUIET in the previous sweep or, for the colours already done,
   in this one.  Same-colour nodes share no element, so the flags read were
   written by finished colour phases only: no race, any thread count. */
static int neighbourhood_changed(const ut_state *u, int32_t i)
{
    const getme_ws *ws = u->ws;
    for (int64_t k = ws->star_ptr[i]; k < ws->star_ptr[i + 1]; k++) {
        int32_t e = ws->star[k];
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int v = 0; v < getme__nv[t]; v++)
            if (u->nflag[c[v]] & 12)
                return 1;
    }
    return 0;
}

/* Mark the hot nodes (bit 32): those sharing an element with a node of a
   pending element.  Only hot nodes are visited, so that the last few
   tangles do not cost sweeps over the whole region.  Serial: the marks are
   the same for any thread count. */
static void mark_hot(ut_state *u)
{
    const getme_ws *ws = u->ws;
    for (int pass = 0; pass < 3; pass++)
        for (int32_t k = 0; k < u->num_elems; k++) {
            int32_t e = u->elems[k];
            int t = getme__ws_type(ws, e);
            const int32_t *c = getme__ws_nodes(ws, t, e);
            int nv = getme__nv[t], near = 0;
            if (pass == 2)
                for (int v = 0; v < nv; v++)
                    near |= u->nflag[c[v]] & 16;
            for (int v = 0; v < nv; v++) {
                uint8_t *f = &u->nflag[c[v]];
                if (pass == 0)
                    *f &= (uint8_t)~(16 | 32);
                else if (pass == 1 && (u->eflag[e] & 2))
                    *f |= 16;
                else if (pass == 2 && near)
                    *f |= 32;
            }
        }
}

/* One Gauss-Seidel sweep in colour order; then the region's qualities.
   Returns the number of region elements not yet untangled (with a free
   node) into *pending and the invalid ones into *invalid.  Returns the
   number of nodes visited (0: nothing changed since the last sweep). */
static int32_t sweep(ut_state *u, int32_t *pending, int32_t *invalid)
{
    int32_t visited = 0;
    getme_ws *ws = u->ws;
    const int nt = ws->nt;
    for (int32_t k = 0; k < u->num_nodes; k++) {
        uint8_t *f = &u->nflag[u->nodes[k]];
        *f = (uint8_t)((*f & ~12) | ((*f & 8) ? 4 : 0));
    }
    mark_hot(u);
    for (int32_t c = 0; c < u->num_colours; c++) {
        int32_t a = u->colour_ptr[c], b = u->colour_ptr[c + 1];
#pragma omp parallel for schedule(static) num_threads(nt) \
    reduction(+ : visited) if (b - a > PAR_MIN)
        for (int32_t k = a; k < b; k++) {
            int32_t i = u->nodes[k];
            uint8_t *f = &u->nflag[i];
            if (!(*f & 64) && !neighbourhood_changed(u, i))
                continue;
            if (!(*f & 32)) { /* not hot: remember to come back */
                *f |= 64;
                continue;
            }
            *f &= (uint8_t)~64;
            visited++;
            int r = optimise_node(ws, ws->x, i,
                                  u->scratch + (int64_t)omp_get_thread_num() *
                                                   u->scratch_per_thread);
            if (r)
                u->nflag[i] |= (uint8_t)(r == 2 ? 2 | 8 : 2);
        }
    }
    int32_t pend = 0, bad = 0;
    const int32_t ne = u->num_elems;
#pragma omp parallel for schedule(static) num_threads(nt) \
    reduction(+ : pend, bad) if (ne > PAR_MIN)
    for (int32_t k = 0; k < ne; k++) {
        int32_t e = u->elems[k];
        u->q[e] = getme__ws_quality(ws, ws->x, e);
        int valid = u->q[e] > 0.0;
        int p = ws->free_elem[e] &&
                (!valid || !element_untangled(ws, ws->x, e));
        bad += !valid;
        pend += p;
        u->eflag[e] = (uint8_t)((u->eflag[e] & ~2) | (p ? 2 : 0));
    }
    *pending = pend;
    *invalid = bad;
    return visited;
}

getme_status getme__untangle(getme_ws *ws, double *q,
                             getme_untangle_result *res)
{
    double t0 = omp_get_wtime();
    memset(res, 0, sizeof *res);
    int64_t bad = 0;
    for (int32_t e = 0; e < ws->ne; e++)
        bad += !(q[e] > 0.0);
    res->num_invalid_before = res->num_invalid_after = bad;
    if (bad == 0)
        return GETME_OK;
    ut_state u;
    memset(&u, 0, sizeof u);
    u.ws = ws;
    u.q = q;
    size_t nn = (size_t)(ws->nn ? ws->nn : 1), ne = (size_t)(ws->ne ? ws->ne : 1);
    u.max_colours = 8 * ws->max_star + 2;
    u.nflag = getme__calloc(nn, 1);
    u.eflag = getme__calloc(ne, 1);
    u.nodes = getme__malloc(nn * sizeof *u.nodes);
    u.colour = getme__malloc(nn * sizeof *u.colour);
    u.elems = getme__malloc(ne * sizeof *u.elems);
    u.stamp = getme__calloc((size_t)u.max_colours, sizeof *u.stamp);
    u.scratch_per_thread = (int64_t)CORNERS_PER_ELEMENT * ws->max_star;
    u.scratch = getme__malloc((size_t)(ws->nt * u.scratch_per_thread) *
                              sizeof *u.scratch);
    getme_status st = GETME_ERR_NOMEM;
    if (!u.nflag || !u.eflag || !u.nodes || !u.colour || !u.elems || !u.stamp ||
        !u.scratch)
        goto out;
    /* ring 0: the free nodes of the invalid elements */
    for (int32_t e = 0; e < ws->ne; e++) {
        if (q[e] > 0.0)
            continue;
        int t = getme__ws_type(ws, e);
        const int32_t *c = getme__ws_nodes(ws, t, e);
        for (int v = 0; v < getme__nv[t]; v++)
            if (!ws->fixed[c[v]])
                u.nflag[c[v]] |= 1 | 8;
    }
    for (int ring = 0; ring <= MAX_RINGS; ring++) {
        if ((st = colour_nodes(&u)) != GETME_OK)
            goto out;
        if (u.num_nodes == 0)
            break;
        collect_region(&u);
        res->rings = ring;
        int32_t pending = 1, invalid = 1;
        int32_t visited = 1;
        for (int s = 0; s < SWEEPS_PER_RING && pending > 0 && visited > 0;
             s++) {
            visited = sweep(&u, &pending, &invalid);
            res->sweeps++;
        }
        if (invalid == 0 || ring == MAX_RINGS || grow_ring(&u) == 0)
            break;
    }
    st = GETME_OK;
out:
    res->num_invalid_after = 0;
    res->num_stuck = 0;
    for (int32_t e = 0; e < ws->ne; e++) {
        if (q[e] > 0.0)
            continue;
        res->num_invalid_after++;
        res->num_stuck += !ws->free_elem[e];
        /* keep the smallest caller indices, ascending */
        int32_t o = ws->elem_orig[e];
        int32_t n = res->num_reported;
        if (n == GETME_MAX_REPORTED_INVALID &&
            o > res->remaining[GETME_MAX_REPORTED_INVALID - 1])
            continue;
        if (n < GETME_MAX_REPORTED_INVALID)
            res->num_reported = ++n;
        int32_t j = n - 1;
        while (j > 0 && res->remaining[j - 1] > o) {
            res->remaining[j] = res->remaining[j - 1];
            j--;
        }
        res->remaining[j] = o;
    }
    if (u.nflag)
        for (int32_t i = 0; i < ws->nn; i++)
            res->num_moved += (u.nflag[i] & 2) != 0;
    free(u.nflag);
    free(u.eflag);
    free(u.nodes);
    free(u.colour);
    free(u.elems);
    free(u.stamp);
    free(u.scratch);
    free(u.colour_ptr);
    res->seconds = omp_get_wtime() - t0;
    return st;
}

getme_status getme__untangle_message(getme_mesh *mesh,
                                     const getme_untangle_result *r)
{
    char list[160] = "";
    size_t len = 0;
    for (int i = 0; i < r->num_reported && len < sizeof list; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%d",
                                i ? ", " : "", (int)r->remaining[i]);
    return getme__fail(
        mesh, GETME_ERR_INVALID_MESH,
        "%lld of %lld invalid (inverted or degenerate) element%s could not "
        "be untangled (%lld without a free node), first: %s%s",
        (long long)r->num_invalid_after, (long long)r->num_invalid_before,
        r->num_invalid_before == 1 ? "" : "s", (long long)r->num_stuck, list,
        r->num_invalid_after > r->num_reported ? ", ..." : "");
}

getme_status getme_mesh_untangle(getme_mesh *mesh, const getme_params *params,
                                 getme_untangle_result *result)
{
    getme_params defaults;
    getme_untangle_result local;
    double t0;
    getme_ws ws;
    if (!result)
        result = &local;
    getme_status st = getme__enter(mesh, &params, &defaults, &ws, result,
                                   sizeof *result, &t0, 0);
    if (st != GETME_OK)
        return st;
    double *q = getme__malloc((size_t)ws.ne * sizeof *q);
    if (!q) {
        getme__ws_free(&ws);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    /* second order: highorder_repair.c */
    int32_t ho_found = 0, ho_e = 0, ho_n = 0;
    st = getme__ho_repair(&ws, &ho_found, &ho_e, &ho_n);
    if (st == GETME_OK) {
        getme__ws_qualities(&ws, q);
        st = getme__untangle(&ws, q, result);
    }
    result->num_invalid_before += ho_e;
    result->num_ho_invalid = ho_found;
    result->num_ho_repaired = ho_e;
    result->num_ho_moved = ho_n;
    if (st == GETME_OK && (result->num_moved > 0 || ho_n > 0))
        getme__ws_store(&ws, mesh);
    free(q);
    getme__ws_free(&ws);
    result->seconds = omp_get_wtime() - t0;
    if (st != GETME_OK)
        return getme__fail(mesh, st, "out of memory untangling %d elements",
                           (int)mesh->num_elements);
    if (result->num_invalid_after > 0)
        return getme__untangle_message(mesh, result);
    return GETME_OK;
}
