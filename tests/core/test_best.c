/*
 * test_best.c -- keep_best returns the mesh of the best q*_min seen from the
 * end of the q_mean stage on, bit for bit: the best is kept as an undo log
 * of the nodes moved since (core/src/best.c), which becomes a whole copy
 * when the q*_min stage moves many nodes (threshold_fraction 1).  Checked
 * against the progress reports: the returned q*_min is exactly the best
 * reported one, and the coordinates returned give it again; in some runs
 * the last iteration was worse (so the best was restored), and 1 and 2
 * threads give the same coordinates.
 */
#include "check.h"
#include "getme.h"
#include "gen_mesh.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct seen {
    double best;   /* best q*_min from the q_mean stage's end on */
    double prev;   /* the previous report's q*_min               */
    double last;   /* the last report's q*_min                   */
    int in_min;    /* the q*_min stage has started               */
} seen;

static int on_progress(const getme_progress *p, void *data)
{
    seen *s = data;
    if (p->stage == GETME_STAGE_MIN) {
        if (!s->in_min) /* the q_mean stage's last iteration: 1st candidate */
            s->best = s->prev;
        s->in_min = 1;
        s->best = p->q_min_star > s->best ? p->q_min_star : s->best;
    }
    s->prev = s->last = p->q_min_star;
    return 0;
}

/* Smooth kind with threshold_fraction tf; 1 if the last iteration was
   worse than the best (the best was restored). */
static int check_case(int kind, double tf, int threads, double *coords_out)
{
    gen g = make_mesh(kind);
    getme_mesh *m = distorted(&g);
    getme_params p;
    getme_params_init(&p);
    p.threshold_fraction = tf;
    p.finish = 0; /* the result is the q*_min stage's own */
    p.num_threads = threads;
    seen s = {-1.0, -1.0, -1.0, 0};
    p.progress = on_progress;
    p.progress_data = &s;
    getme_result r;
    CHECK(getme_smooth(m, &p, &r) == GETME_OK);
    CHECK(s.in_min && r.iterations_min > 0);
    /* exactly the best seen: the same bits */
    CHECK(r.q_min_star == s.best);
    getme_quality_stats st;
    CHECK(getme_mesh_quality_stats(m, -1, &st) == GETME_OK);
    CHECK_EQ_INT(st.num_invalid, 0);
    CHECK(st.q_min_star == s.best);
    getme_mesh_get_coords(m, coords_out);
    getme_mesh_free(m);
    free_gen(&g);
    return s.last < s.best;
}

int main(void)
{
    int restored = 0;
    for (int kind = 0; kind <= 4; kind++) {
        gen g = make_mesh(kind);
        size_t bytes = (size_t)g.nn * 3 * sizeof(double);
        free_gen(&g);
        double *x1 = malloc(bytes), *x2 = malloc(bytes);
        const double tfs[] = {0.005, 0.05, 1.0};
        for (int k = 0; k < 3; k++) {
            restored += check_case(kind, tfs[k], 1, x1);
            check_case(kind, tfs[k], 2, x2);
            CHECK(!memcmp(x1, x2, bytes));
        }
        free(x1), free(x2);
    }
    /* the restore path ran (the q*_min stage's last cycle lost q*_min) */
    printf("runs that restored the best: %d of 15\n", restored);
    CHECK(restored > 0);
    return check_summary("test_best");
}
