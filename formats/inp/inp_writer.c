/*
 * inp_writer.c -- write the deck back with the smoothed coordinates.
 *
 * Every file (the deck and each *INCLUDE occurrence) is re-read and copied
 * byte for byte, with its own line endings: what lies between node blocks
 * and *INCLUDE lines as it is, a buffer at a time; node lines in runs
 * rewritten on several threads (inp_write_nodes.c); the rest line by
 * line.  Two kinds of lines change:
 *  - a *NODE data line whose node moved: the coordinate fields get the new
 *    values, everything else on the line (node number, spacing, extra
 *    fields) stays; a node that did not move, or moved by no more than
 *    1e-12 times the bounding-box diagonal (a rounding step, see
 *    keep_tolerance), keeps its original text, so fixed nodes stay
 *    bit-identical and unmoved nodes do not show up in a diff;
 *  - an *INCLUDE line: its INPUT= value names the written copy of the
 *    included file, "<output stem>.<included file name>" next to the
 *    output (a "-2", "-3"... before the extension if two included files
 *    share a name).
 * Everything goes to temporary files that are renamed only once all are
 * complete: no partial output, the input is never touched.
 */
#define _POSIX_C_SOURCE 200809L
#include "inp_internal.h"
#include "getme_alloc.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#define PATH_BUF 4096

typedef struct writer {
    getme_doc *doc;
    const inp_doc *st;
    const double *xyz;
    int dim;
    char (*out)[PATH_BUF]; /* final name per file occurrence        */
    char (*tmp)[PATH_BUF]; /* temporary name per file occurrence    */
    int32_t moved;         /* node lines rewritten                  */
    inp_node_out nodes;    /* coordinates, tolerance, run buffer     */
    char *line;            /* one node line (INP_MAX_LINE + GROW)    */
} writer;

static const char *base_name(const char *p)
{
    const char *s = strrchr(p, '/');
    return s ? s + 1 : p;
}

/* Output names: the deck to out_path, includes next to it. */
static getme_formats_status name_outputs(writer *w, const char *out_path)
{
    const inp_doc *st = w->st;
    const char *base = base_name(out_path);
    size_t dirlen = (size_t)(base - out_path);
    const char *dot = strrchr(base, '.');
    size_t stemlen = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    if (strlen(out_path) >= PATH_BUF - 64)
        return getme_doc_fail(w->doc, GETME_FORMATS_ERR_WRITE, "%s: path too long",
                              out_path);
    snprintf(w->out[0], PATH_BUF, "%s", out_path);
    for (size_t i = 1; i < st->nfiles; i++) {
        const char *inc = base_name(st->files[i].path);
        const char *idot = strrchr(inc, '.');
        size_t ilen = idot && idot != inc ? (size_t)(idot - inc) : strlen(inc);
        const char *ext = idot && idot != inc ? idot : "";
        for (int n = 1;; n++) {
            char suffix[16] = "";
            if (n > 1)
                snprintf(suffix, sizeof suffix, "-%d", n);
            int len = snprintf(w->out[i], PATH_BUF, "%.*s%.*s.%.*s%s%s",
                               (int)dirlen, out_path, (int)stemlen, base,
                               (int)ilen, inc, suffix, ext);
            if (len < 0 || len >= PATH_BUF)
                return getme_doc_fail(w->doc, GETME_FORMATS_ERR_WRITE,
                                      "%s: path too long", out_path);
            int clash = 0;
            for (size_t j = 0; j < i && !clash; j++)
                clash = strcmp(w->out[j], w->out[i]) == 0;
            if (!clash)
                break;
        }
    }
    /* Never replace anything but a regular file (the deck's own name was
       checked by getme_doc_write). */
    for (size_t i = 1; i < st->nfiles; i++) {
        struct stat sb;
        if (lstat(w->out[i], &sb) == 0 && !S_ISREG(sb.st_mode))
            return getme_doc_fail(w->doc, GETME_FORMATS_ERR_ARGUMENT,
                                  "output '%s' (the copy of included '%s') "
                                  "exists and is not a regular file",
                                  w->out[i], st->files[i].path);
    }
    /* Never overwrite any file of the input deck. */
    for (size_t i = 0; i < st->nfiles; i++)
        for (size_t j = 0; j < st->nfiles; j++)
            if (getme_io_same_file(w->out[i], st->files[j].path))
                return getme_doc_fail(w->doc, GETME_FORMATS_ERR_ARGUMENT,
                                      "output '%s' would overwrite input '%s'",
                                      w->out[i], st->files[j].path);
    return GETME_FORMATS_OK;
}

/* ---- one node line ---------------------------------------------------------- */

static int put(FILE *out, const char *s, size_t n)
{
    return n && fwrite(s, 1, n, out) != n ? -1 : 0;
}

