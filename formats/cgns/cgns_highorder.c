/*
 * cgns_highorder.c -- CGNS second-order volume elements (TETRA_10,
 * HEXA_20, HEXA_27, PENTA_15, PENTA_18): which getme_ho_type each is, and
 * the CGNS (SIDS) node order mapped to Gmsh's, the order of
 * getme_mesh_add_elements_ho.  SIDS lists the mid-edge nodes edge by edge
 * around the bottom face, then the vertical edges, then around the top
 * face (tets: the base edges, then the edges to the apex), then face
 * centres and the body centre; Gmsh lists edges by their first corner.
 * tests/highorder/test_highorder_cgns.py proves the tables with the CGNS
 * project's cgns_to_vtk and meshio (docs/highorder.md).
 */
#include "cgns_internal.h"

/* Gmsh's node k is CGNS node order[k] (0-based). */
static const int8_t order_tetra10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
static const int8_t order_hexa27[27] = {
    0,  1,  2,  3,  4,  5,  6,  7,  8,  11, 12, 9,  13, 10,
    14, 15, 16, 19, 17, 18, 20, 21, 24, 22, 23, 25, 26};
static const int8_t order_penta18[18] = {0,  1,  2,  3,  4,  5,  6,  8,  9,
                                         7,  10, 11, 12, 14, 13, 15, 17, 16};

int cgns_ho_type(cgns_elem_t type)
{
    switch (type) {
    case CGNS_ENUMV(TETRA_10): return GETME_TET10;
    case CGNS_ENUMV(HEXA_20):  return GETME_HEX20;
    case CGNS_ENUMV(HEXA_27):  return GETME_HEX27;
    case CGNS_ENUMV(PENTA_15): return GETME_PRISM15;
    case CGNS_ENUMV(PENTA_18): return GETME_PRISM18;
    default:                   return -1;
    }
}

/* hex20 and prism15 are the first nodes of hex27 and prism18 in both
   orders. */
const int8_t *cgns_ho_order(int ho_type)
{
    switch (ho_type) {
    case GETME_TET10: return order_tetra10;
    case GETME_HEX20: case GETME_HEX27: return order_hexa27;
    case GETME_PRISM15: case GETME_PRISM18: return order_penta18;
    default: return NULL;
    }
}
