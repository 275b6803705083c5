/*
 * test_smooth.c -- getme_smooth on generated, distorted meshes of every
 * type: output valid, fixed nodes bit-identical, q*min and qmean improved,
 * GETMe adaptive ahead of smart Laplace on q*min, bit-identical results for
 * 1 and 2 threads, argument and invalid-input errors.
 */
#include "check.h"
#include "getme.h"
#include "gen_mesh.h"

#include <stdlib.h>
#include <string.h>

static void check_kind(int kind, const char *name)
{
    gen g = make_mesh(kind);
    getme_mesh *m = distorted(&g);
    int32_t nn = getme_mesh_num_nodes(m);

    /* Skin: everything on the cube surface; count it exactly. */
    int32_t side = N + 1, expect_fixed = g.dim == 3
        ? side * side * side - (N - 1) * (N - 1) * (N - 1)
        : side * side - (N - 1) * (N - 1);
    if (kind == 2) /* centre nodes of the cubes that are not pyramids */
        expect_fixed += N * N * N - 8;
    CHECK_EQ_INT(getme_mesh_num_fixed(m), expect_fixed);

    getme_quality_stats before, after, lap;
    CHECK(getme_mesh_quality_stats(m, -1, &before) == GETME_OK);
    CHECK_EQ_INT(before.num_invalid, 0);
    double *x0 = malloc((size_t)nn * 3 * sizeof *x0);
    uint8_t *fixed = malloc((size_t)nn);
    getme_mesh_get_coords(m, x0);
    getme_mesh_get_fixed_mask(m, fixed);

    /* Laplace on a copy. */
    getme_mesh *ml = distorted(&g);
    getme_params p;
    getme_params_init(&p);
    p.method = GETME_METHOD_SMART_LAPLACE;
    getme_result rl;
    CHECK(getme_smooth(ml, &p, &rl) == GETME_OK);
    getme_mesh_quality_stats(ml, -1, &lap);
    CHECK_EQ_INT(lap.num_invalid, 0);

    getme_params_init(&p);
    p.num_threads = 1;
    getme_result r1;
    CHECK(getme_smooth(m, &p, &r1) == GETME_OK);
    CHECK(getme_mesh_quality_stats(m, -1, &after) == GETME_OK);
    CHECK_EQ_INT(after.num_invalid, 0);
    CHECK(after.q_min_star > before.q_min_star + 0.1);
    CHECK(after.q_mean > before.q_mean + 0.05);
    /* These structured meshes have a ceiling both methods reach (the Kuhn
       tets and right triangles cannot become regular: q <= 0.76 / 0.866),
       so GETMe must match smart Laplace there; the strict "well beyond"
       comparison is made on unstructured Gmsh meshes in tests/cli. */
    CHECK(after.q_min_star >= lap.q_min_star - 1e-3);
    CHECK(r1.iterations_mean > 0 && r1.iterations_min > 0);
    CHECK_NEAR(r1.q_min_star, after.q_min_star, 1e-12);
    CHECK_NEAR(r1.q_mean, after.q_mean, 1e-12);

    const double *x1 = getme_mesh_coords(m);
    int fixed_same = 1, moved = 0;
    for (int32_t i = 0; i < nn; i++) {
        int same = !memcmp(x1 + 3 * i, x0 + 3 * i, 3 * sizeof(double));
        if (fixed[i] && !same)
            fixed_same = 0;
        moved += !same;
    }
    CHECK(fixed_same);
    CHECK(moved > 0);

    /* Two threads: bit for bit the same coordinates. */
    getme_mesh *m2 = distorted(&g);
    p.num_threads = 2;
    getme_result r2;
    CHECK(getme_smooth(m2, &p, &r2) == GETME_OK);
    CHECK(!memcmp(getme_mesh_coords(m2), x1, (size_t)nn * 3 * sizeof(double)));
    CHECK_EQ_INT(r2.iterations, r1.iterations);

    printf("%-6s q*min %.4f -> getme %.4f (laplace %.4f), qmean %.4f -> %.4f "
           "(laplace %.4f), iterations %d/%d (laplace %d)\n",
           name, before.q_min_star, after.q_min_star, lap.q_min_star,
           before.q_mean, after.q_mean, lap.q_mean, r1.iterations_mean,
           r1.iterations_min, rl.iterations);
    getme_mesh_free(m);
    getme_mesh_free(m2);
    getme_mesh_free(ml);
    free(x0);
    free(fixed);
    free_gen(&g);
}

