/*
 * gmsh_boxes.h -- the two-material Gmsh model shared by the C tests that
 * build models through Gmsh's C API (tests/msh, tests/plugin): volume 1
 * [0,1]^3 in physical volume 1 "steel" and volume 2 [1,2]x[0,1]^2 in
 * physical volume 2 "alu", fragmented so that they share the face x = 1,
 * synchronized, not meshed.  Include after <gmshc.h>.
 */
#ifndef GETME_TEST_GMSH_BOXES_H
#define GETME_TEST_GMSH_BOXES_H

#include <stddef.h>

/* with_loose_box: also volume 3 [3,4]x[0,1]^2, in no physical group. */
static inline void two_material_boxes(const char *model, int with_loose_box)
{
    int ierr = 0;
    gmshModelAdd(model, &ierr);
    gmshModelOccAddBox(0, 0, 0, 1, 1, 1, 1, &ierr);
    gmshModelOccAddBox(1, 0, 0, 1, 1, 1, 2, &ierr);
    if (with_loose_box)
        gmshModelOccAddBox(3, 0, 0, 1, 1, 1, 3, &ierr);
    int obj[2] = {3, 1}, tool[2] = {3, 2}, *o = NULL, **m = NULL;
    size_t on = 0, *mn = NULL, mnn = 0;
    gmshModelOccFragment(obj, 2, tool, 2, &o, &on, &m, &mn, &mnn, -1, 1, 1,
                         &ierr);
    for (size_t i = 0; i < mnn; i++)
        gmshFree(m[i]);
    gmshFree(m);
    gmshFree(mn);
    gmshFree(o);
    gmshModelOccSynchronize(&ierr);
    int v1 = 1, v2 = 2;
    gmshModelAddPhysicalGroup(3, &v1, 1, 1, &ierr);
    gmshModelSetPhysicalName(3, 1, "steel", &ierr);
    gmshModelAddPhysicalGroup(3, &v2, 1, 2, &ierr);
    gmshModelSetPhysicalName(3, 2, "alu", &ierr);
}

#endif /* GETME_TEST_GMSH_BOXES_H */
