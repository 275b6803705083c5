/*
 * finish_sub.c -- the finishing step on a sub-mesh (getme.h:
 * getme_element_key, getme_finish_rest_*, getme_smooth_finish_sub;
 * docs/distributed.md, "The finishing step on a sub-mesh").
 *
 * Why: a distributed run ends with the serial finishing step, which
 * touches only the worst elements and the stars of their nodes.  Running
 * it on the whole mesh makes one process hold the whole mesh; running it
 * on those elements alone gives the same bits when
 *  - the elements are in the whole mesh's workspace order (ties of the
 *    worst-first list, the order of stars and so of patches and of the
 *    finishing budget): the caller's keys give it, and the sub-mesh's
 *    workspace keeps the caller's order (renumber = 0);
 *  - the values of the whole mesh that a pass reads (its bound, q*_min,
 *    q_mean) add the constant rest of the mesh, exactly (exact.h);
 *  - every element a pass can touch is inside: finish.c checks it per
 *    pass (run->sub) and gives up with GETME_ERR_INCOMPLETE otherwise.
 */
#include "smooth_internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

uint64_t getme_element_key(getme_elem_type type, int32_t index,
                           const double first_node_xyz[3],
                           const double lo[3], const double hi[3])
{
    uint64_t m = 0;
    if (lo && hi && first_node_xyz) {
        double scale[3];
        for (int d = 0; d < 3; d++) /* as the workspace's order_elements */
            scale[d] = hi[d] > lo[d] ? 1023.0 / (hi[d] - lo[d]) : 0.0;
        m = getme__morton(first_node_xyz, lo, scale);
    }
    return (uint64_t)type << 61 | m << 31 | (uint64_t)(uint32_t)index;
}

void getme_finish_rest_init(getme_finish_rest *rest)
{
    memset(rest, 0, sizeof *rest);
    rest->q_min = rest->q_min_free = rest->corner_min = 1.0;
}

static getme_ufx rest_sum(const getme_finish_rest *r)
{
    return (getme_ufx)r->q_sum[1] << 64 | r->q_sum[0];
}

static void set_sum(getme_finish_rest *r, getme_ufx s)
{
    r->q_sum[0] = (uint64_t)s;
    r->q_sum[1] = (uint64_t)(s >> 64);
}

getme_status getme_finish_rest_add(getme_finish_rest *rest,
                                   const getme_mesh *mesh,
                                   const uint8_t *include,
                                   const double *qual)
{
    if (!rest || !mesh)
        return GETME_ERR_ARGUMENT;
    if (mesh->ho || mesh->dim != 3)
        return GETME_ERR_ARGUMENT;
    getme_ufx s = rest_sum(rest);
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        int t = bl->type, nv = getme__nv[t];
        for (int32_t i = 0; i < bl->count; i++) {
            if (include && !include[bl->first + i])
                continue;
            double x[3 * GETME_MAX_NV];
            getme__gather_local(mesh, bl, i, 1.0, x);
            /* the workspace's values: getme__ws_quality, free_elem,
               getme__ws_corner_min */
            double q = qual ? qual[bl->first + i] : getme__quality(t, x);
            int free = 0;
            for (int j = 0; j < nv; j++)
                free |= !mesh->fixed[bl->conn[(int64_t)i * nv + j]];
            s += (getme_ufx)getme__fx_q(q);
            rest->num_elements++;
            rest->q_min = q < rest->q_min ? q : rest->q_min;
            if (free) {
                rest->num_free_elements++;
                rest->q_min_free = q < rest->q_min_free ? q : rest->q_min_free;
            }
            if (getme__has_corners(t)) {
                double c = getme__corner_sj(t, x);
                rest->corner_min = c < rest->corner_min ? c : rest->corner_min;
            }
        }
    }
    set_sum(rest, s);
    return GETME_OK;
}

void getme_finish_rest_merge(getme_finish_rest *into,
                             const getme_finish_rest *from)
{
    into->num_elements += from->num_elements;
    into->num_free_elements += from->num_free_elements;
    set_sum(into, rest_sum(into) + rest_sum(from));
    into->q_min = from->q_min < into->q_min ? from->q_min : into->q_min;
    into->q_min_free = from->q_min_free < into->q_min_free ? from->q_min_free
                                                         : into->q_min_free;
    into->corner_min = from->corner_min < into->corner_min ? from->corner_min
                                                         : into->corner_min;
}