static void check_errors(void)
{
    getme_mesh *m = NULL;
    double xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    CHECK(getme_mesh_create(&m, 4, 4, xyz) == GETME_ERR_ARGUMENT);
    CHECK(getme_mesh_create(NULL, 3, 4, xyz) == GETME_ERR_ARGUMENT);
    CHECK(getme_mesh_create(&m, 3, 4, xyz) == GETME_OK);
    CHECK(getme_smooth(m, NULL, NULL) == GETME_ERR_STATE);
    int32_t bad[4] = {0, 1, 2, 4};
    CHECK(getme_mesh_add_elements(m, GETME_TET, 1, bad, NULL) == GETME_ERR_TOPOLOGY);
    CHECK(strstr(getme_mesh_error(m), "element 0") != NULL);
    int32_t rep[4] = {0, 1, 1, 3};
    CHECK(getme_mesh_add_elements(m, GETME_TET, 1, rep, NULL) == GETME_ERR_TOPOLOGY);
    CHECK(getme_mesh_add_elements(m, GETME_TRI, 1, rep, NULL) == GETME_ERR_ARGUMENT);
    /* Inverted tet: refused with untangle = 0, nothing moves; by default
       untangled (its nodes are free), then smoothed. */
    int32_t inv[4] = {0, 2, 1, 3};
    CHECK(getme_mesh_add_elements(m, GETME_TET, 1, inv, NULL) == GETME_OK);
    /* the distortion refuses it too, naming the element (the message
       once read the freed workspace: a crash, not an error) */
    CHECK(getme_mesh_distort(m, 1, 0.1, 0.0, 1) == GETME_ERR_INVALID_MESH);
    CHECK(strstr(getme_mesh_error(m),
                 "element 0 is invalid before distortion") != NULL);
    CHECK(!memcmp(getme_mesh_coords(m), xyz, sizeof xyz));
    getme_params off;
    getme_params_init(&off);
    off.untangle = 0;
    CHECK(getme_smooth(m, &off, NULL) == GETME_ERR_INVALID_MESH);
    CHECK(strstr(getme_mesh_error(m), "1 invalid") != NULL);
    CHECK(!memcmp(getme_mesh_coords(m), xyz, sizeof xyz));
    getme_result res;
    CHECK(getme_smooth(m, NULL, &res) == GETME_OK);
    CHECK(res.num_invalid_initial == 1 && res.q_min > 0.0);
    getme_mesh_free(m);

    getme_params p;
    getme_params_init(&p);
    CHECK(getme_params_set(&p, "sigma", 0.5) == GETME_OK && p.sigma == 0.5);
    CHECK(getme_params_set(&p, "sigma", -1) == GETME_ERR_ARGUMENT);
    CHECK(getme_params_set(&p, "nonsense", 1) == GETME_ERR_ARGUMENT);
    CHECK(getme_params_set(&p, "max_iter", 2.5) == GETME_ERR_ARGUMENT);
    double r[3] = {1, 0.5, 0.1};
    CHECK(getme_params_set_relax(&p, GETME_STAGE_MIN, 3, r) == GETME_ERR_ARGUMENT);
    r[2] = 0;
    CHECK(getme_params_set_relax(&p, GETME_STAGE_MIN, 3, r) == GETME_OK);
    CHECK_EQ_INT(p.num_relax_min, 3);

    /* The parameter table: every entry round-trips through set/get, its
       default is what getme_params_init sets, and its range is enforced. */
    getme_params d;
    getme_params_init(&d);
    CHECK(getme_param_count() >= 16);
    CHECK(getme_param_at(-1) == NULL && getme_param_at(getme_param_count()) == NULL);
    for (int i = 0; i < getme_param_count(); i++) {
        const getme_param_info *info = getme_param_at(i);
        double v = -99;
        CHECK(getme_param_find(info->name) == info);
        CHECK(getme_params_get(&d, info->name, &v) == GETME_OK);
        CHECK(v == info->default_value);
        CHECK(info->help && info->help[0]);
        getme_params q = d;
        double top = isfinite(info->max) ? info->max : 1e300;
        CHECK(getme_params_set(&q, info->name, top) == GETME_OK);
        CHECK(getme_params_get(&q, info->name, &v) == GETME_OK && v == top);
        CHECK(isfinite(info->max) ||
              getme_params_set(&q, info->name, INFINITY) == GETME_ERR_ARGUMENT);
        CHECK(getme_params_set(&q, info->name, info->min - 1) == GETME_ERR_ARGUMENT);
        CHECK(getme_params_set(&q, info->name, NAN) == GETME_ERR_ARGUMENT);
        if (info->type != GETME_PARAM_REAL)
            CHECK(getme_params_set(&q, info->name, info->min + 0.5) == GETME_ERR_ARGUMENT);
    }
    CHECK(d.max_iter == 1000 && d.sigma == 1.5 && d.threshold_fraction == 0.005 &&
          d.finish == 1 && d.corner_guard == 1 && d.untangle == 1 &&
          d.method == GETME_METHOD_ADAPTIVE && d.min_tol == 1e-5);
    CHECK(getme_params_set(&d, "sigma", 0.0) == GETME_ERR_ARGUMENT); /* open */
    CHECK(getme_params_set(&d, "method", 1) == GETME_OK &&
          d.method == GETME_METHOD_SMART_LAPLACE);
    CHECK(getme_param_find("nonsense") == NULL);
    /* A struct filled by hand is checked against the same table. */
    getme_mesh *mm = NULL;
    double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    int32_t c4[4] = {0, 1, 2, 3};
    CHECK(getme_mesh_create(&mm, 3, 4, tet) == GETME_OK);
    CHECK(getme_mesh_add_elements(mm, GETME_TET, 1, c4, NULL) == GETME_OK);
    getme_params_init(&d);
    d.finish_fraction = 2.0;
    CHECK(getme_smooth(mm, &d, NULL) == GETME_ERR_ARGUMENT);
    CHECK(strstr(getme_mesh_error(mm), "finish_fraction = 2 is out of its range [0, 1]") != NULL);
    getme_mesh_free(mm);
}

