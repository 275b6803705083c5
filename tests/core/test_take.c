/*
 * test_take.c -- getme_mesh_take_elements() and getme_mesh_create_take():
 * the mesh keeps the caller's malloc'd connectivity and coordinates
 * instead of copies, and the result is the mesh that getme_mesh_create()
 * and getme_mesh_add_elements() build: the same elements back, and the
 * same smoothed coordinates bit for bit, for every element type of the
 * generator (tets, hexes, mixed, planar).  A call that fails (a node out of
 * range, a repeated node, a wrong type, a coordinate not finite) or adds
 * nothing frees the array, so that nothing leaks and nothing is freed
 * twice: the ASan + UBSan build runs this with LeakSanitizer.
 */
#include "check.h"
#include "getme.h"
#include "gen_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A malloc'd copy of n ints of c. */
static int32_t *dup_ints(const int32_t *c, size_t n)
{
    int32_t *d = malloc((n ? n : 1) * sizeof *d);
    if (d && n)
        memcpy(d, c, n * sizeof *d);
    return d;
}

/* A malloc'd copy of n doubles of x. */
static double *dup_doubles(const double *x, size_t n)
{
    double *d = malloc((n ? n : 1) * sizeof *d);
    if (d && n)
        memcpy(d, x, n * sizeof *d);
    return d;
}

/* g's mesh as gen_mesh.h's distorted() builds it, with take instead of
   create and add; its elements checked against g's. */
static getme_mesh *taken(const gen *g)
{
    getme_mesh *m = NULL;
    double *x = dup_doubles(g->xyz, (size_t)g->nn * 3);
    CHECK(getme_mesh_create_take(&m, g->dim, g->nn, x) == GETME_OK);
    /* kept, not copied */
    CHECK(getme_mesh_coords(m) == x);
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        if (!g->count[t])
            continue;
        size_t len = (size_t)g->count[t] * getme_type_num_nodes((getme_elem_type)t);
        CHECK(getme_mesh_take_elements(m, (getme_elem_type)t, g->count[t],
                                       dup_ints(g->conn[t], len), NULL) == GETME_OK);
    }
    /* the elements read back are the caller's */
    int32_t e = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = getme_type_num_nodes((getme_elem_type)t);
        for (int32_t k = 0; k < g->count[t]; k++, e++) {
            getme_elem_type ty;
            int32_t nodes[8];
            CHECK(getme_mesh_get_element(m, e, &ty, nodes) == nv && (int)ty == t);
            CHECK(!memcmp(nodes, g->conn[t] + (size_t)k * nv, (size_t)nv * sizeof *nodes));
        }
    }
    int32_t nfix = 0;
    CHECK(getme_mesh_fix_boundary(m, GETME_FIX_SKIN | GETME_FIX_INTERFACES, &nfix) == GETME_OK);
    CHECK(getme_mesh_distort(m, 42, 0.6, 0.0, 3) == GETME_OK);
    return m;
}

/* m smoothed on 2 threads: its coordinates into x; m freed. */
static void smoothed(getme_mesh *m, double *x)
{
    getme_params p;
    getme_params_init(&p);
    p.num_threads = 2;
    CHECK(getme_smooth(m, &p, NULL) == GETME_OK);
    CHECK(getme_mesh_get_coords(m, x) == GETME_OK);
    getme_mesh_free(m);
}

