/*
 * stars.c -- the node stars packed for the smoothing loop (stars.h says
 * what and why).
 */
#include "stars.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

static int64_t leb_put(uint8_t *out, int64_t w, uint32_t v)
{
    while (v >= 0x80) {
        out[w++] = (uint8_t)(v | 0x80);
        v >>= 7;
    }
    out[w++] = (uint8_t)v;
    return w;
}

/* Pack the stars of nodes [a, b) in place from byte w = 4 star_ptr[a],
   the range's own start; kb: the old star_ptr[b] (the next range's thread
   rewrites it).  star_ptr[v] becomes v's byte offset once v's entries are
   read.  Returns the end.  Every value is below 2^28, so it takes at most
   4 bytes: before entry k is written, the range has written at most 4 k
   bytes, so writing it never reaches entry k + 1, still to be read, and
   never leaves the range's own bytes. */
static int64_t pack_range(getme_ws *ws, int32_t a, int32_t b, int32_t kb,
                          int64_t w)
{
    int32_t *ptr = ws->star_ptr;
    uint8_t *out = (uint8_t *)ws->star;
    for (int32_t v = a; v < b; v++) {
        int32_t k0 = ptr[v], k1 = v + 1 < b ? ptr[v + 1] : kb, prev = 0;
        ptr[v] = (int32_t)w;
        for (int32_t k = k0; k < k1; k++) {
            int32_t e = ws->star[k];
            w = leb_put(out, w, (uint32_t)(e - prev));
            prev = e;
        }
    }
    return w;
}

void getme__stars_pack(getme_ws *ws)
{
    /* byte offsets up to 4 entries' worth must fit star_ptr's 32 bits */
    if (ws->stars_packed || !ws->star || ws->nn == 0 ||
        ws->ne >= (1 << 28) || ws->star_ptr[ws->nn] > INT32_MAX / 4)
        return;
    enum { MAX_TEAM = 64 };
    int64_t from[MAX_TEAM], end[MAX_TEAM], to[MAX_TEAM + 1];
    int32_t *ptr = ws->star_ptr;
    uint8_t *bytes = (uint8_t *)ws->star;
    /* Each thread packs its nodes' range in place at the range's start;
       then the ranges move down to close the gaps (serial, a few ms), and
       each thread shifts its offsets.  The same bytes for any count. */
#pragma omp parallel num_threads(ws->nt < MAX_TEAM ? ws->nt : MAX_TEAM)
    {
        int th = omp_get_thread_num(), team = omp_get_num_threads();
        int32_t a = (int32_t)((int64_t)ws->nn * th / team);
        int32_t b = (int32_t)((int64_t)ws->nn * (th + 1) / team);
        int32_t kb = ptr[b];
        from[th] = 4 * (int64_t)ptr[a];
#pragma omp barrier
        end[th] = pack_range(ws, a, b, kb, from[th]);
#pragma omp barrier
#pragma omp single
        {
            to[0] = 0;
            for (int t = 0; t < team; t++) {
                if (to[t] != from[t]) /* the first range stays put */
                    memmove(bytes + to[t], bytes + from[t],
                            (size_t)(end[t] - from[t]));
                to[t + 1] = to[t] + end[t] - from[t];
            }
            ptr[ws->nn] = (int32_t)to[team];
        } /* implicit barrier */
        for (int32_t v = a; v < b; v++)
            ptr[v] -= (int32_t)(from[th] - to[th]);
    }
    ws->stars_packed = 1;
    /* Give the tail back, keeping room for getme__ws_unpack_map's maps
       if they are packed (getme__ws_pack_map made sure they fit). */
    int64_t keep = ws->maps_packed == 1 ? 4 * ((int64_t)ws->ne + ws->nn) : 0;
    keep = keep > ptr[ws->nn] ? keep : ptr[ws->nn];
    int32_t *shrunk = getme__realloc(ws->star, (size_t)(keep ? keep : 1));
    if (shrunk)
        ws->star = shrunk;
    /* the offsets in 2.25 bytes per node, if their groups fit */
    getme__offs_take(&ws->star_offs, ws->star_ptr, (int64_t)ws->nn + 1);
    ws->star_ptr = ws->star_offs.plain; /* NULL if packed */
    ws->star_offs.plain = NULL;
}
