/*
 * inp_write_nodes.c -- the writer's *NODE data lines (inp_writer.c copies
 * everything else as it is).
 *
 * A node line keeps its text except for the coordinate fields of a node
 * that moved (inp_node_text).  Most of a deck's node lines are plain data
 * lines, one node each, so runs of them are taken from the line reader's
 * window and rewritten on several threads (inp_node_run): the run is cut
 * into pieces at line starts (linepar_pieces, as the readers' runs), each
 * piece writes its lines into its own stretch of one output buffer (room
 * for its bytes plus INP_NODE_GROW per line), and the stretches go to the
 * file in order.  Each line's text
 * depends only on that line and its node, so the output is the same bytes
 * for any thread count.  A line that is not a plain data line (a comment,
 * a blank line, a keyword) or not the node expected (the file changed)
 * stops the run there; inp_writer.c then handles that line alone, as
 * before.
 */
#define _GNU_SOURCE /* memrchr */
#include "inp_internal.h"
#include "getme_alloc.h"
#include "linepar.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define NODE_WANT ((size_t)8 << 20) /* bytes of a run's window          */
#define MIN_PARALLEL_LINES 4096

static char *put(char *d, const char *s, size_t n)
{
    memcpy(d, s, n);
    return d + n;
}

long inp_node_text(const inp_node_out *o, const char *text, size_t len,
                   int32_t node, char *dst, int32_t *moved)
{
    const char *p = text, *end = text + len;
    inp_field f[4];
    int last = 0, nf = 0;
    while (nf < 4 && !last && inp_next_field(&p, end, &f[nf], &last))
        nf++;
    int64_t id;
    if (nf < 1 || inp_parse_int(&f[0], &id) || id != o->node_id[node])
        return -1;
    const double *x = o->xyz + 3 * (size_t)node;
    double old[3] = {0, 0, 0};
    int move = 0, ncoord = nf - 1;
    for (int k = 0; k < 3; k++) {
        if (k < ncoord && inp_parse_real(&f[k + 1], &old[k]))
            return -1;
        move |= !(fabs(x[k] - old[k]) <= o->keep_tol);
    }
    /* A node that moved by no more than keep_tol in every coordinate keeps
       its line, so it is back exactly where the deck had it. */
    if (!move)
        return (long)(put(dst, text, len) - dst);
    (*moved)++;
    /* Replace the number of each changed coordinate field in place; a
       coordinate that kept its value keeps its text. */
    char *d = dst;
    const char *cur = text;
    for (int k = 0; k < ncoord; k++) {
        if (fabs(x[k] - old[k]) <= o->keep_tol)
            continue; /* this coordinate keeps its text */
        d = put(d, cur, (size_t)(f[k + 1].s - cur));
        d += inp_format_real(x[k], d);
        cur = f[k + 1].s + f[k + 1].n;
    }
    /* Coordinates the line left out (0 in Abaqus) that are not 0 now. */
    int need = ncoord;
    for (int k = ncoord; k < 3; k++)
        if (!(fabs(x[k]) <= o->keep_tol))
            need = k + 1;
    d = put(d, cur, (size_t)(end - cur));
    for (int k = ncoord; k < need; k++) {
        d = put(d, ", ", 2);
        d += inp_format_real(x[k], d);
    }
    return (long)(d - dst);
}

/* The lines first.. of [s, e) rewritten into dst, nodes node0 + index,
   until a line that is not a plain node data line of its node; the
   index after the last line done, with *stop the start of the line not
   done (or e) and *dend the end of the output. */
static size_t piece(const inp_node_out *o, const char **s, const char *e,
                    size_t first, int32_t node0, char *dst, char **dend,
                    int32_t *moved)
{
    const char *p = *s;
    size_t i = first;
    while (p < e) {
        const char *nl = memchr(p, '\n', (size_t)(e - p));
        size_t len = (size_t)(nl - p);
        size_t tlen = len && p[len - 1] == '\r' ? len - 1 : len;
        if (tlen > INP_MAX_LINE || memchr(p, '\0', tlen) ||
            inp_line_kind(p, tlen) != INP_LINE_DATA)
            break;
        long n = inp_node_text(o, p, tlen, node0 + (int32_t)i, dst, moved);
        if (n < 0)
            break;
        dst = put(dst + n, p + tlen, len + 1 - tlen); /* its terminator */
        p = nl + 1;
        i++;
    }
    *s = p;
    *dend = dst;
    return i;
}

int inp_node_run(inp_node_out *o, inp_lines *in, int32_t *node,
                 int32_t *remain, FILE *out, int32_t *moved)
{
    size_t avail;
    const char *w = inp_lines_window(in, NODE_WANT, &avail);
    const char *nl = avail ? memrchr(w, '\n', avail) : NULL;
    if (!nl)
        return 0;
    /* the run: up to *remain whole lines of the window, in pieces */
    int np = o->threads > 1 ? 4 * o->threads : 1, ncut;
    if (np > LINEPAR_MAX_PIECES)
        np = LINEPAR_MAX_PIECES;
    const char *cut[LINEPAR_MAX_PIECES + 1];
    size_t first[LINEPAR_MAX_PIECES + 1];
    size_t nlines = linepar_pieces(w, (size_t)(nl + 1 - w), (size_t)*remain,
                                   np, cut, first, &ncut);
    if (nlines == 0)
        return 0;
    const char *p = cut[ncut];
    size_t bytes = (size_t)(p - w), need = bytes + nlines * INP_NODE_GROW;
    if (need > o->cap) {
        char *b = getme__realloc(o->buf, need);
        if (!b)
            return 0; /* the line by line path does the same, slower */
        o->buf = b;
        o->cap = need;
    }
    const char *stop[LINEPAR_MAX_PIECES];
    char *dend[LINEPAR_MAX_PIECES];
    size_t done[LINEPAR_MAX_PIECES];
    int32_t mv[LINEPAR_MAX_PIECES];
    int threads = nlines >= MIN_PARALLEL_LINES ? o->threads : 1;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) \
    if (threads > 1)
    for (int k = 0; k < ncut; k++) {
        /* piece k's stretch: its bytes plus room for its lines to grow */
        char *dst = o->buf + (cut[k] - w) + first[k] * INP_NODE_GROW;
        stop[k] = cut[k];
        mv[k] = 0;
        done[k] = piece(o, &stop[k], cut[k + 1], first[k], *node, dst,
                        &dend[k], &mv[k]);
    }
    /* the pieces in order, up to the first line one of them stopped at */
    size_t lines = 0;
    const char *upto = w;
    int err = 0;
    for (int k = 0; k < ncut; k++) {
        char *dst = o->buf + (cut[k] - w) + first[k] * INP_NODE_GROW;
        size_t n = (size_t)(dend[k] - dst);
        if (n && fwrite(dst, 1, n, out) != n)
            err = 1;
        *moved += mv[k];
        lines = done[k];
        upto = stop[k];
        if (done[k] < first[k + 1])
            break;
    }
    inp_lines_consume(in, (size_t)(upto - w), lines);
    *node += (int32_t)lines;
    *remain -= (int32_t)lines;
    return err ? -1 : (int)(lines > 0);
}
