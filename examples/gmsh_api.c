/*
 * gmsh_api.c -- GETMe adaptive next to Gmsh's own optimizers, through the
 * C APIs (gmshc.h + getme_gmsh.h).
 *
 *   gmsh_api [mesh size] [out.msh]
 *
 * Builds a flanged part with a bore and a pin (two materials) with
 * OpenCASCADE, meshes it, saves the mesh, and smooths that same mesh with
 * getme_gmsh_optimize(), gmshModelMeshOptimize("") and
 * gmshModelMeshOptimize("Relocate3D"), reopening the saved mesh before each.
 *
 *   cc gmsh_api.c -lgetme_gmsh -lgetme -lgmsh -o gmsh_api
 */
#include "getme_gmsh.h"

#include <gmshc.h>

#include <stdio.h>
#include <stdlib.h>

static int check(int ierr, const char *what)
{
    if (ierr)
        fprintf(stderr, "Error   : %s failed\n", what);
    return ierr;
}

/* OCC boolean results come back as Gmsh-allocated arrays: free them all. */
static void free_map(int *out, int **map, size_t *map_n, size_t map_nn)
{
    for (size_t i = 0; i < map_nn; i++)
        gmshFree(map[i]);
    gmshFree(map);
    gmshFree(map_n);
    gmshFree(out);
}

static void build(double size)
{
    int ierr = 0, *out = NULL, **map = NULL;
    size_t out_n = 0, *map_n = NULL, map_nn = 0;
    int base[2] = {3, gmshModelOccAddBox(0, 0, 0, 4, 2, 0.6, -1, &ierr)};
    int boss[2] = {3, gmshModelOccAddCylinder(2, 1, 0, 0, 0, 1.6, 0.8, -1,
                                              6.283185307179586, &ierr)};
    gmshModelOccFuse(base, 2, boss, 2, &out, &out_n, &map, &map_n, &map_nn,
                     -1, 1, 1, &ierr);
    int part[2] = {out[0], out[1]};
    free_map(out, map, map_n, map_nn);
    int bore[2] = {3, gmshModelOccAddCylinder(2, 1, -0.1, 0, 0, 1.8, 0.45,
                                              -1, 6.283185307179586, &ierr)};
    gmshModelOccCut(part, 2, bore, 2, &out, &out_n, &map, &map_n, &map_nn, -1,
                    1, 1, &ierr);
    part[0] = out[0];
    part[1] = out[1];
    free_map(out, map, map_n, map_nn);
    int pin[2] = {3, gmshModelOccAddCylinder(2, 1, -0.1, 0, 0, 1.8, 0.45, -1,
                                             6.283185307179586, &ierr)};
    gmshModelOccFragment(part, 2, pin, 2, &out, &out_n, &map, &map_n,
                         &map_nn, -1, 1, 1, &ierr);
    free_map(out, map, map_n, map_nn);
    gmshModelOccSynchronize(&ierr);
    gmshOptionSetNumber("Mesh.MeshSizeMax", size, &ierr);
    gmshModelMeshGenerate(3, &ierr);
    check(ierr, "meshing");
}

static void print_row(const char *name, const getme_gmsh_report *q,
                      double seconds)
{
    printf("%-36s %8.4f %8.4f %8.4f %9ld %8.2f\n", name, q->before.q_min_star,
           q->before.q_min, q->before.q_mean, (long)q->num_elements, seconds);
}

static double now(void)
{
    int ierr = 0;
    return gmshLoggerGetWallTime(&ierr);
}

int main(int argc, char **argv)
{
    double size = argc > 1 ? atof(argv[1]) : 0.12;
    const char *out = argc > 2 ? argv[2] : "part-getme.msh";
    int ierr = 0;
    gmshInitialize(0, NULL, 0, &ierr);
    gmshOptionSetNumber("General.Terminal", 0, &ierr);
    gmshModelAdd("part", &ierr);
    build(size);
    gmshWrite("part-raw.msh", &ierr);

    getme_gmsh_report q, rep;
    printf("%-36s %8s %8s %8s %9s %8s\n", "method", "q*min", "q_min",
           "q_mean", "elements", "seconds");
    getme_gmsh_quality(NULL, 0, NULL, &q);
    print_row("input", &q, 0);

    getme_gmsh_options *opt = getme_gmsh_options_new();
    getme_gmsh_options_set(opt, "log", 0);
    if (getme_gmsh_optimize(0, NULL, 0, opt, &rep) != GETME_OK) {
        fprintf(stderr, "Error   : %s\n", rep.message);
        return 1;
    }
    getme_gmsh_quality(NULL, 0, NULL, &q);
    print_row("getme_gmsh_optimize()", &q, rep.wall);
    gmshWrite(out, &ierr);
    getme_gmsh_options_free(opt);

    const char *methods[2] = {"", "Relocate3D"};
    for (int m = 0; m < 2; m++) {
        char name[64];
        gmshModelRemove(&ierr);
        gmshOpen("part-raw.msh", &ierr);
        double t0 = now();
        gmshModelMeshOptimize(methods[m], 1, 1, NULL, 0, &ierr);
        double seconds = now() - t0;
        getme_gmsh_quality(NULL, 0, NULL, &q);
        snprintf(name, sizeof name, "gmshModelMeshOptimize(\"%s\")",
                 methods[m]);
        print_row(name, &q, seconds);
    }
    printf("GETMe result written to %s\n", out);
    gmshFinalize(&ierr);
    return 0;
}
