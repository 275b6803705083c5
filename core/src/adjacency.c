/*
 * adjacency.c -- edge ids, face neighbours, exact neighbour counts and the
 * per-node / per-edge quality sums behind the Eq. 9 weights (adjacency.h
 * says why and proves the formula).
 *
 * Everything is built from the node stars the workspace already has, in
 * parallel loops where each iteration writes only what it owns (a node's
 * edges, an element's rows), so the result is the same for any number of
 * threads.
 */
#include "adjacency.h"
#include "smooth_internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* bench/setup.c times the phases below on their own: their signatures
   take a lent scratch since this was set (round 9). */
#define GETME_ADJ_LENT_SCRATCH 1
/* ... and check_all takes no nodes' check sums since this was set
   (round 12: summed in its walk) */
#define GETME_ADJ_CHECK_SUMS_IN_WALK 1
/* ... and check_all returns nothing since this was set (its scratch is
   lent, so it cannot run out of memory) */
#define GETME_ADJ_CHECK_VOID 1

void getme__adj_free(getme_adj *adj)
{
    getme__offs_free(&adj->eptr);
    free(adj->eslot);
    getme__facenb_free(&adj->fnb);
    free(adj->count);
    free(adj->irregular);
    free(adj->nsum);
    free(adj->esum);
    getme__blocks_free(&adj->blk);
    memset(adj, 0, sizeof *adj);
}

/* The check value of element n: a fixed pseudo-random 64-bit integer
   (splitmix64), so that sum(formula) == sum(union) over such values means
   every element was counted exactly once, with overwhelming probability. */
