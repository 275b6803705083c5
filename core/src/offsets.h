/*
 * offsets.h -- a nondecreasing table of 32-bit offsets (the row starts of
 * a compressed-sparse-row array) in 2.25 bytes per entry instead of 4.
 *
 * The smoothing loop keeps two such tables per node for the whole run:
 * the first edge of each node (adjacency.h's eptr) and the first byte of
 * each node's packed star (stars.h).  Neighbouring entries differ by a
 * node's edge count or star bytes, so each group of 16 entries keeps its
 * first entry as int32 (base) and every entry as its uint16 distance from
 * it (off): 4 / 16 + 2 bytes per entry.  On the full benchmark hexes both
 * tables were 10.2 MiB each.  A table whose groups span 65536 or more
 * (a node with thousands of edges or elements) stays plain.
 */
#ifndef GETME_OFFSETS_H
#define GETME_OFFSETS_H

#include "getme.h"

#include <stdint.h>

#define GETME_OFFS_GROUP 16

typedef struct getme_offsets {
    int32_t *plain;  /* n entries, or NULL when packed                     */
    int32_t *base;   /* packed: entry GETME_OFFS_GROUP g of each group g   */
    uint16_t *off;   /* packed: entry v minus its group's base             */
} getme_offsets;

/* Entry v. */
static inline int32_t getme__offs_at(const getme_offsets *o, int64_t v)
{
    if (o->plain)
        return o->plain[v];
    return o->base[(uint64_t)v / GETME_OFFS_GROUP] + o->off[v];
}

/* Take table (n entries, nondecreasing, malloc'd) into o: packed in place
   (table becomes o->off, shrunk) if every group spans less than 65536,
   else kept as o->plain.  Serial, one pass (~3 ms per million entries).
   Cannot fail: without memory for the bases the table stays plain. */
void getme__offs_take(getme_offsets *o, int32_t *table, int64_t n);
void getme__offs_free(getme_offsets *o);

#endif /* GETME_OFFSETS_H */