/* A mesh with no free node is left alone. */
static void check_all_fixed(void)
{
    double xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    int32_t c[4] = {0, 1, 2, 3};
    getme_mesh *m = NULL;
    CHECK(getme_mesh_create(&m, 3, 4, xyz) == GETME_OK);
    CHECK(getme_mesh_add_elements(m, GETME_TET, 1, c, NULL) == GETME_OK);
    int32_t nfix = 0;
    CHECK(getme_mesh_fix_boundary(m, GETME_FIX_SKIN, &nfix) == GETME_OK);
    CHECK_EQ_INT(nfix, 4);
    getme_result r;
    CHECK(getme_smooth(m, NULL, &r) == GETME_OK);
    CHECK_EQ_INT(r.stop_reason, GETME_STOP_NOTHING_TO_DO);
    CHECK(!memcmp(getme_mesh_coords(m), xyz, sizeof xyz));
    getme_mesh_free(m);
}

/* A mostly perfect mesh, a 20^3 hex grid with one interior node moved,
   smoothed with threshold_fraction = 1: every q*_min cycle then transforms
   every free element (q_t = the best quality, within 1e-12 of 1 here), so
   the q*_min stage's own lists (built from the stars, grown as needed) hold
   the whole mesh.  It must end valid, improve q*_min, and not depend on
   the thread count. */
