/*
 * highorder_ws.c -- dependent nodes in the smoother's workspace.
 *
 * The smoother sees the linear elements the corners define; a second-order
 * element's other nodes are dependent nodes, each a pure function of the
 * corners of its own edge, face or (hex27's centre) body and of the input
 * coordinates (docs/highorder.md):
 *
 *   x = S(corners) + M(corners) * r
 *
 * S is the straight position (edge midpoint, mean of the face's or body's
 * corners: the isoparametric position of the node in the linear/trilinear
 * element), r the input's offset from it in the entity's own frame, M that
 * frame now: for an edge the similarity (minimal rotation and scaling)
 * taking the input edge vector to the current one, for a quad face the
 * bilinear map's two tangents at its centre and their normal, for the body
 * the trilinear map's Jacobian at the centre.  An input node exactly at S
 * stays exactly at S.  Because a node depends only on corners of every
 * element that holds it, the relaxation's reset argument (relax.c) holds
 * for the check at all nodes too: an element whose corners are back at
 * their old coordinates has its old dependent nodes, hence is valid.  A
 * node whose corners all have their input coordinates keeps its input
 * coordinates bit for bit, and a pinned node never moves.
 */
#include "highorder.h"
#include "workspace.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void getme__ho_free(getme_ho_ws *ho)
{
    if (!ho)
        return;
    free(ho->node);
    free(ho->nc);
    free(ho->pinned);
    free(ho->straight);
    free(ho->cn);
    free(ho->ref);
    free(ho->x0);
    free(ho->etype);
    free(ho->eptr);
    free(ho->eho);
    free(ho->info);
    free(ho->floor);
    free(ho);
}

static void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Straight position of the entity with nc corners c at coords X. */
static void straight_pos(int nc, const int32_t *c, const double *X, double *s)
{
    double w = 1.0 / nc;
    for (int d = 0; d < 3; d++) {
        double sum = 0.0;
        for (int i = 0; i < nc; i++)
            sum += X[3 * (int64_t)c[i] + d];
        s[d] = w * sum;
    }
}

