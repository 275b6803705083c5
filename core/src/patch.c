/*
 * patch.c -- local max-min optimisation of a few nodes (patch.h).
 */
#include "patch.h"
#include "workspace.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define D_MAX (3 * GETME_PATCH_MAX_MOVE)

/* Doubles of one lane group in getme_patch.lx. */
#define LX_GROUP (3 * GETME_MAX_NV * GETME_LANES)

void getme__patch_free(getme_patch *p)
{
    free(p->type);
    free(p->conn);
    free(p->id);
    free(p->q);
    free(p->sj);
    free(p->qt);
    free(p->lx);
    free(p->lok);
    free(p->mpos);
    free(p->midx);
    free(p->hdep);
    free(p->hmov);
    free(p->hok);
    memset(p, 0, sizeof *p);
}

/* Grow every per-element array to cap entries; qt also holds the active
   gradients, D_MAX values per element.  RESIZE keeps a field unchanged
   when realloc fails. */
#define RESIZE(field, n)                                                   \
    ((tmp = getme__realloc(p->field, (n) * sizeof *p->field)) ? (p->field = tmp, 0) \
                                                       : -1)

static getme_status grow(getme_patch *p, int32_t cap)
{
    size_t n = (size_t)cap;
    void *tmp;
    if (RESIZE(type, n) || RESIZE(conn, n) || RESIZE(id, n) || RESIZE(q, n) ||
        RESIZE(sj, n) || RESIZE(qt, n * D_MAX))
        return GETME_ERR_NOMEM;
    p->cap = cap;
    /* the lane cache is optional: without it trials gather as before */
    size_t ng = (n + GETME_LANES - 1) / GETME_LANES;
    if (RESIZE(lx, ng * LX_GROUP) || RESIZE(lok, ng) ||
        RESIZE(mpos, n * GETME_MAX_NV) || RESIZE(midx, n * GETME_MAX_NV)) {
        free(p->lx), free(p->lok), free(p->mpos), free(p->midx);
        p->lx = NULL, p->lok = NULL, p->mpos = NULL, p->midx = NULL;
    }
    return GETME_OK;
}

getme_status getme__patch_init(getme_patch *p, int32_t cap)
{
    memset(p, 0, sizeof *p);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        p->skip_q[t] = 2.0;
    return grow(p, cap > 64 ? cap : 64);
}

getme_status getme__patch_add(getme_patch *p, int type, const int32_t *conn,
                              int32_t id)
{
    if (p->n == p->cap && grow(p, 2 * p->cap) != GETME_OK)
        return GETME_ERR_NOMEM;
    p->type[p->n] = (int8_t)type;
    p->conn[p->n] = conn;
    p->id[p->n] = id;
    p->n++;
    return GETME_OK;
}

/* Coordinates of patch element i at p->x, one node after the other. */
static void elem_x(const getme_patch *p, int32_t i, double *x)
{
    const int32_t *c = p->conn[i];
    for (int j = 0; j < getme__nv[p->type[i]]; j++) {
        const double *s = p->x + 3 * (int64_t)c[j];
        x[3 * j] = s[0];
        x[3 * j + 1] = p->mirror ? -s[1] : s[1];
        x[3 * j + 2] = s[2];
    }
}

/* What elem_q adds to the mean ratio q of patch element i at coordinates
   x: its worst corner into *sj (unless NULL) when the corner guard
   applies to its type, and, with ho, 0 for a second-order element invalid
   at a node (trial() takes that test itself, and only where it decides). */
static double elem_finish(const getme_patch *p, int32_t i, const double *x,
                          double q, double *sj, int ho)
{
    int t = p->type[i];
    /* a skipped corner stays 1: above the floor, like the true one, it
       rejects nothing as a new corner, and as an old one the test is the
       same (sj < floor implies sj < any old corner >= floor) */
    if (sj && p->guard && getme__has_corners(t) && !(q >= p->skip_q[t]))
        *sj = getme__corner_sj(t, x);
    if (ho && q > 0.0 && p->ws && p->ws->ho &&
        !getme__ho_accept(p->ws, p->x, p->id[i]))
        return 0.0; /* second order: det J > 0 at every node, ratio floor */
    return q;
}

