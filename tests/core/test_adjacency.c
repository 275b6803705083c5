/*
 * test_adjacency.c -- the Eq. 9 neighbour sums by inclusion-exclusion
 * (core/src/adjacency.h) against a brute-force walk over the union of the
 * node stars, on conforming meshes of every type (where the formula must
 * be exact for every element), and on non-conforming ones (where the
 * elements it cannot count must be found and flagged); and the whole
 * set-up (workspace, faces, edges, counts, flags, blocks) built with 1, 2
 * and 3 threads, entry for entry the same.
 *
 * Built from the core's sources (not libgetme), because it checks private
 * functions.
 */
#include "adjacency.h"
#include "block_edges.h"
#include "check.h"

#include <stdlib.h>
#include <string.h>

/* ---- mesh builders ------------------------------------------------------ */

typedef struct gen {
    int dim;
    double *xyz;
    int32_t nn, cap_n;
    int32_t *conn[GETME_NUM_TYPES];
    int32_t count[GETME_NUM_TYPES], cap[GETME_NUM_TYPES];
} gen;

static int32_t add_node(gen *g, double x, double y, double z)
{
    if (g->nn == g->cap_n) {
        g->cap_n = g->cap_n ? 2 * g->cap_n : 256;
        g->xyz = realloc(g->xyz, (size_t)g->cap_n * 3 * sizeof *g->xyz);
    }
    g->xyz[3 * g->nn] = x, g->xyz[3 * g->nn + 1] = y, g->xyz[3 * g->nn + 2] = z;
    return g->nn++;
}

static void add_elem(gen *g, int t, const int32_t *c)
{
    int nv = getme_type_num_nodes((getme_elem_type)t);
    if (g->count[t] == g->cap[t]) {
        g->cap[t] = g->cap[t] ? 2 * g->cap[t] : 256;
        g->conn[t] = realloc(g->conn[t], (size_t)g->cap[t] * nv * sizeof(int32_t));
    }
    memcpy(g->conn[t] + (size_t)g->count[t] * nv, c, (size_t)nv * sizeof *c);
    g->count[t]++;
}

/* A twin of every 97th element of each type: faces of three sides and
   twin simplices, so the irregular paths run. */
static void add_twins(gen *g)
{
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        for (int32_t e = 0; e < g->count[t]; e += 97) {
            int32_t c[GETME_MAX_NV]; /* add_elem may move g->conn[t] */
            memcpy(c, g->conn[t] + (size_t)e * getme__nv[t],
                   (size_t)getme__nv[t] * sizeof *c);
            add_elem(g, t, c);
        }
}

static void free_gen(gen *g)
{
    free(g->xyz);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        free(g->conn[t]);
}

/* Cells per side of the grids (5; a larger grid for the block order). */
static int N = 5;
static int32_t grid(int i, int j, int k) { return (k * (N + 1) + j) * (N + 1) + i; }

static void grid_nodes(gen *g, int dim)
{
    g->dim = dim;
    for (int k = 0; k <= (dim == 3 ? N : 0); k++)
        for (int j = 0; j <= N; j++)
            for (int i = 0; i <= N; i++)
                add_node(g, i, j, k);
}

/* Corners of cell (i, j, k) in hex order. */
static void cell(int i, int j, int k, int32_t v[8])
{
    v[0] = grid(i, j, k), v[1] = grid(i + 1, j, k);
    v[2] = grid(i + 1, j + 1, k), v[3] = grid(i, j + 1, k);
    v[4] = grid(i, j, k + 1), v[5] = grid(i + 1, j, k + 1);
    v[6] = grid(i + 1, j + 1, k + 1), v[7] = grid(i, j + 1, k + 1);
}

/* Kuhn split of a cube into 6 tets around the diagonal 0-6: conforming
   across cubes because every cube uses the same diagonal direction. */
static void kuhn(gen *g, const int32_t v[8])
{
    static const int8_t tets[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                      {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    for (int t = 0; t < 6; t++) {
        int32_t c[4] = {v[tets[t][0]], v[tets[t][1]], v[tets[t][2]], v[tets[t][3]]};
        add_elem(g, GETME_TET, c);
    }
}

/* Hexes, prism columns and pyramid-split cells: all faces between cells
   are the cells' quads (prisms' triangles meet prisms), so it conforms. */
static void mixed_cell(gen *g, int i, int j, int k, const int32_t v[8])
{
    int kind = (i + j) % 3;
    if (kind == 0) { /* two prisms: triangles in the xy faces */
        int32_t a[6] = {v[0], v[1], v[2], v[4], v[5], v[6]};
        int32_t b[6] = {v[0], v[2], v[3], v[4], v[6], v[7]};
        add_elem(g, GETME_PRISM, a);
        add_elem(g, GETME_PRISM, b);
    } else if (kind == 1 && k % 2 == 0) { /* six pyramids to the centre */
        int32_t c = add_node(g, i + 0.5, j + 0.5, k + 0.5);
        /* each base counter-clockwise seen from the apex (the centre),
           as Gmsh orders a pyramid; listed seen from outside, all six
           were inverted, and the mixed cases ran with about half of their
           elements invalid */
        static const int8_t faces[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1},
                                           {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}};
        for (int f = 0; f < 6; f++) {
            int32_t p[5] = {v[faces[f][0]], v[faces[f][1]], v[faces[f][2]],
                            v[faces[f][3]], c};
            add_elem(g, GETME_PYRAMID, p);
        }
    } else {
        add_elem(g, GETME_HEX, v);
    }
}

static gen make(const char *kind)
{
    gen g;
    memset(&g, 0, sizeof g);
    if (!strcmp(kind, "tri") || !strcmp(kind, "quad") || !strcmp(kind, "tri+quad")) {
        grid_nodes(&g, 2);
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                int32_t a = grid(i, j, 0), b = grid(i + 1, j, 0);
                int32_t c = grid(i + 1, j + 1, 0), d = grid(i, j + 1, 0);
                int quads = !strcmp(kind, "quad") || (!strcmp(kind, "tri+quad") && (i + j) % 2);
                if (quads) {
                    int32_t q[4] = {a, b, c, d};
                    add_elem(&g, GETME_QUAD, q);
                } else {
                    int32_t t1[3] = {a, b, c}, t2[3] = {a, c, d};
                    add_elem(&g, GETME_TRI, t1);
                    add_elem(&g, GETME_TRI, t2);
                }
            }
        return g;
    }
    grid_nodes(&g, 3);
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                int32_t v[8];
                cell(i, j, k, v);
                if (!strcmp(kind, "tet"))
                    kuhn(&g, v);
                else if (!strcmp(kind, "hex"))
                    add_elem(&g, GETME_HEX, v);
                else
                    mixed_cell(&g, i, j, k, v);
            }
    return g;
}

