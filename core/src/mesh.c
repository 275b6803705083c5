/*
 * mesh.c -- the getme_mesh container: coordinates, element blocks, fixed
 * mask, error message.  Everything the caller passes is copied once into
 * flat arrays; nothing is allocated per node or element.
 */
#include "highorder.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *getme_version(void) { return GETME_VERSION_STRING; }

const char *getme_status_string(getme_status status)
{
    switch (status) {
    case GETME_OK: return "ok";
    case GETME_ERR_ARGUMENT: return "invalid argument";
    case GETME_ERR_NOMEM: return "out of memory";
    case GETME_ERR_INVALID_MESH: return "invalid mesh";
    case GETME_ERR_TOPOLOGY: return "bad connectivity";
    case GETME_ERR_STATE: return "call out of order";
    case GETME_ERR_CANCELLED: return "cancelled";
    case GETME_ERR_COMM: return "communication failed";
    case GETME_ERR_INCOMPLETE: return "the sub-mesh is too small";
    }
    return "unknown status";
}

getme_status getme__fail(getme_mesh *mesh, getme_status status,
                         const char *fmt, ...)
{
    if (mesh) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(mesh->error, sizeof mesh->error, fmt, ap);
        va_end(ap);
    }
    return status;
}

const char *getme_mesh_error(const getme_mesh *mesh)
{
    return mesh ? mesh->error : "no mesh";
}

/* getme_mesh_create (take NULL) and getme_mesh_create_take (take ==
   coords, freed on every path where the mesh does not keep it). */
static getme_status create(getme_mesh **out, int dim, int32_t num_nodes,
                           const double *coords, double *take)
{
    getme_status st = GETME_ERR_ARGUMENT;
    getme_mesh *m = NULL;
    if (!out)
        goto fail;
    *out = NULL;
    if ((dim != 2 && dim != 3) || num_nodes < 0 ||
        (num_nodes > 0 && !coords) || num_nodes > INT32_MAX / 3)
        goto fail;
    st = GETME_ERR_NOMEM;
    m = getme__calloc(1, sizeof *m);
    if (!m)
        goto fail;
    m->dim = dim;
    m->num_nodes = num_nodes;
    size_t n = (size_t)num_nodes;
    if (take && n) {
        m->coords = take; /* freed with the mesh from here on */
        take = NULL;
    } else {
        m->coords = getme__malloc((n ? n : 1) * 3 * sizeof(double));
    }
    m->fixed = getme__calloc(n ? n : 1, 1);
    if (!m->coords || !m->fixed)
        goto fail;
    if (n && m->coords != coords)
        memcpy(m->coords, coords, n * 3 * sizeof(double));
    st = GETME_ERR_ARGUMENT;
    for (size_t i = 0; i < 3 * n; i++)
        if (!isfinite(m->coords[i]))
            goto fail;
    free(take); /* num_nodes 0: nothing taken */
    *out = m;
    return GETME_OK;
fail:
    getme_mesh_free(m);
    free(take);
    return st;
}

getme_status getme_mesh_create(getme_mesh **out, int dim, int32_t num_nodes,
                               const double *coords)
{
    return create(out, dim, num_nodes, coords, NULL);
}

getme_status getme_mesh_create_take(getme_mesh **out, int dim,
                                    int32_t num_nodes, double *coords)
{
    return create(out, dim, num_nodes, coords, coords);
}

void getme_mesh_free(getme_mesh *mesh)
{
    if (!mesh)
        return;
    for (int b = 0; b < mesh->num_blocks; b++) {
        free(mesh->blocks[b].conn);
        free(mesh->blocks[b].region);
    }
    free(mesh->blocks);
    getme__ho_mesh_free(mesh->ho);
    getme__mesh_drop_ws(mesh);
    free(mesh->coords);
    free(mesh->fixed);
    free(mesh);
}

/* Shared with highorder.c (internal.h): one rule for every element kind. */
int getme__element_nodes_ok(const int32_t *c, int nv, int32_t num_nodes)
{
    for (int i = 0; i < nv; i++) {
        if (c[i] < 0 || c[i] >= num_nodes)
            return 0;
        for (int j = 0; j < i; j++)
            if (c[j] == c[i])
                return 0;
    }
    return 1;
}

/* getme_mesh_add_elements, and with take (conn itself, writable) set
   getme_mesh_take_elements: the block then keeps take instead of a copy
   of conn (the caller's array is freed on failure, by the public
   function). */
