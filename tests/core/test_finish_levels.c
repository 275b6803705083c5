/*
 * test_finish_levels.c -- the finishing step's levelled sweeps (finish.c,
 * finish_levels.h) make exactly the serial moves.
 *
 * Distorted tet, hex and mixed meshes with clusters of very bad elements
 * (balls of nodes distorted hard, so many listed elements share nodes and
 * stars) go through getme_smooth_finish() with a long list (5 % of the
 * elements): on one thread the serial sweeps, on 2..4 threads the
 * levelled ones.  Every coordinate must have the same bits, and the
 * result the same passes, raised count and qualities:
 *   - as scheduled (levels in parallel);
 *   - each level run backwards (GETME_FINISH_REVERSE, test builds);
 *   - every second sweep taken back from a third of its list and finished
 *     serially (GETME_FINISH_TAKE_BACK), the path the serial budget takes
 *     when it refuses a move the levelled sweep made;
 *   - without the memo of failed climbs (GETME_FINISH_NO_MEMO): it only
 *     skips climbs that would fail.
 * Built from the core's sources with GETME_FINISH_TEST and
 * GETME_CHECK_SUMS (the pool's bound, list and sums checked every pass).
 *
 * With the argument "mutant" (the build with GETME_FINISH_MUTANT, whose
 * levels ignore every free node's star but the first) the backwards
 * schedule must give different bits on some mesh: the check can fail.
 */
#define _POSIX_C_SOURCE 200112L /* setenv */
#include "check.h"
#include "getme.h"
#define N 14
#include "gen_mesh.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* gen's mesh, distorted everywhere, then hard inside three balls. */
static getme_mesh *clustered(const gen *g)
{
    getme_mesh *m = distorted(g);
    int32_t nn = getme_mesh_num_nodes(m);
    uint8_t *fixed = malloc((size_t)nn), *inner = malloc((size_t)nn);
    getme_mesh_get_fixed_mask(m, fixed);
    const double *x = getme_mesh_coords(m);
    static const double centre[3][3] = {{3.5, 3.5, 3.5}, {9.5, 4.5, 8.5},
                                        {6.5, 10.5, 5.5}};
    for (int32_t i = 0; i < nn; i++) {
        int in = 0;
        for (int b = 0; b < 3; b++) {
            double d2 = 0.0;
            for (int d = 0; d < 3; d++) {
                double v = x[3 * (size_t)i + d] - centre[b][d];
                d2 += v * v;
            }
            in |= d2 < 2.6 * 2.6;
        }
        inner[i] = fixed[i] || !in;
    }
    CHECK(getme_mesh_set_fixed_mask(m, inner) == GETME_OK);
    CHECK(getme_mesh_distort(m, 7, 0.9, 0.0, 12) == GETME_OK);
    CHECK(getme_mesh_set_fixed_mask(m, fixed) == GETME_OK);
    free(fixed), free(inner);
    return m;
}

typedef struct run_out {
    double *x;
    getme_result res;
} run_out;

/* The finishing step on gen's clustered mesh with t threads. */
static run_out finish(const gen *g, int t)
{
    getme_mesh *m = clustered(g);
    int32_t nn = getme_mesh_num_nodes(m);
    double *start = malloc((size_t)nn * 3 * sizeof *start);
    memcpy(start, getme_mesh_coords(m), (size_t)nn * 3 * sizeof *start);
    getme_params p;
    getme_params_init(&p);
    p.num_threads = t;
    p.finish = 1;
    p.finish_fraction = 0.05;
    run_out o;
    memset(&o.res, 0, sizeof o.res);
    CHECK(getme_smooth_finish(m, &p, start, &o.res) == GETME_OK);
    o.x = malloc((size_t)nn * 3 * sizeof *o.x);
    memcpy(o.x, getme_mesh_coords(m), (size_t)nn * 3 * sizeof *o.x);
    free(start);
    getme_mesh_free(m);
    return o;
}

