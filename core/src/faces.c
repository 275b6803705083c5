/*
 * faces.c -- which element lies across each face (each edge of a planar
 * element), for the skin and interface search (topology.c) and the Eq. 9
 * sums (adjacency.c).
 *
 * Every face is met at its lowest node: walking that node's star, each
 * element contributes the faces it has there whose other nodes are all
 * higher, keyed by those other nodes (sorted); sides with equal keys are
 * the same face.  No global face table is built (a short per-thread list
 * groups the sides met at one node), each loop iteration
 * writes only the entries of faces whose lowest node it owns (race-free),
 * and the node order of the workspace keeps the stars it reads in cache.
 */
#include "workspace.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

int64_t getme__ws_face_offsets(const getme_ws *ws,
                               int64_t foff[GETME_NUM_TYPES])
{
    int64_t total = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        foff[t] = total;
        total += (int64_t)(ws->tstart[t + 1] - ws->tstart[t]) *
                 getme__faces[t].num_faces;
    }
    return total;
}

/* The node of a simplex face f's element not on f (tet: 6 minus the sum
   of the face's local nodes, triangle: 3 minus it), or -1. */
static int apex(int t, int f)
{
    const getme_face_table *ft = &getme__faces[t];
    int sum = 0;
    for (int i = 0; i < ft->size[f]; i++)
        sum += ft->node[f][i];
    return t == GETME_TET ? 6 - sum : t == GETME_TRI ? 3 - sum : -1;
}

/* The faces of each type at each corner, with the face's other corners:
   built from getme__faces once per call (a few hundred bytes). */
typedef struct corner_faces {
    int8_t num;        /* faces at this corner                  */
    int8_t face[4];    /* which faces                           */
    int8_t size[4];    /* how many other corners each has       */
    int8_t other[4][3];
    int8_t apex[4];    /* simplices: the corner not on the face, else -1 */
} corner_faces;

static void corner_table(corner_faces table[GETME_NUM_TYPES][GETME_MAX_NV])
{
    memset(table, 0, sizeof(corner_faces) * GETME_NUM_TYPES * GETME_MAX_NV);
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        const getme_face_table *ft = &getme__faces[t];
        for (int f = 0; f < ft->num_faces; f++)
            for (int j = 0; j < ft->size[f]; j++) {
                corner_faces *cf = &table[t][ft->node[f][j]];
                int k = cf->num++;
                cf->face[k] = (int8_t)f;
                cf->size[k] = (int8_t)(ft->size[f] - 1);
                for (int i = 1; i < ft->size[f]; i++)
                    cf->other[k][i - 1] = ft->node[f][(j + i) % ft->size[f]];
                cf->apex[k] = (int8_t)apex(t, f);
            }
    }
}

/* A face seen from its lowest node: the other nodes, sorted (-1 padded),
   how many sides (element faces) it has, and its first two. */
typedef struct face_group {
    int32_t k[3];
    int32_t n, first, second;
    int32_t slot; /* in the hash table */
} face_group;

/* One side: the element, which face of it, its group. */
typedef struct face_side {
    int32_t elem, face, group;
    int32_t apex; /* simplices: the element's node not on the face; -1 */
} face_side;

/* Are the two sides of a two-sided face the same simplex (duplicate
   elements)?  They share the face's nodes, so exactly when their apexes
   are the same node, read when the side was met (its element's row then
   in cache).  Other types' sides have apex -1: a side of a tet and one
   of a prism or pyramid are never the same element. */
static inline int same_simplex(const face_side *a, const face_side *b)
{
    return (a->apex >= 0) & (a->apex == b->apex);
}

/* The faces whose lowest node is u: every side in sides, grouped by its
   other nodes into groups through the hash table (all -1 on entry and on
   return; mask + 1 slots, at least twice the sides: a linear search of
   the ~11 faces a node has in a tet mesh was slower).  Returns how many
   sides; *ng: how many groups.  tf: the mesh's one type (a constant in
   each inlined copy), or -1.
   Two passes: the star's faces at u are first written as candidates, each
   kept (the count advanced) only if u is its lowest node, without a
   branch: whether it is, is a coin toss (about one face in three at a
   corner), and its mispredictions were most of the walk's cost.  The
   keys' other nodes are sorted by a min/max network, also branch-free. */