static getme_status add_elements(getme_mesh *mesh, getme_elem_type type,
                                 int32_t count, const int32_t *conn,
                                 const int32_t *region, int32_t *take)
{
    if (!mesh)
        return GETME_ERR_ARGUMENT;
    if ((int)type < 0 || type >= GETME_NUM_TYPES)
        return getme__fail(mesh, GETME_ERR_ARGUMENT,
                           "unknown element type %d", (int)type);
    if (getme_type_dim(type) != mesh->dim)
        return getme__fail(mesh, GETME_ERR_ARGUMENT,
                           "%s elements in a %d-D mesh", getme_type_name(type),
                           mesh->dim);
    if (count < 0 || (count > 0 && !conn))
        return getme__fail(mesh, GETME_ERR_ARGUMENT, "bad element count");
    if (count == 0)
        return GETME_OK;
    if (count > INT32_MAX - mesh->num_elements)
        return getme__fail(mesh, GETME_ERR_ARGUMENT,
                           "more than 2^31-1 elements");
    int nv = getme__nv[type];
    /* the first bad element: the least of the threads' first ones, the
       same for any thread count */
    int32_t bad = count;
#pragma omp parallel for schedule(static) reduction(min : bad) \
    if (count >= 16384)
    for (int32_t e = 0; e < count; e++)
        if (e < bad && !getme__element_nodes_ok(conn + (size_t)e * nv, nv,
                                                mesh->num_nodes))
            bad = e;
    if (bad < count)
        return getme__fail(mesh, GETME_ERR_TOPOLOGY,
                           "element %d (%s %d of this block): node index "
                           "out of range or repeated",
                           (int)(mesh->num_elements + bad),
                           getme_type_name(type), (int)bad);
    if (mesh->num_blocks == mesh->cap_blocks) {
        int cap = mesh->cap_blocks ? 2 * mesh->cap_blocks : 4;
        getme_block *nb =
            getme__realloc(mesh->blocks, (size_t)cap * sizeof *nb);
        if (!nb)
            return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
        mesh->blocks = nb;
        mesh->cap_blocks = cap;
    }
    getme__mesh_drop_ws(mesh);
    getme_block *b = &mesh->blocks[mesh->num_blocks];
    memset(b, 0, sizeof *b);
    b->type = type;
    b->first = mesh->num_elements;
    b->count = count;
    b->conn = take ? take
                   : getme__malloc((size_t)count * nv * sizeof(int32_t));
    int32_t same = 1; /* one region for the whole block: no array */
    for (int32_t e = 1; region && same && e < count; e++)
        same = region[e] == region[0];
    if (region && same) {
        b->region_all = count ? region[0] : 0;
        region = NULL;
    }
    if (region)
        b->region = getme__malloc((size_t)count * sizeof(int32_t));
    if (!b->conn || (region && !b->region)) {
        if (!take) /* a taken conn is the caller's to free on failure */
            free(b->conn);
        free(b->region);
        return getme__fail(mesh, GETME_ERR_NOMEM, "out of memory");
    }
    if (!take)
        memcpy(b->conn, conn, (size_t)count * nv * sizeof(int32_t));
    if (region)
        memcpy(b->region, region, (size_t)count * sizeof(int32_t));
    mesh->num_blocks++;
    mesh->num_elements += count;
    mesh->mirror = -1; /* orientation of planar meshes: decide again */
    return GETME_OK;
}

getme_status getme_mesh_add_elements(getme_mesh *mesh, getme_elem_type type,
                                     int32_t count, const int32_t *conn,
                                     const int32_t *region)
{
    return add_elements(mesh, type, count, conn, region, NULL);
}

getme_status getme_mesh_take_elements(getme_mesh *mesh, getme_elem_type type,
                                      int32_t count, int32_t *conn,
                                      const int32_t *region)
{
    getme_status st = add_elements(mesh, type, count, conn, region, conn);
    /* count 0 adds no block: nothing keeps conn either */
    if (st != GETME_OK || count == 0)
        free(conn);
    return st;
}

int getme_mesh_dim(const getme_mesh *mesh) { return mesh ? mesh->dim : 0; }

int32_t getme_mesh_num_nodes(const getme_mesh *mesh)
{
    return mesh ? mesh->num_nodes : 0;
}

int32_t getme_mesh_num_elements(const getme_mesh *mesh)
{
    return mesh ? mesh->num_elements : 0;
}

int32_t getme_mesh_num_elements_of_type(const getme_mesh *mesh,
                                        getme_elem_type type)
{
    int32_t n = 0;
    if (!mesh)
        return 0;
    for (int b = 0; b < mesh->num_blocks; b++)
        if (mesh->blocks[b].type == (int)type)
            n += mesh->blocks[b].count;
    return n;
}

int getme_mesh_get_element(const getme_mesh *mesh, int32_t e,
                           getme_elem_type *type, int32_t *nodes)
{
    if (!mesh || !type || !nodes || e < 0 || e >= mesh->num_elements)
        return 0;
    int32_t local;
    const getme_block *b = getme__find_block(mesh, e, &local);
    int nv = getme__nv[b->type];
    memcpy(nodes, b->conn + (size_t)local * nv, (size_t)nv * sizeof *nodes);
    *type = (getme_elem_type)b->type;
    return nv;
}

void getme_mesh_lend_coords(getme_mesh *mesh, int on)
{
    if (mesh)
        mesh->lend_coords = on != 0;
}

const double *getme_mesh_coords(const getme_mesh *mesh)
{
    return mesh ? mesh->coords : NULL;
}

