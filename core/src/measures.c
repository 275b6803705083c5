/*
 * measures.c -- the quality measures FE analysts read (getme.h "Quality
 * measures for analysts", docs/quality.md): dihedral angles, the Verdict /
 * CUBIT scaled Jacobian, Gmsh's gamma and SICN, and their mesh statistics.
 *
 * Pure functions of the element's coordinates, so the mesh statistics can
 * evaluate them from any thread.  The getme command measures every mesh
 * before and after smoothing, so getme_mesh_measure_all runs the 3-D types
 * eight elements at a time in vector lanes with the same kernels (every
 * value the same bits as the one-element functions give), and reduces
 * each measure's statistics in element order.
 */
#include "internal.h"
#include "angle.h"

/* Compiled with -fno-trapping-math (core/CMakeLists.txt says why): the
   measures' lane loops, where a division or square root is evaluated on
   a lane whose result a select then discards. */

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define M_SQRT2_ 1.41421356237309504880
#define M_SQRT3_ 1.73205080756887729353
#define M_PI_ 3.14159265358979323846
#define RAD2DEG (180.0 / M_PI_)

/* The kernels on 3-vectors below are shared by the one-element functions
   and the lane loops of getme_mesh_measure_all (further down): inlined
   there, on scalars rather than arrays, and with their divisions made
   unconditional (by 1 where the result is the fallback), the compiler
   turns those loops into vector instructions.  Either way every value is
   the same bits. */
#if defined(__GNUC__)
#define KERNEL static inline __attribute__((always_inline))
#else
#define KERNEL static inline
#endif

typedef struct v3 {
    double x, y, z;
} v3;

KERNEL v3 v3_sub(v3 a, v3 b) { return (v3){a.x - b.x, a.y - b.y, a.z - b.z}; }

KERNEL double v3_dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

KERNEL v3 v3_cross(v3 a, v3 b)
{
    return (v3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z,
                a.x * b.y - a.y * b.x};
}

KERNEL double v3_norm(v3 a) { return sqrt(v3_dot(a, a)); }

/* node i of one element's coordinates */
KERNEL v3 v3_at(const double *x, int i)
{
    return (v3){x[3 * i], x[3 * i + 1], x[3 * i + 2]};
}

/* q / d, or z where d is not > 0 (the division done either way) */
KERNEL double div_or(double q, double d, double z)
{
    double r = q / (d > 0.0 ? d : 1.0);
    return d > 0.0 ? r : z;
}

/* det of the three unit vectors a / |a|, ...; 0 if one has length 0. */
KERNEL double unit_det3(v3 a, v3 b, v3 c)
{
    double l = v3_norm(a) * v3_norm(b) * v3_norm(c);
    return div_or(v3_dot(a, v3_cross(b, c)), l, 0.0);
}

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
/* Verdict's scaled Jacobian of a hex also checks the centre: the
   principal axes, each the sum of the four parallel edges {from, to}. */
static const int8_t hex_axis[3][4][2] = {
    {{0, 1}, {3, 2}, {4, 5}, {7, 6}},
    {{0, 3}, {1, 2}, {4, 7}, {5, 6}},
    {{0, 4}, {1, 5}, {2, 6}, {3, 7}}};

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
    return unit_det3(v3_at(e[0], 0), v3_at(e[1], 0), v3_at(e[2], 0));
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

/* The dihedral end a-b seen from a, p and q a's neighbours in its two
   faces: u, v the components of p - a and q - a normal to the edge, and
   the cosine of their angle (1 when u or v vanishes). */
KERNEL double end_uv(v3 a, v3 b, v3 p, v3 q, v3 *u, v3 *v)
{
    v3 e = v3_sub(b, a), dp = v3_sub(p, a), dq = v3_sub(q, a);
    double ee = v3_dot(e, e), inv = div_or(1.0, ee, 0.0);
    double pe = v3_dot(dp, e) * inv, qe = v3_dot(dq, e) * inv;
    *u = (v3){dp.x - pe * e.x, dp.y - pe * e.y, dp.z - pe * e.z};
    *v = (v3){dq.x - qe * e.x, dq.y - qe * e.y, dq.z - qe * e.z};
    double den = sqrt(v3_dot(*u, *u) * v3_dot(*v, *v));
    return div_or(v3_dot(*u, *v), den, 1.0);
}

/* atan2(|u x v|, u . v): the angle between u and v in [0, pi] (angle.h:
   the lanes' kernel, so both give the same bits) */