static inline uint64_t check_value(int32_t n)
{
    uint64_t z = (uint64_t)(uint32_t)n + 0x9e3779b97f4a7c15u;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* The edges of each type at each corner: corner li of a type-t element
   has num[t][li] edges, local edge j[t][li][k] to corner o[t][li][k]
   (at most 4: a pyramid's apex).  From getme__edges, once per build. */
typedef struct corner_edges {
    int8_t num[GETME_NUM_TYPES][GETME_MAX_NV];
    int8_t j[GETME_NUM_TYPES][GETME_MAX_NV][4];
    int8_t o[GETME_NUM_TYPES][GETME_MAX_NV][4];
} corner_edges;

static void corner_edge_table(corner_edges *ce)
{
    memset(ce, 0, sizeof *ce);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        for (int j = 0; j < getme__edges[t].num_edges; j++)
            for (int s = 0; s < 2; s++) {
                int li = getme__edges[t].node[j][s];
                int k = ce->num[t][li]++;
                ce->j[t][li][k] = (int8_t)j;
                ce->o[t][li][k] = getme__edges[t].node[j][1 - s];
            }
}

/* What one thread keeps while it walks its nodes: the current node's
   upper neighbours (the other ends w > u of its edges, in the order its
   star meets them: the slots) with each edge's element count and check
   sum, and the edges of all its nodes so far, appended in node order. */
typedef struct edge_walk {
    int32_t *nbr, *deg;  /* the current node's list (max_star * 4 + 1)  */
    uint64_t *chk;
    int32_t *edeg;       /* all edges of the thread's nodes so far       */
    uint64_t *re;
    int64_t len, cap;
} edge_walk;

/* Append the current node's m edges; 0 if out of memory. */
static int walk_append(edge_walk *w, int m, int checks)
{
    if (w->len + m > w->cap) {
        int64_t cap = w->cap * 2 > w->len + m ? w->cap * 2 : w->len + m + 1024;
        int32_t *d = getme__realloc(w->edeg, (size_t)cap * sizeof *d);
        if (d)
            w->edeg = d;
        uint64_t *r =
            checks ? getme__realloc(w->re, (size_t)cap * sizeof *r) : NULL;
        if (r)
            w->re = r;
        if (!d || (checks && !r))
            return 0;
        w->cap = cap;
    }
    memcpy(w->edeg + w->len, w->deg, (size_t)m * sizeof *w->deg);
    if (checks)
        memcpy(w->re + w->len, w->chk, (size_t)m * sizeof *w->chk);
    w->len += m;
    return 1;
}

/* Every edge belongs to its lower node u: walk u's star once (elements
   ascending), giving each element edge at u whose other end is higher its
   slot (the other end's position in u's list, appended if new: the lists
   are short, ~7 in a tet mesh, so a linear search; a per-thread table
   over all nodes was faster on tets only, at 8 B per node per thread)
   and counting its elements.  Returns the number of u's edges.
   tf: the mesh's one type (a constant in each inlined copy), or -1.
   The element's edges at u that are u's (the other end higher) are
   picked without a branch first: which they are is a coin toss, and
   its mispredictions, and searches for edges that are not u's, were
   most of the cost. */
static inline __attribute__((always_inline)) int
node_edges(int tf, getme_adj *adj, const getme_ws *ws,
           const corner_edges *ce, int32_t u, edge_walk *w, int checks)
{
    /* Locals and restrict: the byte stores into the slots may alias
       anything, which made the compiler reload every pointer after each. */
    int32_t *restrict nbr = w->nbr, *restrict deg = w->deg;
    uint64_t *restrict chk = w->chk;
    const int32_t *restrict star = ws->star;
    int32_t k0 = ws->star_ptr[u], k1 = ws->star_ptr[u + 1];
    int32_t kend = ws->star_ptr[ws->nn];
    int m = 0;
    for (int32_t k = k0; k < k1; k++) {
        int32_t n = star[k];
        if (tf >= 0 && k + GETME_STAR_AHEAD < kend) {
            /* the stars' elements are scattered: fetch ahead */
            int32_t a = star[k + GETME_STAR_AHEAD];
            __builtin_prefetch(getme__ws_nodes(ws, tf, a));
            __builtin_prefetch(getme__adj_slots(adj, ws, tf, a), 1);
        }
        int t = tf >= 0 ? tf : getme__ws_type(ws, n), nv = getme__nv[t];
        const int32_t *c = getme__ws_nodes(ws, t, n);
        int li = 0;
        for (int i = 1; i < nv; i++)
            li |= (c[i] == u) * i;
        uint64_t cv = checks ? check_value(n) : 0;
        /* the edges whose other end is higher, compacted branch-free */
        int ne = ce->num[t][li], nu = 0;
        int32_t ou[4];
        int8_t ju[4];
        for (int i = 0; i < ne; i++) {
            int32_t o = c[ce->o[t][li][i]];
            ou[nu] = o;
            ju[nu] = ce->j[t][li][i];
            nu += o > u;
        }
        uint8_t *slots = getme__adj_slots(adj, ws, t, n);
        for (int i = 0; i < nu; i++) {
            int32_t o = ou[i];
            int s = m;
            for (int q = m - 1; q >= 0; q--)
                s = nbr[q] == o ? q : s;
            int fresh = s == m;
            nbr[m] = o; /* past the list's end unless fresh */
            /* masks, not selects: gcc made the selects branches, and
               whether an edge is new is a coin toss */
            uint32_t keep = 0 - (uint32_t)!fresh;
            deg[s] = (int32_t)(((uint32_t)deg[s] & keep) + 1);
            if (checks)
                chk[s] = (chk[s] & (0 - (uint64_t)!fresh)) + cv;
            m += fresh;
            slots[ju[i]] = (uint8_t)(s < GETME_NO_SLOT ? s : GETME_NO_SLOT);
        }
    }
    return m;
}

/* The first node of range th of n ranges with equal star entries (the
   first node whose stars start at or after th / n of them). */
static int32_t star_split(const getme_ws *ws, int th, int n)
{
    int64_t want = (int64_t)ws->star_ptr[ws->nn] * th / n;
    int32_t lo = 0, hi = ws->nn;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (ws->star_ptr[mid] < want)
            lo = mid + 1;
        else
            hi = mid;
    }
    return th == n ? ws->nn : lo;
}

/* Edge ids of every element edge (3-D), numbered node by node (a node's
   edges in the order its star meets them), how many elements have each
   edge (edeg), and if checks is set the check-value sums of every edge
   (re).  One walk over the stars: each thread takes one contiguous range
   of nodes, writes its elements' slots (each node writes only its own
   edges' entries) and appends its edges' counts in node order; the prefix
   sum of the nodes' edge counts then says where each thread's edges go,
   so the arrays are the same for any number of threads. */
static getme_status build_edges(getme_adj *adj, const getme_ws *ws,
                                int32_t **edeg_out, int checks,
                                uint64_t **re_out)
{
    int64_t total = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        adj->eoff[t] = total;
        total += (int64_t)(ws->tstart[t + 1] - ws->tstart[t]) *
                 getme__edges[t].num_edges;
    }
    int nt = ws->nt;
    size_t bufsize = (size_t)ws->max_star * 4 + 1;
    adj->eptr.plain =
        getme__malloc(((size_t)ws->nn + 1) * sizeof *adj->eptr.plain);
    adj->eslot = getme__malloc((size_t)(total ? total : 1));
    int64_t *first = getme__calloc((size_t)nt + 1, sizeof *first);
    edge_walk *walks = getme__calloc((size_t)nt, sizeof *walks);
    int32_t *bufs = getme__malloc((size_t)nt * bufsize * 2 * sizeof *bufs);
    uint64_t *chks = getme__malloc((size_t)nt * bufsize * sizeof *chks);
    int32_t *edeg = NULL;
    uint64_t *re = NULL;
    getme_status st = GETME_ERR_NOMEM;
    if (!adj->eptr.plain || !adj->eslot || !first || !walks || !bufs || !chks)
        goto done;
    corner_edges ce;
    corner_edge_table(&ce);
    int ok = 1, single = getme__ws_single_type(ws), nteam = 1;
    adj->eptr.plain[0] = 0;
#pragma omp parallel num_threads(nt) reduction(&& : ok)
    {
        int th = omp_get_thread_num(), n = omp_get_num_threads();
        if (th == 0)
            nteam = n;
        /* The walk's state on this thread's stack, copied out at the end:
           in walks[], the threads' len fields shared a cache line, and
           walk_append writes len once per node (false sharing: the full
           hexes' walk took as long on two threads as on one) */
        edge_walk wl;
        memset(&wl, 0, sizeof wl);
        edge_walk *w = &wl;
        w->nbr = bufs + (size_t)th * 2 * bufsize;
        w->deg = w->nbr + bufsize;
        w->chk = chks + (size_t)th * bufsize;
        /* ranges of equal star entries, not nodes: the work is the stars
           (nodes used by no element are numbered last) */
        int32_t u0 = star_split(ws, th, n), u1 = star_split(ws, th + 1, n);
        /* Room for the range's edges at once (about one per 3 star
           entries in tet and hex meshes; half of them allowed): grown
           from small sizes, the arrays left freed blocks in the heap that
           stayed resident. */
        w->cap = (ws->star_ptr[u1] - ws->star_ptr[u0]) / 2 + 1024;
        w->edeg = getme__malloc((size_t)w->cap * sizeof *w->edeg);
        w->re = checks ? getme__malloc((size_t)w->cap * sizeof *w->re) : NULL;
        if (!w->edeg || (checks && !w->re))
            ok = 0, w->cap = 0;
        for (int32_t u = u0; u < u1 && ok; u++) {
            int m = single == GETME_TET
                        ? node_edges(GETME_TET, adj, ws, &ce, u, w, checks)
                    : single == GETME_HEX
                        ? node_edges(GETME_HEX, adj, ws, &ce, u, w, checks)
                        : node_edges(-1, adj, ws, &ce, u, w, checks);
            adj->eptr.plain[u + 1] = m; /* a count until the prefix sum */
            ok = walk_append(w, m, checks);
        }
        /* the range's own prefix sum (its edges before each node); the
           ranges' offsets are added below (a serial pass over all nodes
           took ~50 ms of the full hexes' set-up at any thread count) */
        int64_t sum = 0;
        for (int32_t u = u0; u < u1 && ok; u++) {
            sum += adj->eptr.plain[u + 1];
            adj->eptr.plain[u + 1] = (int32_t)sum; /* <= w->len */
        }
        first[th + 1] = w->len;
        walks[th] = wl; /* freed at done, also after a failure */
    }
    if (!ok)
        goto done;
    for (int k = 0; k < nt; k++)
        first[k + 1] += first[k];
    if (first[nt] > INT32_MAX)
        goto done;
    /* fits: every entry is at most first[nt] */
#pragma omp parallel for schedule(static, 1) num_threads(nteam)
    for (int k = 0; k < nteam; k++) {
        int32_t u1 = star_split(ws, k + 1, nteam), off = (int32_t)first[k];
        for (int32_t u = star_split(ws, k, nteam); u < u1; u++)
            adj->eptr.plain[u + 1] += off;
    }
    adj->num_edges = (int32_t)first[nt];
    /* The first thread's arrays become the whole (no copy with one
       thread); the others' are appended in thread order.  Without checks
       the counts get 8 bytes per edge: their buffer becomes the S_e
       array once they are read (getme__adj_build). */
    size_t nedge = (size_t)(first[nt] ? first[nt] : 1);
    edeg = getme__realloc(walks[0].edeg,
                          nedge * (checks ? sizeof *edeg : sizeof(int64_t)));
    if (edeg)
        walks[0].edeg = NULL;
    re = checks ? getme__realloc(walks[0].re, nedge * sizeof *re) : NULL;
    if (re)
        walks[0].re = NULL;
    if (!edeg || (checks && !re))
        goto done;
    for (int k = 1; k < nt; k++) {
        size_t len = (size_t)(first[k + 1] - first[k]);
        getme__copy(edeg + first[k], walks[k].edeg, len * sizeof *edeg, nteam);
        if (checks)
            getme__copy(re + first[k], walks[k].re, len * sizeof *re, nteam);
    }
    *edeg_out = edeg;
    *re_out = re;
    edeg = NULL, re = NULL;
    st = GETME_OK;
done:
    for (int k = 0; walks && k < nt; k++)
        free(walks[k].edeg), free(walks[k].re);
    free(walks), free(first), free(bufs), free(chks), free(edeg), free(re);
    return st;
}