/* 1: the line is not node `id` (the file changed); -1: write error. */
static int node_line(writer *w, FILE *out, const inp_lines *in, int32_t node)
{
    long n = inp_node_text(&w->nodes, in->text, in->len, node, w->line,
                           &w->moved);
    return n < 0 ? 1 : put(out, w->line, (size_t)n);
}

/* ---- one file --------------------------------------------------------------- */

static int include_line(writer *w, FILE *out, const inp_lines *in,
                        const inp_include *inc)
{
    if (inc->col < 0 || (size_t)(inc->col + inc->len) > in->len)
        return 1;
    const char *name = base_name(w->out[inc->child]);
    int quoted = inc->len > 0 && in->text[inc->col] == '"';
    if (put(out, in->text, (size_t)inc->col) || (quoted && put(out, "\"", 1)) ||
        put(out, name, strlen(name)) || (quoted && put(out, "\"", 1)) ||
        put(out, in->text + inc->col + inc->len,
            in->len - (size_t)(inc->col + inc->len)))
        return -1;
    return 0;
}

static getme_formats_status changed(writer *w, int file)
{
    return getme_doc_fail(w->doc, GETME_FORMATS_ERR_WRITE,
                          "'%s' changed since it was read: not writing",
                          w->st->files[file].path);
}

static int unchanged(const inp_file *f)
{
    struct stat sb;
    return stat(f->path, &sb) == 0 && (int64_t)sb.st_size == f->size &&
           (int64_t)sb.st_mtim.tv_sec == f->mtime_sec &&
           (int64_t)sb.st_mtim.tv_nsec == f->mtime_nsec;
}

typedef struct cursor {
    size_t nb, inc;        /* next node block / include of this file   */
    int32_t node, remain;  /* inside a node block                      */
} cursor;

static size_t next_nblock(const inp_doc *st, size_t k, int file)
{
    while (k < st->nnblocks && st->nblocks[k].file != file)
        k++;
    return k;
}

static size_t next_inc(const inp_doc *st, size_t k, int file)
{
    while (k < st->nincs && st->incs[k].file != file)
        k++;
    return k;
}

/* Copy one line, patched if needed: 0 ok, 1 file changed, -1 write error. */
static int copy_line(writer *w, FILE *out, const inp_lines *in, int file,
                     cursor *c)
{
    const inp_doc *st = w->st;
    int rc;
    if (in->lineno == 1 && in->bom && put(out, "\xEF\xBB\xBF", 3))
        return -1;
    if (c->inc < st->nincs && st->incs[c->inc].offset == in->offset) {
        rc = include_line(w, out, in, &st->incs[c->inc]);
        c->inc = next_inc(st, c->inc + 1, file);
    } else if (c->remain == 0 && c->nb < st->nnblocks &&
               st->nblocks[c->nb].offset == in->offset) {
        c->node = st->nblocks[c->nb].first;
        c->remain = st->nblocks[c->nb].count;
        c->nb = next_nblock(st, c->nb + 1, file);
        rc = node_line(w, out, in, c->node++);
        c->remain--;
    } else if (c->remain > 0) {
        int kind = inp_line_kind(in->text, in->len);
        if (kind == INP_LINE_KEYWORD)
            return 1;
        if (kind == INP_LINE_DATA) {
            rc = node_line(w, out, in, c->node++);
            c->remain--;
        } else {
            rc = put(out, in->text, in->len);
        }
    } else {
        rc = put(out, in->text, in->len);
    }
    if (rc)
        return rc;
    return put(out, in->term, strlen(in->term));
}