/* Quality of patch element i at p->x; its worst corner into *sj when the
   corner guard applies to its type. */
static double elem_q(const getme_patch *p, int32_t i, double *sj, int ho)
{
    double x[3 * GETME_MAX_NV];
    elem_x(p, i, x);
    return elem_finish(p, i, x, getme__quality(p->type[i], x), sj, ho);
}

static void lanes_x(const getme_patch *p, int32_t i0, int32_t n, int t,
                    double (*x)[GETME_LANES]);

/* The mean ratios of the n <= GETME_LANES patch elements from i0 into q
   by one lane kernel (quality.c: the same bits as getme__quality, several
   times faster; trials evaluate every patch element, which is most of the
   finishing step's time).  Returns 0, and computes nothing, when they are
   not all of one type that has a lane kernel. */
static int lanes_q(const getme_patch *p, int32_t i0, int32_t n, double *q)
{
    int t = p->type[i0];
    for (int32_t l = 1; l < n; l++)
        if (p->type[i0 + l] != t)
            return 0;
    if (t != GETME_TET && t != GETME_HEX)
        return 0;
    double x[3 * GETME_MAX_NV][GETME_LANES];
    lanes_x(p, i0, n, t, x);
    return getme__quality_lanes(t, (const double(*)[GETME_LANES])x, q);
}

/* The lane-major coordinates of the n <= GETME_LANES patch elements from
   i0 (all of type t) into x, as lanes_q gathers them. */
static void lanes_x(const getme_patch *p, int32_t i0, int32_t n, int t,
                    double (*x)[GETME_LANES])
{
    for (int32_t l = 0; l < GETME_LANES; l++) {
        /* unused lanes repeat the last element: finite, and ignored */
        const int32_t *c = p->conn[i0 + (l < n ? l : n - 1)];
        for (int j = 0; j < getme__nv[t]; j++) {
            const double *s = p->x + 3 * (int64_t)c[j];
            x[3 * j][l] = s[0];
            x[3 * j + 1][l] = p->mirror ? -s[1] : s[1];
            x[3 * j + 2][l] = s[2];
        }
    }
}

/* Fill the lane cache for trials that move the k nodes mv: every group of
   one type with a lane kernel gathered, and where the moving nodes sit in
   it (a node occurs once per element; repeated lanes are filled too).
   Nothing is cached without the arrays (then trials gather). */
static void lane_cache(getme_patch *p, const int32_t *mv, int k)
{
    p->cached = 0;
    if (!p->lx)
        return;
    int32_t m = 0;
    for (int32_t i0 = 0, g = 0; i0 < p->n; i0 += GETME_LANES, g++) {
        int32_t n = p->n - i0 < GETME_LANES ? p->n - i0 : GETME_LANES;
        int t = p->type[i0], ok = t == GETME_TET || t == GETME_HEX;
        for (int32_t l = 1; l < n; l++)
            ok &= p->type[i0 + l] == t;
        p->lok[g] = (int8_t)ok;
        if (!ok)
            continue;
        double(*x)[GETME_LANES] = (double(*)[GETME_LANES])(p->lx + (int64_t)g * LX_GROUP);
        lanes_x(p, i0, n, t, x);
        for (int32_t l = 0; l < GETME_LANES; l++) {
            const int32_t *c = p->conn[i0 + (l < n ? l : n - 1)];
            for (int j = 0; j < getme__nv[t]; j++)
                for (int a = 0; a < k; a++)
                    if (c[j] == mv[a]) {
                        p->mpos[m] = (int32_t)((int64_t)g * LX_GROUP +
                                               3 * j * GETME_LANES + l);
                        p->midx[m++] = (uint8_t)a;
                    }
        }
    }
    p->nmpos = m;
    p->cached = 1;
}

/* The dependent-node cache for trials that move the k nodes mv (curved
   second-order elements of the finishing step): each element's slots
   that follow no moving node placed now, once, instead of in every
   trial (a curved tet10 moved at one corner keeps 3 of its 6).  Without
   the memory, trials place every slot as before. */
