/*
 * msh41_fast.c -- the fast path of the ASCII MSH reader: node tags,
 * coordinates and element records parsed a buffer's worth of lines at a
 * time, on several threads (linepar.c), straight from the read buffer.
 *
 * msh41_reader.c reads every record with its token reader (one call per
 * token, a copy of each token, one error message per kind of problem).
 * The fast path takes only lines that hold exactly one well-formed record
 * (Gmsh writes one per line) and refuses any other line: the token reader
 * then reads that record, with its own checks and messages, and the fast
 * path resumes at the next line.  So a file the fast path takes is read
 * into the same arrays as by the token reader, a file it refuses gets the
 * same error at the same line, and the arrays are filled at each record's
 * index: the same bytes for any thread count.
 *
 * What a line must be to be taken:
 *   - tokens separated by blanks (space, tab, CR, FF, VT), as many as the
 *     record has, nothing else before the newline;
 *   - integers: 1 to 18 decimal digits (the token reader also takes a '+'
 *     and 19-digit values: those lines are refused here, not rejected);
 *   - reals: what numparse_strtod reads in full, finite, shorter than the
 *     token reader's limit;
 *   - elements: nodes that exist and do not repeat in a kept element.
 */
#define _GNU_SOURCE /* memrchr */
#include "msh41_internal.h"
#include "linepar.h"
#include "numparse.h"
#include "msh41_digits.h"

#include <math.h>
#include <string.h>

#define MSH41_TOKEN_MAX 127 /* msh41_reader.c's TOK - 1 */
#define WANT_MIN ((size_t)4096)
#define WANT_MAX ((size_t)8 << 20)

/* Blanks between tokens; a line's '\n' ends every scan below (the run
   handed to linepar ends with one). */
static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

static const char *skip_blanks(const char *p)
{
    while (is_blank(*p))
        p++;
    return p;
}

/* The rest of the line is blank: the next line's start, else NULL. */
static const char *line_end(const char *p)
{
    p = skip_blanks(p);
    return *p == '\n' ? p + 1 : NULL;
}

static int fast_u64(const char **p, const char *end, uint64_t *v)
{
    return msh41_digits(skip_blanks(*p), end, p, v);
}

static int fast_double(const char **p, double *v)
{
    const char *s = skip_blanks(*p);
    char *end;
    if (*s == '\n') /* numparse_strtod would skip it */
        return -1;
    double x = numparse_strtod(s, &end);
    if (end == s || end - s > MSH41_TOKEN_MAX ||
        !(is_blank(*end) || *end == '\n') || !isfinite(x))
        return -1;
    *v = x;
    *p = end;
    return 0;
}

typedef struct fast_ctx {
    msh41_reader *r;
    const msh41_fast_job *job;
    size_t base; /* record index of the run's first line */
} fast_ctx;

static const char *tag_line(void *vc, const char *p, const char *end,
                            size_t i)
{
    fast_ctx *c = vc;
    uint64_t t;
    if (fast_u64(&p, end, &t) || !(p = line_end(p)))
        return NULL;
    c->job->tags[c->base + i] = t;
    return p;
}

static const char *coord_line(void *vc, const char *p, const char *end,
                              size_t i)
{
    fast_ctx *c = vc;
    double x[3];
    (void)end;
    for (int k = 0; k < 3; k++)
        if (fast_double(&p, &x[k]))
            return NULL;
    if (!(p = line_end(p)))
        return NULL;
    double *dst = c->job->xyz + 3 * (c->base + i);
    dst[0] = x[0];
    dst[1] = x[1];
    dst[2] = x[2];
    return p;
}

static const char *element_line(void *vc, const char *p, const char *end,
                                size_t i)
{
    fast_ctx *c = vc;
    const msh41_fast_job *job = c->job;
    uint64_t rec[MSH41_MAX_REC];
    for (int k = 0; k <= job->nv; k++)
        if (fast_u64(&p, end, &rec[k]))
            return NULL;
    if (!(p = line_end(p)) ||
        msh41_store_element(c->r, job->b, c->base + i, rec, job->nv,
                            job->fix))
        return NULL;
    return p;
}

size_t msh41_fast(msh41_reader *r, const msh41_fast_job *job, size_t first,
                  size_t n)
{
    linepar_fn fn = job->kind == MSH41_FAST_TAGS     ? tag_line
                    : job->kind == MSH41_FAST_COORDS ? coord_line
                                                     : element_line;
    if (job->kind == MSH41_FAST_ELEMENTS && job->nv + 1 > MSH41_MAX_REC)
        return 0;
    /* --fix flags are set while parsing: one thread, no shared writes */
    int threads = job->fix ? 1 : r->threads;
    fast_ctx c = {r, job, first};
    size_t done = 0;
    /* The window grows while lines are taken and shrinks back after a
       refused one, so a file the fast path keeps refusing costs a few
       lines of scanning per record, not a buffer's worth. */
    while (done < n) {
        size_t avail, bytes;
        if (r->fast_want < WANT_MIN)
            r->fast_want = WANT_MIN;
        const char *w = msh41_in_window(&r->in, r->fast_want, &avail);
        const char *nl = avail ? memrchr(w, '\n', avail) : NULL;
        if (!nl)
            break;
        c.base = first + done;
        size_t got = linepar_run(w, (size_t)(nl + 1 - w), n - done, threads,
                                 fn, &c, &bytes);
        msh41_in_consume(&r->in, bytes, (long)got);
        done += got;
        if (bytes <= (size_t)(nl - w) && done < n) { /* a refused line */
            r->fast_want = WANT_MIN;
            break;
        }
        if (r->fast_want < WANT_MAX)
            r->fast_want *= 2;
    }
    return done;
}
