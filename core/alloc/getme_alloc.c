/*
 * getme_alloc.c -- allocation placed for huge pages (getme_alloc.h).
 */
#define _DEFAULT_SOURCE /* madvise, MADV_HUGEPAGE, posix_memalign, c11 */
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

#if defined(__linux__) && defined(MADV_HUGEPAGE) && !defined(GETME_NO_HUGE_PAGES)
#define HUGE_PAGES 1
#else
#define HUGE_PAGES 0
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
#if HUGE_PAGES
    if (p) {
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

#if HUGE_PAGES
/* A large block that starts on a huge-page boundary, advised.
   Why aligned: glibc maps a large block from any 4 KiB boundary, and the
   kernel can give a huge page only to a whole aligned 2 MiB stretch of a
   mapping; the stretch a block starts in (on average 1 MiB of it) was
   4 KiB pages, each a page fault at its first touch, and so was every
   block of 2-4 MiB, which held no whole stretch at all.  On the
   benchmark's VM such a fault costs 6-17 us even on memory just freed
   (docs/design.md §6): the full tets took ~38,000 faults a run, 23,000
   with this (bench.md, session 32).
   The end stays on 4 KiB pages: rounding the size up to a whole huge page
   would make the rest of the block's last stretch resident too (a huge
   page is resident in full), up to 2 MiB a block, 37 MiB more at the full
   hexes' peak. */
static void *huge_block(size_t n)
{
    void *p = NULL;
    if (posix_memalign(&p, GETME_HUGE_PAGE, n) != 0)
        return NULL;
    return advise(p, n);
}
#endif

void *getme__malloc(size_t n)
{
#if HUGE_PAGES
    if (n >= GETME_HUGE_MIN)
        return huge_block(n);
#endif
    return malloc(n);
}

/* calloc's block is neither aligned nor advised below 4 MiB.  A large
   calloc'd block is a fresh mapping whose pages stay the kernel's shared
   zero page until written, and many calloc'd arrays are marks written at
   a few places: on 4 KiB pages only the pages written become resident,
   on huge pages every 2 MiB stretch written once (advising calloc'd
   blocks from 1 MiB on put the full hexes' peak 6 MiB higher).  An
   aligned block would also have to be zeroed here, touching every page:
   posix_memalign may take it from the heap's freed memory. */
void *getme__calloc(size_t k, size_t n)
{
    void *p = calloc(k, n); /* an overflowing k * n fails here: NULL */
    size_t t = k && n <= SIZE_MAX / k ? k * n : 0;
    return t >= GETME_HUGE_CALLOC_MIN ? advise(p, t) : p;
}

/* Growing into a large block: a new, aligned block, then the copy.  The C
   library's realloc would copy the old contents into a block that is not
   advised yet (every page a 4 KiB fault: a sixth of all faults on the full
   tets, build_edges' count arrays growing from the heap into a mapping),
   or move an already large block's pages with mremap to an address that
   is not aligned.  The copy costs ~1 ms per 10 MiB.  Shrinking stays
   realloc's, in place. */
void *getme__realloc(void *p, size_t n)
{
    if (!p)
        return getme__malloc(n); /* aligned where it is large */
#if HUGE_PAGES && defined(__GLIBC__)
    if (n >= GETME_HUGE_MIN) {
        size_t old = malloc_usable_size(p);
        if (old < n) {
            void *q = huge_block(n);
            if (!q)
                return NULL; /* p stays valid, as after realloc */
            memcpy(q, p, old);
            free(p);
            return q;
        }
    }
#endif
    return n >= GETME_HUGE_MIN ? advise(realloc(p, n), n) : realloc(p, n);
}

void *getme__aligned_alloc(size_t align, size_t n)
{
#if HUGE_PAGES
    if (n >= GETME_HUGE_MIN && align <= GETME_HUGE_PAGE)
        return huge_block(n); /* a huge page's boundary is any smaller one */
#endif
    return aligned_alloc(align, n);
}
