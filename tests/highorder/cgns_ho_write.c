/*
 * cgns_ho_write.c -- write a CGNS file with libcgns from a text
 * description, for test_highorder_cgns.py (Gmsh cannot write CGNS here and
 * meshio writes tetrahedra only):
 *   cgns_ho_write IN.txt OUT.cgns
 * IN.txt: the node count N, N lines "x y z", then sections
 * "<SIDS type name> <count> <nodes per element>" each followed by count
 * lines of 1-based node numbers in the CGNS order.
 */
#include <cgnslib.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int type_by_name(const char *name)
{
    for (int t = 0; t < NofValidElementTypes; t++)
        if (strcmp(cg_ElementTypeName((CGNS_ENUMT(ElementType_t))t), name) == 0)
            return t;
    return -1;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: cgns_ho_write IN.txt OUT.cgns\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "r");
    long n = 0;
    if (!f || fscanf(f, "%ld", &n) != 1 || n <= 0)
        return 3;
    double *x = malloc((size_t)n * 3 * sizeof *x);
    double *c[3];
    for (int d = 0; d < 3; d++)
        c[d] = malloc((size_t)n * sizeof **c);
    for (long i = 0; i < n; i++)
        for (int d = 0; d < 3; d++)
            if (fscanf(f, "%lf", &c[d][i]) != 1)
                return 3;
    /* sections are read twice: count the elements first (zone size) */
    long pos = ftell(f), ne = 0, cnt;
    int nv;
    char name[64];
    while (fscanf(f, "%63s %ld %d", name, &cnt, &nv) == 3) {
        ne += cnt;
        for (long k = 0; k < cnt * nv; k++) {
            long v;
            if (fscanf(f, "%ld", &v) != 1)
                return 3;
        }
    }
    fseek(f, pos, SEEK_SET);
    int fn, B, Z, C, S;
    cgsize_t size[3] = {(cgsize_t)n, (cgsize_t)ne, 0};
    if (cg_open(argv[2], CG_MODE_WRITE, &fn) || cg_base_write(fn, "Base", 3, 3, &B) ||
        cg_zone_write(fn, B, "Zone", size, CGNS_ENUMV(Unstructured), &Z) ||
        cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateX", c[0], &C) ||
        cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateY", c[1], &C) ||
        cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateZ", c[2], &C)) {
        fprintf(stderr, "%s\n", cg_get_error());
        return 1;
    }
    cgsize_t first = 1;
    int sec = 0;
    while (fscanf(f, "%63s %ld %d", name, &cnt, &nv) == 3) {
        int t = type_by_name(name);
        if (t < 0)
            return 3;
        cgsize_t *conn = malloc((size_t)(cnt * nv) * sizeof *conn);
        for (long k = 0; k < cnt * nv; k++) {
            long v;
            if (fscanf(f, "%ld", &v) != 1)
                return 3;
            conn[k] = (cgsize_t)v;
        }
        char sname[32];
        snprintf(sname, sizeof sname, "Elem%d", ++sec);
        if (cg_section_write(fn, B, Z, sname, (CGNS_ENUMT(ElementType_t))t,
                             first, first + cnt - 1, 0, conn, &S)) {
            fprintf(stderr, "%s\n", cg_get_error());
            return 1;
        }
        first += cnt;
        free(conn);
    }
    cg_close(fn);
    fclose(f);
    free(x);
    for (int d = 0; d < 3; d++)
        free(c[d]);
    return 0;
}