static void ho_cache(getme_patch *p, const int32_t *mv, int k)
{
    p->hcached = 0;
    if (!p->ws || !p->ws->ho || p->n == 0)
        return;
    if (p->hcap < p->n) {
        size_t n = (size_t)p->cap;
        free(p->hdep), free(p->hmov), free(p->hok);
        p->hdep = getme__malloc(n * GETME_HO_MAX_DEP * 3 * sizeof *p->hdep);
        p->hmov = getme__malloc(n * GETME_HO_MAX_DEP);
        p->hok = getme__malloc(n);
        if (!p->hdep || !p->hmov || !p->hok) {
            free(p->hdep), free(p->hmov), free(p->hok);
            p->hdep = NULL, p->hmov = NULL, p->hok = NULL, p->hcap = 0;
            return;
        }
        p->hcap = p->cap;
    }
    for (int32_t i = 0; i < p->n; i++)
        p->hok[i] = (uint8_t)getme__ho_dep_split(
            p->ws, p->x, p->id[i], mv, k,
            p->hdep + (int64_t)i * GETME_HO_MAX_DEP * 3,
            p->hmov + (int64_t)i * GETME_HO_MAX_DEP);
    p->hcached = 1;
}

/* getme__ho_accept of patch element i at p->x, from the dependent-node
   cache where it holds the element: the same answer. */
static int ho_accept(const getme_patch *p, int32_t i)
{
    if (p->hcached && p->hok[i])
        return getme__ho_accept_dep(
            p->ws, p->x, p->id[i], p->hdep + (int64_t)i * GETME_HO_MAX_DEP * 3,
            p->hmov + (int64_t)i * GETME_HO_MAX_DEP);
    return getme__ho_accept(p->ws, p->x, p->id[i]);
}

/* Bring the lane cache to the moving nodes' current coordinates. */
static void lane_cache_move(getme_patch *p, const int32_t *mv)
{
    for (int32_t m = 0; m < p->nmpos; m++) {
        double *r = p->lx + p->mpos[m];
        const double *s = p->x + 3 * (int64_t)mv[p->midx[m]];
        r[0] = s[0];
        r[GETME_LANES] = p->mirror ? -s[1] : s[1];
        r[2 * GETME_LANES] = s[2];
    }
}

/* elem_q of the n <= GETME_LANES patch elements from i0 into q (and into
   sj where elem_q sets it); from the lane cache where it holds them.  ho:
   with the second-order test (elem_finish). */
static void group_q(const getme_patch *p, int32_t i0, int32_t n, double *q,
                    double *sj, int ho)
{
    double ql[GETME_LANES], x[3 * GETME_MAX_NV];
    const double(*cx)[GETME_LANES] = NULL;
    int lanes;
    if (p->cached && p->lok[i0 / GETME_LANES]) {
        cx = (const double(*)[GETME_LANES])(p->lx +
                                            (int64_t)(i0 / GETME_LANES) * LX_GROUP);
        lanes = getme__quality_lanes(p->type[i0], cx, ql);
    } else {
        lanes = lanes_q(p, i0, n, ql);
    }
    for (int32_t l = 0; l < n; l++) {
        if (!lanes) {
            q[l] = elem_q(p, i0 + l, &sj[l], ho);
            continue;
        }
        int t = p->type[i0 + l];
        int more = (p->guard && getme__has_corners(t) &&
                    !(ql[l] >= p->skip_q[t])) ||
                   (ho && p->ws && p->ws->ho);
        if (!more) {
            q[l] = ql[l];
            continue;
        }
        if (cx) /* elem_x's values, from the cache */
            for (int j = 0; j < 3 * getme__nv[t]; j++)
                x[j] = cx[j][l];
        else
            elem_x(p, i0 + l, x);
        q[l] = elem_finish(p, i0 + l, x, ql[l], &sj[l], ho);
    }
}