getme_status getme_mesh_get_coords(const getme_mesh *mesh, double *coords)
{
    if (!mesh || (!coords && mesh->num_nodes))
        return GETME_ERR_ARGUMENT;
    memcpy(coords, mesh->coords, (size_t)mesh->num_nodes * 3 * sizeof(double));
    return GETME_OK;
}

getme_status getme_mesh_set_coords(getme_mesh *mesh, const double *coords)
{
    if (!mesh || (!coords && mesh->num_nodes))
        return GETME_ERR_ARGUMENT;
    for (size_t i = 0; i < (size_t)mesh->num_nodes * 3; i++)
        if (!isfinite(coords[i]))
            return getme__fail(mesh, GETME_ERR_ARGUMENT,
                               "node %zu: non-finite coordinate", i / 3);
    memcpy(mesh->coords, coords, (size_t)mesh->num_nodes * 3 * sizeof(double));
    mesh->mirror = -1;
    getme__mesh_drop_ws(mesh);
    return GETME_OK;
}

getme_status getme_mesh_set_fixed_mask(getme_mesh *mesh, const uint8_t *fixed)
{
    if (!mesh || (!fixed && mesh->num_nodes))
        return GETME_ERR_ARGUMENT;
    for (int32_t i = 0; i < mesh->num_nodes; i++)
        if (fixed[i])
            mesh->fixed[i] |= GETME__FIXED_USER;
    return GETME_OK;
}

getme_status getme_mesh_fix_nodes(getme_mesh *mesh, int32_t count,
                                  const int32_t *nodes)
{
    if (!mesh || count < 0 || (count && !nodes))
        return GETME_ERR_ARGUMENT;
    for (int32_t k = 0; k < count; k++)
        if (nodes[k] < 0 || nodes[k] >= mesh->num_nodes)
            return getme__fail(mesh, GETME_ERR_ARGUMENT,
                               "fixed node index %d out of range (%d nodes)",
                               (int)nodes[k], (int)mesh->num_nodes);
    for (int32_t k = 0; k < count; k++)
        mesh->fixed[nodes[k]] |= GETME__FIXED_USER;
    return GETME_OK;
}

void getme_mesh_clear_fixed(getme_mesh *mesh)
{
    if (mesh)
        memset(mesh->fixed, 0, (size_t)mesh->num_nodes);
}

getme_status getme_mesh_get_fixed_mask(const getme_mesh *mesh, uint8_t *fixed)
{
    if (!mesh || (!fixed && mesh->num_nodes))
        return GETME_ERR_ARGUMENT;
    for (int32_t i = 0; i < mesh->num_nodes; i++)
        fixed[i] = mesh->fixed[i] != 0;
    return GETME_OK;
}

int32_t getme_mesh_num_fixed(const getme_mesh *mesh)
{
    int32_t n = 0;
    if (!mesh)
        return 0;
    for (int32_t i = 0; i < mesh->num_nodes; i++)
        n += mesh->fixed[i] != 0;
    return n;
}

const getme_block *getme__find_block(const getme_mesh *mesh, int32_t e,
                                     int32_t *local)
{
    /* Few blocks (one per add call): binary search on their first index. */
    int lo = 0, hi = mesh->num_blocks - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (mesh->blocks[mid].first <= e)
            lo = mid;
        else
            hi = mid - 1;
    }
    *local = e - mesh->blocks[lo].first;
    return &mesh->blocks[lo];
}

void getme__detect_orientation(getme_mesh *mesh)
{
    /* A planar mesh whose elements are all clockwise (a Gmsh surface with a
       -z normal, say) is smoothed as its mirror image: negate y.  Decide by
       the signed area sum, which is dominated by the majority. */
    mesh->mirror = 0;
    if (mesh->dim != 2)
        return;
    double area = 0.0;
    for (int b = 0; b < mesh->num_blocks; b++) {
        const getme_block *bl = &mesh->blocks[b];
        int nv = getme__nv[bl->type];
        for (int32_t e = 0; e < bl->count; e++) {
            const int32_t *c = bl->conn + (size_t)e * nv;
            for (int i = 0; i < nv; i++) {
                const double *p = mesh->coords + 3 * (size_t)c[i];
                const double *q = mesh->coords + 3 * (size_t)c[(i + 1) % nv];
                area += p[0] * q[1] - q[0] * p[1];
            }
        }
    }
    mesh->mirror = area < 0.0;
}

int getme__gather(const getme_mesh *mesh, int32_t e, double *x)
{
    int32_t local;
    const getme_block *b = getme__find_block(mesh, e, &local);
    int nv = getme__nv[b->type];
    const int32_t *c = b->conn + (size_t)local * nv;
    for (int i = 0; i < nv; i++) {
        const double *p = mesh->coords + 3 * (size_t)c[i];
        x[3 * i] = p[0];
        x[3 * i + 1] = mesh->mirror == 1 ? -p[1] : p[1];
        x[3 * i + 2] = p[2];
    }
    return b->type;
}
