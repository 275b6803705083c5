/*
 * measures.c -- the quality measures FE analysts read (getme.h "Quality
 * measures for analysts", docs/quality.md): dihedral angles, the Verdict /
 * CUBIT scaled Jacobian, Gmsh's gamma and SICN, and their mesh statistics.
 *
 * These are reporting kernels, not the smoother's hot path: clarity over
 * speed (libm's sqrt, atan2), but still pure functions of the element's
 * coordinates, so the mesh statistics can evaluate them from any thread.
 */
#include "internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define M_SQRT2_ 1.41421356237309504880
#define M_SQRT3_ 1.73205080756887729353
#define M_PI_ 3.14159265358979323846
#define RAD2DEG (180.0 / M_PI_)

/* ---- corners ------------------------------------------------------------ */

/* {node, three neighbours} with det(e1, e2, e3) > 0 on the regular element;
   the edge order matches the W of quality.c (prism: 2 triangle edges then
   the vertical one; pyramid: 2 base edges then the apex). */
static const int8_t hex_corner[8][4] = {
    {0, 1, 3, 4}, {1, 2, 0, 5}, {2, 3, 1, 6}, {3, 0, 2, 7},
    {4, 7, 5, 0}, {5, 4, 6, 1}, {6, 5, 7, 2}, {7, 6, 4, 3}};
static const int8_t prism_corner[6][4] = {
    {0, 1, 2, 3}, {1, 2, 0, 4}, {2, 0, 1, 5},
    {3, 5, 4, 0}, {4, 3, 5, 1}, {5, 4, 3, 2}};
static const int8_t pyramid_corner[4][4] = {
    {0, 1, 3, 4}, {1, 2, 0, 4}, {2, 3, 1, 4}, {3, 0, 2, 4}};

static void vsub(const double *x, int a, int b, double e[3])
{
    for (int c = 0; c < 3; c++)
        e[c] = x[3 * b + c] - x[3 * a + c];
}

static double vdot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void vcross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double vdet(const double a[3], const double b[3], const double c[3])
{
    double bc[3];
    vcross(b, c, bc);
    return vdot(a, bc);
}

static double vnorm(const double a[3]) { return sqrt(vdot(a, a)); }

/* The three edge vectors of corner k of a 3-D element. */
static void corner_edges(const double *x, const int8_t c[4], double e[3][3])
{
    for (int i = 0; i < 3; i++)
        vsub(x, c[0], c[i + 1], e[i]);
}

/* det of the three unit edge vectors; 0 if an edge has length 0. */
static double unit_det(double e[3][3])
{
    double l = vnorm(e[0]) * vnorm(e[1]) * vnorm(e[2]);
    return l > 0.0 ? vdet(e[0], e[1], e[2]) / l : 0.0;
}

/* 2-D: the edges x[b] - x[a] in the xy plane and their cross / dot. */
static double cross_xy(const double *x, int a, int b, int c)
{
    return (x[3 * b] - x[3 * a]) * (x[3 * c + 1] - x[3 * a + 1]) -
           (x[3 * b + 1] - x[3 * a + 1]) * (x[3 * c] - x[3 * a]);
}

static double dot_xy(const double *x, int a, int b, int c)
{
    return (x[3 * b] - x[3 * a]) * (x[3 * c] - x[3 * a]) +
           (x[3 * b + 1] - x[3 * a + 1]) * (x[3 * c + 1] - x[3 * a + 1]);
}

static double len_xy(const double *x, int a, int b)
{
    return sqrt(dot_xy(x, a, b, b));
}

/* ---- dihedral angles ---------------------------------------------------- */

/*
 * The edge ends of a 3-D type: {a, b, p, q} for the edge a-b seen from a,
 * p and q a's neighbours (other than b) in the two faces through the edge.
 * Both ends of an edge are listed unless both faces are triangles (then
 * they give the same angle).  Built from the face and edge tables.
 */