static getme_formats_status write_file(writer *w, int file)
{
    const inp_doc *st = w->st;
    const char *path = st->files[file].path;
    if (!unchanged(&st->files[file]))
        return changed(w, file);
    inp_lines in;
    if (inp_lines_open(&in, path))
        return getme_doc_fail(w->doc, GETME_FORMATS_ERR_OPEN, "cannot reopen '%s': %s",
                              path, strerror(errno));
    FILE *out = fopen(w->tmp[file], "wb");
    if (!out) {
        int e = errno;
        inp_lines_close(&in);
        return getme_doc_fail(w->doc, GETME_FORMATS_ERR_WRITE, "cannot write '%s': %s",
                              w->out[file], strerror(e));
    }
    static const size_t outbuf = 1 << 20;
    setvbuf(out, NULL, _IOFBF, outbuf);
    cursor c = {next_nblock(st, 0, file), next_inc(st, 0, file), 0, 0};
    int rc = 0, r = 1;
    while (rc == 0) {
        /* Outside node blocks, up to the next node block or *INCLUDE
           line, the file is copied as it is, in the reader's buffers
           (line by line, the copy of the element lines and sets was most
           of the writing: 0.77 s for 4M tets). */
        if (c.remain == 0) {
            int64_t to = INT64_MAX;
            if (c.nb < st->nnblocks)
                to = st->nblocks[c.nb].offset;
            if (c.inc < st->nincs && st->incs[c.inc].offset < to)
                to = st->incs[c.inc].offset;
            if ((rc = inp_lines_copy(&in, to, out)) != 0 || to == INT64_MAX)
                break;
        }
        /* inside a node block: its plain data lines a run at a time */
        if (c.remain > 0 &&
            (rc = inp_node_run(&w->nodes, &in, &c.node, &c.remain, out,
                               &w->moved)) != 0) {
            rc = rc < 0 ? -1 : 0;
            continue;
        }
        if ((r = inp_lines_next(&in)) != 1)
            break;
        rc = copy_line(w, out, &in, file, &c);
    }
    if (rc == 0 && (r < 0 || c.remain > 0 || c.nb < st->nnblocks))
        rc = 1;
    int werr = rc < 0 || ferror(out);
    if (fclose(out) != 0)
        werr = 1;
    inp_lines_close(&in);
    if (werr)
        return getme_doc_fail(w->doc, GETME_FORMATS_ERR_WRITE, "cannot write '%s': %s",
                              w->out[file], strerror(errno ? errno : EIO));
    if (rc)
        return changed(w, file);
    return GETME_FORMATS_OK;
}

static getme_formats_status write_all(writer *w, const char *out_path)
{
    const inp_doc *st = w->st;
    getme_formats_status s = name_outputs(w, out_path);
    if (s)
        return s;
    size_t made = 0;
    for (; made < st->nfiles && !s; made++)
        if (getme_io_tmp_path(w->out[made], w->tmp[made], PATH_BUF))
            s = getme_doc_fail(w->doc, GETME_FORMATS_ERR_WRITE,
                               "cannot create a temporary file next to '%s': %s",
                               w->out[made], strerror(errno));
    if (s)
        made--; /* the failed one created nothing */
    for (size_t i = 0; i < st->nfiles && !s; i++)
        s = write_file(w, (int)i);
    if (s) {
        for (size_t i = 0; i < made; i++)
            remove(w->tmp[i]);
        return s;
    }
    /* Includes first, the deck last: a reader of the output never sees a
       deck whose includes are missing. */
    for (size_t i = st->nfiles; i-- > 0;)
        if (getme_io_commit(w->tmp[i], w->out[i])) {
            int e = errno;
            for (size_t j = 0; j < i; j++)
                remove(w->tmp[j]);
            return getme_doc_fail(w->doc, GETME_FORMATS_ERR_WRITE,
                                  "cannot write '%s': %s", w->out[i],
                                  strerror(e));
        }
    return GETME_FORMATS_OK;
}

/* Smoothing can move a node that is already where it belongs by a
   rounding step (0.75 -> 0.75000000000000011 on a perfect hex grid); such
   moves are not worth a changed line in the user's diff.  Nodes that move
   by at most INP_KEEP_REL times the mesh's bounding-box diagonal (in each
   coordinate) keep their original text. */
#define INP_KEEP_REL 1e-12

static double keep_tolerance(const double *xyz, int32_t n)
{
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            double v = xyz[3 * (size_t)i + k];
            if (i == 0 || v < lo[k])
                lo[k] = v;
            if (i == 0 || v > hi[k])
                hi[k] = v;
        }
    double d2 = 0;
    for (int k = 0; k < 3; k++)
        d2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return INP_KEEP_REL * sqrt(d2);
}

getme_formats_status inp_write(getme_doc *doc, const inp_doc *st,
                          const char *out_path)
{
    if (!st || !doc->mesh)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "document not open");
    if (getme_mesh_num_nodes(doc->mesh) != st->nnodes)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                              "mesh and deck differ in node count");
    writer w;
    memset(&w, 0, sizeof w);
    w.doc = doc;
    w.st = st;
    w.xyz = getme_mesh_coords(doc->mesh);
    w.dim = getme_mesh_dim(doc->mesh);
    w.nodes.node_id = st->node_id;
    w.nodes.xyz = w.xyz;
    w.nodes.keep_tol = keep_tolerance(w.xyz, st->nnodes);
    w.nodes.threads = st->threads > 0 ? st->threads : 1;
    w.out = getme__malloc(st->nfiles * sizeof *w.out);
    w.tmp = getme__malloc(st->nfiles * sizeof *w.tmp);
    w.line = getme__malloc(INP_MAX_LINE + INP_NODE_GROW + 1);
    getme_formats_status s = w.out && w.tmp && w.line
                            ? write_all(&w, out_path)
                            : getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                                             "out of memory");
    free(w.out);
    free(w.tmp);
    free(w.line);
    free(w.nodes.buf);
    return s;
}
