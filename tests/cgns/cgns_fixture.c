/*
 * cgns_fixture.c -- writes the CGNS test files described in cgns_fixture.h
 * through the mid-level libcgns API.
 */
#include "cgns_fixture.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define TRY(call)                                                           \
    do {                                                                    \
        if ((call) != CG_OK) {                                              \
            fprintf(stderr, "fixture: %s: %s\n", #call, cg_get_error());    \
            return -1;                                                      \
        }                                                                   \
    } while (0)

#include <stdio.h>

/* Deterministic jitter in [-1, 1] per node and axis. */
static double jitter(uint32_t node, int axis)
{
    uint32_t h = node * 2654435761u + (uint32_t)axis * 40503u + 12345u;
    h ^= h >> 15;
    h *= 2246822519u;
    h ^= h >> 13;
    return (double)(h % 20001u) / 10000.0 - 1.0;
}

/* 1-based node number of grid point (i, j, k) with n points per axis. */
static cgsize_t gid(int n, int i, int j, int k)
{
    return (cgsize_t)(1 + i + n * (j + n * k));
}

/* Coordinates of an n^3 grid, shifted by x0, interior points jittered. */
static int write_grid_coords(int fn, int B, int Z, int n, double x0,
                             double distort, int single)
{
    size_t nn = (size_t)n * n * n;
    double *xyz[3];
    float *f = malloc(nn * sizeof *f);
    int C;

    for (int a = 0; a < 3; a++)
        xyz[a] = malloc(nn * sizeof(double));
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                size_t p = (size_t)gid(n, i, j, k) - 1;
                int inner = i > 0 && j > 0 && k > 0 && i < n - 1 && j < n - 1 &&
                            k < n - 1;
                double base[3] = {x0 + i, (double)j, (double)k};
                for (int a = 0; a < 3; a++)
                    xyz[a][p] = base[a] + (inner ? distort * jitter((uint32_t)p, a)
                                                 : 0.0);
            }
    static const char *const names[3] = {"CoordinateX", "CoordinateY",
                                         "CoordinateZ"};
    int rc = 0;
    for (int a = 0; a < 3 && rc == 0; a++) {
        if (single) {
            for (size_t p = 0; p < nn; p++)
                f[p] = (float)xyz[a][p];
            rc = cg_coord_write(fn, B, Z, CGNS_ENUMV(RealSingle), names[a], f, &C);
        } else {
            rc = cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), names[a],
                                xyz[a], &C);
        }
    }
    for (int a = 0; a < 3; a++)
        free(xyz[a]);
    free(f);
    return rc;
}

static void hex_nodes(int n, int i, int j, int k, cgsize_t *v)
{
    v[0] = gid(n, i, j, k);
    v[1] = gid(n, i + 1, j, k);
    v[2] = gid(n, i + 1, j + 1, k);
    v[3] = gid(n, i, j + 1, k);
    v[4] = gid(n, i, j, k + 1);
    v[5] = gid(n, i + 1, j, k + 1);
    v[6] = gid(n, i + 1, j + 1, k + 1);
    v[7] = gid(n, i, j + 1, k + 1);
}