/* |N(E)| by the same inclusion-exclusion, with element counts (node and
   edge degrees) in place of qualities; and irregular = a face the formula
   cannot handle. */
static void counts_and_flags(getme_adj *adj, const getme_ws *ws,
                             const int32_t *edeg)
{
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int32_t e = 0; e < ws->ne; e++) {
        int t = getme__ws_type(ws, e), nv = getme__nv[t];
        const int32_t *c = getme__ws_nodes(ws, t, e);
        const getme_face_table *ft = &getme__faces[t];
        int32_t f[6];
        getme__adj_faces(adj, ws, t, e, f);
        int64_t cnt = 0, nb = 0, bad = 0;
        for (int i = 0; i < nv; i++)
            cnt += ws->star_ptr[c[i] + 1] - ws->star_ptr[c[i]];
        for (int k = 0; k < ft->num_faces; k++) {
            nb += f[k] >= 0;
            bad |= f[k] == GETME_FACE_IRREGULAR;
        }
        if (ws->dim == 2) {
            cnt -= (nv - 1) + nb;
        } else {
            const uint8_t *slot = getme__adj_slots(adj, ws, t, e);
            for (int j = 0; j < getme__edges[t].num_edges; j++) {
                bad |= slot[j] == GETME_NO_SLOT;
                cnt -= edeg[getme__adj_edge(adj, c, t, j, slot[j])];
            }
            cnt += (ft->num_faces - 1) + nb;
        }
        bad |= cnt > UINT16_MAX;
        adj->count[e] = (uint16_t)(bad ? 0 : cnt);
        if (bad) /* only then: see getme__adj_build */
            adj->irregular[e] = 1;
    }
}