static inline __attribute__((always_inline)) int
faces_at(int tf, const getme_ws *ws,
         corner_faces table[GETME_NUM_TYPES][GETME_MAX_NV], int32_t u,
         face_side *sides, face_group *groups, int32_t *hash, uint32_t mask,
         int *ng)
{
    int m = 0, g = 0;
    /* Local copies: the stores into sides and groups may alias anything,
       so ws's fields were reloaded for every star entry (getme__ws_nodes
       alone was ~15 % of the walk's instructions). */
    const int32_t *star = ws->star;
    int32_t s0 = ws->star_ptr[u], s1 = ws->star_ptr[u + 1];
    int32_t kend = ws->star_ptr[ws->nn];
    int tc = tf >= 0 ? tf : 0;
    const int32_t *conn_tf = ws->conn + ws->coff[tc];
    int32_t t0 = ws->tstart[tc];
    /* groups[] doubles as the candidates' key store: a candidate's key
       goes to groups[m].k until the second pass moves it into its group
       (groups are numbered in first-seen order, so group q <= candidate
       m and is written only after candidate m was read). */
    for (int32_t s = s0; s < s1; s++) {
        int32_t n = star[s];
        /* the mesh's one type: its corner count a constant, so the local
           index loop below unrolls */
        int t = tf >= 0 ? tf : getme__ws_type(ws, n);
        int nv = tf == GETME_TET ? 4 : tf == GETME_HEX ? 8 : getme__nv[t];
        if (tf >= 0 && s + GETME_STAR_AHEAD < kend)
            __builtin_prefetch(conn_tf + (int64_t)(star[s + GETME_STAR_AHEAD] - t0) * nv);
        const int32_t *c = tf >= 0 ? conn_tf + (int64_t)(n - t0) * nv
                                   : getme__ws_nodes(ws, t, n);
        int li = 0;
        for (int i = 1; i < nv; i++)
            li |= (c[i] == u) * i;
        const corner_faces *cf = &table[t][li];
        /* In a tet or hex mesh every corner is on 3 faces of 3 or 4
           nodes: as constants the loop unrolls and the "none" selects
           fold away. */
        int nf = tf == GETME_TET || tf == GETME_HEX ? 3 : cf->num;
        for (int k = 0; k < nf; k++) {
            int size = tf == GETME_TET ? 2 : tf == GETME_HEX ? 3 : cf->size[k];
            /* INT32_MAX stands for "none" (a face of 2 or 3 nodes): it
               passes the test and sorts last */
            int32_t a = c[cf->other[k][0]];
            int32_t b = size > 1 ? c[cf->other[k][1]] : INT32_MAX;
            int32_t d = size > 2 ? c[cf->other[k][2]] : INT32_MAX;
            int lowest = (a > u) & (b > u) & (d > u);
            int32_t lo = a < b ? a : b, hi = a < b ? b : a;
            int32_t k0 = lo < d ? lo : d, mid = lo < d ? d : lo;
            int32_t k1 = mid < hi ? mid : hi, k2 = mid < hi ? hi : mid;
            face_group *r = &groups[m];
            r->k[0] = k0;
            r->k[1] = k1 == INT32_MAX ? -1 : k1;
            r->k[2] = k2 == INT32_MAX ? -1 : k2;
            /* a tet's faces all have an apex: no test */
            int8_t ap = tf == GETME_HEX ? -1 : cf->apex[k];
            int32_t apn = tf == GETME_TET ? c[ap] : ap >= 0 ? c[ap] : -1;
            sides[m] = (face_side){n, cf->face[k], 0, apn};
            m += lowest;
        }
    }
    for (int i = 0; i < m; i++) {
        int32_t o0 = groups[i].k[0], o1 = groups[i].k[1], o2 = groups[i].k[2];
        uint32_t h = (((uint32_t)o0 * 0x9E3779B1u) ^
                      ((uint32_t)o1 * 0x85EBCA77u) ^
                      ((uint32_t)o2 * 0xC2B2AE3Du));
        h = (h ^ (h >> 15)) & mask;
        /* Probing past a slot taken by another face is rare (the table
           is at least 8 times the sides); whether the face is new or
           seen before is a coin toss, so that is decided by selects.
           The probe's test too: `hash[h] >= 0 && !same key` branched
           on the empty slot first (a coin toss, half the sides
           mispredicted); here the key is compared against group 0 when
           the slot is empty (groups[0] always exists) and only "taken by
           another face" branches. */
        int32_t q0;
        for (;;) {
            q0 = hash[h];
            /* all ones if the slot is taken, by a shift: with a compare
               gcc rebuilt the coin-toss branch */
            uint32_t occ = -((~(uint32_t)q0) >> 31);
            const face_group *p = &groups[q0 & (int32_t)occ];
            uint32_t diff = ((uint32_t)p->k[0] ^ (uint32_t)o0) |
                            ((uint32_t)p->k[1] ^ (uint32_t)o1) |
                            ((uint32_t)p->k[2] ^ (uint32_t)o2);
            if (__builtin_expect((diff & occ) == 0, 1))
                break;
            h = (h + 1) & mask;
        }
        /* The group's update by masks (fm: all ones if the face is new,
           n0 == 1: its second side): gcc turned each select on "new"
           back into a coin-toss branch.  A new group's old fields are
           read and masked away. */
        int32_t fm = -(int32_t)((uint32_t)q0 >> 31);
        int32_t q = (g & fm) | (q0 & ~fm);
        face_group *r = &groups[q];
        int32_t n0 = r->n & ~fm;
        int32_t m1 = -(int32_t)(n0 == 1);
        r->second = (i & m1) | (r->second & ~m1) | fm;
        r->first = (i & fm) | (r->first & ~fm);
        r->k[0] = o0, r->k[1] = o1, r->k[2] = o2;
        r->n = n0 + 1;
        r->slot = (int32_t)h;
        hash[h] = q;
        g -= fm;
        sides[i].group = q;
    }
    for (int i = 0; i < g; i++)
        hash[groups[i].slot] = -1;
    *ng = g;
    return m;
}

