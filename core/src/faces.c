/*
 * faces.c -- which element lies across each face (each edge of a planar
 * element), for the skin and interface search (topology.c) and the Eq. 9
 * sums (adjacency.c).
 *
 * Every face is met at its lowest node: walking that node's star, each
 * element contributes the faces it has there whose other nodes are all
 * higher, keyed by those other nodes (sorted); sides with equal keys are
 * the same face.  No global face table is built (a small per-thread hash
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

/* The faces of each type at each corner, with the face's other corners:
   built from getme__faces once per call (a few hundred bytes). */
typedef struct corner_faces {
    int8_t num;        /* faces at this corner                  */
    int8_t face[4];    /* which faces                           */
    int8_t size[4];    /* how many other corners each has       */
    int8_t other[4][3];
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
            }
    }
}

/* One side of a face seen from its lowest node: the other nodes, sorted
   (-1 padded), and which element face it is; rep: the first side with the
   same key (its group), and for that first side, how many sides the group
   has (n), the second one (second) and its hash slot (slot). */
typedef struct face_key {
    int32_t k[3];
    int32_t elem;
    int32_t face;
    int32_t rep, n, second, slot;
} face_key;

static inline int key_same(const face_key *a, const face_key *b)
{
    return a->k[0] == b->k[0] && a->k[1] == b->k[1] && a->k[2] == b->k[2];
}

static inline uint32_t key_hash(const face_key *a)
{
    uint32_t h = (uint32_t)a->k[0] * 0x9E3779B1u ^
                 (uint32_t)a->k[1] * 0x85EBCA77u ^
                 (uint32_t)a->k[2] * 0xC2B2AE3Du;
    return h ^ (h >> 15);
}

/* The faces whose lowest node is u, as keys in buf, grouped by key through
   the hash table (all -1 on entry and on return; mask + 1 slots, at least
   twice the sides).  Only the groups matter, not their order, so no sort
   is needed: a hash lookup per side is linear in the star, where the
   sorted insertion it replaces was quadratic.  Returns how many sides. */
static int faces_at(const getme_ws *ws,
                    corner_faces table[GETME_NUM_TYPES][GETME_MAX_NV],
                    int32_t u, face_key *buf, int32_t *hash, uint32_t mask)
{
    int m = 0;
    for (int64_t s = ws->star_ptr[u]; s < ws->star_ptr[u + 1]; s++) {
        int32_t n = ws->star[s];
        int t = getme__ws_type(ws, n);
        const int32_t *c = getme__ws_nodes(ws, t, n);
        const corner_faces *cf = &table[t][getme__local_index(c, getme__nv[t], u)];
        for (int k = 0; k < cf->num; k++) {
            int32_t o[3] = {-1, -1, -1};
            int lowest = 1;
            for (int i = 0; i < cf->size[k]; i++) {
                o[i] = c[cf->other[k][i]];
                lowest &= o[i] > u;
            }
            if (!lowest)
                continue;
            for (int i = 1; i < cf->size[k]; i++) /* sort the <= 3 others */
                for (int j = i; j > 0 && o[j - 1] > o[j]; j--) {
                    int32_t tmp = o[j];
                    o[j] = o[j - 1];
                    o[j - 1] = tmp;
                }
            face_key *key = &buf[m];
            *key = (face_key){{o[0], o[1], o[2]}, n, cf->face[k], m, 1, -1, 0};
            uint32_t h = key_hash(key) & mask;
            while (hash[h] >= 0 && !key_same(&buf[hash[h]], key))
                h = (h + 1) & mask;
            if (hash[h] < 0) {
                hash[h] = m;
                key->slot = (int32_t)h;
            } else {
                face_key *r = &buf[hash[h]];
                key->rep = hash[h];
                if (r->n++ == 1)
                    r->second = m;
            }
            m++;
        }
    }
    for (int i = 0; i < m; i++)
        if (buf[i].rep == i)
            hash[buf[i].slot] = -1;
    return m;
}

/* Do simplices a and b have the same nodes (duplicates)? */
static int same_simplex(const getme_ws *ws, int32_t a, int32_t b)
{
    int ta = getme__ws_type(ws, a), tb = getme__ws_type(ws, b);
    if (ta != tb || (ta != GETME_TET && ta != GETME_TRI))
        return 0;
    const int32_t *ca = getme__ws_nodes(ws, ta, a), *cb = getme__ws_nodes(ws, tb, b);
    for (int i = 0; i < getme__nv[ta]; i++)
        if (getme__local_index(cb, getme__nv[tb], ca[i]) < 0)
            return 0;
    return 1;
}

/* Entry of out for face f of element e. */
static inline int32_t *slot(const getme_ws *ws, const int64_t *foff,
                            int32_t *out, int32_t e, int f)
{
    int t = getme__ws_type(ws, e);
    return out + foff[t] + (int64_t)(e - ws->tstart[t]) * getme__faces[t].num_faces + f;
}

getme_status getme__ws_faces(const getme_ws *ws, const int64_t *foff,
                             int32_t *out)
{
    static const int max_faces_at_corner = 4; /* pyramid apex */
    size_t bufsize = (size_t)ws->max_star * max_faces_at_corner + 1;
    size_t hsize = 16;
    while (hsize < 2 * bufsize)
        hsize *= 2;
    face_key *bufs = malloc((size_t)ws->nt * bufsize * sizeof *bufs);
    int32_t *hashes = malloc((size_t)ws->nt * hsize * sizeof *hashes);
    if (!bufs || !hashes) {
        free(bufs);
        free(hashes);
        return GETME_ERR_NOMEM;
    }
    memset(hashes, 0xff, (size_t)ws->nt * hsize * sizeof *hashes);
    corner_faces table[GETME_NUM_TYPES][GETME_MAX_NV];
    corner_table(table);
#pragma omp parallel for schedule(dynamic, 1024) num_threads(ws->nt)
    for (int32_t u = 0; u < ws->nn; u++) {
        int th = omp_get_thread_num();
        face_key *buf = bufs + (size_t)th * bufsize;
        int m = faces_at(ws, table, u, buf, hashes + (size_t)th * hsize,
                         (uint32_t)(hsize - 1));
        for (int i = 0; i < m; i++) {
            const face_key *r = &buf[buf[i].rep];
            int32_t v = -1;
            if (r->n > 2) {
                v = GETME_FACE_IRREGULAR;
            } else if (r->n == 2) {
                v = buf[i].rep == i ? buf[r->second].elem : r->elem;
                if (same_simplex(ws, buf[i].elem, v))
                    v = GETME_FACE_IRREGULAR;
            }
            *slot(ws, foff, out, buf[i].elem, buf[i].face) = v;
        }
    }
    free(bufs);
    free(hashes);
    return GETME_OK;
}
