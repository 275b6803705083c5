/*
 * gmsh_optimize.c -- getme_gmsh_optimize(): read the current Gmsh model,
 * check it, smooth it with libgetme, write moved nodes back, and tell the
 * user what happened through Gmsh's logger.
 *
 * The model is touched only at the very end (getme_gmsh_model_apply), after
 * every check passed and the smoother succeeded, so a failure anywhere
 * leaves it exactly as it was.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct gg_run {
    const getme_gmsh_options *opt;
    getme_gmsh_report *rep;
    getme_gmsh_model *model;
    double wall0, cpu0;
    getme_params params;
} gg_run;

/* Our per-iteration line, then the caller's own callback if any. */
static int progress_chain(const getme_progress *p, void *user)
{
    const gg_run *run = user;
    if (run->opt->log >= 2)
        gg_log_progress(p, NULL);
    const getme_params *up = &run->opt->params;
    return up->progress ? up->progress(p, up->progress_data) : 0;
}

static double wall_now(void)
{
    int ierr = 0;
    return gmshLoggerGetWallTime(&ierr);
}

static double cpu_now(void)
{
    int ierr = 0;
    return gmshLoggerGetCpuTime(&ierr);
}

static getme_status fail(gg_run *run, getme_status st, const char *text)
{
    snprintf(run->rep->message, sizeof run->rep->message, "%s", text);
    if (run->opt->log >= 1 && gg_gmsh_initialized())
        gg_log("error", "%s", text);
    return st;
}

/* "1200 tetrahedra, 30 prisms" style summary of the element types. */
static void describe_types(getme_mesh *mesh, char *buf, size_t size)
{
    static const char *const plural[GETME_NUM_TYPES] = {
        "tetrahedra", "hexahedra", "prisms", "pyramids", "triangles",
        "quadrangles"};
    size_t used = 0;
    buf[0] = 0;
    for (int t = 0; t < GETME_NUM_TYPES && used < size; t++) {
        int32_t n = getme_mesh_num_elements_of_type(mesh, (getme_elem_type)t);
        if (n)
            used += (size_t)snprintf(buf + used, size - used, "%s%ld %s",
                                     used ? ", " : "", (long)n, plural[t]);
    }
}

static void describe_entities(const getme_gmsh_model *m, char *buf,
                              size_t size)
{
    size_t used = (size_t)snprintf(buf, size, "%s%s", gg_dim_word(m->dim),
                                   m->num_entities > 1 ? "s" : "");
    for (int e = 0; e < m->num_entities && used < size; e++) {
        if (e == 8 && m->num_entities > 9) {
            snprintf(buf + used, size - used, " ... (%d in all)",
                     m->num_entities);
            return;
        }
        used += (size_t)snprintf(buf + used, size - used, "%s %d",
                                 e ? "," : "", m->entities[2 * e + 1]);
    }
}

/* "<head>: tetrahedron 12 in volume 1, ...<tail>" naming the elements of
   list (n of count) by their Gmsh tags. */
static void name_elements(const gg_run *run, char *text, size_t size,
                          const char *head, int64_t count, const int32_t *list,
                          int n, const char *tail)
{
    char one[128];
    int used = snprintf(text, size, "%s: ", head);
    for (int i = 0; i < n && used < (int)size; i++) {
        gg_describe_element(run->model, list[i], one,
                                          sizeof one);
        used += snprintf(text + used, size - (size_t)used, "%s%s",
                         i ? ", " : "", one);
    }
    if (used < (int)size)
        snprintf(text + used, size - (size_t)used, "%s%s",
                 count > n ? ", ..." : "", tail);
}

/* With untangling off, an invalid input is refused. */
static getme_status check_valid(gg_run *run)
{
    const getme_quality_stats *s = &run->rep->before;
    if (s->num_invalid == 0 || run->opt->params.untangle)
        return GETME_OK;
    char text[GG_MSG], head[96];
    snprintf(head, sizeof head, "%lld invalid (inverted or degenerate) "
             "element%s", (long long)s->num_invalid,
             s->num_invalid > 1 ? "s" : "");
    name_elements(run, text, sizeof text, head, s->num_invalid,
                  s->first_invalid, s->num_reported_invalid,
                  ": GETMe needs a valid mesh");
    return fail(run, GETME_ERR_INVALID_MESH, text);
}

