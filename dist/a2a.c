/*
 * a2a.c -- the collective steps the driver's set-up is made of: one
 * personalised all-to-all exchange of int64 records (MPI_Alltoallv with
 * the counts exchanged first), every round of split_setup.c; and the
 * agreement on a failure (which rank, its message on rank 0).
 */
#include "dist.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int dist_a2a(dist_ctx *c, const int64_t *send, const int *scount,
             int64_t **recv, int **rcount)
{
    int p = c->size, ok = 1;
    int *sdisp = malloc((size_t)p * sizeof *sdisp);
    int *rdisp = malloc((size_t)p * sizeof *rdisp);
    *rcount = malloc((size_t)p * sizeof **rcount);
    *recv = NULL;
    if (!sdisp || !rdisp || !*rcount)
        ok = 0;
    /* every rank takes part in every call, even after a local failure,
       so that no rank waits for one that gave up */
    int all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_LAND, c->comm);
    if (!all) {
        free(sdisp), free(rdisp), free(*rcount);
        *rcount = NULL;
        return -1;
    }
    MPI_Alltoall(scount, 1, MPI_INT, *rcount, 1, MPI_INT, c->comm);
    int64_t stotal = 0, rtotal = 0;
    for (int q = 0; ok && q < p; q++) {
        sdisp[q] = (int)stotal;
        rdisp[q] = (int)rtotal;
        stotal += scount[q];
        rtotal += (*rcount)[q];
    }
    if (ok && (stotal > INT32_MAX || rtotal > INT32_MAX))
        ok = 0;
    if (ok && !(*recv = malloc((size_t)(rtotal ? rtotal : 1) * sizeof **recv)))
        ok = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_LAND, c->comm);
    if (all)
        MPI_Alltoallv(send, scount, sdisp, MPI_INT64_T, *recv, *rcount, rdisp,
                      MPI_INT64_T, c->comm);
    free(sdisp);
    free(rdisp);
    if (!all) {
        free(*recv), free(*rcount);
        *recv = NULL, *rcount = NULL;
        return -1;
    }
    c->bytes_sent += 8 * stotal;
    return 0;
}

/* The lowest failing rank's message on rank 0; every rank learns whether
   any failed (the failing rank, or -1). */
int dist_agree(dist_ctx *c, int failed, const char *msg, char *out,
               size_t size)
{
    int mine = failed ? c->rank : c->size, first = c->size;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, c->comm);
    if (first == c->size)
        return -1;
    if (first != 0) {
        if (c->rank == first)
            MPI_Send(msg, (int)strlen(msg) + 1, MPI_CHAR, 0, 99, c->comm);
        if (c->rank == 0)
            MPI_Recv(out, (int)size, MPI_CHAR, first, 99, c->comm,
                     MPI_STATUS_IGNORE);
    } else if (c->rank == 0) {
        snprintf(out, size, "%s", msg);
    }
    return first;
}