/* Nodes whose bits differ from ref's. */
static int32_t differ(const run_out *ref, const run_out *o, int32_t nn)
{
    int32_t d = 0;
    for (int32_t i = 0; i < nn; i++)
        d += memcmp(ref->x + 3 * (size_t)i, o->x + 3 * (size_t)i,
                    3 * sizeof *o->x) != 0;
    return d;
}

static int same_result(const getme_result *a, const getme_result *b)
{
    return a->passes_finish == b->passes_finish &&
           a->moved_finish == b->moved_finish && a->q_min == b->q_min &&
           a->q_min_star == b->q_min_star && a->q_mean == b->q_mean;
}

/* GETME_CHECK_SUMS builds: smooth.c's corner minimum, which skips the
   elements whose quality bounds their corners, equals the full sweep
   (else it returns NaN), before and after, for both methods. */
static void corner_minimum(void)
{
    static const int kinds[] = {1, 2, 4};
    for (int k = 0; k < 3; k++)
        for (int method = 0; method < 2; method++) {
            gen g = make_mesh(kinds[k]);
            getme_mesh *m = distorted(&g);
            getme_params p;
            getme_params_init(&p);
            p.num_threads = 2;
            p.method = method ? GETME_METHOD_SMART_LAPLACE
                              : GETME_METHOD_ADAPTIVE;
            getme_result r;
            CHECK(getme_smooth(m, &p, &r) == GETME_OK);
            CHECK(r.corner_sj_initial == r.corner_sj_initial);
            CHECK(r.corner_sj == r.corner_sj && r.corner_sj > 0.0);
            getme_mesh_free(m);
            free_gen(&g);
        }
}

int main(int argc, char **argv)
{
    int mutant = argc > 1 && strcmp(argv[1], "mutant") == 0;
    static const char *modes[] = {NULL, "GETME_FINISH_REVERSE",
                                  "GETME_FINISH_TAKE_BACK",
                                  "GETME_FINISH_NO_MEMO"};
    int32_t mutant_diffs = 0;
    for (int kind = 0; kind < 3; kind++) {
        gen g = make_mesh(kind);
        run_out ref = finish(&g, 1);
        int32_t nn = g.nn;
        printf("kind %d: %d passes, %d raised, q*min %.4f\n", kind,
               ref.res.passes_finish, ref.res.moved_finish, ref.res.q_min_star);
        /* the step does work on many elements here */
        CHECK(ref.res.passes_finish >= 2);
        CHECK(ref.res.moved_finish > 100);
        for (int mode = 0; mode < 4; mode++) {
            if (mutant && mode != 1)
                continue;
            if (modes[mode])
                setenv(modes[mode], "1", 1);
            for (int t = mutant ? 2 : 1; t <= (mutant ? 2 : 4); t++) {
                run_out o = finish(&g, t);
                int32_t d = differ(&ref, &o, nn);
                if (mutant) {
                    mutant_diffs += d != 0 || !same_result(&ref.res, &o.res);
                    printf("mutant: kind %d, %d nodes differ\n", kind, (int)d);
                } else {
                    if (d)
                        fprintf(stderr, "kind %d mode %s threads %d: %d "
                                "nodes differ\n", kind,
                                modes[mode] ? modes[mode] : "-", t, (int)d);
                    CHECK_EQ_INT(d, 0);
                    CHECK(same_result(&ref.res, &o.res));
                }
                free(o.x);
            }
            if (modes[mode])
                unsetenv(modes[mode]);
        }
        free(ref.x);
        free_gen(&g);
    }
    if (!mutant)
        corner_minimum();
    if (mutant) {
        /* the broken rule must show: some mesh ends elsewhere */
        CHECK(mutant_diffs > 0);
        return check_summary("core_finish_levels_mutant");
    }
    return check_summary("core_finish_levels");
}
