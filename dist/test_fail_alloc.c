/*
 * test_fail_alloc.c -- a test shim (LD_PRELOAD) for test_mpi.py: on the
 * rank named by GETME_TEST_FAIL_HIST_RANK (OMPI_COMM_WORLD_RANK), libgetme's
 * malloc of the q*_min threshold histogram (65536 int64, getme__threshold)
 * fails, as if that rank ran out of memory inside the loop.  Every process
 * must then stop with GETME_ERR_NOMEM instead of waiting for the one that
 * gave up in its next hook.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static void *(*real_malloc)(size_t);

/* dlsym may allocate before real_malloc is known: a small static arena */
static char arena[4096];
static size_t arena_used;
static int resolving;

static int armed(void)
{
    const char *want = getenv("GETME_TEST_FAIL_HIST_RANK");
    const char *rank = getenv("OMPI_COMM_WORLD_RANK");
    return want && rank && strcmp(want, rank) == 0;
}

static int from_libgetme(void *caller)
{
    Dl_info info;
    return dladdr(caller, &info) && info.dli_fname &&
           strstr(info.dli_fname, "libgetme.so") != NULL;
}

void *malloc(size_t n)
{
    if (!real_malloc) {
        if (resolving) {
            size_t at = (arena_used + 15) & ~(size_t)15;
            if (at + n > sizeof arena)
                return NULL;
            arena_used = at + n;
            return arena + at;
        }
        resolving = 1;
        void *sym = dlsym(RTLD_NEXT, "malloc");
        memcpy(&real_malloc, &sym, sizeof sym); /* POSIX: same size */
        resolving = 0;
    }
    if (n == 65536 * sizeof(int64_t) && armed() &&
        from_libgetme(__builtin_return_address(0)))
        return NULL;
    return real_malloc(n);
}