typedef struct dihedral_ends {
    int n;
    int8_t end[24][4];
} dihedral_ends;

/* The neighbour of node a in face f that is not b (-1 if a-b is not an
   edge of f). */
static int face_neighbour(const getme_face_table *ft, int f, int a, int b)
{
    int n = ft->size[f];
    for (int i = 0; i < n; i++) {
        if (ft->node[f][i] != a)
            continue;
        int prev = ft->node[f][(i + n - 1) % n], next = ft->node[f][(i + 1) % n];
        if (prev == b)
            return next;
        if (next == b)
            return prev;
        return -1;
    }
    return -1;
}

static void dihedral_ends_of(int type, dihedral_ends *d)
{
    const getme_face_table *ft = &getme__faces[type];
    const getme_edge_table *et = &getme__edges[type];
    d->n = 0;
    for (int k = 0; k < et->num_edges; k++) {
        int a = et->node[k][0], b = et->node[k][1];
        int pa[2], pb[2], n = 0;
        for (int f = 0; f < ft->num_faces && n < 2; f++) {
            int na = face_neighbour(ft, f, a, b);
            if (na < 0)
                continue;
            pa[n] = na;
            pb[n++] = face_neighbour(ft, f, b, a);
        }
        int8_t *e = d->end[d->n++];
        e[0] = (int8_t)a, e[1] = (int8_t)b, e[2] = (int8_t)pa[0], e[3] = (int8_t)pa[1];
        if (pa[0] == pb[0] && pa[1] == pb[1])
            continue; /* two triangles: the same half-planes from b */
        e = d->end[d->n++];
        e[0] = (int8_t)b, e[1] = (int8_t)a, e[2] = (int8_t)pb[0], e[3] = (int8_t)pb[1];
    }
}

/* atan2(|u x v|, u . v): the angle between u and v in [0, pi] */
static double angle_between(const double u[3], const double v[3])
{
    double w[3];
    vcross(u, v, w);
    return atan2(vnorm(w), vdot(u, v));
}

/*
 * min and max dihedral angle of a 3-D element, radians.  At the edge end
 * {a, b, p, q}: u, v the components of p - a and q - a normal to the edge;
 * the angle is that between u and v.  The ends are ranked by the cosine
 * u.v / (|u| |v|) (1, i.e. angle 0, when u or v vanishes), and only the two
 * extreme ones get the accurate atan2 form.
 */
static void dihedral3(const dihedral_ends *d, const double *x, double *lo,
                      double *hi)
{
    double cmin = INFINITY, cmax = -INFINITY;
    double umin[3] = {0}, vmin[3] = {0}, umax[3] = {0}, vmax[3] = {0};
    for (int k = 0; k < d->n; k++) {
        const int8_t *end = d->end[k];
        double e[3], dp[3], dq[3], u[3], v[3];
        vsub(x, end[0], end[1], e);
        vsub(x, end[0], end[2], dp);
        vsub(x, end[0], end[3], dq);
        double ee = vdot(e, e), inv = ee > 0.0 ? 1.0 / ee : 0.0;
        double pe = vdot(dp, e) * inv, qe = vdot(dq, e) * inv;
        for (int c = 0; c < 3; c++) {
            u[c] = dp[c] - pe * e[c];
            v[c] = dq[c] - qe * e[c];
        }
        double den = sqrt(vdot(u, u) * vdot(v, v));
        double cs = den > 0.0 ? vdot(u, v) / den : 1.0;
        if (cs > cmax) { /* smallest angle so far */
            cmax = cs;
            memcpy(umax, u, sizeof u);
            memcpy(vmax, v, sizeof v);
        }
        if (cs < cmin) { /* largest angle so far */
            cmin = cs;
            memcpy(umin, u, sizeof u);
            memcpy(vmin, v, sizeof v);
        }
    }
    *lo = angle_between(umax, vmax);
    *hi = angle_between(umin, vmin);
}

