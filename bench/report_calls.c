/*
 * report_calls.c -- the library calls behind the lines `getme smooth -v`
 * prints before and after smoothing (issue #13): the six measures, the
 * quality statistics and the two worst lists, each timed (CPU seconds of
 * all threads and wall seconds, the best of the repetitions), and every
 * value they return printed in %a to a file, so that two builds or two
 * thread counts can be compared bit for bit (cmp).
 *
 *     report_calls MESH [repetitions] [values-file]
 *
 * Built against an installed or build-tree libgetme (bench/report_calls.sh);
 * with -DGETME_SHARED_Q the calls that share one quality array
 * (getme_mesh_measure_all_qualities, getme_mesh_quality_stats_from,
 * getme_mesh_worst_elements_from) are timed too, as the CLI makes them.
 */
#include "getme.h"
#include "getme_formats.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void put_measures(FILE *f, const getme_measure_stats *m)
{
    for (int k = 0; k < GETME_NUM_TYPES * GETME_NUM_MEASURES; k++) {
        const getme_measure_stats *s = &m[k];
        fprintf(f, "m%d %lld %lld %lld %a %a %a %d %d %a %a", k,
                (long long)s->num_elements, (long long)s->num_negative,
                (long long)s->num_below, s->min, s->max, s->mean,
                (int)s->min_element, (int)s->max_element, s->hist_lo,
                s->hist_hi);
        for (int b = 0; b < GETME_HIST_BINS; b++)
            fprintf(f, " %lld", (long long)s->histogram[b]);
        fputc('\n', f);
    }
}

static void put_stats(FILE *f, const getme_quality_stats *s)
{
    fprintf(f, "q %lld %lld %lld %a %a %a %a %lld %lld", (long long)s->num_elements,
            (long long)s->num_invalid, (long long)s->num_free, s->q_min,
            s->q_min_star, s->q_mean, s->q_max, (long long)s->num_below_04,
            (long long)s->num_below_01);
    for (int b = 0; b < GETME_HIST_BINS; b++)
        fprintf(f, " %lld", (long long)s->histogram[b]);
    for (int i = 0; i < s->num_reported_invalid; i++)
        fprintf(f, " i%d", (int)s->first_invalid[i]);
    fputc('\n', f);
}

static void put_worst(FILE *f, const getme_worst_element *w, int32_t n)
{
    for (int32_t i = 0; i < n; i++)
        fprintf(f, "w %d %d %a %a %d %d %d\n", (int)w[i].element, (int)w[i].type,
                w[i].quality, w[i].corner_sj, w[i].num_nodes, w[i].num_free,
                (int)w[i].reason);
}

enum { WORST = 10 };

typedef struct timing {
    double cpu, wall;
} timing;

static void best(timing *t, double c0, double w0, int rep)
{
    double c = cpu() - c0, w = omp_get_wtime() - w0;
    if (rep == 0 || c < t->cpu)
        t->cpu = c;
    if (rep == 0 || w < t->wall)
        t->wall = w;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: report_calls MESH [repetitions] [values-file]\n");
        return 2;
    }
    int reps = argc > 2 ? atoi(argv[2]) : 3;
    getme_doc *doc = NULL;
    getme_doc_options opts;
    getme_doc_options_init(&opts);
    if (getme_doc_open(&doc, argv[1], &opts) != GETME_FORMATS_OK) {
        fprintf(stderr, "%s\n", getme_doc_error(doc));
        return 1;
    }
    getme_mesh *mesh = getme_doc_mesh(doc);
    static getme_measure_stats m[GETME_NUM_TYPES * GETME_NUM_MEASURES];
    getme_quality_stats s;
    getme_worst_element w[WORST], wf[WORST];
    int32_t nw = 0, nwf = 0;
    timing tm = {0, 0}, tq = {0, 0}, tw = {0, 0};
    for (int r = 0; r < reps; r++) {
        double c0 = cpu(), w0 = omp_get_wtime();
        getme_mesh_measure_all(mesh, m);
        best(&tm, c0, w0, r);
        c0 = cpu(), w0 = omp_get_wtime();
        getme_mesh_quality_stats(mesh, -1, &s);
        best(&tq, c0, w0, r);
        c0 = cpu(), w0 = omp_get_wtime();
        getme_mesh_worst_elements(mesh, WORST, 0, w, &nw);
        getme_mesh_worst_elements(mesh, WORST, GETME_WORST_FREE_ONLY, wf, &nwf);
        best(&tw, c0, w0, r);
    }
    printf("threads %d: measure_all %.3f s (wall %.3f), quality_stats %.3f (%.3f), "
           "worst x2 %.3f (%.3f), sum %.3f (%.3f)\n",
           omp_get_max_threads(), tm.cpu, tm.wall, tq.cpu, tq.wall, tw.cpu,
           tw.wall, tm.cpu + tq.cpu + tw.cpu, tm.wall + tq.wall + tw.wall);
    FILE *f = argc > 3 ? fopen(argv[3], "w") : NULL;
    if (f) {
        put_measures(f, m);
        put_stats(f, &s);
        put_worst(f, w, nw);
        put_worst(f, wf, nwf);
    }
#ifdef GETME_SHARED_Q
    {
        double *q = malloc((size_t)getme_mesh_num_elements(mesh) * sizeof *q);
        timing ta = {0, 0}, t1 = {0, 0}, t2 = {0, 0}, t3 = {0, 0};
        for (int r = 0; r < reps; r++) {
            double c0 = cpu(), w0 = omp_get_wtime();
            getme_mesh_measure_all_qualities(mesh, m, q);
            best(&t1, c0, w0, r);
            double c1 = cpu(), w1 = omp_get_wtime();
            getme_mesh_quality_stats_from(mesh, q, -1, &s);
            best(&t2, c1, w1, r);
            c1 = cpu(), w1 = omp_get_wtime();
            getme_mesh_worst_elements_from(mesh, q, WORST, 0, w, &nw);
            getme_mesh_worst_elements_from(mesh, q, WORST, GETME_WORST_FREE_ONLY,
                                           wf, &nwf);
            best(&t3, c1, w1, r);
            best(&ta, c0, w0, r);
        }
        printf("threads %d: shared qualities: all four %.3f s (wall %.3f): "
               "measures %.3f (%.3f), stats %.3f (%.3f), worst x2 %.3f (%.3f)\n",
               omp_get_max_threads(), ta.cpu, ta.wall, t1.cpu, t1.wall,
               t2.cpu, t2.wall, t3.cpu, t3.wall);
        if (f) {
            put_measures(f, m);
            put_stats(f, &s);
            put_worst(f, w, nw);
            put_worst(f, wf, nwf);
        }
        free(q);
    }
#endif
    if (f)
        fclose(f);
    getme_doc_close(doc);
    return 0;
}
