/*
 * test_untangle.c -- getme_mesh_untangle() and getme_smooth() on tangled
 * inputs of every element type.
 *
 * Each mesh is a valid structured grid (cubes as hexes, as 12 tets or 6
 * pyramids around a centre node, as 2 prisms, a hex / pyramid / tet mix;
 * squares as quads or 2 triangles) in which a few interior grid nodes are
 * pushed through the opposite face of their cell.  Asserted: the input has
 * invalid elements; after untangling none (getme_element_quality > 0 for
 * every element); fixed (skin) nodes bit-identical; nodes away from the
 * tangles untouched; 1 thread = 2 threads byte for byte; getme_smooth()
 * untangles by itself and gives the same valid result with 1 and 2 threads,
 * and refuses with untangle = 0.  A mesh with an inverted element whose
 * nodes are all fixed fails with GETME_ERR_INVALID_MESH naming it.
 */
#include "check.h"
#include "getme.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { K_HEX, K_TET, K_PYR, K_PRISM, K_MIXED, K_TRI, K_QUAD };
static const char *const KIND_NAME[] = {"hex",   "tet",   "pyramid", "prism",
                                        "mixed", "tri", "quad"};

typedef struct grid {
    int dim, n;
    int32_t nn;
    double *xyz;
    int32_t *conn[GETME_NUM_TYPES];
    int32_t count[GETME_NUM_TYPES], cap[GETME_NUM_TYPES];
} grid;

static void add(grid *g, int type, const int32_t *nodes)
{
    int nv = getme_type_num_nodes((getme_elem_type)type);
    if (g->count[type] == g->cap[type]) {
        g->cap[type] = g->cap[type] ? 2 * g->cap[type] : 256;
        g->conn[type] = realloc(g->conn[type],
                                (size_t)g->cap[type] * nv * sizeof(int32_t));
    }
    memcpy(g->conn[type] + (size_t)g->count[type] * nv, nodes,
           (size_t)nv * sizeof(int32_t));
    g->count[type]++;
}

static int32_t gid(const grid *g, int i, int j, int k)
{
    return i + (g->n + 1) * (j + (g->n + 1) * k);
}

/* Cell kind of the mixed mesh: hexes for x < n/2, split cubes beyond. */
static int is_hex_cell(int kind, int n, int i)
{
    return kind == K_HEX || (kind == K_MIXED && i < n / 2);
}

/* Cube faces with inward normals (CCW seen from the cube's centre), in the
   Gmsh hex numbering, and the neighbouring cell's offset. */
static const int FACE[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1},
                               {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 5, 6, 2}};
static const int FACE_NB[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0},
                                  {0, 1, 0},  {-1, 0, 0}, {1, 0, 0}};

static grid make_grid(int kind, int n)
{
    grid g;
    memset(&g, 0, sizeof g);
    g.n = n;
    g.dim = kind >= K_TRI ? 2 : 3;
    int32_t grid_nodes = g.dim == 3 ? (n + 1) * (n + 1) * (n + 1)
                                    : (n + 1) * (n + 1);
    int32_t cells = g.dim == 3 ? n * n * n : n * n;
    g.xyz = malloc((size_t)(grid_nodes + cells) * 3 * sizeof(double));
    g.nn = grid_nodes;
    for (int k = 0; k <= (g.dim == 3 ? n : 0); k++)
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++) {
                double *p = g.xyz + 3 * (size_t)gid(&g, i, j, k);
                p[0] = i, p[1] = j, p[2] = g.dim == 3 ? k : 0.5;
            }
    if (g.dim == 2) {
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                int32_t q[4] = {gid(&g, i, j, 0), gid(&g, i + 1, j, 0),
                                gid(&g, i + 1, j + 1, 0), gid(&g, i, j + 1, 0)};
                if (kind == K_QUAD) {
                    add(&g, GETME_QUAD, q);
                } else {
                    int32_t t1[3] = {q[0], q[1], q[2]}, t2[3] = {q[0], q[2], q[3]};
                    add(&g, GETME_TRI, t1);
                    add(&g, GETME_TRI, t2);
                }
            }
        return g;
    }
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                int32_t h[8] = {gid(&g, i, j, k),         gid(&g, i + 1, j, k),
                                gid(&g, i + 1, j + 1, k), gid(&g, i, j + 1, k),
                                gid(&g, i, j, k + 1),     gid(&g, i + 1, j, k + 1),
                                gid(&g, i + 1, j + 1, k + 1),
                                gid(&g, i, j + 1, k + 1)};
                if (is_hex_cell(kind, n, i)) {
                    add(&g, GETME_HEX, h);
                    continue;
                }
                if (kind == K_PRISM) {
                    int32_t p1[6] = {h[0], h[1], h[2], h[4], h[5], h[6]};
                    int32_t p2[6] = {h[0], h[2], h[3], h[4], h[6], h[7]};
                    add(&g, GETME_PRISM, p1);
                    add(&g, GETME_PRISM, p2);
                    continue;
                }
                /* split cube: a centre node, a pyramid or two tets per face */
                int32_t c = g.nn++;
                double *p = g.xyz + 3 * (size_t)c;
                p[0] = i + 0.5, p[1] = j + 0.5, p[2] = k + 0.5;
                for (int f = 0; f < 6; f++) {
                    int ni = i + FACE_NB[f][0];
                    int nb_hex = ni >= 0 && ni < n &&
                                 j + FACE_NB[f][1] >= 0 && j + FACE_NB[f][1] < n &&
                                 k + FACE_NB[f][2] >= 0 && k + FACE_NB[f][2] < n &&
                                 is_hex_cell(kind, n, ni);
                    int pyramid = kind == K_PYR || nb_hex ||
                                  (kind == K_MIXED && FACE_NB[f][0] == 0 &&
                                   FACE_NB[f][2] == 0);
                    int32_t a = h[FACE[f][0]], b = h[FACE[f][1]],
                            cc = h[FACE[f][2]], d = h[FACE[f][3]];
                    if (pyramid) {
                        int32_t py[5] = {a, b, cc, d, c};
                        add(&g, GETME_PYRAMID, py);
                        continue;
                    }
                    /* diagonal through the face's smallest node id, so both
                       sides of the face split it the same way */
                    int32_t m = a < b ? a : b;
                    m = cc < m ? cc : m;
                    m = d < m ? d : m;
                    if (m == a || m == cc) {
                        int32_t t1[4] = {a, b, cc, c}, t2[4] = {a, cc, d, c};
                        add(&g, GETME_TET, t1);
                        add(&g, GETME_TET, t2);
                    } else {
                        int32_t t1[4] = {a, b, d, c}, t2[4] = {b, cc, d, c};
                        add(&g, GETME_TET, t1);
                        add(&g, GETME_TET, t2);
                    }
                }
            }
    return g;
}

