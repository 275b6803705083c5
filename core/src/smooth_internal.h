/*
 * smooth_internal.h -- pieces shared by the smoothing methods
 * (getme_adaptive.c, laplace.c) and their driver (smooth.c).
 */
#ifndef GETME_SMOOTH_INTERNAL_H
#define GETME_SMOOTH_INTERNAL_H

#include "exact.h"
#include "stars.h"
#include "workspace.h"

#include <string.h>

/* Byte offset of a node's old coordinates after its p-hat (getme_run). */
#define GETME_XOLD_OFF (3 * (int64_t)sizeof(double))

/* Loops over fewer items than this run on one thread: in the q*_min stage
   the lists are small, and a parallel loop's barrier then costs more than
   the work (libgomp spins at barriers, which is slow on a loaded machine).
   Results do not depend on it: every loop is deterministic. */
#define GETME_PAR_MIN 8192

/* Per-thread dedupe marks for the Eq. 9 neighbour sums (weights.c).  now
   changes once per element walked, so each thread's is padded apart from
   the others' (two threads writing one cache line slow each other down:
   false sharing). */
typedef struct getme_stamp {
    uint32_t *mark; /* ne entries */
    uint32_t now;
    char pad[128 - sizeof(uint32_t *) - sizeof(uint32_t)];
} getme_stamp;

