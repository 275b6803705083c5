/*
 * getme_alloc.c -- allocation with a huge-page hint for large blocks
 * (getme_alloc.h).
 */
#define _DEFAULT_SOURCE /* madvise and MADV_HUGEPAGE under -std=c11 */
#include "getme_alloc.h"

#include <stdint.h>
#include <stdlib.h>
#if defined(__linux__) && !defined(GETME_NO_HUGE_PAGES)
#include <sys/mman.h>
#include <unistd.h>
#endif

/* Advise the whole pages of [p, p + n) as wanting huge pages: the kernel
   then backs each 2 MiB-aligned stretch of them with one huge page when
   it is first touched (and khugepaged may merge stretches touched
   before).  Only a hint: if it fails (an old kernel, THP "never") the
   block works the same, so its result is not looked at.  p may be NULL
   (a failed allocation), returned as it is. */
static void *advise(void *p, size_t n)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE) && !defined(GETME_NO_HUGE_PAGES)
    if (p && n >= GETME_HUGE_MIN) {
        long ps = sysconf(_SC_PAGESIZE);
        uintptr_t page = ps > 0 ? (uintptr_t)ps : 4096;
        uintptr_t a = ((uintptr_t)p + page - 1) & ~(page - 1);
        uintptr_t b = ((uintptr_t)p + n) & ~(page - 1);
        if (b > a)
            (void)madvise((void *)a, b - a, MADV_HUGEPAGE);
    }
#else
    (void)n;
#endif
    return p;
}

void *getme__malloc(size_t n) { return advise(malloc(n), n); }

void *getme__calloc(size_t k, size_t n)
{
    /* an overflowing k * n fails in calloc: NULL, nothing advised */
    return advise(calloc(k, n), k && n <= SIZE_MAX / k ? k * n : 0);
}

void *getme__realloc(void *p, size_t n) { return advise(realloc(p, n), n); }

void *getme__aligned_alloc(size_t align, size_t n)
{
    return advise(aligned_alloc(align, n), n);
}
