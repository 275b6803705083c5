/*
 * measures_sweep.c -- the quality measures' sweep (getme_mesh_measure_all_
 * qualities: dihedral angles, scaled Jacobian, gamma, SICN, mean ratio and
 * their statistics) timed inside one process, best of N, so a change of
 * measures.c is compared without the read and the page faults of a whole
 * command (issue #13, session 28).  Not a library file: a measuring aid.
 *
 *     B=build   # a build tree of this checkout (or of an older commit)
 *     gcc -O2 -std=c11 -fopenmp -Icore/include -Iformats/include \
 *         bench/measures_sweep.c -o /tmp/measures_sweep \
 *         -L$B/core -L$B/formats -lgetme_formats -lgetme \
 *         -Wl,-rpath,$PWD/$B/core:$PWD/$B/formats
 *     OMP_NUM_THREADS=2 /tmp/measures_sweep MESH [repetitions]
 *
 * Prints the best and the median time of the repetitions and the tet
 * and hex means of the minimum dihedral angle and the scaled Jacobian
 * (to see that two builds give the same statistics).
 */
#include <getme.h>
#include <getme_formats.h>

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s MESH [repetitions]\n", argv[0]);
        return 2;
    }
    int reps = argc > 2 ? atoi(argv[2]) : 5;
    if (reps < 1 || reps > 1000)
        reps = 5;
    getme_doc *doc = NULL;
    getme_doc_options opts;
    getme_doc_options_init(&opts);
    if (getme_doc_open(&doc, argv[1], &opts) != GETME_FORMATS_OK) {
        fprintf(stderr, "%s\n", doc ? getme_doc_error(doc) : argv[1]);
        getme_doc_close(doc);
        return 1;
    }
    getme_mesh *mesh = getme_doc_mesh(doc);
    int32_t ne = getme_mesh_num_elements(mesh);
    double *q = malloc((size_t)(ne ? ne : 1) * sizeof *q);
    double *t = malloc((size_t)reps * sizeof *t);
    static getme_measure_stats s[GETME_NUM_TYPES * GETME_NUM_MEASURES];
    if (!q || !t)
        return 1;
    for (int r = 0; r < reps; r++) {
        double t0 = omp_get_wtime();
        if (getme_mesh_measure_all_qualities(mesh, s, q) != GETME_OK)
            return 1;
        t[r] = omp_get_wtime() - t0;
    }
    qsort(t, (size_t)reps, sizeof *t, cmp);
    printf("%s: %d elements, %d threads, %d repetitions: best %.4f s, "
           "median %.4f s\n",
           argv[1], (int)ne, omp_get_max_threads(), reps, t[0], t[reps / 2]);
    int types[2] = {GETME_TET, GETME_HEX};
    for (int k = 0; k < 2; k++) {
        const getme_measure_stats *d =
            &s[types[k] * GETME_NUM_MEASURES + GETME_MEASURE_MIN_DIHEDRAL];
        const getme_measure_stats *j =
            &s[types[k] * GETME_NUM_MEASURES + GETME_MEASURE_SCALED_JACOBIAN];
        if (d->num_elements)
            printf("  %s: min dihedral mean %.17g, scaled Jacobian mean %.17g\n",
                   k ? "hex" : "tet", d->mean, j->mean);
    }
    free(q);
    free(t);
    getme_doc_close(doc);
    return 0;
}
