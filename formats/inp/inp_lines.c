/*
 * inp_lines.c -- streaming line reader and data-line fields of the INP
 * adapter.  One buffer per open file, reused for every line: a deck of any
 * size is read with constant memory for its text.
 */
#include "inp_internal.h"
#include "getme_alloc.h"
#include "numformat.h"
#include "numparse.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CHUNK (1 << 16)

int inp_lines_open(inp_lines *r, const char *path)
{
    memset(r, 0, sizeof *r);
    r->fp = fopen(path, "rb");
    if (!r->fp)
        return -1;
    r->cap = 4 * CHUNK;
    r->buf = getme__malloc(r->cap + 1);
    if (!r->buf) {
        fclose(r->fp);
        r->fp = NULL;
        errno = ENOMEM;
        return -1;
    }
    return 0;
}

void inp_lines_close(inp_lines *r)
{
    if (r->fp)
        fclose(r->fp);
    free(r->buf);
    memset(r, 0, sizeof *r);
}

/* Move the unread bytes to the front and read more; grow the buffer only
   when one line does not fit.  0, -1 read error, -2 line too long. */
static int refill(inp_lines *r)
{
    if (r->beg > 0) {
        memmove(r->buf, r->buf + r->beg, r->end - r->beg);
        r->end -= r->beg;
        r->beg = 0;
    }
    if (r->end == r->cap) {
        if (r->cap > INP_MAX_LINE)
            return -2;
        char *b = getme__realloc(r->buf, 2 * r->cap + 1);
        if (!b)
            return -1;
        r->buf = b;
        r->cap *= 2;
    }
    size_t got = fread(r->buf + r->end, 1, r->cap - r->end, r->fp);
    if (got == 0) {
        if (ferror(r->fp))
            return -1;
        r->eof = 1;
    }
    r->end += got;
    return 0;
}

int inp_lines_next(inp_lines *r)
{
    char *nl;
    for (;;) {
        nl = memchr(r->buf + r->beg, '\n', r->end - r->beg);
        if (nl || r->eof)
            break;
        int rc = refill(r);
        if (rc)
            return rc;
    }
    if (!nl && r->beg == r->end)
        return 0;
    char *start = r->buf + r->beg;
    size_t len = nl ? (size_t)(nl - start) : r->end - r->beg;
    size_t used = nl ? len + 1 : len;
    r->term = nl ? "\n" : "";
    if (nl && len > 0 && start[len - 1] == '\r') {
        len--;
        r->term = "\r\n";
    }
    if (len > INP_MAX_LINE)
        return -2;
    /* The terminator byte (or the spare byte after the buffer) becomes the
       NUL, so callers get a C string without copying. */
    start[len] = '\0';
    if (r->lineno == 0 && len >= 3 && memcmp(start, "\xEF\xBB\xBF", 3) == 0) {
        /* Windows editors may start a deck with a byte order mark. */
        r->bom = 1;
        start += 3;
        len -= 3;
    }
    r->text = start;
    r->len = len;
    r->offset = r->next_offset;
    r->next_offset += (int64_t)used;
    r->beg += used;
    r->lineno++;
    return 1;
}

static int is_blank(int c) { return c == ' ' || c == '\t' || c == '\r'; }

int inp_line_kind(const char *text, size_t len)
{
    size_t i = 0;
    while (i < len && is_blank((unsigned char)text[i]))
        i++;
    if (i == len)
        return INP_LINE_BLANK;
    if (text[i] == '*')
        return i + 1 < len && text[i + 1] == '*' ? INP_LINE_COMMENT
                                                 : INP_LINE_KEYWORD;
    return INP_LINE_DATA;
}

int inp_next_field(const char **p, const char *end, inp_field *f, int *last)
{
    const char *s = *p;
    if (!s || s > end)
        return 0;
    const char *c = memchr(s, ',', (size_t)(end - s));
    const char *e = c ? c : end;
    while (s < e && is_blank((unsigned char)*s))
        s++;
    const char *t = e;
    while (t > s && is_blank((unsigned char)t[-1]))
        t--;
    f->s = s;
    f->n = (size_t)(t - s);
    *last = c == NULL;
    /* After the last field *p is past the end, so the next call says 0. */
    *p = c ? c + 1 : end + 1;
    return 1;
}

int inp_parse_int(const inp_field *f, int64_t *v)
{
    size_t i = 0;
    int neg = 0;
    if (f->n == 0)
        return -1;
    if (f->s[0] == '+' || f->s[0] == '-') {
        neg = f->s[0] == '-';
        i = 1;
    }
    if (i == f->n)
        return -1;
    int64_t x = 0;
    for (; i < f->n; i++) {
        int c = (unsigned char)f->s[i];
        if (c < '0' || c > '9')
            return -1;
        if (x > (INT64_MAX - 9) / 10)
            return -1;
        x = 10 * x + (c - '0');
    }
    *v = neg ? -x : x;
    return 0;
}

