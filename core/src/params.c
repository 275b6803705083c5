/*
 * params.c -- smoothing parameters: the paper's defaults (Sec. 3.1) and
 * setters by name for bindings.
 */
#include "internal.h"

#include <math.h>
#include <string.h>

/* Our choice for DetermineTransformationThreshold's position (the paper
   gives none), measured with bench/ (q*min after smoothing for
   0.002 / 0.005 / 0.01 / 0.02 / 0.05):
     1.0M tets   0.421 / 0.425 / 0.412 / 0.331 / 0.295
     578k hexes  0.862 / 0.865 / 0.863 / 0.862 / 0.857
     191k tets   0.409 / 0.397 / 0.388 / 0.386 / 0.334
     94k hexes   0.853 / 0.854 / 0.839 / 0.829 / 0.830
   0.005 is best on the larger meshes and close to best on the small ones;
   larger fractions are clearly worse (as DESIGN's prototype found). */
#define DEFAULT_THRESHOLD_FRACTION 0.005

void getme_params_init(getme_params *p)
{
    static const double rmean[] = {1.0, 0.25, 0.0625, 0.0};
    static const double rmin[] = {0.5, 0.25, 0.1, 0.01, 0.0};
    memset(p, 0, sizeof *p);
    p->method = GETME_METHOD_ADAPTIVE;
    p->max_iter = 1000;
    p->tol = 1e-4;
    p->sigma = 1.5;
    p->num_relax_mean = 4;
    memcpy(p->relax_mean, rmean, sizeof rmean);
    p->num_relax_min = 5;
    memcpy(p->relax_min, rmin, sizeof rmin);
    p->max_no_min_improve = 5;
    p->min_tol = 1e-5;
    p->threshold_fraction = DEFAULT_THRESHOLD_FRACTION;
    p->keep_best = 1;
    p->finish = 1;
    p->finish_fraction = 0.001;
    p->finish_max_passes = 100;
    p->corner_guard = 1;
    p->corner_floor = 0.0;
    p->num_threads = 0;
    p->renumber = 1;
    p->untangle = 1;
}

size_t getme_params_sizeof(void) { return sizeof(getme_params); }

static int is_int(double v) { return isfinite(v) && v == floor(v); }

getme_status getme_params_set(getme_params *p, const char *name, double v)
{
    if (!p || !name || isnan(v))
        return GETME_ERR_ARGUMENT;
    if (!strcmp(name, "method")) {
        if (v != 0.0 && v != 1.0)
            return GETME_ERR_ARGUMENT;
        p->method = v == 0.0 ? GETME_METHOD_ADAPTIVE : GETME_METHOD_SMART_LAPLACE;
    } else if (!strcmp(name, "max_iter")) {
        if (!is_int(v) || v < 0 || v > 1e9)
            return GETME_ERR_ARGUMENT;
        p->max_iter = (int)v;
    } else if (!strcmp(name, "tol")) {
        if (!(v >= 0.0) || !isfinite(v))
            return GETME_ERR_ARGUMENT;
        p->tol = v;
    } else if (!strcmp(name, "sigma")) {
        if (!(v > 0.0) || !isfinite(v))
            return GETME_ERR_ARGUMENT;
        p->sigma = v;
    } else if (!strcmp(name, "max_no_min_improve")) {
        if (!is_int(v) || v < 1 || v > 1e6)
            return GETME_ERR_ARGUMENT;
        p->max_no_min_improve = (int)v;
    } else if (!strcmp(name, "min_tol")) {
        if (!(v >= 0.0) || !isfinite(v))
            return GETME_ERR_ARGUMENT;
        p->min_tol = v;
    } else if (!strcmp(name, "threshold_fraction")) {
        if (!(v >= 0.0 && v <= 1.0))
            return GETME_ERR_ARGUMENT;
        p->threshold_fraction = v;
    } else if (!strcmp(name, "keep_best")) {
        if (v != 0.0 && v != 1.0)
            return GETME_ERR_ARGUMENT;
        p->keep_best = (int)v;
    } else if (!strcmp(name, "finish")) {
        if (v != 0.0 && v != 1.0)
            return GETME_ERR_ARGUMENT;
        p->finish = (int)v;
    } else if (!strcmp(name, "finish_fraction")) {
        if (!(v >= 0.0 && v <= 1.0))
            return GETME_ERR_ARGUMENT;
        p->finish_fraction = v;
    } else if (!strcmp(name, "finish_max_passes")) {
        if (!is_int(v) || v < 0 || v > 1e6)
            return GETME_ERR_ARGUMENT;
        p->finish_max_passes = (int)v;
    } else if (!strcmp(name, "corner_guard")) {
        if (v != 0.0 && v != 1.0)
            return GETME_ERR_ARGUMENT;
        p->corner_guard = (int)v;
    } else if (!strcmp(name, "corner_floor")) {
        if (!(v >= -1.0 && v <= 1.0))
            return GETME_ERR_ARGUMENT;
        p->corner_floor = v;
    } else if (!strcmp(name, "num_threads")) {
        if (!is_int(v) || v < 0 || v > 4096)
            return GETME_ERR_ARGUMENT;
        p->num_threads = (int)v;
    } else if (!strcmp(name, "renumber")) {
        if (v != 0.0 && v != 1.0)
            return GETME_ERR_ARGUMENT;
        p->renumber = (int)v;
    } else if (!strcmp(name, "untangle")) {
        if (v != 0.0 && v != 1.0)
            return GETME_ERR_ARGUMENT;
        p->untangle = (int)v;
    } else {
        return GETME_ERR_ARGUMENT;
    }
    return GETME_OK;
}

