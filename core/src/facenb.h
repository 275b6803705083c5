/*
 * facenb.h -- the face table (the element across each element face; each
 * edge of a planar element) in 2 bytes per face instead of 4.
 *
 * The table is read in every iteration (the Eq. 9 sums need the face
 * neighbours' qualities, adjacency.h) and lives for the whole run: 24 B
 * per hex, 16 B per tet as int32.  Elements are in Morton order, so a face
 * neighbour is mostly near: on the full benchmark meshes 95.7 % of the
 * hexes' and 96.5 % of the tets' face neighbours are within 32767 of
 * their element (docs/bench.md, session 15).  So each entry holds
 * d = nb - e as an int16: 0 means no neighbour (-1, the skin: an element
 * is never its own neighbour), a value in [INT16_MIN, INT16_MIN +
 * GETME_FNB_CHUNK) an escape, any other value the difference.  Escapes
 * (far neighbours, GETME_FACE_IRREGULAR, and an element across from
 * itself, which faces.c never gives but which must not read as skin) are
 * kept apart, 4 bytes each, chunk by chunk of GETME_FNB_CHUNK entries:
 * an escape's code is its index among its chunk's escapes (a chunk has at
 * most GETME_FNB_CHUNK), so reading it is two loads.  (A first version
 * kept each escape's position in its chunk and found it by binary search:
 * the search's dependent, unpredictable steps cost stage 1 ~6-8 % on the
 * medium meshes, docs/bench.md, session 16.)  Differences in [-32767,
 * -31745] become escapes too (the lowest direct code is -31744).
 */
#ifndef GETME_FACENB_H
#define GETME_FACENB_H

#include "workspace.h"

/* Entries per chunk of the escape index.  Escape codes are
   [GETME_FNB_ESCAPE, GETME_FNB_ESCAPE + GETME_FNB_CHUNK). */
#define GETME_FNB_CHUNK 1024
#define GETME_FNB_ESCAPE INT16_MIN

/* Pack table (getme__ws_faces' entries, laid out as foff says:
   getme__ws_face_offsets) into fb, in place: table (malloc'd) becomes
   fb->d, shrunk to 2 bytes per entry, or is freed on failure.  The same
   bytes for any thread count (ws->nt).  GETME_OK or GETME_ERR_NOMEM (fb
   then empty). */
getme_status getme__facenb_pack(getme_facenb *fb, const getme_ws *ws,
                                const int64_t *foff, int32_t *table);
void getme__facenb_free(getme_facenb *fb);

/* The neighbour across entry k of element e: an element, -1 or
   GETME_FACE_IRREGULAR. */
static inline int32_t getme__facenb_at(const getme_facenb *fb, int64_t k,
                                       int32_t e)
{
    int32_t d = fb->d[k];
    if (d == 0)
        return -1;
    if (d >= GETME_FNB_ESCAPE + GETME_FNB_CHUNK)
        return e + d;
    return fb->enb[fb->cptr[k / GETME_FNB_CHUNK] + (d - GETME_FNB_ESCAPE)];
}

/* The neighbours across all faces of element e (type t) into f[]
   (getme__faces[t].num_faces entries). */
static inline void getme__facenb_elem(const getme_facenb *fb,
                                      const getme_ws *ws, const int64_t *foff,
                                      int t, int32_t e, int32_t *f)
{
    int nf = getme__faces[t].num_faces;
    int64_t k = foff[t] + (int64_t)(e - ws->tstart[t]) * nf;
    for (int j = 0; j < nf; j++)
        f[j] = getme__facenb_at(fb, k + j, e);
}

#endif /* GETME_FACENB_H */
