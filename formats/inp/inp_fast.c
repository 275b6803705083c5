/*
 * inp_fast.c -- the fast path of the INP reader: runs of plain *NODE and
 * *ELEMENT data lines parsed straight from the line reader's buffer, a
 * piece per thread (linepar.c), into the deck's arrays at known offsets.
 *
 * inp_reader.c reads a deck line by line: kind of line, comma fields
 * trimmed, each number checked, one message per kind of problem.  Inside
 * a *NODE or *ELEMENT block most lines are the same shape, and this file
 * takes only those:
 *   *NODE     "id, x, y, z"            (3 coordinates, no empty field)
 *   *ELEMENT  "id, n1, ..., nv"        (exactly the type's nv nodes on
 *                                       the line, no trailing comma)
 * with blanks (space, tab; CR before the newline) around fields, ids of 1
 * to 10 digits up to 2^31-1, nodes of elements >= 1, reals that
 * numparse_strtod reads in full, finite, shorter than INP_MAX_TOKEN.  Any
 * other line (a keyword, a comment, a blank line, a continued element, a
 * bad number...) stops the run there; inp_reader.c reads it as before,
 * with the same message at the same line whatever the thread count, and
 * the fast path resumes after it.
 */
#define _GNU_SOURCE /* memrchr */
#include "inp_internal.h"
#include "linepar.h"
#include "numparse.h"

#include <math.h>
#include <string.h>

static int is_blank(char c) { return c == ' ' || c == '\t'; }

static const char *skip_blanks(const char *p)
{
    while (is_blank(*p))
        p++;
    return p;
}

/* After a field: blanks, then ',' (*more = 1) or the line's end ("\n" or
   "\r\n": *more = 0).  The next field's start or the next line's, NULL if
   something else follows. */
static const char *after_field(const char *p, int *more)
{
    p = skip_blanks(p);
    if (*p == ',') {
        *more = 1;
        return p + 1;
    }
    *more = 0;
    if (*p == '\r')
        p++;
    return *p == '\n' ? p + 1 : NULL;
}

/* An id 1..INT32_MAX (nodes of elements: the same range). */
static const char *fast_id(const char *p, int32_t *v, int *more)
{
    const char *s = skip_blanks(p), *d = s;
    int64_t x = 0;
    for (; *s >= '0' && *s <= '9'; s++) {
        if (s - d == 10)
            return NULL;
        x = 10 * x + (*s - '0');
    }
    if (s == d || x < 1 || x > INT32_MAX)
        return NULL;
    *v = (int32_t)x;
    return after_field(s, more);
}

static const char *fast_real(const char *p, double *v, int *more)
{
    const char *s = skip_blanks(p);
    int c0 = (unsigned char)*s;
    if (!(c0 == '+' || c0 == '-' || c0 == '.' || (c0 >= '0' && c0 <= '9')))
        return NULL; /* empty, nan, inf... (inp_parse_real decides) */
    const char *h = s + (c0 == '+' || c0 == '-');
    if (h[0] == '0' && (h[1] == 'x' || h[1] == 'X'))
        return NULL; /* hexadecimal: refused by inp_parse_real */
    char *end;
    double x = numparse_strtod(s, &end);
    if (end == s || end - s >= INP_MAX_TOKEN || !isfinite(x))
        return NULL;
    *v = x;
    return after_field(end, more);
}

typedef struct fast_ctx {
    inp_deck *d;
    int32_t node0, elem0;   /* first node / element index of the run   */
    int64_t conn0;          /* first connectivity entry of the run     */
    uint32_t line0;         /* line number of the run's first line     */
    int nv;
} fast_ctx;

static const char *node_line(void *vc, const char *p, const char *end,
                             size_t i)
{
    fast_ctx *c = vc;
    int32_t id;
    double x[3];
    int more;
    (void)end;
    if (!(p = fast_id(p, &id, &more)) || !more)
        return NULL;
    for (int k = 0; k < 3; k++)
        if (!(p = fast_real(p, &x[k], &more)) || more != (k < 2))
            return NULL;
    size_t n = (size_t)c->node0 + i;
    c->d->node_id[n] = id;
    c->d->node_line[n] = c->line0 + (uint32_t)i;
    memcpy(&c->d->xyz[3 * n], x, sizeof x);
    return p;
}

static const char *element_line(void *vc, const char *p, const char *end,
                                size_t i)
{
    fast_ctx *c = vc;
    int32_t id, *conn = c->d->conn + c->conn0 + (int64_t)i * c->nv;
    int more;
    (void)end;
    if (!(p = fast_id(p, &id, &more)) || !more)
        return NULL;
    for (int k = 0; k < c->nv; k++)
        if (!(p = fast_id(p, &conn[k], &more)) || more != (k < c->nv - 1))
            return NULL;
    size_t e = (size_t)c->elem0 + i;
    c->d->elem_id[e] = id;
    c->d->elem_line[e] = c->line0 + (uint32_t)i;
    return p;
}

