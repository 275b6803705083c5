/*
 * planar.c -- planar surface meshes: the plane, the frame, the
 * orientation.
 *
 * libgetme smooths planar meshes in the xy plane.  A Gmsh surface mesh may
 * lie in any plane, so we rotate it into a frame (e1, e2, normal) whose xy
 * plane is the mesh plane, smooth there, and rotate moved nodes back.  When
 * every node already has the same z the frame is the identity, so nothing
 * but x and y of free nodes ever changes.  Surfaces that are not planar, or
 * several surfaces that do not share one plane, are refused: moving their
 * nodes in a plane would pull them off the geometry.
 *
 * Gmsh orients each surface mesh like its surface, so two surfaces of one
 * plane can be oriented oppositely; libgetme wants one orientation, so the
 * elements of clockwise surfaces are handed over with reversed node order
 * (this only changes our copy, never the Gmsh model).  Second-order
 * elements (tri6, quad8, quad9) are reversed with their mid-edge nodes, so
 * each mid-node stays on its edge (reverse_element).
 */
#include "model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Relative tolerance for "on the plane": Gmsh's own geometric tolerance is
   1e-8 of the model size. */
#define PLANE_TOL 1e-8

static void sub3(const double *a, const double *b, double *r)
{
    r[0] = a[0] - b[0];
    r[1] = a[1] - b[1];
    r[2] = a[2] - b[2];
}

static void cross3(const double *a, const double *b, double *r)
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double *a) { return sqrt(dot3(a, a)); }

/* Corners and all nodes of an element of a planar block (MSH type: 2 tri,
   3 quad, 9 tri6, 16 quad8, 10 quad9). */
static int corners_of(const getme__model_block *b)
{
    return getme__msh_type_corners(b->type, 2) == GETME_TRI ? 3 : 4;
}

static int nodes_of(const getme__model_block *b)
{
    return getme__msh_type_nodes(b->type, NULL);
}

/* Twice the area vector of a tri, or of a quad through its diagonals. */
static void element_normal(const double *xyz, const int32_t *c, int nv,
                           double *nrm)
{
    double a[3], b[3];
    if (nv == 3) {
        sub3(xyz + 3 * c[1], xyz + 3 * c[0], a);
        sub3(xyz + 3 * c[2], xyz + 3 * c[0], b);
    } else {
        sub3(xyz + 3 * c[2], xyz + 3 * c[0], a);
        sub3(xyz + 3 * c[3], xyz + 3 * c[1], b);
    }
    cross3(a, b, nrm);
}

static double diagonal(const double *xyz, int32_t n)
{
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
    double hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], xyz[3 * i + k]);
            hi[k] = fmax(hi[k], xyz[3 * i + k]);
        }
    double d[3];
    sub3(hi, lo, d);
    return n ? norm3(d) : 0.0;
}

int getme__all_same_z(const double *xyz, int32_t n)
{
    for (int32_t i = 1; i < n; i++)
        if (xyz[3 * i + 2] != xyz[2])
            return 0;
    return 1;
}

/* Blocks [b0, b1) belong to one entity (they are read entity by entity). */
static size_t entity_end(const getme__model_block *blocks, size_t nb,
                         size_t b0)
{
    size_t b1 = b0 + 1;
    while (b1 < nb && blocks[b1].tag == blocks[b0].tag)
        b1++;
    return b1;
}

/* Unit normal of one surface: element normals summed with a common sign. */
static int surface_normal(const double *xyz, const getme__model_block *blocks, size_t b0,
                          size_t b1, double *nrm)
{
    double ref[3] = {0, 0, 0}, e[3];
    nrm[0] = nrm[1] = nrm[2] = 0;
    for (size_t b = b0; b < b1; b++) {
        int nv = corners_of(&blocks[b]), stride = nodes_of(&blocks[b]);
        for (int32_t i = 0; i < blocks[b].count; i++) {
            element_normal(xyz, blocks[b].conn + (size_t)stride * i, nv, e);
            if (norm3(ref) == 0)
                memcpy(ref, e, sizeof ref);
            double s = dot3(e, ref) < 0 ? -1.0 : 1.0;
            for (int k = 0; k < 3; k++)
                nrm[k] += s * e[k];
        }
    }
    double len = norm3(nrm);
    if (!(len > 0))
        return 0;
    for (int k = 0; k < 3; k++)
        nrm[k] /= len;
    return 1;
}

/* Largest distance of the surface's nodes to the plane (p0, nrm). */
static double plane_distance(const double *xyz, const getme__model_block *blocks,
                             size_t b0, size_t b1,
                             const double *p0, const double *nrm)
{
    double worst = 0, d[3];
    for (size_t b = b0; b < b1; b++) {
        int nv = nodes_of(&blocks[b]);
        for (int64_t i = 0; i < (int64_t)blocks[b].count * nv; i++) {
            sub3(xyz + 3 * blocks[b].conn[i], p0, d);
            worst = fmax(worst, fabs(dot3(d, nrm)));
        }
    }
    return worst;
}

