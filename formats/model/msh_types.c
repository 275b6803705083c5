/*
 * msh_types.c -- the Gmsh MSH element types getme knows: the one table the
 * native MSH reader, the Gmsh-SDK path and their messages share.
 */
#include "model.h"

#include <stdio.h>
#include <string.h>

typedef struct type_info {
    int type, nodes, order;
    const char *family;
} type_info;

/* The MSH types Gmsh writes for meshes up to order 5 (Gmsh's
   getElementProperties: family, order, nodes).  Other types make the
   native reader decline the file, so Gmsh's reader deals with them. */
static const type_info TYPES[] = {
    {1, 2, 1, "line"},           {2, 3, 1, "triangle"},
    {3, 4, 1, "quadrilateral"},  {4, 4, 1, "tetrahedron"},
    {5, 8, 1, "hexahedron"},     {6, 6, 1, "prism"},
    {7, 5, 1, "pyramid"},        {8, 3, 2, "line"},
    {9, 6, 2, "triangle"},       {10, 9, 2, "quadrilateral"},
    {11, 10, 2, "tetrahedron"},  {12, 27, 2, "hexahedron"},
    {13, 18, 2, "prism"},        {14, 14, 2, "pyramid"},
    {15, 1, 0, "point"},         {16, 8, 2, "quadrilateral"},
    {17, 20, 2, "hexahedron"},   {18, 15, 2, "prism"},
    {19, 13, 2, "pyramid"},      {20, 9, 3, "triangle"},
    {21, 10, 3, "triangle"},     {22, 12, 4, "triangle"},
    {23, 15, 4, "triangle"},     {24, 15, 5, "triangle"},
    {25, 21, 5, "triangle"},     {26, 4, 3, "line"},
    {27, 5, 4, "line"},          {28, 6, 5, "line"},
    {29, 20, 3, "tetrahedron"},  {30, 35, 4, "tetrahedron"},
    {31, 56, 5, "tetrahedron"},  {92, 64, 3, "hexahedron"},
    {93, 125, 4, "hexahedron"},
};

static const type_info *find_type(int msh_type)
{
    for (size_t i = 0; i < sizeof TYPES / sizeof *TYPES; i++)
        if (TYPES[i].type == msh_type)
            return &TYPES[i];
    return NULL;
}

int getme__msh_type_nodes(int msh_type, int *order)
{
    const type_info *t = find_type(msh_type);
    if (order)
        *order = t ? t->order : 0;
    return t ? t->nodes : 0;
}

int getme__msh_type_name(int msh_type, char *buf, size_t size)
{
    const type_info *t = find_type(msh_type);
    if (!t)
        snprintf(buf, size, "element type %d", msh_type);
    else if (t->order > 1)
        snprintf(buf, size, "%d-node %s", t->nodes, t->family);
    else
        snprintf(buf, size, "%s", t->family);
    return t != NULL;
}

int getme__msh_type_dim(int msh_type)
{
    const type_info *t = find_type(msh_type);
    if (!t)
        return -1;
    const char *f = t->family;
    return !strcmp(f, "point") ? 0 : !strcmp(f, "line") ? 1
           : !strcmp(f, "triangle") || !strcmp(f, "quadrilateral") ? 2 : 3;
}

/* MSH 2 tri3, 3 quad4, 4 tet4, 5 hex8, 6 prism6, 7 pyramid5. */
int getme__msh_type_getme(int msh_type)
{
    static const int by_msh[6] = {GETME_TRI, GETME_QUAD,  GETME_TET,
                                  GETME_HEX, GETME_PRISM, GETME_PYRAMID};
    return msh_type >= 2 && msh_type <= 7 ? by_msh[msh_type - 2] : -1;
}

/* Second-order volume types smoothed with their corners (Gmsh's node order
   is getme_mesh_add_elements_ho's, docs/highorder.md): 11 tet10, 17 hex20,
   12 hex27, 18 prism15, 13 prism18 in a 3-D mesh; -1 otherwise. */
int getme__msh_type_ho(int msh_type, int dim)
{
    switch (dim == 3 ? msh_type : 0) {
    case 11: return GETME_TET10;
    case 17: return GETME_HEX20;
    case 12: return GETME_HEX27;
    case 18: return GETME_PRISM15;
    case 13: return GETME_PRISM18;
    default: return -1;
    }
}

int getme__msh_type_corners(int msh_type, int dim)
{
    int ho = getme__msh_type_ho(msh_type, dim);
    return ho >= 0 ? getme_ho_type_linear((getme_ho_type)ho)
                   : getme__msh_type_getme(msh_type);
}

const char *getme__dim_word(int dim, int capital)
{
    static const char *const w[2][5] = {
        {"point", "curve", "surface", "volume", "entity"},
        {"Point", "Curve", "Surface", "Volume", "Entity"}};
    return w[capital != 0][dim >= 0 && dim <= 3 ? dim : 4];
}