double getme__patch_eval(getme_patch *p)
{
    double m = INFINITY;
    for (int32_t i = 0; i < p->n; i++)
        p->sj[i] = 1.0;
    for (int32_t i0 = 0; i0 < p->n; i0 += GETME_LANES) {
        int32_t n = p->n - i0 < GETME_LANES ? p->n - i0 : GETME_LANES;
        group_q(p, i0, n, p->q + i0, p->sj + i0, 1);
    }
    for (int32_t i = 0; i < p->n; i++)
        m = fmin(m, p->q[i]);
    return m;
}

double getme__patch_eval_known(getme_patch *p, const double *known)
{
    if (p->ws && p->ws->ho)
        return getme__patch_eval(p);
    double m = INFINITY;
    for (int32_t i0 = 0; i0 < p->n; i0 += GETME_LANES) {
        int32_t n = p->n - i0 < GETME_LANES ? p->n - i0 : GETME_LANES;
        int corners = 0;
        for (int32_t l = 0; l < n; l++) {
            p->sj[i0 + l] = 1.0;
            int t = p->type[i0 + l];
            corners |= p->guard && getme__has_corners(t) &&
                       !(known[p->id[i0 + l]] >= p->skip_q[t]);
        }
        if (corners)
            group_q(p, i0, n, p->q + i0, p->sj + i0, 1);
        else
            for (int32_t l = 0; l < n; l++)
                p->q[i0 + l] = known[p->id[i0 + l]];
    }
    for (int32_t i = 0; i < p->n; i++)
        m = fmin(m, p->q[i]);
    return m;
}

/* Trial qualities into p->qt at the moved coordinates.  Returns 1 if the
 * move is acceptable:
 *  - every element ends above cur, the patch's minimum, so the minimum
 *    strictly rises (by gain);
 *  - the patch's total quality falls by at most p->loss times gain, and
 *    by no more than p->budget, the total quality earlier moves gained.
 *    Pure max-min steps would otherwise buy a tiny rise of the worst
 *    element with large losses around it (measured on the bundled bracket:
 *    q_mean 0.843 -> 0.829 for a q*_min gain of 0.001); the budget makes
 *    sure the sum of all qualities, hence q_mean, never ends below where
 *    the optimisation started;
 *  - with the corner guard, no corner of a hex, prism, pyramid or quad
 *    falls below min(its old value, floor). */
static int trial(getme_patch *p, double cur, const int32_t *mv)
{
    double m = INFINITY, sum_new = 0.0, sum_old = 0.0;
    if (p->cached)
        lane_cache_move(p, mv);
    /* Most trials of the finishing step are failed line-search halvings
       that evaluate the whole patch, so the per-element bookkeeping
       matters next to the lane kernel: the arrays are read through locals
       (stores to qt could alias the fields otherwise, so they were
       reloaded per element), and a cached group takes the kernel's
       qualities directly, with group_q's worst corner
       only where the corner guard needs it and the element passed the
       minimum (its result, bit for bit).  A corner not computed stays 1,
       as in group_q: the floor is at most 1 (params.c), so it rejects
       nothing. */
    const double *pq = p->q, *psj = p->sj;
    double *qt = p->qt;
    const int ho = p->ws && p->ws->ho, guard = p->guard;
    const double floor = p->floor;
    for (int32_t i0 = 0; i0 < p->n; i0 += GETME_LANES) {
        int32_t n = p->n - i0 < GETME_LANES ? p->n - i0 : GETME_LANES;
        double qg[GETME_LANES], sj[GETME_LANES];
        for (int32_t l = 0; l < n; l++)
            sj[l] = 1.0; /* no corner: above any floor, rejects nothing */
        int t = p->type[i0];
        const double(*cx)[GETME_LANES] = NULL;
        if (p->cached && p->lok[i0 / GETME_LANES]) {
            cx = (const double(*)[GETME_LANES])(p->lx + (int64_t)(i0 / GETME_LANES) *
                                                            LX_GROUP);
            getme__quality_lanes(t, cx, qg);
        } else {
            group_q(p, i0, n, qg, sj, 0);
        }
        /* the lane path's worst corners, where group_q computes them */
        const int corners = cx && guard && getme__has_corners(t);
        const double skip = p->skip_q[t];
        for (int32_t l = 0; l < n; l++) {
            int32_t i = i0 + l;
            double q = qg[l];
            if (!(q > cur))
                return 0;
            if (corners && !(q >= skip)) {
                double x[3 * GETME_MAX_NV];
                for (int j = 0; j < 3 * getme__nv[t]; j++)
                    x[j] = cx[j][l];
                q = elem_finish(p, i, x, q, &sj[l], 0);
            }
            /* second order: the test at every node only for an element
               that passed the minimum (elem_finish would have made q 0,
               failing it, as here), so a trial that fails on a quality
               skips it for that element and the ones after it; on a
               curved tet10 the test costs many times the quality */
            if (ho && q > 0.0 && !ho_accept(p, i))
                q = 0.0;
            if (!(q > cur))
                return 0;
            if (sj[l] < psj[i] && sj[l] < floor && guard)
                return 0;
            qt[i] = q;
            m = q < m ? q : m; /* q > cur: not NaN (fmin was a call) */
            sum_new += q;
            sum_old += pq[i];
        }
    }
    double change = sum_new - sum_old, allowed = (m - cur) * p->loss;
    p->change = change;
    p->allowed_max = allowed > p->allowed_max ? allowed : p->allowed_max;
    return change >= -(allowed < p->budget ? allowed : p->budget);
}

