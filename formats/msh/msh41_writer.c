/*
 * msh41_writer.c -- write a natively read MSH 4.1 or 2.2 file back: a
 * byte-for-byte copy of the input in which only node coordinates in $Nodes
 * change (MSH 2.2: "tag x y z" lines, or int32 tag + 3 doubles records).
 *
 * The input is streamed through msh41_input with its echo on (every byte
 * read is copied to the temporary output); inside $Nodes the echo is
 * switched off for the coordinates only:
 *  - binary: the 24 bytes of a node are replaced by its new doubles (same
 *    file size);
 *  - ASCII: the line "x y z" of a node is rewritten with the shortest of
 *    %.15g / %.16g / %.17g that reads back to the same double, keeping the
 *    line's end ("\n" or "\r\n").
 * A node keeps its bytes unless its coordinates differ from the file's
 * (fixed nodes, nodes outside the mesh and nodes that did not move are
 * copied as they are).  The output goes to a temporary file next to it,
 * with the input's permissions, renamed when complete.
 */
#define _POSIX_C_SOURCE 200809L
#include "msh41_internal.h"
#include "getme_alloc.h"
#include "numformat.h"
#include "numparse.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define NODE_CHUNK 4096

typedef struct writer {
    getme_doc *doc;
    const msh41_doc *m;
    msh41_input in;
    FILE *out;
    const double *xyz; /* current mesh coordinates */
    int failed;        /* the input is not what was read */
} writer;

static uint64_t le64(const unsigned char *b)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | b[i];
    return v;
}

static void put_le64(unsigned char *b, uint64_t v)
{
    for (int i = 0; i < 8; i++, v >>= 8)
        b[i] = (unsigned char)(v & 0xff);
}

/* New coordinates of the node with this tag, or NULL to keep old ones. */
static const double *moved(const writer *w, uint64_t tag, const double *old)
{
    int32_t i = msh41_map_find(&w->m->map, tag);
    if (i < 0)
        return NULL;
    const double *x = w->xyz + 3 * (size_t)i;
    return memcmp(x, old, 3 * sizeof *x) != 0 ? x : NULL;
}

/* ---- binary ------------------------------------------------------------- */

static int bin_u64(writer *w, uint64_t *v)
{
    unsigned char b[8];
    if (msh41_in_read(&w->in, b, 8))
        return -1;
    *v = le64(b);
    return 0;
}

/* Coordinates of count nodes with these tags, chunk by chunk. */
static int bin_coords(writer *w, const uint64_t *tags, size_t count)
{
    unsigned char *buf = getme__malloc(NODE_CHUNK * 24);
    if (!buf)
        return -2;
    msh41_in_echo(&w->in, NULL);
    for (size_t i0 = 0; i0 < count; i0 += NODE_CHUNK) {
        size_t k = count - i0 < NODE_CHUNK ? count - i0 : NODE_CHUNK;
        if (msh41_in_read(&w->in, buf, 24 * k)) {
            free(buf);
            return -1;
        }
        for (size_t j = 0; j < k; j++) {
            double old[3];
            for (int c = 0; c < 3; c++) {
                uint64_t bits = le64(buf + 24 * j + 8 * c);
                memcpy(&old[c], &bits, sizeof bits);
            }
            const double *x = moved(w, tags[i0 + j], old);
            for (int c = 0; x && c < 3; c++) {
                uint64_t bits;
                memcpy(&bits, &x[c], sizeof bits);
                put_le64(buf + 24 * j + 8 * c, bits);
            }
        }
        if (fwrite(buf, 24, k, w->out) != k)
            w->in.werr = 1;
    }
    free(buf);
    msh41_in_echo(&w->in, w->out);
    return 0;
}

static int bin_block(writer *w)
{
    unsigned char head[12];
    uint64_t count;
    if (msh41_in_read(&w->in, head, 12) || bin_u64(w, &count) ||
        count > (uint64_t)w->m->size / 32)
        return -1;
    uint64_t *tags = getme__malloc((count ? (size_t)count : 1) * sizeof *tags);
    int rc = tags ? 0 : -2;
    for (size_t i = 0; rc == 0 && i < count; i++)
        rc = bin_u64(w, &tags[i]);
    if (rc == 0)
        rc = bin_coords(w, tags, (size_t)count);
    free(tags);
    return rc;
}

/* ---- ASCII -------------------------------------------------------------- */

