/*
 * linepar.c -- parse a run of text lines on several threads.
 *
 * The ASCII readers know how many records a section holds (MSH block
 * headers) or can check that a line is a plain data line (INP), and each
 * record is one line, so a run of lines in the read buffer can be cut into
 * pieces at line boundaries (four per thread, taken as threads come free).
 * One serial pass finds where the run's lines end and notes line starts
 * with their index on the way, so every piece knows the index of its first
 * line: the arrays are filled at known offsets, the same bytes for any
 * thread count.  A line the parse function refuses stops its piece; the
 * result is the number of lines before the first refused line in text
 * order, so the caller's serial reader takes over exactly where a serial
 * parse would have met the problem and reports it with its own message,
 * file and line.
 */
#include "linepar.h"

#include <string.h>

#define NMARK 256 /* line starts noted per run, where pieces may start */
/* Below this many bytes a run is parsed by the calling thread: starting a
   team costs a few microseconds, parsing 256 KiB about a millisecond. */
#define MIN_PARALLEL_BYTES (256u << 10)

int linepar_threads(int threads, size_t len)
{
    if (threads < 1 || len < MIN_PARALLEL_BYTES)
        return 1;
    return threads > LINEPAR_MAX_PIECES ? LINEPAR_MAX_PIECES : threads;
}

size_t linepar_count(const char *p, const char *end)
{
    size_t k = 0;
    while (p < end && (p = memchr(p, '\n', (size_t)(end - p))) != NULL) {
        p++;
        k++;
    }
    return k;
}

/* Parse lines first.. of [*p, end) while their index is below max; the
   index of the first refused line (*p left at its start), or the index
   after the last line parsed (*p past it). */
static size_t parse_piece(const char **p, const char *end, size_t first,
                          size_t max, linepar_fn fn, void *ctx)
{
    size_t i = first;
    const char *s = *p;
    for (; s < end && i < max; i++) {
        const char *next = fn(ctx, s, end, i);
        if (!next)
            break;
        s = next;
    }
    *p = s;
    return i;
}

size_t linepar_pieces(const char *text, size_t len, size_t max, int np,
                      const char **cut, size_t *first, int *ncut)
{
    /* Find where the run's max lines end, noting a line start and its
       index about every len / NMARK bytes: one memchr per line, a few per
       cent of parsing them, and no work for lines past max (a block may
       end early in a big window). */
    const char *end = text + len;
    const char *mark_at[NMARK + 1];
    size_t mark_line[NMARK + 1];
    int nmark = 0;
    size_t interval = len / NMARK + 1, nrun = 0;
    const char *p = text, *next_mark = text + interval;
    while (nrun < max && p < end) {
        p = (const char *)memchr(p, '\n', (size_t)(end - p)) + 1;
        nrun++;
        if (p >= next_mark && nmark < NMARK) {
            mark_at[nmark] = p;
            mark_line[nmark++] = nrun;
            next_mark = p + interval;
        }
    }
    const char *run_end = p;
    /* the cuts at the marks nearest to equal shares of the run */
    int n = 1, m = 0;
    cut[0] = text;
    first[0] = 0;
    for (int k = 1; k < np; k++) {
        const char *target = text + (size_t)k * (size_t)(run_end - text) /
                                        (size_t)np;
        while (m < nmark && mark_at[m] < target)
            m++;
        if (m == nmark || mark_at[m] >= run_end)
            break;
        cut[n] = mark_at[m];
        first[n++] = mark_line[m++];
    }
    cut[n] = run_end;
    first[n] = nrun;
    *ncut = n;
    return nrun;
}

size_t linepar_run(const char *text, size_t len, size_t max, int threads,
                   linepar_fn fn, void *ctx, size_t *bytes)
{
    const char *end = text + len;
    if (linepar_threads(threads, len) == 1) {
        const char *p = text;
        size_t k = parse_piece(&p, end, 0, max, fn, ctx);
        *bytes = (size_t)(p - text);
        return k;
    }
    /* Four pieces per thread, handed out as threads come free: on a
       loaded machine a thread that is not running does not hold up the
       others for its whole share. */
    int t = linepar_threads(threads, len);
    int want = 4 * t > LINEPAR_MAX_PIECES ? LINEPAR_MAX_PIECES : 4 * t;
    int np;
    const char *cut[LINEPAR_MAX_PIECES + 1], *stop_at[LINEPAR_MAX_PIECES];
    size_t first[LINEPAR_MAX_PIECES + 1], stop[LINEPAR_MAX_PIECES];
    size_t nrun = linepar_pieces(text, len, max, want, cut, first, &np);
    const char *run_end = cut[np];
    if (linepar_threads(threads, (size_t)(run_end - text)) == 1) {
        const char *p = text;
        size_t k = parse_piece(&p, run_end, 0, nrun, fn, ctx);
        *bytes = (size_t)(p - text);
        return k;
    }
#pragma omp parallel for num_threads(t) schedule(dynamic, 1)
    for (int k = 0; k < np; k++) {
        stop_at[k] = cut[k];
        stop[k] = parse_piece(&stop_at[k], cut[k + 1], first[k], first[k + 1],
                              fn, ctx);
    }
    /* the first piece that stopped early: a refused line */
    for (int k = 0; k < np; k++)
        if (stop[k] < first[k + 1]) {
            *bytes = (size_t)(stop_at[k] - text);
            return stop[k];
        }
    *bytes = (size_t)(run_end - text);
    return nrun;
}