static getme_mesh *to_mesh(const gen *g)
{
    getme_mesh *m = NULL;
    CHECK(getme_mesh_create(&m, g->dim, g->nn, g->xyz) == GETME_OK);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        if (g->count[t])
            CHECK(getme_mesh_add_elements(m, (getme_elem_type)t, g->count[t],
                                          g->conn[t], NULL) == GETME_OK);
    return m;
}

/* ---- brute force -------------------------------------------------------- */

/* Sum and count of q over the union of the stars of e's nodes. */
static double brute(const getme_ws *ws, const double *q, int32_t e,
                    int32_t *count, uint32_t *mark, uint32_t now)
{
    int t = getme__ws_type(ws, e);
    const int32_t *c = getme__ws_nodes(ws, t, e);
    double s = 0.0;
    *count = 0;
    for (int i = 0; i < getme__nv[t]; i++)
        for (int64_t k = ws->star_ptr[c[i]]; k < ws->star_ptr[c[i] + 1]; k++) {
            int32_t n = ws->star[k];
            if (mark[n] != now) {
                mark[n] = now;
                s += q[n];
                (*count)++;
            }
        }
    return s;
}

static int32_t check_order(const getme_blocks *blk, const getme_ws *ws);

/* The blocks' node lists (block_local.h, built with adj): each block
   lists its elements' nodes once each, and the local connectivity maps
   back to the workspace's. */
static void check_blocks(const getme_blocks *blk, const getme_ws *ws)
{
    uint32_t *seen = calloc((size_t)ws->nn, sizeof *seen);
    int ok = blk->nptr[0] == 0;
    int32_t big = 0;
    for (int32_t b = 0; b < ws->num_blocks; b++) {
        const int32_t *gn = blk->nodes + blk->nptr[b];
        int32_t m = (int32_t)(blk->nptr[b + 1] - blk->nptr[b]);
        big = m > big ? m : big;
        for (int32_t k = 0; k < m; k++) { /* distinct */
            ok &= seen[gn[k]] != (uint32_t)b + 1;
            seen[gn[k]] = (uint32_t)b + 1;
        }
        int32_t used = 0;
        getme__blocks_localise(blk, ws, b, &blk->scratch[0]);
        for (int32_t e = ws->block_start[b]; e < ws->block_start[b + 1]; e++) {
            int t = getme__ws_type(ws, e);
            const int32_t *c = getme__ws_nodes(ws, t, e);
            const uint16_t *lc = getme__blocks_lnodes(
                &blk->scratch[0], getme__nv[t], e - ws->block_start[b]);
            for (int i = 0; i < getme__nv[t]; i++) {
                ok &= lc[i] < m && gn[lc[i]] == c[i];
                used = lc[i] + 1 > used ? lc[i] + 1 : used;
            }
        }
        ok &= used == m; /* no node listed that no element uses */
    }
    CHECK(ok);
    CHECK_EQ_INT(blk->max_nodes, big);
    free(seen);
    check_order(blk, ws);
}

/* The blocks left after the levels are coloured greedily in block order
   among themselves (block_local.c colour_left): a block of colour c > 0
   shares a node with an earlier block (by index) of every colour below
   c, or a greedy colouring would have given it that colour; a block of
   the serial colour with one of each of the others, which are then all
   there are.  A colouring that wasted colours (all the blocks', as the
   workspace's was) fails this.  mark: room for ws->nn entries. */
static void check_colours(const getme_blocks *blk, const getme_ws *ws,
                          int32_t *mark)
{
    int nc = blk->num_colours, ok = 1;
    int32_t k0 = blk->col_ptr[0], k1 = blk->col_ptr[nc];
    for (int32_t k = k0; ok && k < k1; k++) {
        int32_t b = blk->order[k];
        int c = 0;
        while (k >= blk->col_ptr[c + 1])
            c++;
        /* the colours of the earlier blocks left that share a node with b */
        uint64_t met = 0;
        for (int32_t n = 0; n < ws->nn; n++)
            mark[n] = 0;
        for (int64_t j = blk->nptr[b]; j < blk->nptr[b + 1]; j++)
            mark[blk->nodes[j]] = 1;
        for (int32_t i = k0; i < k1; i++) {
            int32_t o = blk->order[i];
            if (o >= b)
                continue;
            int oc = 0;
            while (i >= blk->col_ptr[oc + 1])
                oc++;
            for (int64_t j = blk->nptr[o]; j < blk->nptr[o + 1]; j++)
                if (mark[blk->nodes[j]]) {
                    met |= (uint64_t)1 << oc;
                    break;
                }
        }
        int below = c == blk->serial_colour ? nc - 1 : c;
        uint64_t want = (((uint64_t)1 << below) - 1); /* nc <= 33 */
        ok &= (met & want) == want;
    }
    CHECK(ok);
}

/* The blocks' visiting order (getme__blocks_run): every block once, and
   no node shared by two blocks that may run at the same time: the parts
   of one level, or two blocks of one colour (but the serial one).
   Returns how many blocks the parts' levels hold. */
