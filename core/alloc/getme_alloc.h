/*
 * getme_alloc.h -- the libraries' allocation functions: malloc, calloc, realloc
 * and aligned_alloc as the C library has them, except that large blocks are
 * placed for transparent huge pages (Linux madvise(MADV_HUGEPAGE);
 * elsewhere, or where the kernel refuses, nothing changes):
 *   - a block of at least GETME_HUGE_MIN bytes from getme__malloc,
 *     getme__realloc or getme__aligned_alloc starts on a GETME_HUGE_PAGE
 *     boundary and is advised, so that every whole 2 MiB stretch of it,
 *     its first one included, can be one huge page;
 *   - a block of at least GETME_HUGE_CALLOC_MIN bytes from getme__calloc
 *     is advised where the C library puts it (see getme_alloc.c for why
 *     not aligned and why from a larger size).
 * Free with free().
 *
 * Why: a multi-million-element mesh lives in a few hundred MiB of arrays
 * that the read, the set-up and the q*_min stage walk in scattered order,
 * and most Linux systems give huge pages only on request (THP "madvise").
 * On 4 KiB pages every first touch is a page fault and nearly every
 * scattered load a TLB miss, dearer still under virtualisation (two-level
 * page walks).  docs/design.md §6 has the measurements.
 */
#ifndef GETME_ALLOC_H
#define GETME_ALLOC_H

#include <stddef.h>

/* The huge page's size on x86-64 and arm64 (4 KiB base pages). */
#define GETME_HUGE_PAGE ((size_t)2 << 20)
/* Blocks from this size on are aligned and advised: below one huge page
   none fits. */
#define GETME_HUGE_MIN GETME_HUGE_PAGE
/* calloc'd blocks from this size on are advised. */
#define GETME_HUGE_CALLOC_MIN ((size_t)4 << 20)

void *getme__malloc(size_t n);
void *getme__calloc(size_t k, size_t n);
void *getme__realloc(void *p, size_t n);
void *getme__aligned_alloc(size_t align, size_t n);

#endif /* GETME_ALLOC_H */