/* Scratch arrays of one smoothing run, allocated once. */
typedef struct getme_run {
    getme_ws *ws;
    const getme_params *params;
    getme_result *result;
    double t0;          /* omp_get_wtime() at start                        */
    double *q;          /* ne: quality at ws->x                            */
    /* The target p-hat of node i: 3 doubles at getme__phat(run, i), and
       during the relaxation (Eq. 10, relax.c), which moves the nodes of
       I_T (in_t) in ws->x itself, their old coordinates at
       getme__xold(run, i); read and written with memcpy.  Laplace owns a
       6 * nn array (p-hat, then the old coordinates: GETME_XOLD_OFF).  In
       GETMe adaptive phat is facc: without a slot map the node's entry
       holds both from ComputeNewNodes to getme__reset_nodes; with one,
       the old coordinates are in xold and the p-hat in the node's slot
       (the q*_min stage) or in ws->x until getme__save_phat (the q_mean
       stage). */
    unsigned char *phat;
    int64_t phat_step;
    /* The nodes of run->nodes are already at R[0] (getme__place_first,
       done by GETMe adaptive's ComputeNewNodes in the same pass);
       getme__relax clears it. */
    int placed;
    /* GETMe adaptive's q_mean stage on one process: the block that adds a
       node's last contribution (the sign bit of its entry in blk->nodes,
       getme_adaptive.c mark_last) computes the node's p-hat and places it
       at R[0] = place_rho itself, while the node's sums and coordinates
       are in its cache, instead of ComputeNewNodes' pass over all nodes;
       in_t = 2 marks a node so placed.  0: ComputeNewNodes does it. */
    int place_early;
    double place_rho;
    uint8_t *in_t;      /* nn: node is in I_T (moves this iteration); 2:
                           placed by its last block (place_early)         */
    uint8_t *flag;      /* nn: scratch flag, all zero between uses          */
    uint8_t *ridx;      /* nn: index into the relaxation table              */
    uint8_t *eflag;     /* ne: scratch flag                                 */
    int32_t *nodes;     /* nn: compacted list of I_T; implicit while
                           nodes_all (getme__run_node)                    */
    int nodes_all;      /* I_T is every free node in use (GETMe adaptive's
                           q_mean stage, one process): run->nodes stays
                           untouched, so not resident, until the q*min
                           stage                                          */
    int32_t *elems;     /* ne: compacted list of elements touching I_T; in
                           GETMe adaptive's q_mean stage (live) every free
                           element, which it then does not hold (relax.c) */
    int32_t num_nodes, num_elems;
    /* GETMe adaptive's q_mean stage: how many of each block's free
       elements the relaxation's first pass found invalid (relax.c), so the
       list of them is made from those blocks alone; num_blocks entries,
       or NULL (a scan over every element instead) */
    int32_t *block_bad;
    /* Curved second-order elements (GETMe adaptive): every dependent
       node's position at the trial coordinates (3 * ws->ho->nh), computed
       once before the relaxation's first pass (getme__ho_table), which
       then checks each element from it instead of placing each of its
       dependent nodes again (each is in about 5 elements).  NULL without
       curved elements; ho_tab_on only during that pass. */
    double *ho_tab;
    int ho_tab_on;
    int32_t *list;      /* nn: scratch node list (relaxation, sum updates)  */
    int32_t first_steps; /* nodes the relaxation stepped down the table
                            for the first time (getme__relax's count)    */
    /* GETMe adaptive only (getme_adaptive.c): */
    struct getme_adj *adj; /* Eq. 9 sums (adjacency.h)                      */
    /* Set (to adj) in the q_mean stage, where run->elems is every free
       element: getme__relax then keeps adj's S_v and S_e equal to the sums
       at run->q as it changes q, in the pass that computes the new
       qualities (relax.c), instead of a sweep of its own. */
    struct getme_adj *live;
    getme_stamp *stamps;/* one per thread, only if adj has irregular ones   */
    int32_t *tlist;     /* q*_min stage: the elements with q <= q_t, sorted */
    int32_t num_t;
    int64_t cap_t;      /* room in tlist                                    */
    uint8_t *tflag;     /* ne: element is in tlist                          */
    double *qold;       /* q*_min stage: qualities of run->elems before the
                           relaxation step (NULL: sums are recomputed)      */
    struct getme_tally *tally; /* q*_min stage: q_mean's exact sum, which
                           update_after keeps (tally.h), or NULL            */
    int64_t cap_qold;
    /* GETMe's node sums in exact fixed point (exact.h, getme_adaptive.c):
       sum w x' (3) and sum w, one entry of four per node, zero between
       iterations.  Without a slot map (distributed runs, a q_mean table
       not starting at 1), node i's entry is i: pool_cap = nn.  With one
       (slot, below) the entries are a pool that only the nodes whose sums
       are open at the same time share out (getme_adaptive.c
       assign_slots): in the q_mean stage a node holds its slot from its
       first block to its last, which places it and zeroes the slot, so
       the pool is ~3 % of the nodes on one thread, ~8 % on two (full
       hexes, tets); in the q*_min stage node nodes[k] holds slot k. */
    getme_fx *facc;     /* 4 * pool_cap                                    */
    int64_t pool_cap;   /* entries in facc                                 */
    int64_t pool_limit; /* the most slots a reorder of the blocks may need
                           (getme_adaptive.c, rebalance): 1/32 more than
                           the first order's, so that it never lifts the
                           q_mean stage's peak of memory by more          */
    int32_t *slot;      /* nn: node i's entry in facc, or NULL (i)         */
    /* With a slot map, the old coordinates during the relaxation
       (getme__xold) are here, 3 per node, not in the node's entry, which
       its last block frees; NULL otherwise. */
    double *xold;
    /* The q_mean stage with a slot map: the nodes placed at R[0] = 1 have
       their p-hat in ws->x itself until they step down the table; the
       first step keeps it in facc entry k < nsaved (getme_adaptive.c
       getme__save_phat), and slot[i] points there until
       getme__reset_nodes puts the node's own slot back. */
    int save_phat;
    int32_t nsaved;
    /* The leading entries of facc that hold p-hats or sums between the
       relaxation and getme__reset_nodes, which zeroes them (with a slot
       map; without one it zeroes the entries of run->nodes). */
    int64_t pool_used;
    double xbound;      /* power of two >= |x'| of any transformed node    */
    double star_bound;  /* power of two > any node's number of elements    */
    double pscale, wscale; /* this iteration's scales of sum w x', sum w   */
    int overflow;       /* a term exceeded xbound: the scatter is redone   */
    /* Distributed runs only (getme_smooth_part, dist.c); NULL otherwise. */
    const getme_comm *comm;
    uint8_t *owned;     /* ne: element owned by this process (else ghost)  */
    uint8_t *counted;   /* nn: node counted by this process                */
    int comm_failed;    /* a hook failed: the loop stops (GETME_ERR_COMM)  */
    /* getme_smooth_finish_sub only (finish_sub.c); NULL otherwise. */
    struct getme_finish_sub *sub;
    /* The corner guard (params.corner_guard): relaxation and the finishing
       step treat a hex/prism/pyramid/quad whose worst corner falls below
       min(its old value, corner_floor) like an invalid element. */
    int guard;
    double corner_floor; /* max(params.corner_floor, the input's worst)   */
    /* Per type, a mean ratio from which on the worst corner is provably
       above corner_floor, so the guard need not compute it: a hex's corner
       mean ratios q_k are <= 1 and average to q, so min q_k >= 8q - 7, and
       a corner's scaled Jacobian is >= q_k^(3/2) (AM-GM on its edge
       lengths); a quad's >= q_k with min q_k >= 4q - 3.  Prisms and
       pyramids (other targets W) are always checked: 2 never skips. */
    double guard_skip_q[GETME_NUM_TYPES];
} getme_run;