static void free_grid(grid *g)
{
    free(g->xyz);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        free(g->conn[t]);
}

/* Push a few interior grid nodes through the opposite face of their cell. */
static void tangle(grid *g)
{
    int n = g->n;
    if (g->dim == 3) {
        static const int at[3][3] = {{2, 2, 2}, {5, 5, 5}, {2, 5, 4}};
        static const double by[3][3] = {
            {1.6, 0.1, 0.05}, {-0.1, -1.7, 0.1}, {0.05, 0.1, 1.5}};
        for (int s = 0; s < 3; s++)
            for (int d = 0; d < 3; d++)
                g->xyz[3 * (size_t)gid(g, at[s][0], at[s][1], at[s][2]) + d] +=
                    by[s][d];
    } else {
        static const int at[2][2] = {{3, 3}, {7, 6}};
        static const double by[2][2] = {{1.6, 0.1}, {-0.2, -1.5}};
        for (int s = 0; s < 2; s++)
            for (int d = 0; d < 2; d++)
                g->xyz[3 * (size_t)gid(g, at[s][0], at[s][1], 0) + d] +=
                    by[s][d];
    }
    (void)n;
}

static getme_mesh *build(const grid *g)
{
    getme_mesh *m = NULL;
    if (getme_mesh_create(&m, g->dim, g->nn, g->xyz) != GETME_OK)
        return NULL;
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        if (g->count[t])
            getme_mesh_add_elements(m, (getme_elem_type)t, g->count[t],
                                    g->conn[t], NULL);
    getme_mesh_fix_boundary(m, GETME_FIX_SKIN | GETME_FIX_INTERFACES, NULL);
    return m;
}

static int64_t num_invalid(getme_mesh *m)
{
    getme_quality_stats s;
    getme_mesh_quality_stats(m, -1, &s);
    return s.num_invalid;
}

