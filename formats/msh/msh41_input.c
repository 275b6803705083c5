/*
 * msh41_input.c -- buffered reading of an MSH file for the native MSH 4.1
 * path: tokens and lines for the ASCII parts, byte records for the binary
 * parts, with an optional echo of every consumed byte into an output file.
 *
 * stdio's getc would do, but the echo needs to see the bytes in blocks
 * (one fwrite per buffer, not one per byte), so we keep our own 1 MiB
 * buffer and flush the consumed part of it to the echo file whenever it
 * is refilled or the echo is switched.
 */
#include "msh41_internal.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

/* 8 MiB: the ASCII fast path (msh41_fast.c) parses what the buffer holds
   in pieces across threads (linepar.c). */
#define IN_CHUNK (8u << 20)
/* What a refill reads unless the fast path asks for more: copying the
   file through (the writer's echo) is faster through a buffer that stays
   in the cache. */
#define IN_READ (1u << 20)

int msh41_in_open(msh41_input *in, const char *path)
{
    memset(in, 0, sizeof *in);
    in->line = 1;
    in->f = fopen(path, "rb");
    in->buf = getme__malloc(IN_CHUNK);
    if (in->f && in->buf)
        return 0;
    msh41_in_close(in);
    return -1;
}

static void echo_flush(msh41_input *in)
{
    if (in->echo && in->pos > in->echo_from &&
        fwrite(in->buf + in->echo_from, 1, in->pos - in->echo_from,
               in->echo) != in->pos - in->echo_from)
        in->werr = 1;
    in->echo_from = in->pos;
}

void msh41_in_close(msh41_input *in)
{
    echo_flush(in);
    if (in->f)
        fclose(in->f);
    free(in->buf);
    in->f = NULL;
    in->buf = NULL;
}

void msh41_in_echo(msh41_input *in, FILE *out)
{
    echo_flush(in);
    in->echo = out;
    in->echo_from = in->pos;
}

int64_t msh41_in_offset(const msh41_input *in)
{
    return in->base + (int64_t)in->pos;
}

/* Refill once the buffer is used up: 0, or -1 at end of file. */
static int refill(msh41_input *in)
{
    if (in->pos < in->len)
        return 0;
    echo_flush(in);
    in->base += (int64_t)in->len;
    in->pos = in->echo_from = 0;
    in->len = in->f ? fread(in->buf, 1, IN_READ, in->f) : 0;
    return in->len ? 0 : -1;
}

int msh41_in_peek(msh41_input *in)
{
    return refill(in) ? -1 : in->buf[in->pos];
}

int msh41_in_getc(msh41_input *in)
{
    if (refill(in))
        return -1;
    int c = in->buf[in->pos++];
    in->line += c == '\n';
    return c;
}

/* A large read once the buffer is used up goes straight into the caller's
   array: a copy less (the binary elements and nodes are most of a binary
   file).  The echo then writes the bytes from there, after the buffer's
   consumed part, so it still sees every byte once and in order.  Returns
   the bytes read (fewer than n only at the end of the file or an error:
   the caller's next refill then fails as it would have). */
static size_t read_direct(msh41_input *in, unsigned char *d, size_t n)
{
    echo_flush(in);
    in->base += (int64_t)in->len;
    in->pos = in->len = in->echo_from = 0;
    size_t got = fread(d, 1, n, in->f);
    if (in->echo && got && fwrite(d, 1, got, in->echo) != got)
        in->werr = 1;
    in->base += (int64_t)got;
    return got;
}

static int wants_direct(const msh41_input *in, size_t n)
{
    return in->f && in->pos >= in->len && n >= IN_READ;
}