/* Accept the trial: qualities become current, and what the move gained or
   spent of the total quality goes to the budget. */
static void accept(getme_patch *p)
{
    memcpy(p->q, p->qt, (size_t)p->n * sizeof *p->q);
    p->budget += p->change;
    if (p->log) {
        if (p->nlog < p->cap_log)
            p->log[p->nlog] = p->change;
        p->nlog++;
    }
}

static inline double *coord(const getme_patch *p, int32_t node, int d)
{
    return p->x + 3 * (int64_t)node + d;
}

/* Set the moving nodes to base + s * u (D = 3k values). */
static void place(getme_patch *p, const int32_t *mv, int k, const double *base,
                  double s, const double *u)
{
    for (int j = 0; j < k; j++)
        for (int d = 0; d < 3; d++)
            *coord(p, mv[j], d) = base[3 * j + d] + s * u[3 * j + d];
}

static void restore(getme_patch *p, const int32_t *mv, int k,
                    const double *base)
{
    for (int j = 0; j < k; j++)
        for (int d = 0; d < 3; d++)
            *coord(p, mv[j], d) = base[3 * j + d];
}

/* Shortest edge of the patch that touches a moving node: the length scale
   of steps and difference quotients. */
static double edge_scale(const getme_patch *p, const int32_t *mv, int k)
{
    double l2 = INFINITY;
    for (int32_t i = 0; i < p->n; i++) {
        const getme_edge_table *et = &getme__edges[p->type[i]];
        const int32_t *c = p->conn[i];
        for (int j = 0; j < et->num_edges; j++) {
            int32_t a = c[et->node[j][0]], b = c[et->node[j][1]];
            int moving = 0;
            for (int m = 0; m < k; m++)
                moving |= a == mv[m] || b == mv[m];
            if (!moving)
                continue;
            double s = 0.0;
            for (int d = 0; d < 3; d++) {
                double v = *coord(p, a, d) - *coord(p, b, d);
                s += v * v;
            }
            l2 = s < l2 ? s : l2; /* fmin, inlined: l2 never NaN */
        }
    }
    return sqrt(l2);
}

/* The qualities of patch element i (a tet or hex of a first-order patch)
   with one coordinate of a moving node moved by +h or -h, as elem_q gives
   them after writing x0 +- h into p->x: evaluation m is node mv[m / 6],
   coordinate m / 2 % 3, sign + for even m; only the nodes in the element
   (in[j]).  Up to GETME_LANES at once through the lane kernel, which has
   getme__quality's bits. */