/* One thread's state of check_all's walk, on that thread's stack: now
   changes once per element, and in an array of them the threads' fields
   shared a cache line (false sharing, as build_edges' lengths did; the
   check's own two-thread time did not move with it, docs/bench.md
   session 29). */
typedef struct union_scratch {
    uint32_t *stamp; /* ne: element last seen at this stamp value */
    const uint64_t *cv; /* ne: check_value of every element (shared) */
    uint32_t now;
} union_scratch;

/* Non-simplex meshes: two elements may share nodes that are not a common
   edge or face of both (a face diagonal), which the formula would
   miscount.  Check every element once against the true union, with
   pseudo-random integers in place of q (exact arithmetic), and take the
   union's exact count where they disagree. */
static void check_element(getme_adj *adj, const getme_ws *ws,
                          const uint64_t *re,
                          const int32_t *edeg, int32_t e, union_scratch *sc)
{
    int t = getme__ws_type(ws, e), nv = getme__nv[t];
    const int32_t *c = getme__ws_nodes(ws, t, e);
    const getme_face_table *ft = &getme__faces[t];
    int32_t f[6];
    getme__adj_faces(adj, ws, t, e, f);
    /* counts_and_flags' test first, fused here (it read the same edge
       ids and faces in a pass of its own; its count was overwritten
       below): an element it would mark irregular is marked, count 0, as
       the walk below would leave it, without the walk. */
    int64_t fcnt = 0, nb = 0, bad = 0;
    for (int i = 0; i < nv; i++)
        fcnt += ws->star_ptr[c[i] + 1] - ws->star_ptr[c[i]];
    for (int k = 0; k < ft->num_faces; k++) {
        nb += f[k] >= 0;
        bad |= f[k] == GETME_FACE_IRREGULAR;
    }
    /* the edge ids once, for the counts and the check sums, every
       node's eptr loaded side by side (getme__adj_edge_ids) */
    int32_t id[12];
    if (ws->dim == 2) {
        fcnt -= (nv - 1) + nb;
    } else {
        getme__adj_edge_ids(adj, c, t, getme__adj_slots(adj, ws, t, e), id);
        for (int j = 0; j < getme__edges[t].num_edges; j++) {
            bad |= id[j] < 0; /* GETME_NO_SLOT */
            /* a missing slot's id is not read */
            fcnt -= id[j] < 0 ? 0 : edeg[id[j]];
        }
        fcnt += (ft->num_faces - 1) + nb;
    }
    if (bad || fcnt > UINT16_MAX) {
        adj->irregular[e] = 1;
        adj->count[e] = 0;
        return;
    }
    uint32_t now = ++sc->now;
    int32_t cnt = 0;
    uint64_t truth = 0, formula = 0;
    /* Branch-free: whether an element was seen already is a coin toss
       (a hex's 8 stars hold ~64 entries, ~27 of them distinct). */
    uint32_t *restrict stamp = sc->stamp;
    const uint64_t *restrict cv = sc->cv;
    const int32_t *restrict star = ws->star;
    for (int i = 0; i < nv; i++)
        for (int32_t k = ws->star_ptr[c[i]]; k < ws->star_ptr[c[i] + 1]; k++) {
            int32_t n = star[k];
            uint32_t fresh = stamp[n] != now;
            stamp[n] = now;
            /* masked, not selected: gcc made the select a branch again */
            truth += cv[n] & (0 - (uint64_t)fresh);
            /* the formula's S_v of e's nodes: the sum over the same
               entries, repeats included (a pass of its own over every
               star, ~0.04 s of the full hexes, before this) */
            formula += cv[n];
            cnt += (int32_t)fresh;
        }
    uint64_t fs = 0;
    for (int j = 0; j < ft->num_faces; j++)
        fs += f[j] >= 0 ? cv[f[j]] : 0;
    uint64_t self = cv[e];
    if (ws->dim == 2) {
        formula -= (uint64_t)(nv - 1) * self + fs;
    } else {
        for (int j = 0; j < getme__edges[t].num_edges; j++)
            formula -= re[id[j]];
        formula += (uint64_t)(ft->num_faces - 1) * self + fs;
    }
    if (formula != truth || cnt > UINT16_MAX)
        adj->irregular[e] = 1;
    adj->count[e] = (uint16_t)(adj->irregular[e] ? 0 : cnt);
}

