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
/* The neighbour lists from each part node's other holders (optr: nn + 1
   offsets into orank, ranks ascending): per rank the shared nodes in the
   part's node order, which both sides must agree on (ascending global
   index or tag).  0 or -1 (out of memory). */
int dist_neighbours(dist_ctx *c, int32_t nn, const int64_t *optr,
                    const int *orank);

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

/* a2a.c: one MPI_Alltoallv of int64 records (counts exchanged first);
   *recv and *rcount (per source rank) are malloc'd.  0, or -1 on every
   rank if any could not allocate. */
int dist_a2a(dist_ctx *c, const int64_t *send, const int *scount,
             int64_t **recv, int **rcount);

/* split.c: Gmsh-partitioned input read per rank (docs/distributed.md §3). */
enum { DIST_SPLIT_NONE, DIST_SPLIT_FILES, DIST_SPLIT_ONE };
enum { DIST_PATH = 4096 };

typedef struct dist_node { /* a node of a part: tag, position, fixed */
    uint64_t tag;
    double x[3];
    int64_t fixed;
} dist_node;

typedef struct dist_elem { /* an element of a part, nodes by tag */
    int64_t tag;
    int type, nv;
    int32_t region;
    uint64_t node[8];
} dist_elem;

typedef struct dist_split {
    int mode;              /* DIST_SPLIT_*                                  */
    int nparts;            /* N: files NAME_1..N.msh, or partitions          */
    char input[DIST_PATH]; /* as named (NAME_1.msh, or the one file)        */
    char stem[DIST_PATH];  /* NAME                                          */
    int first, count;      /* this rank's parts: first .. first+count-1     */
    getme_doc **docs;      /* count, open while read (then closed: opened
                              again to be written)                         */
    getme_doc_options opts; /* how they were read                          */
    int32_t nn, ne, own_ne;
    dist_node *node;       /* the part's nodes, ascending tag               */
    dist_elem *elem;       /* own elements, then the ghost layer            */
    int64_t *optr;         /* nn + 1: other ranks holding each node ...     */
    int *orank;            /* ... ascending                                 */
    /* element order keys of the whole mesh (dist_split_setup): its box
       (min xyz, max xyz, allreduced) for Morton keys, and whether element
       tags are one dense run, so that an element's index in the
       single-process order is tag - tag_min without a global sort */
    double box[6];
    int64_t tag_min;
    int dense_tags;
    /* rank 0, one partitioned file: the tags of the gathered positions
       (dist_split_gather), ascending */
    int32_t whole_nn;
    uint64_t *whole_tag;
} dist_split;

/* Rank 0: NAME_1.msh with $PartitionedEntities and NAME_2.msh .. beside
   it (split files), or a file with $PartitionedEntities; the mode. */
int dist_split_detect(dist_split *s, const char *input);
/* Input part k's path (1-based). */
void dist_split_path(const dist_split *s, int k, char *buf, size_t size);
/* Rank's contiguous range of the N parts (P <= N). */
void dist_split_range(dist_split *s, int rank, int size);
/* Rank 0 before reading: the output parts may be written and none is an
   input part; note gets a line about stale parts of an earlier run. */
int dist_split_check_output(const dist_split *s, const char *output,
                            char *msg, size_t size, char *note,
                            size_t note_size);
/* Read this rank's parts (not collective): 0, or -1 with msg and the exit
   code getme smooth gives for that error. */
int dist_split_read(dist_split *s, const getme_doc_options *opts, char *msg,
                    size_t size, int *code);
/* Collective: skin, interfaces, fixed marks, ghost layer, neighbours:
   the part into c. */
int dist_split_setup(dist_split *s, dist_ctx *c, unsigned fix_flags);
/* split_finish.c.  Collective: node ids (tags) and element indices in the
   single-process order (c->gid, c->egid) for finish_sub.c's keys; frees
   the set-up's tables.  0, or -1 on every rank with msg. */
int dist_split_ids(dist_split *s, dist_ctx *c, char *msg, size_t size);
/* Collective: the whole mesh's getme_mesh_quality_stats on rank 0,
   reduced over the parts' owned elements.  0, or -1 on every rank. */
int dist_split_stats(dist_ctx *c, getme_mesh *part,
                     getme_quality_stats *out);
/* Collective: getme smooth's "Measures" lines on rank 0, reduced over the
   parts: ranges and minima (exact); not the means (element-order double
   sums). */
struct cli_log;
void dist_split_measures(dist_ctx *c, getme_mesh *part,
                         const struct cli_log *log, const char *title);
/* Collective, one partitioned file: the counted nodes' positions on rank
   0 (*xyz, by s->whole_tag ascending; NULL elsewhere). */
void dist_split_gather(dist_split *s, dist_ctx *c, const double *part_xyz,
                       double **xyz);
int32_t whole_index(const dist_split *s, uint64_t tag);
/* Collective: write the output parts (temporary files, agreement,
   renames).  0, or -1 with rank 0's message. */
int dist_split_write(dist_split *s, dist_ctx *c, const char *output,
                     const double *xyz, char *msg, size_t size);
/* The lowest failing rank's message on rank 0; every rank learns whether
   any failed (the failing rank, or -1). */
int dist_agree(dist_ctx *c, int failed, const char *msg, char *out,
               size_t size);
void dist_split_free(dist_split *s);

/* split_common.c: shared by the split*.c files */
void dist_stop(const char *why);      /* MPI_Abort with one error line */
void *dist_xalloc(size_t n);          /* malloc or dist_stop           */
int32_t dist_find_node(const dist_split *s, uint64_t tag); /* -1: none */
int dist_merge_nodes(dist_split *s, char *msg, size_t size);
int dist_cmp_node(const void *a, const void *b); /* qsort by tag */

#endif /* GETME_DIST_H */