static int32_t check_order(const getme_blocks *blk, const getme_ws *ws)
{
    int32_t nb = ws->num_blocks, np = blk->num_parts;
    int32_t *own = malloc((size_t)ws->nn * sizeof *own);
    int32_t *seen = calloc((size_t)(nb ? nb : 1), sizeof *seen);
    int ok = blk->part_ptr[0] == 0 &&
             blk->col_ptr[0] == blk->part_ptr[GETME_ORDER_LEVELS * np] &&
             blk->col_ptr[blk->num_colours] == nb;
    for (int32_t k = 0; ok && k < nb; k++)
        seen[blk->order[k]]++;
    for (int32_t b = 0; ok && b < nb; b++)
        ok &= seen[b] == 1;
    /* the parts of a level are equal (they run side by side) */
    for (int l = 0; l < GETME_ORDER_LEVELS; l++)
        for (int p = 1; p < np; p++)
            CHECK_EQ_INT(blk->part_ptr[l * np + p + 1] - blk->part_ptr[l * np + p],
                         blk->part_ptr[l * np + 1] - blk->part_ptr[l * np]);
    /* groups: each level's parts (several each), then each colour's
       blocks (one each) */
    for (int g = 0; ok && g < GETME_ORDER_LEVELS + blk->num_colours; g++) {
        int level = g < GETME_ORDER_LEVELS;
        if (!level && g - GETME_ORDER_LEVELS == blk->serial_colour)
            continue;
        for (int32_t n = 0; n < ws->nn; n++)
            own[n] = -1;
        int32_t k0 = level ? blk->part_ptr[g * np] : blk->col_ptr[g - GETME_ORDER_LEVELS];
        int32_t k1 = level ? blk->part_ptr[(g + 1) * np]
                           : blk->col_ptr[g - GETME_ORDER_LEVELS + 1];
        int32_t p = 0;
        for (int32_t k = k0; k < k1; k++) {
            while (level && k >= blk->part_ptr[g * np + p + 1])
                p++;
            int32_t who = level ? p : k, b = blk->order[k];
            for (int64_t j = blk->nptr[b]; j < blk->nptr[b + 1]; j++) {
                int32_t n = blk->nodes[j];
                ok &= own[n] == -1 || own[n] == who;
                own[n] = who;
            }
        }
    }
    CHECK(ok);
    check_colours(blk, ws, own);
    free(own), free(seen);
    return blk->part_ptr[GETME_ORDER_LEVELS * np];
}

/* getme__blocks_of and getme__blocks_group (block_local.h): every
   element's block holds it; a list of every third element, backwards,
   grouped by block: each block lists exactly the positions of its
   elements, ascending.  Returns the group's positions (caller frees), to
   compare across thread counts. */
static int32_t *check_group(getme_blocks *blk, const getme_ws *ws)
{
    int ok = 1;
    for (int32_t b = 0; b < ws->num_blocks; b++)
        for (int32_t e = ws->block_start[b]; e < ws->block_start[b + 1]; e++)
            ok &= getme__blocks_of(blk, ws, getme__ws_type(ws, e), e) == b;
    CHECK(ok);
    int32_t n = 0;
    int32_t *list = malloc((size_t)(ws->ne / 3 + 1) * sizeof *list);
    for (int32_t e = ws->ne - 1; e >= 0; e -= 3)
        list[n++] = e;
    CHECK(getme__blocks_group(blk, ws, list, n) == GETME_OK);
    const struct getme_block_group *g = &blk->group;
    CHECK_EQ_INT(g->n, n);
    CHECK_EQ_INT(g->ptr[0], 0);
    CHECK_EQ_INT(g->ptr[ws->num_blocks], n);
    uint8_t *seen = calloc((size_t)n + 1, 1);
    for (int32_t b = 0; b < ws->num_blocks; b++) {
        int32_t expect = 0; /* list entries in block b */
        for (int32_t k = 0; k < n; k++)
            expect += list[k] >= ws->block_start[b] && list[k] < ws->block_start[b + 1];
        ok &= g->ptr[b + 1] - g->ptr[b] == expect;
        for (int32_t j = g->ptr[b]; j < g->ptr[b + 1]; j++) {
            int32_t k = g->pos[j];
            ok &= k >= 0 && k < n && !seen[k];
            ok &= j == g->ptr[b] || g->pos[j - 1] < k;
            ok &= list[k] >= ws->block_start[b] && list[k] < ws->block_start[b + 1];
            seen[k] = 1;
        }
    }
    CHECK(ok);
    int32_t *pos = malloc((size_t)n * sizeof *pos + 1);
    memcpy(pos, g->pos, (size_t)n * sizeof *pos);
    free(seen), free(list);
    return pos;
}

/* A 24^3 Kuhn grid (162 blocks) for 1-4 threads: the order is race-free,
   the parts take the blocks they should, and the Eq. 9 sums built in it
   are the same integers for every thread count. */
static void check_block_order(void)
{
    N = 24;
    gen g = make("tet");
    N = 5;
    getme_mesh *mesh = to_mesh(&g);
    int64_t *ref = NULL;
    int32_t *gref = NULL;
    for (int nt = 1; nt <= 4; nt++) {
        getme_ws ws;
        getme_adj adj;
        CHECK(getme__ws_build(&ws, mesh, 1, nt) == GETME_OK);
        CHECK(getme__adj_build(&adj, &ws) == GETME_OK);
        CHECK_EQ_INT(ws.num_blocks, 162);
        int32_t in_parts = check_order(&adj.blk, &ws);
        /* 1 thread: all in element order; more: over three levels
           (block_local.c), the blocks that share no node with another
           part's that run (each part keeps its side of the interfaces
           with the parts after it, level_runs), as many in each part of
           a level as in its smallest; the grid is only ~5 blocks wide, so
           the interfaces hold many of them.  With both sides of every
           interface left for the next level (each part's interior
           blocks): 114, 18 and 20 */
        static const int32_t expect[5] = {0, 162, 130, 99, 60};
        CHECK_EQ_INT(in_parts, expect[nt]);
        int32_t *pos = check_group(&adj.blk, &ws);
        if (!gref) { /* the same grouping for every nt */
            gref = pos;
        } else {
            CHECK(memcmp(gref, pos, (size_t)((ws.ne + 2) / 3) * sizeof *pos) == 0);
            free(pos);
        }
        double *q = malloc((size_t)ws.ne * sizeof *q);
        for (int32_t e = 0; e < ws.ne; e++)
            q[e] = 0.05 + 0.9 * (double)((ws.elem_orig[e] * 7919) % 1000) / 1000.0;
        getme__adj_sums_all(&adj, &ws, q);
        if (!ref) {
            ref = malloc((size_t)adj.num_edges * sizeof *ref);
            memcpy(ref, adj.esum, (size_t)adj.num_edges * sizeof *ref);
        } else { /* same numbering for every nt (node order is fixed) */
            CHECK(memcmp(ref, adj.esum, (size_t)adj.num_edges * sizeof *ref) == 0);
        }
        free(q);
        getme__adj_free(&adj);
        getme__ws_free(&ws);
    }
    free(ref), free(gref);
    getme_mesh_free(mesh);
    free_gen(&g);
}

