/*
 * getme_alloc.h -- the libraries' allocation functions: malloc, calloc, realloc
 * and aligned_alloc as the C library has them, except that a block of at
 * least GETME_HUGE_MIN bytes is advised to the kernel as wanting
 * transparent huge pages (Linux madvise(MADV_HUGEPAGE); elsewhere, or
 * where the kernel refuses, nothing changes).  Free with free().
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

/* Blocks from this size on are advised: below 2 MiB no huge page fits. */
#define GETME_HUGE_MIN ((size_t)4 << 20)

void *getme__malloc(size_t n);
void *getme__calloc(size_t k, size_t n);
void *getme__realloc(void *p, size_t n);
void *getme__aligned_alloc(size_t align, size_t n);

#endif /* GETME_ALLOC_H */
