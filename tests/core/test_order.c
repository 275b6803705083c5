/*
 * test_order.c -- GETMe adaptive's result does not depend on how the mesh
 * is numbered (issue #14): the node and Eq. 9 sums are exact (exact.h),
 * so permuting nodes and elements gives the same coordinates bit for bit.
 * Before the exact sums the colour order of the scatter followed the
 * numbering and the last bits differed.  Also runs the distributed entry
 * points (getme_smooth_part + getme_smooth_finish) with one part and
 * pass-through hooks: they must equal getme_smooth bit for bit.
 */
#include "check.h"
#include "getme.h"
#include "gen_mesh.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* A fixed pseudo-random permutation of 0..n-1 (xorshift, Fisher-Yates). */
static int32_t *permutation(int32_t n, uint64_t seed)
{
    int32_t *p = malloc((size_t)n * sizeof *p);
    for (int32_t i = 0; i < n; i++)
        p[i] = i;
    for (int32_t i = n - 1; i > 0; i--) {
        seed ^= seed << 13, seed ^= seed >> 7, seed ^= seed << 17;
        int32_t j = (int32_t)(seed % (uint64_t)(i + 1));
        int32_t t = p[i];
        p[i] = p[j], p[j] = t;
    }
    return p;
}

/* m's copy with node i renamed perm[i], each type's elements reversed and
   the types added in reverse order; the same fixed nodes. */
static getme_mesh *permuted(getme_mesh *m, const int32_t *perm)
{
    int32_t nn = getme_mesh_num_nodes(m), ne = getme_mesh_num_elements(m);
    const double *x = getme_mesh_coords(m);
    double *y = malloc((size_t)nn * 3 * sizeof *y);
    uint8_t *fx = malloc((size_t)nn), *fy = malloc((size_t)nn);
    getme_mesh_get_fixed_mask(m, fx);
    for (int32_t i = 0; i < nn; i++) {
        memcpy(y + 3 * (size_t)perm[i], x + 3 * (size_t)i, 3 * sizeof *x);
        fy[perm[i]] = fx[i];
    }
    getme_mesh *out = NULL;
    CHECK(getme_mesh_create(&out, getme_mesh_dim(m), nn, y) == GETME_OK);
    int32_t *conn = malloc((size_t)ne * 8 * sizeof *conn);
    for (int t = GETME_NUM_TYPES - 1; t >= 0; t--) {
        int32_t count = 0;
        int nv = getme_type_num_nodes((getme_elem_type)t);
        for (int32_t e = ne - 1; e >= 0; e--) {
            getme_elem_type type;
            int32_t c[8];
            getme_mesh_get_element(m, e, &type, c);
            if ((int)type != t)
                continue;
            for (int i = 0; i < nv; i++)
                conn[(size_t)count * nv + i] = perm[c[i]];
            count++;
        }
        if (count)
            CHECK(getme_mesh_add_elements(out, (getme_elem_type)t, count, conn,
                                          NULL) == GETME_OK);
    }
    CHECK(getme_mesh_set_fixed_mask(out, fy) == GETME_OK);
    free(conn), free(y), free(fx), free(fy);
    return out;
}

/* One part holding everything: the hooks have nothing to exchange. */
static int no_order(void *ctx, int32_t n, const int32_t *idx)
{
    (void)ctx, (void)n, (void)idx;
    return 0;
}
static int no_sum(void *ctx, void *v, int k) { (void)ctx, (void)v, (void)k; return 0; }
static int no_or(void *ctx, uint8_t *f) { (void)ctx, (void)f; return 0; }
static int no_i64(void *ctx, int64_t *v, int n) { (void)ctx, (void)v, (void)n; return 0; }
static int no_min(void *ctx, double *v, int n) { (void)ctx, (void)v, (void)n; return 0; }
static int fail_i64(void *ctx, int64_t *v, int n)
{
    int *calls = ctx;
    (void)v, (void)n;
    return ++*calls > 40; /* fails some way into the loop */
}