/* GETMe adaptive on a 24^3 Kuhn grid distorted like the benchmark meshes
   (getme_mesh_distort to q_mean 0.45), 1 and 2 threads: this
   test is built with GETME_CHECK_SUMS, so every iteration compares the
   Eq. 9 sums it keeps by differences (relaxation, update_after) with a
   recomputation and fails with GETME_ERR_STATE if they differ.  The
   q_mean stage's relaxation steps nodes back (num_relaxed > 0), so the
   corrections after its first trial pass run (without them: status 5). */
static int count_relaxed(const getme_progress *pr, void *data)
{
    if (pr->stage == GETME_STAGE_MEAN)
        *(int64_t *)data += pr->num_relaxed;
    return 0;
}

static void check_live_sums(void)
{
    N = 24;
    gen g = make("tet");
    N = 5;
    double q_mean[3], *ref = NULL;
    for (int nt = 1; nt <= 2; nt++) {
        getme_mesh *mesh = to_mesh(&g);
        CHECK(getme_mesh_fix_boundary(mesh, GETME_FIX_SKIN, NULL) == GETME_OK);
        /* as the benchmark meshes: q_mean down to 0.45 */
        CHECK(getme_mesh_distort(mesh, 1, 0.5, 0.45, 200) == GETME_OK);
        getme_params p;
        getme_params_init(&p);
        p.num_threads = nt;
        int64_t relaxed = 0;
        p.progress = count_relaxed;
        p.progress_data = &relaxed;
        getme_result r;
        CHECK_EQ_INT(getme_smooth(mesh, &p, &r), GETME_OK);
        CHECK(relaxed > 0); /* the step corrections ran */
        CHECK(r.iterations_mean >= 3 && r.iterations_min >= 1);
        CHECK(r.q_mean > r.q_mean_initial);
        q_mean[nt] = r.q_mean;
        /* every coordinate the same bits: with 2 threads the q_mean stage
           swaps the parts' threads and deals the blocks again with
           uneven shares between its iterations (getme_adaptive.c,
           rebalance_due in test builds) */
        int32_t nn = getme_mesh_num_nodes(mesh);
        const double *x = getme_mesh_coords(mesh);
        if (!ref) {
            ref = malloc((size_t)nn * 3 * sizeof *ref);
            memcpy(ref, x, (size_t)nn * 3 * sizeof *ref);
        } else {
            CHECK(memcmp(ref, x, (size_t)nn * 3 * sizeof *ref) == 0);
        }
        getme_mesh_free(mesh);
    }
    CHECK(memcmp(&q_mean[1], &q_mean[2], sizeof *q_mean) == 0);
    free(ref);
    free_gen(&g);
}

/* The q*_min stage's lists and sums (getme_adaptive.c): its ring of
   elements around I_T is listed in ascending order (ring_sweep) or in
   first-occurrence order, and its Eq. 9 contributions and sum updates run
   element by element in list order or block by block in chunks
   (some_chunks, update_block).  None of that may change a bit: this test
   is built with GETME_CHECK_SUMS, where 2 threads always take the sweep
   and 1 and 3 never, and 3 threads always go element by element and 1 and
   2 never, so every output coordinate of 1, 2 and 3 threads must be the
   same bits.
   Tets, hexes and a mixed mesh (blocks of several types, irregular
   elements' union weights), each distorted as the benchmark meshes. */
static void check_ring_orders(const char *kind)
{
    N = 10;
    gen g = make(kind);
    N = 5;
    double *ref = NULL;
    int32_t nn = 0;
    for (int nt = 1; nt <= 3; nt++) {
        getme_mesh *mesh = to_mesh(&g);
        CHECK(getme_mesh_fix_boundary(mesh, GETME_FIX_SKIN, NULL) == GETME_OK);
        CHECK(getme_mesh_distort(mesh, 3, 0.5, 0.45, 200) == GETME_OK);
        getme_params p;
        getme_params_init(&p);
        p.num_threads = nt;
        getme_result r;
        CHECK_EQ_INT(getme_smooth(mesh, &p, &r), GETME_OK);
        CHECK(r.iterations_min >= 1);
        nn = getme_mesh_num_nodes(mesh);
        const double *x = getme_mesh_coords(mesh);
        if (nt == 1) {
            ref = malloc((size_t)nn * 3 * sizeof *ref);
            memcpy(ref, x, (size_t)nn * 3 * sizeof *ref);
        } else {
            CHECK(memcmp(ref, x, (size_t)nn * 3 * sizeof *ref) == 0);
        }
        getme_mesh_free(mesh);
    }
    free(ref);
    free_gen(&g);
}

/* What the end of the smoothing keeps by changes instead of sweeps
   (tally.h, best.c, finish.c): q_mean's exact sum and q*_min after each
   q*_min iteration, the qualities after keep_best puts the best mesh back
   (only the stars of the nodes it puts back are rescored), and each
   finishing pass's list, bound and summary.  This test is built with
   GETME_CHECK_SUMS, where each of them is compared with a sweep and a
   difference fails the run with GETME_ERR_STATE (dropping the
   getme__tally_change in update_after, or one star from best.c's rescore,
   makes these runs return it).  Several distortions, so that some runs end
   the q*_min stage below their best (keep_best restores) and all run
   finishing passes; 1 and 2 threads give the same result (with 2, test
   builds run scatter_some and update_after's sums block by block, in
   parallel: getme_adaptive.c's SOME_PAR_MIN). */
