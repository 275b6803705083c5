/*
 * faultcost.c -- what a first touch of fresh memory costs on this machine,
 * on 4 KiB pages and on transparent huge pages (issue #13, session 18:
 * why page faults were a tenth of a `getme smooth` run on the benchmark VM).
 *
 *     gcc -O2 -o /tmp/faultcost bench/faultcost.c && /tmp/faultcost 256
 *
 * For each mode, three rounds of: map MiB fresh anonymous memory (2 MiB
 * aligned), optionally madvise it MADV_HUGEPAGE and/or pre-fault it with
 * MADV_POPULATE_WRITE, write one byte per cache line, unmap.  Prints the
 * seconds of the map (+ populate) and of the writes.  The later rounds
 * show memory the kernel had just freed, the first one memory it had not
 * handed out before.  Then one growth round (growth()).  Not a library
 * file: a measuring aid, like bench/heappeak.c.
 */
#define _GNU_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <time.h>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23 /* Linux 5.14 */
#endif

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

enum { ALIGN = 2 << 20 }; /* one huge page */

/* n bytes of fresh anonymous memory from a 2 MiB boundary, advised as
   wanting huge pages or not; *base is the mapping to unmap (n + ALIGN
   bytes).  Exits on failure: a measuring aid. */
static char *map_aligned(size_t n, int huge, char **base)
{
    char *m = mmap(NULL, n + ALIGN, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) {
        perror("mmap");
        exit(1);
    }
    char *a = (char *)(((uintptr_t)m + ALIGN - 1) & ~(uintptr_t)(ALIGN - 1));
    (void)madvise(a, n, huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
    *base = m;
    return a;
}

/* One byte per cache line of [a, a + n). */
static void touch(char *a, size_t n)
{
    for (size_t i = 0; i < n; i += 64)
        a[i] = 1;
}

static void round_of(size_t n, int huge, int populate)
{
    double t0 = now();
    char *m, *a = map_aligned(n, huge, &m);
    if (populate && madvise(a, n, MADV_POPULATE_WRITE) != 0)
        perror("MADV_POPULATE_WRITE");
    double t1 = now();
    touch(a, n);
    double t2 = now();
    printf("%-9s %-9s %6zu MiB: map%s %.3f s, first writes %.3f s, "
           "total %.3f s\n",
           huge ? "huge" : "4 KiB", populate ? "populate" : "", n >> 20,
           populate ? "+populate" : "", t1 - t0, t2 - t1, t2 - t0);
    munmap(m, n + ALIGN);
}

/* Growth past what was just freed (session 27): huge pages, n bytes
   touched and unmapped, then 2 n touched, timed by halves.  The first
   half reuses the pages just freed, the second needs pages the guest had
   not handed out lately: on the benchmark VM (kdamond running) the
   second half costs ~25x the first, so what a process pays for fresh
   memory is its growth to its peak, not how often it frees and
   allocates below it. */
static void growth(size_t n)
{
    char *m, *a = map_aligned(n, 1, &m);
    touch(a, n);
    munmap(m, n + ALIGN);
    a = map_aligned(2 * n, 1, &m);
    double t0 = now();
    touch(a, n);
    double t1 = now();
    touch(a + n, n);
    double t2 = now();
    printf("growth    huge      %6zu MiB after freeing %zu: first half %.3f s, "
           "second half %.3f s\n", (2 * n) >> 20, n >> 20, t1 - t0, t2 - t1);
    munmap(m, 2 * n + ALIGN);
}

int main(int argc, char **argv)
{
    size_t mib = argc > 1 ? (size_t)atol(argv[1]) : 256;
    for (int mode = 0; mode < 4; mode++)
        for (int r = 0; r < 3; r++)
            round_of(mib << 20, mode & 1, mode >> 1);
    growth(mib << 20);
    return 0;
}
