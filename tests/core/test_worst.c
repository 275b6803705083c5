/*
 * test_worst.c -- the worst-element report and the corner guard.
 *
 *  - getme_mesh_worst_elements names the right elements and reasons on a
 *    triangle mesh whose worst element has all nodes on the skin, and one
 *    whose nodes are fixed partly as interface nodes; its probes move no
 *    node; GETME_WORST_FREE_ONLY gives the elements behind q*_min;
 *  - the corner guard: with corner_floor F, every hex corner ends at or
 *    above min(its input value, F), element by element; without the guard
 *    the same run breaks that (so the check can fail);
 *  - the finishing step never ends below the paper's method alone, in
 *    q*_min or in q_mean.
 */
#define N 6
#include "check.h"
#include "getme.h"
#include "gen_mesh.h"

#include <stdlib.h>
#include <string.h>

/* Triangles of cell (i, 0) in gen's numbering: 2 per cell, cells by row. */
static int32_t tri_of_cell(int i, int which) { return 2 * i + which; }

static void check_reasons(void)
{
    gen g = make_mesh(3);
    /* Pull the bottom-right corner node toward the diagonal of its cell:
       the triangle (N-1,0), (N,0), (N,1) becomes thin, all its nodes stay
       on the skin. */
    double *b = g.xyz + 3 * node_id(N, 0, 0);
    b[0] = N - 0.45, b[1] = 0.45;
    getme_mesh *m = NULL;
    CHECK(getme_mesh_create(&m, 2, g.nn, g.xyz) == GETME_OK);
    /* Two regions split at x = N/2, so the line x = N/2 is an interface. */
    int32_t *region = malloc((size_t)g.count[GETME_TRI] * sizeof *region);
    for (int32_t e = 0; e < g.count[GETME_TRI]; e++) {
        double cx = 0.0;
        for (int k = 0; k < 3; k++)
            cx += g.xyz[3 * g.conn[GETME_TRI][3 * e + k]] / 3.0;
        region[e] = cx > N / 2.0;
    }
    CHECK(getme_mesh_add_elements(m, GETME_TRI, g.count[GETME_TRI],
                                  g.conn[GETME_TRI], region) == GETME_OK);
    CHECK(getme_mesh_fix_boundary(m, GETME_FIX_SKIN | GETME_FIX_INTERFACES,
                                  NULL) == GETME_OK);
    int32_t ne = getme_mesh_num_elements(m), nn = getme_mesh_num_nodes(m);
    double *x0 = malloc((size_t)nn * 3 * sizeof *x0);
    memcpy(x0, getme_mesh_coords(m), (size_t)nn * 3 * sizeof *x0);

    getme_worst_element *w = malloc((size_t)ne * sizeof *w);
    int32_t n = -1;
    CHECK(getme_mesh_worst_elements(m, ne, 0, w, &n) == GETME_OK);
    CHECK_EQ_INT(n, ne);
    CHECK(!memcmp(getme_mesh_coords(m), x0, (size_t)nn * 3 * sizeof *x0));
    int32_t corner = tri_of_cell(N - 1, 0), iface = tri_of_cell(N / 2 - 1, 0);
    CHECK_EQ_INT(w[0].element, corner);
    CHECK_EQ_INT(w[0].reason, GETME_WORST_ALL_FIXED);
    CHECK_EQ_INT(w[0].num_free, 0);
    CHECK_EQ_INT(w[0].num_nodes, 3);
    CHECK_EQ_INT(w[0].type, GETME_TRI);
    double q[3 * 3];
    for (int k = 0; k < 3; k++)
        memcpy(q + 3 * k, g.xyz + 3 * g.conn[GETME_TRI][3 * corner + k],
               3 * sizeof(double));
    CHECK_NEAR(w[0].quality, getme_element_quality(GETME_TRI, q), 0.0);
    int found = 0;
    for (int32_t k = 1; k < n; k++) {
        CHECK(w[k].quality >= w[k - 1].quality);
        if (w[k].element == iface) {
            found = 1;
            CHECK_EQ_INT(w[k].reason, GETME_WORST_INTERFACE);
            CHECK_EQ_INT(w[k].num_free, 0);
        }
        if (w[k].num_free > 0)
            CHECK(w[k].reason == GETME_WORST_IMPROVABLE ||
                  w[k].reason == GETME_WORST_LOCAL_OPTIMUM);
    }
    CHECK(found);

    /* Free only: the first is q*_min, none without a free node. */
    getme_quality_stats s;
    CHECK(getme_mesh_quality_stats(m, -1, &s) == GETME_OK);
    CHECK(getme_mesh_worst_elements(m, 5, GETME_WORST_FREE_ONLY, w, &n) ==
          GETME_OK);
    CHECK_EQ_INT(n, 5);
    CHECK_NEAR(w[0].quality, s.q_min_star, 0.0);
    for (int32_t k = 0; k < n; k++)
        CHECK(w[k].num_free > 0);
    CHECK(getme_mesh_worst_elements(m, 0, 0, w, &n) == GETME_OK && n == 0);
    CHECK(getme_mesh_worst_elements(m, -1, 0, w, &n) == GETME_ERR_ARGUMENT);
    CHECK(strcmp(getme_worst_reason_string(GETME_WORST_ALL_FIXED),
                 "all nodes fixed") == 0);

    /* After smoothing, the worst free elements are at a local optimum or
       still improvable; the corner triangle is untouched. */
    getme_params p;
    getme_params_init(&p);
    CHECK(getme_smooth(m, &p, NULL) == GETME_OK);
    CHECK(getme_mesh_worst_elements(m, 1, 0, w, &n) == GETME_OK);
    CHECK_EQ_INT(w[0].element, corner);
    free(w), free(x0), free(region);
    getme_mesh_free(m);
    free_gen(&g);
}