/* Untangle an input with invalid elements (getme_mesh_untangle): a warning
   with the counts; elements that stay invalid are named by their tags, and
   with allow_invalid the partly untangled coordinates go to the model. */
static getme_status untangle(gg_run *run)
{
    getme_mesh *mesh = getme_gmsh_model_mesh(run->model);
    getme_untangle_result *u = &run->rep->untangle;
    getme_status st = getme_mesh_untangle(mesh, &run->opt->params, u);
    if (st != GETME_OK && st != GETME_ERR_INVALID_MESH)
        return fail(run, st, getme_mesh_error(mesh));
    if (run->opt->log >= 1)
        gg_log("warning", "%lld invalid (inverted or degenerate) element%s, "
               "%lld remain%s after untangling (%d sweep%s, %ld nodes "
               "moved, %g s)", (long long)u->num_invalid_before,
               u->num_invalid_before == 1 ? "" : "s",
               (long long)u->num_invalid_after,
               u->num_invalid_after == 1 ? "s" : "", u->sweeps,
               u->sweeps == 1 ? "" : "s", (long)u->num_moved, u->seconds);
    if (run->opt->log >= 1 && u->num_ho_moved > 0)
        gg_log("warning", "%d second-order element%s invalid only at curved "
               "mid-nodes: %d mid-node%s pulled toward the straight "
               "position, %d element%s now valid",
               (int)u->num_ho_invalid, u->num_ho_invalid == 1 ? "" : "s",
               (int)u->num_ho_moved, u->num_ho_moved == 1 ? "" : "s",
               (int)u->num_ho_repaired, u->num_ho_repaired == 1 ? "" : "s");
    if (st == GETME_OK)
        return GETME_OK;
    char text[GG_MSG], head[128];
    if (run->opt->allow_invalid &&
        getme_mesh_quality_stats(mesh, -1, &run->rep->after) == GETME_OK &&
        getme_gmsh_model_apply(run->model, getme_mesh_coords(mesh),
                               &run->rep->num_moved, text,
                               sizeof text) != GETME_OK)
        return fail(run, GETME_ERR_NOMEM, text);
    snprintf(head, sizeof head, "%lld invalid element%s could not be "
             "untangled (%lld with every node fixed)",
             (long long)u->num_invalid_after,
             u->num_invalid_after > 1 ? "s" : "", (long long)u->num_stuck);
    name_elements(run, text, sizeof text, head, u->num_invalid_after,
                  u->remaining, u->num_reported,
                  run->opt->allow_invalid
                      ? "; the partly untangled mesh was written to the model"
                      : "; the model is unchanged");
    return fail(run, GETME_ERR_INVALID_MESH, text);
}

static void log_start(gg_run *run)
{
    const getme_gmsh_report *r = run->rep;
    char types[160], ents[160];
    describe_types(getme_gmsh_model_mesh(run->model), types, sizeof types);
    describe_entities(run->model, ents, sizeof ents);
    gg_log("info", "Smoothing %s: %s, %ld nodes (%ld fixed)", ents, types,
           (long)r->num_nodes, (long)r->num_fixed);
    gg_log("info",
           "Optimization starts with worst = %.6g / average = %.6g "
           "(worst over elements with a free node):",
           r->before.q_min_star, r->before.q_mean);
    gg_log_histogram(&r->before);
    gg_log_measures("before", r->measures_before);
}

