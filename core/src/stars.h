/*
 * stars.h -- walking a node's star (its incident elements, ascending),
 * plain or packed.
 *
 * The stars hold every element's nodes once more (32 B per hex, 16 B per
 * tet), and the set-up reads them as plain int32 arrays (edges, faces,
 * colours).  From the smoothing loop on they are read only node by node:
 * the relaxation's steps, the q*_min stage's rings, the finishing step.
 * So getme__stars_pack stores each star as the differences of its
 * ascending elements (the first from 0), each in LEB128 (7 bits per byte,
 * the high bit set on all but a value's last byte).  Elements are in
 * Morton order, so a star's elements are near each other: on the full
 * benchmark meshes a hex mesh's star of ~7.7 elements takes ~11 bytes
 * instead of 31, a tet mesh's of ~22.6 ~27 instead of 90 (docs/bench.md,
 * session 14).  ws->star_ptr then holds byte offsets.
 *
 * Every reader after the set-up walks a star with getme__star_open and
 * getme__star_next, which read either form: the distributed part runs,
 * which never pack, and a mesh packing did not pay for.
 */
#ifndef GETME_STARS_H
#define GETME_STARS_H

#include "workspace.h"

#include <string.h>

/* Pack ws's stars in place (in parallel; the same bytes for any thread
   count) and give the block's tail back (realloc), keeping room for
   getme__ws_unpack_map's two maps.  Does nothing if already packed or if
   an element index needs more than 4 bytes (ne >= 2^28): packing then
   never grows a star.  The byte offsets then go to ws->star_offs
   (offsets.h; star_ptr NULL), which getme__ws_star_at reads.  It cannot
   fail. */
void getme__stars_pack(getme_ws *ws);

typedef struct getme_star_it {
    const uint8_t *p, *end;
    int32_t e;  /* the last element read (packed)                 */
    int packed;
} getme_star_it;

/* The star of node v, to read with getme__star_next. */
static inline getme_star_it getme__star_open(const getme_ws *ws, int32_t v)
{
    getme_star_it it;
    it.packed = ws->stars_packed;
    if (it.packed) {
        const uint8_t *b = (const uint8_t *)ws->star;
        it.p = b + getme__ws_star_at(ws, v);
        it.end = b + getme__ws_star_at(ws, v + 1);
    } else {
        it.p = (const uint8_t *)(ws->star + ws->star_ptr[v]);
        it.end = (const uint8_t *)(ws->star + ws->star_ptr[v + 1]);
    }
    it.e = 0;
    return it;
}

/* The next element of the star into *e: 1, or 0 at its end. */
static inline int getme__star_next(getme_star_it *it, int32_t *e)
{
    if (it->p == it->end)
        return 0;
    if (!it->packed) {
        memcpy(e, it->p, sizeof *e);
        it->p += sizeof *e;
        return 1;
    }
    uint32_t d = 0;
    int shift = 0;
    uint8_t b;
    do {
        b = *it->p++;
        d |= (uint32_t)(b & 0x7f) << shift;
        shift += 7;
    } while (b & 0x80);
    it->e += (int32_t)d;
    *e = it->e;
    return 1;
}

/* At least the number of elements in node v's star (its bytes when
   packed): a bound for buffers, with no walk. */
static inline int32_t getme__star_bound(const getme_ws *ws, int32_t v)
{
    return getme__ws_star_at(ws, v + 1) - getme__ws_star_at(ws, v);
}

/* The number of elements in node v's star. */
static inline int32_t getme__star_size(const getme_ws *ws, int32_t v)
{
    int32_t k0 = getme__ws_star_at(ws, v), k1 = getme__ws_star_at(ws, v + 1);
    if (!ws->stars_packed)
        return k1 - k0;
    const uint8_t *b = (const uint8_t *)ws->star;
    int32_t n = 0;
    for (int32_t k = k0; k < k1; k++)
        n += !(b[k] & 0x80); /* a value's last byte */
    return n;
}

#endif /* GETME_STARS_H */
