/*
 * test_finish_sub.c -- the finishing step on a sub-mesh
 * (getme_smooth_finish_sub) gives getme_smooth_finish()'s bits on the
 * whole mesh, for random cuts of distorted tet, hex and mixed meshes.
 *
 * A cut: a random set of elements (the lowest qualities up to a random
 * count, plus random others) whose nodes get complete stars; the sub-mesh
 * is every element touching those nodes.  Too small a cut must be refused
 * with GETME_ERR_INCOMPLETE (result untouched, nothing reported); then
 * the cut doubles until it is accepted, and the accepted run must move
 * the same nodes to the same bits and report the whole mesh's values.
 */
#include "check.h"
#include "getme.h"
#define N 14 /* big enough that the finishing step's elements are a part */
#include "gen_mesh.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static uint64_t rnd(uint64_t *s)
{
    *s ^= *s << 13, *s ^= *s >> 7, *s ^= *s << 17;
    return *s;
}

static int calls;
static int count_calls(const getme_progress *p, void *data)
{
    (void)p, (void)data;
    calls++;
    return 0;
}

typedef struct elem_rank {
    double q;
    uint64_t key;
    int32_t e;
} elem_rank;

static int cmp_rank(const void *a, const void *b)
{
    const elem_rank *x = a, *y = b;
    if (x->q != y->q)
        return x->q < y->q ? -1 : 1;
    return (x->key > y->key) - (x->key < y->key);
}

/* Sub-mesh elements sorted by key (qsort on indices through a global:
   the test is single-threaded). */
static const uint64_t *sort_keys;
static int cmp_by_key(const void *a, const void *b)
{
    uint64_t x = sort_keys[*(const int32_t *)a];
    uint64_t y = sort_keys[*(const int32_t *)b];
    return (x > y) - (x < y);
}

typedef struct cut_out {
    getme_status st;
    int32_t ne_sub, nn_sub;
    getme_result res;
} cut_out;

/* Run the finishing step on the cut: elements with a node of the first
   `take` ranked elements or of the random extras. */
