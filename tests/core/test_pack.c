/*
 * test_pack.c -- pack.c's bit-packed int32 arrays: every value comes back
 * (runs of one value, narrow and wide runs, a last run shorter than the
 * others, negative values), the packed size is what the widths say, and an
 * array that would not shrink is left unpacked.
 */
#include "check.h"
#include "pack.h"

#include <stdlib.h>
#include <string.h>

static uint64_t rng = 88172645463325252u;
static uint32_t next32(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (uint32_t)rng;
}

/* Pack v, unpack it, compare; returns whether it packed. */
static int round_trip(const int32_t *v, int64_t n)
{
    getme_packed p;
    int packed = getme__pack(&p, v, n);
    if (!packed) {
        CHECK(p.data == NULL && p.base == NULL);
        return 0;
    }
    CHECK(getme__packed_bytes(&p) < n * 4);
    int32_t *out = malloc((size_t)n * sizeof *out);
    getme__unpack(&p, out);
    CHECK(!memcmp(out, v, (size_t)n * sizeof *v));
    CHECK(p.data == NULL && p.n == 0); /* unpack frees */
    free(out);
    return 1;
}

int main(void)
{
    int64_t n = 5 * GETME_PACK_RUN + 77;
    int32_t *v = malloc((size_t)n * sizeof *v);

    /* A permutation with locality (shuffled inside windows of 1000), as
       the element map is: packs, about 10 bits per entry. */
    for (int64_t k = 0; k < n; k++)
        v[k] = (int32_t)k;
    for (int64_t k = 0; k < n; k++) {
        int64_t w = k / 1000 * 1000, j = w + next32() % 1000;
        j = j < n ? j : n - 1;
        int32_t t = v[k];
        v[k] = v[j], v[j] = t;
    }
    CHECK(round_trip(v, n));
    getme_packed p;
    CHECK(getme__pack(&p, v, n));
    CHECK(getme__packed_bytes(&p) < n * 2);
    getme__packed_free(&p);

    /* One value per run (width 0), negative values included. */
    for (int64_t k = 0; k < n; k++)
        v[k] = (int32_t)(k / GETME_PACK_RUN) - 3;
    CHECK(round_trip(v, n));

    /* Widths from 1 to 31 bits, one run each, offsets up to the top. */
    for (int64_t k = 0; k < n; k++) {
        int w = (int)(k / GETME_PACK_RUN) * 6 + 1;
        uint32_t span = w >= 31 ? 0x7fffffffu : (1u << w) - 1;
        v[k] = (int32_t)(next32() & span) - (int32_t)(span / 2);
        if (k % GETME_PACK_RUN == 0)
            v[k] = -(int32_t)(span / 2); /* the run's full span */
    }
    CHECK(round_trip(v, n));

    /* Full 32-bit values: nothing to gain, not packed. */
    for (int64_t k = 0; k < n; k++)
        v[k] = (int32_t)next32();
    v[0] = INT32_MIN, v[1] = INT32_MAX;
    CHECK(!round_trip(v, n));

    /* Short arrays: one partial run. */
    CHECK(round_trip(v + 2, 0) == 0);
    for (int64_t m = 1; m < 40; m++) {
        for (int64_t k = 0; k < m; k++)
            v[k] = (int32_t)(1000 + k % 7);
        round_trip(v, m); /* packed or not, never wrong */
    }
    free(v);
    return check_summary("test_pack");
}
