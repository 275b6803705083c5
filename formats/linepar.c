/*
 * linepar.c -- parse a run of text lines on several threads.
 *
 * The ASCII readers know how many records a section holds (MSH block
 * headers) or can check that a line is a plain data line (INP), and each
 * record is one line, so a run of lines in the read buffer can be cut into
 * pieces at line boundaries (four per thread, taken as threads come free).  Each piece first counts its
 * lines (so every piece knows the index of its first line: the arrays are
 * filled at known offsets, the same bytes for any thread count), then
 * parses them.  A line the parse function refuses stops its piece; the
 * result is the number of lines before the first refused line in text
 * order, so the caller's serial reader takes over exactly where a serial
 * parse would have met the problem and reports it with its own message,
 * file and line.
 */
#include "linepar.h"

#include <string.h>

#define MAX_PIECES 64
/* Below this many bytes a run is parsed by the calling thread: starting a
   team costs a few microseconds, parsing 256 KiB about a millisecond. */
#define MIN_PARALLEL_BYTES (256u << 10)

int linepar_threads(int threads, size_t len)
{
    if (threads < 1 || len < MIN_PARALLEL_BYTES)
        return 1;
    return threads > MAX_PIECES ? MAX_PIECES : threads;
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

size_t linepar_run(const char *text, size_t len, size_t max, int threads,
                   linepar_fn fn, void *ctx, size_t *bytes)
{
    int t = linepar_threads(threads, len);
    /* Four pieces per thread, handed out as threads come free: on a
       loaded machine a thread that is not running does not hold up the
       others for its whole share. */
    int np = t == 1 ? 1 : 4 * t > MAX_PIECES ? MAX_PIECES : 4 * t;
    if (t == 1) {
        const char *p = text;
        size_t k = parse_piece(&p, text + len, 0, max, fn, ctx);
        *bytes = (size_t)(p - text);
        return k;
    }
    const char *cut[MAX_PIECES + 1], *stop_at[MAX_PIECES], *end = text + len;
    size_t first[MAX_PIECES + 1], stop[MAX_PIECES];
    cut[0] = text;
    cut[np] = end;
    for (int k = 1; k < np; k++) {
        /* the start of the first line that begins at or after k/np */
        const char *p = text + (size_t)k * (len / (size_t)np);
        const char *nl = p > cut[k - 1]
                             ? memchr(p - 1, '\n', (size_t)(end - (p - 1)))
                             : NULL;
        cut[k] = p <= cut[k - 1] ? cut[k - 1] : nl ? nl + 1 : end;
    }
    first[0] = 0;
#pragma omp parallel num_threads(t)
    {
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < np; k++)
            first[k + 1] = linepar_count(cut[k], cut[k + 1]);
#pragma omp single
        for (int k = 0; k < np; k++)
            first[k + 1] += first[k];
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < np; k++) {
            stop_at[k] = cut[k];
            stop[k] = parse_piece(&stop_at[k], cut[k + 1], first[k], max, fn,
                                  ctx);
        }
    }
    /* the first piece that stopped early (refused a line or reached max) */
    for (int k = 0; k < np; k++)
        if (stop[k] < first[k + 1]) {
            *bytes = (size_t)(stop_at[k] - text);
            return stop[k];
        }
    *bytes = len;
    return first[np];
}