static double angle_between(const double u[3], const double v[3])
{
    double w[3];
    vcross(u, v, w);
    return getme__angle(vnorm(w), vdot(u, v));
}

/*
 * min and max dihedral angle of a 3-D element, radians.  At the edge end
 * {a, b, p, q}: u, v the components of p - a and q - a normal to the edge;
 * the angle is that between u and v.  The ends are ranked by the cosine
 * u.v / (|u| |v|) (1, i.e. angle 0, when u or v vanishes), and only the two
 * extreme ones get the accurate atan2 form (getme__angle, angle.h).
 */
static void dihedral3(const dihedral_ends *d, const double *x, double *lo,
                      double *hi)
{
    double cmin = INFINITY, cmax = -INFINITY;
    double umin[3] = {0}, vmin[3] = {0}, umax[3] = {0}, vmax[3] = {0};
    for (int k = 0; k < d->n; k++) {
        const int8_t *end = d->end[k];
        v3 uu, vv;
        double cs = end_uv(v3_at(x, end[0]), v3_at(x, end[1]),
                           v3_at(x, end[2]), v3_at(x, end[3]), &uu, &vv);
        double u[3] = {uu.x, uu.y, uu.z}, v[3] = {vv.x, vv.y, vv.z};
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
        double p[3][3] = {{0}};
        for (int d = 0; d < 3; d++)
            for (int i = 0; i < 4; i++) {
                double e[3];
                vsub(x, hex_axis[d][i][0], hex_axis[d][i][1], e);
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
KERNEL double gamma_tet4(v3 p0, v3 p1, v3 p2, v3 p3)
{
    v3 a = v3_sub(p1, p0), b = v3_sub(p2, p0), c = v3_sub(p3, p0);
    v3 bc = v3_cross(b, c), ca = v3_cross(c, a), ab = v3_cross(a, b);
    v3 fg = v3_cross(v3_sub(p2, p1), v3_sub(p3, p1));
    double det = v3_dot(a, bc);
    double areas =
        0.5 * (v3_norm(bc) + v3_norm(ca) + v3_norm(ab) + v3_norm(fg));
    double la = v3_dot(a, a), lb = v3_dot(b, b), lc = v3_dot(c, c);
    v3 n = {la * bc.x + lb * ca.x + lc * ab.x, la * bc.y + lb * ca.y + lc * ab.y,
            la * bc.z + lb * ca.z + lc * ab.z};
    return div_or(3.0 * det * det, areas * v3_norm(n), 0.0);
}

static double gamma_tet(const double *x)
{
    return gamma_tet4(v3_at(x, 0), v3_at(x, 1), v3_at(x, 2), v3_at(x, 3));
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
        double a = getme__angle(fabs(cr), dt);
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

/* 3 det S / (|S|_F |cof S|_F) for S = D W^-1, D the corner's edges
   e0, e1, e2 and W that of quality.c; 0 if degenerate. */
KERNEL double icn3(int type, v3 e0, v3 e1, v3 e2)
{
    v3 s1 = e1, s2 = e2;
    if (type == GETME_TET || type == GETME_PRISM)
        s1 = (v3){(2.0 * e1.x - e0.x) / M_SQRT3_, (2.0 * e1.y - e0.y) / M_SQRT3_,
                  (2.0 * e1.z - e0.z) / M_SQRT3_};
    if (type == GETME_TET) {
        const double k = M_SQRT2_ * M_SQRT3_;
        s2 = (v3){(3.0 * e2.x - e0.x - e1.x) / k, (3.0 * e2.y - e0.y - e1.y) / k,
                  (3.0 * e2.z - e0.z - e1.z) / k};
    } else if (type == GETME_PYRAMID) {
        s2 = (v3){M_SQRT2_ * (e2.x - 0.5 * (e0.x + e1.x)),
                  M_SQRT2_ * (e2.y - 0.5 * (e0.y + e1.y)),
                  M_SQRT2_ * (e2.z - 0.5 * (e0.z + e1.z))};
    }
    v3 c0 = v3_cross(s1, s2), c1 = v3_cross(s2, e0), c2 = v3_cross(e0, s1);
    double f = v3_dot(e0, e0) + v3_dot(s1, s1) + v3_dot(s2, s2);
    double g = v3_dot(c0, c0) + v3_dot(c1, c1) + v3_dot(c2, c2);
    return div_or(3.0 * v3_dot(e0, c0), sqrt(f * g), 0.0);
}

static const int8_t tet_corner[1][4] = {{0, 1, 2, 3}};

/* The corners of a 3-D type and their number. */
static const int8_t (*corners_of(int type, int *n))[4]
{
    *n = type == GETME_TET ? 1 : type == GETME_HEX ? 8 : type == GETME_PRISM ? 6 : 4;
    return type == GETME_TET     ? tet_corner
           : type == GETME_HEX   ? hex_corner
           : type == GETME_PRISM ? prism_corner
                                 : pyramid_corner;
}

static double sicn3(int type, const double *x)
{
    int n;
    const int8_t(*corner)[4] = corners_of(type, &n);
    double m = INFINITY;
    for (int k = 0; k < n; k++) {
        v3 o = v3_at(x, corner[k][0]);
        m = fmin(m, icn3(type, v3_sub(v3_at(x, corner[k][1]), o),
                         v3_sub(v3_at(x, corner[k][2]), o),
                         v3_sub(v3_at(x, corner[k][3]), o)));
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
            getme__prefetch_local(mesh, bl, e + GETME_PREFETCH_AHEAD, 1);
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

/* The histogram bin of a value t = v - hist_lo >= 0 (or NaN, or below:
   then any number, which the callers do not use) in a range of width w.
   Most ranges are [0, 1]: dividing by 1 changes no bit, so it is skipped
   (a scalar division per element and measure).  KERNEL: inlined into
   lanes_add's vector loop. */
KERNEL int32_t hist_bin(double t, double w)
{
    if (w != 1.0)
        t /= w;
    int32_t k = (int32_t)(t * GETME_HIST_BINS);
    return k >= GETME_HIST_BINS ? GETME_HIST_BINS - 1 : k;
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
    s->histogram[hist_bin(v - s->hist_lo, s->hist_hi - s->hist_lo)]++;
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
    return getme__malloc((size_t)(mesh->num_elements ? mesh->num_elements : 1) *
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

/* ---- GETME_LANES 3-D elements at once ---------------------------------- */

/*
 * getme_mesh_measure_all evaluates the 3-D types GETME_LANES elements at a
 * time, x in lanes (x[3 i + d][l]: coordinate d of node i of element l),
 * with the kernels the one-element functions use, in the same order, so
 * every value is the same bits (no fused multiply-adds: -std=c11); the
 * loops over the lanes become vector instructions, square roots and
 * divisions included, and the mean ratio goes through quality.c's lane
 * kernel.  The dihedral ends are ranked by their cosines in the lanes;
 * only the two extreme ends of each element get an angle (getme__angle,
 * in the lanes as well).
 */
enum { L = GETME_LANES };

/* node i of lane l */
KERNEL v3 v3_lane(const double (*x)[L], int i, int l)
{
    return (v3){x[3 * i][l], x[3 * i + 1][l], x[3 * i + 2][l]};
}

/* fmin and fmax (glibc's: minsd / maxsd when ordered, including which
   zero they give for +0 and -0) for an a that is not NaN, as selects that
   vectorise. */
KERNEL double min_nn(double a, double b)
{
    return b != b ? a : (a < b ? a : b);
}

KERNEL double max_nn(double a, double b)
{
    return b != b ? a : (a > b ? a : b);
}

/* end_uv of end k of lane l */
KERNEL double end_lane(const dihedral_ends *d, const double (*x)[L], int k,
                       int l, v3 *u, v3 *v)
{
    const int8_t *e = d->end[k];
    return end_uv(v3_lane(x, e[0], l), v3_lane(x, e[1], l),
                  v3_lane(x, e[2], l), v3_lane(x, e[3], l), u, v);
}

/* |u x v| and u . v of the lanes, angle_between's atan2 arguments (its
   operations in its order) */
static void atan2_args_lanes(double (*u)[L], double (*v)[L],
                             double *y, double *x)
{
#pragma omp simd
    for (int l = 0; l < L; l++) {
        double cx = u[1][l] * v[2][l] - u[2][l] * v[1][l];
        double cy = u[2][l] * v[0][l] - u[0][l] * v[2][l];
        double cz = u[0][l] * v[1][l] - u[1][l] * v[0][l];
        y[l] = sqrt(cx * cx + cy * cy + cz * cz);
        x[l] = u[0][l] * v[0][l] + u[1][l] * v[1][l] + u[2][l] * v[2][l];
    }
}

/* dihedral3 of the lanes, in degrees as measure() gives them.  The
   extreme ends' u and v are kept in the lanes as they are ranked (no end
   evaluated twice); the two angles per element, getme__angle, are in the
   lanes too. */
static void dihedral_lanes(const dihedral_ends *d, const double (*x)[L],
                           double *lo, double *hi)
{
    /* The extreme cosines so far and the ends that gave them (-1: none,
       while no end is ranked: NaN cosines).  Only the ends' numbers follow
       the ranking; their u and v are computed again below, with the same
       operations, so the same bits.  Keeping u and v themselves cost 12
       blends, loads and stores per end and lane (perf: those, not the
       divider, bounded the 24 ends of a hex on Zen 3). */
    /* two copies, read from one and written to the other at each end:
       updated in place, `c = up ? cs : c` became a branch around a
       masked store (vmaskmovpd, slow on Zen 3: perf, 10 % of the
       measures of hexes); into the other copy it is a blend and a store */
    enum { CMAX, CMIN, EMAX, EMIN };
    double r[2][4][L];
    for (int l = 0; l < L; l++) {
        r[0][CMAX][l] = -INFINITY, r[0][CMIN][l] = INFINITY;
        r[0][EMAX][l] = r[0][EMIN][l] = -1.0;
    }
    for (int k = 0; k < d->n; k++) {
        const double (*o)[L] = (const double(*)[L])r[k & 1];
        double (*w)[L] = r[(k + 1) & 1];
        double *restrict w0 = w[CMAX], *restrict w1 = w[CMIN],
                         *restrict w2 = w[EMAX], *restrict w3 = w[EMIN];
        const double kd = (double)k;
#pragma omp simd
        for (int l = 0; l < L; l++) {
            v3 u, v;
            double cs = end_lane(d, x, k, l, &u, &v);
            int up = cs > o[CMAX][l], down = cs < o[CMIN][l];
            w0[l] = up ? cs : o[CMAX][l];
            w1[l] = down ? cs : o[CMIN][l];
            /* the end numbers by arithmetic (small integers: exact), as
               selects gcc 12 made them masked stores */
            double fu = (double)up, fd = (double)down;
            w2[l] = fu * kd + (1.0 - fu) * o[EMAX][l];
            w3[l] = fd * kd + (1.0 - fd) * o[EMIN][l];
        }
    }
    const double *emax = r[d->n & 1][EMAX], *emin = r[d->n & 1][EMIN];
    /* u, v of the largest (rows 0-5) and of the smallest cosine (6-11); 0
       where no end is ranked, as dihedral3 has it */
    double f[12][L];
    for (int l = 0; l < L; l++) {
        v3 w[4] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
        if (emax[l] >= 0.0)
            (void)end_lane(d, x, (int)emax[l], l, &w[0], &w[1]);
        if (emin[l] >= 0.0)
            (void)end_lane(d, x, (int)emin[l], l, &w[2], &w[3]);
        for (int i = 0; i < 4; i++) {
            f[3 * i][l] = w[i].x;
            f[3 * i + 1][l] = w[i].y;
            f[3 * i + 2][l] = w[i].z;
        }
    }
    double ylo[L], xlo[L], yhi[L], xhi[L];
    atan2_args_lanes(f, f + 3, ylo, xlo);
    atan2_args_lanes(f + 6, f + 9, yhi, xhi);
#pragma omp simd
    for (int l = 0; l < L; l++) {
        lo[l] = getme__angle(ylo[l], xlo[l]) * RAD2DEG;
        hi[l] = getme__angle(yhi[l], xhi[l]) * RAD2DEG;
    }
}

/* unit_det of corner c of the lanes into u */
static void corner_det_lanes(const double (*x)[L], const int8_t *c, double *u)
{
#pragma omp simd
    for (int l = 0; l < L; l++) {
        v3 o = v3_lane(x, c[0], l);
        u[l] = unit_det3(v3_sub(v3_lane(x, c[1], l), o),
                         v3_sub(v3_lane(x, c[2], l), o),
                         v3_sub(v3_lane(x, c[3], l), o));
    }
}

/* scaled_jacobian of tets: max_length_product and the corner at node 0. */
static void sj_tet_lanes(const double (*x)[L], double *sj)
{
    const getme_edge_table *et = &getme__edges[GETME_TET];
    double prod[4][L];
    for (int i = 0; i < 4; i++)
        for (int l = 0; l < L; l++)
            prod[i][l] = 1.0;
    for (int k = 0; k < et->num_edges; k++) {
        int a = et->node[k][0], b = et->node[k][1];
#pragma omp simd
        for (int l = 0; l < L; l++) {
            double len = v3_norm(v3_sub(v3_lane(x, b, l), v3_lane(x, a, l)));
            prod[a][l] *= len;
            prod[b][l] *= len;
        }
    }
#pragma omp simd
    for (int l = 0; l < L; l++) {
        double m = 0.0;
        for (int i = 0; i < 4; i++)
            m = max_nn(m, prod[i][l]);
        v3 o = v3_lane(x, 0, l), e0 = v3_sub(v3_lane(x, 1, l), o),
           e1 = v3_sub(v3_lane(x, 2, l), o), e2 = v3_sub(v3_lane(x, 3, l), o);
        sj[l] = div_or(M_SQRT2_ * v3_dot(e0, v3_cross(e1, e2)), m, 0.0);
    }
}

/* unit_det of the principal axes of hexes (scaled_jacobian's centre). */
static void hex_axes_lanes(const double (*x)[L], double *u)
{
#pragma omp simd
    for (int l = 0; l < L; l++) {
        v3 p[3];
        for (int d = 0; d < 3; d++) {
            p[d] = (v3){0, 0, 0};
            for (int i = 0; i < 4; i++) {
                v3 e = v3_sub(v3_lane(x, hex_axis[d][i][1], l),
                              v3_lane(x, hex_axis[d][i][0], l));
                p[d] = (v3){p[d].x + e.x, p[d].y + e.y, p[d].z + e.z};
            }
        }
        u[l] = unit_det3(p[0], p[1], p[2]);
    }
}

/* One corner of sicn3 in the lanes, into r; inlined with a constant
   type, so icn3's choice of W is made at compile time. */
KERNEL void sicn_corner_lanes(int type, const double (*x)[L],
                              const int8_t *c, double *r)
{
#pragma omp simd
    for (int l = 0; l < L; l++) {
        v3 o = v3_lane(x, c[0], l);
        r[l] = icn3(type, v3_sub(v3_lane(x, c[1], l), o),
                    v3_sub(v3_lane(x, c[2], l), o),
                    v3_sub(v3_lane(x, c[3], l), o));
    }
}

/* The corners' values first, then their minimum in a register: a running
   minimum in out, `out = min(out, r)`, became a branch around a masked
   store (vmaskmovpd, slow on Zen 3). */
static void sicn_lanes(int type, const double (*x)[L], double *out)
{
    int n;
    const int8_t(*corner)[4] = corners_of(type, &n);
    double r[8][L];
    for (int k = 0; k < n; k++)
        switch (type) {
        case GETME_TET: sicn_corner_lanes(GETME_TET, x, corner[k], r[k]); break;
        case GETME_HEX: sicn_corner_lanes(GETME_HEX, x, corner[k], r[k]); break;
        case GETME_PRISM: sicn_corner_lanes(GETME_PRISM, x, corner[k], r[k]); break;
        default: sicn_corner_lanes(GETME_PYRAMID, x, corner[k], r[k]); break;
        }
#pragma omp simd
    for (int l = 0; l < L; l++) {
        double m = INFINITY;
        for (int k = 0; k < n; k++)
            m = min_nn(m, r[k][l]);
        out[l] = m;
    }
}

/* Every measure of the GETME_LANES 3-D elements of type t in x into
   v[m * stride + l] (NaN where not defined for the type). */
static void measures3_lanes(int t, const dihedral_ends *de,
                            const double (*x)[L], double *v, int64_t stride)
{
    double q[L], lo[L], hi[L], sj[L], g[L], s[L], cu[8][L];
    if (!getme__quality_lanes(t, x, q))
        for (int l = 0; l < L; l++) {
            double xl[3 * GETME_MAX_NV];
            for (int i = 0; i < 3 * getme__nv[t]; i++)
                xl[i] = x[i][l];
            q[l] = getme__quality(t, xl);
        }
    dihedral_lanes(de, x, lo, hi);
    int n;
    const int8_t(*corner)[4] = corners_of(t, &n);
    if (t != GETME_TET)
        for (int k = 0; k < n; k++)
            corner_det_lanes(x, corner[k], cu[k]);
    for (int l = 0; l < L; l++)
        g[l] = NAN;
    if (t == GETME_TET) {
        sj_tet_lanes(x, sj);
#pragma omp simd
        for (int l = 0; l < L; l++)
            g[l] = gamma_tet4(v3_lane(x, 0, l), v3_lane(x, 1, l),
                              v3_lane(x, 2, l), v3_lane(x, 3, l));
    } else {
        double ax[L];
        if (t == GETME_HEX)
            hex_axes_lanes(x, ax);
        for (int l = 0; l < L; l++) {
            double m = INFINITY, ma = INFINITY;
            for (int k = 0; k < n; k++) {
                m = min_nn(m, cu[k][l]);
                ma = min_nn(ma, fabs(cu[k][l]));
            }
            sj[l] = t == GETME_HEX     ? min_nn(m, ax[l])
                    : t == GETME_PRISM ? 2.0 / M_SQRT3_ * m
                                       : min_nn(1.0, M_SQRT2_ * m);
            if (t == GETME_PRISM)
                g[l] = 2.0 / M_SQRT3_ * ma;
        }
    }
    sicn_lanes(t, x, s);
    memcpy(v + GETME_MEASURE_MEAN_RATIO * stride, q, sizeof q);
    memcpy(v + GETME_MEASURE_MIN_DIHEDRAL * stride, lo, sizeof lo);
    memcpy(v + GETME_MEASURE_MAX_DIHEDRAL * stride, hi, sizeof hi);
    memcpy(v + GETME_MEASURE_SCALED_JACOBIAN * stride, sj, sizeof sj);
    memcpy(v + GETME_MEASURE_GAMMA * stride, g, sizeof g);
    memcpy(v + GETME_MEASURE_SICN * stride, s, sizeof s);
}

/* Gather the n <= GETME_LANES elements from e of block bl into lanes
   (unused lanes repeat the last one) and measure them into v[m * stride
   + l], l < n. */
static void measure_group(const getme_mesh *mesh, const getme_block *bl,
                          int32_t e, int32_t n, double ysign,
                          const dihedral_ends *de, double *v, int64_t stride)
{
    double x[3 * GETME_MAX_NV][L];
    int nv = getme__nv[bl->type];
    /* straight into the lanes (getme__gather_local's values) */
    for (int l = 0; l < L; l++) {
        const int32_t *c = bl->conn + (int64_t)(e + (l < n ? l : n - 1)) * nv;
        for (int i = 0; i < nv; i++) {
            const double *p = mesh->coords + 3 * (int64_t)c[i];
            x[3 * i][l] = p[0];
            x[3 * i + 1][l] = ysign * p[1];
            x[3 * i + 2][l] = p[2];
        }
    }
    if (n == L) {
        measures3_lanes(bl->type, de, (const double(*)[L])x, v, stride);
        return;
    }
    double w[GETME_NUM_MEASURES * L];
    measures3_lanes(bl->type, de, (const double(*)[L])x, w, L);
    for (int m = 0; m < GETME_NUM_MEASURES; m++)
        memcpy(v + m * stride, w + m * L, (size_t)n * sizeof *v);
}

/* Elements per tile of getme_mesh_measure_all: the tile's values of every
   measure (6 doubles per element, 1.5 MiB, measure by measure:
   v[m * MEASURE_TILE + i]) are computed in parallel, each thread reducing
   its contiguous part at once (counts, extremes, histograms: exact,
   merged in thread order), then the sums of the means are added serially
   in element order. */
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

/* How many groups of GETME_LANES elements ahead the 3-D sweep prefetches
   the nodes (the caller's element order can be unrelated to its node
   order). */
enum { PREFETCH_GROUPS = 2 };

/* add_stat without the sum: what a thread's part of a tile can reduce in
   any order of threads (count, first extreme, histogram). */
static void add_part(getme_measure_stats *s, double v, int32_t e)
{
    double sum = 0.0;
    add_stat(s, v, e, &sum);
}

/* Add p, the statistics of elements after those of s, into s (first
   extremes win ties: the serial sweep's min_element and max_element). */
static void merge_part(getme_measure_stats *s, const getme_measure_stats *p)
{
    if (!p->num_elements)
        return;
    if (s->num_elements == 0 || p->min < s->min) {
        s->min = p->min;
        s->min_element = p->min_element;
    }
    if (s->num_elements == 0 || p->max > s->max) {
        s->max = p->max;
        s->max_element = p->max_element;
    }
    s->num_elements += p->num_elements;
    s->num_negative += p->num_negative;
    s->num_below += p->num_below;
    for (int b = 0; b < GETME_HIST_BINS; b++)
        s->histogram[b] += p->histogram[b];
}

/*
 * One measure's statistics of a thread's full groups of GETME_LANES 3-D
 * elements, kept per lane so that the reduction is vector instructions
 * (the scalar add_stat per element and measure cost as much as half the
 * lane kernels): in lane l, the elements l, l + L, ... of the groups in
 * order, each lane's extremes the first of its elements to reach them.
 * lanes_into turns them into add_stat's statistics: the extreme of the
 * lanes, on ties the element first in the mesh, is the serial sweep's.
 * The histogram bins are counted from the lanes' bin numbers, bin
 * GETME_HIST_BINS for values not in the histogram.
 */
typedef struct lane_stats {
    double min[L], max[L];
    int64_t min_element[L], max_element[L]; /* -1: no element yet */
    int64_t num_elements[L], num_negative[L], num_below[L];
    int64_t histogram[GETME_HIST_BINS + 1];
} lane_stats;

static void lanes_init(lane_stats *ls)
{
    memset(ls, 0, sizeof *ls);
    for (int l = 0; l < L; l++)
        ls->min_element[l] = ls->max_element[l] = -1;
}

/* add_stat of the values v[l] of elements g + l, as the serial sweep
   computes each element's bin (t / w only where w is not 1). */
static void lanes_add(lane_stats *ls, const double *v, int32_t g, double lo,
                      double w)
{
    int32_t bin[L];
#pragma omp simd
    for (int l = 0; l < L; l++) {
        double x = v[l];
        int64_t e = (int64_t)g + l;
        int64_t ok = x == x; /* not NaN: counted */
        int64_t first = ok & (ls->min_element[l] < 0);
        int64_t down = (x < ls->min[l]) | first, up = (x > ls->max[l]) | first;
        ls->min[l] = down ? x : ls->min[l];
        ls->min_element[l] = down ? e : ls->min_element[l];
        ls->max[l] = up ? x : ls->max[l];
        ls->max_element[l] = up ? e : ls->max_element[l];
        ls->num_elements[l] += ok;
        ls->num_negative[l] += x < 0.0;
        int64_t below = x < lo;
        ls->num_below[l] += below;
        /* NaN and values below lo get no bin number from the conversion
           (out of range) */
        int32_t k = hist_bin(ok & !below ? x - lo : 0.0, w);
        bin[l] = ok & !below ? k : GETME_HIST_BINS;
    }
    for (int l = 0; l < L; l++)
        ls->histogram[bin[l]]++;
}

/* The statistics of ls into s (init_stats'd, no element yet). */
static void lanes_into(const lane_stats *ls, getme_measure_stats *s)
{
    for (int l = 0; l < L; l++) {
        s->num_elements += ls->num_elements[l];
        s->num_negative += ls->num_negative[l];
        s->num_below += ls->num_below[l];
        int64_t e = ls->min_element[l];
        if (e >= 0 && (s->min_element < 0 || ls->min[l] < s->min ||
                       (ls->min[l] == s->min && e < s->min_element))) {
            s->min = ls->min[l];
            s->min_element = (int32_t)e;
        }
        e = ls->max_element[l];
        if (e >= 0 && (s->max_element < 0 || ls->max[l] > s->max ||
                       (ls->max[l] == s->max && e < s->max_element))) {
            s->max = ls->max[l];
            s->max_element = (int32_t)e;
        }
    }
    for (int b = 0; b < GETME_HIST_BINS; b++)
        s->histogram[b] += ls->histogram[b];
}

/* The measures of n elements from e0 of block bl into v (v[m *
   MEASURE_TILE + i]), their mean ratios into q + bl->first + e0 if q, and
   each thread's reduction into part[thread * GETME_NUM_MEASURES...]. */
static void tile_measures(const getme_mesh *mesh, const getme_block *bl,
                          int32_t e0, int32_t n, double ysign,
                          const dihedral_ends *de, const uint8_t *defined,
                          double *v, double *q, getme_measure_stats *part,
                          int nt)
{
    int dim3 = getme_type_dim((getme_elem_type)bl->type) == 3;
    int32_t step = dim3 ? L : 1;
    /* also the parts of threads the runtime does not start */
    for (int k = 0; k < nt * GETME_NUM_MEASURES; k++)
        init_stats(&part[k], k % GETME_NUM_MEASURES);
#pragma omp parallel num_threads(nt)
    {
        /* p: the elements reduced one at a time (planar types, a last
           group of fewer than L), which come after the full groups of
           the thread's part */
        getme_measure_stats p[GETME_NUM_MEASURES], r[GETME_NUM_MEASURES];
        lane_stats ls[GETME_NUM_MEASURES];
        double lo[GETME_NUM_MEASURES], w[GETME_NUM_MEASURES];
        for (int m = 0; m < GETME_NUM_MEASURES; m++) {
            init_stats(&p[m], m);
            lanes_init(&ls[m]);
            lo[m] = p[m].hist_lo;
            w[m] = p[m].hist_hi - p[m].hist_lo;
        }
        /* static: thread k's groups come before thread k + 1's */
#pragma omp for schedule(static)
        for (int32_t i = 0; i < n; i += step) {
            int32_t k = n - i < step ? n - i : step;
            int32_t g = bl->first + e0 + i;
            if (dim3) {
                getme__prefetch_local(mesh, bl, e0 + i + PREFETCH_GROUPS * L, L);
                measure_group(mesh, bl, e0 + i, k, ysign, de, v + i,
                              MEASURE_TILE);
            } else {
                double vi[GETME_NUM_MEASURES];
                getme__prefetch_local(mesh, bl, e0 + i + GETME_PREFETCH_AHEAD, 1);
                element_measures(mesh, bl, e0 + i, ysign, de, defined, vi);
                for (int m = 0; m < GETME_NUM_MEASURES; m++)
                    v[(int64_t)m * MEASURE_TILE + i] = vi[m];
            }
            if (q)
                memcpy(q + g, v + (int64_t)GETME_MEASURE_MEAN_RATIO * MEASURE_TILE + i,
                       (size_t)k * sizeof *q);
            for (int m = 0; m < GETME_NUM_MEASURES; m++) {
                const double *vm = v + (int64_t)m * MEASURE_TILE + i;
                if (k == L && dim3) {
                    lanes_add(&ls[m], vm, g, lo[m], w[m]);
                    continue;
                }
                for (int32_t j = 0; j < k; j++)
                    if (!isnan(vm[j]))
                        add_part(&p[m], vm[j], g + j);
            }
        }
        for (int m = 0; m < GETME_NUM_MEASURES; m++) {
            init_stats(&r[m], m);
            lanes_into(&ls[m], &r[m]);
            merge_part(&r[m], &p[m]);
        }
        memcpy(part + (int64_t)omp_get_thread_num() * GETME_NUM_MEASURES, r,
               sizeof r);
    }
}

getme_status getme_mesh_measure_all_qualities(getme_mesh *mesh,
                                              getme_measure_stats *stats,
                                              double *q)
{
    if (!mesh || !stats)
        return GETME_ERR_ARGUMENT;
    for (int k = 0; k < GETME_NUM_TYPES * GETME_NUM_MEASURES; k++)
        init_stats(&stats[k], k % GETME_NUM_MEASURES);
    int nt = omp_get_max_threads();
    double *v =
        getme__malloc((size_t)MEASURE_TILE * GETME_NUM_MEASURES * sizeof *v);
    getme_measure_stats *part =
        getme__malloc((size_t)nt * GETME_NUM_MEASURES * sizeof *part);
    if (!v || !part) {
        free(v);
        free(part);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
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
        getme_measure_stats *s = stats + t * GETME_NUM_MEASURES;
        double *st = sum[t];
        for (int32_t e0 = 0; e0 < bl->count; e0 += MEASURE_TILE) {
            int32_t n = bl->count - e0 < MEASURE_TILE ? bl->count - e0
                                                       : MEASURE_TILE;
            tile_measures(mesh, bl, e0, n, ysign, &de, defined, v, q, part,
                          nt);
            for (int k = 0; k < nt; k++)
                for (int m = 0; m < GETME_NUM_MEASURES; m++)
                    merge_part(&s[m], &part[k * GETME_NUM_MEASURES + m]);
            /* the sums in element order, as one serial sweep adds them
               (six independent chains) */
            for (int32_t i = 0; i < n; i++)
                for (int m = 0; m < GETME_NUM_MEASURES; m++) {
                    double x = v[(int64_t)m * MEASURE_TILE + i];
                    if (!isnan(x))
                        st[m] += x;
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
    free(part);
    return GETME_OK;
}

getme_status getme_mesh_measure_all(getme_mesh *mesh,
                                    getme_measure_stats *stats)
{
    return getme_mesh_measure_all_qualities(mesh, stats, NULL);
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
