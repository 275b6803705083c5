/*
 * inp_test_util.h -- helpers shared by the INP adapter's C tests: write a
 * deck to a scratch directory, read files back, open documents.
 */
#ifndef GETME_INP_TEST_UTIL_H
#define GETME_INP_TEST_UTIL_H

#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "getme_formats.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char tdir[256];

/* A fresh scratch directory under the current one (the test build dir). */
static inline void scratch_init(const char *name)
{
    snprintf(tdir, sizeof tdir, "%s.XXXXXX", name);
    if (!mkdtemp(tdir)) {
        perror("mkdtemp");
        exit(2);
    }
}

/* Remove the scratch directory when the test passed (kept for a look
   otherwise). */
static inline void scratch_done(int passed)
{
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tdir);
    if (passed && system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tdir);
}

static inline const char *tpath(const char *name)
{
    static char buf[8][512];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tdir, name);
    return buf[k];
}

static inline void put_file(const char *name, const char *text, size_t n)
{
    FILE *f = fopen(tpath(name), "wb");
    if (!f || fwrite(text, 1, n, f) != n) {
        perror(name);
        exit(2);
    }
    fclose(f);
}

static inline void put_text(const char *name, const char *text)
{
    put_file(name, text, strlen(text));
}

/* Whole file, NUL-terminated (caller frees); *n gets the size. */
static inline char *get_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long sz = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)sz + 1);
    if (b && fread(b, 1, (size_t)sz, f) != (size_t)sz) {
        free(b);
        b = NULL;
    }
    fclose(f);
    if (b)
        b[sz] = '\0';
    if (n)
        *n = (size_t)sz;
    return b;
}

/* Open with default options plus extra fixed sets and interface flag. */
static inline getme_formats_status open_deck(getme_doc **doc, const char *name,
                                 int fix_interfaces, int nfix,
                                 const char *const *fix)
{
    getme_doc_options o;
    getme_doc_options_init(&o);
    o.fix_interfaces = fix_interfaces;
    o.num_fix = nfix;
    o.fix = fix;
    return getme_doc_open(doc, tpath(name), &o);
}

#endif