static int write_block_zone(int fn, int B, const fixture_opts *o)
{
    const int n = 5, c = 4;
    cgsize_t size[3] = {n * n * n, c * c * c, 0};
    cgsize_t hex[64 * 8], quad[16 * 4], v[8];
    int Z, S, BC, Sol, F;

    TRY(cg_zone_write(fn, B, "Block", size, CGNS_ENUMV(Unstructured), &Z));
    TRY(write_grid_coords(fn, B, Z, n, 0.0, o->distort, o->single));
    for (int k = 0, e = 0; k < c; k++)
        for (int j = 0; j < c; j++)
            for (int i = 0; i < c; i++, e++)
                hex_nodes(n, i, j, k, hex + 8 * e);
    TRY(cg_section_write(fn, B, Z, "Hexes", CGNS_ENUMV(HEXA_8), 1, 64, 0, hex, &S));
    for (int pass = 0; pass < 2; pass++) { /* Floor (z = 0), Baffle (z = 2) */
        int kz = pass ? 2 : 0;
        for (int j = 0, e = 0; j < c; j++)
            for (int i = 0; i < c; i++, e++) {
                hex_nodes(n, i, j, kz, v);
                memcpy(quad + 4 * e, v, 4 * sizeof *v);
            }
        TRY(cg_section_write(fn, B, Z, pass ? "Baffle" : "Floor",
                             CGNS_ENUMV(QUAD_4), 65 + 16 * pass, 80 + 16 * pass,
                             0, quad, &S));
    }
    /* libcgns 3.4 has no FamilyName under Elements_t: families go on the
       zone and the BCs */
    TRY(cg_goto(fn, B, "Zone_t", Z, "end"));
    TRY(cg_famname_write("BlockFam"));
    cgsize_t inlet[25], range[2] = {65, 80};
    for (int k = 0, p = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            inlet[p++] = gid(n, 0, j, k);
    TRY(cg_boco_write(fn, B, Z, "inlet", CGNS_ENUMV(BCInflow),
                      CGNS_ENUMV(PointList), 25, inlet, &BC));
    TRY(cg_boco_write(fn, B, Z, "floor", CGNS_ENUMV(BCWall),
                      CGNS_ENUMV(PointRange), 2, range, &BC));
    TRY(cg_boco_gridlocation_write(fn, B, Z, BC, CGNS_ENUMV(FaceCenter)));
    TRY(cg_goto(fn, B, "Zone_t", Z, "ZoneBC_t", 1, "BC_t", BC, "end"));
    TRY(cg_famname_write("OutFam"));
    cgsize_t probe[2] = {gid(n, 1, 1, 1), gid(n, 3, 3, 3)};
    TRY(cg_boco_write(fn, B, Z, "probe", CGNS_ENUMV(BCGeneral),
                      CGNS_ENUMV(PointList), 2, probe, &BC));
    TRY(cg_goto(fn, B, "Zone_t", Z, "ZoneBC_t", 1, "BC_t", BC, "end"));
    TRY(cg_famname_write("ProbeFam"));
    double p[125];
    for (int i = 0; i < 125; i++)
        p[i] = 1e5 + i;
    TRY(cg_sol_write(fn, B, Z, "Sol", CGNS_ENUMV(Vertex), &Sol));
    TRY(cg_field_write(fn, B, Z, Sol, CGNS_ENUMV(RealDouble), "Pressure", p, &F));
    TRY(cg_goto(fn, B, "Zone_t", Z, "end"));
    TRY(cg_user_data_write("Meta"));
    TRY(cg_goto(fn, B, "Zone_t", Z, "UserDefinedData_t", 1, "end"));
    cgsize_t three = 3;
    double meta[3] = {1.5, 2.5, 3.5};
    TRY(cg_array_write("Values", CGNS_ENUMV(RealDouble), 1, &three, meta));
    return 0;
}

static int write_tet_zone(int fn, int B, const fixture_opts *o)
{
    const int n = 4, c = 3;
    static const int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                   {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    cgsize_t size[3] = {n * n * n, 162, 0};
    cgsize_t data[162 * 5 + 18 * 4], off[181], v[8];
    size_t len = 0;
    int Z, S, e = 0;

    TRY(cg_zone_write(fn, B, "Tets", size, CGNS_ENUMV(Unstructured), &Z));
    TRY(cg_goto(fn, B, "Zone_t", Z, "end"));
    TRY(cg_famname_write("TetFam"));
    TRY(write_grid_coords(fn, B, Z, n, 10.0, o->distort, o->single));
    for (int k = 0; k < c; k++)
        for (int j = 0; j < c; j++)
            for (int i = 0; i < c; i++) {
                hex_nodes(n, i, j, k, v);
                for (int t = 0; t < 6; t++) {
                    off[e++] = (cgsize_t)len;
                    data[len++] = CGNS_ENUMV(TETRA_4);
                    for (int a = 0; a < 4; a++)
                        data[len++] = v[kuhn[t][a]];
                }
            }
    for (int k = 0; k < c; k++) /* x = x0 face: (v0, v3, v7), (v0, v7, v4) */
        for (int j = 0; j < c; j++) {
            hex_nodes(n, 0, j, k, v);
            static const int tri[2][3] = {{0, 3, 7}, {0, 7, 4}};
            for (int t = 0; t < 2; t++) {
                off[e++] = (cgsize_t)len;
                data[len++] = CGNS_ENUMV(TRI_3);
                for (int a = 0; a < 3; a++)
                    data[len++] = v[tri[t][a]];
            }
        }
    off[e] = (cgsize_t)len;
    TRY(cg_poly_section_write(fn, B, Z, "TetMix", CGNS_ENUMV(MIXED), 1, 180, 0,
                              data, off, &S));
    return 0;
}

int fixture_write(const char *path, const fixture_opts *o)
{
    int fn, B, F;

    TRY(cg_set_file_type(o->file_type));
    TRY(cg_open(path, CG_MODE_WRITE, &fn));
    TRY(cg_base_write(fn, "Base", 3, 3, &B));
    TRY(cg_family_write(fn, B, "BlockFam", &F));
    TRY(cg_family_write(fn, B, "TetFam", &F));
    TRY(cg_family_write(fn, B, "OutFam", &F));
    TRY(cg_family_write(fn, B, "ProbeFam", &F));
    if (write_block_zone(fn, B, o) || write_tet_zone(fn, B, o))
        return -1;
    TRY(cg_close(fn));
    return 0;
}

int fixture_write_2d(const char *path)
{
    const int n = 4;
    double x[16], y[16], z[16];
    cgsize_t size[3] = {16, 12, 0}, quad[6 * 4], tri[6 * 3], bar[12 * 2];
    int fn, B, Z, C, S, q = 0, t = 0, b = 0;

    TRY(cg_set_file_type(CG_FILE_HDF5));
    TRY(cg_open(path, CG_MODE_WRITE, &fn));
    TRY(cg_base_write(fn, "Plane", 2, 3, &B));
    TRY(cg_zone_write(fn, B, "Sheet", size, CGNS_ENUMV(Unstructured), &Z));
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int p = i + n * j, inner = i > 0 && j > 0 && i < n - 1 && j < n - 1;
            x[p] = i + (inner ? 0.25 * jitter((uint32_t)p, 0) : 0.0);
            y[p] = j + (inner ? 0.25 * jitter((uint32_t)p, 1) : 0.0);
            z[p] = 0.5;
        }
    TRY(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateX", x, &C));
    TRY(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateY", y, &C));
    TRY(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateZ", z, &C));
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            cgsize_t v0 = 1 + i + n * j, v1 = v0 + 1, v2 = v0 + n + 1, v3 = v0 + n;
            if (j < 2) {
                cgsize_t e[4] = {v0, v1, v2, v3};
                memcpy(quad + 4 * q++, e, sizeof e);
            } else {
                cgsize_t e[6] = {v0, v1, v2, v0, v2, v3};
                memcpy(tri + 3 * t, e, sizeof e);
                t += 2;
            }
        }
    for (int i = 0; i < 3; i++) { /* the four sides */
        cgsize_t s[4][2] = {{1 + i, 2 + i},
                            {n * (n - 1) + 1 + i, n * (n - 1) + 2 + i},
                            {1 + n * i, 1 + n * (i + 1)},
                            {n + n * i, n + n * (i + 1)}};
        for (int k = 0; k < 4; k++, b++)
            memcpy(bar + 2 * b, s[k], sizeof s[k]);
    }
    TRY(cg_section_write(fn, B, Z, "Quads", CGNS_ENUMV(QUAD_4), 1, 6, 0, quad, &S));
    TRY(cg_section_write(fn, B, Z, "Tris", CGNS_ENUMV(TRI_3), 7, 12, 0, tri, &S));
    TRY(cg_section_write(fn, B, Z, "Edges", CGNS_ENUMV(BAR_2), 13, 24, 0, bar, &S));
    TRY(cg_close(fn));
    return 0;
}

static int write_hex_zone(int fn, int B, const char *name, int no_coords,
                          int *Zout)
{
    const int n = 4, c = 3;
    cgsize_t size[3] = {n * n * n, c * c * c, 0}, hex[27 * 8];
    int Z, S;

    TRY(cg_zone_write(fn, B, name, size, CGNS_ENUMV(Unstructured), &Z));
    if (!no_coords)
        TRY(write_grid_coords(fn, B, Z, n, 0.0, 0.2, 0));
    for (int k = 0, e = 0; k < c; k++)
        for (int j = 0; j < c; j++)
            for (int i = 0; i < c; i++, e++)
                hex_nodes(n, i, j, k, hex + 8 * e);
    TRY(cg_section_write(fn, B, Z, "Hexes", CGNS_ENUMV(HEXA_8), 1, 27, 0, hex, &S));
    *Zout = Z;
    return 0;
}

int fixture_write_custom(const char *path, CGNS_ENUMT(ElementType_t) type,
                         int count, const cgsize_t *conn, int no_coords)
{
    int fn, B, Z, S;

    TRY(cg_set_file_type(CG_FILE_HDF5));
    TRY(cg_open(path, CG_MODE_WRITE, &fn));
    TRY(cg_base_write(fn, "Base", 3, 3, &B));
    if (write_hex_zone(fn, B, "Zone", no_coords, &Z))
        return -1;
    if (count > 0) {
        char name[33];
        snprintf(name, sizeof name, "Elem_%s", cg_ElementTypeName(type));
        TRY(cg_section_write(fn, B, Z, name, type, 28, 27 + count, 0, conn, &S));
    }
    TRY(cg_close(fn));
    return 0;
}

int fixture_write_structured(const char *path, int structured_only)
{
    int fn, B, Z, C;
    cgsize_t size[9] = {3, 3, 3, 2, 2, 2, 0, 0, 0};
    double x[27], y[27], z[27];

    for (int k = 0, p = 0; k < 3; k++)
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 3; i++, p++) {
                x[p] = 20.0 + i;
                y[p] = j;
                z[p] = k;
            }
    TRY(cg_set_file_type(CG_FILE_HDF5));
    TRY(cg_open(path, CG_MODE_WRITE, &fn));
    TRY(cg_base_write(fn, "Base", 3, 3, &B));
    TRY(cg_zone_write(fn, B, "Struct", size, CGNS_ENUMV(Structured), &Z));
    TRY(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateX", x, &C));
    TRY(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateY", y, &C));
    TRY(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateZ", z, &C));
    if (!structured_only && write_hex_zone(fn, B, "Zone", 0, &Z))
        return -1;
    TRY(cg_close(fn));
    return 0;
}

int fixture_write_meshio_style(const char *path)
{
    const int n = 4, c = 3;
    static const int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                   {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    cgsize_t size[3] = {n * n * n, 162, 0}, tets[162 * 4], v[8];
    int fn, B, Z, S, e = 0;

    TRY(cg_set_file_type(CG_FILE_HDF5));
    TRY(cg_open(path, CG_MODE_WRITE, &fn));
    TRY(cg_base_write(fn, "Base", 3, 3, &B));
    TRY(cg_zone_write(fn, B, "Zone1", size, CGNS_ENUMV(Unstructured), &Z));
    TRY(write_grid_coords(fn, B, Z, n, 0.0, 0.3, 0));
    for (int k = 0; k < c; k++)
        for (int j = 0; j < c; j++)
            for (int i = 0; i < c; i++) {
                hex_nodes(n, i, j, k, v);
                for (int t = 0; t < 6; t++, e++)
                    for (int a = 0; a < 4; a++)
                        tets[4 * e + a] = v[kuhn[t][a]];
            }
    TRY(cg_section_write(fn, B, Z, "GridElements", CGNS_ENUMV(TETRA_4), 1, 162,
                         0, tets, &S));
    TRY(cg_close(fn));
    return 0;
}
