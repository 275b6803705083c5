/*
 * heappeak.c -- which large heap blocks are live at a process's heap peak
 * (issue #13's memory rounds; heaptrack is not installed here).
 *
 *     gcc -O2 -shared -fPIC -o /tmp/heappeak.so bench/heappeak.c -ldl -lpthread
 *     HEAPPEAK_OUT=peak.txt LD_PRELOAD=/tmp/heappeak.so getme smooth IN -o OUT
 *
 * Wraps malloc, calloc, realloc, aligned_alloc, posix_memalign and free;
 * tracks the blocks of 512 KiB or more (with the call stack that made
 * them) and copies the live set whenever their total reaches a new
 * maximum.  At exit it writes that set: size, MiB, and the return
 * addresses as library:offset, which `addr2line -f -e LIB OFFSET` names
 * (static functions inlined by LTO show as their caller).  Not a library
 * file: a measuring aid, like bench/setup.c.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <execinfo.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

extern void *__libc_malloc(size_t);
extern void *__libc_calloc(size_t, size_t);
extern void *__libc_realloc(void *, size_t);
extern void *__libc_memalign(size_t, size_t);
extern void __libc_free(void *);

#define MAX_BLOCKS 4096
#define BIG (512 * 1024)
#define DEPTH 8

typedef struct block {
    void *p;
    size_t size;
    void *stack[DEPTH];
    int depth;
} block;

static block live[MAX_BLOCKS], peak_set[MAX_BLOCKS];
static int num_live, num_peak;
static size_t now, peak;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static __thread int inside; /* backtrace() may allocate */
static int ready;

static void note(void *p, size_t size)
{
    if (!p || size < BIG || inside || !ready)
        return;
    inside = 1;
    void *stack[DEPTH];
    int depth = backtrace(stack, DEPTH);
    pthread_mutex_lock(&lock);
    if (num_live < MAX_BLOCKS) {
        block *b = &live[num_live++];
        b->p = p, b->size = size, b->depth = depth;
        memcpy(b->stack, stack, sizeof stack);
        now += size;
        if (now > peak) {
            peak = now;
            memcpy(peak_set, live, (size_t)num_live * sizeof *live);
            num_peak = num_live;
        }
    }
    pthread_mutex_unlock(&lock);
    inside = 0;
}

static void forget(void *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&lock);
    for (int i = num_live - 1; i >= 0; i--)
        if (live[i].p == p) {
            now -= live[i].size;
            live[i] = live[--num_live];
            break;
        }
    pthread_mutex_unlock(&lock);
}

void *malloc(size_t n)
{
    void *p = __libc_malloc(n);
    note(p, n);
    return p;
}

void *calloc(size_t a, size_t b)
{
    void *p = __libc_calloc(a, b);
    note(p, a * b);
    return p;
}

void *realloc(void *q, size_t n)
{
    forget(q);
    void *p = __libc_realloc(q, n);
    note(p, n);
    return p;
}

void *aligned_alloc(size_t a, size_t n)
{
    void *p = __libc_memalign(a, n);
    note(p, n);
    return p;
}

int posix_memalign(void **out, size_t a, size_t n)
{
    void *p = __libc_memalign(a, n);
    note(p, n);
    *out = p;
    return p ? 0 : 12; /* ENOMEM */
}

void free(void *p)
{
    forget(p);
    __libc_free(p);
}

__attribute__((constructor)) static void start(void)
{
    void *stack[2];
    inside = 1;
    backtrace(stack, 2); /* loads libgcc's unwinder now, not inside note */
    inside = 0;
    ready = 1;
}

__attribute__((destructor)) static void report(void)
{
    /* only the file the user names (HEAPPEAK_OUT), else stderr: a tool
       preloaded into any command must not create or replace a file in
       its working directory */
    const char *path = getenv("HEAPPEAK_OUT");
    FILE *f = path ? fopen(path, "w") : stderr;
    if (!f)
        return;
    fprintf(f, "peak %.1f MiB in %d blocks of %d KiB or more\n",
            (double)peak / 1048576.0, num_peak, BIG / 1024);
    for (int i = 0; i < num_peak; i++) {
        fprintf(f, "%12zu %8.2f", peak_set[i].size,
                (double)peak_set[i].size / 1048576.0);
        for (int k = 1; k < peak_set[i].depth; k++) {
            Dl_info d;
            if (dladdr(peak_set[i].stack[k], &d) && d.dli_fname)
                fprintf(f, " %s:0x%lx", d.dli_fname,
                        (unsigned long)((char *)peak_set[i].stack[k] -
                                        (char *)d.dli_fbase));
        }
        fprintf(f, "\n");
    }
    if (f != stderr)
        fclose(f);
}
