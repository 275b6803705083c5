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

static getme_status check_valid(gg_run *run)
{
    const getme_quality_stats *s = &run->rep->before;
    if (s->num_invalid == 0)
        return GETME_OK;
    char text[GG_MSG], one[128];
    int used = snprintf(text, sizeof text, "%lld invalid (inverted or "
                        "degenerate) element%s: ",
                        (long long)s->num_invalid,
                        s->num_invalid > 1 ? "s" : "");
    for (int i = 0; i < s->num_reported_invalid && used < (int)sizeof text;
         i++) {
        getme_gmsh_model_describe_element(run->model, s->first_invalid[i],
                                          one, sizeof one);
        used += snprintf(text + used, sizeof text - (size_t)used, "%s%s",
                         i ? ", " : "", one);
    }
    if (used < (int)sizeof text)
        snprintf(text + used, sizeof text - (size_t)used, "%s",
                 s->num_invalid > s->num_reported_invalid
                     ? ", ...: GETMe needs a valid mesh"
                     : ": GETMe needs a valid mesh");
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
}

static getme_status read_and_check(gg_run *run, const int *dim_tags,
                                   size_t n)
{
    char text[GG_MSG];
    getme_status st = getme_gmsh_model_read(&run->model, dim_tags, n,
                                            run->opt, text, sizeof text);
    if (st != GETME_OK)
        return fail(run, st, text);
    getme_mesh *mesh = getme_gmsh_model_mesh(run->model);
    getme_gmsh_report *r = run->rep;
    r->dim = getme_gmsh_model_dim(run->model);
    r->num_entities = getme_gmsh_model_num_entities(run->model);
    r->num_nodes = getme_mesh_num_nodes(mesh);
    r->num_elements = getme_mesh_num_elements(mesh);
    r->num_fixed = getme_mesh_num_fixed(mesh);
    st = getme_mesh_quality_stats(mesh, -1, &r->before);
    if (st == GETME_OK)
        st = getme_mesh_measure_all(mesh, &r->measures_before[0][0]);
    if (st != GETME_OK)
        return fail(run, st, getme_mesh_error(mesh));
    return check_valid(run);
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
    if (st != GETME_OK && st != GETME_ERR_CANCELLED)
        return fail(run, st, getme_mesh_error(mesh));
    /* A cancelled run still leaves a valid, partly smoothed mesh. */
    getme_status st2 = getme_mesh_quality_stats(mesh, -1, &run->rep->after);
    if (st2 == GETME_OK)
        st2 = getme_mesh_measure_all(mesh, &run->rep->measures_after[0][0]);
    char text[GG_MSG];
    if (st2 == GETME_OK)
        st2 = getme_gmsh_model_apply(run->model, getme_mesh_coords(mesh),
                                     &run->rep->num_moved, text,
                                     sizeof text);
    else
        snprintf(text, sizeof text, "%s", getme_mesh_error(mesh));
    return st2 != GETME_OK ? fail(run, st2, text) : st;
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
    if (st == GETME_OK && options->log >= 1)
        log_start(&run);
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
    run.rep->dim = getme_gmsh_model_dim(run.model);
    run.rep->num_entities = getme_gmsh_model_num_entities(run.model);
    run.rep->num_nodes = getme_mesh_num_nodes(mesh);
    run.rep->num_elements = getme_mesh_num_elements(mesh);
    run.rep->num_fixed = getme_mesh_num_fixed(mesh);
    st = getme_mesh_quality_stats(mesh, -1, &run.rep->before);
    if (st == GETME_OK)
        st = getme_mesh_measure_all(mesh, &run.rep->measures_before[0][0]);
    run.rep->after = run.rep->before;
    memcpy(run.rep->measures_after, run.rep->measures_before,
           sizeof run.rep->measures_after);
    if (st != GETME_OK)
        snprintf(run.rep->message, sizeof run.rep->message, "%s",
                 getme_mesh_error(mesh));
    getme_gmsh_model_free(run.model);
    return st;
}