/* The bytes check_all needs in its scratch: a stamp per element and
   thread, and every element's check value. */
static size_t check_scratch_bytes(const getme_ws *ws)
{
    size_t ne = (size_t)(ws->ne ? ws->ne : 1);
    size_t stamps = ((size_t)ws->nt * ne * sizeof(uint32_t) + 7) & ~(size_t)7;
    return stamps + ne * sizeof(uint64_t);
}

/* scratch: check_scratch_bytes(ws) bytes, any contents (getme__adj_build
   lends the pages the blocks' build used: already faulted in). */
static void check_all(getme_adj *adj, const getme_ws *ws, const uint64_t *re,
                      const int32_t *edeg, void *scratch)
{
    int nt = ws->nt;
    size_t ne = (size_t)(ws->ne ? ws->ne : 1);
    uint32_t *stamps = scratch;
    /* every element's check value once (8 B per element while the
       check runs, below the smoothing's peak): the union walk meets each
       ~2.4 times */
    uint64_t *cv = (uint64_t *)(void *)((char *)scratch +
                                        (((size_t)nt * ne * sizeof *stamps + 7) &
                                         ~(size_t)7));
    /* the stamps start at 0 and a walk's first stamp is 1 */
    memset(stamps, 0, (size_t)nt * ne * sizeof *stamps);
#pragma omp parallel for schedule(static) num_threads(nt)
    for (int32_t e = 0; e < ws->ne; e++)
        cv[e] = check_value(e);
#pragma omp parallel num_threads(nt)
    {
        union_scratch sc = {stamps + (size_t)omp_get_thread_num() * ne, cv, 0};
#pragma omp for schedule(dynamic, 2048)
        for (int32_t e = 0; e < ws->ne; e++)
            check_element(adj, ws, re, edeg, e, &sc);
    }
}

