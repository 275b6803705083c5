/*
 * affinity.c -- cli_affinity_unbind(): give the whole CPU mask back before
 * main.c's re-exec, when libgomp's thread binding has narrowed it.
 */
#define _GNU_SOURCE /* cpu_set_t, sched_setaffinity */
#include "cli.h"

#include <omp.h>
#include <stdlib.h>
#ifdef __linux__
#include <sched.h>
#endif

void cli_affinity_unbind(void)
{
#ifdef __linux__
    /* libgomp builds its places from the mask the process started with
       (inside it, also for an explicit OMP_PLACES), and lists none when
       no binding was asked for: then the mask was never touched. */
    int np = omp_get_num_places();
    if (np <= 0)
        return;
    cpu_set_t set;
    CPU_ZERO(&set);
    for (int p = 0; p < np; p++) {
        int n = omp_get_place_num_procs(p);
        int *ids = n > 0 ? malloc((size_t)n * sizeof *ids) : NULL;
        if (!ids)
            continue;
        omp_get_place_proc_ids(p, ids);
        for (int i = 0; i < n; i++)
            if (ids[i] >= 0 && ids[i] < CPU_SETSIZE)
                CPU_SET(ids[i], &set);
        free(ids);
    }
    /* a failure leaves the mask as it was: the run is slower, not wrong */
    if (CPU_COUNT(&set) > 0)
        (void)sched_setaffinity(0, sizeof set, &set);
#endif
}
