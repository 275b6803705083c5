/*
 * io_bench.c -- read and write time of libgetme_formats on one file, any
 * format (bench/io.py runs it for docs/bench.md):
 *   io_bench IN [OUT] [--threads N] [--move] [--no-skin]
 * opens IN with N parsing threads (getme_doc_options.num_threads; 0 =
 * OpenMP's default) and, with OUT, writes it; --move first moves every free
 * node by 1e-3 of its x, so that every free node's coordinates are written
 * (the worst case of a smoothing run's output).  Prints one line:
 *   read S write S nodes N elements E
 * The read time is the whole getme_doc_open: parsing, building the mesh,
 * the boundary search and the validity check (the last two are the same
 * code for every format).  --no-skin opens without fixing the skin and
 * the interfaces: no boundary search, so the read time is the reader's own
 * (parsing and building the mesh) plus the validity check.
 */
#define _POSIX_C_SOURCE 200809L
#include "getme_formats.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void move_free_nodes(getme_mesh *m)
{
    int32_t n = getme_mesh_num_nodes(m);
    double *x = malloc((size_t)n * 3 * sizeof *x);
    uint8_t *fixed = malloc((size_t)n);
    if (x && fixed) {
        getme_mesh_get_coords(m, x);
        getme_mesh_get_fixed_mask(m, fixed);
        for (int32_t i = 0; i < n; i++)
            if (!fixed[i])
                x[3 * i] += 1e-3 * x[3 * i];
        getme_mesh_set_coords(m, x);
    }
    free(x);
    free(fixed);
}

int main(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    int threads = 0, move = 0, skin = 1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--move"))
            move = 1;
        else if (!strcmp(argv[i], "--no-skin"))
            skin = 0;
        else if (!in)
            in = argv[i];
        else if (!out)
            out = argv[i];
        else
            in = NULL, argc = 0;
    }
    if (!in) {
        fprintf(stderr, "usage: io_bench IN [OUT] [--threads N] [--move] "
                        "[--no-skin]\n");
        return 2;
    }
    getme_doc_options o;
    getme_doc_options_init(&o);
    o.num_threads = threads;
    o.fix_skin = o.fix_interfaces = skin;
    double t0 = now();
    getme_doc *doc;
    getme_formats_status st = getme_doc_open(&doc, in, &o);
    double t1 = now(), t2 = t1, t3 = t1;
    if (st == GETME_FORMATS_OK && out) {
        if (move)
            move_free_nodes(getme_doc_mesh(doc));
        t2 = now();
        st = getme_doc_write(doc, out);
        t3 = now();
    }
    if (st != GETME_FORMATS_OK) {
        fprintf(stderr, "Error   : %s\n", getme_doc_error(doc));
        getme_doc_close(doc);
        return (int)st;
    }
    getme_mesh *m = getme_doc_mesh(doc);
    printf("read %.4f write %.4f nodes %d elements %d\n", t1 - t0, t3 - t2,
           (int)getme_mesh_num_nodes(m), (int)getme_mesh_num_elements(m));
    getme_doc_close(doc);
    return 0;
}
