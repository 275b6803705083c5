/*
 * facenb.c -- packing the face table to 2 bytes per face (facenb.h says
 * why and how).
 */
#include "facenb.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

void getme__facenb_free(getme_facenb *fb)
{
    free(fb->d);
    free(fb->enb);
    free(fb->cptr);
    memset(fb, 0, sizeof *fb);
}

/* The element whose faces hold entry k (foff's layout). */
static int32_t entry_elem(const getme_ws *ws, const int64_t *foff, int64_t k)
{
    int t = GETME_NUM_TYPES - 1;
    while (t > 0 && (foff[t] > k || ws->tstart[t + 1] == ws->tstart[t]))
        t--;
    return ws->tstart[t] + (int32_t)((k - foff[t]) / getme__faces[t].num_faces);
}

/* Whether element e's neighbour nb is an escape (else its int16 code is
   0 for the skin or the difference). */
static int escapes(int32_t e, int32_t nb)
{
    if (nb == -1)
        return 0;
    int64_t d = (int64_t)nb - e;
    return nb < 0 || d == 0 || d < GETME_FNB_ESCAPE + GETME_FNB_CHUNK ||
           d > INT16_MAX;
}

/* Chunk c's escapes: counted (fill 0, nothing written), or (fill 1) its
   codes written into fb->d and its escapes into fb->enb from fb->cptr[c];
   returns the count (at most GETME_FNB_CHUNK, so an escape's index in its
   chunk is a code).  Entries are followed element by
   element, so no division per entry.  fb->d is table's own bytes (packing
   in place): entry k's code goes to bytes [2k, 2k + 2), inside entries
   already read; both are accessed as bytes (memcpy), which may alias. */
static int32_t pack_chunk(getme_facenb *fb, const getme_ws *ws,
                          const int64_t *foff, const unsigned char *table,
                          int64_t c, int fill)
{
    int64_t k0 = c * GETME_FNB_CHUNK, k1 = k0 + GETME_FNB_CHUNK;
    if (k1 > fb->n)
        k1 = fb->n;
    int32_t e = entry_elem(ws, foff, k0);
    int t = getme__ws_type(ws, e), nf = getme__faces[t].num_faces;
    int j = (int)((k0 - foff[t]) % nf); /* entry k0's face of e */
    int64_t at = fill ? fb->cptr[c] : 0;
    int32_t m = 0;
    for (int64_t k = k0; k < k1; k++) {
        int32_t nb;
        memcpy(&nb, table + 4 * k, sizeof nb);
        int esc = escapes(e, nb);
        if (fill) {
            int16_t code = esc        ? (int16_t)(GETME_FNB_ESCAPE + m)
                         : nb == -1   ? 0
                                      : (int16_t)(nb - e);
            memcpy((unsigned char *)fb->d + 2 * k, &code, sizeof code);
            if (esc)
                fb->enb[at + m] = nb;
        }
        m += esc;
        if (++j == nf && k + 1 < k1) { /* the next element, maybe a type on */
            j = 0;
            e++;
            t = getme__ws_type(ws, e);
            nf = getme__faces[t].num_faces;
        }
    }
    return m;
}

getme_status getme__facenb_pack(getme_facenb *fb, const getme_ws *ws,
                                const int64_t *foff, int32_t *table)
{
    memset(fb, 0, sizeof *fb);
    int64_t n = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        n += (int64_t)(ws->tstart[t + 1] - ws->tstart[t]) *
             getme__faces[t].num_faces;
    int64_t nc = (n + GETME_FNB_CHUNK - 1) / GETME_FNB_CHUNK;
    fb->n = n;
    fb->cptr = getme__malloc((size_t)(nc + 1) * sizeof *fb->cptr);
    if (!fb->cptr)
        goto fail;
    /* The escapes counted chunk by chunk in parallel (reading only), then
       the codes written in place in one serial pass: in parallel a chunk's
       codes would land on entries another thread may not have read yet.
       The serial pass is ~10 ms per 10M faces; a second array would add
       2 bytes per face to the set-up's peak, which this runs inside. */
#pragma omp parallel for schedule(static) num_threads(ws->nt)
    for (int64_t c = 0; c < nc; c++)
        fb->cptr[c + 1] =
            pack_chunk(fb, ws, foff, (const unsigned char *)table, c, 0);
    fb->cptr[0] = 0;
    for (int64_t c = 0; c < nc; c++)
        fb->cptr[c + 1] += fb->cptr[c];
    int64_t ne = fb->cptr[nc];
    fb->enb = getme__malloc((size_t)(ne ? ne : 1) * sizeof *fb->enb);
    if (!fb->enb)
        goto fail;
    fb->d = (int16_t *)(void *)table;
    table = NULL;
    for (int64_t c = 0; c < nc; c++)
        pack_chunk(fb, ws, foff, (const unsigned char *)fb->d, c, 1);
    /* the int32 table's second half back (a shrinking realloc does not
       fail in practice; if it does, the block is kept whole) */
    int16_t *d = getme__realloc(fb->d, (size_t)(n ? n : 1) * sizeof *fb->d);
    if (d)
        fb->d = d;
    return GETME_OK;
fail:
    free(table);
    getme__facenb_free(fb);
    return GETME_ERR_NOMEM;
}
