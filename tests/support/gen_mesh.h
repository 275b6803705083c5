/*
 * gen_mesh.h -- generated test meshes shared by the C tests: an N^3 (N^2)
 * grid of unit cells split into tets (Kuhn), hexes, a hex / pyramid /
 * prism mix, triangles or quads; skin and interfaces fixed; distorted by
 * getme_mesh_distort with a fixed seed.  Header-only (static functions),
 * included after check.h.
 */
#ifndef GETME_TEST_GEN_MESH_H
#define GETME_TEST_GEN_MESH_H

#include "check.h"
#include "getme.h"

#include <stdlib.h>
#include <string.h>

#ifndef N
#define N 8 /* cells per side */
#endif

typedef struct gen {
    int dim;
    int32_t nn;
    double *xyz;
    int32_t count[GETME_NUM_TYPES];
    int32_t *conn[GETME_NUM_TYPES];
} gen;

static int32_t node_id(int i, int j, int k) { return (k * (N + 1) + j) * (N + 1) + i; }

static void add(gen *g, int type, const int32_t *c)
{
    int nv = getme_type_num_nodes((getme_elem_type)type);
    int32_t *dst = g->conn[type] + (size_t)g->count[type] * nv;
    memcpy(dst, c, (size_t)nv * sizeof *c);
    /* Orient by quality: the reversed order of a wrongly oriented element. */
    double x[24];
    for (int i = 0; i < nv; i++)
        memcpy(x + 3 * i, g->xyz + 3 * dst[i], 3 * sizeof(double));
    if (!(getme_element_quality((getme_elem_type)type, x) > 0.0)) {
        static const int flip_tet[] = {0, 2, 1, 3};
        static const int flip_prism[] = {0, 2, 1, 3, 5, 4};
        static const int flip_pyr[] = {0, 3, 2, 1, 4};
        static const int flip_tri[] = {0, 2, 1};
        const int *f = type == GETME_TET ? flip_tet : type == GETME_PRISM ? flip_prism
                     : type == GETME_PYRAMID ? flip_pyr : flip_tri;
        int32_t tmp[8];
        for (int i = 0; i < nv; i++)
            tmp[i] = dst[f[i]];
        memcpy(dst, tmp, (size_t)nv * sizeof *tmp);
    }
    g->count[type]++;
}

static void cube_nodes(int i, int j, int k, int32_t v[8])
{
    /* Gmsh hex order. */
    v[0] = node_id(i, j, k), v[1] = node_id(i + 1, j, k);
    v[2] = node_id(i + 1, j + 1, k), v[3] = node_id(i, j + 1, k);
    v[4] = node_id(i, j, k + 1), v[5] = node_id(i + 1, j, k + 1);
    v[6] = node_id(i + 1, j + 1, k + 1), v[7] = node_id(i, j + 1, k + 1);
}

/* kind: 0 tets (Kuhn split), 1 hexes, 2 mixed hex / prism / pyramid, 3 tri,
   4 quad. */
static gen make_mesh(int kind)
{
    gen g;
    memset(&g, 0, sizeof g);
    g.dim = kind >= 3 ? 2 : 3;
    int nz = g.dim == 3 ? N : 0;
    int32_t grid = (N + 1) * (N + 1) * (nz + 1);
    g.nn = grid + (kind == 2 ? N * N * N : 0);
    g.xyz = calloc((size_t)g.nn * 3, sizeof *g.xyz);
    for (int k = 0; k <= nz; k++)
        for (int j = 0; j <= N; j++)
            for (int i = 0; i <= N; i++) {
                double *p = g.xyz + 3 * node_id(i, j, k);
                p[0] = i, p[1] = j, p[2] = k;
            }
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        g.conn[t] = malloc((size_t)12 * N * N * N * 8 * sizeof(int32_t));
    for (int k = 0; k < (nz ? nz : 1); k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                int32_t v[8];
                cube_nodes(i, j, k, v);
                if (kind == 0) {
                    static const int path[6][2] = {{1, 3}, {1, 5}, {3, 1}, {3, 7}, {4, 5}, {4, 7}};
                    /* Kuhn: 0 -> a -> b -> 6 along cube edges. */
                    static const int second[6] = {2, 5, 2, 7, 5, 7};
                    for (int p = 0; p < 6; p++) {
                        int32_t c[4] = {v[0], v[path[p][0]], v[second[p]], v[6]};
                        add(&g, GETME_TET, c);
                    }
                } else if (kind == 1 || (kind == 2 && i < N / 2 && !(i >= 1 && i <= 2 && j >= 3 && j <= 4 && k >= 3 && k <= 4))) {
                    add(&g, GETME_HEX, v);
                } else if (kind == 2 && i < N / 2) {
                    /* A cube split into 6 pyramids around a centre node. */
                    int32_t c = grid + (k * N + j) * N + i;
                    double *p = g.xyz + 3 * c;
                    p[0] = i + 0.5, p[1] = j + 0.5, p[2] = k + 0.5;
                    static const int faces[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                    {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
                    for (int f = 0; f < 6; f++) {
                        int32_t py[5] = {v[faces[f][0]], v[faces[f][1]], v[faces[f][2]],
                                         v[faces[f][3]], c};
                        add(&g, GETME_PYRAMID, py);
                    }
                } else if (kind == 2) {
                    int32_t a[6] = {v[0], v[1], v[2], v[4], v[5], v[6]};
                    int32_t b[6] = {v[0], v[2], v[3], v[4], v[6], v[7]};
                    add(&g, GETME_PRISM, a);
                    add(&g, GETME_PRISM, b);
                } else if (kind == 3) {
                    int32_t a[3] = {v[0], v[1], v[2]}, b[3] = {v[0], v[2], v[3]};
                    add(&g, GETME_TRI, a);
                    add(&g, GETME_TRI, b);
                } else {
                    add(&g, GETME_QUAD, v);
                }
            }
    return g;
}

static getme_mesh *build(const gen *g)
{
    getme_mesh *m = NULL;
    CHECK(getme_mesh_create(&m, g->dim, g->nn, g->xyz) == GETME_OK);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        if (g->count[t])
            CHECK(getme_mesh_add_elements(m, (getme_elem_type)t, g->count[t],
                                          g->conn[t], NULL) == GETME_OK);
    int32_t nfix = 0;
    CHECK(getme_mesh_fix_boundary(m, GETME_FIX_SKIN | GETME_FIX_INTERFACES, &nfix) == GETME_OK);
    return m;
}

static void free_gen(gen *g)
{
    free(g->xyz);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        free(g->conn[t]);
}

static getme_mesh *distorted(const gen *g)
{
    getme_mesh *m = build(g);
    CHECK(getme_mesh_distort(m, 42, 0.6, 0.0, 3) == GETME_OK);
    return m;
}

#endif /* GETME_TEST_GEN_MESH_H */