/* min and max interior angle of a planar element, radians in [0, 2 pi). */
static void angles2(int nv, const double *x, double *lo, double *hi)
{
    double mn = INFINITY, mx = -INFINITY;
    for (int k = 0; k < nv; k++) {
        int next = (k + 1) % nv, prev = (k + nv - 1) % nv;
        double t = atan2(cross_xy(x, k, next, prev), dot_xy(x, k, next, prev));
        if (t < 0.0)
            t += 2.0 * M_PI_;
        mn = fmin(mn, t);
        mx = fmax(mx, t);
    }
    *lo = mn;
    *hi = mx;
}

/* ---- scaled Jacobian ---------------------------------------------------- */

/* product of the lengths of the edges at each node, maximum over nodes */
static double max_length_product(int type, const double *x)
{
    const getme_edge_table *et = &getme__edges[type];
    double prod[GETME_MAX_NV];
    for (int i = 0; i < getme__nv[type]; i++)
        prod[i] = 1.0;
    for (int k = 0; k < et->num_edges; k++) {
        double e[3];
        vsub(x, et->node[k][0], et->node[k][1], e);
        if (type == GETME_TRI || type == GETME_QUAD)
            e[2] = 0.0;
        double l = vnorm(e);
        prod[et->node[k][0]] *= l;
        prod[et->node[k][1]] *= l;
    }
    double m = 0.0;
    for (int i = 0; i < getme__nv[type]; i++)
        m = fmax(m, prod[i]);
    return m;
}

static double min_corner_unit_det(const double *x, const int8_t (*corner)[4],
                                  int n)
{
    double m = INFINITY;
    for (int k = 0; k < n; k++) {
        double e[3][3];
        corner_edges(x, corner[k], e);
        m = fmin(m, unit_det(e));
    }
    return m;
}

static double scaled_jacobian(int type, const double *x)
{
    switch (type) {
    case GETME_TET: {
        double e[3][3], m = max_length_product(type, x);
        static const int8_t c0[4] = {0, 1, 2, 3};
        corner_edges(x, c0, e);
        return m > 0.0 ? M_SQRT2_ * vdet(e[0], e[1], e[2]) / m : 0.0;
    }
    case GETME_HEX: {
        /* Verdict also checks the centre: the principal axes, each the sum
           of the four parallel edges */
        static const int8_t axis[3][4][2] = {
            {{0, 1}, {3, 2}, {4, 5}, {7, 6}},
            {{0, 3}, {1, 2}, {4, 7}, {5, 6}},
            {{0, 4}, {1, 5}, {2, 6}, {3, 7}}};
        double p[3][3] = {{0}};
        for (int d = 0; d < 3; d++)
            for (int i = 0; i < 4; i++) {
                double e[3];
                vsub(x, axis[d][i][0], axis[d][i][1], e);
                for (int c = 0; c < 3; c++)
                    p[d][c] += e[c];
            }
        return fmin(min_corner_unit_det(x, hex_corner, 8), unit_det(p));
    }
    case GETME_PRISM:
        return 2.0 / M_SQRT3_ * min_corner_unit_det(x, prism_corner, 6);
    case GETME_PYRAMID:
        return fmin(1.0, M_SQRT2_ * min_corner_unit_det(x, pyramid_corner, 4));
    case GETME_TRI: {
        double m = max_length_product(type, x);
        return m > 0.0 ? 2.0 / M_SQRT3_ * cross_xy(x, 0, 1, 2) / m : 0.0;
    }
    default: { /* quad */
        double m = INFINITY;
        for (int k = 0; k < 4; k++) {
            int next = (k + 1) % 4, prev = (k + 3) % 4;
            double l = len_xy(x, k, next) * len_xy(x, k, prev);
            m = fmin(m, l > 0.0 ? cross_xy(x, k, next, prev) / l : 0.0);
        }
        return m;
    }
    }
}