static void same_coords(getme_mesh *a, getme_mesh *b, const int32_t *perm,
                        const char *what)
{
    int32_t nn = getme_mesh_num_nodes(a), differ = 0;
    const double *x = getme_mesh_coords(a), *y = getme_mesh_coords(b);
    for (int32_t i = 0; i < nn; i++)
        differ += memcmp(x + 3 * (size_t)i,
                         y + 3 * (size_t)(perm ? perm[i] : i),
                         3 * sizeof *x) != 0;
    if (differ)
        fprintf(stderr, "%s: %d nodes differ\n", what, (int)differ);
    CHECK(differ == 0);
}

int main(void)
{
    for (int kind = 0; kind < 3; kind++) {
        gen g = make_mesh(kind);
        getme_mesh *a = distorted(&g);
        int32_t nn = getme_mesh_num_nodes(a);
        int32_t *perm = permutation(nn, 0x9e3779b97f4a7c15ull + (uint64_t)kind);
        getme_mesh *b = permuted(a, perm);
        getme_mesh *c = permuted(a, perm); /* for the distributed path */
        getme_mesh *d = permuted(a, perm);
        getme_params p;
        getme_params_init(&p);
        p.finish = 0; /* its worst-first order follows the numbering */
        p.num_threads = 2;
        getme_result ra, rb;
        CHECK(getme_smooth(a, &p, &ra) == GETME_OK);
        p.num_threads = 1;
        CHECK(getme_smooth(b, &p, &rb) == GETME_OK);
        CHECK(ra.iterations > 5);
        CHECK_EQ_INT(ra.iterations, rb.iterations);
        CHECK(memcmp(&ra.q_mean, &rb.q_mean, sizeof ra.q_mean) == 0);
        CHECK(memcmp(&ra.q_min_star, &rb.q_min_star, sizeof ra.q_min_star) == 0);
        same_coords(a, b, perm, "permuted numbering");

        /* getme_smooth_part with one part = getme_smooth without the
           finishing step, then getme_smooth_finish = with it */
        int32_t ne = getme_mesh_num_elements(c);
        uint8_t *ones = malloc((size_t)(ne > nn ? ne : nn));
        memset(ones, 1, (size_t)(ne > nn ? ne : nn));
        getme_comm h = {NULL, ones, ones, no_order, no_sum, no_or, no_i64,
                        no_sum, no_min};
        getme_params q;
        getme_params_init(&q);
        q.num_threads = 2;
        getme_result rc, rd;
        double *start = malloc((size_t)nn * 3 * sizeof *start);
        getme_mesh_get_coords(c, start);
        CHECK(getme_smooth_part(c, &q, &h, &rc) == GETME_OK);
        CHECK_EQ_INT(rc.iterations, rb.iterations);
        CHECK(rc.passes_finish == 0);
        same_coords(b, c, NULL, "getme_smooth_part, one part");
        double *xyz = malloc((size_t)nn * 3 * sizeof *xyz);
        getme_mesh_get_coords(c, xyz);
        CHECK(getme_mesh_set_coords(c, start) == GETME_OK);
        CHECK(getme_smooth_finish(c, &q, xyz, &rc) == GETME_OK);
        CHECK(getme_smooth(d, &q, &rd) == GETME_OK);
        CHECK(rd.passes_finish >= 1);
        CHECK_EQ_INT(rc.passes_finish, rd.passes_finish);
        CHECK(memcmp(&rc.q_min_star, &rd.q_min_star, sizeof rc.q_min_star) == 0);
        same_coords(d, c, NULL, "getme_smooth_part + getme_smooth_finish");

        /* a failing hook stops the loop with GETME_ERR_COMM, mesh valid */
        int calls = 0;
        getme_comm bad = h;
        bad.ctx = &calls;
        bad.sum_i64 = fail_i64;
        CHECK(getme_mesh_set_coords(c, start) == GETME_OK);
        CHECK(getme_smooth_part(c, &q, &bad, &rc) == GETME_ERR_COMM);
        getme_quality_stats s;
        CHECK(getme_mesh_quality_stats(c, -1, &s) == GETME_OK);
        CHECK(s.num_invalid == 0);

        free(start), free(xyz), free(ones), free(perm);
        getme_mesh_free(a), getme_mesh_free(b), getme_mesh_free(c);
        getme_mesh_free(d);
        free_gen(&g);
    }
    return check_summary("test_order");
}