static int simplices_only(const getme_ws *ws)
{
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        if (t != GETME_TET && t != GETME_TRI && ws->tstart[t + 1] > ws->tstart[t])
            return 0;
    return 1;
}

getme_status getme__adj_build(getme_adj *adj, getme_ws *ws)
{
    memset(adj, 0, sizeof *adj);
    size_t nn = (size_t)(ws->nn ? ws->nn : 1), ne = (size_t)(ws->ne ? ws->ne : 1);
    int64_t ftotal = getme__ws_face_offsets(ws, adj->foff);
    /* Simplices meet only in common sub-faces (any 2 or 3 nodes of a tet
       are an edge or a face of it), so the formula can fail only where
       build_faces sees it; other types need the check. */
    int check = !simplices_only(ws);
    /* The boundary search's table, packed (facenb.h), or one built and
       packed here first, in place, before the rest is allocated. */
    getme_status st = GETME_ERR_NOMEM;
    if (ws->faces.d) {
        adj->fnb = ws->faces;
        memset(&ws->faces, 0, sizeof ws->faces);
    } else {
        int32_t *table =
            getme__malloc((size_t)(ftotal ? ftotal : 1) * sizeof *table);
        if (!table || getme__ws_faces(ws, adj->foff, table) != GETME_OK) {
            free(table);
            return GETME_ERR_NOMEM;
        }
        if (getme__facenb_pack(&adj->fnb, ws, adj->foff, table) != GETME_OK)
            return GETME_ERR_NOMEM; /* table freed */
    }
    adj->count = getme__malloc(ne * sizeof *adj->count);
    /* Zeroed, and only irregular elements written: on a mesh with none
       (tets) its pages are never touched, so they take no memory. */
    adj->irregular = getme__calloc(ne, 1);
    adj->nsum = getme__malloc(nn * sizeof *adj->nsum);
    /* The fixed-point scale of the sums (adjacency.h). */
    adj->qscale = 0x1p61 / getme__pow2_ceil((double)ws->max_star + 1.0);
    adj->qinv = 1.0 / adj->qscale;
    /* The temporaries live in arrays the run needs anyway, or share
       pages: a fresh page costs ~3 ms per MiB to fault in on the VMs
       measured (the CLI maps every block of 1 MiB or more afresh), ~0.3 s
       of the full hexes' set-up.  The edges' check sums (re) become S_e's
       array, and without checks the
       edges' element counts' buffer does (8 bytes per edge reserved):
       getme__adj_sums_all overwrites both before any sum is read.  The
       blocks' build and the check share one scratch. */
    uint64_t *re = NULL;
    int32_t *edeg = NULL;
    size_t sbytes = getme__blocks_scratch_bytes(ws);
    if (check && check_scratch_bytes(ws) > sbytes)
        sbytes = check_scratch_bytes(ws);
    void *scratch = NULL;
    if (!adj->count || !adj->irregular || !adj->nsum)
        goto fail;
    if (ws->dim == 3 &&
        (st = build_edges(adj, ws, &edeg, check, &re)) != GETME_OK)
        goto fail;
    st = GETME_ERR_NOMEM;
    if (!check) /* else fused into check_all's walk */
        counts_and_flags(adj, ws, edeg);
    if (ws->dim == 3) {
        /* S_e's array: the check sums' (read by check_all below, then
           overwritten by the sums) or the counts' */
        adj->esum = check ? (int64_t *)(void *)re : (int64_t *)(void *)edeg;
        if (check)
            re = NULL;
        else
            edeg = NULL;
    }
    if (!(scratch = getme__malloc(sbytes)))
        goto fail;
    if ((st = getme__blocks_build(&adj->blk, ws, scratch)) != GETME_OK)
        goto fail;
    if (check)
        check_all(adj, ws, (const uint64_t *)adj->esum, edeg, scratch);
    free(edeg), edeg = NULL;
    int32_t nirr = 0;
#pragma omp parallel for schedule(static) num_threads(ws->nt) \
    reduction(+ : nirr)
    for (int32_t e = 0; e < ws->ne; e++)
        nirr += adj->irregular[e];
    adj->num_irregular = nirr;
    free(scratch), free(edeg);
    /* read node by node from here on: 2.25 bytes per node (offsets.h) */
    if (adj->eptr.plain)
        getme__offs_take(&adj->eptr, adj->eptr.plain, (int64_t)ws->nn + 1);
    return GETME_OK;
fail:
    free(re), free(edeg), free(scratch);
    getme__adj_free(adj);
    return st;
}