/* ---- Gmsh's gamma ------------------------------------------------------- */

/* 3 r / R of a tet: with the edges a, b, c from node 0, V = |det| / 6,
   r = 3 V / (sum of face areas), R = |a^2 (b x c) + b^2 (c x a) +
   c^2 (a x b)| / (2 |det|), so 3 r / R = 3 det^2 / (areas * |N|). */
static double gamma_tet(const double *x)
{
    double a[3], b[3], c[3], bc[3], ca[3], ab[3], f[3], g[3], fg[3], n[3];
    vsub(x, 0, 1, a);
    vsub(x, 0, 2, b);
    vsub(x, 0, 3, c);
    vcross(b, c, bc);
    vcross(c, a, ca);
    vcross(a, b, ab);
    vsub(x, 1, 2, f);
    vsub(x, 1, 3, g);
    vcross(f, g, fg);
    double det = vdot(a, bc);
    double areas = 0.5 * (vnorm(bc) + vnorm(ca) + vnorm(ab) + vnorm(fg));
    double la = vdot(a, a), lb = vdot(b, b), lc = vdot(c, c);
    for (int k = 0; k < 3; k++)
        n[k] = la * bc[k] + lb * ca[k] + lc * ab[k];
    double den = areas * vnorm(n);
    return den > 0.0 ? 3.0 * det * det / den : 0.0;
}

/* 2 r / R of a triangle = 16 A^2 / (perimeter * product of the edges) */
static double gamma_tri(const double *x)
{
    double l0 = len_xy(x, 0, 1), l1 = len_xy(x, 1, 2), l2 = len_xy(x, 2, 0);
    double twice_area = cross_xy(x, 0, 1, 2);
    double den = (l0 + l1 + l2) * l0 * l1 * l2;
    return den > 0.0 ? 4.0 * twice_area * twice_area / den : 0.0;
}

/* s (1 - max |pi/2 - a_k| / (pi/2)), a_k in [0, pi] the angle between the
   consecutive edge vectors x[k+1] - x[k] and x[k+2] - x[k+1]. */
static double gamma_quad(const double *x)
{
    double dev = 0.0, sign = 1.0;
    for (int k = 0; k < 4; k++) {
        int k1 = (k + 1) % 4, k2 = (k + 2) % 4;
        /* edges from k1: back to k is -(x[k1] - x[k]) */
        double cr = -cross_xy(x, k1, k, k2), dt = -dot_xy(x, k1, k, k2);
        double a = atan2(fabs(cr), dt);
        dev = fmax(dev, fabs(0.5 * M_PI_ - a));
        if (cr < 0.0)
            sign = -1.0;
    }
    return sign * (1.0 - dev / (0.5 * M_PI_));
}

static double gamma_prism(const double *x)
{
    double m = INFINITY;
    for (int k = 0; k < 6; k++) {
        double e[3][3];
        corner_edges(x, prism_corner[k], e);
        m = fmin(m, fabs(unit_det(e)));
    }
    return 2.0 / M_SQRT3_ * m;
}

/* ---- Gmsh's SICN -------------------------------------------------------- */

/* 3 det S / (|S|_F |cof S|_F) for the columns s of S; 0 if degenerate. */
static double icn3(double s[3][3])
{
    double c0[3], c1[3], c2[3];
    vcross(s[1], s[2], c0);
    vcross(s[2], s[0], c1);
    vcross(s[0], s[1], c2);
    double f = vdot(s[0], s[0]) + vdot(s[1], s[1]) + vdot(s[2], s[2]);
    double g = vdot(c0, c0) + vdot(c1, c1) + vdot(c2, c2);
    double den = sqrt(f * g);
    return den > 0.0 ? 3.0 * vdot(s[0], c0) / den : 0.0;
}

