/*
 * test_shared_qualities.c -- the calls behind the CLI's lines after
 * smoothing share one quality array (issue #13):
 *
 *  - getme_mesh_measure_all_qualities gives every element's quality bit
 *    for bit as getme_mesh_element_qualities, and the same statistics as
 *    getme_mesh_measure_all, for 1, 2 and 3 threads (the statistics
 *    byte-identical across thread counts);
 *  - getme_mesh_quality_stats_from against statistics counted here from
 *    the qualities and the fixed mask (every type and all of them);
 *  - getme_mesh_worst_elements_from's bounded selection against a full
 *    sort of (quality, index), all elements and only those with a free
 *    node, for several list lengths, the same for any thread count.
 *
 * Meshes: 48,000 distorted tets (blocks longer than a measure tile), the
 * hex / prism / pyramid mix, triangles and quads, all distorted.
 */
#define N 20
#include "check.h"
#include "gen_mesh.h"

#include <omp.h>

typedef struct ranked {
    double q;
    int32_t e;
} ranked;

static int by_quality(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    if (x->q != y->q)
        return x->q < y->q ? -1 : 1;
    return x->e < y->e ? -1 : x->e > y->e;
}

/* Element e's nodes in gen's connectivity (blocks added in type order). */
static const int32_t *nodes_of(const gen *g, int32_t e, int *type)
{
    *type = -1;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        if (e < g->count[t]) {
            *type = t;
            return g->conn[t] + (int64_t)e * getme_type_num_nodes((getme_elem_type)t);
        }
        e -= g->count[t];
    }
    return NULL;
}

static int has_free(const gen *g, const uint8_t *fixed, int32_t e)
{
    int t = -1;
    const int32_t *c = nodes_of(g, e, &t);
    for (int i = 0; c && i < getme_type_num_nodes((getme_elem_type)t); i++)
        if (!fixed[c[i]])
            return 1;
    return 0;
}

/* getme_mesh_quality_stats_from(q, type) against the statistics counted
   here. */
static void check_stats(getme_mesh *m, const gen *g, const double *q,
                        const uint8_t *fixed, int type)
{
    getme_quality_stats s;
    CHECK_EQ_INT(getme_mesh_quality_stats_from(m, q, type, &s), GETME_OK);
    int64_t n = 0, invalid = 0, nfree = 0, b04 = 0, b01 = 0;
    int64_t hist[GETME_HIST_BINS] = {0};
    double qmin = 1.0, qmax = 0.0, qstar = 1.0, sum = 0.0;
    for (int32_t e = 0; e < getme_mesh_num_elements(m); e++) {
        int t = -1;
        nodes_of(g, e, &t);
        if (type >= 0 && t != type)
            continue;
        double v = q[e] > 0.0 ? q[e] : 0.0;
        n++;
        invalid += v == 0.0;
        if (v > 0.0)
            hist[v * GETME_HIST_BINS >= GETME_HIST_BINS
                     ? GETME_HIST_BINS - 1
                     : (int)(v * GETME_HIST_BINS)]++;
        qmin = v < qmin ? v : qmin;
        qmax = v > qmax ? v : qmax;
        if (has_free(g, fixed, e)) {
            nfree++;
            qstar = v < qstar ? v : qstar;
        }
        b04 += v <= 0.4;
        b01 += v < 0.1;
        sum += v;
    }
    CHECK(s.num_elements == n);
    CHECK(s.num_invalid == invalid);
    CHECK(s.num_free == nfree);
    CHECK(s.num_below_04 == b04 && s.num_below_01 == b01);
    CHECK(memcmp(s.histogram, hist, sizeof hist) == 0);
    if (n) {
        CHECK(s.q_min == qmin && s.q_max == qmax && s.q_min_star == qstar);
        CHECK(fabs(s.q_mean - sum / (double)n) < 1e-12);
    }
}

/* getme_mesh_worst_elements_from's list against a full sort. */
static void check_worst(getme_mesh *m, const gen *g, const double *q,
                        const uint8_t *fixed, int32_t max, unsigned flags,
                        getme_worst_element *w, int32_t *count)
{
    int32_t ne = getme_mesh_num_elements(m), n = 0;
    ranked *all = malloc((size_t)ne * sizeof *all);
    for (int32_t e = 0; e < ne; e++)
        if (!(flags & GETME_WORST_FREE_ONLY) || has_free(g, fixed, e))
            all[n++] = (ranked){q[e], e};
    qsort(all, (size_t)n, sizeof *all, by_quality);
    CHECK_EQ_INT(getme_mesh_worst_elements_from(m, q, max, flags, w, count),
                 GETME_OK);
    CHECK_EQ_INT(*count, n < max ? n : max);
    for (int32_t i = 0; i < *count; i++) {
        CHECK_EQ_INT(w[i].element, all[i].e);
        CHECK(w[i].quality == all[i].q);
    }
    free(all);
}