static void test_kind(int kind)
{
    grid g = make_grid(kind, kind >= K_TRI ? 10 : 8);
    tangle(&g);
    printf("%s: %d nodes\n", KIND_NAME[kind], (int)g.nn);
    size_t bytes = (size_t)g.nn * 3 * sizeof(double);
    double *ref = NULL;
    uint8_t *fixed = malloc((size_t)g.nn);
    int64_t before = 0;
    for (int threads = 1; threads <= 2; threads++) {
        getme_mesh *m = build(&g);
        CHECK(m != NULL);
        if (!m)
            return;
        getme_mesh_get_fixed_mask(m, fixed);
        before = num_invalid(m);
        CHECK(before > 0);
        getme_params p;
        getme_params_init(&p);
        p.num_threads = threads;
        getme_untangle_result r;
        getme_status st = getme_mesh_untangle(m, &p, &r);
        printf("  untangle, %d thread(s): status %d, invalid %lld -> %lld, "
               "%d sweeps, %d rings, %d nodes moved, %.3f s%s%s\n",
               threads, (int)st, (long long)r.num_invalid_before,
               (long long)r.num_invalid_after, r.sweeps, r.rings,
               (int)r.num_moved, r.seconds, st ? ": " : "",
               st ? getme_mesh_error(m) : "");
        CHECK_EQ_INT(st, GETME_OK);
        CHECK_EQ_INT(r.num_invalid_before, before);
        CHECK_EQ_INT(r.num_invalid_after, 0);
        CHECK_EQ_INT(num_invalid(m), 0);
        const double *x = getme_mesh_coords(m);
        int32_t changed = 0, fixed_moved = 0;
        for (int32_t i = 0; i < g.nn; i++) {
            int diff = memcmp(x + 3 * (size_t)i, g.xyz + 3 * (size_t)i,
                              3 * sizeof(double)) != 0;
            changed += diff;
            fixed_moved += diff && fixed[i];
        }
        CHECK_EQ_INT(fixed_moved, 0);
        CHECK_EQ_INT(changed, r.num_moved);
        CHECK(changed > 0 && changed < g.nn / 4);
        if (!ref) {
            ref = malloc(bytes);
            memcpy(ref, x, bytes);
        } else {
            CHECK(memcmp(ref, x, bytes) == 0); /* 1 = 2 threads */
        }
        getme_mesh_free(m);
    }
    /* getme_smooth untangles by itself, then smooths: valid, skin identical,
       1 = 2 threads; the same untangling as getme_mesh_untangle */
    double *smooth_ref = malloc(bytes);
    for (int threads = 1; threads <= 2; threads++) {
        getme_mesh *m = build(&g);
        getme_params p;
        getme_params_init(&p);
        p.num_threads = threads;
        getme_result res;
        getme_status st = getme_smooth(m, &p, &res);
        CHECK_EQ_INT(st, GETME_OK);
        CHECK_EQ_INT(res.num_invalid_initial, before);
        CHECK(res.untangle_sweeps > 0);
        CHECK(res.q_min > 0.0);
        getme_quality_stats s;
        getme_mesh_quality_stats(m, -1, &s);
        CHECK_EQ_INT(s.num_invalid, 0);
        CHECK(s.q_min > 0.05);
        printf("  smooth, %d thread(s): q_min %.4f, q_mean %.4f\n", threads,
               s.q_min, s.q_mean);
        const double *x = getme_mesh_coords(m);
        int fixed_moved = 0;
        for (int32_t i = 0; i < g.nn; i++)
            fixed_moved += fixed[i] && memcmp(x + 3 * (size_t)i,
                                              g.xyz + 3 * (size_t)i,
                                              3 * sizeof(double)) != 0;
        CHECK_EQ_INT(fixed_moved, 0);
        if (threads == 1)
            memcpy(smooth_ref, x, bytes);
        else
            CHECK(memcmp(smooth_ref, x, bytes) == 0);
        getme_mesh_free(m);
    }
    /* getme_mesh_untangle then getme_smooth = getme_smooth alone (with
       renumber = 0: the locality order depends on the coordinates), for
       both methods (smart Laplace moves only some nodes per iteration, so
       it sees whether the untangled coordinates reached every buffer) */
    for (int method = 0; method <= 1; method++) {
        getme_params p;
        getme_params_init(&p);
        p.renumber = 0;
        p.method = (getme_method)method;
        getme_mesh *m = build(&g), *m2 = build(&g);
        CHECK_EQ_INT(getme_mesh_untangle(m, &p, NULL), GETME_OK);
        getme_result res;
        CHECK_EQ_INT(getme_smooth(m, &p, &res), GETME_OK);
        CHECK_EQ_INT(res.num_invalid_initial, 0);
        CHECK_EQ_INT(getme_smooth(m2, &p, &res), GETME_OK);
        CHECK_EQ_INT(res.num_invalid_initial, before);
        CHECK(memcmp(getme_mesh_coords(m), getme_mesh_coords(m2), bytes) == 0);
        CHECK_EQ_INT(num_invalid(m2), 0);
        getme_mesh_free(m);
        getme_mesh_free(m2);
    }
    /* untangle = 0: today's refusal, nothing moves */
    {
        getme_mesh *m = build(&g);
        getme_params p;
        getme_params_init(&p);
        CHECK_EQ_INT(getme_params_set(&p, "untangle", 0), GETME_OK);
        CHECK_EQ_INT(getme_smooth(m, &p, NULL), GETME_ERR_INVALID_MESH);
        CHECK(memcmp(getme_mesh_coords(m), g.xyz, bytes) == 0);
        CHECK(strstr(getme_mesh_error(m), "invalid") != NULL);
        getme_mesh_free(m);
    }
    free(smooth_ref);
    free(ref);
    free(fixed);
    free_grid(&g);
}