/* Map corner edges to S = D W^-1 (the W of quality.c). */
static void to_regular(int type, double e[3][3])
{
    for (int c = 0; c < 3; c++) {
        double e1 = e[0][c], e2 = e[1][c], e3 = e[2][c];
        if (type == GETME_TET) {
            e[1][c] = (2.0 * e2 - e1) / M_SQRT3_;
            e[2][c] = (3.0 * e3 - e1 - e2) / (M_SQRT2_ * M_SQRT3_);
        } else if (type == GETME_PRISM) {
            e[1][c] = (2.0 * e2 - e1) / M_SQRT3_;
        } else if (type == GETME_PYRAMID) {
            e[2][c] = M_SQRT2_ * (e3 - 0.5 * (e1 + e2));
        }
    }
}

static double sicn3(int type, const double *x)
{
    static const int8_t tet_corner[1][4] = {{0, 1, 2, 3}};
    const int8_t(*corner)[4] = type == GETME_TET     ? tet_corner
                               : type == GETME_HEX   ? hex_corner
                               : type == GETME_PRISM ? prism_corner
                                                     : pyramid_corner;
    int n = type == GETME_TET ? 1 : type == GETME_HEX ? 8 : type == GETME_PRISM ? 6 : 4;
    double m = INFINITY;
    for (int k = 0; k < n; k++) {
        double e[3][3];
        corner_edges(x, corner[k], e);
        to_regular(type, e);
        m = fmin(m, icn3(e));
    }
    return m;
}

/* 2 det S / |S|_F^2 for the 2x2 matrix with columns (a0, a1), (b0, b1) */
static double icn2(double a0, double a1, double b0, double b1)
{
    double f = a0 * a0 + a1 * a1 + b0 * b0 + b1 * b1;
    return f > 0.0 ? 2.0 * (a0 * b1 - a1 * b0) / f : 0.0;
}

static double sicn2(int type, const double *x)
{
    if (type == GETME_TRI) {
        double a0 = x[3] - x[0], a1 = x[4] - x[1];
        double b0 = x[6] - x[0], b1 = x[7] - x[1];
        return icn2(a0, a1, (2.0 * b0 - a0) / M_SQRT3_,
                    (2.0 * b1 - a1) / M_SQRT3_);
    }
    double m = INFINITY;
    for (int k = 0; k < 4; k++) {
        int next = (k + 1) % 4, prev = (k + 3) % 4;
        m = fmin(m, icn2(x[3 * next] - x[3 * k], x[3 * next + 1] - x[3 * k + 1],
                         x[3 * prev] - x[3 * k], x[3 * prev + 1] - x[3 * k + 1]));
    }
    return m;
}

/* ---- dispatch ----------------------------------------------------------- */

static const char *const measure_name[GETME_NUM_MEASURES] = {
    "mean_ratio", "min_dihedral", "max_dihedral",
    "scaled_jacobian", "gamma", "sicn"};

const char *getme_measure_name(getme_measure measure)
{
    return (unsigned)measure < (unsigned)GETME_NUM_MEASURES
               ? measure_name[measure]
               : "unknown";
}

int getme_measure_defined(getme_elem_type type, getme_measure measure)
{
    if ((unsigned)type >= (unsigned)GETME_NUM_TYPES ||
        (unsigned)measure >= (unsigned)GETME_NUM_MEASURES)
        return 0;
    return !(measure == GETME_MEASURE_GAMMA &&
             (type == GETME_HEX || type == GETME_PYRAMID));
}

getme_status getme_measure_range(getme_measure measure, double *lo,
                                 double *hi)
{
    if ((unsigned)measure >= (unsigned)GETME_NUM_MEASURES || !lo || !hi)
        return GETME_ERR_ARGUMENT;
    int angle = measure == GETME_MEASURE_MIN_DIHEDRAL ||
                measure == GETME_MEASURE_MAX_DIHEDRAL;
    *lo = 0.0;
    *hi = angle ? 180.0 : 1.0;
    return GETME_OK;
}