size_t msh41_in_read_some(msh41_input *in, void *dst, size_t n)
{
    unsigned char *d = dst;
    size_t done = 0;
    while (done < n) {
        size_t want = n - done;
        if (wants_direct(in, want)) {
            size_t got = read_direct(in, d + done, want);
            done += got;
            if (got < want)
                break; /* end of file or error */
            continue;
        }
        if (refill(in))
            break;
        size_t k = in->len - in->pos < n - done ? in->len - in->pos : n - done;
        memcpy(d + done, in->buf + in->pos, k);
        in->pos += k;
        done += k;
    }
    return done;
}

int msh41_in_read(msh41_input *in, void *dst, size_t n)
{
    /* skipping (dst NULL) goes through the buffer: the echo copies the
       skipped bytes from there */
    if (dst)
        return msh41_in_read_some(in, dst, n) == n ? 0 : -1;
    while (n) {
        if (refill(in))
            return -1;
        size_t k = in->len - in->pos < n ? in->len - in->pos : n;
        in->pos += k;
        n -= k;
    }
    return 0;
}

int msh41_in_line(msh41_input *in, char *buf, size_t size)
{
    size_t n = 0;
    int c = msh41_in_getc(in);
    if (c < 0)
        return -1;
    for (; c >= 0 && c != '\n'; c = msh41_in_getc(in))
        if (n + 1 < size)
            buf[n++] = (char)c;
    /* CR and trailing blanks: Gmsh takes "$Nodes " for "$Nodes" */
    while (n && (buf[n - 1] == '\r' || buf[n - 1] == ' ' ||
                 buf[n - 1] == '\t' || buf[n - 1] == '\f' ||
                 buf[n - 1] == '\v'))
        n--;
    buf[n] = 0;
    return 0;
}

static int is_space(int c)
{
    return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' ||
           c == '\v';
}

void msh41_in_skip_space(msh41_input *in)
{
    for (;;) {
        /* Inside the buffer without a call per byte; refill at its end. */
        while (in->pos < in->len && is_space(in->buf[in->pos]))
            in->line += in->buf[in->pos++] == '\n';
        if (in->pos < in->len || refill(in))
            return;
    }
}

int msh41_in_token(msh41_input *in, char *tok, size_t size)
{
    msh41_in_skip_space(in);
    size_t n = 0;
    int too_long = 0;
    for (;;) {
        size_t pos = in->pos, len = in->len;
        const unsigned char *b = in->buf;
        while (pos < len && !is_space(b[pos])) {
            if (n + 1 < size)
                tok[n++] = (char)b[pos];
            else
                too_long = 1;
            pos++;
        }
        in->pos = pos;
        if (pos < len || refill(in))
            break;
    }
    tok[n] = 0;
    return too_long ? -1 : (int)n;
}

int msh41_in_eol(msh41_input *in)
{
    int c;
    while ((c = msh41_in_peek(in)) == ' ' || c == '\t' || c == '\r')
        in->pos++;
    if (c == '\n')
        msh41_in_getc(in);
    return c == '\n' || c < 0;
}

const char *msh41_in_window(msh41_input *in, size_t want, size_t *avail)
{
    if (want > IN_CHUNK)
        want = IN_CHUNK;
    /* Refill when less than want is left, or less than 1/16 of the
       buffer: a refill moves what is left to the front, at most a 16th of
       what it then reads. */
    if (in->len - in->pos < (want < IN_CHUNK / 16 ? want : IN_CHUNK / 16) &&
        in->f) {
        echo_flush(in);
        size_t tail = in->len - in->pos;
        memmove(in->buf, in->buf + in->pos, tail);
        in->base += (int64_t)in->pos;
        in->pos = in->echo_from = 0;
        size_t fill = want > IN_READ ? want : IN_READ;
        in->len = tail + fread(in->buf + tail, 1, fill - tail, in->f);
    }
    size_t n = in->len - in->pos;
    *avail = n < want ? n : want;
    return (const char *)in->buf + in->pos;
}

void msh41_in_consume(msh41_input *in, size_t bytes, long lines)
{
    in->pos += bytes;
    in->line += lines;
}