typedef struct tail_seen {
    double best_min, last_min; /* over the q*_min stage */
    int finish_passes;
} tail_seen;

static int see_tail(const getme_progress *pr, void *data)
{
    tail_seen *s = data;
    if (pr->stage == GETME_STAGE_MIN) {
        s->best_min = pr->q_min_star > s->best_min ? pr->q_min_star : s->best_min;
        s->last_min = pr->q_min_star;
    } else if (pr->stage == GETME_STAGE_FINISH) {
        s->finish_passes++;
    }
    return 0;
}

static void check_tail_bookkeeping(void)
{
    N = 12;
    gen g = make("tet");
    N = 5;
    int restored = 0, finished = 0;
    for (uint64_t seed = 1; seed <= 4; seed++) {
        double q[3];
        for (int nt = 1; nt <= 2; nt++) {
            getme_mesh *mesh = to_mesh(&g);
            CHECK(getme_mesh_fix_boundary(mesh, GETME_FIX_SKIN, NULL) == GETME_OK);
            CHECK(getme_mesh_distort(mesh, seed, 0.5, 0.45, 200) == GETME_OK);
            getme_params p;
            getme_params_init(&p);
            p.num_threads = nt;
            tail_seen seen = {-1.0, -1.0, 0};
            p.progress = see_tail;
            p.progress_data = &seen;
            getme_result r;
            CHECK_EQ_INT(getme_smooth(mesh, &p, &r), GETME_OK);
            CHECK(r.iterations_min >= 1);
            restored += nt == 1 && seen.best_min > seen.last_min;
            finished += nt == 1 && seen.finish_passes > 0;
            /* the result's statistics are those of the output mesh */
            getme_quality_stats st;
            CHECK(getme_mesh_quality_stats(mesh, -1, &st) == GETME_OK);
            CHECK(st.q_mean == r.q_mean && st.q_min_star == r.q_min_star);
            q[nt] = r.q_mean;
            getme_mesh_free(mesh);
        }
        CHECK(q[1] == q[2]);
    }
    CHECK(restored > 0);
    CHECK(finished > 0);
    free_gen(&g);
}

/* Build ws + adj for g with nt threads; check every regular element's
   formula sum and count against the brute force; return the irregular
   flags (caller frees) in ws element order, and the ws (caller frees). */
static uint8_t *check_formula(const gen *g, int nt, getme_ws *ws,
                              getme_mesh **mesh_out)
{
    getme_mesh *mesh = to_mesh(g);
    CHECK(getme__ws_build(ws, mesh, 1, nt) == GETME_OK);
    getme_adj adj;
    CHECK(getme__adj_build(&adj, ws) == GETME_OK);
    double *q = malloc((size_t)ws->ne * sizeof *q);
    uint32_t *mark = calloc((size_t)ws->ne, sizeof *mark);
    srand(7);
    for (int32_t e = 0; e < ws->ne; e++)
        q[e] = 0.05 + 0.95 * rand() / (double)RAND_MAX;
    getme__adj_sums_all(&adj, ws, q);
    int exact = 1;
    for (int32_t e = 0; e < ws->ne; e++) {
        int32_t cnt;
        double s = brute(ws, q, e, &cnt, mark, (uint32_t)e + 1);
        if (adj.irregular[e])
            continue;
        double f = getme__adj_nsum(&adj, ws, q, getme__ws_type(ws, e), e);
        if (fabs(f - s) > 1e-12 * s || adj.count[e] != cnt) {
            exact = 0;
            fprintf(stderr, "element %d: formula %.17g (count %d), union %.17g "
                    "(count %d)\n", (int)e, f, (int)adj.count[e], s, (int)cnt);
        }
    }
    CHECK(exact);
    check_blocks(&adj.blk, ws);
    free(check_group(&adj.blk, ws));
    uint8_t *irr = malloc((size_t)ws->ne);
    memcpy(irr, adj.irregular, (size_t)ws->ne);
    getme__adj_free(&adj);
    free(q), free(mark);
    *mesh_out = mesh;
    return irr;
}

/* Conforming meshes: every element regular, every sum exact, and the same
   flags and sums for 1 and 2 threads. */
static void check_conforming(const char *kind)
{
    gen g = make(kind);
    for (int nt = 1; nt <= 2; nt++) {
        getme_ws ws;
        getme_mesh *mesh;
        uint8_t *irr = check_formula(&g, nt, &ws, &mesh);
        int32_t nirr = 0;
        for (int32_t e = 0; e < ws.ne; e++)
            nirr += irr[e];
        if (nirr != 0)
            fprintf(stderr, "%s: %d irregular elements\n", kind, (int)nirr);
        CHECK_EQ_INT(nirr, 0);
        free(irr);
        getme__ws_free(&ws);
        getme_mesh_free(mesh);
    }
    free_gen(&g);
}

/* Which caller elements did adj flag? */
static int flagged(const getme_ws *ws, const uint8_t *irr, int32_t caller_elem)
{
    for (int32_t e = 0; e < ws->ne; e++)
        if (ws->elem_orig[e] == caller_elem)
            return irr[e];
    return -1;
}

/* Non-conforming meshes: the elements the formula would miscount are
   flagged (check_formula proves the others exact). */