/* Signs of the hex corners along the reference axes (Gmsh's order). */
static const int8_t hex_sign[8][3] = {
    {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
    {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};

/* The frame (columns f[0..2]) of a face (nc 4) or body (nc 8). */
static void frame(int nc, const int32_t *c, const double *X, double f[3][3])
{
    memset(f, 0, 9 * sizeof(double));
    if (nc == 4) { /* quad p0..p3 in cyclic order */
        const double *p[4];
        for (int i = 0; i < 4; i++)
            p[i] = X + 3 * (int64_t)c[i];
        for (int d = 0; d < 3; d++) {
            f[0][d] = (p[1][d] + p[2][d]) - (p[0][d] + p[3][d]);
            f[1][d] = (p[2][d] + p[3][d]) - (p[0][d] + p[1][d]);
        }
        cross(f[0], f[1], f[2]);
        double n = sqrt(sqrt(dot(f[2], f[2])));
        if (n > 0.0)
            for (int d = 0; d < 3; d++)
                f[2][d] /= n;
        return;
    }
    for (int i = 0; i < 8; i++) {
        const double *p = X + 3 * (int64_t)c[i];
        for (int a = 0; a < 3; a++)
            for (int d = 0; d < 3; d++)
                f[a][d] += hex_sign[i][a] * p[d];
    }
}

/* Solve f r = d (columns f[a]) by Cramer's rule; 0 if singular. */
static void solve3(double f[3][3], const double *d, double *r)
{
    double c12[3], c20[3], c01[3];
    cross(f[1], f[2], c12);
    cross(f[2], f[0], c20);
    cross(f[0], f[1], c01);
    double det = dot(f[0], c12);
    if (!(fabs(det) > 0.0)) {
        r[0] = r[1] = r[2] = 0.0;
        return;
    }
    r[0] = dot(d, c12) / det;
    r[1] = dot(d, c20) / det;
    r[2] = dot(d, c01) / det;
}

/* Position of dependent node h with corners at coords X. */
static void ho_pos(const getme_ho_ws *ho, int32_t h, const double *X,
                   double *out)
{
    const double *x0 = ho->x0;
    const double *orig = x0 + 3 * (int64_t)ho->node[h];
    int nc = ho->nc[h];
    const int32_t *c = ho->cn + 8 * (int64_t)h;
    int same = !ho->pinned[h];
    for (int i = 0; i < nc && same; i++) {
        const double *a = X + 3 * (int64_t)c[i], *b = x0 + 3 * (int64_t)c[i];
        same = a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
    }
    if (ho->pinned[h] || same) {
        out[0] = orig[0], out[1] = orig[1], out[2] = orig[2];
        return;
    }
    double s[3], d[3];
    straight_pos(nc, c, X, s);
    const double *r = ho->ref + 3 * (int64_t)h;
    if (ho->straight[h]) {
        out[0] = s[0], out[1] = s[1], out[2] = s[2];
        return;
    }
    if (nc == 2) {
        const double *a0 = x0 + 3 * (int64_t)c[0], *b0 = x0 + 3 * (int64_t)c[1];
        const double *a = X + 3 * (int64_t)c[0], *b = X + 3 * (int64_t)c[1];
        double u[3] = {b0[0] - a0[0], b0[1] - a0[1], b0[2] - a0[2]};
        double v[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double lu = sqrt(dot(u, u)), lv = sqrt(dot(v, v));
        for (int k = 0; k < 3; k++)
            u[k] /= lu, v[k] /= lv;
        double cs = dot(u, v), w[3], wr[3];
        cross(u, v, w);
        cross(w, r, wr);
        double scale = lv / lu;
        if (1.0 + cs > 1e-12) {
            double f = dot(w, r) / (1.0 + cs);
            for (int k = 0; k < 3; k++)
                d[k] = scale * (cs * r[k] + wr[k] + f * w[k]);
        } else { /* the edge turned around: never valid, any answer */
            for (int k = 0; k < 3; k++)
                d[k] = -scale * r[k];
        }
    } else {
        double f[3][3];
        frame(nc, c, X, f);
        for (int k = 0; k < 3; k++)
            d[k] = f[0][k] * r[0] + f[1][k] * r[1] + f[2][k] * r[2];
    }
    for (int k = 0; k < 3; k++)
        out[k] = s[k] + d[k];
}

/* Corner a before corner b: by input coordinates (x, then y, then z), not
   by index, so that the result does not depend on how the caller numbered
   the nodes (two corners of one valid element never coincide). */
static int before(const double *x0, int32_t a, int32_t b)
{
    const double *p = x0 + 3 * (int64_t)a, *q = x0 + 3 * (int64_t)b;
    for (int d = 0; d < 3; d++)
        if (p[d] != q[d])
            return p[d] < q[d];
    return a < b;
}

/* Canonical corner order of an entity, so that every element holding a
   dependent node computes the same function: edges from the first corner
   (before()), quad faces from the first corner towards its first
   neighbour; a body keeps its element's order (one element holds it). */
static void canonical(int nc, const int32_t *in, const double *x0,
                      int32_t *out)
{
    if (nc == 2) {
        int s = before(x0, in[1], in[0]);
        out[0] = in[s];
        out[1] = in[1 - s];
    } else if (nc == 4) {
        int m = 0;
        for (int i = 1; i < 4; i++)
            if (before(x0, in[i], in[m]))
                m = i;
        int dir = before(x0, in[(m + 1) % 4], in[(m + 3) % 4]) ? 1 : 3;
        for (int i = 0; i < 4; i++)
            out[i] = in[(m + dir * i) % 4];
    } else {
        memcpy(out, in, (size_t)nc * sizeof *out);
    }
}

static int bl_nv(const getme_ho_block *bl) { return getme__ho_nv[bl->type]; }

getme_status getme__ho_attach(getme_ws *ws, getme_mesh *mesh)
{
    ws->ho = NULL;
    if (!mesh->ho || mesh->ho->num_elements == 0)
        return GETME_OK;
    const getme_ho_mesh *hm = mesh->ho;
    getme_ho_ws *ho = getme__calloc(1, sizeof *ho);
    size_t nn = (size_t)ws->nn + 1, ne = (size_t)ws->ne + 1;
    int32_t *inv_node = getme__malloc(nn * sizeof *inv_node);
    int32_t *inv_elem = getme__malloc(ne * sizeof *inv_elem);
    /* hid: internal node -> h, or -1 */
    int32_t *hid = getme__malloc(nn * sizeof *hid);
    getme_status st = GETME_ERR_NOMEM;
    if (!ho || !inv_node || !inv_elem || !hid)
        goto fail;
    ho->info = getme__calloc(GETME_NUM_HO_TYPES, sizeof *ho->info);
    ho->etype = getme__malloc(ne);
    ho->eptr = getme__calloc(ne, sizeof *ho->eptr);
    ho->x0 = getme__malloc(3 * nn * sizeof *ho->x0);
    if (!ho->info || !ho->etype || !ho->eptr || !ho->x0)
        goto fail;
    memcpy(ho->x0, ws->x, (size_t)ws->nn * 3 * sizeof *ho->x0);
    for (int32_t i = 0; i < ws->nn; i++)
        inv_node[ws->node_orig[i]] = i, hid[i] = -1;
    for (int32_t e = 0; e < ws->ne; e++)
        inv_elem[ws->elem_orig[e]] = e;
    memset(ho->etype, 0xff, ne);
    int have[GETME_NUM_HO_TYPES] = {0};
    for (int b = 0; b < hm->num_blocks; b++) {
        const getme_ho_block *bl = &hm->blocks[b];
        if (!have[bl->type]) {
            have[bl->type] = 1;
            if (getme__ho_info_init(bl->type, &ho->info[bl->type])) {
                st = getme__fail(mesh, GETME_ERR_ARGUMENT,
                                 "internal: %s tables are singular",
                                 getme_ho_type_name((getme_ho_type)bl->type));
                goto fail;
            }
        }
        for (int32_t l = 0; l < bl->count; l++) {
            int32_t e = inv_elem[bl->first + l];
            ho->etype[e] = (int8_t)bl->type;
            ho->eptr[e + 1] = getme__ho_nv[bl->type] -
                              getme__nv[getme__ho_lin[bl->type]];
        }
    }
    for (int32_t e = 0; e < ws->ne; e++)
        ho->eptr[e + 1] += ho->eptr[e];
    int64_t slots = ho->eptr[ws->ne];
    ho->eho = getme__malloc((size_t)(slots + 1) * sizeof *ho->eho);
    if (!ho->eho)
        goto fail;
    /* Number the dependent nodes in internal element order (deterministic
       and independent of the thread count), then fill them in. */
    int32_t nh = 0;
    for (int32_t e = 0; e < ws->ne; e++) {
        int t = ho->etype[e];
        if (t < 0)
            continue;
        int32_t ec = ws->elem_orig[e];
        const getme_ho_block *bl = hm->blocks;
        while (ec < bl->first || ec >= bl->first + bl->count)
            bl++;
        const int32_t *conn = bl->conn + (int64_t)(ec - bl->first) * bl_nv(bl);
        for (int k = ho->info[t].nlin; k < ho->info[t].nv; k++)
            if (hid[inv_node[conn[k]]] < 0)
                hid[inv_node[conn[k]]] = nh++;
    }
    ho->node = getme__malloc(((size_t)nh + 1) * sizeof *ho->node);
    ho->nc = getme__calloc((size_t)nh + 1, 1);
    ho->cn = getme__malloc(((size_t)nh + 1) * 8 * sizeof *ho->cn);
    if (!ho->node || !ho->nc || !ho->cn)
        goto fail;
    for (int32_t e = 0; e < ws->ne; e++) {
        int t = ho->etype[e];
        if (t < 0)
            continue;
        const getme_ho_info *in = &ho->info[t];
        int32_t ec = ws->elem_orig[e];
        const getme_ho_block *bl = hm->blocks;
        while (ec < bl->first || ec >= bl->first + bl->count)
            bl++;
        const int32_t *conn = bl->conn + (int64_t)(ec - bl->first) * in->nv;
        const int32_t *lc = getme__ws_nodes(ws, in->lin, e);
        for (int k = in->nlin; k < in->nv; k++) {
            int32_t u = inv_node[conn[k]];
            int nc = in->ncorner[k];
            int32_t ent[8], can[8];
            for (int i = 0; i < nc; i++)
                ent[i] = lc[in->corner[k][i]];
            canonical(nc, ent, ho->x0, can);
            if (ws->star_ptr[u + 1] > ws->star_ptr[u]) {
                st = getme__fail(mesh, GETME_ERR_TOPOLOGY,
                                 "node %d is a mid-node of element %d and a "
                                 "corner of another element",
                                 (int)conn[k], (int)ec);
                goto fail;
            }
            int32_t h = hid[u];
            if (ho->nc[h] == 0) { /* first element holding it */
                ho->node[h] = u;
                ho->nc[h] = (uint8_t)nc;
                memcpy(ho->cn + 8 * (int64_t)h, can, (size_t)nc * sizeof *can);
            } else if (nc == 8 || ho->nc[h] != nc ||
                       memcmp(ho->cn + 8 * (int64_t)h, can,
                              (size_t)nc * sizeof *can) != 0) {
                st = getme__fail(mesh, GETME_ERR_TOPOLOGY,
                                 "node %d is a mid-node of element %d and of "
                                 "another edge or face elsewhere",
                                 (int)conn[k], (int)ec);
                goto fail;
            }
            ho->eho[ho->eptr[e] + k - in->nlin] = h;
        }
    }
    ho->nh = nh;
    ho->pinned = getme__malloc((size_t)nh + 1);
    ho->straight = getme__malloc((size_t)nh + 1);
    ho->ref = getme__malloc(((size_t)nh + 1) * 3 * sizeof *ho->ref);
    if (!ho->pinned || !ho->straight || !ho->ref)
        goto fail;
    for (int32_t h = 0; h < nh; h++) {
        int32_t u = ho->node[h];
        const int32_t *c = ho->cn + 8 * (int64_t)h;
        int all_fixed = 1;
        for (int i = 0; i < ho->nc[h]; i++)
            all_fixed &= ws->fixed[c[i]] != 0;
        /* fixed by the caller (not merely "used by no linear element",
           which every dependent node is), or on a fixed edge/face */
        ho->pinned[h] = all_fixed ||
                        (mesh->fixed[ws->node_orig[u]] & ~GETME__FIXED_UNUSED);
        double s[3], d[3];
        straight_pos(ho->nc[h], c, ho->x0, s);
        for (int k = 0; k < 3; k++)
            d[k] = ho->x0[3 * (int64_t)u + k] - s[k];
        ho->straight[h] = d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0;
        double *r = ho->ref + 3 * (int64_t)h;
        if (ho->nc[h] == 2) {
            r[0] = d[0], r[1] = d[1], r[2] = d[2];
        } else {
            double f[3][3];
            frame(ho->nc[h], c, ho->x0, f);
            solve3(f, d, r);
        }
    }
    /* A tet10 or tri6 whose dependent nodes are all straight and move with
       their corners (not pinned, or pinned on fixed corners) is the linear
       element for good: its Jacobian is constant, positive exactly when
       its mean ratio is.  Its check at all nodes is skipped (etype -1);
       getme__ho_store still places its nodes. */
    for (int32_t e = 0; e < ws->ne; e++) {
        int t = ho->etype[e];
        if (t != GETME_TET10 && t != GETME_TRI6)
            continue;
        int affine = 1;
        for (int64_t s = ho->eptr[e]; s < ho->eptr[e + 1] && affine; s++) {
            int32_t h = ho->eho[s];
            int fixed_corners = 1;
            for (int i = 0; i < ho->nc[h]; i++)
                fixed_corners &= ws->fixed[ho->cn[8 * (int64_t)h + i]] != 0;
            affine = ho->straight[h] && (!ho->pinned[h] || fixed_corners);
        }
        if (affine)
            ho->etype[e] = -1;
    }
    free(inv_node);
    free(inv_elem);
    free(hid);
    ws->ho = ho;
    return GETME_OK;
fail:
    free(inv_node);
    free(inv_elem);
    free(hid);
    getme__ho_free(ho);
    if (st == GETME_ERR_NOMEM)
        getme__fail(mesh, st, "out of memory for second-order elements");
    return st;
}

/* min and max of det J at element e's nodes placed from coords (the
   dependent ones read from tab when it is not NULL: getme__ho_table of
   the same coords; or those not flagged in mov from dep, when dep is not
   NULL: getme__ho_dep_split); 0, or 1 for an element checked at its
   corners only (etype -1). */
static int det_range(const getme_ws *ws, const double *coords,
                     const double *tab, const double *dep, const uint8_t *mov,
                     int32_t e, double *lo, double *hi)
{
    const getme_ho_ws *ho = ws->ho;
    int t = ho->etype[e];
    if (t < 0)
        return 1;
    const getme_ho_info *in = &ho->info[t];
    double x[3 * GETME_HO_MAX_NV];
    getme__ws_gather(ws, coords, in->lin, e, x);
    const int32_t *hs = ho->eho + ho->eptr[e];
    if (tab)
        for (int k = in->nlin; k < in->nv; k++)
            memcpy(x + 3 * k, tab + 3 * (int64_t)hs[k - in->nlin],
                   3 * sizeof *x);
    else if (dep)
        for (int k = in->nlin; k < in->nv; k++) {
            int s = k - in->nlin;
            if (mov[s])
                ho_pos(ho, hs[s], coords, x + 3 * k);
            else
                memcpy(x + 3 * k, dep + 3 * s, 3 * sizeof *x);
        }
    else
        for (int k = in->nlin; k < in->nv; k++)
            ho_pos(ho, hs[k - in->nlin], coords, x + 3 * k);
    getme__ho_det_range(in, x, lo, hi);
    return 0;
}

static double ratio_of(const getme_ws *ws, const double *coords,
                       const double *tab, const double *dep,
                       const uint8_t *mov, int32_t e)
{
    double lo, hi;
    if (det_range(ws, coords, tab, dep, mov, e, &lo, &hi))
        return 1.0;
    return lo > 0.0 && hi > 0.0 ? lo / hi : (lo > 0.0 ? 0.0 : lo);
}

double getme__ho_ratio(const getme_ws *ws, const double *coords, int32_t e)
{
    return ratio_of(ws, coords, NULL, NULL, NULL, e);
}

int getme__ho_curved(const getme_ws *ws)
{
    const getme_ho_ws *ho = ws->ho;
    if (!ho)
        return 0;
    for (int32_t e = 0; e < ws->ne; e++)
        if (ho->etype[e] >= 0)
            return 1;
    return 0;
}

void getme__ho_table(const getme_ws *ws, const double *coords, double *tab)
{
    const getme_ho_ws *ho = ws->ho;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t h = 0; h < ho->nh; h++)
        ho_pos(ho, h, coords, tab + 3 * (int64_t)h);
}

/* Why a floor: smoothing moves the corners toward their GETMe positions
   and curved elements follow (their dependent nodes keep their offsets),
   so with validity alone as the test a curved element could end valid by
   a rounding (a repaired sphere element: node det J ratio 0.1 -> 2e-9),
   which Gmsh and solvers reject.  An element's ratio at the start always
   passes, so a relaxation that resets a node still finds every element
   acceptable, as with the corner guard. */
getme_status getme__ho_floor_start(getme_ws *ws)
{
    getme_ho_ws *ho = ws->ho;
    if (!ho)
        return GETME_OK;
    free(ho->floor);
    ho->floor =
        getme__malloc((size_t)(ws->ne ? ws->ne : 1) * sizeof *ho->floor);
    if (!ho->floor)
        return GETME_ERR_NOMEM;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t e = 0; e < ws->ne; e++) {
        double r = getme__ho_ratio(ws, ws->x, e); /* 1 if not second order */
        ho->floor[e] = r < GETME_HO_RATIO_FLOOR ? r : GETME_HO_RATIO_FLOOR;
    }
    return GETME_OK;
}

static int accept_of(const getme_ws *ws, const double *coords,
                     const double *tab, const double *dep,
                     const uint8_t *mov, int32_t e)
{
    const getme_ho_ws *ho = ws->ho;
    if (!ho->floor) {
        double lo, hi;
        return det_range(ws, coords, tab, dep, mov, e, &lo, &hi) || lo > 0.0;
    }
    double r = ratio_of(ws, coords, tab, dep, mov, e); /* 1: at corners */
    return r > 0.0 && r >= ho->floor[e];
}

int getme__ho_accept(const getme_ws *ws, const double *coords, int32_t e)
{
    return accept_of(ws, coords, NULL, NULL, NULL, e);
}

int getme__ho_accept_tab(const getme_ws *ws, const double *coords,
                         const double *tab, int32_t e)
{
    return accept_of(ws, coords, tab, NULL, NULL, e);
}

/* accept_of's rule from an element's det J range */
static int accept_range(const getme_ho_ws *ho, int32_t e, double lo, double hi)
{
    if (!ho->floor)
        return lo > 0.0;
    double r = lo > 0.0 && hi > 0.0 ? lo / hi : (lo > 0.0 ? 0.0 : lo);
    return r > 0.0 && r >= ho->floor[e];
}

void getme__ho_accept_tab_lanes(const getme_ws *ws, const double *coords,
                                const double *tab, const int32_t *elems,
                                int n, const double *q, uint8_t *ok)
{
    enum { L = GETME_LANES };
    const getme_ho_ws *ho = ws->ho;
    /* the lanes to check, all of one second-order type, or one at a time */
    int t = -1, same = 1, m = 0;
    int32_t e[L];
    for (int l = 0; l < n; l++) {
        ok[l] = 1;
        if (!(q[l] > 0.0) || ho->etype[elems[l]] < 0)
            continue; /* rejected anyway, or checked at its corners */
        if (t < 0)
            t = ho->etype[elems[l]];
        same &= ho->etype[elems[l]] == t;
        m++;
    }
    if (m == 0)
        return;
    const getme_ho_info *in = &ho->info[t > 0 ? t : 0];
    if (same && m > 1) {
        double x[3 * GETME_HO_MAX_NV][L], lo[L], hi[L];
        int first = -1;
        for (int l = 0; l < L; l++) {
            int use = l < n && q[l] > 0.0 && ho->etype[elems[l]] >= 0;
            if (use && first < 0)
                first = l;
            e[l] = use ? elems[l] : -1;
        }
        for (int l = 0; l < L; l++) { /* an unused lane repeats the first */
            int32_t el = e[l] >= 0 ? e[l] : elems[first];
            double xl[3 * GETME_HO_MAX_NV];
            getme__ws_gather(ws, coords, in->lin, el, xl);
            const int32_t *hs = ho->eho + ho->eptr[el];
            for (int k = in->nlin; k < in->nv; k++)
                memcpy(xl + 3 * k, tab + 3 * (int64_t)hs[k - in->nlin],
                       3 * sizeof *xl);
            for (int i = 0; i < 3 * in->nv; i++)
                x[i][l] = xl[i];
        }
        if (getme__ho_det_range_lanes(in, (const double(*)[L])x, lo, hi)) {
            for (int l = 0; l < n; l++)
                if (e[l] >= 0)
                    ok[l] = (uint8_t)accept_range(ho, e[l], lo[l], hi[l]);
            return;
        }
    }
    for (int l = 0; l < n; l++)
        if (q[l] > 0.0 && ho->etype[elems[l]] >= 0)
            ok[l] = (uint8_t)accept_of(ws, coords, tab, NULL, NULL, elems[l]);
}

int getme__ho_dep_split(const getme_ws *ws, const double *coords,
                        int32_t e, const int32_t *mv, int k, double *dep,
                        uint8_t *mov)
{
    const getme_ho_ws *ho = ws->ho;
    int t = ho->etype[e];
    if (t < 0)
        return 0;
    const getme_ho_info *in = &ho->info[t];
    const int32_t *hs = ho->eho + ho->eptr[e];
    for (int s = 0; s < in->nv - in->nlin; s++) {
        int32_t h = hs[s];
        const int32_t *c = ho->cn + 8 * (int64_t)h;
        int m = 0;
        for (int i = 0; i < ho->nc[h] && !m; i++)
            for (int a = 0; a < k; a++)
                m |= c[i] == mv[a];
        mov[s] = (uint8_t)m;
        if (!m)
            ho_pos(ho, h, coords, dep + 3 * s);
    }
    return 1;
}

int getme__ho_accept_dep(const getme_ws *ws, const double *coords,
                         int32_t e, const double *dep, const uint8_t *mov)
{
    return accept_of(ws, coords, NULL, dep, mov, e);
}

int getme__ho_valid(const getme_ws *ws, const double *coords, int32_t e)
{
    double lo, hi;
    return det_range(ws, coords, NULL, NULL, NULL, e, &lo, &hi) || lo > 0.0;
}

void getme__ho_store(const getme_ws *ws, getme_mesh *mesh)
{
    const getme_ho_ws *ho = ws->ho;
    if (!ho)
        return;
    double ysign = mesh->mirror == 1 ? -1.0 : 1.0;
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t h = 0; h < ho->nh; h++) {
        if (ho->pinned[h])
            continue; /* never written: bit-identical */
        double p[3];
        ho_pos(ho, h, ws->x, p);
        double *q = mesh->coords + 3 * (int64_t)ws->node_orig[ho->node[h]];
        q[0] = p[0];
        q[1] = ysign * p[1];
        q[2] = p[2];
    }
}