int main(void)
{
    for (int kind = 0; kind <= 4; kind++) {
        gen g = make_mesh(kind);
        size_t bytes = (size_t)g.nn * 3 * sizeof(double);
        double *a = malloc(bytes), *b = malloc(bytes);
        smoothed(distorted(&g), a);
        smoothed(taken(&g), b);
        CHECK(!memcmp(a, b, bytes));
        free(a);
        free(b);
        free_gen(&g);
    }

    /* failures free the array (LeakSanitizer would report it otherwise)
       and leave the mesh without the block */
    double xyz[5 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    getme_mesh *m = NULL;
    CHECK(getme_mesh_create(&m, 3, 5, xyz) == GETME_OK);
    int32_t out_of_range[4] = {0, 1, 2, 5}, repeated[4] = {0, 1, 1, 3};
    int32_t good[8] = {0, 1, 2, 3, 1, 2, 3, 4};
    CHECK(getme_mesh_take_elements(m, GETME_TET, 1, dup_ints(out_of_range, 4),
                                   NULL) == GETME_ERR_TOPOLOGY);
    CHECK(getme_mesh_take_elements(m, GETME_TET, 1, dup_ints(repeated, 4),
                                   NULL) == GETME_ERR_TOPOLOGY);
    CHECK(getme_mesh_take_elements(m, GETME_TRI, 1, dup_ints(good, 3), NULL) ==
          GETME_ERR_ARGUMENT); /* a planar type in a 3-D mesh */
    CHECK(getme_mesh_take_elements(m, GETME_TET, -1, dup_ints(good, 4), NULL) ==
          GETME_ERR_ARGUMENT);
    CHECK(getme_mesh_take_elements(m, GETME_TET, 0, dup_ints(good, 0), NULL) ==
          GETME_OK);
    CHECK(getme_mesh_num_elements(m) == 0);
    int32_t region[2] = {7, 9};
    CHECK(getme_mesh_take_elements(m, GETME_TET, 2, dup_ints(good, 8), region) ==
          GETME_OK);
    CHECK(getme_mesh_num_elements(m) == 2);
    getme_elem_type ty;
    int32_t nodes[8];
    CHECK(getme_mesh_get_element(m, 1, &ty, nodes) == 4 && ty == GETME_TET &&
          !memcmp(nodes, good + 4, 4 * sizeof *nodes));
    CHECK(getme_mesh_take_elements(NULL, GETME_TET, 1, dup_ints(good, 4), NULL) ==
          GETME_ERR_ARGUMENT);
    getme_mesh_free(m);

    /* getme_mesh_create_take's failures free the coordinates too, and
       leave no mesh */
    double bad[5 * 3];
    memcpy(bad, xyz, sizeof bad);
    bad[7] = NAN;
    getme_mesh *other = NULL;
    CHECK(getme_mesh_create(&other, 3, 5, xyz) == GETME_OK);
    m = other; /* a failed call sets it to NULL */
    CHECK(getme_mesh_create_take(&m, 3, 5, dup_doubles(bad, 15)) ==
          GETME_ERR_ARGUMENT);
    CHECK(m == NULL);
    getme_mesh_free(other);
    bad[7] = INFINITY;
    CHECK(getme_mesh_create_take(&m, 3, 5, dup_doubles(bad, 15)) ==
          GETME_ERR_ARGUMENT);
    CHECK(getme_mesh_create_take(&m, 4, 5, dup_doubles(xyz, 15)) ==
          GETME_ERR_ARGUMENT);
    CHECK(getme_mesh_create_take(&m, 3, -1, dup_doubles(xyz, 15)) ==
          GETME_ERR_ARGUMENT);
    CHECK(getme_mesh_create_take(NULL, 3, 5, dup_doubles(xyz, 15)) ==
          GETME_ERR_ARGUMENT);
    CHECK(getme_mesh_create_take(&m, 3, 5, NULL) == GETME_ERR_ARGUMENT);
    CHECK(m == NULL);
    /* no nodes: the array is freed, the mesh has its own (empty) one */
    CHECK(getme_mesh_create_take(&m, 3, 0, dup_doubles(xyz, 3)) == GETME_OK);
    CHECK(m != NULL && getme_mesh_num_nodes(m) == 0);
    getme_mesh_free(m);
    /* a taken mesh's coordinates are the caller's values */
    double *x = dup_doubles(xyz, 15);
    CHECK(getme_mesh_create_take(&m, 3, 5, x) == GETME_OK);
    double back[15];
    CHECK(getme_mesh_get_coords(m, back) == GETME_OK);
    CHECK(!memcmp(back, xyz, sizeof back));
    getme_mesh_free(m);
    return check_summary("core_take");
}
