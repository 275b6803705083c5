/*
 * comm.c -- the getme_comm hooks (getme.h) over MPI: node sums and ORs
 * between the processes that hold copies of a node, global reductions.
 *
 * Node exchanges: every process holds, per neighbour rank, the list of the
 * nodes both hold, in ascending global id (so both sides pack the same
 * nodes in the same order).  A hook sends its own values of those nodes to
 * every neighbour and adds (ORs) what it receives: all copies then hold the
 * same total, because each adds the same set of exact integers.
 */
#include "dist.h"

#include <stdlib.h>
#include <string.h>

__extension__ typedef unsigned __int128 u128;

static void add_i128(void *in, void *inout, int *len, MPI_Datatype *type)
{
    (void)type;
    for (int i = 0; i < *len; i++) {
        u128 a, b;
        memcpy(&a, (char *)in + 16 * (size_t)i, 16);
        memcpy(&b, (char *)inout + 16 * (size_t)i, 16);
        b += a;
        memcpy((char *)inout + 16 * (size_t)i, &b, 16);
    }
}

int dist_comm_init(dist_ctx *c)
{
    if (MPI_Type_contiguous(16, MPI_BYTE, &c->t128) != MPI_SUCCESS ||
        MPI_Type_commit(&c->t128) != MPI_SUCCESS ||
        MPI_Op_create(add_i128, 1, &c->op128) != MPI_SUCCESS)
        return -1;
    int64_t total = 0;
    for (int k = 0; k < c->num_nb; k++)
        total += c->nb_count[k];
    c->buf_cap = total;
    c->sendbuf = malloc((size_t)(total ? total : 1) * 64);
    c->recvbuf = malloc((size_t)(total ? total : 1) * 64);
    c->req = malloc((size_t)(2 * c->num_nb + 1) * sizeof *c->req);
    return c->sendbuf && c->recvbuf && c->req ? 0 : -1;
}

void dist_comm_free(dist_ctx *c)
{
    if (c->op128 != MPI_OP_NULL)
        MPI_Op_free(&c->op128);
    if (c->t128 != MPI_DATATYPE_NULL)
        MPI_Type_free(&c->t128);
    free(c->sendbuf);
    free(c->recvbuf);
    free(c->req);
}

/* The shared-node lists were built in the caller's (part's) numbering;
   the library's order is a permutation of it. */
static int node_order(void *ctx, int32_t nn, const int32_t *caller_index)
{
    dist_ctx *c = ctx;
    int32_t *inv = malloc((size_t)(nn ? nn : 1) * sizeof *inv);
    if (!inv)
        return -1;
    for (int32_t i = 0; i < nn; i++)
        inv[caller_index[i]] = i;
    for (int64_t j = 0; j < c->nb_ptr[c->num_nb]; j++)
        c->nb_node[j] = inv[c->nb_node[j]];
    free(inv);
    return 0;
}

/* Send the packed bytes (size bytes per shared node) to every neighbour
   and receive theirs. */
static int exchange(dist_ctx *c, size_t size)
{
    double t0 = MPI_Wtime();
    int n = 0;
    for (int k = 0; k < c->num_nb; k++) {
        size_t off = (size_t)c->nb_ptr[k] * size;
        int bytes = (int)((size_t)c->nb_count[k] * size);
        if (MPI_Irecv(c->recvbuf + off, bytes, MPI_BYTE, c->nb_rank[k], 7,
                      c->comm, &c->req[n++]) != MPI_SUCCESS ||
            MPI_Isend(c->sendbuf + off, bytes, MPI_BYTE, c->nb_rank[k], 7,
                      c->comm, &c->req[n++]) != MPI_SUCCESS)
            return -1;
        c->bytes_sent += bytes;
    }
    int rc = MPI_Waitall(n, c->req, MPI_STATUSES_IGNORE);
    c->comm_seconds += MPI_Wtime() - t0;
    return rc == MPI_SUCCESS ? 0 : -1;
}

static int node_sum(void *ctx, void *values, int per_node)
{
    dist_ctx *c = ctx;
    size_t size = 16 * (size_t)per_node;
    if (per_node > 4)
        return -1; /* the buffers hold 64 bytes per shared node */
    char *v = values;
    for (int64_t j = 0; j < c->nb_ptr[c->num_nb]; j++)
        memcpy(c->sendbuf + (size_t)j * size,
               v + (size_t)c->nb_node[j] * size, size);
    if (exchange(c, size) != 0)
        return -1;
    for (int64_t j = 0; j < c->nb_ptr[c->num_nb]; j++)
        for (int w = 0; w < per_node; w++) {
            u128 a, b;
            char *dst = v + (size_t)c->nb_node[j] * size + 16 * (size_t)w;
            memcpy(&a, c->recvbuf + (size_t)j * size + 16 * (size_t)w, 16);
            memcpy(&b, dst, 16);
            b += a;
            memcpy(dst, &b, 16);
        }
    return 0;
}

