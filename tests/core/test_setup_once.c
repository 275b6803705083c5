/*
 * test_setup_once.c -- the smoother's set-up is built once and the caller's
 * arrays are lent to it (issue #13), without changing any result:
 *  - getme_mesh_fix_boundary keeps its workspace and face table on the
 *    mesh and getme_smooth takes them over: the same bits as a smoothing
 *    that builds its own;
 *  - new coordinates drop the kept workspace (it holds a copy of the old
 *    ones): smoothing then starts from the new coordinates;
 *  - a second boundary search reuses it and fixes the same nodes;
 *  - a one-block mesh lends its connectivity during getme_smooth and gets
 *    it back unchanged.
 */
#include "check.h"
#include "getme.h"
#include "gen_mesh.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static getme_mesh *with_coords(const gen *g, const double *xyz)
{
    getme_mesh *m = NULL;
    CHECK(getme_mesh_create(&m, g->dim, g->nn, xyz) == GETME_OK);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        if (g->count[t])
            CHECK(getme_mesh_add_elements(m, (getme_elem_type)t, g->count[t],
                                          g->conn[t], NULL) == GETME_OK);
    return m;
}

static int32_t fix(getme_mesh *m)
{
    int32_t n = -1;
    CHECK(getme_mesh_fix_boundary(m, GETME_FIX_SKIN | GETME_FIX_INTERFACES,
                                  &n) == GETME_OK);
    return n;
}

static void same_coords(getme_mesh *a, getme_mesh *b, const char *what)
{
    int32_t nn = getme_mesh_num_nodes(a);
    int differ = memcmp(getme_mesh_coords(a), getme_mesh_coords(b),
                        (size_t)nn * 3 * sizeof(double)) != 0;
    if (differ)
        fprintf(stderr, "%s: coordinates differ\n", what);
    CHECK(!differ);
}

/* The elements of m are those of g, in g's order. */
static void same_elements(getme_mesh *m, const gen *g)
{
    int32_t e = 0, bad = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nv = getme_type_num_nodes((getme_elem_type)t);
        for (int32_t k = 0; k < g->count[t]; k++, e++) {
            getme_elem_type type;
            int32_t c[8];
            bad += getme_mesh_get_element(m, e, &type, c) != nv ||
                   (int)type != t ||
                   memcmp(c, g->conn[t] + (size_t)k * nv,
                          (size_t)nv * sizeof *c) != 0;
        }
    }
    CHECK_EQ_INT(e, getme_mesh_num_elements(m));
    CHECK_EQ_INT(bad, 0);
}

int main(void)
{
    for (int kind = 0; kind < 4; kind++) { /* tet, hex, mixed (3 blocks), tri */
        gen g = make_mesh(kind);
        getme_mesh *d = distorted(&g);
        int32_t nn = getme_mesh_num_nodes(d);
        double *xyz = malloc((size_t)nn * 3 * sizeof *xyz);
        CHECK(getme_mesh_get_coords(d, xyz) == GETME_OK);

        getme_mesh *a = with_coords(&g, xyz); /* kept workspace used      */
        getme_mesh *b = with_coords(&g, xyz); /* dropped: built again     */
        getme_mesh *c = with_coords(&g, g.xyz); /* kept for other coords */
        int32_t na = fix(a), nb = fix(b), nc = fix(c);
        CHECK(na > 0);
        CHECK_EQ_INT(na, nb);
        CHECK_EQ_INT(na, nc);
        CHECK_EQ_INT(fix(a), na); /* again, on the kept workspace */
        CHECK(getme_mesh_set_coords(b, xyz) == GETME_OK);
        CHECK(getme_mesh_set_coords(c, xyz) == GETME_OK);

        getme_params p;
        getme_params_init(&p);
        p.num_threads = 2;
        getme_result ra, rb, rc;
        CHECK(getme_smooth(a, &p, &ra) == GETME_OK);
        CHECK(getme_smooth(b, &p, &rb) == GETME_OK);
        CHECK(getme_smooth(c, &p, &rc) == GETME_OK);
        CHECK(ra.iterations > 5);
        CHECK_EQ_INT(ra.iterations, rb.iterations);
        CHECK_EQ_INT(ra.iterations, rc.iterations);
        CHECK(memcmp(&ra.q_min_star, &rb.q_min_star, sizeof ra.q_min_star) == 0);
        CHECK(memcmp(&ra.q_mean, &rc.q_mean, sizeof ra.q_mean) == 0);
        same_coords(a, b, "kept workspace against a new one");
        same_coords(c, b, "workspace kept for other coordinates");
        same_elements(a, &g);
        same_elements(c, &g);

        /* and a second smoothing of the smoothed mesh still works (its
           connectivity is back; the workspace is built again) */
        CHECK(getme_smooth(a, &p, &ra) == GETME_OK);
        CHECK(getme_smooth(b, &p, &rb) == GETME_OK);
        same_coords(a, b, "second smoothing");
        same_elements(a, &g);

        free(xyz);
        getme_mesh_free(a), getme_mesh_free(b), getme_mesh_free(c);
        getme_mesh_free(d);
        free_gen(&g);
    }
    return check_summary("test_setup_once");
}
