/*
 * stats.c -- element qualities and the statistics the CLI, the Gmsh plugin
 * and the benchmark report (Gmsh-style histogram, q*_min, q_mean).
 */
#include "exact.h"
#include "internal.h"

#include <stdlib.h>
#include <string.h>

getme_status getme_mesh_element_qualities(getme_mesh *mesh, double *q)
{
    if (!mesh || (!q && mesh->num_elements))
        return GETME_ERR_ARGUMENT;
    if (mesh->mirror < 0)
        getme__detect_orientation(mesh);
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        double ysign = mesh->mirror == 1 ? -1.0 : 1.0;
#pragma omp parallel for schedule(static)
        for (int32_t e = 0; e < bl->count; e++) {
            double x[3 * GETME_MAX_NV];
            getme__prefetch_local(mesh, bl, e + GETME_PREFETCH_AHEAD);
            getme__gather_local(mesh, bl, e, ysign, x);
            q[bl->first + e] = getme__quality(bl->type, x);
        }
    }
    return GETME_OK;
}

static void add_value(getme_quality_stats *s, double v, int has_free,
                      int32_t e, getme_ufx *sum)
{
    s->num_elements++;
    if (!(v > 0.0)) {
        s->num_invalid++;
        if (s->num_reported_invalid < GETME_MAX_REPORTED_INVALID)
            s->first_invalid[s->num_reported_invalid++] = e;
        v = 0.0;
    } else {
        int bin = (int)(v * GETME_HIST_BINS);
        s->histogram[bin >= GETME_HIST_BINS ? GETME_HIST_BINS - 1 : bin]++;
    }
    *sum += (getme_ufx)getme__fx_q(v);
    if (v < s->q_min)
        s->q_min = v;
    if (v > s->q_max)
        s->q_max = v;
    if (has_free) {
        s->num_free++;
        if (v < s->q_min_star)
            s->q_min_star = v;
    }
    s->num_below_04 += v <= 0.4;
    s->num_below_01 += v < 0.1;
}

getme_status getme_mesh_quality_stats(getme_mesh *mesh, int type,
                                      getme_quality_stats *s)
{
    if (!mesh || !s || type < -1 || type >= GETME_NUM_TYPES)
        return GETME_ERR_ARGUMENT;
    memset(s, 0, sizeof *s);
    s->q_min = s->q_min_star = 1.0;
    s->q_max = 0.0;
    double *q = malloc((size_t)(mesh->num_elements ? mesh->num_elements : 1) *
                       sizeof *q);
    if (!q)
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    getme_mesh_element_qualities(mesh, q);
    /* An exact fixed-point sum (exact.h): q_mean is the same bits for any
       thread count and any order or split of the elements. */
    getme_ufx sum = 0;
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        if (type >= 0 && bl->type != type)
            continue;
        int nv = getme__nv[bl->type];
        for (int32_t e = 0; e < bl->count; e++) {
            const int32_t *c = bl->conn + (int64_t)e * nv;
            int has_free = 0;
            for (int i = 0; i < nv; i++)
                has_free |= !mesh->fixed[c[i]];
            add_value(s, q[bl->first + e], has_free, bl->first + e, &sum);
        }
    }
    s->q_mean = s->num_elements ? getme__fx_double((getme_fx)sum, GETME_FX_QINV) /
                                    (double)s->num_elements
                              : 0.0;
    if (s->num_elements == 0)
        s->q_min = s->q_max = 0.0;
    free(q);
    return GETME_OK;
}