static void perturbed_q(const getme_patch *p, int32_t i, const int32_t *mv,
                        int k, const int *in, double h, double *qs)
{
    const int32_t *c = p->conn[i];
    int t = p->type[i], nv = getme__nv[t];
    double x0[3 * GETME_MAX_NV], x[3 * GETME_MAX_NV][GETME_LANES];
    double ql[GETME_LANES];
    int ev[GETME_LANES], n = 0;
    elem_x(p, i, x0);
    for (int m = 0; m < 6 * k; m++) {
        if (in[m / 6])
            ev[n++] = m;
        if (n < GETME_LANES && !(m == 6 * k - 1 && n > 0))
            continue;
        for (int l = 0; l < GETME_LANES; l++) { /* spare lanes repeat */
            int e = ev[l < n ? l : n - 1], j = e / 6, d = e / 2 % 3;
            double raw = *coord(p, mv[j], d);
            double v = e % 2 ? raw - h : raw + h;
            for (int r = 0; r < 3 * nv; r++)
                x[r][l] = x0[r];
            for (int a = 0; a < nv; a++)
                if (c[a] == mv[j])
                    x[3 * a + d][l] = p->mirror && d == 1 ? -v : v;
        }
        getme__quality_lanes(t, (const double(*)[GETME_LANES])x, ql);
        for (int l = 0; l < n; l++)
            qs[ev[l]] = ql[l];
        n = 0;
    }
}

/* Central-difference gradient of element i's quality with respect to the
   moving nodes (zero for the nodes it does not contain).  Only the mean
   ratio: no worst corner (the step does not use one). */
static void gradient(getme_patch *p, int32_t i, const int32_t *mv, int k,
                     double h, double *g)
{
    const int32_t *c = p->conn[i];
    int t = p->type[i], nv = getme__nv[t];
    int in[GETME_PATCH_MAX_MOVE];
    for (int j = 0; j < k; j++) {
        in[j] = 0;
        for (int v = 0; v < nv; v++)
            in[j] |= c[v] == mv[j];
    }
    double qs[6 * GETME_PATCH_MAX_MOVE], x[3 * GETME_MAX_NV];
    if ((t == GETME_TET || t == GETME_HEX) && !(p->ws && p->ws->ho)) {
        perturbed_q(p, i, mv, k, in, h, qs);
    } else {
        for (int m = 0; m < 6 * k; m++) {
            if (!in[m / 6])
                continue;
            double *xp = coord(p, mv[m / 6], m / 2 % 3), x0 = *xp;
            *xp = m % 2 ? x0 - h : x0 + h;
            elem_x(p, i, x);
            qs[m] = elem_finish(p, i, x, getme__quality(t, x), NULL, 1);
            *xp = x0;
        }
    }
    for (int j = 0; j < k; j++)
        for (int d = 0; d < 3; d++)
            g[3 * j + d] = in[j] ? (qs[6 * j + 2 * d] - qs[6 * j + 2 * d + 1]) /
                                       (2.0 * h)
                                 : 0.0;
}

