/*
 * inp_bench.c -- read and write time of the INP adapter on one deck:
 *   inp_bench IN OUT   opens IN, moves every free node by 1e-3 of its x
 *                      (worst case: every free node line is rewritten),
 *                      writes OUT; prints the times.  Run it under
 *                      /usr/bin/time -v for the peak memory.
 */
#define _POSIX_C_SOURCE 200809L
#include "getme_formats.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: inp_bench IN OUT\n");
        return 2;
    }
    getme_doc_options o;
    getme_doc_options_init(&o);
    double t0 = now();
    getme_doc *doc;
    getme_formats_status st = getme_doc_open(&doc, argv[1], &o);
    double t1 = now();
    if (st != GETME_FORMATS_OK) {
        fprintf(stderr, "Error   : %s\n", getme_doc_error(doc));
        getme_doc_close(doc);
        return (int)st;
    }
    getme_mesh *m = getme_doc_mesh(doc);
    int32_t n = getme_mesh_num_nodes(m);
    double *x = malloc((size_t)n * 3 * sizeof *x);
    uint8_t *fixed = malloc((size_t)n);
    getme_mesh_get_coords(m, x);
    getme_mesh_get_fixed_mask(m, fixed);
    for (int32_t i = 0; i < n; i++)
        if (!fixed[i])
            x[3 * i] += 1e-3 * x[3 * i];
    getme_mesh_set_coords(m, x);
    free(x);
    free(fixed);
    double t2 = now();
    st = getme_doc_write(doc, argv[2]);
    double t3 = now();
    if (st != GETME_FORMATS_OK)
        fprintf(stderr, "Error   : %s\n", getme_doc_error(doc));
    printf("Info    : %s\nInfo    : read %.2f s, write %.2f s\n",
           getme_doc_info(doc), t1 - t0, t3 - t2);
    getme_doc_close(doc);
    return (int)st;
}
