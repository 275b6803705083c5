/*
 * test_highorder.c -- second-order elements in the core (docs/highorder.md):
 * the Jacobian at all nodes, dependent nodes following the corners,
 * pinned mid-nodes, topology errors.
 */
#include "check.h"
#include "getme.h"

#include <stdlib.h>
#include <string.h>

/* Gmsh's tet10 reference nodes. */
static const double tet10_ref[10][3] = {
    {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {.5, 0, 0},
    {.5, .5, 0}, {0, .5, 0}, {0, 0, .5}, {0, .5, .5}, {.5, 0, .5}};

/* Gmsh's hex27 reference nodes (corners, edges, faces, body). */
static const int hex27_ref[27][3] = {
    {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
    {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1},
    {0, -1, -1}, {-1, 0, -1}, {-1, -1, 0}, {1, 0, -1},
    {1, -1, 0}, {0, 1, -1}, {1, 1, 0}, {-1, 1, 0},
    {0, -1, 1}, {-1, 0, 1}, {1, 0, 1}, {0, 1, 1},
    {0, 0, -1}, {0, -1, 0}, {-1, 0, 0}, {1, 0, 0},
    {0, 1, 0}, {0, 0, 1}, {0, 0, 0}};

/* getme_mesh_jacobian_ratio_min runs in parallel (highorder.c): it must
   still give the serial answer, the first element with the smallest
   ratio.  6000 separate tet10: regular, except elements 4500 and 2999
   (in different threads' ranges at 2 threads) with the same lower ratio,
   and element 5999 with a ratio between. */
static void test_ratio_min_first(void)
{
    enum { N = 6000 };
    double *xyz = malloc(sizeof(double) * 30 * N);
    int32_t *conn = malloc(sizeof(int32_t) * 10 * N);
    CHECK(xyz && conn);
    if (!xyz || !conn)
        return;
    for (int e = 0; e < N; e++)
        for (int i = 0; i < 10; i++) {
            for (int d = 0; d < 3; d++)
                xyz[30 * e + 3 * i + d] = tet10_ref[i][d] + (d == 0 ? 2.0 * e : 0.0);
            conn[10 * e + i] = 10 * e + i;
        }
    xyz[30 * 4500 + 12] = 2.0 * 4500 + 0.4; /* mid-node 4 at x = 0.4 */
    xyz[30 * 2999 + 12] = 2.0 * 2999 + 0.4;
    xyz[30 * 5999 + 12] = 2.0 * 5999 + 0.45;
    getme_mesh *m;
    CHECK(getme_mesh_create(&m, 3, 10 * N, xyz) == GETME_OK);
    CHECK(getme_mesh_add_elements_ho(m, GETME_TET10, N, conn, NULL) == GETME_OK);
    double r4500 = 0, r2999 = 0, r = 0;
    int32_t worst = -2;
    CHECK(getme_mesh_element_jacobian_ratio(m, 4500, &r4500) == GETME_OK);
    CHECK(getme_mesh_element_jacobian_ratio(m, 2999, &r2999) == GETME_OK);
    CHECK(r4500 == r2999 && r2999 < 0.5); /* the same bits: a real tie */
    CHECK(getme_mesh_jacobian_ratio_min(m, &r, &worst) == GETME_OK);
    CHECK_EQ_INT(worst, 2999);
    CHECK(r == r2999);
    getme_mesh_free(m);
    free(xyz);
    free(conn);
}

static void test_jacobian_ratio(void)
{
    double xyz[30];
    memcpy(xyz, tet10_ref, sizeof xyz);
    int32_t conn[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    getme_mesh *m;
    CHECK(getme_mesh_create(&m, 3, 10, xyz) == GETME_OK);
    CHECK(getme_mesh_add_elements_ho(m, GETME_TET10, 1, conn, NULL) == GETME_OK);
    CHECK_EQ_INT(getme_mesh_num_elements(m), 1);
    CHECK_EQ_INT(getme_mesh_num_elements_ho(m), 1);
    CHECK_EQ_INT(getme_mesh_num_elements_of_type(m, GETME_TET), 1);
    double r = 0;
    CHECK(getme_mesh_element_jacobian_ratio(m, 0, &r) == GETME_OK);
    CHECK_NEAR(r, 1.0, 1e-12);
    /* Mid-node of edge 0-1 at x = 0.4: dx/dxi = 1 + 4 * (-0.1) at node 0,
       1 - 4 * (-0.1) at node 1, so the ratio is 0.6 / 1.4. */
    xyz[12] = 0.4;
    CHECK(getme_mesh_set_coords(m, xyz) == GETME_OK);
    CHECK(getme_mesh_element_jacobian_ratio(m, 0, &r) == GETME_OK);
    CHECK_NEAR(r, 0.6 / 1.4, 1e-12);
    int32_t worst = -2;
    CHECK(getme_mesh_jacobian_ratio_min(m, &r, &worst) == GETME_OK);
    CHECK_NEAR(r, 0.6 / 1.4, 1e-12);
    CHECK_EQ_INT(worst, 0);
    /* x = 0.2: dx/dxi = -0.2 at node 0: invalid though the corners are
       the regular tet's. */
    xyz[12] = 0.2;
    CHECK(getme_mesh_set_coords(m, xyz) == GETME_OK);
    CHECK(getme_mesh_element_jacobian_ratio(m, 0, &r) == GETME_OK);
    CHECK(r < 0.0);
    CHECK(getme_element_quality(GETME_TET, xyz) > 0.8); /* corners: fine */
    /* ... so smoothing refuses it (nothing to untangle: no free node can
       repair a mid-node) */
    getme_params p;
    getme_params_init(&p);
    p.untangle = 0;
    CHECK(getme_smooth(m, &p, NULL) == GETME_ERR_INVALID_MESH);
    CHECK(strstr(getme_mesh_error(m), "first: 0") != NULL);
    getme_mesh_free(m);

    /* bad input */
    CHECK(getme_mesh_create(&m, 3, 10, tet10_ref[0]) == GETME_OK);
    int32_t rep[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 8};
    CHECK(getme_mesh_add_elements_ho(m, GETME_TET10, 1, rep, NULL) ==
          GETME_ERR_TOPOLOGY);
    CHECK(getme_mesh_add_elements_ho(m, GETME_NUM_HO_TYPES, 1, conn, NULL) ==
          GETME_ERR_ARGUMENT);
    CHECK_EQ_INT(getme_mesh_num_elements(m), 0);
    getme_mesh_free(m);
    CHECK_EQ_INT(getme_ho_type_num_nodes(GETME_HEX27), 27);
    CHECK_EQ_INT(getme_ho_type_linear(GETME_PRISM15), GETME_PRISM);
    CHECK(strcmp(getme_ho_type_name(GETME_QUAD8), "quad8") == 0);
}

/* A 2 x 2 x 2 block of hex27 on a 5 x 5 x 5 lattice (spacing 0.5): lattice
   point (a, b, c) is node a + 5 b + 25 c; corners have even indices. */
#define L 5
static int32_t lat(int a, int b, int c) { return a + L * b + L * L * c; }

/* Put every non-corner lattice node at the mean of its entity's corners. */
static void place_dependent(double *xyz)
{
    for (int c = 0; c < L; c++)
        for (int b = 0; b < L; b++)
            for (int a = 0; a < L; a++) {
                int odd[3] = {a & 1, b & 1, c & 1};
                if (!odd[0] && !odd[1] && !odd[2])
                    continue;
                double s[3] = {0, 0, 0};
                int n = 0;
                for (int i = -odd[0]; i <= odd[0]; i += 2)
                    for (int j = -odd[1]; j <= odd[1]; j += 2)
                        for (int k = -odd[2]; k <= odd[2]; k += 2, n++)
                            for (int d = 0; d < 3; d++)
                                s[d] += xyz[3 * lat(a + i, b + j, c + k) + d];
                for (int d = 0; d < 3; d++)
                    xyz[3 * lat(a, b, c) + d] = s[d] / n;
            }
}

static getme_mesh *hex27_block(double *xyz, int32_t *conn)
{
    for (int c = 0; c < L; c++)
        for (int b = 0; b < L; b++)
            for (int a = 0; a < L; a++) {
                double *p = xyz + 3 * lat(a, b, c);
                p[0] = 0.5 * a, p[1] = 0.5 * b, p[2] = 0.5 * c;
            }
    /* the centre corner off its place; dependent nodes straight */
    double *ctr = xyz + 3 * lat(2, 2, 2);
    ctr[0] += 0.3, ctr[1] -= 0.2, ctr[2] += 0.25;
    place_dependent(xyz);
    int e = 0;
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++, e++)
                for (int n = 0; n < 27; n++)
                    conn[27 * e + n] = lat(2 * i + 1 + hex27_ref[n][0],
                                           2 * j + 1 + hex27_ref[n][1],
                                           2 * k + 1 + hex27_ref[n][2]);
    getme_mesh *m;
    if (getme_mesh_create(&m, 3, L * L * L, xyz) != GETME_OK)
        return NULL;
    if (getme_mesh_add_elements_ho(m, GETME_HEX27, 8, conn, NULL) != GETME_OK) {
        getme_mesh_free(m);
        return NULL;
    }
    return m;
}

static void test_hex27_smooth(void)
{
    double xyz[3 * L * L * L], in[3 * L * L * L], out1[3 * L * L * L];
    int32_t conn[8 * 27];
    for (int threads = 1; threads <= 2; threads++) {
        getme_mesh *m = hex27_block(xyz, conn);
        CHECK(m != NULL);
        if (!m)
            return;
        memcpy(in, xyz, sizeof in);
        int32_t nfix = 0;
        CHECK(getme_mesh_fix_boundary(m, GETME_FIX_SKIN, &nfix) == GETME_OK);
        getme_params p;
        getme_params_init(&p);
        p.num_threads = threads;
        getme_result res;
        CHECK(getme_smooth(m, &p, &res) == GETME_OK);
        const double *x = getme_mesh_coords(m);
        /* the centre corner goes back to (1, 1, 1), the regular block */
        CHECK_NEAR(x[3 * lat(2, 2, 2)], 1.0, 1e-3);
        CHECK_NEAR(x[3 * lat(2, 2, 2) + 1], 1.0, 1e-3);
        CHECK_NEAR(x[3 * lat(2, 2, 2) + 2], 1.0, 1e-3);
        CHECK(res.q_min > 0.999);
        /* dependent nodes at their corners' mean (straight-sided) */
        double want[3 * L * L * L];
        memcpy(want, x, sizeof want);
        place_dependent(want);
        double worst = 0;
        for (int i = 0; i < 3 * L * L * L; i++)
            worst = fmax(worst, fabs(want[i] - x[i]));
        CHECK(worst < 1e-14);
        /* skin nodes (corners and mid-nodes) keep their bytes; interior
           mid-nodes moved */
        int skin_same = 1, moved = 0;
        for (int c = 0; c < L; c++)
            for (int b = 0; b < L; b++)
                for (int a = 0; a < L; a++) {
                    int32_t n = lat(a, b, c);
                    int skin = a == 0 || b == 0 || c == 0 || a == L - 1 ||
                               b == L - 1 || c == L - 1;
                    int same = memcmp(x + 3 * n, in + 3 * n,
                                      3 * sizeof *x) == 0;
                    if (skin)
                        skin_same &= same;
                    else
                        moved += !same;
                }
        CHECK(skin_same);
        CHECK_EQ_INT(moved, 27); /* 3x3x3 interior lattice points */
        for (int e = 0; e < 8; e++) {
            double r;
            CHECK(getme_mesh_element_jacobian_ratio(m, e, &r) == GETME_OK);
            CHECK(r > 0.999);
        }
        if (threads == 1)
            memcpy(out1, x, sizeof out1);
        else
            CHECK(memcmp(out1, x, sizeof out1) == 0);
        getme_mesh_free(m);
    }
}

/* A mid-node fixed by the caller stays bit for bit; the element is then
   curved by the corner move, and stays valid at every node. */
static void test_pinned_midnode(void)
{
    double xyz[3 * L * L * L];
    int32_t conn[8 * 27];
    getme_mesh *m = hex27_block(xyz, conn);
    CHECK(m != NULL);
    if (!m)
        return;
    CHECK(getme_mesh_fix_boundary(m, GETME_FIX_SKIN, NULL) == GETME_OK);
    int32_t mid = lat(2, 2, 1); /* edge between centre and bottom centre */
    double before[3];
    memcpy(before, xyz + 3 * mid, sizeof before);
    CHECK(getme_mesh_fix_nodes(m, 1, &mid) == GETME_OK);
    CHECK(getme_smooth(m, NULL, NULL) == GETME_OK);
    const double *x = getme_mesh_coords(m);
    CHECK(memcmp(x + 3 * mid, before, sizeof before) == 0);
    CHECK(memcmp(x + 3 * lat(2, 2, 2), xyz + 3 * lat(2, 2, 2),
                 3 * sizeof *x) != 0);
    for (int e = 0; e < 8; e++) {
        double r;
        CHECK(getme_mesh_element_jacobian_ratio(m, e, &r) == GETME_OK);
        CHECK(r > 0.0);
    }
    getme_mesh_free(m);
}

/* A node that is a mid-node of one element and a corner of another. */
static void test_topology(void)
{
    double xyz[3 * 14];
    memcpy(xyz, tet10_ref, sizeof tet10_ref);
    double extra[12] = {1, 1, 1, 2, 0, 0, 0, 2, 0, 0.5, 0.5, 2};
    memcpy(xyz + 30, extra, sizeof extra);
    int32_t conn[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    int32_t lin[4] = {5, 10, 11, 12};
    getme_mesh *m;
    CHECK(getme_mesh_create(&m, 3, 14, xyz) == GETME_OK);
    CHECK(getme_mesh_add_elements_ho(m, GETME_TET10, 1, conn, NULL) == GETME_OK);
    CHECK(getme_mesh_add_elements(m, GETME_TET, 1, lin, NULL) == GETME_OK);
    CHECK(getme_smooth(m, NULL, NULL) == GETME_ERR_TOPOLOGY);
    CHECK(strstr(getme_mesh_error(m), "node 5") != NULL);
    getme_mesh_free(m);
}

/* Second-order pyramids: rational shape functions (Gmsh's, docs/highorder.md).
   Expected values are gmsh.model.mesh.getJacobians (Gmsh 4.8) at the 13/14
   reference nodes of this element: Gmsh's reference pyramid with mid-node 5
   moved by (0, .3, 0), mid-node 7 (edge 0-apex) by (.1, .1, -.2) and, for
   pyramid14, the base centre by (0, 0, dz).  det J is 0.2 at node 0 and 1.1
   at most (0.2 / 1.1 for both types at dz = 0.1); at dz = 0.25 Gmsh gives
   det J = 0 (-1.1e-16) at node 6. */
static void test_pyramid(void)
{
    static const double ref[14][3] = {
        {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1},
        {0, -1, 0}, {-1, 0, 0}, {-.5, -.5, .5}, {1, 0, 0}, {.5, -.5, .5},
        {0, 1, 0}, {.5, .5, .5}, {-.5, .5, .5}, {0, 0, 0}};
    const double dz[3] = {0, 0.1, 0.25};
    for (int c = 0; c < 3; c++) {
        int pyr14 = c > 0;
        double xyz[42];
        memcpy(xyz, ref, sizeof xyz);
        xyz[3 * 5 + 1] += 0.3;
        xyz[3 * 7 + 0] += 0.1, xyz[3 * 7 + 1] += 0.1, xyz[3 * 7 + 2] -= 0.2;
        xyz[3 * 13 + 2] += dz[c];
        int32_t conn[14] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13};
        getme_mesh *m;
        CHECK(getme_mesh_create(&m, 3, 14, xyz) == GETME_OK);
        CHECK(getme_mesh_add_elements_ho(
                  m, pyr14 ? GETME_PYRAMID14 : GETME_PYRAMID13, 1, conn,
                  NULL) == GETME_OK);
        CHECK_EQ_INT(getme_mesh_num_elements_of_type(m, GETME_PYRAMID), 1);
        double r = 0;
        CHECK(getme_mesh_element_jacobian_ratio(m, 0, &r) == GETME_OK);
        if (c < 2)
            CHECK_NEAR(r, 0.2 / 1.1, 1e-12);
        else
            CHECK_NEAR(r, 0.0, 1e-12);
        getme_mesh_free(m);
    }
    CHECK_EQ_INT(getme_ho_type_num_nodes(GETME_PYRAMID13), 13);
    CHECK_EQ_INT(getme_ho_type_num_nodes(GETME_PYRAMID14), 14);
    CHECK(!strcmp(getme_ho_type_name(GETME_PYRAMID14), "pyramid14"));
}

int main(void)
{
    test_pyramid();
    test_jacobian_ratio();
    test_ratio_min_first();
    test_hex27_smooth();
    test_pinned_midnode();
    test_topology();
    return check_summary("core_test_highorder");
}