/* The measure m of a known (type, m) pair; de: the type's dihedral ends
   (3-D types).  For MIN_DIHEDRAL, *max_angle (if not NULL) also receives
   the max dihedral angle. */
static double measure(int type, int m, const double *x,
                      const dihedral_ends *de, double *max_angle)
{
    int planar = type == GETME_TRI || type == GETME_QUAD;
    switch (m) {
    case GETME_MEASURE_MEAN_RATIO:
        return getme__quality(type, x);
    case GETME_MEASURE_MIN_DIHEDRAL:
    case GETME_MEASURE_MAX_DIHEDRAL: {
        double lo, hi;
        if (planar)
            angles2(getme__nv[type], x, &lo, &hi);
        else
            dihedral3(de, x, &lo, &hi);
        if (max_angle)
            *max_angle = hi * RAD2DEG;
        return (m == GETME_MEASURE_MIN_DIHEDRAL ? lo : hi) * RAD2DEG;
    }
    case GETME_MEASURE_SCALED_JACOBIAN:
        return scaled_jacobian(type, x);
    case GETME_MEASURE_GAMMA:
        switch (type) {
        case GETME_TET: return gamma_tet(x);
        case GETME_PRISM: return gamma_prism(x);
        case GETME_TRI: return gamma_tri(x);
        case GETME_QUAD: return gamma_quad(x);
        default: return NAN;
        }
    default:
        return planar ? sicn2(type, x) : sicn3(type, x);
    }
}

double getme_element_measure(getme_elem_type type, getme_measure m,
                             const double *xyz)
{
    if (!xyz || !getme_measure_defined(type, m))
        return NAN;
    dihedral_ends de;
    if (getme_type_dim(type) == 3 && (m == GETME_MEASURE_MIN_DIHEDRAL ||
                                      m == GETME_MEASURE_MAX_DIHEDRAL))
        dihedral_ends_of((int)type, &de);
    return measure((int)type, (int)m, xyz, &de, NULL);
}

/* ---- mesh-level --------------------------------------------------------- */

/* The values of the blocks of one type (-1: all) into v, NaN elsewhere;
   for MIN_DIHEDRAL also the max dihedral angles into v_max if not NULL. */
static void block_values(getme_mesh *mesh, int type, int m, double *v,
                         double *v_max)
{
    if (mesh->mirror < 0)
        getme__detect_orientation(mesh);
    double ysign = mesh->mirror == 1 ? -1.0 : 1.0;
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        int skip = (type >= 0 && bl->type != type) ||
                   !getme_measure_defined((getme_elem_type)bl->type,
                                          (getme_measure)m);
        dihedral_ends de;
        if (getme_type_dim((getme_elem_type)bl->type) == 3)
            dihedral_ends_of(bl->type, &de);
#pragma omp parallel for schedule(static)
        for (int32_t e = 0; e < bl->count; e++) {
            int32_t g = bl->first + e;
            if (skip) {
                v[g] = NAN;
                if (v_max)
                    v_max[g] = NAN;
                continue;
            }
            double x[3 * GETME_MAX_NV];
            getme__prefetch_local(mesh, bl, e + GETME_PREFETCH_AHEAD);
            getme__gather_local(mesh, bl, e, ysign, x);
            v[g] = measure(bl->type, m, x, &de, v_max ? v_max + g : NULL);
        }
    }
}

getme_status getme_mesh_element_measures(getme_mesh *mesh,
                                         getme_measure measure_id,
                                         double *values)
{
    if (!mesh || (unsigned)measure_id >= (unsigned)GETME_NUM_MEASURES ||
        (!values && mesh->num_elements))
        return GETME_ERR_ARGUMENT;
    block_values(mesh, -1, (int)measure_id, values, NULL);
    return GETME_OK;
}