/* Worst corner of every element, by element index. */
static double *corners(getme_mesh *m)
{
    int32_t ne = getme_mesh_num_elements(m), n = 0;
    getme_worst_element *w = malloc((size_t)ne * sizeof *w);
    double *sj = malloc((size_t)ne * sizeof *sj);
    CHECK(getme_mesh_worst_elements(m, ne, 0, w, &n) == GETME_OK);
    for (int32_t k = 0; k < n; k++)
        sj[w[k].element] = w[k].corner_sj;
    free(w);
    return sj;
}

/* How many hexes end below min(their input corner, floor). */
static int32_t guard_violations(const gen *g, int guard, double floor,
                                double *q_min_star)
{
    getme_mesh *m = build(g);
    double *before = corners(m);
    getme_params p;
    getme_params_init(&p);
    p.corner_guard = guard;
    p.corner_floor = floor;
    getme_result r;
    CHECK(getme_smooth(m, &p, &r) == GETME_OK);
    double *after = corners(m);
    int32_t bad = 0, ne = getme_mesh_num_elements(m);
    double fl = floor > r.corner_sj_initial ? floor : r.corner_sj_initial;
    for (int32_t e = 0; e < ne; e++)
        bad += after[e] < (before[e] < fl ? before[e] : fl);
    if (guard)
        CHECK(r.corner_sj >= r.corner_sj_initial);
    *q_min_star = r.q_min_star;
    free(before), free(after);
    getme_mesh_free(m);
    return bad;
}

static void check_corner_guard(void)
{
    gen g = make_mesh(1);
    /* A twisted block: every layer turned a little more about the z axis,
       so that no node placement makes all hexes cubes and smoothing has
       to trade corners for the mean. */
    for (int32_t v = 0; v < g.nn; v++) {
        double *x = g.xyz + 3 * v, c = N / 2.0;
        double a = 1.6 * x[2] / N, u = x[0] - c, w = x[1] - c;
        x[0] = c + cos(a) * u - sin(a) * w;
        x[1] = c + sin(a) * u + cos(a) * w;
    }
    double q_guard, q_free;
    int32_t with = guard_violations(&g, 1, 0.95, &q_guard);
    int32_t without = guard_violations(&g, 0, 0.95, &q_free);
    printf("corner guard (floor 0.95): %d hexes below min(input, floor) "
           "with the guard, %d without; q*min %.4f / %.4f\n",
           (int)with, (int)without, q_guard, q_free);
    CHECK_EQ_INT(with, 0);
    CHECK(without > 0); /* the check above can fail */
    free_gen(&g);
}

/* The finishing step starts from the paper's result and never lowers it. */
static void check_finish_not_worse(void)
{
    for (int kind = 0; kind < 5; kind++) {
        gen g = make_mesh(kind);
        getme_result r[2];
        for (int f = 0; f < 2; f++) {
            getme_mesh *m = distorted(&g);
            getme_params p;
            getme_params_init(&p);
            p.finish = f;
            CHECK(getme_smooth(m, &p, &r[f]) == GETME_OK);
            getme_mesh_free(m);
        }
        CHECK(r[1].q_min_star >= r[0].q_min_star);
        /* the finishing step spends no more total quality than it gains */
        CHECK(r[1].q_mean >= r[0].q_mean - 1e-12);
        CHECK_EQ_INT(r[1].iterations, r[0].iterations);
        CHECK(r[1].passes_finish >= 1 && r[0].passes_finish == 0);
        free_gen(&g);
    }
}

int main(void)
{
    check_reasons();
    check_corner_guard();
    check_finish_not_worse();
    return check_summary("test_worst");
}
