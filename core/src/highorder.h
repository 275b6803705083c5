/*
 * highorder.h -- second-order elements (docs/highorder.md): the mesh's
 * record of them, the reference elements, and the workspace view in which
 * the smoother sees linear elements and the other nodes are dependent.
 */
#ifndef GETME_HIGHORDER_H
#define GETME_HIGHORDER_H

#include "internal.h"

#define GETME_HO_MAX_NV 27
/* nonzero shape function derivatives at the nodes, all types (hex20,
   the most, has 288) */
#define GETME_HO_MAX_NZ 512

/* ---- the mesh's record (highorder.c) ------------------------------------ */

typedef struct getme_ho_block {
    int type;        /* getme_ho_type                                      */
    int32_t first;   /* global index of its first element                  */
    int32_t count;
    int32_t *conn;   /* count * nv, Gmsh order                             */
} getme_ho_block;

typedef struct getme_ho_mesh {
    getme_ho_block *blocks;
    int num_blocks, cap_blocks;
    int32_t num_elements;
} getme_ho_mesh;

void getme__ho_mesh_free(getme_ho_mesh *ho);

/* ---- reference elements (highorder_basis.c) ----------------------------- */

typedef struct getme_ho_info {
    int nv;       /* all nodes                                             */
    int nlin;     /* corners                                               */
    int lin;      /* linear getme_elem_type                                */
    int dim;      /* 2 or 3                                                */
    /* corners of the edge (2), quad face (4) or body (8) of each
       dependent node k >= nlin, local indices; ncorner[k] is 2, 4 or 8 */
    int8_t ncorner[GETME_HO_MAX_NV];
    int8_t corner[GETME_HO_MAX_NV][8];
    /* dn[k][j][d]: derivative along reference axis d of shape function j at
       node k (Gmsh's reference element and polynomial space)             */
    double dn[GETME_HO_MAX_NV][GETME_HO_MAX_NV][3];
    /* The nonzero entries of dn by node k and axis d, in
       [sp_ptr[3 k + d], sp_ptr[3 k + d + 1]): shape function sp_n, value
       sp_v, in shape function order.  Most of dn is exactly 0 (tet10
       58 %, hex20 76 %, hex27 90 %), and a Jacobian sum that skips exact
       zeros is the same bits (getme__ho_det_range says why). */
    int16_t sp_ptr[3 * GETME_HO_MAX_NV + 1];
    uint8_t sp_n[GETME_HO_MAX_NZ];
    double sp_v[GETME_HO_MAX_NZ];
} getme_ho_info;

extern const int getme__ho_nv[GETME_NUM_HO_TYPES];
extern const int getme__ho_lin[GETME_NUM_HO_TYPES];

/* Fill info for type: solves the Vandermonde system of the type's
   polynomial space on its reference nodes.  0, or -1 if singular (a bug in
   the tables). */
int getme__ho_info_init(int type, getme_ho_info *info);

/* Smallest and largest Jacobian determinant over the nodes of one element
   with all nv nodes at x (nv triples). */
void getme__ho_det_range(const getme_ho_info *info, const double *x,
                         double *dmin, double *dmax);
/* The same for GETME_LANES elements of one type, x[3 n + a][l] for node
   n of lane l: the same bits per lane.  0 (nothing written) if a lane
   has a coordinate that is not finite: those take getme__ho_det_range. */
int getme__ho_det_range_lanes(const getme_ho_info *info,
                              const double (*x)[GETME_LANES], double *dmin,
                              double *dmax);

/* ---- the workspace view (highorder_ws.c) -------------------------------- */

struct getme_ws;

typedef struct getme_ho_ws {
    int32_t nh;       /* dependent nodes                                   */
    int32_t *node;    /* nh: its internal node index                       */
    uint8_t *nc;      /* nh: 2 edge, 4 face, 8 body                        */
    uint8_t *pinned;  /* nh: never moves                                   */
    uint8_t *straight;/* nh: exactly at its straight position initially   */
    int32_t *cn;      /* 8 * nh: corners, internal indices, canonical order */
    double *ref;      /* 3 * nh: the offset in the entity's frame          */
    double *x0;       /* 3 * nn: workspace coordinates at the start        */
    int8_t *etype;    /* ne: getme_ho_type of internal element, or -1 (also
                         for a tet10/tri6 that stays affine: see attach)   */
    int64_t *eptr;    /* ne + 1: into eho                                  */
    int32_t *eho;     /* dependent node index of each slot k >= nlin       */
    getme_ho_info *info; /* GETME_NUM_HO_TYPES, filled for types present   */
    double *floor;    /* ne, or NULL: the node det J ratio a move may not
                         go below (getme__ho_floor_start)                  */
} getme_ho_ws;