/* The workspace (renumber = 0: the caller's order) must be in ascending
   key order, each key naming its element's type. */
static getme_status check_keys(getme_mesh *sub, const getme_ws *ws,
                               const uint64_t *key)
{
    for (int32_t e = 0; e < ws->ne; e++) {
        uint64_t k = key[ws->elem_orig[e]];
        if ((int)(k >> 61) != getme__ws_type(ws, e) ||
            (e > 0 && !(k > key[ws->elem_orig[e - 1]])))
            return getme__fail(sub, GETME_ERR_ARGUMENT,
                               "sub-mesh element %d: its key is not its type "
                               "or not above the previous one (add the "
                               "elements in ascending key order)",
                               (int)ws->elem_orig[e]);
    }
    return GETME_OK;
}

getme_status getme_smooth_finish_sub(getme_mesh *sub,
                                     const getme_params *params,
                                     const uint64_t *key,
                                     const uint8_t *complete,
                                     const getme_finish_rest *rest,
                                     getme_result *result)
{
    if (!sub || !key || !complete || !rest || !result)
        return GETME_ERR_ARGUMENT;
    /* a planar sub-mesh would decide its orientation (mirror) alone */
    if (sub->ho || sub->dim != 3)
        return getme__fail(sub, GETME_ERR_ARGUMENT, "the finishing step on "
                           "a sub-mesh takes linear volume elements only");
    getme_params defaults, local;
    if (!params) {
        getme_params_init(&defaults);
        params = &defaults;
    }
    local = *params;
    local.renumber = 0; /* the keys give the whole mesh's order */
    const getme_params *lp = &local;
    double t0 = omp_get_wtime();
    getme_ws ws;
    getme_status st = getme__start(sub, &lp, &defaults, &ws);
    if (st != GETME_OK)
        return st;
    getme_run run;
    memset(&run, 0, sizeof run);
    getme_result r = *result; /* result changes only on success */
    getme_finish_sub fs;
    memset(&fs, 0, sizeof fs);
    fs.rest = rest;
    fs.cap_log = params->finish_max_passes > 0 ? params->finish_max_passes : 0;
    fs.log = getme__malloc((size_t)(fs.cap_log + 1) * sizeof *fs.log);
    uint8_t *inside = getme__malloc((size_t)(ws.nn ? ws.nn : 1));
    fs.complete = inside;
    run.ws = &ws;
    run.params = lp;
    run.result = &r;
    run.t0 = t0 - result->seconds;
    run.sub = &fs;
    if ((st = check_keys(sub, &ws, key)) != GETME_OK)
        goto done;
    if (!fs.log || !inside || (st = getme__run_alloc(&run)) != GETME_OK) {
        st = getme__fail(sub, GETME_ERR_NOMEM, "out of memory for %d nodes, "
                         "%d elements", (int)ws.nn, (int)ws.ne);
        goto done;
    }
    for (int32_t i = 0; i < ws.nn; i++)
        inside[i] = complete[ws.node_orig[i]] != 0;
    getme__ws_qualities(&ws, run.q);
    st = getme__adaptive_finish(&run);
    if (st == GETME_ERR_INCOMPLETE) {
        getme__fail(sub, st, "the finishing step needs elements outside the "
                             "sub-mesh: grow it");
        result->threshold = fs.need;
        goto done;
    }
    if (st != GETME_OK) {
        getme__fail(sub, st, "%s", getme_status_string(st));
        goto done;
    }
    getme__finish_summary(&run, &r.q_mean, &r.q_min_star, &r.q_min);
    double c = getme__ws_corner_min(&ws);
    r.corner_sj = c < rest->corner_min ? c : rest->corner_min;
    getme__ws_store(&ws, sub);
    r.seconds += omp_get_wtime() - t0;
    *result = r;
    for (int i = 0; params->progress && i < fs.num_log; i++)
        (void)params->progress(&fs.log[i], params->progress_data);
done:
    free(fs.log);
    free(inside);
    getme__run_free(&run);
    getme__ws_free(&ws);
    return st;
}