static cut_out run_cut(getme_mesh *loop, const elem_rank *ranked,
                       int32_t take, const uint8_t *extra,
                       const uint64_t *key, const getme_params *p,
                       const getme_result *loop_res, const double *ref)
{
    int32_t nn = getme_mesh_num_nodes(loop), ne = getme_mesh_num_elements(loop);
    const double *x = getme_mesh_coords(loop);
    uint8_t *in_s = calloc((size_t)nn, 1), *in_sub = calloc((size_t)ne, 1);
    uint8_t *fixed = malloc((size_t)nn);
    getme_mesh_get_fixed_mask(loop, fixed);
    for (int32_t e = 0; e < ne; e++) {
        int pick = extra[e];
        for (int32_t i = 0; i < take && !pick; i++)
            pick = ranked[i].e == e;
        if (!pick)
            continue;
        getme_elem_type t;
        int32_t c[8];
        int nv = getme_mesh_get_element(loop, e, &t, c);
        for (int i = 0; i < nv; i++)
            in_s[c[i]] = 1;
    }
    int32_t *elems = malloc((size_t)ne * sizeof *elems), m = 0;
    for (int32_t e = 0; e < ne; e++) {
        getme_elem_type t;
        int32_t c[8];
        int nv = getme_mesh_get_element(loop, e, &t, c);
        for (int i = 0; i < nv; i++)
            in_sub[e] |= in_s[c[i]];
        if (in_sub[e])
            elems[m++] = e;
    }
    sort_keys = key;
    qsort(elems, (size_t)m, sizeof *elems, cmp_by_key);
    /* sub nodes numbered in first use; fixed marks and positions of the
       whole mesh */
    int32_t *local = malloc((size_t)nn * sizeof *local), snn = 0;
    int32_t *global = malloc((size_t)nn * sizeof *global);
    for (int32_t i = 0; i < nn; i++)
        local[i] = -1;
    int32_t *conn = malloc((size_t)m * 8 * sizeof *conn);
    getme_elem_type *types = malloc((size_t)m * sizeof *types);
    int64_t nc = 0;
    for (int32_t k = 0; k < m; k++) {
        int32_t c[8];
        int nv = getme_mesh_get_element(loop, elems[k], &types[k], c);
        for (int i = 0; i < nv; i++) {
            if (local[c[i]] < 0)
                global[snn] = c[i], local[c[i]] = snn++;
            conn[nc++] = local[c[i]];
        }
    }
    double *sx = malloc((size_t)(snn ? snn : 1) * 3 * sizeof *sx);
    uint8_t *sfix = malloc((size_t)(snn ? snn : 1));
    uint8_t *complete = malloc((size_t)(snn ? snn : 1));
    uint64_t *skey = malloc((size_t)(m ? m : 1) * sizeof *skey);
    for (int32_t i = 0; i < snn; i++) {
        memcpy(sx + 3 * (size_t)i, x + 3 * (size_t)global[i], 3 * sizeof *sx);
        sfix[i] = fixed[global[i]];
        complete[i] = in_s[global[i]];
    }
    getme_mesh *sub = NULL;
    CHECK(getme_mesh_create(&sub, 3, snn, sx) == GETME_OK);
    nc = 0;
    for (int32_t k = 0; k < m;) { /* runs of one type, in key order */
        int32_t k1 = k;
        while (k1 < m && types[k1] == types[k])
            k1++;
        CHECK(getme_mesh_add_elements(sub, types[k], k1 - k, conn + nc,
                                      NULL) == GETME_OK);
        for (int32_t j = k; j < k1; j++)
            skey[j] = key[elems[j]];
        nc += (int64_t)(k1 - k) * getme_type_num_nodes(types[k]);
        k = k1;
    }
    CHECK(getme_mesh_set_fixed_mask(sub, sfix) == GETME_OK);
    /* the rest in two halves, merged: parts of it may come from anywhere */
    getme_finish_rest rest, half;
    getme_finish_rest_init(&rest);
    getme_finish_rest_init(&half);
    uint8_t *a = malloc((size_t)ne), *b = malloc((size_t)ne);
    for (int32_t e = 0; e < ne; e++) {
        a[e] = !in_sub[e] && e % 3 == 0;
        b[e] = !in_sub[e] && e % 3 != 0;
    }
    double *q = malloc((size_t)ne * sizeof *q); /* given for one half */
    for (int32_t e = 0; e < ne; e++) {
        getme_elem_type t;
        int32_t c[8];
        double xe[24];
        int nv = getme_mesh_get_element(loop, e, &t, c);
        for (int i = 0; i < nv; i++)
            memcpy(xe + 3 * i, x + 3 * (size_t)c[i], 3 * sizeof *xe);
        q[e] = getme_element_quality(t, xe);
    }
    CHECK(getme_finish_rest_add(&rest, loop, a, q) == GETME_OK);
    CHECK(getme_finish_rest_add(&half, loop, b, NULL) == GETME_OK);
    free(q);
    getme_finish_rest_merge(&rest, &half);
    CHECK(rest.num_elements == ne - m);

    cut_out out;
    out.res = *loop_res;
    out.ne_sub = m;
    out.nn_sub = snn;
    calls = 0;
    out.st = getme_smooth_finish_sub(sub, p, skey, complete, &rest, &out.res);
    if (out.st == GETME_ERR_INCOMPLETE) {
        CHECK(calls == 0);
        /* the bound that did not fit: one of the whole run's, so at most
           its last pass's, and at least q*_min at the start */
        CHECK(out.res.threshold >= loop_res->q_min_star);
        out.res.threshold = loop_res->threshold;
        CHECK(memcmp(&out.res, loop_res, sizeof out.res) == 0);
    } else if (out.st == GETME_OK) {
        CHECK_EQ_INT(calls, out.res.passes_finish);
        const double *y = getme_mesh_coords(sub);
        int32_t differ = 0;
        for (int32_t i = 0; i < snn; i++)
            differ += memcmp(y + 3 * (size_t)i, ref + 3 * (size_t)global[i],
                             3 * sizeof *y) != 0;
        for (int32_t i = 0; i < nn; i++) /* outside: nothing moved */
            if (local[i] < 0)
                differ += memcmp(x + 3 * (size_t)i, ref + 3 * (size_t)i,
                                 3 * sizeof *x) != 0;
        if (differ)
            fprintf(stderr, "sub-mesh of %d elements: %d nodes differ\n",
                    (int)m, (int)differ);
        CHECK(differ == 0);
        /* a shuffled element order is refused */
        if (m >= 2 && types[0] == types[1]) {
            uint64_t t = skey[0];
            skey[0] = skey[1], skey[1] = t;
            getme_result r2 = *loop_res;
            CHECK(getme_smooth_finish_sub(sub, p, skey, complete, &rest,
                                          &r2) == GETME_ERR_ARGUMENT);
        }
    }
    getme_mesh_free(sub);
    free(in_s), free(in_sub), free(fixed), free(elems), free(local);
    free(global), free(conn), free(types), free(sx), free(sfix);
    free(complete), free(skey), free(a), free(b);
    return out;
}

