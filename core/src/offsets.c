/*
 * offsets.c -- packing a table of row starts to 2.25 bytes per entry
 * (offsets.h says why and how).
 */
#include "offsets.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

void getme__offs_free(getme_offsets *o)
{
    free(o->plain);
    free(o->base);
    free(o->off);
    memset(o, 0, sizeof *o);
}

void getme__offs_take(getme_offsets *o, int32_t *table, int64_t n)
{
    memset(o, 0, sizeof *o);
    o->plain = table;
    int64_t ng = (n + GETME_OFFS_GROUP - 1) / GETME_OFFS_GROUP;
    for (int64_t g = 0; g < ng; g++) { /* the last entry spans most */
        int64_t last = (g + 1) * GETME_OFFS_GROUP - 1;
        if (last >= n)
            last = n - 1;
        if ((int64_t)table[last] - table[g * GETME_OFFS_GROUP] > UINT16_MAX)
            return;
    }
    int32_t *base = getme__malloc((size_t)(ng ? ng : 1) * sizeof *base);
    if (!base)
        return;
    /* In place: entry v's uint16 goes to bytes [2v, 2v + 2), inside
       entries already read (as bytes, which may alias: memcpy). */
    unsigned char *bytes = (unsigned char *)table;
    for (int64_t v = 0; v < n; v++) {
        int32_t x;
        memcpy(&x, bytes + 4 * v, sizeof x);
        if (v % GETME_OFFS_GROUP == 0)
            base[v / GETME_OFFS_GROUP] = x;
        uint16_t d = (uint16_t)(x - base[v / GETME_OFFS_GROUP]);
        memcpy(bytes + 2 * v, &d, sizeof d);
    }
    uint16_t *off = getme__realloc(table, (size_t)(n ? n : 1) * sizeof *off);
    o->off = off ? off : (uint16_t *)(void *)table;
    o->base = base;
    o->plain = NULL;
}
