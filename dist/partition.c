/*
 * partition.c -- rank 0 splits the mesh it read and sends every rank its
 * part: the elements METIS gives it (owned) plus one ghost layer, every
 * element sharing a node with an owned one, so that the Eq. 9
 * neighbourhood of every owned element is complete on its rank.
 *
 * METIS_PartMeshDual with a fixed seed and options is deterministic, so a
 * run is reproducible; the result does not depend on the partition anyway
 * (exact sums, docs/distributed.md).  Parts keep nodes and elements in
 * ascending global index.  A node is "counted" by the lowest rank holding
 * it (each node once in reported counts and in the final gather).
 */
#include "dist.h"

#include <metis.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { TAG_HEAD = 11, TAG_DATA };

/* What rank 0 knows about one part while building it. */
typedef struct part {
    int32_t nn, ne;
    int32_t *nodes, *elems; /* global indices, ascending */
} part;

static void *xmalloc(size_t n) { return malloc(n ? n : 1); }

/* The part's arrays into c (rank 0's own part, or before sending). */
static int fill_part(dist_ctx *c, const part *p, const getme_mesh *mesh,
                     const int32_t *epart, const uint8_t *gfixed,
                     const int32_t *eptr, const int32_t *eind,
                     const uint8_t *etype, const int32_t *glocal,
                     const int32_t *hptr, const int *hrank, int r)
{
    const double *x = getme_mesh_coords(mesh);
    c->nn = p->nn;
    c->ne = p->ne;
    c->coords = xmalloc((size_t)p->nn * 3 * sizeof *c->coords);
    c->fixed = xmalloc((size_t)p->nn);
    c->gid = xmalloc((size_t)p->nn * sizeof *c->gid);
    c->counted = xmalloc((size_t)p->nn);
    c->etype = xmalloc((size_t)p->ne);
    c->egid = xmalloc((size_t)p->ne * sizeof *c->egid);
    c->owned = xmalloc((size_t)p->ne);
    c->nconn = 0;
    for (int32_t k = 0; k < p->ne; k++)
        c->nconn += eptr[p->elems[k] + 1] - eptr[p->elems[k]];
    c->conn = xmalloc((size_t)c->nconn * sizeof *c->conn);
    if (!c->coords || !c->fixed || !c->gid || !c->counted || !c->etype ||
        !c->egid || !c->owned || !c->conn)
        return -1;
    for (int32_t k = 0; k < p->nn; k++) {
        int32_t g = p->nodes[k];
        memcpy(c->coords + 3 * (size_t)k, x + 3 * (size_t)g, 3 * sizeof *x);
        c->fixed[k] = gfixed[g];
        c->gid[k] = g;
        c->counted[k] = hrank[hptr[g]] == r;
    }
    int64_t m = 0;
    for (int32_t k = 0; k < p->ne; k++) {
        int32_t e = p->elems[k];
        c->etype[k] = etype[e];
        c->egid[k] = e;
        c->owned[k] = epart[e] == r;
        for (int32_t j = eptr[e]; j < eptr[e + 1]; j++)
            c->conn[m++] = glocal[eind[j]];
    }
    /* neighbours: for each node, the other ranks holding it */
    int64_t *optr = xmalloc(((size_t)p->nn + 1) * sizeof *optr);
    int *orank = NULL;
    if (!optr)
        return -1;
    optr[0] = 0;
    for (int32_t k = 0; k < p->nn; k++)
        optr[k + 1] = optr[k] + hptr[p->nodes[k] + 1] - hptr[p->nodes[k]] - 1;
    if (!(orank = xmalloc((size_t)optr[p->nn] * sizeof *orank))) {
        free(optr);
        return -1;
    }
    for (int32_t k = 0, m = 0; k < p->nn; k++)
        for (int32_t h = hptr[p->nodes[k]]; h < hptr[p->nodes[k] + 1]; h++)
            if (hrank[h] != r)
                orank[m++] = hrank[h];
    int rc = dist_neighbours(c, p->nn, optr, orank);
    free(optr), free(orank);
    return rc;
}

