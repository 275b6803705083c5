/*
 * pack.h -- an int32 array held bit-packed while nobody reads it.
 *
 * The workspace's element map (internal -> caller element index, 4 B per
 * element) is read before the smoothing loop (messages) and after it (the
 * lent connectivity goes back in the caller's order), never in it, while
 * the loop's arrays make the run's peak.  The map is a permutation with
 * locality: both orders keep neighbouring elements near each other, so a
 * run of 256 consecutive entries spans a narrow range of values.  Each run
 * is stored as its minimum and the offsets from it in the fewest bits that
 * hold them all.  If that is not smaller than the array, it stays as it is.
 */
#ifndef GETME_PACK_H
#define GETME_PACK_H

#include <stdint.h>

typedef struct getme_packed {
    int64_t n;
    int32_t *base;    /* per run of GETME_PACK_RUN entries: its minimum    */
    uint8_t *bits;    /* per run: the offsets' width in bits (0..32)       */
    int64_t *start;   /* per run: its first bit in data                   */
    uint64_t *data;
    int64_t words;    /* in data                                          */
} getme_packed;

#define GETME_PACK_RUN 256

/* Pack v[0..n) into p (zeroed first).  Returns 1 if packed (v may then be
   freed), 0 if packing would not save memory or memory ran out (p stays
   empty, v is still needed). */
int getme__pack(getme_packed *p, const int32_t *v, int64_t n);

/* Write the n values back into out (room for p->n entries), then free p. */
void getme__unpack(getme_packed *p, int32_t *out);

/* Bytes p holds (for the decision above and the benchmark notes). */
int64_t getme__packed_bytes(const getme_packed *p);

void getme__packed_free(getme_packed *p);

#endif /* GETME_PACK_H */