static void check_nonconforming(void)
{
    /* Three tets on one face (0,1,2), and a duplicate of the first. */
    gen g;
    memset(&g, 0, sizeof g);
    g.dim = 3;
    add_node(&g, 0, 0, 0), add_node(&g, 1, 0, 0), add_node(&g, 0, 1, 0);
    add_node(&g, 0, 0, 1), add_node(&g, 0, 0, -1), add_node(&g, 1, 1, 1);
    add_node(&g, 3, 3, 3);
    int32_t t0[4] = {0, 1, 2, 3}, t1[4] = {0, 2, 1, 4}, t2[4] = {0, 1, 2, 5};
    int32_t t3[4] = {3, 5, 6, 1};
    add_elem(&g, GETME_TET, t0), add_elem(&g, GETME_TET, t1);
    add_elem(&g, GETME_TET, t2), add_elem(&g, GETME_TET, t3);
    getme_ws ws;
    getme_mesh *mesh;
    uint8_t *irr = check_formula(&g, 2, &ws, &mesh);
    CHECK_EQ_INT(flagged(&ws, irr, 0), 1);
    CHECK_EQ_INT(flagged(&ws, irr, 1), 1);
    CHECK_EQ_INT(flagged(&ws, irr, 2), 1);
    free(irr), getme__ws_free(&ws), getme_mesh_free(mesh), free_gen(&g);

    memset(&g, 0, sizeof g);
    g.dim = 3;
    add_node(&g, 0, 0, 0), add_node(&g, 1, 0, 0), add_node(&g, 0, 1, 0);
    add_node(&g, 0, 0, 1), add_node(&g, 2, 2, 2);
    int32_t d0[4] = {0, 1, 2, 3}, d1[4] = {0, 1, 2, 3}, d2[4] = {1, 2, 3, 4};
    add_elem(&g, GETME_TET, d0), add_elem(&g, GETME_TET, d1);
    add_elem(&g, GETME_TET, d2);
    irr = check_formula(&g, 1, &ws, &mesh);
    CHECK_EQ_INT(flagged(&ws, irr, 0), 1); /* the duplicates */
    CHECK_EQ_INT(flagged(&ws, irr, 1), 1);
    free(irr), getme__ws_free(&ws), getme_mesh_free(mesh), free_gen(&g);

    /* A tet whose edge is the diagonal 4-6 of a hex's top face: neither
       the hex nor the tet has that pair as a common edge or face. */
    memset(&g, 0, sizeof g);
    g.dim = 3;
    int32_t h[8];
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++)
                add_node(&g, i, j, k);
    int32_t order[8] = {0, 1, 3, 2, 4, 5, 7, 6}; /* lexicographic -> hex */
    for (int i = 0; i < 8; i++)
        h[i] = order[i];
    add_elem(&g, GETME_HEX, h);
    int32_t a = add_node(&g, 0.2, 0.8, 2), b = add_node(&g, 0.9, 0.1, 2.5);
    int32_t tt[4] = {h[4], h[6], a, b};
    add_elem(&g, GETME_TET, tt);
    irr = check_formula(&g, 2, &ws, &mesh);
    int32_t tet_caller = 0, hex_caller = 1; /* to_mesh adds types in enum order */
    CHECK_EQ_INT(flagged(&ws, irr, hex_caller), 1);
    CHECK_EQ_INT(flagged(&ws, irr, tet_caller), 1);
    free(irr), getme__ws_free(&ws), getme_mesh_free(mesh), free_gen(&g);
}

/* ---- the same set-up for any number of threads ------------------------ */

#define SAME(a, b, n) CHECK(!memcmp((a), (b), (size_t)(n) * sizeof *(a)))

/* The workspace, face table, edges, counts, flags and the blocks' node
   lists built with nt threads are those built with one, entry for entry
   (each thread takes other nodes, elements and blocks, so a race or an
   order that depends on the split would show). */
static void same_setup(const getme_ws *a, const getme_adj *aa,
                       const getme_ws *b, const getme_adj *ab)
{
    CHECK_EQ_INT(a->nn, b->nn);
    CHECK_EQ_INT(a->ne, b->ne);
    if (a->nn != b->nn || a->ne != b->ne)
        return;
    int64_t nc = 0, ns = 0, nf = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int32_t n = a->tstart[t + 1] - a->tstart[t];
        nc += (int64_t)n * getme__nv[t];
        ns += (int64_t)n * getme__edges[t].num_edges;
        nf += (int64_t)n * getme__faces[t].num_faces;
    }
    SAME(a->tstart, b->tstart, GETME_NUM_TYPES + 1);
    SAME(a->conn, b->conn, nc);
    SAME(a->elem_orig, b->elem_orig, a->ne);
    SAME(a->node_orig, b->node_orig, a->nn);
    SAME(a->x, b->x, 3 * (int64_t)a->nn);
    SAME(a->star_ptr, b->star_ptr, a->nn + 1);
    SAME(a->star, b->star, nc);
    CHECK_EQ_INT(a->max_star, b->max_star);
    SAME(a->fixed, b->fixed, a->nn);
    SAME(a->free_elem, b->free_elem, a->ne);
    CHECK_EQ_INT(a->num_free_elem, b->num_free_elem);
    CHECK_EQ_INT(a->num_free_nodes, b->num_free_nodes);
    CHECK_EQ_INT(a->num_blocks, b->num_blocks);
    if (a->num_blocks == b->num_blocks) {
        SAME(a->block_start, b->block_start, a->num_blocks + 1);
        SAME(aa->blk.nptr, ab->blk.nptr, a->num_blocks + 1);
        SAME(aa->blk.nodes, ab->blk.nodes, aa->blk.nptr[a->num_blocks]);
        /* the local connectivity follows from these and conn (it is
           rebuilt per block: getme__blocks_localise) */
    }
    SAME(aa->fnb.d, ab->fnb.d, nf);
    int64_t nch = (nf + GETME_FNB_CHUNK - 1) / GETME_FNB_CHUNK;
    SAME(aa->fnb.cptr, ab->fnb.cptr, nch + 1);
    if (aa->fnb.cptr[nch] == ab->fnb.cptr[nch]) {
        SAME(aa->fnb.enb, ab->fnb.enb, aa->fnb.cptr[nch]);
    }
    SAME(aa->count, ab->count, a->ne);
    SAME(aa->irregular, ab->irregular, a->ne);
    CHECK_EQ_INT(aa->num_irregular, ab->num_irregular);
    CHECK(aa->qscale == ab->qscale);
    if (a->dim == 3) {
        CHECK_EQ_INT(aa->num_edges, ab->num_edges);
        int64_t ediff = 0;
        for (int64_t v = 0; v <= a->nn; v++)
            ediff += getme__offs_at(&aa->eptr, v) != getme__offs_at(&ab->eptr, v);
        CHECK(ediff == 0);
        SAME(aa->eslot, ab->eslot, ns);
    }
}

/* ---- the face table against a plain construction -------------------- */

typedef struct ref_side {
    int32_t key[4]; /* the face's nodes, sorted, -1 padded */
    int32_t elem, face;
} ref_side;