static void add_stat(getme_measure_stats *s, double v, int32_t e, double *sum)
{
    if (s->num_elements == 0 || v < s->min) {
        s->min = v;
        s->min_element = e;
    }
    if (s->num_elements == 0 || v > s->max) {
        s->max = v;
        s->max_element = e;
    }
    s->num_elements++;
    s->num_negative += v < 0.0;
    *sum += v;
    if (v < s->hist_lo) {
        s->num_below++;
        return;
    }
    double t = (v - s->hist_lo) / (s->hist_hi - s->hist_lo);
    int bin = (int)(t * GETME_HIST_BINS);
    s->histogram[bin >= GETME_HIST_BINS ? GETME_HIST_BINS - 1 : bin]++;
}

static void init_stats(getme_measure_stats *s, int m)
{
    memset(s, 0, sizeof *s);
    s->min_element = s->max_element = -1;
    getme_measure_range((getme_measure)m, &s->hist_lo, &s->hist_hi);
}

/* Reduce the values v of one measure serially in element order (the same
   sums for any thread count): into out[type] for each type if per_type,
   else all into out[0]. */
static void reduce(const getme_mesh *mesh, const double *v, int per_type,
                   getme_measure_stats *out, int stride)
{
    double sum[GETME_NUM_TYPES] = {0};
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        int slot = per_type ? bl->type : 0;
        for (int32_t e = bl->first; e < bl->first + bl->count; e++)
            if (!isnan(v[e]))
                add_stat(&out[slot * stride], v[e], e, &sum[slot]);
    }
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        getme_measure_stats *s = &out[t * stride];
        if (t < (per_type ? GETME_NUM_TYPES : 1) && s->num_elements)
            s->mean = sum[t] / (double)s->num_elements;
    }
}

static double *values_buffer(getme_mesh *mesh)
{
    return malloc((size_t)(mesh->num_elements ? mesh->num_elements : 1) *
                  sizeof(double));
}

getme_status getme_mesh_measure_stats(getme_mesh *mesh, int type,
                                      getme_measure measure_id,
                                      getme_measure_stats *s)
{
    if (!mesh || !s || type < -1 || type >= GETME_NUM_TYPES ||
        (unsigned)measure_id >= (unsigned)GETME_NUM_MEASURES)
        return GETME_ERR_ARGUMENT;
    init_stats(s, (int)measure_id);
    double *v = values_buffer(mesh);
    if (!v)
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    block_values(mesh, type, (int)measure_id, v, NULL);
    reduce(mesh, v, 0, s, 0);
    free(v);
    return GETME_OK;
}

/* Elements per tile of getme_mesh_measure_all: the tile's values of every
   measure (6 doubles per element, 1.5 MiB) are computed in parallel, then
   reduced serially in element order. */
enum { MEASURE_TILE = 32768 };

/* Every measure of element e of block bl into v[GETME_NUM_MEASURES] (NaN
   where it is not defined for the type): one gather for all of them. */
static void element_measures(const getme_mesh *mesh, const getme_block *bl,
                             int32_t e, double ysign, const dihedral_ends *de,
                             const uint8_t *defined, double *v)
{
    double x[3 * GETME_MAX_NV];
    getme__gather_local(mesh, bl, e, ysign, x);
    for (int m = 0; m < GETME_NUM_MEASURES; m++) {
        if (m == GETME_MEASURE_MAX_DIHEDRAL)
            continue; /* with the min */
        double *vmax = m == GETME_MEASURE_MIN_DIHEDRAL
                           ? v + GETME_MEASURE_MAX_DIHEDRAL : NULL;
        if (defined[m]) {
            v[m] = measure(bl->type, m, x, de, vmax);
        } else {
            v[m] = NAN;
            if (vmax)
                *vmax = NAN;
        }
    }
}

/* All measures in one sweep over the elements instead of one per measure:
   the gather of an element's nodes (random access into the coordinates
   in the caller's order) is most of the cost, so it is done once.  The
   values and their reduction, in element order per (type, measure), are
   the same as getme_mesh_measure_stats() gives one measure at a time. */