getme_status getme_params_set_relax(getme_params *p, getme_stage stage, int n,
                                    const double *v)
{
    if (!p || !v || n < 1 || n > GETME_MAX_RELAX)
        return GETME_ERR_ARGUMENT;
    if (stage != GETME_STAGE_MEAN && stage != GETME_STAGE_MIN)
        return GETME_ERR_ARGUMENT;
    for (int i = 0; i < n; i++) {
        if (!(v[i] >= 0.0 && v[i] <= 1.0))
            return GETME_ERR_ARGUMENT;
        if (i > 0 && !(v[i] < v[i - 1]))
            return GETME_ERR_ARGUMENT; /* strictly descending */
    }
    if (v[n - 1] != 0.0)
        return GETME_ERR_ARGUMENT; /* the reset entry guarantees validity */
    double *dst = stage == GETME_STAGE_MEAN ? p->relax_mean : p->relax_min;
    memcpy(dst, v, (size_t)n * sizeof *v);
    if (stage == GETME_STAGE_MEAN)
        p->num_relax_mean = n;
    else
        p->num_relax_min = n;
    return GETME_OK;
}

/* Check a parameter set as a whole (callers may fill the struct directly).
   Returns NULL if it is usable, else what is wrong. */
const char *getme__params_problem(const getme_params *p)
{
    if (p->method != GETME_METHOD_ADAPTIVE &&
        p->method != GETME_METHOD_SMART_LAPLACE)
        return "unknown method";
    if (p->max_iter < 0)
        return "max_iter must be >= 0";
    if (!(p->tol >= 0.0) || !isfinite(p->tol))
        return "tol must be finite and >= 0";
    if (!(p->sigma > 0.0) || !isfinite(p->sigma))
        return "sigma must be finite and > 0";
    if (p->max_no_min_improve < 1)
        return "max_no_min_improve must be >= 1";
    if (!(p->min_tol >= 0.0) || !isfinite(p->min_tol))
        return "min_tol must be finite and >= 0";
    if (!(p->threshold_fraction >= 0.0 && p->threshold_fraction <= 1.0))
        return "threshold_fraction must be in [0, 1]";
    if (p->num_threads < 0)
        return "num_threads must be >= 0";
    if (!(p->finish_fraction >= 0.0 && p->finish_fraction <= 1.0))
        return "finish_fraction must be in [0, 1]";
    if (p->finish_max_passes < 0)
        return "finish_max_passes must be >= 0";
    if (!(p->corner_floor >= -1.0 && p->corner_floor <= 1.0))
        return "corner_floor must be in [-1, 1]";
    const double *tab[2] = {p->relax_mean, p->relax_min};
    int num[2] = {p->num_relax_mean, p->num_relax_min};
    for (int s = 0; s < 2; s++) {
        if (num[s] < 1 || num[s] > GETME_MAX_RELAX)
            return "relaxation table size out of range";
        for (int i = 0; i < num[s]; i++)
            if (!(tab[s][i] >= 0.0 && tab[s][i] <= 1.0) ||
                (i > 0 && !(tab[s][i] < tab[s][i - 1])))
                return "relaxation tables must descend strictly in [0, 1]";
        if (tab[s][num[s] - 1] != 0.0)
            return "relaxation tables must end with 0";
    }
    return NULL;
}