static getme_status fit_plane(getme__frame *f, const double *xyz, int32_t n,
                              const getme__model_block *blocks, size_t nb,
                              char *msg, size_t size)
{
    double tol = PLANE_TOL * diagonal(xyz, n), nrm[3], first[3] = {0, 0, 0};
    const double *p0 = xyz + 3 * blocks[0].conn[0];
    int first_tag = blocks[0].tag;
    for (size_t b0 = 0; b0 < nb; b0 = entity_end(blocks, nb, b0)) {
        size_t b1 = entity_end(blocks, nb, b0);
        int tag = blocks[b0].tag;
        const double *q0 = xyz + 3 * blocks[b0].conn[0];
        if (!surface_normal(xyz, blocks, b0, b1, nrm)) {
            snprintf(msg, size,
                     "Surface %d has a degenerate mesh (zero area)", tag);
            return GETME_ERR_INVALID_MESH;
        }
        double d = plane_distance(xyz, blocks, b0, b1, q0, nrm);
        if (d > tol) {
            snprintf(msg, size,
                     "Surface %d is not planar (a node lies %.3g from its "
                     "mean plane): only planar surface meshes can be "
                     "smoothed",
                     tag, d);
            return GETME_ERR_TOPOLOGY;
        }
        if (b0 == 0) {
            memcpy(first, nrm, sizeof first);
            continue;
        }
        double c[3];
        cross3(first, nrm, c);
        if (norm3(c) > PLANE_TOL * 100 ||
            plane_distance(xyz, blocks, b0, b1, p0, first) > tol) {
            snprintf(msg, size,
                     "Surfaces %d and %d do not lie in one plane: smooth "
                     "them in separate calls",
                     first_tag, tag);
            return GETME_ERR_TOPOLOGY;
        }
    }
    /* e1: the unit axis most orthogonal to the normal, made orthogonal. */
    double axis[3] = {0, 0, 0}, e1[3], e2[3];
    int k = fabs(first[0]) < fabs(first[1])
                ? (fabs(first[0]) < fabs(first[2]) ? 0 : 2)
                : (fabs(first[1]) < fabs(first[2]) ? 1 : 2);
    axis[k] = 1;
    double t = dot3(axis, first);
    for (int i = 0; i < 3; i++)
        e1[i] = axis[i] - t * first[i];
    double len = norm3(e1);
    for (int i = 0; i < 3; i++)
        e1[i] /= len;
    cross3(first, e1, e2);
    f->rotated = 1;
    memcpy(f->origin, p0, sizeof f->origin);
    memcpy(f->axis[0], e1, sizeof e1);
    memcpy(f->axis[1], e2, sizeof e2);
    memcpy(f->axis[2], first, sizeof first);
    return GETME_OK;
}

static void to_local(const getme__frame *f, double *xyz, int32_t n)
{
    for (int32_t i = 0; i < n; i++) {
        double d[3];
        sub3(xyz + 3 * i, f->origin, d);
        for (int k = 0; k < 3; k++)
            xyz[3 * i + k] = dot3(d, f->axis[k]);
    }
}

void getme__frame_to_global(const getme__frame *f, const double *local,
                        double *global)
{
    if (!f->rotated) {
        memcpy(global, local, 3 * sizeof *global);
        return;
    }
    for (int k = 0; k < 3; k++)
        global[k] = f->origin[k] + local[0] * f->axis[0][k] +
                    local[1] * f->axis[1][k] + local[2] * f->axis[2][k];
}

/* Signed area (z of the area vector) in the local xy plane. */
static double signed_area(const double *xyz, const int32_t *c, int nv)
{
    double s = 0;
    for (int i = 0; i < nv; i++) {
        const double *a = xyz + 3 * c[i], *b = xyz + 3 * c[(i + 1) % nv];
        s += a[0] * b[1] - a[1] * b[0];
    }
    return 0.5 * s;
}

/* Corners 0 1 .. n-1 become 0 n-1 .. 1 (swap 1 and n-1, enough for n = 3,
   4).  Mid-edge node k of edge (k, k+1) then belongs to the new edge n-1-k,
   so the mid-edge list (Gmsh order: after the corners) is reversed; a
   quad9's centre stays. */
static void reverse_element(int32_t *c, int nv, int all)
{
    int32_t t = c[1];
    c[1] = c[nv - 1];
    c[nv - 1] = t;
    for (int i = 0, j = nv - 1; all > nv && i < j; i++, j--) {
        t = c[nv + i];
        c[nv + i] = c[nv + j];
        c[nv + j] = t;
    }
}

double getme__planar_area(const double *xyz, const int32_t *conn,
                          int32_t count, int nv, int stride)
{
    double total = 0;
    for (int32_t i = 0; i < count; i++)
        total += signed_area(xyz, conn + (size_t)stride * i, nv);
    return total;
}

void getme__planar_reverse(int32_t *conn, int32_t count, int nv, int stride)
{
    for (int32_t i = 0; i < count; i++)
        reverse_element(conn + (size_t)stride * i, nv, stride);
}

static void orient_surfaces(const double *xyz,
                            const getme__model_block *blocks, size_t nb)
{
    for (size_t b0 = 0; b0 < nb; b0 = entity_end(blocks, nb, b0)) {
        size_t b1 = entity_end(blocks, nb, b0);
        double total = 0;
        for (size_t b = b0; b < b1; b++)
            total += getme__planar_area(xyz, blocks[b].conn, blocks[b].count,
                                        corners_of(&blocks[b]),
                                        nodes_of(&blocks[b]));
        if (total >= 0)
            continue;
        for (size_t b = b0; b < b1; b++)
            getme__planar_reverse(blocks[b].conn, blocks[b].count,
                                  corners_of(&blocks[b]), nodes_of(&blocks[b]));
    }
}

getme_status getme__planar_prepare(getme__frame *frame, double *xyz,
                                   int32_t n, getme__model_block *blocks,
                                   size_t nb, char *msg, size_t size)
{
    memset(frame, 0, sizeof *frame);
    if (!getme__all_same_z(xyz, n)) {
        getme_status st = fit_plane(frame, xyz, n, blocks, nb, msg, size);
        if (st != GETME_OK)
            return st;
        to_local(frame, xyz, n);
    }
    orient_surfaces(xyz, blocks, nb);
    return GETME_OK;
}
