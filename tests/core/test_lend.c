/*
 * test_lend.c -- getme_mesh_lend_coords(): the smoother works in the mesh's
 * own coordinate array and gives it back in the caller's order.  The
 * coordinates returned are bit for bit those of a run without lending, for
 * every element type, mirrored planar meshes (y negated inside) and the
 * caller's node order (renumber 0); an invalid input with untangling off
 * still leaves the mesh unchanged; a cancelled run ends where the run
 * without lending ends.
 */
#include "check.h"
#include "getme.h"
#include "gen_mesh.h"

#include <stdlib.h>
#include <string.h>

static int stop_after_3(const getme_progress *p, void *data)
{
    (void)data;
    return p->iteration >= 3;
}

/* Smooth a fresh copy of g (y negated if flip) with params p, lending or
   not; the coordinates after it into x. */
static getme_status run(const gen *g, int flip, const getme_params *p,
                        int lend, double *x)
{
    gen h = *g;
    size_t bytes = (size_t)g->nn * 3 * sizeof(double);
    h.xyz = malloc(bytes);
    memcpy(h.xyz, g->xyz, bytes);
    for (int32_t i = 0; flip && i < g->nn; i++)
        h.xyz[3 * i + 1] = -h.xyz[3 * i + 1];
    getme_mesh *m = distorted(&h);
    getme_mesh_lend_coords(m, lend);
    getme_status st = getme_smooth(m, p, NULL);
    getme_mesh_get_coords(m, x);
    getme_mesh_free(m);
    free(h.xyz);
    return st;
}

int main(void)
{
    for (int kind = 0; kind <= 4; kind++)
        for (int flip = 0; flip <= (kind >= 3); flip++) {
            gen g = make_mesh(kind);
            size_t bytes = (size_t)g.nn * 3 * sizeof(double);
            double *a = malloc(bytes), *b = malloc(bytes);
            getme_params p;
            getme_params_init(&p);
            p.num_threads = 2;
            for (int renumber = 0; renumber <= 1; renumber++) {
                p.renumber = renumber;
                CHECK(run(&g, flip, &p, 0, a) == GETME_OK);
                CHECK(run(&g, flip, &p, 1, b) == GETME_OK);
                CHECK(!memcmp(a, b, bytes));
            }
            p.progress = stop_after_3;
            CHECK(run(&g, flip, &p, 0, a) == GETME_ERR_CANCELLED);
            CHECK(run(&g, flip, &p, 1, b) == GETME_ERR_CANCELLED);
            CHECK(!memcmp(a, b, bytes));
            free(a), free(b);
            free_gen(&g);
        }

    /* An inverted tet, untangling off: refused, coordinates unchanged. */
    double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    int32_t inv[] = {0, 2, 1, 3, 1, 2, 3, 4};
    getme_mesh *m = NULL;
    CHECK(getme_mesh_create(&m, 3, 5, xyz) == GETME_OK);
    CHECK(getme_mesh_add_elements(m, GETME_TET, 2, inv, NULL) == GETME_OK);
    getme_mesh_lend_coords(m, 1);
    getme_params off;
    getme_params_init(&off);
    off.untangle = 0;
    CHECK(getme_smooth(m, &off, NULL) == GETME_ERR_INVALID_MESH);
    CHECK(getme_mesh_coords(m) && !memcmp(getme_mesh_coords(m), xyz, sizeof xyz));
    getme_mesh_free(m);
    return check_summary("test_lend");
}