static int ascii_u64(writer *w, uint64_t *v)
{
    char tok[64], *end;
    if (msh41_in_token(&w->in, tok, sizeof tok) <= 0)
        return -1;
    errno = 0;
    *v = strtoull(tok, &end, 10);
    return *end || errno ? -1 : 0;
}

/* Shortest of %.15g/%.16g/%.17g that reads back to v (buf: 32 bytes). */
static int format_double(double v, char *buf)
{
    int n = 0, back = 0;
    for (int prec = 15; prec <= 17 && !back; prec++)
        n = numformat_g(v, prec, buf, &back);
    return n;
}

/* One node's line (read raw, echo off): "x y z" (MSH 4.1, tag given) or
   "tag x y z" (MSH 2.2, tag == 0: read from the line, its text kept);
   the coordinates are rewritten if the node moved. */
static int ascii_coord_line(writer *w, uint64_t tag)
{
    char line[8192], *p = line, *end;
    size_t avail;
    const char *buf = msh41_in_window(&w->in, sizeof line, &avail);
    const char *nl = memchr(buf, '\n', avail);
    size_t n = nl ? (size_t)(nl + 1 - buf) : avail;
    if (n >= sizeof line) /* no newline in 8 KiB */
        return -1;
    memcpy(line, buf, n);
    msh41_in_consume(&w->in, n, nl != NULL);
    line[n] = 0;
    if (tag == 0) {
        errno = 0;
        tag = strtoull(line, &p, 10);
        if (p == line || errno || tag == 0)
            return -1;
    }
    size_t prefix = (size_t)(p - line); /* the tag's text, kept */
    double old[3];
    for (int k = 0; k < 3; k++, p = end) {
        old[k] = numparse_strtod(p, &end);
        if (end == p)
            return -1;
    }
    const double *x = moved(w, tag, old);
    if (!x)
        return fwrite(line, 1, n, w->out) == n ? 0 : -1;
    const char *eol = n >= 2 && line[n - 2] == '\r' ? "\r\n"
                      : n >= 1 && line[n - 1] == '\n' ? "\n"
                                                       : "";
    char text[8192 + 3 * 33 + 3];
    size_t len = prefix;
    memcpy(text, line, prefix);
    for (int k = 0; k < 3; k++) {
        if (k > 0 || prefix)
            text[len++] = ' ';
        len += (size_t)format_double(x[k], text + len);
    }
    for (const char *e = eol; *e; e++)
        text[len++] = *e;
    return fwrite(text, 1, len, w->out) == len ? 0 : -1;
}

static int ascii_block(writer *w)
{
    uint64_t head[4];
    for (int k = 0; k < 4; k++) {
        char tok[64];
        if (msh41_in_token(&w->in, tok, sizeof tok) <= 0)
            return -1;
        head[k] = strtoull(tok, NULL, 10);
    }
    uint64_t count = head[3];
    if (count > (uint64_t)w->m->size / 8)
        return -1;
    uint64_t *tags = getme__malloc((count ? (size_t)count : 1) * sizeof *tags);
    int rc = tags ? 0 : -2;
    for (size_t i = 0; rc == 0 && i < count; i++)
        rc = ascii_u64(w, &tags[i]);
    if (rc == 0 && count && !msh41_in_eol(&w->in)) /* end of the tag line */
        rc = -1;
    msh41_in_echo(&w->in, NULL);
    for (size_t i = 0; rc == 0 && i < count; i++)
        rc = ascii_coord_line(w, tags[i]);
    msh41_in_echo(&w->in, w->out);
    free(tags);
    return rc;
}

/* ---- MSH 2.2: one node per record ---------------------------------------- */

/* Binary: int32 tag + 3 doubles per node, patched in place. */
static int bin_node22(writer *w)
{
    unsigned char rec[28];
    if (msh41_in_read(&w->in, rec, sizeof rec))
        return -1;
    uint32_t t = (uint32_t)rec[0] | (uint32_t)rec[1] << 8 |
                 (uint32_t)rec[2] << 16 | (uint32_t)rec[3] << 24;
    double old[3];
    for (int k = 0; k < 3; k++) {
        uint64_t bits = le64(rec + 4 + 8 * k);
        memcpy(&old[k], &bits, sizeof bits);
    }
    const double *x = moved(w, t, old);
    for (int k = 0; x && k < 3; k++) {
        uint64_t bits;
        memcpy(&bits, &x[k], sizeof bits);
        put_le64(rec + 4 + 8 * k, bits);
    }
    return fwrite(rec, 1, sizeof rec, w->out) == sizeof rec ? 0 : -1;
}