/* The start of getme_smooth() and getme_mesh_untangle(): params NULL ->
   defaults (filled in), error cleared, a mesh with elements and usable
   params, the workspace built.  GETME_OK, or a status with the message on
   the mesh. */
getme_status getme__start(getme_mesh *mesh, const getme_params **params,
                          getme_params *defaults, getme_ws *ws);

/* The entry of getme_smooth(), getme_smooth_part() and
   getme_mesh_untangle(): ws zeroed; mesh and result (size bytes) must be
   there (else GETME_ERR_ARGUMENT); result cleared, *t0 the start time; a
   distributed run needs a volume mesh and GETMe adaptive; then
   getme__start().  ws needs getme__ws_free() only after GETME_OK. */
getme_status getme__enter(getme_mesh *mesh, const getme_params **params,
                          getme_params *defaults, getme_ws *ws, void *result,
                          size_t size, double *t0, int distributed);

getme_status getme__run_alloc(getme_run *run);
void getme__run_free(getme_run *run);

/* Eq. 9 weight of an irregular element (adjacency.h): walks the union of
   its node stars (needs run->stamps). */
double getme__weight_union(const getme_run *run, int t, int32_t e);

/* Build run->nodes from run->in_t and run->elems (elements with a node in
   I_T), both ascending; deterministic. */
void getme__collect(getme_run *run);

/* I_T node by node: for (k = 0; k < getme__run_nodes_end(run); k++)
   with n = getme__run_node(run, k), skipping n < 0.  While nodes_all,
   k runs over every node and n is k if the smoother moves it
   (getme__ws_moves), else -1: the same nodes in the same order as the
   list. */
static inline int32_t getme__run_nodes_end(const getme_run *run)
{
    return run->nodes_all ? run->ws->nn : run->num_nodes;
}

static inline int32_t getme__run_node(const getme_run *run, int32_t k)
{
    if (!run->nodes_all)
        return run->nodes[k];
    return getme__ws_moves(run->ws, k) ? k : -1;
}

/* During the relaxation ws->x holds the trial coordinates, and a node
   that moves (I_T, in_t) keeps its old coordinates after its p-hat
   (GETME_XOLD_OFF): the trial qualities gather from the dense coordinate
   array, the end of the relaxation has nothing to copy, and no trial
   array is needed (24 B per node).  Node i's old coordinates: */
static inline int64_t getme__slot(const getme_run *run, int32_t i)
{
    return run->slot ? run->slot[i] : i;
}

static inline unsigned char *getme__xold(const getme_run *run, int32_t i)
{
    if (run->xold)
        return (unsigned char *)(run->xold + 3 * (int64_t)i);
    return run->phat + getme__slot(run, i) * run->phat_step + GETME_XOLD_OFF;
}