static void log_worst(const char *title, const getme_worst_element *w,
                      const size_t *tags, int32_t n)
{
    if (n == 0)
        return;
    gg_log("info", "%s (tag, type, quality, worst corner, free nodes: why it "
                   "stays):", title);
    for (int32_t i = 0; i < n; i++)
        gg_log("info", "  %zu %s q %.4f sj %.4f, %d/%d free: %s", tags[i],
               getme_type_name(w[i].type), w[i].quality, w[i].corner_sj,
               w[i].num_free, w[i].num_nodes,
               getme_worst_reason_string(w[i].reason));
}

static void log_end(gg_run *run)
{
    const getme_gmsh_report *r = run->rep;
    const getme_result *res = &r->result;
    gg_log("info", "Optimization ends with worst = %.6g / average = %.6g:",
           r->after.q_min_star, r->after.q_mean);
    gg_log_histogram(&r->after);
    gg_log_measures("after", r->measures_after);
    if (run->params.method == GETME_METHOD_SMART_LAPLACE)
        gg_log("info", "%d Laplace iterations, %ld nodes moved",
               res->iterations, (long)r->num_moved);
    else
        gg_log("info",
               "%d GETMe iterations (%d mean stage, %d min stage in %d "
               "cycles), %ld nodes moved",
               res->iterations, res->iterations_mean, res->iterations_min,
               res->cycles_min, (long)r->num_moved);
    if (res->passes_finish)
        gg_log("info", "%d finishing passes raised %ld elements",
               res->passes_finish, (long)res->moved_finish);
    if (res->reverted_nodes)
        gg_log("info", "%ld nodes put back at their input positions: q*min "
                       "had ended below the input's %.4f (keep_best)",
               (long)res->reverted_nodes, res->q_min_star_initial);
    if (res->corner_sj_initial < 1.0 || res->corner_sj < 1.0)
        gg_log("info", "Worst corner scaled Jacobian (hex, prism, pyramid, "
                       "quad): %.4g before, %.4g after",
               res->corner_sj_initial, res->corner_sj);
    if (r->num_second_order > 0)
        gg_log("info", "Second order: %ld elements, worst node Jacobian ratio "
                       "%.4g before (element %zu), %.4g after (element %zu)",
               (long)r->num_second_order, r->jacobian_ratio_before,
               r->jacobian_ratio_tag_before, r->jacobian_ratio_after,
               r->jacobian_ratio_tag_after);
    if (r->after.q_min < r->after.q_min_star)
        gg_log("warning", "Worst element %.4g is below the worst with a free "
                          "node %.4g: no node move can fix it (option "
                          "topology=1 lets Gmsh's optimizer swap it away)",
               r->after.q_min, r->after.q_min_star);
    if (run->opt->log >= 2) {
        log_worst("Worst elements", r->worst, r->worst_tag, r->num_worst);
        if (r->after.q_min < r->after.q_min_star)
            log_worst("Worst elements with a free node", r->worst_free,
                      r->worst_free_tag, r->num_worst_free);
    }
}

static getme_status check_model(gg_run *run);

static getme_status read_and_check(gg_run *run, const int *dim_tags,
                                   size_t n)
{
    char text[GG_MSG];
    getme_status st = getme_gmsh_model_read(&run->model, dim_tags, n,
                                            run->opt, text, sizeof text);
    if (st != GETME_OK)
        return fail(run, st, text);
    return check_model(run);
}

/* The worst node Jacobian ratio of the second-order elements and its
   element's Gmsh tag (docs/highorder.md); ratio 1, tag 0 without any. */
static void ho_ratio(gg_run *run, double *ratio, size_t *tag)
{
    getme_mesh *mesh = getme_gmsh_model_mesh(run->model);
    int32_t e = -1;
    *ratio = 1.0;
    *tag = 0;
    run->rep->num_second_order = getme_mesh_num_elements_ho(mesh);
    if (run->rep->num_second_order > 0 &&
        getme_mesh_jacobian_ratio_min(mesh, ratio, &e) == GETME_OK && e >= 0)
        *tag = run->model->elem_tags[e];
}

/* The mesh's statistics and measures from one sweep over its elements
   (each evaluated once), and its qualities into *q (the caller frees
   them) when q is not NULL, for the worst lists.  GETME_ERR_NOMEM when
   the qualities get no room (the mesh's message is then not set). */
