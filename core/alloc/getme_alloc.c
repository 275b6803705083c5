/*
 * getme_alloc.c -- allocation with a huge-page hint for large blocks
 * (getme_alloc.h).
 */
#define _DEFAULT_SOURCE /* madvise and MADV_HUGEPAGE under -std=c11 */
#include "getme_alloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef __GLIBC__
#include <malloc.h> /* malloc_usable_size */
#endif
#if defined(__linux__) && !defined(GETME_NO_HUGE_PAGES)
#include <sys/mman.h>
#include <unistd.h>
#endif

/* Advise the pages that [p, p + n) touches as wanting huge pages: the
   kernel then backs each 2 MiB-aligned stretch of them with one huge page
   when it is first touched (and khugepaged may merge stretches touched
   before).  Only a hint: if it fails (an old kernel, THP "never") the
   block works the same, so its result is not looked at.  p may be NULL
   (a failed allocation), returned as it is.
   The partial pages at both ends are advised too: a large block is its
   own mapping from its first page on (glibc's header sits before p), and
   advice that left that page out split the mapping in two, after which
   glibc's realloc could no longer grow it with mremap (EFAULT) and
   copied it into a fresh block instead, whose every page was a 4 KiB
   fault before the copy's result was advised (strace, perf; build_edges'
   count array on the full tets).  The end pages may hold other blocks
   of the heap; the hint does not change their contents. */
static void *advise(void *p, size_t n)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE) && !defined(GETME_NO_HUGE_PAGES)
    if (p && n >= GETME_HUGE_MIN) {
        long ps = sysconf(_SC_PAGESIZE);
        uintptr_t page = ps > 0 ? (uintptr_t)ps : 4096;
        uintptr_t a = (uintptr_t)p & ~(page - 1);
        uintptr_t b = ((uintptr_t)p + n + page - 1) & ~(page - 1);
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

/* Growing into a large block: realloc copies the old contents into the
   new block before it could be advised, so each of the new block's pages
   was first touched as a 4 KiB page fault (perf -e page-faults: a sixth
   of all faults on the full tets, build_edges' count arrays growing from
   the heap into a mapping).  So a new, advised block, then the copy.
   Shrinking, or growing a block that is already large (glibc moves its
   pages with mremap, no copy), stays realloc's. */
void *getme__realloc(void *p, size_t n)
{
#if defined(__GLIBC__) && defined(MADV_HUGEPAGE) && !defined(GETME_NO_HUGE_PAGES)
    if (p && n >= GETME_HUGE_MIN) {
        size_t old = malloc_usable_size(p);
        if (old < GETME_HUGE_MIN) { /* n > old */
            void *q = getme__malloc(n);
            if (!q)
                return NULL; /* p stays valid, as after realloc */
            memcpy(q, p, old);
            free(p);
            return q;
        }
    }
#endif
    return advise(realloc(p, n), n);
}

void *getme__aligned_alloc(size_t align, size_t n)
{
    return advise(aligned_alloc(align, n), n);
}