static int cmp_side(const void *pa, const void *pb)
{
    const ref_side *a = pa, *b = pb;
    for (int i = 0; i < 4; i++)
        if (a->key[i] != b->key[i])
            return a->key[i] < b->key[i] ? -1 : 1;
    return a->elem != b->elem ? (a->elem < b->elem ? -1 : 1)
                              : (a->face > b->face) - (a->face < b->face);
}

static int same_nodes(const getme_ws *ws, int32_t a, int32_t b)
{
    int ta = getme__ws_type(ws, a), tb = getme__ws_type(ws, b);
    if (ta != tb)
        return 0;
    int32_t x[GETME_MAX_NV], y[GETME_MAX_NV];
    int nv = getme__nv[ta];
    memcpy(x, getme__ws_nodes(ws, ta, a), (size_t)nv * sizeof *x);
    memcpy(y, getme__ws_nodes(ws, tb, b), (size_t)nv * sizeof *y);
    for (int i = 1; i < nv; i++) /* insertion sorts of <= 8 */
        for (int j = i; j > 0 && x[j - 1] > x[j]; j--) {
            int32_t t = x[j]; x[j] = x[j - 1]; x[j - 1] = t;
        }
    for (int i = 1; i < nv; i++)
        for (int j = i; j > 0 && y[j - 1] > y[j]; j--) {
            int32_t t = y[j]; y[j] = y[j - 1]; y[j - 1] = t;
        }
    return !memcmp(x, y, (size_t)nv * sizeof *x);
}

/* Every element face's entry of the face table (getme__ws_faces, as
   getme__adj_build keeps it) against the definition, from all sides
   sorted by their node sets: a face of one side is -1, of three or more
   GETME_FACE_IRREGULAR, of two the other element, unless the two are the
   same tet or triangle (duplicates: irregular). */
static void check_faces_reference(const getme_ws *ws, const getme_adj *adj,
                                  int duplicates)
{
    int64_t foff[GETME_NUM_TYPES];
    int64_t nf = getme__ws_face_offsets(ws, foff);
    ref_side *sd = malloc((size_t)(nf ? nf : 1) * sizeof *sd);
    int64_t m = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        const getme_face_table *ft = &getme__faces[t];
        for (int32_t e = ws->tstart[t]; e < ws->tstart[t + 1]; e++) {
            const int32_t *c = getme__ws_nodes(ws, t, e);
            for (int f = 0; f < ft->num_faces; f++, m++) {
                ref_side *r = &sd[m];
                r->elem = e, r->face = f;
                for (int i = 0; i < 4; i++)
                    r->key[i] = i < ft->size[f] ? c[ft->node[f][i]] : -1;
                for (int i = 1; i < ft->size[f]; i++)
                    for (int j = i; j > 0 && r->key[j - 1] > r->key[j]; j--) {
                        int32_t tmp = r->key[j];
                        r->key[j] = r->key[j - 1];
                        r->key[j - 1] = tmp;
                    }
            }
        }
    }
    qsort(sd, (size_t)m, sizeof *sd, cmp_side);
    int64_t bad = 0, irregular = 0, two = 0;
    for (int64_t a = 0, b; a < m; a = b) {
        for (b = a + 1; b < m && !memcmp(sd[a].key, sd[b].key, sizeof sd[a].key); b++)
            ;
        for (int64_t k = a; k < b; k++) {
            int32_t e = sd[k].elem, want = -1;
            int t = getme__ws_type(ws, e);
            if (b - a > 2) {
                want = GETME_FACE_IRREGULAR;
            } else if (b - a == 2) {
                int32_t o = sd[k == a ? a + 1 : a].elem;
                int simplex = t == GETME_TET || t == GETME_TRI;
                want = simplex && same_nodes(ws, e, o) ? GETME_FACE_IRREGULAR : o;
                two++;
            }
            irregular += want == GETME_FACE_IRREGULAR;
            int32_t got = getme__facenb_at(
                &adj->fnb,
                foff[t] + (int64_t)(e - ws->tstart[t]) * getme__faces[t].num_faces +
                    sd[k].face,
                e);
            if (got != want && bad++ < 5)
                fprintf(stderr, "element %d face %d: table %d, reference %d\n",
                        (int)e, (int)sd[k].face, (int)got, (int)want);
        }
    }
    CHECK_EQ_INT((int)bad, 0);
    CHECK(two > 0);
    CHECK(duplicates ? irregular > 0 : irregular == 0);
    free(sd);
}

static void check_threads(const char *kind, int duplicates)
{
    int n0 = N;
    int planar = !strncmp(kind, "tri", 3) || !strcmp(kind, "quad");
    N = planar ? 40 : 13; /* more than 3 blocks */
    gen g = make(kind);
    /* duplicate elements: faces of three sides and twin simplices, so
       the irregular paths run too */
    if (duplicates)
        add_twins(&g);
    /* with duplicates, also three nodes used by no element: they are
       numbered last, after the first-touch numbering (which 2 and 3
       threads do by ranges merged in order), so its count must be
       exact */
    for (int k = 0; k < 3 * duplicates; k++)
        add_node(&g, 0.5 + k, 0.5 + k, g.dim == 2 ? 0.0 : 0.5 + k);
    /* jittered, so the Morton keys differ (ties would keep input order) */
    srand(11);
    for (int32_t i = 0; i < 3 * g.nn; i++)
        g.xyz[i] += 0.2 * ((double)rand() / RAND_MAX - 0.5);
    if (g.dim == 2)
        for (int32_t i = 0; i < g.nn; i++)
            g.xyz[3 * i + 2] = 0.0;
    getme_mesh *mesh = to_mesh(&g);
    CHECK(getme_mesh_fix_boundary(mesh, GETME_FIX_SKIN, NULL) == GETME_OK);
    getme__mesh_drop_ws(mesh); /* built here, with each thread count */
    getme_ws ws[3];
    getme_adj adj[3];
    for (int k = 0; k < 3; k++) {
        CHECK(getme__ws_build(&ws[k], mesh, 1, k + 1) == GETME_OK);
        CHECK(getme__adj_build(&adj[k], &ws[k]) == GETME_OK);
    }
    CHECK(ws[0].nn > 500 && ws[0].num_blocks > 3);
    CHECK(duplicates ? adj[0].num_irregular > 0 : 1);
    check_faces_reference(&ws[0], &adj[0], duplicates);
    check_faces_reference(&ws[2], &adj[2], duplicates);
    for (int k = 1; k < 3; k++)
        same_setup(&ws[0], &adj[0], &ws[k], &adj[k]);
    for (int k = 0; k < 3; k++) {
        getme__adj_free(&adj[k]);
        getme__ws_free(&ws[k]);
    }
    getme_mesh_free(mesh);
    free_gen(&g);
    N = n0;
}