/* Node i's p-hat (3 doubles, memcpy). */
static inline unsigned char *getme__phat(const getme_run *run, int32_t i)
{
    return run->phat + getme__slot(run, i) * run->phat_step;
}

/* Before node i first steps down the q_mean stage's table with a slot
   map (save_phat): keep its p-hat, which is its position at R[0] = 1, in
   facc entry nsaved (getme_adaptive.c).  GETME_OK or GETME_ERR_NOMEM
   (the pool could not grow). */
getme_status getme__save_phat(getme_run *run, int32_t i);

/* With a slot map: the saved nodes' own slots back, and the pool's used
   entries (pool_used) zeroed (getme__reset_nodes). */
void getme__pool_reset(getme_run *run);

/* Eq. 10: the trial position xn at table entry rho between old
   coordinates x and p-hat ph.  rho = 0 and rho = 1 are taken literally so
   that a reset node gets its old coordinates bit for bit. */
static inline void getme__eq10(double rho, const double x[3],
                               const double ph[3], double xn[3])
{
    for (int d = 0; d < 3; d++)
        xn[d] = rho == 0.0 ? x[d]
              : rho == 1.0 ? ph[d]
                           : (1.0 - rho) * x[d] + rho * ph[d];
}

/* The relaxation's first placement of node i at table entry rho (index
   0), from its p-hat ph, in one pass with ComputeNewNodes: its
   coordinates saved as the old ones (xold, getme__xold), the trial ones
   into x = ws->x.  Plain pointers: stores through the byte array phat
   could alias run's fields, which a loop would then reload per node. */
static inline void getme__place_first(double *x, unsigned char *xold,
                                      uint8_t *ridx, int32_t i, double rho,
                                      const double ph[3])
{
    double *xi = x + 3 * (int64_t)i, o[3] = {xi[0], xi[1], xi[2]}, xn[3];
    memcpy(xold, o, sizeof o);
    ridx[i] = 0;
    getme__eq10(rho, o, ph, xn);
    xi[0] = xn[0], xi[1] = xn[1], xi[2] = xn[2];
}

/*
 * IterativeNodeRelaxation (paper Sec. 2.2, Eq. 10): move every node of
 * run->nodes to (1 - rho) x + rho p-hat (run->phat) with
 * rho from table R, re-evaluate the elements of run->elems, and step the
 * nodes of invalid elements down the table until no element is invalid.
 * R's last entry is 0, so a node can always go back to where it was and the
 * mesh stays valid.  Updates ws->x and run->q; returns how many nodes
 * ended beyond the table's first entry (GETME_CHECK_SUMS builds: -1 if
 * the count kept while stepping differs from a count over I_T).
 */
int32_t getme__relax(getme_run *run, const double *R, int nR);

/* Clear run->in_t for the nodes of run->nodes, and their exact sums
   (run->facc, holding p-hat since ComputeNewNodes) if there are. */
void getme__reset_nodes(getme_run *run);

/* Report progress; returns nonzero if the callback asks to stop. */
int getme__report(getme_run *run, int iteration, getme_stage stage, int cycle,
                  double q_min_star, double q_mean, double threshold,
                  int32_t num_transformed, int32_t num_relaxed);

/* GETMe adaptive; run->adj must be built (getme_smooth does it before the
   run's arrays, so that its temporaries do not add to the peak). */
getme_status getme__adaptive(getme_run *run);

/* getme_smooth_finish(): the finishing step and the final statistics on a
   workspace at the positions a distributed loop reached, set up as
   getme__adaptive() sets it (corner guard and floor). */
getme_status getme__adaptive_finish(getme_run *run);

/* The 0-based position of getme__threshold's quantile among n > 0 sorted
   values: fraction * n, at least min_count - 1, at most n - 1.  One
   function, because the finishing step on a sub-mesh (finish.c) must pick
   exactly the position the whole mesh's threshold picks. */