static void check_mostly_perfect(void)
{
    enum { M = 20 };
    int32_t nn = (M + 1) * (M + 1) * (M + 1), ne = M * M * M;
    double *xyz = malloc((size_t)nn * 3 * sizeof *xyz);
    int32_t *hex = malloc((size_t)ne * 8 * sizeof *hex);
    for (int k = 0; k <= M; k++)
        for (int j = 0; j <= M; j++)
            for (int i = 0; i <= M; i++) {
                int32_t v = (k * (M + 1) + j) * (M + 1) + i;
                xyz[3 * v] = i, xyz[3 * v + 1] = j, xyz[3 * v + 2] = k;
            }
    int32_t moved = (10 * (M + 1) + 10) * (M + 1) + 10;
    xyz[3 * moved] += 0.3, xyz[3 * moved + 1] -= 0.2, xyz[3 * moved + 2] += 0.25;
    int32_t e = 0;
    for (int k = 0; k < M; k++)
        for (int j = 0; j < M; j++)
            for (int i = 0; i < M; i++, e++) {
                int32_t a = (k * (M + 1) + j) * (M + 1) + i, s = M + 1, l = s * s;
                int32_t c[8] = {a, a + 1, a + s + 1, a + s,
                                a + l, a + l + 1, a + l + s + 1, a + l + s};
                memcpy(hex + 8 * e, c, sizeof c);
            }
    double *out[2];
    getme_result r[2];
    for (int t = 0; t < 2; t++) {
        getme_mesh *m = NULL;
        CHECK(getme_mesh_create(&m, 3, nn, xyz) == GETME_OK);
        CHECK(getme_mesh_add_elements(m, GETME_HEX, ne, hex, NULL) == GETME_OK);
        CHECK(getme_mesh_fix_boundary(m, GETME_FIX_SKIN, NULL) == GETME_OK);
        getme_params p;
        getme_params_init(&p);
        p.num_threads = t + 1;
        p.threshold_fraction = 1.0;
        CHECK(getme_smooth(m, &p, &r[t]) == GETME_OK);
        CHECK(r[t].threshold > 1.0 - 1e-9); /* all free elements transformed */
        CHECK(r[t].cycles_min >= 1);
        CHECK(r[t].q_min > 0.0);
        CHECK(r[t].q_min_star > r[t].q_min_star_initial);
        out[t] = malloc((size_t)nn * 3 * sizeof *out[t]);
        memcpy(out[t], getme_mesh_coords(m), (size_t)nn * 3 * sizeof *out[t]);
        getme_mesh_free(m);
    }
    CHECK(!memcmp(out[0], out[1], (size_t)nn * 3 * sizeof *out[0]));
    free(out[0]), free(out[1]), free(xyz), free(hex);
}

/* keep_best: the result is never below the input's q*_min.  A perfect
   hex grid (q*_min 1 exactly) comes out of the q_mean stage a rounding step
   below 1 by rounding, and the best mesh of the q*_min stage stays below
   1: without the finishing step (which happens to win it back) and
   without putting nodes back it would end below 1 -- the case this
   guards (checked: the assertion fails when getme__input_revert is not
   called).  keep_best 0 puts nothing back.  On mildly distorted grids of
   every type q*_min must not end below the input's either. */
static void check_never_below_input(void)
{
    for (int kb = 0; kb < 2; kb++) {
        gen g = make_mesh(1);
        getme_mesh *m = build(&g);
        getme_params p;
        getme_params_init(&p);
        p.keep_best = kb;
        p.finish = 0;
        getme_result r;
        CHECK(getme_smooth(m, &p, &r) == GETME_OK);
        CHECK(r.q_min_star_initial == 1.0);
        if (kb) {
            CHECK(r.q_min_star >= r.q_min_star_initial);
            CHECK(r.reverted_nodes > 0);
        } else {
            CHECK_EQ_INT(r.reverted_nodes, 0);
        }
        getme_mesh_free(m);
        free_gen(&g);
    }
    for (int kind = 0; kind < 5; kind++)
        for (int s = 0; s < 4; s++) {
            gen g = make_mesh(kind);
            getme_mesh *m = build(&g);
            if (s)
                CHECK(getme_mesh_distort(m, 7 + s, 0.05 * s, 0.0, 3) ==
                      GETME_OK);
            getme_result r;
            CHECK(getme_smooth(m, NULL, &r) == GETME_OK);
            CHECK(r.q_min_star >= r.q_min_star_initial);
            getme_quality_stats after;
            CHECK(getme_mesh_quality_stats(m, -1, &after) == GETME_OK);
            CHECK_EQ_INT(after.num_invalid, 0);
            CHECK(after.q_min_star == r.q_min_star);
            getme_mesh_free(m);
            free_gen(&g);
        }
}

int main(void)
{
    check_never_below_input();
    check_errors();
    check_all_fixed();
    check_mostly_perfect();
    check_kind(0, "tet");
    check_kind(1, "hex");
    check_kind(2, "mixed");
    check_kind(3, "tri");
    check_kind(4, "quad");
    return check_summary("test_smooth");
}
