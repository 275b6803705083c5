/*
 * setup.c -- the smoother's set-up alone (issue #13): the workspace build
 * (Morton order, node numbering, stars, colours), the face table, the
 * adjacency (edges, counts, the inclusion-exclusion check, the blocks'
 * node lists), each timed (CPU seconds of all threads, the best of the
 * repetitions), and a hash of every array they build, so that
 * two builds (SRC=... bench/setup.sh) or two thread counts can be
 * compared bit for bit.  Built from the core's sources with the library's
 * flags (bench/setup.sh).
 *
 *     setup MESH.raw [threads] [repetitions]
 *
 * MESH.raw: int32 dim, nodes, blocks; 3 doubles per node; per block
 * int32 type, count, then count * nodes(type) int32 node indices (0-based).
 * bench/setup.sh writes it from a .msh with Gmsh's Python module.
 */
/* adjacency.c itself, for its static phases (setup.sh leaves it out of
   the sources it compiles) */
#include "adjacency.c"

#include <malloc.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* CPU seconds of the whole process (all threads): the machine is shared,
   so wall time would count other processes' turns.  WALL=1 in the
   environment: wall seconds instead, to see the serial parts at several
   threads. */
static double cpu(void)
{
    static int wall = -1;
    if (wall < 0)
        wall = getenv("WALL") && atoi(getenv("WALL")) > 0;
    struct timespec ts;
    clock_gettime(wall ? CLOCK_MONOTONIC : CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t i = 0; i < n; i++)
        h = (h ^ c[i]) * 0x100000001b3ULL;
    return h;
}

static void *read_n(FILE *f, size_t size, size_t n)
{
    void *p = malloc(size * (n ? n : 1));
    if (!p || fread(p, size, n, f) != n) {
        fprintf(stderr, "setup: short file\n");
        exit(1);
    }
    return p;
}

static getme_mesh *load(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        exit(1);
    }
    int32_t *hd = read_n(f, sizeof(int32_t), 3);
    double *x = read_n(f, sizeof(double), 3 * (size_t)hd[1]);
    getme_mesh *mesh;
    if (getme_mesh_create(&mesh, hd[0], hd[1], x) != GETME_OK)
        exit(1);
    free(x);
    for (int b = 0; b < hd[2]; b++) {
        int32_t tc[2];
        if (fread(tc, sizeof tc, 1, f) != 1)
            exit(1);
        int nv = getme_type_num_nodes((getme_elem_type)tc[0]);
        int32_t *c = read_n(f, sizeof(int32_t), (size_t)tc[1] * nv);
        if (getme_mesh_add_elements(mesh, (getme_elem_type)tc[0], tc[1], c,
                                    NULL) != GETME_OK)
            exit(1);
        free(c);
    }
    free(hd);
    fclose(f);
    return mesh;
}

static int64_t conn_len(const getme_ws *ws)
{
    return ws->coff[GETME_NUM_TYPES - 1] +
           (int64_t)(ws->tstart[GETME_NUM_TYPES] -
                     ws->tstart[GETME_NUM_TYPES - 1]) *
               getme__nv[GETME_NUM_TYPES - 1];
}

/* Hash of everything the workspace build gives (not the thread count). */
static uint64_t ws_hash(const getme_ws *ws)
{
    size_t nn = (size_t)ws->nn, ne = (size_t)ws->ne;
    int64_t nc = conn_len(ws);
    uint64_t h = 0xcbf29ce484222325ULL;
    h = fnv(h, ws->tstart, sizeof ws->tstart);
    h = fnv(h, ws->conn, (size_t)nc * 4);
    h = fnv(h, ws->elem_orig, ne * 4);
    h = fnv(h, ws->node_orig, nn * 4);
    h = fnv(h, ws->x, nn * 24);
    h = fnv(h, ws->fixed, nn);
    h = fnv(h, ws->free_elem, ne);
    h = fnv(h, &ws->num_free_elem, 4);
    h = fnv(h, &ws->num_free_nodes, 4);
    h = fnv(h, ws->star_ptr, (nn + 1) * 4);
    h = fnv(h, ws->star, (size_t)nc * 4);
    h = fnv(h, &ws->max_star, 4);
    h = fnv(h, ws->block_start, ((size_t)ws->num_blocks + 1) * 4);
    return h;
}