/* The out entries of the faces whose lowest node is u (tf: the mesh's
   one type, or -1). */
static inline __attribute__((always_inline)) void
faces_node(int tf, const getme_ws *ws,
           corner_faces table[GETME_NUM_TYPES][GETME_MAX_NV], int32_t u,
           face_side *sd, face_group *gr, int32_t *hs, uint32_t mask,
           const int64_t *foff, int32_t *out)
{
    int ng;
    int m = faces_at(tf, ws, table, u, sd, gr, hs, mask, &ng);
    for (int i = 0; i < m; i++) {
        const face_group *r = &gr[sd[i].group];
        int32_t v = -1;
        if (r->n > 2) {
            v = GETME_FACE_IRREGULAR;
        } else if (r->n == 2) {
            /* i is first or second: the other one without a branch
               (which one is a coin toss) */
            const face_side *other = &sd[r->first ^ r->second ^ i];
            v = same_simplex(&sd[i], other) ? GETME_FACE_IRREGULAR
                                            : other->elem;
        }
        int t = tf >= 0 ? tf : getme__ws_type(ws, sd[i].elem);
        out[foff[t] + (int64_t)(sd[i].elem - ws->tstart[t]) *
                          getme__faces[t].num_faces + sd[i].face] = v;
    }
}

getme_status getme__ws_faces(const getme_ws *ws, const int64_t *foff,
                             int32_t *out)
{
    static const int max_faces_at_corner = 4; /* pyramid apex */
    size_t bufsize = (size_t)ws->max_star * max_faces_at_corner + 1;
    face_side *sides = getme__malloc((size_t)ws->nt * bufsize * sizeof *sides);
    face_group *groups =
        getme__malloc((size_t)ws->nt * bufsize * sizeof *groups);
    size_t hsize = 16;
    while (hsize < 2 * bufsize)
        hsize *= 2;
    int32_t *hashes = getme__malloc((size_t)ws->nt * hsize * sizeof *hashes);
    if (!sides || !groups || !hashes) {
        free(sides), free(groups), free(hashes);
        return GETME_ERR_NOMEM;
    }
    memset(hashes, 0xff, (size_t)ws->nt * hsize * sizeof *hashes);
    corner_faces table[GETME_NUM_TYPES][GETME_MAX_NV];
    corner_table(table);
    int single = getme__ws_single_type(ws);
#pragma omp parallel for schedule(dynamic, 1024) num_threads(ws->nt)
    for (int32_t u = 0; u < ws->nn; u++) {
        int th = omp_get_thread_num();
        face_side *sd = sides + (size_t)th * bufsize;
        face_group *gr = groups + (size_t)th * bufsize;
        int32_t *hs = hashes + (size_t)th * hsize;
        uint32_t mask = (uint32_t)(hsize - 1);
        if (single == GETME_TET)
            faces_node(GETME_TET, ws, table, u, sd, gr, hs, mask, foff, out);
        else if (single == GETME_HEX)
            faces_node(GETME_HEX, ws, table, u, sd, gr, hs, mask, foff, out);
        else
            faces_node(-1, ws, table, u, sd, gr, hs, mask, foff, out);
    }
    free(sides), free(groups), free(hashes);
    return GETME_OK;
}
