/*
 * doc_read.h -- what the formats tests compare after reading a file:
 * the status, the error text and the mesh (coordinates, every element's
 * nodes padded to 8, the fixed nodes), read through the public
 * getme_formats.h API with a given reader thread count.  Shared by the
 * tests that check a parallel parse gives the serial reader's mesh and
 * message (test_fastpath.c: ASCII MSH and INP; test_binpar.c: binary
 * MSH).
 */
#ifndef GETME_TEST_DOC_READ_H
#define GETME_TEST_DOC_READ_H

#include "getme_formats.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct doc_read {
    getme_formats_status st;
    char error[1024];
    double *x;
    int32_t *conn; /* 8 per element */
    uint8_t *fixed;
    int32_t nn, ne;
} doc_read;

/* fix: a set to fix (getme_doc_options.fix), or NULL */
static doc_read doc_read_file_fix(const char *path, int threads,
                                  const char *fix)
{
    doc_read r;
    memset(&r, 0, sizeof r);
    getme_doc_options o;
    getme_doc_options_init(&o);
    o.num_threads = threads;
    const char *const names[1] = {fix};
    if (fix) {
        o.num_fix = 1;
        o.fix = names;
    }
    getme_doc *doc = NULL;
    r.st = getme_doc_open(&doc, path, &o);
    snprintf(r.error, sizeof r.error, "%s",
             r.st == GETME_FORMATS_OK ? "" : getme_doc_error(doc));
    getme_mesh *m = r.st == GETME_FORMATS_OK ? getme_doc_mesh(doc) : NULL;
    if (m) {
        r.nn = getme_mesh_num_nodes(m);
        r.ne = getme_mesh_num_elements(m);
        r.x = malloc((size_t)r.nn * 3 * sizeof *r.x);
        r.conn = calloc((size_t)r.ne * 8, sizeof *r.conn);
        r.fixed = calloc((size_t)r.nn + 1, 1);
        getme_mesh_get_coords(m, r.x);
        getme_mesh_get_fixed_mask(m, r.fixed);
        for (int32_t e = 0; e < r.ne; e++) {
            getme_elem_type t;
            getme_mesh_get_element(m, e, &t, r.conn + 8 * e);
        }
    }
    getme_doc_close(doc);
    return r;
}

static doc_read doc_read_file(const char *path, int threads)
{
    return doc_read_file_fix(path, threads, NULL);
}

/* Both read, and the same mesh bit for bit. */
static inline int doc_read_same(const doc_read *a, const doc_read *b)
{
    return a->st == GETME_FORMATS_OK && b->st == GETME_FORMATS_OK &&
           a->nn == b->nn && a->ne == b->ne &&
           memcmp(a->x, b->x, (size_t)a->nn * 3 * sizeof *a->x) == 0 &&
           memcmp(a->conn, b->conn, (size_t)a->ne * 8 * sizeof *a->conn) == 0 &&
           memcmp(a->fixed, b->fixed, (size_t)a->nn) == 0;
}

static inline void doc_read_free(doc_read *r)
{
    free(r->x);
    free(r->conn);
    free(r->fixed);
}

#endif