static uint64_t adj_hash(const getme_adj *adj, const getme_ws *ws)
{
    size_t nn = (size_t)ws->nn, ne = (size_t)ws->ne;
    int64_t foff[GETME_NUM_TYPES];
    int64_t nf = getme__ws_face_offsets(ws, foff);
    uint64_t h = 0xcbf29ce484222325ULL;
    if (ws->dim == 3) {
        int64_t ns = 0;
        for (int t = 0; t < GETME_NUM_TYPES; t++)
            ns += (int64_t)(ws->tstart[t + 1] - ws->tstart[t]) *
                  getme__edges[t].num_edges;
        for (size_t v = 0; v <= nn; v++) { /* as int32, whatever the form */
            int32_t x = getme__offs_at(&adj->eptr, (int64_t)v);
            h = fnv(h, &x, 4);
        }
        h = fnv(h, adj->eslot, (size_t)ns);
        h = fnv(h, &adj->num_edges, 4);
    }
    /* the face table as int32 entries, whatever its form (facenb.h) */
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nft = getme__faces[t].num_faces;
        for (int32_t e = ws->tstart[t]; e < ws->tstart[t + 1]; e++) {
            int32_t f[6];
            getme__adj_faces(adj, ws, t, e, f);
            h = fnv(h, f, (size_t)nft * 4);
        }
    }
    (void)nf;
    h = fnv(h, adj->count, ne * 2);
    h = fnv(h, adj->irregular, ne);
    h = fnv(h, &adj->num_irregular, 4);
    h = fnv(h, &adj->qscale, 8);
    const getme_blocks *b = &adj->blk;
    h = fnv(h, b->nptr, ((size_t)ws->num_blocks + 1) * 8);
    h = fnv(h, b->nodes, (size_t)b->nptr[ws->num_blocks] * 4);
    /* the local connectivity as the kernels rebuild it, block by block
       (blocks hold consecutive elements: the bytes of the array it was) */
    for (int32_t k = 0; k < ws->num_blocks; k++) {
        int32_t e0 = ws->block_start[k], e1 = ws->block_start[k + 1];
        if (e1 <= e0)
            continue;
        getme__blocks_localise(b, ws, k, &b->scratch[0]);
        h = fnv(h, b->scratch[0].lconn,
                (size_t)(e1 - e0) * getme__nv[getme__ws_type(ws, e0)] * 2);
    }
    h = fnv(h, &b->max_nodes, 4);
    h = fnv(h, &b->max_elems, 4);
    return h;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: setup MESH.raw [threads] [repetitions]\n");
        return 2;
    }
    /* as the CLI does (cli/main.c): every block of 1 MiB or more is
       mapped afresh, so the set-up's temporaries pay their page faults
       in every repetition, as in the command */
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
    int nt = argc > 2 ? atoi(argv[2]) : 1;
    int reps = argc > 3 ? atoi(argv[3]) : 3;
    getme_mesh *mesh = load(argv[1]);
    omp_set_num_threads(nt);
    double t = cpu();
    if (getme_mesh_fix_boundary(mesh, GETME_FIX_SKIN, NULL) != GETME_OK)
        return 1;
    double tfix = cpu() - t;
    printf("%s: %d nodes, %d elements, %d threads\n", argv[1],
           getme_mesh_num_nodes(mesh), getme_mesh_num_elements(mesh), nt);
    printf("fix_boundary (workspace + faces) %.3f s\n", tfix);
    double best[6] = {1e30, 1e30, 1e30, 1e30, 1e30, 1e30};
    uint64_t hws = 0, hadj = 0;
    for (int r = 0; r < reps; r++) {
        getme__mesh_drop_ws(mesh);
        getme_ws ws;
        getme_adj adj;
        double t[7];
        t[0] = cpu();
        if (getme__ws_build(&ws, mesh, 1, nt) != GETME_OK)
            return 1;
        t[1] = cpu();
        int64_t foff[GETME_NUM_TYPES];
        int64_t nf = getme__ws_face_offsets(&ws, foff);
        /* the face search and its packing, as getme_mesh_fix_boundary
           does them (facenb.h) */
        int32_t *table = malloc((size_t)(nf ? nf : 1) * sizeof *table);
        if (!table || getme__ws_faces(&ws, foff, table) != GETME_OK ||
            getme__facenb_pack(&ws.faces, &ws, foff, table) != GETME_OK)
            return 1;
        t[2] = cpu();
        if (getme__adj_build(&adj, &ws) != GETME_OK)
            return 1;
        t[3] = cpu();
        /* the phases alone, on the same workspace */
        getme_adj a2;
        memset(&a2, 0, sizeof a2);
        int32_t *edeg = NULL;
        uint64_t *re = NULL;
        int check = !simplices_only(&ws);
        if (ws.dim == 3 && build_edges(&a2, &ws, &edeg, check, &re) != GETME_OK)
            return 1;
        t[4] = cpu();
        if (check) {
#if defined(GETME_ADJ_CHECK_VOID)
            void *scr = malloc(check_scratch_bytes(&ws));
            if (!scr)
                return 1;
            check_all(&adj, &ws, adj.eslot ? re : NULL, edeg, scr);
            free(scr);
#elif defined(GETME_ADJ_CHECK_SUMS_IN_WALK)
            void *scr = malloc(check_scratch_bytes(&ws));
            if (!scr || check_all(&adj, &ws, adj.eslot ? re : NULL, edeg, scr) !=
                            GETME_OK)
                return 1;
            free(scr);
#else
            uint64_t *rn = malloc((size_t)ws.nn * sizeof *rn);
            node_checks(&ws, rn);
#ifdef GETME_ADJ_LENT_SCRATCH
            void *scr = malloc(check_scratch_bytes(&ws));
            if (!scr || check_all(&adj, &ws, rn, adj.eslot ? re : NULL, edeg, scr) !=
                            GETME_OK)
                return 1;
            free(scr);
#else
            if (check_all(&adj, &ws, rn, adj.eslot ? re : NULL) != GETME_OK)
                return 1;
#endif
            free(rn);
#endif
        }
        t[5] = cpu();
        getme_blocks blk;
#ifdef GETME_ADJ_LENT_SCRATCH
        if (getme__blocks_build(&blk, &ws, NULL) != GETME_OK)
#else
        if (getme__blocks_build(&blk, &ws) != GETME_OK)
#endif
            return 1;
        t[6] = cpu();
        getme__blocks_free(&blk);
        free(edeg), free(re);
        getme__adj_free(&a2);
        for (int k = 0; k < 6; k++)
            best[k] = t[k + 1] - t[k] < best[k] ? t[k + 1] - t[k] : best[k];
        hws = ws_hash(&ws);
        hadj = adj_hash(&adj, &ws);
        getme__adj_free(&adj);
        getme__ws_free(&ws);
    }
    printf("best of %d: workspace %.3f s  faces %.3f s  adjacency %.3f s  "
           "(edges %.3f s  checks %.3f s  blocks %.3f s)  ws+faces+adjacency "
           "%.3f s\nhashes: ws %016llx adj %016llx\n",
           reps, best[0], best[1], best[2], best[3], best[4], best[5],
           best[0] + best[1] + best[2], (unsigned long long)hws,
           (unsigned long long)hadj);
    getme_mesh_free(mesh);
    return 0;
}
