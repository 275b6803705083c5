/*
 * test_measures_tiles.c -- getme_mesh_measure_all() computes every measure
 * in one sweep, in tiles of 32768 elements reduced in element order.  On
 * meshes with blocks longer than a tile (48,000 distorted tets; a
 * hex / pyramid / prism mix in three blocks) its statistics must equal,
 * byte for byte, those of getme_mesh_measure_stats() one measure at a
 * time, for 1 and 2 threads; also undistorted (exact ties everywhere: the
 * first element of each extreme must win, which the lane-wise reduction of
 * full groups of GETME_LANES elements gets by merging its lanes) and with
 * a last group of fewer than GETME_LANES tets (reduced one at a time after
 * the lanes of the same thread).  Also the fixed-node count of the topology
 * search (faces.c's hash grouping) on both meshes: exactly the grid nodes
 * on the skin, counted from the grid (and the unused nodes).
 */
#define N 20
#include "check.h"
#include "gen_mesh.h"

#include <omp.h>

static void compare(getme_mesh *mesh)
{
    getme_measure_stats all[GETME_NUM_TYPES * GETME_NUM_MEASURES], s;
    getme_measure_stats all2[GETME_NUM_TYPES * GETME_NUM_MEASURES];
    omp_set_num_threads(1);
    CHECK_EQ_INT(getme_mesh_measure_all(mesh, all), GETME_OK);
    omp_set_num_threads(2);
    CHECK_EQ_INT(getme_mesh_measure_all(mesh, all2), GETME_OK);
    CHECK(memcmp(all, all2, sizeof all) == 0);
    int64_t counted = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        for (int k = 0; k < GETME_NUM_MEASURES; k++) {
            CHECK_EQ_INT(getme_mesh_measure_stats(mesh, t, (getme_measure)k, &s), GETME_OK);
            CHECK(memcmp(&s, &all[t * GETME_NUM_MEASURES + k], sizeof s) == 0);
            counted += s.num_elements;
        }
    CHECK(counted > 0);
}

/* The tets of g but the last `drop`, undistorted or distorted. */
static getme_mesh *truncated(gen *g, int32_t drop, int distort)
{
    int32_t count = g->count[GETME_TET];
    g->count[GETME_TET] = count - drop;
    getme_mesh *m = build(g);
    g->count[GETME_TET] = count;
    if (distort)
        CHECK(getme_mesh_distort(m, 42, 0.6, 0.0, 3) == GETME_OK);
    return m;
}

int main(void)
{
    /* (N+1)^3 grid nodes, of which (N-1)^3 are interior. */
    int32_t skin = (N + 1) * (N + 1) * (N + 1) - (N - 1) * (N - 1) * (N - 1);
    gen g = make_mesh(0);
    CHECK_EQ_INT(g.count[GETME_TET], 6 * N * N * N);
    getme_mesh *m = distorted(&g);
    CHECK_EQ_INT(getme_mesh_num_fixed(m), skin);
    compare(m);
    getme_mesh_free(m);
    for (int distort = 0; distort < 2; distort++)
        for (int32_t drop = 0; drop < 8; drop += 3) {
            m = truncated(&g, drop, distort);
            compare(m);
            getme_mesh_free(m);
        }
    free_gen(&g);

    g = make_mesh(2);
    m = distorted(&g);
    /* the 8 used pyramid centres are interior, the hex / prism / pyramid
       interfaces are no skin (one region), and the other N^3 - 8 centre
       nodes gen_mesh.h allocates are used by no element: fixed */
    CHECK_EQ_INT(getme_mesh_num_fixed(m), skin + N * N * N - 8);
    compare(m);
    getme_mesh_free(m);
    m = build(&g);
    compare(m);
    getme_mesh_free(m);
    free_gen(&g);
    return check_summary("test_measures_tiles");
}