static getme_status sweep(getme_mesh *mesh, getme_quality_stats *stats,
                          getme_measure_stats *measures, double **q)
{
    int32_t ne = getme_mesh_num_elements(mesh);
    double *v = malloc((size_t)(ne ? ne : 1) * sizeof *v);
    if (q)
        *q = NULL;
    if (!v)
        return GETME_ERR_NOMEM;
    getme_status st = getme_mesh_measure_all_qualities(mesh, measures, v);
    if (st == GETME_OK)
        st = getme_mesh_quality_stats_from(mesh, v, -1, stats);
    if (st == GETME_OK && q)
        *q = v;
    else
        free(v);
    return st;
}

/* fail() for a sweep() that failed. */
static getme_status sweep_failed(gg_run *run, getme_status st)
{
    getme_mesh *mesh = getme_gmsh_model_mesh(run->model);
    return fail(run, st, st == GETME_ERR_NOMEM ? "out of memory"
                                                : getme_mesh_error(mesh));
}

/* Sizes and quality of run->model into the report; refuse invalid ones. */
static getme_status check_model(gg_run *run)
{
    getme_status st;
    getme_mesh *mesh = getme_gmsh_model_mesh(run->model);
    getme_gmsh_report *r = run->rep;
    r->dim = run->model->dim;
    r->num_entities = run->model->num_entities;
    r->num_nodes = getme_mesh_num_nodes(mesh);
    r->num_elements = getme_mesh_num_elements(mesh);
    r->num_fixed = getme_mesh_num_fixed(mesh);
    st = sweep(mesh, &r->before, &r->measures_before[0][0], NULL);
    if (st != GETME_OK)
        return sweep_failed(run, st);
    ho_ratio(run, &r->jacobian_ratio_before, &r->jacobian_ratio_tag_before);
    r->jacobian_ratio_after = r->jacobian_ratio_before;
    r->jacobian_ratio_tag_after = r->jacobian_ratio_tag_before;
    return check_valid(run);
}

/* The worst elements of the smoothed mesh into the report, with their
   Gmsh tags; q: the mesh's qualities (sweep()). */
static getme_status fill_worst(gg_run *run, const double *q)
{
    getme_mesh *mesh = getme_gmsh_model_mesh(run->model);
    getme_gmsh_report *r = run->rep;
    const size_t *tags = run->model->elem_tags;
    getme_status st = getme_mesh_worst_elements_from(
        mesh, q, run->opt->worst, 0, r->worst, &r->num_worst);
    if (st == GETME_OK)
        st = getme_mesh_worst_elements_from(mesh, q, run->opt->worst,
                                            GETME_WORST_FREE_ONLY,
                                            r->worst_free,
                                            &r->num_worst_free);
    for (int32_t i = 0; st == GETME_OK && i < r->num_worst; i++)
        r->worst_tag[i] = tags[r->worst[i].element];
    for (int32_t i = 0; st == GETME_OK && i < r->num_worst_free; i++)
        r->worst_free_tag[i] = tags[r->worst_free[i].element];
    return st;
}