/* The node det J ratio (min / max of det J at the nodes) smoothing keeps
   an element at: it never goes below min(this, its ratio at the start).
   Also the ratio the repair pulls an element invalid at a node up to
   (getme__ho_repair), so that smoothing keeps what the repair made. */
#define GETME_HO_RATIO_FLOOR 0.1

/* Attach the mesh's second-order elements to a freshly built workspace
   (ws->ho stays NULL if there are none): getme_smooth, getme_mesh_untangle
   and getme_mesh_distort do; the workspaces built only for faces
   (fix_boundary, topology) need not.  GETME_OK, GETME_ERR_NOMEM, or
   GETME_ERR_TOPOLOGY with the message on the mesh. */
getme_status getme__ho_attach(struct getme_ws *ws, getme_mesh *mesh);
void getme__ho_free(getme_ho_ws *ho);

/* 1 if internal element e is valid at all its nodes with corners at
   coords (dependent nodes placed from them); 1 for linear elements. */
int getme__ho_valid(const struct getme_ws *ws, const double *coords,
                    int32_t e);
/* min / max of det J over element e's nodes (as getme__ho_valid places
   them): <= 0 if invalid, 1 for linear elements. */
double getme__ho_ratio(const struct getme_ws *ws, const double *coords,
                       int32_t e);
/* Smoothing's floors: per element, min(GETME_HO_RATIO_FLOOR, its ratio
   at ws->x now).  GETME_OK or GETME_ERR_NOMEM; nothing without ws->ho. */
getme_status getme__ho_floor_start(struct getme_ws *ws);
/* Element e may take the shape at coords: valid at every node, and its
   node det J ratio not below its floor (when floors were set). */
int getme__ho_accept(const struct getme_ws *ws, const double *coords,
                     int32_t e);
/* 1 if some element is checked at its nodes (curved second order): only
   then does getme__ho_table pay. */
int getme__ho_curved(const struct getme_ws *ws);
/* Every dependent node placed from coords into tab (3 * nh; pinned ones
   at their input position), in parallel: the bits the checks compute
   for it element by element. */
void getme__ho_table(const struct getme_ws *ws, const double *coords,
                     double *tab);
/* getme__ho_accept at coords, the dependent nodes read from tab
   (getme__ho_table of the same coords): the same answer. */
int getme__ho_accept_tab(const struct getme_ws *ws, const double *coords,
                         const double *tab, int32_t e);
/* getme__ho_accept_tab of the n <= GETME_LANES elements elems (ok[l]: 1
   accepted), the node Jacobians of those of one second-order type in
   vector lanes (getme__ho_det_range_lanes): the same answers.  Lanes
   with q[l] <= 0 are not checked (ok 1: the caller rejects them). */
void getme__ho_accept_tab_lanes(const struct getme_ws *ws,
                                const double *coords, const double *tab,
                                const int32_t *elems, int n, const double *q,
                                uint8_t *ok);
/* Dependent slots of an element (nv - nlin), at most: */
#define GETME_HO_MAX_DEP (GETME_HO_MAX_NV - 4)
/* For element e: which of its dependent nodes follow one of the k nodes
   mv (a corner of their entity is one), into mov[slot] (1), and the
   others placed from coords into dep (3 per slot).  Moves of mv alone
   leave those positions as they are.  0 for an element checked at its
   corners only, else 1. */
int getme__ho_dep_split(const struct getme_ws *ws, const double *coords,
                        int32_t e, const int32_t *mv, int k, double *dep,
                        uint8_t *mov);
/* getme__ho_accept at coords, the slots getme__ho_dep_split did not flag
   read from its dep (computed with only mv moved since): the same
   answer. */
int getme__ho_accept_dep(const struct getme_ws *ws, const double *coords,
                         int32_t e, const double *dep, const uint8_t *mov);

/* Pull the free dependent nodes of elements that are invalid only at
   their non-corner nodes (corners valid) toward their straight positions,
   halving their offsets until those elements are valid
   (highorder_repair.c).  num_found: elements found invalid that way,
   num_elements: those of them valid afterwards, num_nodes: nodes moved.
   GETME_OK or GETME_ERR_NOMEM. */
getme_status getme__ho_repair(struct getme_ws *ws, int32_t *num_found,
                              int32_t *num_elements, int32_t *num_nodes);

/* Write the dependent nodes placed from ws->x into the mesh (pinned ones
   are not written). */
void getme__ho_store(const struct getme_ws *ws, getme_mesh *mesh);

#endif /* GETME_HIGHORDER_H */