static inline int64_t getme__quantile_pos(int64_t n, double fraction,
                                          int32_t min_count)
{
    double pos = fraction * (double)n;
    if (pos < (double)min_count - 1.0)
        pos = (double)min_count - 1.0;
    return pos >= (double)(n - 1) ? n - 1 : pos <= 0.0 ? 0 : (int64_t)pos;
}

/* The k-th smallest of v[0..n) (v is permuted); deterministic
   (getme_adaptive.c). */
double getme__select_kth(double *v, int32_t n, int32_t k);

/* The quality at position fraction * n (at least min_count - 1, at most
   n - 1) of the sorted qualities of the free elements; 0 without free
   elements, -1 if out of memory (getme_adaptive.c). */
double getme__threshold(getme_run *run, double fraction,
                        int32_t min_count);

/* Worst corner scaled Jacobian over the elements with corners (1 if none),
   at ws->x; parallel min, so thread-count independent. */
double getme__ws_corner_min(const getme_ws *ws);

/* The finishing step (finish.c): passes of worst-first local max-min
   optimisation until q*_min stops rising.  Needs run->q up to date.  On a
   sub-mesh (run->sub) it returns GETME_ERR_INCOMPLETE when a pass would
   need an element or a star outside it. */
getme_status getme__finish(getme_run *run);

/* The finishing step on a sub-mesh (finish_sub.c): the elements outside
   it, which nodes have their whole star inside (ws order), and the
   progress reports held back until the step is known to be exact. */
typedef struct getme_finish_sub {
    const getme_finish_rest *rest;
    const uint8_t *complete;
    getme_progress *log;
    int num_log, cap_log;
    double need;    /* GETME_ERR_INCOMPLETE: the pass bound that did not fit */
} getme_finish_sub;

/* q_mean, q*_min, q_min (may be NULL) of the whole mesh: the workspace's
   elements plus run->sub's rest, or the workspace alone without one. */
void getme__finish_summary(const getme_run *run, double *q_mean,
                           double *q_min_star, double *q_min);

/* Untangle ws in place (untangle.c); q holds the qualities at ws->x and is
   kept up to date.  GETME_OK (res says how many elements stay invalid) or
   GETME_ERR_NOMEM. */
getme_status getme__untangle(getme_ws *ws, double *q,
                             getme_untangle_result *res);
/* Record on mesh the message naming the elements res says are still
   invalid; returns GETME_ERR_INVALID_MESH. */
getme_status getme__untangle_message(getme_mesh *mesh,
                                     const getme_untangle_result *res);
getme_status getme__laplace(getme_run *run);

/* ---- distributed runs (dist.c); each is the local operation when
   run->comm is NULL, so the single-process code calls them unchanged ---- */

/* Element e counts here (owned, or not distributed). */
static inline int getme__owned(const getme_run *run, int32_t e)
{
    return !run->owned || run->owned[e];
}

/* 1 if local is nonzero on any process. */
int getme__dist_any(getme_run *run, int local);
/* Each node's flag becomes the OR over its copies. */
void getme__dist_node_or(getme_run *run, uint8_t *flags);
/* Each node's per_node sums become the sums over its copies. */
void getme__dist_node_sum(getme_run *run, getme_fx *v, int per_node);
/* After relax's local choice of nodes to step (their run->flag set): the
   flags ORed over copies, and run->list rebuilt from them in run->nodes
   order; returns its length.  Every copy of a node then steps alike. */
int32_t getme__dist_step_list(getme_run *run, int nR);
/* In-place global sums and minima. */
void getme__dist_sum_i64(getme_run *run, int64_t *v, int n);
void getme__dist_min(getme_run *run, double *v, int n);
/* q_mean, q*_min, q_min (may be NULL) of the whole mesh: sums over owned
   elements (exact), minima over all local ones (a ghost is a copy of
   another process's element, so it cannot change a global minimum). */
void getme__summary(getme_run *run, double *q_mean, double *q_min_star,
                    double *q_min);

#endif /* GETME_SMOOTH_INTERNAL_H */
