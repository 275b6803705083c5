/*
 * pack.c -- bit-packed int32 arrays (pack.h says what for).  Each run
 * starts at a 64-bit word, so runs never share a word.
 */
#include "pack.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

void getme__packed_free(getme_packed *p)
{
    free(p->base), free(p->bits), free(p->start), free(p->data);
    memset(p, 0, sizeof *p);
}

static int64_t bytes_of(int64_t runs, int64_t words)
{
    return runs * (int64_t)(sizeof(int32_t) + sizeof(uint8_t) +
                            sizeof(int64_t)) +
           words * (int64_t)sizeof(uint64_t);
}

int64_t getme__packed_bytes(const getme_packed *p)
{
    return bytes_of((p->n + GETME_PACK_RUN - 1) / GETME_PACK_RUN, p->words);
}

int getme__pack(getme_packed *p, const int32_t *v, int64_t n)
{
    memset(p, 0, sizeof *p);
    int64_t runs = (n + GETME_PACK_RUN - 1) / GETME_PACK_RUN;
    if (runs == 0)
        return 0;
    p->n = n;
    p->base = getme__malloc((size_t)runs * sizeof *p->base);
    p->bits = getme__malloc((size_t)runs * sizeof *p->bits);
    p->start = getme__malloc((size_t)runs * sizeof *p->start);
    if (!p->base || !p->bits || !p->start) {
        getme__packed_free(p);
        return 0;
    }
    int64_t bit = 0;
    for (int64_t r = 0; r < runs; r++) {
        int64_t a = r * GETME_PACK_RUN;
        int64_t b = a + GETME_PACK_RUN < n ? a + GETME_PACK_RUN : n;
        int32_t lo = v[a], hi = v[a];
        for (int64_t k = a; k < b; k++) {
            lo = v[k] < lo ? v[k] : lo;
            hi = v[k] > hi ? v[k] : hi;
        }
        uint32_t span = (uint32_t)hi - (uint32_t)lo;
        int w = 0;
        while (w < 32 && (span >> w) != 0)
            w++;
        p->base[r] = lo;
        p->bits[r] = (uint8_t)w;
        p->start[r] = bit;
        bit += ((b - a) * w + 63) / 64 * 64; /* the next run: a new word */
    }
    int64_t words = bit / 64 + 1;
    p->words = words;
    if (bytes_of(runs, words) >= n * (int64_t)sizeof *v ||
        !(p->data = getme__calloc((size_t)words, sizeof *p->data))) {
        getme__packed_free(p);
        return 0;
    }
    for (int64_t r = 0; r < runs; r++) {
        int w = p->bits[r];
        if (w == 0)
            continue;
        int64_t a = r * GETME_PACK_RUN;
        int64_t b = a + GETME_PACK_RUN < n ? a + GETME_PACK_RUN : n;
        for (int64_t k = a, pos = p->start[r]; k < b; k++, pos += w) {
            uint64_t off = (uint32_t)v[k] - (uint32_t)p->base[r];
            int sh = (int)(pos & 63);
            p->data[pos >> 6] |= off << sh;
            if (sh + w > 64)
                p->data[(pos >> 6) + 1] |= off >> (64 - sh);
        }
    }
    return 1;
}

void getme__unpack(getme_packed *p, int32_t *out)
{
    int64_t runs = (p->n + GETME_PACK_RUN - 1) / GETME_PACK_RUN;
    for (int64_t r = 0; r < runs; r++) {
        int w = p->bits[r];
        uint64_t mask = w == 0 ? 0 : ((uint64_t)1 << w) - 1;
        int64_t a = r * GETME_PACK_RUN;
        int64_t b = a + GETME_PACK_RUN < p->n ? a + GETME_PACK_RUN : p->n;
        for (int64_t k = a, pos = p->start[r]; k < b; k++, pos += w) {
            uint64_t off = 0;
            if (w) {
                int sh = (int)(pos & 63);
                off = p->data[pos >> 6] >> sh;
                if (sh + w > 64)
                    off |= p->data[(pos >> 6) + 1] << (64 - sh);
            }
            out[k] = (int32_t)((uint32_t)p->base[r] + (uint32_t)(off & mask));
        }
    }
    getme__packed_free(p);
}
