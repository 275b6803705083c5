/*
 * highorder.c -- the public calls for second-order elements: adding them to
 * a mesh (the corners become ordinary linear elements, the whole
 * connectivity is kept here) and the per-element Jacobian check.
 */
#include "highorder.h"

#include <omp.h>

#include <stdlib.h>
#include <string.h>

static const char *const ho_names[GETME_NUM_HO_TYPES] = {
    "tet10", "hex20", "hex27", "prism15", "prism18", "tri6", "quad8", "quad9",
    "pyramid13", "pyramid14"};

int getme_ho_type_num_nodes(getme_ho_type type)
{
    return (int)type >= 0 && type < GETME_NUM_HO_TYPES ? getme__ho_nv[type] : 0;
}

int getme_ho_type_linear(getme_ho_type type)
{
    return (int)type >= 0 && type < GETME_NUM_HO_TYPES ? getme__ho_lin[type]
                                                       : -1;
}

const char *getme_ho_type_name(getme_ho_type type)
{
    return (int)type >= 0 && type < GETME_NUM_HO_TYPES ? ho_names[type]
                                                       : "unknown";
}

void getme__ho_mesh_free(getme_ho_mesh *ho)
{
    if (!ho)
        return;
    for (int b = 0; b < ho->num_blocks; b++)
        free(ho->blocks[b].conn);
    free(ho->blocks);
    free(ho);
}

int32_t getme_mesh_num_elements_ho(const getme_mesh *mesh)
{
    return mesh && mesh->ho ? mesh->ho->num_elements : 0;
}