/* An inverted element whose nodes are all fixed cannot be untangled. */
static void test_stuck(void)
{
    /* one inverted tet: all its nodes are skin nodes */
    double xyz[12] = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
    int32_t tet[4] = {0, 1, 2, 3};
    getme_mesh *m = NULL;
    getme_mesh_create(&m, 3, 4, xyz);
    getme_mesh_add_elements(m, GETME_TET, 1, tet, NULL);
    getme_mesh_fix_boundary(m, GETME_FIX_SKIN, NULL);
    getme_untangle_result r;
    CHECK_EQ_INT(getme_mesh_untangle(m, NULL, &r), GETME_ERR_INVALID_MESH);
    CHECK_EQ_INT(r.num_invalid_before, 1);
    CHECK_EQ_INT(r.num_invalid_after, 1);
    CHECK_EQ_INT(r.num_stuck, 1);
    CHECK_EQ_INT(r.num_reported, 1);
    CHECK_EQ_INT(r.remaining[0], 0);
    CHECK_EQ_INT(r.num_moved, 0);
    CHECK(strstr(getme_mesh_error(m), "could not be untangled") != NULL);
    CHECK_EQ_INT(getme_smooth(m, NULL, NULL), GETME_ERR_INVALID_MESH);
    CHECK(memcmp(getme_mesh_coords(m), xyz, sizeof xyz) == 0);
    getme_mesh_free(m);

    /* a hex grid: cell (1,1,1) has all 8 nodes fixed, and its node 6 is
       pushed back through the cell; every other invalid hex has a free
       node */
    grid g = make_grid(K_HEX, 4);
    int32_t cell = 1 + 4 * (1 + 4 * 1);
    const int32_t *h = g.conn[GETME_HEX] + 8 * cell;
    double *p6 = g.xyz + 3 * (size_t)h[6];
    p6[0] = p6[1] = p6[2] = 0.8;
    size_t bytes = (size_t)g.nn * 3 * sizeof(double);
    m = build(&g);
    getme_mesh_fix_nodes(m, 8, h);
    int64_t before = num_invalid(m);
    CHECK(before > 1);
    getme_status st = getme_mesh_untangle(m, NULL, &r);
    printf("stuck hex: status %d, invalid %lld -> %lld (%lld stuck): %s\n",
           (int)st, (long long)r.num_invalid_before,
           (long long)r.num_invalid_after, (long long)r.num_stuck,
           getme_mesh_error(m));
    CHECK_EQ_INT(st, GETME_ERR_INVALID_MESH);
    CHECK_EQ_INT(r.num_invalid_before, before);
    CHECK(r.num_invalid_after >= 1);
    CHECK_EQ_INT(r.num_stuck, 1);
    int named = 0;
    for (int i = 0; i < r.num_reported; i++)
        named |= r.remaining[i] == cell;
    CHECK(named);
    char want[32];
    snprintf(want, sizeof want, "%d", (int)cell);
    CHECK(strstr(getme_mesh_error(m), want) != NULL);
    getme_mesh_free(m);
    /* getme_smooth: the same failure, and the mesh does not move */
    m = build(&g);
    getme_mesh_fix_nodes(m, 8, h);
    CHECK_EQ_INT(getme_smooth(m, NULL, NULL), GETME_ERR_INVALID_MESH);
    CHECK(strstr(getme_mesh_error(m), "could not be untangled") != NULL);
    CHECK(memcmp(getme_mesh_coords(m), g.xyz, bytes) == 0);
    getme_mesh_free(m);
    free_grid(&g);
}

/* A valid mesh is left alone. */
static void test_valid(void)
{
    grid g = make_grid(K_TET, 3);
    getme_mesh *m = build(&g);
    getme_untangle_result r;
    CHECK_EQ_INT(getme_mesh_untangle(m, NULL, &r), GETME_OK);
    CHECK_EQ_INT(r.num_invalid_before, 0);
    CHECK_EQ_INT(r.sweeps, 0);
    CHECK(memcmp(getme_mesh_coords(m), g.xyz,
                 (size_t)g.nn * 3 * sizeof(double)) == 0);
    getme_mesh_free(m);
    free_grid(&g);
    getme_params p;
    getme_params_init(&p);
    CHECK_EQ_INT(p.untangle, 1);
    CHECK_EQ_INT(getme_params_set(&p, "untangle", 2), GETME_ERR_ARGUMENT);
    CHECK_EQ_INT(getme_mesh_untangle(NULL, NULL, NULL), GETME_ERR_ARGUMENT);
}

int main(void)
{
    for (int kind = K_HEX; kind <= K_QUAD; kind++)
        test_kind(kind);
    test_stuck();
    test_valid();
    return check_summary("test_untangle");
}
