/*
 * inp_types.c -- what each Abaqus element type is to the smoother.
 *
 * Names are parsed as <family><node count><suffix letters>, so every
 * formulation variant of a family (C3D8R, C3D8IH, DC3D8, CPE4R, S4R5...)
 * is recognised without a list of all of them.  Linear solids and planar
 * elements are smoothed; their second-order siblings are refused (midside
 * nodes cannot follow a corner move correctly); everything else (beams,
 * trusses, springs, rigid or surface elements, continuum shells, user
 * elements) is kept as it is, with its nodes fixed.
 */
#include "inp_internal.h"

#include <string.h>

static const char *const solid_families[] = {"C3D", "DC3D", "AC3D",
                                             "DCC3D", NULL};
static const char *const planar_families[] = {
    "CPS", "CPE", "CPEG", "CAX", "CGAX", "DC2D", "DCAX", "AC2D", "ACAX",
    "M3D", "S", "STRI", NULL};

/* If type starts with family followed by digits then letters only, the
   node count; else -1. */
static int family_count(const char *type, const char *family)
{
    size_t n = strlen(family);
    if (strncmp(type, family, n) != 0)
        return -1;
    const char *s = type + n;
    if (*s < '0' || *s > '9')
        return -1;
    int count = 0;
    while (*s >= '0' && *s <= '9') {
        count = 10 * count + (*s - '0');
        if (count > 1000)
            return -1;
        s++;
    }
    /* Suffix: a letter, then letters or digits (C3D8RH, S4R5, M3D4R). */
    if (*s && (*s < 'A' || *s > 'Z'))
        return -1;
    for (; *s; s++)
        if (!((*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9')))
            return -1;
    return count;
}

/* Abaqus' node order of C3D10, C3D15 and C3D20 mapped to Gmsh's
   (getme_mesh_add_elements_ho): Gmsh's node k is Abaqus' node order[k]
   (0-based).  Abaqus: corners, then the mid-edge nodes of the bottom
   face's edges in turn, the top face's, then the vertical edges (C3D10:
   1-2, 2-3, 3-1, 1-4, 2-4, 3-4); Gmsh's lists edges by their first
   corner.  Proved on CalculiX's own decks and meshio's output
   (tests/highorder/test_highorder_inp.py, docs/highorder.md). */
static const int8_t order_c3d10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
static const int8_t order_c3d15[15] = {0, 1, 2, 3, 4,  5,  6, 8,
                                       12, 7, 13, 14, 9, 11, 10};
static const int8_t order_c3d20[20] = {0,  1,  2,  3,  4,  5,  6,
                                       7,  8,  11, 16, 9,  17, 10,
                                       18, 19, 12, 15, 13, 14};

const int8_t *inp_ho_order(int ho_type)
{
    return ho_type == GETME_TET10     ? order_c3d10
           : ho_type == GETME_PRISM15 ? order_c3d15
           : ho_type == GETME_HEX20   ? order_c3d20
                                      : NULL;
}

inp_kind inp_element_kind(const char *type, int *gtype, int *nv)
{
    *gtype = -1;
    *nv = 0;
    for (int i = 0; solid_families[i]; i++) {
        int c = family_count(type, solid_families[i]);
        if (c < 0)
            continue;
        *nv = c;
        switch (c) {
        case 4: *gtype = GETME_TET; return INP_KIND_SOLID;
        case 5: *gtype = GETME_PYRAMID; return INP_KIND_SOLID;
        case 6: *gtype = GETME_PRISM; return INP_KIND_SOLID;
        case 8: *gtype = GETME_HEX; return INP_KIND_SOLID;
        /* second order, smoothed with their corners (docs/highorder.md) */
        case 10: *gtype = INP_HO + GETME_TET10; return INP_KIND_SOLID;
        case 15: *gtype = INP_HO + GETME_PRISM15; return INP_KIND_SOLID;
        case 20: *gtype = INP_HO + GETME_HEX20; return INP_KIND_SOLID;
        case 13: case 27: return INP_KIND_SOLID2;
        default: *nv = 0; return INP_KIND_OTHER;
        }
    }
    /* STRI65: triangular shell, 6 nodes ("65": 6 nodes, 5 dof). */
    if (strcmp(type, "STRI65") == 0) {
        *nv = 6;
        return INP_KIND_PLANAR2;
    }
    for (int i = 0; planar_families[i]; i++) {
        int c = family_count(type, planar_families[i]);
        if (c < 0)
            continue;
        *nv = c;
        switch (c) {
        case 3: *gtype = GETME_TRI; return INP_KIND_PLANAR;
        case 4: *gtype = GETME_QUAD; return INP_KIND_PLANAR;
        case 6: case 8: case 9: return INP_KIND_PLANAR2;
        default: *nv = 0; return INP_KIND_OTHER;
        }
    }
    return INP_KIND_OTHER;
}