static getme_status smooth_and_apply(gg_run *run, int niter)
{
    getme_mesh *mesh = getme_gmsh_model_mesh(run->model);
    run->params = run->opt->params;
    if (niter > 0)
        run->params.max_iter = niter;
    run->params.progress = progress_chain;
    run->params.progress_data = run;
    getme_status st = getme_smooth(mesh, &run->params, &run->rep->result);
    run->rep->result.num_invalid_initial = run->rep->untangle.num_invalid_before;
    run->rep->result.untangle_sweeps = run->rep->untangle.sweeps;
    run->rep->result.untangle_seconds = run->rep->untangle.seconds;
    if (st != GETME_OK && st != GETME_ERR_CANCELLED)
        return fail(run, st, getme_mesh_error(mesh));
    /* A cancelled run still leaves a valid, partly smoothed mesh. */
    double *q;
    getme_status st2 = sweep(mesh, &run->rep->after,
                             &run->rep->measures_after[0][0], &q);
    if (st2 != GETME_OK)
        return sweep_failed(run, st2);
    st2 = fill_worst(run, q);
    free(q);
    if (st2 == GETME_OK)
        ho_ratio(run, &run->rep->jacobian_ratio_after,
                 &run->rep->jacobian_ratio_tag_after);
    char text[GG_MSG];
    if (st2 == GETME_OK)
        st2 = getme_gmsh_model_apply(run->model, getme_mesh_coords(mesh),
                                     &run->rep->num_moved, text,
                                     sizeof text);
    else
        snprintf(text, sizeof text, "%s", getme_mesh_error(mesh));
    return st2 != GETME_OK ? fail(run, st2, text) : st;
}

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

/* Option "topology": if some of the worst elements of the current model
   have no free node (no node move can fix them) and the mesh is all tets,
   run Gmsh's own optimizer (edge and face swaps) on it first, and count
   the elements it replaced.  run->model is freed: the caller reads the
   changed model again. */
static getme_status topology_first(gg_run *run, const int *dim_tags,
                                   size_t n)
{
    getme_mesh *mesh = getme_gmsh_model_mesh(run->model);
    getme_gmsh_report *r = run->rep;
    getme_worst_element w[GETME_GMSH_MAX_WORST];
    int32_t nw = 0, stuck = 0;
    if (getme_mesh_worst_elements(mesh, GETME_GMSH_MAX_WORST, 0, w, &nw) !=
        GETME_OK)
        return fail(run, GETME_ERR_NOMEM, "out of memory");
    for (int32_t i = 0; i < nw; i++)
        stuck += w[i].num_free == 0;
    int32_t ne = getme_mesh_num_elements(mesh);
    if (!stuck || getme_mesh_num_elements_of_type(mesh, GETME_TET) != ne) {
        if (run->opt->log >= 1)
            gg_log("info", "Topology: %s; Gmsh's optimizer not needed",
                   stuck ? "not a tetrahedral mesh"
                         : "every worst element has a free node");
        return GETME_OK;
    }
    size_t *before = malloc((size_t)ne * sizeof *before);
    if (!before)
        return fail(run, GETME_ERR_NOMEM, "out of memory");
    memcpy(before, run->model->elem_tags,
           (size_t)ne * sizeof *before);
    qsort(before, (size_t)ne, sizeof *before, cmp_size);
    getme_gmsh_model_free(run->model);
    run->model = NULL;
    if (run->opt->log >= 1)
        gg_log("info", "Topology: %d of the %d worst elements have no free "
                       "node; running Gmsh's optimizer first",
               (int)stuck, (int)nw);
    int ierr = 0;
    gmshModelMeshOptimize("", 1, 1, (int *)dim_tags, n, &ierr);
    char text[GG_MSG];
    getme_status st = ierr ? GETME_ERR_STATE
                           : getme_gmsh_model_read(&run->model, dim_tags, n,
                                                   run->opt, text,
                                                   sizeof text);
    if (st == GETME_OK) {
        int32_t na = run->model->num_elements, gone = ne;
        const size_t *after = run->model->elem_tags;
        for (int32_t i = 0; i < na; i++)
            gone -= bsearch(&after[i], before, (size_t)ne, sizeof *before,
                            cmp_size) != NULL;
        r->topology_ran = 1;
        r->topology_elements_before = ne;
        r->topology_elements_after = na;
        r->topology_changed = gone;
        if (run->opt->log >= 1)
            gg_log("info", "Topology: Gmsh's optimizer changed %d elements "
                           "(%d -> %d elements)",
                   (int)gone, (int)ne, (int)na);
    }
    free(before);
    if (st != GETME_OK)
        return fail(run, st, ierr ? "Gmsh's optimize(\"\") failed" : text);
    return GETME_OK;
}

