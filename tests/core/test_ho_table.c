/*
 * test_ho_table.c -- getme__ho_table and getme__ho_accept_tab: the q_mean
 * stage's first relaxation pass checks curved second-order elements with
 * every dependent node read from a table placed once (relax.c), and must
 * decide exactly as placing each node per element (getme__ho_accept).
 *
 * A block of curved tet10 (each cube of an N^3 lattice in 6 tets; mid-
 * edge nodes on the lattice of half the spacing, pushed off their edges)
 * is checked at random moves of its corners: with the ratio floors of
 * getme__ho_floor_start (a small change of an element's node det J ratio
 * flips the answer) and without them (validity alone).  A table left at
 * the coordinates before a move must give different answers: that shows
 * the moves reach the decisions, so that the test can fail.
 *
 * The same for the finishing step's cache (patch.c): getme__ho_dep_split
 * once, then trials that move only its moving nodes, checked with
 * getme__ho_accept_dep.
 */
#define RANDOM_GEOMETRY_SEED 0x7ab1e5eedULL
#include "check.h"
#include "highorder.h"
#include "random_geometry.h"
#include "workspace.h"

#include <stdlib.h>
#include <string.h>

enum { N = 4, P = 2 * N + 1 };

static int32_t fine(int a, int b, int c) { return a + P * (b + P * c); }

/* the 6 tets of a cube around its diagonal 0-6 (corners as in a hex) */
static const int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                               {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
/* tet10's edges, in its node order 4..9 (Gmsh's) */
static const int tet10_edge[6][2] = {{0, 1}, {1, 2}, {0, 2},
                                     {0, 3}, {2, 3}, {1, 3}};

static getme_mesh *curved_block(double *xyz, int32_t *conn, int32_t *ne)
{
    for (int c = 0; c < P; c++)
        for (int b = 0; b < P; b++)
            for (int a = 0; a < P; a++) {
                double *p = xyz + 3 * fine(a, b, c);
                p[0] = 0.5 * a, p[1] = 0.5 * b, p[2] = 0.5 * c;
                /* a mid-edge point (an odd index) off its edge: curved */
                if ((a | b | c) & 1)
                    for (int d = 0; d < 3; d++)
                        p[d] += 0.02 * (urand() - 0.5);
            }
    int32_t n = 0;
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                int cube[8][3];
                for (int v = 0; v < 8; v++) {
                    int x = (v == 1 || v == 2 || v == 5 || v == 6);
                    int y = (v == 2 || v == 3 || v == 6 || v == 7);
                    cube[v][0] = 2 * (i + x), cube[v][1] = 2 * (j + y);
                    cube[v][2] = 2 * (k + (v >= 4));
                }
                for (int t = 0; t < 6; t++, n++) {
                    int32_t *e = conn + 10 * n;
                    for (int v = 0; v < 4; v++) {
                        const int *g = cube[kuhn[t][v]];
                        e[v] = fine(g[0], g[1], g[2]);
                    }
                    for (int m = 0; m < 6; m++) {
                        const int *g = cube[kuhn[t][tet10_edge[m][0]]];
                        const int *h = cube[kuhn[t][tet10_edge[m][1]]];
                        e[4 + m] = fine((g[0] + h[0]) / 2, (g[1] + h[1]) / 2,
                                        (g[2] + h[2]) / 2);
                    }
                }
            }
    *ne = n;
    getme_mesh *m;
    if (getme_mesh_create(&m, 3, P * P * P, xyz) != GETME_OK)
        return NULL;
    if (getme_mesh_add_elements_ho(m, GETME_TET10, n, conn, NULL) != GETME_OK) {
        getme_mesh_free(m);
        return NULL;
    }
    return m;
}

/* Move every corner of ws by up to amount of the spacing. */
static void move_corners(getme_ws *ws, const double *x0, double amount)
{
    for (int32_t i = 0; i < ws->nn; i++)
        for (int d = 0; d < 3; d++)
            ws->x[3 * i + d] = x0[3 * i + d] + amount * (urand() - 0.5);
}