static int node_or(void *ctx, uint8_t *flags)
{
    dist_ctx *c = ctx;
    for (int64_t j = 0; j < c->nb_ptr[c->num_nb]; j++)
        c->sendbuf[j] = (char)(flags[c->nb_node[j]] != 0);
    if (exchange(c, 1) != 0)
        return -1;
    for (int64_t j = 0; j < c->nb_ptr[c->num_nb]; j++) {
        uint8_t *f = &flags[c->nb_node[j]];
        *f = (uint8_t)((*f != 0) | (c->recvbuf[j] != 0));
    }
    return 0;
}

static int timed_allreduce(dist_ctx *c, void *v, int n, MPI_Datatype t,
                           MPI_Op op, size_t size)
{
    double t0 = MPI_Wtime();
    int rc = MPI_Allreduce(MPI_IN_PLACE, v, n, t, op, c->comm);
    c->comm_seconds += MPI_Wtime() - t0;
    c->bytes_reduced += (int64_t)n * (int64_t)size;
    return rc == MPI_SUCCESS ? 0 : -1;
}

static int sum_i64(void *ctx, int64_t *v, int n)
{
    dist_ctx *c = ctx;
    return timed_allreduce(c, v, n, MPI_INT64_T, MPI_SUM, 8);
}

static int sum_i128(void *ctx, void *v, int n)
{
    dist_ctx *c = ctx;
    return timed_allreduce(c, v, n, c->t128, c->op128, 16);
}

static int min_f64(void *ctx, double *v, int n)
{
    dist_ctx *c = ctx;
    return timed_allreduce(c, v, n, MPI_DOUBLE, MPI_MIN, 8);
}

void dist_comm_hooks(dist_ctx *c, getme_comm *h)
{
    memset(h, 0, sizeof *h);
    h->ctx = c;
    h->owned = c->owned;
    h->counted = c->counted;
    h->node_order = node_order;
    h->node_sum = node_sum;
    h->node_or = node_or;
    h->sum_i64 = sum_i64;
    h->sum_i128 = sum_i128;
    h->min = min_f64;
}

int dist_neighbours(dist_ctx *c, int32_t nn, const int64_t *optr,
                    const int *orank)
{
    int *cnt = calloc((size_t)c->size, sizeof *cnt);
    int *slot = malloc((size_t)c->size * sizeof *slot);
    if (!cnt || !slot) {
        free(cnt), free(slot);
        return -1;
    }
    for (int64_t h = 0; h < optr[nn]; h++)
        cnt[orank[h]]++;
    c->num_nb = 0;
    for (int q = 0; q < c->size; q++)
        c->num_nb += cnt[q] > 0;
    size_t nb = (size_t)c->num_nb;
    c->nb_rank = malloc((nb ? nb : 1) * sizeof *c->nb_rank);
    c->nb_count = malloc((nb ? nb : 1) * sizeof *c->nb_count);
    c->nb_ptr = malloc((nb + 1) * sizeof *c->nb_ptr);
    c->nb_node = malloc(((size_t)optr[nn] ? (size_t)optr[nn] : 1) *
                        sizeof *c->nb_node);
    int64_t *pos = malloc((nb + 1) * sizeof *pos);
    int ok = c->nb_rank && c->nb_count && c->nb_ptr && c->nb_node && pos;
    if (ok) {
        c->nb_ptr[0] = 0;
        for (int q = 0, k = 0; q < c->size; q++)
            if (cnt[q] > 0) {
                c->nb_rank[k] = q;
                c->nb_count[k] = cnt[q];
                c->nb_ptr[k + 1] = c->nb_ptr[k] + cnt[q];
                pos[k] = c->nb_ptr[k];
                slot[q] = k++;
            }
        for (int32_t i = 0; i < nn; i++) /* in the caller's node order */
            for (int64_t h = optr[i]; h < optr[i + 1]; h++)
                c->nb_node[pos[slot[orank[h]]]++] = i;
    }
    free(pos), free(cnt), free(slot);
    return ok ? 0 : -1;
}
