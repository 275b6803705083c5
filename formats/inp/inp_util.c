/*
 * inp_util.c -- small helpers of the INP adapter: growing arrays and
 * case-insensitive names.
 */
#include "inp_internal.h"
#include "getme_alloc.h"

#include <stdint.h>
#include <stdlib.h>

int inp_reserve(void **p, size_t *cap, size_t need, size_t sz)
{
    if (need <= *cap)
        return 0;
    size_t n = *cap ? *cap : 64;
    while (n < need) {
        if (n > SIZE_MAX / 2)
            return -1;
        n *= 2;
    }
    if (n > SIZE_MAX / sz)
        return -1;
    /* Doubling keeps the number of reallocations logarithmic in the mesh
       size: no allocation per node, element or line. */
    void *q = getme__realloc(*p, n * sz);
    if (!q)
        return -1;
    *p = q;
    *cap = n;
    return 0;
}

static int upper(int c) { return c >= 'a' && c <= 'z' ? c - 32 : c; }

int inp_name_eq(const char *a, const char *b)
{
    while (*a && upper((unsigned char)*a) == upper((unsigned char)*b)) {
        a++;
        b++;
    }
    return *a == 0 && *b == 0;
}