/* S_v and S_e contributions of the elements of block b, all of type t (a
   constant in each copy, see GETME_FOR_TYPE). */
static inline void add_block_sums(int t, getme_adj *adj, const getme_ws *ws,
                                  const double *q, int32_t b)
{
    for (int32_t e = ws->block_start[b]; e < ws->block_start[b + 1]; e++)
        getme__adj_add(adj, ws, t, e, getme__ws_nodes(ws, t, e),
                       (uint64_t)getme__fx64(q[e], adj->qscale));
}

typedef struct sums_pass {
    getme_adj *adj;
    const getme_ws *ws;
    const double *q;
} sums_pass;

static int64_t sums_block(void *ctx, int32_t b)
{
    sums_pass *p = ctx;
    GETME_FOR_TYPE(getme__ws_type(p->ws, p->ws->block_start[b]),
                   add_block_sums, p->adj, p->ws, p->q, b);
    return 0;
}

void getme__adj_sums_all(getme_adj *adj, const getme_ws *ws, const double *q)
{
    memset(adj->nsum, 0, (size_t)ws->nn * sizeof *adj->nsum);
    if (adj->esum)
        memset(adj->esum, 0, (size_t)adj->num_edges * sizeof *adj->esum);
    /* In the blocks' race-free order (block_local.h): no atomics, and the
       integer sums are the same whatever the order. */
    sums_pass p = {adj, ws, q};
    getme__blocks_run(&adj->blk, ws, sums_block, &p);
}
