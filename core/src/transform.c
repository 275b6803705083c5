/*
 * transform.c -- dispatch of the regularizing element transformations and
 * the public single-element entry point.  The kernels themselves live in
 * transform_tet.c (opposite face normals), transform_dual.c (hex, prism,
 * pyramid) and transform_polygon.c (tri, quad).
 */
#include "internal.h"

#include <math.h>
#include <string.h>

void getme__transform(int type, const double *x, double sigma, double *out)
{
    switch (type) {
    case GETME_TET: getme__transform_tet(x, sigma, out); break;
    case GETME_HEX: getme__transform_hex(x, sigma, out); break;
    case GETME_PRISM: getme__transform_prism(x, sigma, out); break;
    case GETME_PYRAMID: getme__transform_pyramid(x, sigma, out); break;
    case GETME_TRI: getme__transform_tri(x, sigma, out); break;
    case GETME_QUAD: getme__transform_quad(x, sigma, out); break;
    default: break;
    }
}

static int all_finite(const double *x, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i]))
            return 0;
    return 1;
}

/*
 * Arguments are checked here, never in the kernels (the smoother calls those
 * with data it has already validated).  sigma must be a positive number: 0
 * or less does not regularize (the dual step would even turn elements
 * inside out).  Non-finite coordinates are refused rather than turned into
 * NaN output.  The input is copied first, so out == xyz works even though
 * getme.h does not promise it.
 */
getme_status getme_element_transform(getme_elem_type type, const double *xyz,
                                     double sigma, double *out)
{
    int nv = getme_type_num_nodes(type);
    if (nv == 0 || xyz == NULL || out == NULL || !isfinite(sigma) ||
        !(sigma > 0.0))
        return GETME_ERR_ARGUMENT;
    double x[3 * GETME_MAX_NV];
    memcpy(x, xyz, sizeof(double) * 3 * (size_t)nv);
    if (!all_finite(x, 3 * nv))
        return GETME_ERR_ARGUMENT;
    getme__transform((int)type, x, sigma, out);
    return GETME_OK;
}