/* Send c's part to rank r (then free it). */
static int send_part(dist_ctx *c, int r)
{
    int64_t head[5] = {c->nn, c->ne, c->nconn, c->num_nb, 0};
    MPI_Comm w = c->comm;
    int rc = MPI_Send(head, 5, MPI_INT64_T, r, TAG_HEAD, w);
    rc |= MPI_Send(c->coords, 3 * c->nn, MPI_DOUBLE, r, TAG_DATA, w);
    rc |= MPI_Send(c->fixed, c->nn, MPI_UINT8_T, r, TAG_DATA, w);
    rc |= MPI_Send(c->gid, c->nn, MPI_INT32_T, r, TAG_DATA, w);
    rc |= MPI_Send(c->counted, c->nn, MPI_UINT8_T, r, TAG_DATA, w);
    rc |= MPI_Send(c->etype, c->ne, MPI_UINT8_T, r, TAG_DATA, w);
    rc |= MPI_Send(c->egid, c->ne, MPI_INT32_T, r, TAG_DATA, w);
    rc |= MPI_Send(c->owned, c->ne, MPI_UINT8_T, r, TAG_DATA, w);
    rc |= MPI_Send(c->conn, (int)c->nconn, MPI_INT32_T, r, TAG_DATA, w);
    rc |= MPI_Send(c->nb_rank, c->num_nb, MPI_INT, r, TAG_DATA, w);
    rc |= MPI_Send(c->nb_count, c->num_nb, MPI_INT32_T, r, TAG_DATA, w);
    rc |= MPI_Send(c->nb_node, (int)c->nb_ptr[c->num_nb], MPI_INT32_T, r,
                   TAG_DATA, w);
    dist_part_free(c);
    return rc == MPI_SUCCESS ? 0 : -1;
}

int dist_go(dist_ctx *c, int code)
{
    MPI_Bcast(&code, 1, MPI_INT, 0, c->comm);
    return code;
}