getme_status getme_mesh_measure_all(getme_mesh *mesh,
                                    getme_measure_stats *stats)
{
    if (!mesh || !stats)
        return GETME_ERR_ARGUMENT;
    for (int k = 0; k < GETME_NUM_TYPES * GETME_NUM_MEASURES; k++)
        init_stats(&stats[k], k % GETME_NUM_MEASURES);
    double *v = malloc((size_t)MEASURE_TILE * GETME_NUM_MEASURES * sizeof *v);
    if (!v)
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    if (mesh->mirror < 0)
        getme__detect_orientation(mesh);
    double ysign = mesh->mirror == 1 ? -1.0 : 1.0;
    double sum[GETME_NUM_TYPES][GETME_NUM_MEASURES] = {{0}};
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        int t = bl->type;
        dihedral_ends de;
        if (getme_type_dim((getme_elem_type)t) == 3)
            dihedral_ends_of(t, &de);
        uint8_t defined[GETME_NUM_MEASURES];
        for (int m = 0; m < GETME_NUM_MEASURES; m++)
            defined[m] = (uint8_t)getme_measure_defined((getme_elem_type)t,
                                                        (getme_measure)m);
        for (int32_t e0 = 0; e0 < bl->count; e0 += MEASURE_TILE) {
            int32_t n = bl->count - e0 < MEASURE_TILE ? bl->count - e0
                                                       : MEASURE_TILE;
#pragma omp parallel for schedule(static)
            for (int32_t i = 0; i < n; i++) {
                getme__prefetch_local(mesh, bl, e0 + i + GETME_PREFETCH_AHEAD);
                element_measures(mesh, bl, e0 + i, ysign, &de, defined,
                                 v + (int64_t)i * GETME_NUM_MEASURES);
            }
            getme_measure_stats *s = stats + t * GETME_NUM_MEASURES;
            for (int32_t i = 0; i < n; i++) {
                const double *vi = v + (int64_t)i * GETME_NUM_MEASURES;
                for (int m = 0; m < GETME_NUM_MEASURES; m++)
                    if (!isnan(vi[m]))
                        add_stat(&s[m], vi[m], bl->first + e0 + i, &sum[t][m]);
            }
        }
    }
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        for (int m = 0; m < GETME_NUM_MEASURES; m++) {
            getme_measure_stats *s = &stats[t * GETME_NUM_MEASURES + m];
            if (s->num_elements)
                s->mean = sum[t][m] / (double)s->num_elements;
        }
    free(v);
    return GETME_OK;
}

int getme_measure_summary(getme_elem_type type,
                          const getme_measure_stats *s, char *buf,
                          size_t size)
{
    static const char *const label[GETME_NUM_MEASURES] = {
        "mean ratio", "min dihedral", "max dihedral", "scaled Jacobian",
        "gamma", "SICN"};
    if (!buf || !size)
        return 0;
    buf[0] = '\0';
    if (!s || !s[GETME_MEASURE_MEAN_RATIO].num_elements)
        return 0;
    int n = snprintf(buf, size, "%s %.2f to %.2f deg",
                     getme_type_dim(type) == 2 ? "angles" : "dihedral",
                     s[GETME_MEASURE_MIN_DIHEDRAL].min,
                     s[GETME_MEASURE_MAX_DIHEDRAL].max);
    for (int k = GETME_MEASURE_SCALED_JACOBIAN; k < GETME_NUM_MEASURES; k++) {
        if (!s[k].num_elements)
            continue;
        size_t used = (size_t)n < size ? (size_t)n : size - 1;
        n += snprintf(buf + used, size - used, ", %s min %.4f mean %.4f",
                      label[k], s[k].min, s[k].mean);
        used = (size_t)n < size ? (size_t)n : size - 1;
        if (s[k].num_negative)
            n += snprintf(buf + used, size - used, " (%lld negative)",
                          (long long)s[k].num_negative);
    }
    return n;
}