static double dot(const double *a, const double *b, int n)
{
    double s = 0.0;
    for (int i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

/* Minimum-norm point z of the convex hull of the m vectors g (n values
   each) by Frank-Wolfe with exact line search: the steepest ascent
   direction of min_a g_a . z.  A fixed number of steps keeps it
   deterministic and cheap; an approximate z is still an ascent direction
   when min_a g_a . z > 0, which the caller checks. */
static void min_norm(const double *g, int32_t m, int n, double *z)
{
    int32_t best = 0;
    for (int32_t a = 1; a < m; a++)
        if (dot(g + a * n, g + a * n, n) < dot(g + best * n, g + best * n, n))
            best = a;
    memcpy(z, g + best * n, (size_t)n * sizeof *z);
    for (int it = 0; it < 64; it++) {
        double zz = dot(z, z, n);
        int32_t s = 0;
        double smin = INFINITY;
        for (int32_t a = 0; a < m; a++) {
            double v = dot(g + a * n, z, n);
            if (v < smin)
                smin = v, s = a;
        }
        if (zz - smin <= 1e-12 * zz)
            break;
        double diff[D_MAX], dd = 0.0;
        for (int i = 0; i < n; i++) {
            diff[i] = g[s * n + i] - z[i];
            dd += diff[i] * diff[i];
        }
        double t = (zz - smin) / dd;
        t = t > 1.0 ? 1.0 : t;
        for (int i = 0; i < n; i++)
            z[i] += t * diff[i];
    }
}

/* One ascent step; returns 1 if accepted (apply) or found (probe). */
static int step(getme_patch *p, const int32_t *mv, int k, double L,
                int apply)
{
    int n = 3 * k;
    double cur = INFINITY;
    for (int32_t i = 0; i < p->n; i++)
        cur = fmin(cur, p->q[i]);
    /* The active set: elements within 20 % of the minimum.  Wider sets
       give safer directions, narrower ones faster steps; the line search
       below protects the others either way. */
    double band = cur + 0.2 * cur + 1e-12;
    double *g = p->qt; /* room for D_MAX per element; qt is free here */
    int32_t m = 0;
    for (int32_t i = 0; i < p->n; i++)
        if (p->q[i] <= band)
            gradient(p, i, mv, k, 1e-7 * L, g + (int64_t)m++ * n);
    double z[D_MAX];
    min_norm(g, m, n, z);
    double zn = sqrt(dot(z, z, n)), worst = INFINITY;
    for (int32_t a = 0; a < m; a++)
        worst = fmin(worst, dot(g + (int64_t)a * n, z, n));
    if (!(zn > 0.0) || !(worst > 0.0))
        return 0; /* stationary: no ascent direction */
    double base[D_MAX], u[D_MAX];
    for (int j = 0; j < k; j++)
        for (int d = 0; d < 3; d++)
            base[3 * j + d] = *coord(p, mv[j], d);
    for (int i = 0; i < n; i++)
        u[i] = z[i] / zn;
    /* Halve from half the shortest edge down to ~1e-7 of it. */
    for (int h = 1; h <= 24; h++) {
        double s = L * ldexp(1.0, -h);
        place(p, mv, k, base, s, u);
        if (trial(p, cur, mv)) {
            if (!apply) {
                restore(p, mv, k, base);
                return 1;
            }
            accept(p);
            return 1;
        }
    }
    restore(p, mv, k, base);
    return 0;
}

int getme__patch_climb(getme_patch *p, const int32_t *mv, int k,
                       int max_steps, int apply)
{
    if (k < 1 || k > GETME_PATCH_MAX_MOVE || p->n == 0)
        return 0;
    double L = edge_scale(p, mv, k);
    if (!(L > 0.0) || !isfinite(L))
        return 0;
    int done = 0;
    lane_cache(p, mv, k);
    ho_cache(p, mv, k);
    while (done < max_steps && step(p, mv, k, L, apply)) {
        done++;
        if (!apply)
            break;
    }
    p->cached = p->hcached = 0; /* the caller may move other nodes next */
    return done;
}

int getme__patch_toward(getme_patch *p, const int32_t *mv, int k,
                        const double *tg)
{
    if (k < 1 || k > GETME_PATCH_MAX_MOVE || p->n == 0)
        return 0;
    double cur = INFINITY, base[D_MAX], u[D_MAX];
    for (int32_t i = 0; i < p->n; i++)
        cur = fmin(cur, p->q[i]);
    for (int j = 0; j < k; j++)
        for (int d = 0; d < 3; d++) {
            base[3 * j + d] = *coord(p, mv[j], d);
            u[3 * j + d] = tg[3 * j + d] - base[3 * j + d];
        }
    lane_cache(p, mv, k);
    ho_cache(p, mv, k);
    int kept = 0;
    for (int h = 1; h <= 6 && !kept; h++) {
        place(p, mv, k, base, ldexp(1.0, -h), u);
        if (trial(p, cur, mv)) {
            accept(p);
            kept = 1;
        }
    }
    p->cached = p->hcached = 0; /* the caller may move other nodes next */
    if (!kept)
        restore(p, mv, k, base);
    return kept;
}