static void test_table(int floors)
{
    double *xyz = malloc(sizeof(double) * 3 * P * P * P);
    int32_t *conn = malloc(sizeof(int32_t) * 10 * 6 * N * N * N), ne = 0;
    getme_mesh *m = curved_block(xyz, conn, &ne);
    CHECK(m != NULL);
    getme_ws ws;
    CHECK(getme__ws_build(&ws, m, 1, 2) == GETME_OK);
    CHECK(getme__ho_attach(&ws, m) == GETME_OK);
    CHECK(ws.ho != NULL);
    CHECK_EQ_INT(getme__ho_curved(&ws), 1);
    CHECK_EQ_INT(ws.ne, ne);
    int32_t curved = 0;
    for (int32_t e = 0; e < ws.ne; e++)
        curved += ws.ho->etype[e] >= 0;
    CHECK_EQ_INT(curved, ne); /* every element checked at its nodes */
    if (floors)
        CHECK(getme__ho_floor_start(&ws) == GETME_OK);
    size_t nx = (size_t)ws.nn * 3;
    double *x0 = malloc(nx * sizeof *x0);
    memcpy(x0, ws.x, nx * sizeof *x0);
    double *tab = malloc((size_t)ws.ho->nh * 3 * sizeof *tab);
    double *stale = malloc((size_t)ws.ho->nh * 3 * sizeof *stale);
    getme__ho_table(&ws, ws.x, stale);
    int64_t checked = 0, rejected = 0, stale_diff = 0;
    for (int round = 0; round < 20; round++) {
        move_corners(&ws, x0, 0.3 * (1 + round % 5));
        getme__ho_table(&ws, ws.x, tab);
        for (int32_t e = 0; e < ws.ne; e++) {
            int a = getme__ho_accept(&ws, ws.x, e);
            CHECK_EQ_INT(getme__ho_accept_tab(&ws, ws.x, tab, e), a);
            stale_diff += getme__ho_accept_tab(&ws, ws.x, stale, e) != a;
            rejected += !a;
            checked++;
        }
    }
    /* the lanes' test (getme__ho_accept_tab_lanes) at the last moves:
       groups of 1..GETME_LANES elements, some lanes already rejected
       (q <= 0, not checked: ok 1) */
    for (int32_t e0 = 0; e0 < ws.ne; e0 += 5) {
        int n = 1 + e0 % GETME_LANES;
        int32_t elems[GETME_LANES];
        double q[GETME_LANES];
        uint8_t ok[GETME_LANES];
        for (int l = 0; l < n; l++) {
            elems[l] = (e0 + 7 * l) % ws.ne;
            q[l] = (e0 + l) % 6 ? 0.5 : 0.0;
        }
        getme__ho_accept_tab_lanes(&ws, ws.x, tab, elems, n, q, ok);
        for (int l = 0; l < n; l++)
            CHECK_EQ_INT(ok[l], q[l] > 0.0 ? getme__ho_accept_tab(&ws, ws.x, tab,
                                                                  elems[l])
                                          : 1);
    }
    /* the moves decide something, and a stale table decides otherwise */
    CHECK(rejected > 0 && rejected < checked);
    CHECK(stale_diff > 0);
    printf("floors %d: %lld checks, %lld rejected, %lld differ with a stale "
           "table\n",
           floors, (long long)checked, (long long)rejected,
           (long long)stale_diff);
    free(tab), free(stale), free(x0);
    getme__ws_free(&ws);
    getme_mesh_free(m);
    free(xyz), free(conn);
}

/* getme__ho_dep_split at coordinates x1, then only the nodes mv moved:
   getme__ho_accept_dep must decide as getme__ho_accept.  Moving a node
   outside mv as well must change some answers (the cache is then
   stale): the check can fail. */