/* A set's data line of exactly nv ids (items go to conn0 + i * nv of the
   pool), a trailing comma allowed. */
static const char *set_line(void *vc, const char *p, const char *end,
                            size_t i)
{
    fast_ctx *c = vc;
    int32_t *dst = c->d->items + c->conn0 + (int64_t)i * c->nv;
    int more = 1;
    (void)end;
    for (int k = 0; k < c->nv; k++)
        if (!more || !(p = fast_id(p, &dst[k], &more)))
            return NULL;
    if (more) { /* "..., 10," then nothing but blanks */
        p = skip_blanks(p);
        if (*p == '\r')
            p++;
        if (*p != '\n')
            return NULL;
        p++;
    }
    return p;
}

/* The ids on the line at p if it is a plain set line (set_line's shape),
   at most 64; else 0. */
static int set_line_ids(const char *p)
{
    int k = 0, more = 1;
    int32_t v;
    while (more) {
        const char *q = skip_blanks(p);
        if (k > 0 && (*q == '\n' || (q[0] == '\r' && q[1] == '\n')))
            break; /* a trailing comma */
        if (k == 64 || !(p = fast_id(p, &v, &more)))
            return 0;
        k++;
    }
    return k;
}

#define WANT_MIN ((size_t)4096)
#define WANT_MAX ((size_t)8 << 20)

/* The window of whole lines at the reader's position: its start, *len
   bytes and *max lines; NULL if it holds no whole line.  The window grows
   while lines are taken and shrinks back after a refused one (end_window):
   a block the fast path keeps refusing (elements continued over two
   lines...) costs a few lines of scanning per line, not a buffer's worth. */
static const char *window(inp_lines *in, size_t *want, size_t *len,
                          size_t *max)
{
    if (*want < WANT_MIN)
        *want = WANT_MIN;
    size_t avail;
    const char *w = inp_lines_window(in, *want, &avail);
    const char *nl = avail ? memrchr(w, '\n', avail) : NULL;
    if (!nl || in->lineno + (*max = linepar_count(w, nl + 1)) >= UINT32_MAX)
        return NULL;
    *len = (size_t)(nl + 1 - w);
    return w;
}

/* got of the window's max lines taken, bytes long: consumed, and the next
   window's size. */
static size_t end_window(inp_lines *in, size_t *want, size_t bytes,
                         size_t got, size_t max)
{
    inp_lines_consume(in, bytes, got);
    if (got < max)
        *want = WANT_MIN;
    else if (*want < WANT_MAX)
        *want *= 2;
    return got;
}

size_t inp_fast_run(inp_deck *d, inp_lines *in, int nv, int threads,
                    size_t *want)
{
    size_t len, max;
    const char *w = window(in, want, &len, &max);
    if (!w)
        return 0;
    fast_ctx c = {d, d->nnodes, d->nelems, d->nconn, in->lineno + 1, nv};
    if (nv == 0) {
        if ((size_t)d->nnodes + max >= INT32_MAX / 3 - 1 ||
            inp_reserve_nodes(d, (size_t)d->nnodes + max))
            return 0; /* inp_reader.c says why */
    } else if ((size_t)d->nelems + max >= INT32_MAX - 1 ||
               d->nconn + (int64_t)(max * (size_t)nv) >= INT32_MAX * 4LL ||
               inp_reserve_elems(d, (size_t)d->nelems + max) ||
               INP_RESERVE(d->conn, d->cap_conn,
                           (size_t)d->nconn + max * (size_t)nv)) {
        return 0;
    }
    size_t bytes,
           got = linepar_run(w, len, max, threads,
                             nv ? element_line : node_line, &c, &bytes);
    if (nv == 0) {
        d->nnodes += (int32_t)got;
    } else {
        d->nelems += (int32_t)got;
        d->nconn += (int64_t)(got * (size_t)nv);
    }
    return end_window(in, want, bytes, got, max);
}

size_t inp_fast_set(inp_deck *d, inp_lines *in, int threads, size_t *want)
{
    size_t len, max;
    const char *w = window(in, want, &len, &max);
    int k = w ? set_line_ids(w) : 0;
    if (!k || (size_t)d->nitems + max * (size_t)k >= INT32_MAX ||
        INP_RESERVE(d->items, d->cap_items, (size_t)d->nitems + max * (size_t)k))
        return 0; /* the line reader says why */
    fast_ctx c = {d, 0, 0, d->nitems, in->lineno + 1, k};
    size_t bytes, got = linepar_run(w, len, max, threads, set_line, &c, &bytes);
    d->nitems += (int64_t)(got * (size_t)k);
    return end_window(in, want, bytes, got, max);
}