getme_status getme_mesh_add_elements_ho(getme_mesh *mesh, getme_ho_type type,
                                        int32_t count, const int32_t *conn,
                                        const int32_t *region)
{
    if (!mesh)
        return GETME_ERR_ARGUMENT;
    if ((int)type < 0 || type >= GETME_NUM_HO_TYPES)
        return getme__fail(mesh, GETME_ERR_ARGUMENT,
                           "unknown second-order element type %d", (int)type);
    if (count < 0 || (count > 0 && !conn))
        return getme__fail(mesh, GETME_ERR_ARGUMENT, "bad element count");
    if (count == 0)
        return GETME_OK;
    int nv = getme__ho_nv[type], lin = getme__ho_lin[type];
    int nl = getme__nv[lin];
    for (int32_t e = 0; e < count; e++)
        if (!getme__element_nodes_ok(conn + (int64_t)e * nv, nv,
                                     mesh->num_nodes))
            return getme__fail(mesh, GETME_ERR_TOPOLOGY,
                               "element %d (%s %d of this block): node index "
                               "out of range or repeated",
                               (int)(mesh->num_elements + e),
                               ho_names[type], (int)e);
    if (!mesh->ho && !(mesh->ho = getme__calloc(1, sizeof *mesh->ho)))
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    getme_ho_mesh *ho = mesh->ho;
    if (ho->num_blocks == ho->cap_blocks) {
        int cap = ho->cap_blocks ? 2 * ho->cap_blocks : 4;
        getme_ho_block *nb =
            getme__realloc(ho->blocks, (size_t)cap * sizeof *nb);
        if (!nb)
            return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
        ho->blocks = nb;
        ho->cap_blocks = cap;
    }
    int32_t *full = getme__malloc((size_t)count * nv * sizeof *full);
    int32_t *corners = getme__malloc((size_t)count * nl * sizeof *corners);
    if (!full || !corners) {
        free(full);
        free(corners);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    memcpy(full, conn, (size_t)count * nv * sizeof *full);
    for (int32_t e = 0; e < count; e++)
        memcpy(corners + (int64_t)e * nl, conn + (int64_t)e * nv,
               (size_t)nl * sizeof *corners);
    int32_t first = mesh->num_elements;
    getme_status st = getme_mesh_add_elements(mesh, (getme_elem_type)lin,
                                              count, corners, region);
    free(corners);
    if (st != GETME_OK) {
        free(full);
        return st;
    }
    getme_ho_block *b = &ho->blocks[ho->num_blocks++];
    b->type = type;
    b->first = first;
    b->count = count;
    b->conn = full;
    ho->num_elements += count;
    return GETME_OK;
}

/* Ratio of the smallest to the largest det J over the nodes of one element
   of a block (x: scratch for its nodes). */
static double block_ratio(const getme_mesh *mesh, const getme_ho_info *info,
                          const int32_t *c, double *x)
{
    double ysign = mesh->mirror == 1 ? -1.0 : 1.0;
    for (int i = 0; i < info->nv; i++) {
        const double *p = mesh->coords + 3 * (int64_t)c[i];
        x[3 * i] = p[0];
        x[3 * i + 1] = ysign * p[1];
        x[3 * i + 2] = p[2];
    }
    double lo, hi;
    getme__ho_det_range(info, x, &lo, &hi);
    return hi > 0.0 ? lo / hi : (lo < 0.0 ? -1.0 : 0.0);
}

/* The serial answer in parallel: the smallest ratio, the first element
   that has it (strict <); a NaN ratio never wins, except that the first
   element starts as the answer, NaN or not (as the serial loop's
   "no element yet" did).  Each thread keeps its range's smallest non-NaN
   ratio, the first of equals; the ranges are merged in element order. */
getme_status getme_mesh_jacobian_ratio_min(getme_mesh *mesh, double *ratio,
                                           int32_t *element)
{
    if (!mesh || !ratio || !element)
        return GETME_ERR_ARGUMENT;
    *ratio = 1.0;
    *element = -1;
    if (!mesh->ho)
        return GETME_OK;
    if (mesh->mirror < 0)
        getme__detect_orientation(mesh);
    for (int b = 0; b < mesh->ho->num_blocks; b++) {
        const getme_ho_block *bl = &mesh->ho->blocks[b];
        getme_ho_info info;
        if (getme__ho_info_init(bl->type, &info))
            return getme__fail(mesh, GETME_ERR_ARGUMENT, "bad tables");
        int32_t l0 = 0;
        if (*element < 0 && bl->count > 0) { /* the first element */
            double x[3 * GETME_HO_MAX_NV];
            *ratio = block_ratio(mesh, &info, bl->conn, x);
            *element = bl->first;
            l0 = 1;
        }
        double best = 0.0;
        int32_t best_l = -1; /* no non-NaN ratio below *ratio yet */
#pragma omp parallel
        {
            double x[3 * GETME_HO_MAX_NV], tb = 0.0;
            int32_t tl = -1;
#pragma omp for schedule(static) nowait
            for (int32_t l = l0; l < bl->count; l++) {
                double r = block_ratio(mesh, &info,
                                       bl->conn + (int64_t)l * info.nv, x);
                if (r == r && (tl < 0 || r < tb))
                    tb = r, tl = l;
            }
#pragma omp critical(getme_ratio_min)
            if (tl >= 0 && (best_l < 0 || tb < best ||
                            (tb == best && tl < best_l)))
                best = tb, best_l = tl;
        }
        /* blocks come in element order: strict < keeps the smaller index */
        if (best_l >= 0 && best < *ratio) {
            *ratio = best;
            *element = bl->first + best_l;
        }
    }
    return GETME_OK;
}

getme_status getme_mesh_element_jacobian_ratio(getme_mesh *mesh, int32_t e,
                                               double *ratio)
{
    if (!mesh || !ratio || e < 0 || e >= mesh->num_elements)
        return GETME_ERR_ARGUMENT;
    *ratio = 1.0;
    if (!mesh->ho)
        return GETME_OK;
    for (int b = 0; b < mesh->ho->num_blocks; b++) {
        const getme_ho_block *bl = &mesh->ho->blocks[b];
        if (e < bl->first || e >= bl->first + bl->count)
            continue;
        getme_ho_info info;
        if (getme__ho_info_init(bl->type, &info))
            return getme__fail(mesh, GETME_ERR_ARGUMENT, "bad tables");
        double x[3 * GETME_HO_MAX_NV];
        if (mesh->mirror < 0)
            getme__detect_orientation(mesh);
        *ratio = block_ratio(mesh, &info,
                             bl->conn + (int64_t)(e - bl->first) * info.nv, x);
        return GETME_OK;
    }
    return GETME_OK;
}