getme_status getme_gmsh_optimize(int niter, const int *dim_tags,
                                 size_t dim_tags_n,
                                 const getme_gmsh_options *options,
                                 getme_gmsh_report *report)
{
    getme_gmsh_options defaults;
    getme_gmsh_report local;
    gg_run run;
    memset(&run, 0, sizeof run);
    if (!options) {
        gg_options_defaults(&defaults);
        options = &defaults;
    }
    run.opt = options;
    run.rep = report ? report : &local;
    memset(run.rep, 0, sizeof *run.rep);
    if (!gg_gmsh_initialized())
        return fail(&run, GETME_ERR_STATE,
                    "Gmsh is not initialized (call gmshInitialize first)");
    run.wall0 = wall_now();
    run.cpu0 = cpu_now();
    if (options->log >= 1)
        gg_log("info", "Optimizing mesh (%s)...",
               options->params.method == GETME_METHOD_SMART_LAPLACE
                   ? "smart Laplace"
                   : "GETMe adaptive");
    getme_status st = read_and_check(&run, dim_tags, dim_tags_n);
    if (st == GETME_OK && options->topology &&
        (st = topology_first(&run, dim_tags, dim_tags_n)) == GETME_OK &&
        run.rep->topology_ran)
        st = check_model(&run);
    if (st == GETME_OK && options->log >= 1)
        log_start(&run);
    /* second-order elements invalid only at mid-nodes count as valid in
       the statistics (their corners are): untangling repairs them */
    if (st == GETME_OK && (run.rep->before.num_invalid > 0 ||
                           (run.rep->num_second_order > 0 &&
                            run.rep->jacobian_ratio_before <= 0.0 &&
                            options->params.untangle)))
        st = untangle(&run);
    if (st == GETME_OK)
        st = smooth_and_apply(&run, niter);
    run.rep->wall = wall_now() - run.wall0;
    run.rep->cpu = cpu_now() - run.cpu0;
    if ((st == GETME_OK || st == GETME_ERR_CANCELLED) && options->log >= 1) {
        log_end(&run);
        gg_log("info", "Done optimizing mesh (Wall %gs, CPU %gs)",
               run.rep->wall, run.rep->cpu);
    }
    getme_gmsh_model_free(run.model);
    return st;
}

getme_status getme_gmsh_quality(const int *dim_tags, size_t dim_tags_n,
                                const getme_gmsh_options *options,
                                getme_gmsh_report *report)
{
    getme_gmsh_options quiet;
    getme_gmsh_report local;
    gg_run run;
    memset(&run, 0, sizeof run);
    if (options)
        quiet = *options;
    else
        gg_options_defaults(&quiet);
    quiet.log = 0;
    run.opt = &quiet;
    run.rep = report ? report : &local;
    memset(run.rep, 0, sizeof *run.rep);
    char text[GG_MSG];
    getme_status st = getme_gmsh_model_read(&run.model, dim_tags, dim_tags_n,
                                            &quiet, text, sizeof text);
    if (st != GETME_OK) {
        snprintf(run.rep->message, sizeof run.rep->message, "%s", text);
        return st;
    }
    getme_mesh *mesh = getme_gmsh_model_mesh(run.model);
    run.rep->dim = run.model->dim;
    run.rep->num_entities = run.model->num_entities;
    run.rep->num_nodes = getme_mesh_num_nodes(mesh);
    run.rep->num_elements = getme_mesh_num_elements(mesh);
    run.rep->num_fixed = getme_mesh_num_fixed(mesh);
    st = sweep(mesh, &run.rep->before, &run.rep->measures_before[0][0], NULL);
    run.rep->after = run.rep->before;
    memcpy(run.rep->measures_after, run.rep->measures_before,
           sizeof run.rep->measures_after);
    if (st != GETME_OK)
        snprintf(run.rep->message, sizeof run.rep->message, "%s",
                 st == GETME_ERR_NOMEM ? "out of memory"
                                       : getme_mesh_error(mesh));
    getme_gmsh_model_free(run.model);
    return st;
}