/* The count line, then the nodes (echo off while they are patched). */
static int nodes22(writer *w)
{
    uint64_t count;
    if (ascii_u64(w, &count) || !msh41_in_eol(&w->in) ||
        count > (uint64_t)w->m->size / 8)
        return -1;
    msh41_in_echo(&w->in, NULL);
    int rc = 0;
    for (uint64_t i = 0; rc == 0 && i < count; i++)
        rc = w->m->binary ? bin_node22(w) : ascii_coord_line(w, 0);
    msh41_in_echo(&w->in, w->out);
    return rc;
}

/* ---- the file ----------------------------------------------------------- */

/* Copy up to $Nodes, patch the node blocks, copy the rest. */
static int copy_file(writer *w)
{
    const msh41_doc *m = w->m;
    msh41_in_echo(&w->in, w->out);
    if (msh41_in_read(&w->in, NULL, (size_t)m->nodes_offset))
        return -1;
    uint64_t nblocks = 0, skip;
    int rc = 0;
    if (m->v22)
        rc = nodes22(w);
    else if (m->binary)
        rc = bin_u64(w, &nblocks) || bin_u64(w, &skip) || bin_u64(w, &skip) ||
             bin_u64(w, &skip);
    else
        rc = ascii_u64(w, &nblocks) || ascii_u64(w, &skip) ||
             ascii_u64(w, &skip) || ascii_u64(w, &skip);
    for (uint64_t b = 0; rc == 0 && b < nblocks; b++)
        rc = m->binary ? bin_block(w) : ascii_block(w);
    int64_t rest = m->size - msh41_in_offset(&w->in);
    if (rc == 0 && (rest < 0 || msh41_in_read(&w->in, NULL, (size_t)rest)))
        rc = -1;
    if (rc == 0 && msh41_in_peek(&w->in) >= 0)
        rc = -1; /* longer than when it was read */
    return rc;
}

static int same_input(const msh41_doc *m, const struct stat *sb)
{
    int64_t mtime = (int64_t)sb->st_mtim.tv_sec * 1000000000 +
                    sb->st_mtim.tv_nsec;
    return (int64_t)sb->st_size == m->size && (uint64_t)sb->st_dev == m->dev &&
           (uint64_t)sb->st_ino == m->ino && mtime == m->mtime_ns;
}

static getme_formats_status write_tmp(writer *w, const char *tmp,
                                 const char *out_path)
{
    getme_doc *doc = w->doc;
    struct stat sb;
    if (msh41_in_open(&w->in, doc->path))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "Cannot open '%s': %s",
                              doc->path, strerror(errno));
    if (fstat(fileno(w->in.f), &sb) != 0 || !same_input(w->m, &sb)) {
        msh41_in_close(&w->in);
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "'%s' changed since it was read: not writing",
                              doc->path);
    }
    w->out = fopen(tmp, "wb");
    if (!w->out) {
        int e = errno;
        msh41_in_close(&w->in);
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "Cannot write '%s': %s",
                              out_path, strerror(e));
    }
    /* getme_io_tmp_path made it with the umask's mode: the input's instead */
    (void)fchmod(fileno(w->out), sb.st_mode & 07777);
    int rc = copy_file(w);
    int werr = w->in.werr;
    msh41_in_echo(&w->in, NULL); /* flushes what is still pending */
    werr |= w->in.werr;
    msh41_in_close(&w->in);
    int e = errno;
    if (fclose(w->out) != 0)
        werr = 1;
    if (rc == -2)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "Out of memory");
    if (rc)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "'%s' changed since it was read: not writing",
                              doc->path);
    if (werr)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "Cannot write '%s': %s",
                              out_path, strerror(e ? e : EIO));
    return GETME_FORMATS_OK;
}

getme_formats_status msh41_write(getme_doc *doc, const msh41_doc *m,
                            const char *out_path)
{
    char tmp[4096];
    if (getme_io_tmp_path(out_path, tmp, sizeof tmp) != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "Cannot create a temporary file next to '%s'",
                              out_path);
    writer w;
    memset(&w, 0, sizeof w);
    w.doc = doc;
    w.m = m;
    w.xyz = getme_mesh_coords(doc->mesh);
    getme_formats_status st = write_tmp(&w, tmp, out_path);
    if (st != GETME_FORMATS_OK) {
        remove(tmp);
        return st;
    }
    if (getme_io_commit(tmp, out_path) != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "Cannot write '%s': %s",
                              out_path, strerror(errno));
    return GETME_FORMATS_OK;
}