enum { MAX_LIST = 50 };

static void check_mesh(int kind)
{
    gen g = make_mesh(kind);
    getme_mesh *m = distorted(&g);
    int32_t ne = getme_mesh_num_elements(m), nn = getme_mesh_num_nodes(m);
    CHECK(ne > 0);
    double *q = malloc((size_t)ne * sizeof *q);
    double *q1 = malloc((size_t)ne * sizeof *q1);
    uint8_t *fixed = malloc((size_t)nn);
    CHECK_EQ_INT(getme_mesh_get_fixed_mask(m, fixed), GETME_OK);
    CHECK_EQ_INT(getme_mesh_element_qualities(m, q1), GETME_OK);
    enum { S = GETME_NUM_TYPES * GETME_NUM_MEASURES };
    static getme_measure_stats ref[S], st[S], plain[S];
    static getme_worst_element w1[2][MAX_LIST], w[MAX_LIST];
    int32_t n1[2] = {0, 0};
    for (int threads = 1; threads <= 3; threads++) {
        omp_set_num_threads(threads);
        for (int32_t e = 0; e < ne; e++)
            q[e] = -1.0;
        CHECK_EQ_INT(getme_mesh_measure_all_qualities(m, st, q), GETME_OK);
        CHECK(memcmp(q, q1, (size_t)ne * sizeof *q) == 0);
        CHECK_EQ_INT(getme_mesh_measure_all(m, plain), GETME_OK);
        CHECK(memcmp(st, plain, sizeof st) == 0);
        if (threads == 1)
            memcpy(ref, st, sizeof ref);
        CHECK(memcmp(st, ref, sizeof st) == 0);
        for (int t = -1; t < GETME_NUM_TYPES; t++)
            check_stats(m, &g, q, fixed, t);
        for (int f = 0; f < 2; f++) {
            unsigned flags = f ? GETME_WORST_FREE_ONLY : 0;
            static const int32_t lens[] = {1, 7, MAX_LIST};
            for (int k = 0; k < 3; k++) {
                int32_t n = 0;
                check_worst(m, &g, q, fixed, lens[k], flags, w, &n);
                if (lens[k] != MAX_LIST)
                    continue;
                /* the reasons too: the same list for any thread count */
                if (threads == 1) {
                    memcpy(w1[f], w, sizeof w);
                    n1[f] = n;
                }
                CHECK_EQ_INT(n, n1[f]);
                CHECK(memcmp(w, w1[f], (size_t)n * sizeof *w) == 0);
            }
        }
    }
    /* the one-call forms agree with the shared array */
    getme_quality_stats a, b;
    CHECK_EQ_INT(getme_mesh_quality_stats(m, -1, &a), GETME_OK);
    CHECK_EQ_INT(getme_mesh_quality_stats_from(m, q, -1, &b), GETME_OK);
    CHECK(a.q_mean == b.q_mean && a.q_min_star == b.q_min_star &&
          a.num_free == b.num_free);
    int32_t n = 0;
    CHECK_EQ_INT(getme_mesh_worst_elements(m, MAX_LIST, 0, w, &n), GETME_OK);
    CHECK(n == n1[0] && memcmp(w, w1[0], (size_t)n * sizeof *w) == 0);
    /* arguments */
    CHECK_EQ_INT(getme_mesh_quality_stats_from(m, NULL, -1, &a),
                 GETME_ERR_ARGUMENT);
    CHECK_EQ_INT(getme_mesh_quality_stats_from(m, q, 6, &a), GETME_ERR_ARGUMENT);
    CHECK_EQ_INT(getme_mesh_worst_elements_from(m, NULL, 3, 0, w, &n),
                 GETME_ERR_ARGUMENT);
    CHECK_EQ_INT(getme_mesh_worst_elements_from(m, q, 0, 0, w, &n), GETME_OK);
    CHECK_EQ_INT(n, 0);
    CHECK_EQ_INT(getme_mesh_measure_all_qualities(m, NULL, q),
                 GETME_ERR_ARGUMENT);
    free(q);
    free(q1);
    free(fixed);
    getme_mesh_free(m);
    free_gen(&g);
}

int main(void)
{
    for (int kind = 0; kind <= 4; kind++)
        if (kind != 1)
            check_mesh(kind);
    return check_summary("test_shared_qualities");
}