int dist_partition_recv(dist_ctx *c)
{
    int code = dist_go(c, 0);
    if (code != 0) {
        c->exit_code = code;
        return -2;
    }
    int64_t head[5];
    MPI_Comm w = c->comm;
    if (MPI_Recv(head, 5, MPI_INT64_T, 0, TAG_HEAD, w, MPI_STATUS_IGNORE))
        return -1;
    c->nn = (int32_t)head[0], c->ne = (int32_t)head[1];
    c->nconn = head[2], c->num_nb = (int)head[3];
    c->coords = xmalloc((size_t)c->nn * 3 * sizeof *c->coords);
    c->fixed = xmalloc((size_t)c->nn);
    c->gid = xmalloc((size_t)c->nn * sizeof *c->gid);
    c->counted = xmalloc((size_t)c->nn);
    c->etype = xmalloc((size_t)c->ne);
    c->egid = xmalloc((size_t)c->ne * sizeof *c->egid);
    c->owned = xmalloc((size_t)c->ne);
    c->conn = xmalloc((size_t)c->nconn * sizeof *c->conn);
    c->nb_rank = xmalloc((size_t)c->num_nb * sizeof *c->nb_rank);
    c->nb_count = xmalloc((size_t)c->num_nb * sizeof *c->nb_count);
    c->nb_ptr = xmalloc(((size_t)c->num_nb + 1) * sizeof *c->nb_ptr);
    /* receive everything even if an allocation failed, so rank 0 is not
       left waiting; a NULL buffer fails the receive and the run */
    int rc = MPI_Recv(c->coords, 3 * c->nn, MPI_DOUBLE, 0, TAG_DATA, w,
                      MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->fixed, c->nn, MPI_UINT8_T, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->gid, c->nn, MPI_INT32_T, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->counted, c->nn, MPI_UINT8_T, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->etype, c->ne, MPI_UINT8_T, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->egid, c->ne, MPI_INT32_T, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->owned, c->ne, MPI_UINT8_T, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->conn, (int)c->nconn, MPI_INT32_T, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->nb_rank, c->num_nb, MPI_INT, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    rc |= MPI_Recv(c->nb_count, c->num_nb, MPI_INT32_T, 0, TAG_DATA, w,
                   MPI_STATUS_IGNORE);
    if (rc != MPI_SUCCESS || !c->nb_ptr)
        return -1;
    c->nb_ptr[0] = 0;
    for (int k = 0; k < c->num_nb; k++)
        c->nb_ptr[k + 1] = c->nb_ptr[k] + c->nb_count[k];
    c->nb_node = xmalloc((size_t)c->nb_ptr[c->num_nb] * sizeof *c->nb_node);
    rc = MPI_Recv(c->nb_node, (int)c->nb_ptr[c->num_nb], MPI_INT32_T, 0,
                  TAG_DATA, w, MPI_STATUS_IGNORE);
    return rc == MPI_SUCCESS && c->coords && c->fixed && c->gid &&
                   c->counted && c->etype && c->egid && c->owned && c->conn &&
                   c->nb_rank && c->nb_count && c->nb_node
               ? 0
               : -1;
}

void dist_part_free(dist_ctx *c)
{
    free(c->coords), free(c->fixed), free(c->gid), free(c->counted);
    free(c->etype), free(c->egid), free(c->owned), free(c->conn);
    free(c->nb_rank), free(c->nb_count), free(c->nb_ptr), free(c->nb_node);
    c->coords = NULL, c->fixed = NULL, c->gid = NULL, c->counted = NULL;
    c->etype = NULL, c->egid = NULL, c->owned = NULL, c->conn = NULL;
    c->nb_rank = NULL, c->nb_count = NULL, c->nb_ptr = NULL, c->nb_node = NULL;
}

/* METIS's element partition (all 0 for one part). */
static int metis_split(int32_t ne, int32_t nn, int32_t *eptr, int32_t *eind,
                       int nparts, int32_t *epart, char *err, size_t es)
{
    if (nparts == 1) {
        memset(epart, 0, (size_t)ne * sizeof *epart);
        return 0;
    }
    idx_t opt[METIS_NOPTIONS];
    METIS_SetDefaultOptions(opt);
    opt[METIS_OPTION_SEED] = 1;
    opt[METIS_OPTION_NUMBERING] = 0;
    idx_t n_e = ne, n_n = nn, common = 3, np = nparts, cut = 0;
    idx_t *npart = xmalloc((size_t)nn * sizeof *npart);
    if (!npart) {
        snprintf(err, es, "out of memory partitioning");
        return -1;
    }
    int rc = METIS_PartMeshDual(&n_e, &n_n, eptr, eind, NULL, NULL, &common,
                                &np, NULL, opt, &cut, epart, npart);
    free(npart);
    if (rc != METIS_OK) {
        snprintf(err, es, "METIS could not split the mesh into %d parts "
                          "(status %d)", nparts, rc);
        return -1;
    }
    return 0;
}

int dist_partition_send(getme_mesh *mesh, dist_ctx *c, char *err,
                        size_t es)
{
    int32_t ne = getme_mesh_num_elements(mesh), nn = getme_mesh_num_nodes(mesh);
    int np = c->size, ret = -1, went = 0;
    int32_t *eptr = xmalloc(((size_t)ne + 1) * sizeof *eptr);
    int32_t *eind = xmalloc((size_t)ne * 8 * sizeof *eind);
    uint8_t *etype = xmalloc((size_t)ne), *gfixed = xmalloc((size_t)nn);
    int32_t *epart = xmalloc((size_t)ne * sizeof *epart);
    int32_t *nptr = calloc((size_t)nn + 1, sizeof *nptr), *nel = NULL;
    int32_t *emark = xmalloc((size_t)ne * sizeof *emark);
    int32_t *nmark = xmalloc((size_t)nn * sizeof *nmark);
    int32_t *glocal = xmalloc((size_t)nn * sizeof *glocal);
    int32_t *hptr = calloc((size_t)nn + 1, sizeof *hptr);
    int *hrank = NULL;
    part *parts = calloc((size_t)np, sizeof *parts);
    snprintf(err, es, "out of memory partitioning");
    if (!eptr || !eind || !etype || !gfixed || !epart || !nptr || !emark ||
        !nmark || !glocal || !hptr || !parts)
        goto out;
    eptr[0] = 0;
    for (int32_t e = 0; e < ne; e++) {
        getme_elem_type t;
        int nv = getme_mesh_get_element(mesh, e, &t, eind + eptr[e]);
        etype[e] = (uint8_t)t;
        eptr[e + 1] = eptr[e] + nv;
        for (int i = 0; i < nv; i++)
            nptr[eind[eptr[e] + i] + 1]++;
    }
    getme_mesh_get_fixed_mask(mesh, gfixed);
    if (metis_split(ne, nn, eptr, eind, np, epart, err, es) != 0)
        goto out;
    snprintf(err, es, "out of memory partitioning");
    for (int32_t i = 0; i < nn; i++)
        nptr[i + 1] += nptr[i];
    if (!(nel = xmalloc((size_t)nptr[nn] * sizeof *nel)))
        goto out;
    for (int32_t e = 0; e < ne; e++) /* node -> elements, ascending */
        for (int32_t j = eptr[e]; j < eptr[e + 1]; j++)
            nel[nptr[eind[j]]++] = e;
    for (int32_t i = nn; i > 0; i--)
        nptr[i] = nptr[i - 1];
    nptr[0] = 0;

    /* Each part's elements (owned + ghost layer) and nodes. */
    for (int32_t e = 0; e < ne; e++)
        emark[e] = -1;
    for (int32_t i = 0; i < nn; i++)
        nmark[i] = -1;
    for (int r = 0; r < np; r++) {
        for (int32_t e = 0; e < ne; e++) /* nodes of owned elements */
            if (epart[e] == r)
                for (int32_t j = eptr[e]; j < eptr[e + 1]; j++)
                    nmark[eind[j]] = r;
        for (int32_t i = 0; i < nn; i++) /* their stars */
            if (nmark[i] == r)
                for (int32_t j = nptr[i]; j < nptr[i + 1]; j++)
                    emark[nel[j]] = r;
        part *p = &parts[r];
        for (int32_t e = 0; e < ne; e++)
            p->ne += emark[e] == r;
        if (!(p->elems = xmalloc((size_t)p->ne * sizeof *p->elems)))
            goto out;
        p->ne = 0;
        for (int32_t e = 0; e < ne; e++)
            if (emark[e] == r) {
                p->elems[p->ne++] = e;
                for (int32_t j = eptr[e]; j < eptr[e + 1]; j++)
                    nmark[eind[j]] = r;
            }
        for (int32_t i = 0; i < nn; i++)
            p->nn += nmark[i] == r;
        if (!(p->nodes = xmalloc((size_t)p->nn * sizeof *p->nodes)))
            goto out;
        p->nn = 0;
        for (int32_t i = 0; i < nn; i++)
            if (nmark[i] == r) {
                p->nodes[p->nn++] = i;
                hptr[i + 1]++;
            }
    }
    /* holders of every node, ranks ascending */
    for (int32_t i = 0; i < nn; i++)
        hptr[i + 1] += hptr[i];
    if (!(hrank = xmalloc((size_t)hptr[nn] * sizeof *hrank)))
        goto out;
    {
        int32_t *fill = nmark; /* reused as insertion positions */
        for (int32_t i = 0; i < nn; i++)
            fill[i] = hptr[i];
        for (int r = 0; r < np; r++)
            for (int32_t k = 0; k < parts[r].nn; k++)
                hrank[fill[parts[r].nodes[k]]++] = r;
    }
    c->interface_nodes = 0;
    for (int32_t i = 0; i < nn; i++)
        c->interface_nodes += hptr[i + 1] - hptr[i] > 1;
    c->ghost_elements = 0;
    for (int r = 0; r < np; r++) {
        c->ghost_elements += parts[r].ne;
    }
    c->ghost_elements -= ne;
    /* build and send every other part, then keep rank 0's */
    went = 1;
    dist_go(c, 0);
    for (int r = np - 1; r >= 0; r--) {
        for (int32_t k = 0; k < parts[r].nn; k++)
            glocal[parts[r].nodes[k]] = k;
        if (fill_part(c, &parts[r], mesh, epart, gfixed, eptr, eind, etype,
                      glocal, hptr, hrank, r) != 0)
            goto out;
        if (r > 0 && send_part(c, r) != 0) {
            snprintf(err, es, "could not send part %d", r);
            goto out;
        }
    }
    ret = 0;
out:
    if (!went)
        dist_go(c, 1);
    for (int r = 0; parts && r < np; r++)
        free(parts[r].nodes), free(parts[r].elems);
    free(parts), free(eptr), free(eind), free(etype), free(gfixed);
    free(epart), free(nptr), free(nel), free(emark), free(nmark);
    free(glocal), free(hptr), free(hrank);
    return ret;
}