static void test_dep(void)
{
    double *xyz = malloc(sizeof(double) * 3 * P * P * P);
    int32_t *conn = malloc(sizeof(int32_t) * 10 * 6 * N * N * N), ne = 0;
    getme_mesh *m = curved_block(xyz, conn, &ne);
    CHECK(m != NULL);
    getme_ws ws;
    CHECK(getme__ws_build(&ws, m, 1, 1) == GETME_OK);
    CHECK(getme__ho_attach(&ws, m) == GETME_OK);
    CHECK(getme__ho_floor_start(&ws) == GETME_OK);
    size_t nx = (size_t)ws.nn * 3;
    double *x0 = malloc(nx * sizeof *x0);
    memcpy(x0, ws.x, nx * sizeof *x0);
    double dep[GETME_HO_MAX_DEP * 3];
    uint8_t mov[GETME_HO_MAX_DEP];
    int64_t checked = 0, rejected = 0, stale_diff = 0, moving = 0;
    for (int round = 0; round < 200; round++) {
        move_corners(&ws, x0, 0.3); /* x1 */
        int k = 1 + round % 2;
        int32_t mv[2];
        for (int a = 0; a < k; a++)
            mv[a] = (int32_t)(urand() * ws.nn);
        int32_t other = (int32_t)(urand() * ws.nn);
        /* the elements at the first moving node and a few others */
        for (int32_t e = 0; e < ws.ne; e++) {
            const int32_t *c = getme__ws_nodes(&ws, GETME_TET, e);
            int at = 0, at_other = 0;
            for (int i = 0; i < 4; i++)
                at |= c[i] == mv[0], at_other |= c[i] == other;
            if (!at && e % 17)
                continue;
            double keep[6], keepo[3];
            memcpy(keepo, ws.x + 3 * (int64_t)other, sizeof keepo);
            if (!getme__ho_dep_split(&ws, ws.x, e, mv, k, dep, mov)) {
                CHECK(0); /* every element is curved */
                continue;
            }
            for (int s = 0; s < 6; s++)
                moving += mov[s];
            for (int a = 0; a < k; a++)
                memcpy(keep + 3 * a, ws.x + 3 * (int64_t)mv[a], 3 * sizeof *keep);
            for (int trial = 0; trial < 4; trial++) {
                for (int a = 0; a < k; a++)
                    for (int d = 0; d < 3; d++)
                        ws.x[3 * (int64_t)mv[a] + d] =
                            keep[3 * a + d] + 1.4 * (urand() - 0.5);
                int acc = getme__ho_accept(&ws, ws.x, e);
                CHECK_EQ_INT(getme__ho_accept_dep(&ws, ws.x, e, dep, mov), acc);
                rejected += !acc;
                checked++;
                if (at_other && other != mv[0] && other != mv[k - 1]) {
                    for (int d = 0; d < 3; d++)
                        ws.x[3 * (int64_t)other + d] =
                            keepo[d] + 0.8 * (urand() - 0.5);
                    stale_diff += getme__ho_accept_dep(&ws, ws.x, e, dep, mov) !=
                                  getme__ho_accept(&ws, ws.x, e);
                    memcpy(ws.x + 3 * (int64_t)other, keepo, sizeof keepo);
                }
            }
            for (int a = 0; a < k; a++)
                memcpy(ws.x + 3 * (int64_t)mv[a], keep + 3 * a, 3 * sizeof *keep);
        }
    }
    CHECK(moving > 0);
    CHECK(rejected > 0 && rejected < checked);
    CHECK(stale_diff > 0);
    printf("dep: %lld checks, %lld rejected, %lld slots following a moving "
           "node, %lld differ once another node moves\n",
           (long long)checked, (long long)rejected, (long long)moving,
           (long long)stale_diff);
    free(x0);
    getme__ws_free(&ws);
    getme_mesh_free(m);
    free(xyz), free(conn);
}

int main(void)
{
    test_dep();
    test_table(1);
    test_table(0);
    return check_summary("test_ho_table");
}