/* The blocks' own edge lists (block_edges.h) against the global edge ids:
   every tet edge's list entry is its id, no list holds an edge twice,
   every edge is in some list, and 1, 2 and 3 threads build the same
   lists; other meshes get none (their sweeps take the global path).
   With duplicates (twin tets, irregular faces) too. */
static void check_block_edges(const char *kind, int duplicates)
{
    int n0 = N;
    N = 13; /* more than 3 blocks */
    gen g = make(kind);
    if (duplicates)
        add_twins(&g);
    getme_mesh *mesh = to_mesh(&g);
    int64_t *ref_ptr = NULL;
    int32_t *ref_edges = NULL;
    uint16_t *ref_ledge = NULL;
    for (int nt = 1; nt <= 3; nt++) {
        getme_ws ws;
        getme_adj adj;
        CHECK(getme__ws_build(&ws, mesh, 1, nt) == GETME_OK);
        CHECK(getme__adj_build(&adj, &ws) == GETME_OK);
        getme__blocks_edges(&adj.blk, &adj, &ws);
        const getme_blocks *blk = &adj.blk;
        if (strcmp(kind, "tet")) {
            CHECK(blk->ledge == NULL && blk->edges == NULL);
            getme__adj_free(&adj);
            getme__ws_free(&ws);
            continue;
        }
        CHECK(blk->ledge != NULL && blk->edges != NULL && ws.num_blocks > 3);
        int64_t total = blk->eptr[ws.num_blocks];
        uint8_t *seen = calloc((size_t)adj.num_edges + 1, 1);
        int32_t *inlist = calloc((size_t)adj.num_edges + 1, sizeof *inlist);
        int missing = 0;
        for (int32_t b = 0; b < ws.num_blocks; b++) {
            int64_t n = blk->eptr[b + 1] - blk->eptr[b];
            CHECK(n > 0 && n <= blk->estride);
            for (int64_t k = blk->eptr[b]; k < blk->eptr[b + 1]; k++) {
                int32_t id = blk->edges[k];
                CHECK(id >= -1 && id < adj.num_edges);
                /* distinct within the block: the last block it was in */
                CHECK(inlist[id + 1] != b + 1);
                inlist[id + 1] = b + 1;
                seen[id + 1] = 1;
            }
            for (int32_t e = ws.block_start[b]; e < ws.block_start[b + 1]; e++) {
                int32_t id[12];
                getme__adj_edge_ids(&adj, getme__ws_nodes(&ws, GETME_TET, e),
                                    GETME_TET,
                                    getme__adj_slots(&adj, &ws, GETME_TET, e),
                                    id);
                const uint16_t *le = getme__blocks_ledge(blk, e);
                CHECK_EQ_INT(getme__blocks_of(blk, &ws, GETME_TET, e), b);
                for (int j = 0; j < 6; j++) {
                    CHECK(le[j] < n);
                    CHECK_EQ_INT(blk->edges[blk->eptr[b] + le[j]], id[j]);
                    missing += id[j] < 0;
                }
            }
        }
        int32_t listed = 0;
        for (int32_t i = 1; i <= adj.num_edges; i++)
            listed += seen[i];
        CHECK_EQ_INT(listed, adj.num_edges);
        CHECK_EQ_INT(missing, 0); /* twins share their edges' slots */
        free(seen), free(inlist);
        if (!ref_ptr) {
            ref_ptr = malloc((size_t)(ws.num_blocks + 1) * sizeof *ref_ptr);
            ref_edges = malloc((size_t)total * sizeof *ref_edges);
            ref_ledge = malloc((size_t)ws.ne * 6 * sizeof *ref_ledge);
            memcpy(ref_ptr, blk->eptr, (size_t)(ws.num_blocks + 1) * sizeof *ref_ptr);
            memcpy(ref_edges, blk->edges, (size_t)total * sizeof *ref_edges);
            memcpy(ref_ledge, blk->ledge, (size_t)ws.ne * 6 * sizeof *ref_ledge);
        } else {
            CHECK(memcmp(ref_ptr, blk->eptr,
                         (size_t)(ws.num_blocks + 1) * sizeof *ref_ptr) == 0);
            CHECK(memcmp(ref_edges, blk->edges, (size_t)total * sizeof *ref_edges) == 0);
            CHECK(memcmp(ref_ledge, blk->ledge, (size_t)ws.ne * 6 * sizeof *ref_ledge) == 0);
        }
        getme__blocks_free_local(&adj.blk);
        CHECK(adj.blk.ledge == NULL && adj.blk.edges == NULL);
        getme__adj_free(&adj);
        getme__ws_free(&ws);
    }
    free(ref_ptr), free(ref_edges), free(ref_ledge);
    getme_mesh_free(mesh);
    free_gen(&g);
    N = n0;
}

int main(void)
{
    const char *kinds[] = {"tet", "hex", "mixed", "tri", "quad", "tri+quad"};
    for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++)
        check_conforming(kinds[i]);
    check_nonconforming();
    check_block_order();
    check_live_sums();
    check_tail_bookkeeping();
    check_block_edges("tet", 0);
    check_block_edges("tet", 1);
    check_block_edges("hex", 0);
    check_block_edges("mixed", 0);
    check_ring_orders("tet");
    check_ring_orders("hex");
    check_ring_orders("mixed");
    for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++) {
        check_threads(kinds[i], 0);
        check_threads(kinds[i], 1);
    }
    return check_summary("test_adjacency");
}