int inp_parse_real(const inp_field *f, double *v)
{
    char tmp[INP_MAX_TOKEN];
    if (f->n == 0) {
        *v = 0.0;
        return 0;
    }
    if (f->n >= sizeof tmp)
        return -1;
    int c0 = (unsigned char)f->s[0];
    /* strtod would also take "nan", "inf" and hex floats: not numbers in
       an input deck. */
    if (!(c0 == '+' || c0 == '-' || c0 == '.' || (c0 >= '0' && c0 <= '9')))
        return -1;
    for (size_t i = 0; i < f->n; i++) {
        int c = (unsigned char)f->s[i];
        if (c == 'x' || c == 'X')
            return -1;
        /* Fortran double-precision exponents: 1.5D+03. */
        tmp[i] = (char)(c == 'd' || c == 'D' ? 'e' : c);
    }
    tmp[f->n] = '\0';
    char *endp;
    errno = 0;
    double x = numparse_strtod(tmp, &endp);
    if (endp != tmp + f->n || !isfinite(x))
        return -1;
    *v = x;
    return 0;
}

int inp_is_label(const inp_field *f)
{
    if (f->n == 0)
        return 0;
    int c = (unsigned char)f->s[0];
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' ||
           c == '"';
}

int inp_format_real(double v, char *buf)
{
    /* Abaqus reads at most 20 characters per real field.  Values that came
       from short decimal text come back short (%.15g); anything else gets
       the 17 significant digits that always read back to the same double.
       numformat_g is snprintf's "%.*g" without printf's cost. */
    int back;
    int n = numformat_g(v, 15, buf, &back);
    if (n <= 20 && back)
        return n;
    n = numformat_g(v, 17, buf, NULL);
    if (n <= 20)
        return n;
    /* Tiny or huge magnitudes with a long exponent: as many digits as fit
       (a relative change below 1e-15, on a free node only). */
    for (int prec = 16; prec > 1; prec--) {
        n = numformat_g(v, prec, buf, NULL);
        if (n <= 20)
            return n;
    }
    return numformat_g(v, 1, buf, NULL);
}

const char *inp_lines_window(inp_lines *r, size_t want, size_t *avail)
{
    /* Refill when less than want is left and less than 1/16 of the
       buffer: a refill moves what is left to the front, at most a 16th of
       what it then reads.  A buffer smaller than want grows at once,
       however much is left in it: the line reader (inp_lines_next, which
       runs after every stop of the fast path) refills only up to the
       buffer's size, so waiting for the rest to run low kept every window
       just under the first buffer's 256 KiB, below linepar's threshold
       for splitting a run across threads: the INP fast path ran on one
       thread.  Growing moves at most that first buffer, once per
       doubling of want. */
    size_t low = want < r->cap / 16 ? want : r->cap / 16;
    int grow = want > r->cap;
    if ((r->end - r->beg < low || grow) && !r->eof) {
        if (r->beg > 0) {
            memmove(r->buf, r->buf + r->beg, r->end - r->beg);
            r->end -= r->beg;
            r->beg = 0;
        }
        if (grow) {
            char *b = getme__realloc(r->buf, want + 1);
            if (b) { /* else the window stays the buffer's size */
                r->buf = b;
                r->cap = want;
            }
        }
        /* a full buffer reads nothing: that is not the end of the file */
        if (r->end < r->cap) {
            size_t got = fread(r->buf + r->end, 1, r->cap - r->end, r->fp);
            if (got == 0 && !ferror(r->fp))
                r->eof = 1; /* a read error shows at the next inp_lines_next */
            r->end += got;
        }
    }
    size_t n = r->end - r->beg;
    *avail = n < want ? n : want;
    return r->buf + r->beg;
}

void inp_lines_consume(inp_lines *r, size_t bytes, size_t lines)
{
    r->beg += bytes;
    r->next_offset += (int64_t)bytes;
    r->offset = r->next_offset;
    r->lineno += (uint32_t)lines;
}

int inp_lines_copy(inp_lines *r, int64_t to, FILE *out)
{
    int at_start = 1; /* the last byte copied ends a line */
    if (to < r->next_offset)
        return 1;
    while (r->next_offset < to) {
        if (r->beg == r->end) {
            if (r->eof)
                return to == INT64_MAX ? 0 : 1;
            if (refill(r))
                return -1;
            continue;
        }
        size_t n = r->end - r->beg;
        if ((int64_t)n > to - r->next_offset)
            n = (size_t)(to - r->next_offset);
        const char *p = r->buf + r->beg, *end = p + n;
        if (fwrite(p, 1, n, out) != n)
            return -1;
        uint32_t lines = 0;
        while ((p = memchr(p, '\n', (size_t)(end - p))) != NULL) {
            p++;
            lines++;
        }
        at_start = end[-1] == '\n';
        r->beg += n;
        r->next_offset += (int64_t)n;
        r->lineno += lines;
    }
    r->offset = r->next_offset;
    return at_start ? 0 : 1;
}