int main(void)
{
    uint64_t seed = 0x2545f4914f6cdd1dull;
    for (int kind = 0; kind < 3; kind++) {
        gen g = make_mesh(kind);
        getme_mesh *whole = distorted(&g);
        getme_mesh *loop = distorted(&g);
        int32_t nn = getme_mesh_num_nodes(whole);
        int32_t ne = getme_mesh_num_elements(whole);
        /* keys at the input coordinates, in the whole mesh's box */
        const double *x0 = getme_mesh_coords(whole);
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (int32_t i = 0; i < nn; i++)
            for (int d = 0; d < 3; d++) {
                double v = x0[3 * (size_t)i + d];
                lo[d] = v < lo[d] ? v : lo[d];
                hi[d] = v > hi[d] ? v : hi[d];
            }
        uint64_t *key = malloc((size_t)ne * sizeof *key);
        for (int32_t e = 0; e < ne; e++) {
            getme_elem_type t;
            int32_t c[8];
            getme_mesh_get_element(whole, e, &t, c);
            key[e] = getme_element_key(t, e, x0 + 3 * (size_t)c[0], lo, hi);
            CHECK((int)(key[e] >> 61) == (int)t);
            CHECK((int32_t)(key[e] & 0x7fffffff) == e);
        }
        /* the loop without the finishing step, then the reference */
        getme_params p;
        getme_params_init(&p);
        p.num_threads = 2;
        p.finish = 0;
        getme_result loop_res, ref_res;
        CHECK(getme_smooth(loop, &p, &loop_res) == GETME_OK);
        p.finish = 1;
        ref_res = loop_res;
        CHECK(getme_smooth_finish(whole, &p, getme_mesh_coords(loop),
                                  &ref_res) == GETME_OK);
        CHECK(ref_res.passes_finish >= 1);
        const double *ref = getme_mesh_coords(whole);
        int32_t moved = 0;
        for (int32_t i = 0; i < nn; i++)
            moved += memcmp(ref + 3 * (size_t)i,
                            getme_mesh_coords(loop) + 3 * (size_t)i,
                            3 * sizeof *ref) != 0;
        CHECK(moved > 0); /* the finishing step does something here */
        p.progress = count_calls;

        /* free elements ranked by (quality at the loop's end, key) */
        elem_rank *ranked = malloc((size_t)ne * sizeof *ranked);
        uint8_t *fixed = malloc((size_t)nn);
        getme_mesh_get_fixed_mask(loop, fixed);
        int32_t nfree = 0;
        for (int32_t e = 0; e < ne; e++) {
            getme_elem_type t;
            int32_t c[8];
            double xe[24];
            int nv = getme_mesh_get_element(loop, e, &t, c), free_e = 0;
            for (int i = 0; i < nv; i++) {
                memcpy(xe + 3 * i, getme_mesh_coords(loop) + 3 * (size_t)c[i],
                       3 * sizeof *xe);
                free_e |= !fixed[c[i]];
            }
            if (free_e) {
                ranked[nfree].q = getme_element_quality(t, xe);
                ranked[nfree].key = key[e];
                ranked[nfree++].e = e;
            }
        }
        qsort(ranked, (size_t)nfree, sizeof *ranked, cmp_rank);

        uint8_t *extra = calloc((size_t)ne, 1);
        int refused = 0, accepted = 0;
        for (int trial = 0; trial < 4; trial++) {
            memset(extra, 0, (size_t)ne);
            for (int j = 0; j < 1 + trial * 5; j++)
                extra[rnd(&seed) % (uint64_t)ne] = 1;
            int32_t take = (int32_t)(rnd(&seed) % 40); /* below 64: refused */
            for (;;) {
                cut_out o = run_cut(loop, ranked, take, extra, key, &p,
                                    &loop_res, ref);
                if (o.st == GETME_ERR_INCOMPLETE) {
                    refused++;
                    CHECK(take < nfree);
                    take = take ? 2 * take : 32;
                    take = take > nfree ? nfree : take;
                    continue;
                }
                CHECK(o.st == GETME_OK);
                if (o.st != GETME_OK)
                    break;
                accepted++;
                getme_result *r = &o.res;
                CHECK_EQ_INT(r->passes_finish, ref_res.passes_finish);
                CHECK_EQ_INT(r->moved_finish, ref_res.moved_finish);
                CHECK(memcmp(&r->q_mean, &ref_res.q_mean, sizeof r->q_mean) == 0);
                CHECK(memcmp(&r->q_min_star, &ref_res.q_min_star,
                             sizeof r->q_min_star) == 0);
                CHECK(memcmp(&r->q_min, &ref_res.q_min, sizeof r->q_min) == 0);
                CHECK(memcmp(&r->corner_sj, &ref_res.corner_sj,
                             sizeof r->corner_sj) == 0);
                if (trial == 0)
                    fprintf(stderr, "kind %d: sub-mesh of %d of %d elements, "
                            "%d nodes, %d passes\n", kind, (int)o.ne_sub,
                            (int)ne, (int)o.nn_sub, r->passes_finish);
                break;
            }
        }
        CHECK(refused > 0);
        CHECK(accepted == 4);
        free(extra), free(ranked), free(fixed), free(key);
        getme_mesh_free(whole), getme_mesh_free(loop);
        free_gen(&g);
    }
    /* planar meshes are refused (a sub-mesh would decide its orientation
       alone), as are missing arguments */
    gen g = make_mesh(3);
    getme_mesh *flat = build(&g);
    int32_t fne = getme_mesh_num_elements(flat);
    uint64_t *fkey = calloc((size_t)fne, sizeof *fkey);
    uint8_t *fcomplete = calloc((size_t)getme_mesh_num_nodes(flat), 1);
    getme_finish_rest rest;
    getme_finish_rest_init(&rest);
    CHECK(rest.num_elements == 0 && rest.q_min == 1.0 && rest.corner_min == 1.0);
    CHECK(getme_finish_rest_add(&rest, flat, NULL, NULL) == GETME_ERR_ARGUMENT);
    getme_result r;
    memset(&r, 0, sizeof r);
    CHECK(getme_smooth_finish_sub(flat, NULL, fkey, fcomplete, &rest, &r) ==
          GETME_ERR_ARGUMENT);
    CHECK(getme_smooth_finish_sub(flat, NULL, NULL, fcomplete, &rest, &r) ==
          GETME_ERR_ARGUMENT);
    free(fkey), free(fcomplete);
    getme_mesh_free(flat);
    free_gen(&g);
    return check_summary("test_finish_sub");
}
