/*
 * dist.h -- getme-mpi, the distributed driver (docs/distributed.md):
 * shared pieces of its files.
 */
#ifndef GETME_DIST_H
#define GETME_DIST_H

#include "getme.h"
#include "getme_formats.h"

#include <mpi.h>
#include <stdint.h>

/* One process's part and its communication state (the getme_comm ctx). */
typedef struct dist_ctx {
    MPI_Comm comm;
    int rank, size;
    /* the part: nodes and elements in ascending global id */
    int32_t nn, ne;
    double *coords;     /* 3 nn                                             */
    uint8_t *fixed;     /* nn                                               */
    int32_t *gid;       /* nn: global node index                            */
    uint8_t *etype;     /* ne                                               */
    int32_t *egid;      /* ne: global element index (finish_sub.c's keys)   */
    int64_t nconn;
    int32_t *conn;      /* part node indices, element after element          */
    uint8_t *owned;     /* ne                                               */
    uint8_t *counted;   /* nn                                               */
    /* neighbours: ranks sharing nodes, and the shared nodes per neighbour
       (ascending global id; part indices, then library indices) */
    int num_nb;
    int *nb_rank;
    int32_t *nb_count;
    int64_t *nb_ptr;    /* num_nb + 1                                       */
    int32_t *nb_node;
    /* exchange buffers and statistics */
    int64_t buf_cap;
    char *sendbuf, *recvbuf;
    MPI_Request *req;
    MPI_Datatype t128;
    MPI_Op op128;
    int64_t bytes_sent, bytes_reduced;
    double comm_seconds;
    /* rank 0: the partition's interface nodes (held by several ranks) and
       ghost elements (copies, summed over ranks) */
    int64_t interface_nodes, ghost_elements;
    int exit_code;      /* rank 0's exit code when it gave up (dist_go)    */
    /* rank 0: the finishing step's sub-mesh (finish_sub.c): elements and
       node copies gathered in the last try, tries */
    int64_t sub_elements, sub_nodes;
    int sub_tries;
} dist_ctx;

/* finish_sub.c: after getme_smooth_part on every rank (collective), the
   finishing step on rank 0 on the patches of the worst elements only
   (getme_smooth_finish_sub); every copy of a moved node gets its final
   position in part.  whole: rank 0's mesh at its input coordinates (NULL
   elsewhere; its bounding box keys the elements).  res: rank 0's result,
   updated there.  0, or -1 on every rank with the message in err. */
int dist_finish(dist_ctx *c, getme_mesh *part, const getme_mesh *whole,
                const getme_params *params, getme_result *res, char *err,
                size_t err_size);

/* comm.c */
int dist_comm_init(dist_ctx *c);
void dist_comm_free(dist_ctx *c);
void dist_comm_hooks(dist_ctx *c, getme_comm *hooks);

/* partition.c: on rank 0, split mesh into size parts (METIS, fixed seed)
   and send each rank its part; every rank receives its own into c.
   Rank 0 first broadcasts whether it can go on (one MPI_Bcast of an int
   on every rank: dist_go, 0 = go, else the exit code); if it failed to
   read the input it calls dist_go(c, code) instead.  dist_partition_send returns 0, or -1 with the
   message in err; dist_partition_recv returns 0, -1 on failure, -2 if
   rank 0 gave up (it reports why). */
int dist_go(dist_ctx *c, int code);
int dist_partition_send(getme_mesh *mesh, dist_ctx *c, char *err,
                        size_t err_size);
int dist_partition_recv(dist_ctx *c);
void dist_part_free(dist_ctx *c);

#endif /* GETME_DIST_H */
