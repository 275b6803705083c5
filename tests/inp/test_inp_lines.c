/*
 * test_inp_lines.c -- the INP line reader's window for the fast path
 * (formats/inp/inp_lines.c, compiled into this test: its functions are
 * internal to libgetme_formats).
 *
 * inp_lines_window promises want bytes when the file has them (the buffer
 * grows to want).  The reader alternates: one line by inp_lines_next (a
 * keyword, or a line the fast path refused), then windows.  The line
 * reader refills only up to the buffer's size, so a window that waited
 * for the rest to run low before growing stayed just under the first
 * buffer (256 KiB) forever, and linepar never split a run across threads.
 * Checked here: the first window after a line is the size asked for, the
 * windows keep that size while the file lasts, and every line comes out
 * once, in order, whichever reader takes it.  Also inp_lines_copy, the
 * writer's verbatim copy: exact bytes, line count, and 1 for an offset
 * that is not a line start or past the end.
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"

#include "inp_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define CHECK_STR(a, b) CHECK(strcmp((a), (b)) == 0)

enum { NLINES = 600000 };
#define WANT ((size_t)8 << 20)

static void write_deck(const char *path)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    fputs("*NODE\n", f);
    for (long i = 1; i <= NLINES; i++)
        fprintf(f, "%ld, %ld.5, 2.25, -3.125\n", i, i % 977);
    fputs("*ELEMENT, TYPE=C3D4\n", f);
    CHECK(fclose(f) == 0);
}

/* The id of a data line, checked against the next expected one. */
static void expect_line(const char *s, size_t len, long *next)
{
    char buf[64];
    CHECK(len > 0 && len < sizeof buf);
    if (len == 0 || len >= sizeof buf)
        return;
    memcpy(buf, s, len);
    buf[len] = '\0';
    long id = strtol(buf, NULL, 10);
    CHECK_EQ_INT(id, *next);
    char want[64];
    snprintf(want, sizeof want, "%ld, %ld.5, 2.25, -3.125", *next,
             *next % 977);
    CHECK_STR(buf, want);
    (*next)++;
}

int main(void)
{
    char path[] = "/tmp/getme_inp_lines_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    close(fd);
    write_deck(path);

    inp_lines r;
    CHECK(inp_lines_open(&r, path) == 0);
    CHECK(inp_lines_next(&r) == 1);
    CHECK_STR(r.text, "*NODE");

    long next = 1, windows = 0, big = 0;
    size_t first_avail = 0;
    for (;;) {
        size_t avail;
        const char *w = inp_lines_window(&r, WANT, &avail);
        if (windows == 0)
            first_avail = avail;
        /* whole data lines of the window, as the fast path takes them;
           it stops at the keyword */
        size_t used = 0, lines = 0;
        for (;;) {
            const char *nl = memchr(w + used, '\n', avail - used);
            if (!nl || w[used] == '*')
                break;
            expect_line(w + used, (size_t)(nl - (w + used)), &next);
            used = (size_t)(nl + 1 - w);
            lines++;
        }
        windows++;
        if (avail == WANT)
            big++;
        inp_lines_consume(&r, used, lines);
        /* the line reader takes one line between windows, as after a
           line the fast path refused */
        int rc = inp_lines_next(&r);
        CHECK(rc == 1);
        if (rc != 1 || r.text[0] == '*')
            break;
        expect_line(r.text, r.len, &next);
    }
    CHECK_STR(r.text, "*ELEMENT, TYPE=C3D4");
    CHECK_EQ_INT(next, NLINES + 1);
    CHECK(inp_lines_next(&r) == 0);
    /* the first window after a line is the size asked for (was: the
       first buffer's 256 KiB less the line) */
    CHECK_EQ_INT((long long)first_avail, (long long)WANT);
    /* ~17 MB of lines in 8 MiB windows: all but the last are full */
    CHECK(windows >= 2);
    CHECK_EQ_INT(big, windows - 1);

    /* a window never gives more than asked, nor past the end of the file */
    inp_lines_close(&r);
    CHECK(inp_lines_open(&r, path) == 0);
    CHECK(inp_lines_next(&r) == 1);
    size_t avail;
    const char *w = inp_lines_window(&r, 4096, &avail);
    CHECK_EQ_INT((long long)avail, 4096);
    CHECK(memcmp(w, "1, 1.5, 2.25, -3.125\n", 21) == 0);
    inp_lines_close(&r);

    /* inp_lines_copy, the writer's copy of what it does not change */
    long size = 0;
    char *all = NULL;
    {
        FILE *f = fopen(path, "rb");
        CHECK(f != NULL && fseek(f, 0, SEEK_END) == 0);
        size = ftell(f);
        rewind(f);
        all = malloc((size_t)size);
        CHECK(all && fread(all, 1, (size_t)size, f) == (size_t)size);
        fclose(f);
    }
    /* lines 1-3 ("*NODE" and two nodes), then line 4 by the line reader */
    int64_t line4 = (int64_t)(strchr(strchr(strchr(all, '\n') + 1, '\n') + 1,
                                     '\n') + 1 - all);
    char *copy = NULL;
    size_t copy_len = 0;
    FILE *mem = open_memstream(&copy, &copy_len);
    CHECK(inp_lines_open(&r, path) == 0);
    CHECK_EQ_INT(inp_lines_copy(&r, line4, mem), 0);
    CHECK_EQ_INT(r.lineno, 3);
    CHECK(inp_lines_next(&r) == 1);
    CHECK_STR(r.text, "3, 3.5, 2.25, -3.125");
    /* not at a line's start (the file is not the one read): 1 */
    CHECK_EQ_INT(inp_lines_copy(&r, r.next_offset + 5, mem), 1);
    /* the rest, to the end of the file */
    CHECK_EQ_INT(inp_lines_copy(&r, INT64_MAX, mem), 0);
    CHECK_EQ_INT(r.lineno, NLINES + 2);
    CHECK(inp_lines_next(&r) == 0);
    fclose(mem);
    /* everything but line 4, byte for byte */
    size_t l4 = strlen("3, 3.5, 2.25, -3.125\n");
    CHECK_EQ_INT((long long)copy_len, size - (long)l4);
    CHECK(copy_len == (size_t)size - l4 && memcmp(copy, all, (size_t)line4) == 0 &&
          memcmp(copy + line4, all + line4 + l4, copy_len - (size_t)line4) == 0);
    inp_lines_close(&r);
    free(copy);
    copy = NULL;
    /* past the end of the file: 1 */
    mem = open_memstream(&copy, &copy_len);
    CHECK(inp_lines_open(&r, path) == 0);
    CHECK_EQ_INT(inp_lines_copy(&r, size + 10, mem), 1);
    fclose(mem);
    inp_lines_close(&r);
    free(copy);
    free(all);
    remove(path);
    return check_summary("inp_lines");
}
