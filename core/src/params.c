/*
 * params.c -- smoothing parameters: the paper's defaults (Sec. 3.1) and
 * setters by name for bindings.
 */
#include "internal.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

/* Our choice for DetermineTransformationThreshold's position (the paper
   gives none), measured with bench/ (q*min after smoothing for
   0.002 / 0.005 / 0.01 / 0.02 / 0.05):
     1.0M tets   0.421 / 0.425 / 0.412 / 0.331 / 0.295
     578k hexes  0.862 / 0.865 / 0.863 / 0.862 / 0.857
     191k tets   0.409 / 0.397 / 0.388 / 0.386 / 0.334
     94k hexes   0.853 / 0.854 / 0.839 / 0.829 / 0.830
   0.005 is best on the larger meshes and close to best on the small ones;
   larger fractions are clearly worse (as the early prototype found,
   docs/design.md §3). */
#define DEFAULT_THRESHOLD_FRACTION 0.005

/* The one table of the numeric parameters: name, kind, default, range and
   help.  getme_params_init, getme_params_set, getme_params_get, the whole-set
   check and every binding's list (getme_param_info: the CLI's --help and
   --param, Python, the Gmsh options) come from it, so a parameter is
   defined here once.  Ranges are closed; "open_min" makes the lower bound
   exclusive (sigma > 0). */
#define FIELD(f) offsetof(getme_params, f)
static const getme_param_info PARAMS[] = {
    {"method", GETME_PARAM_ENUM, 0, 0, 1, 0, FIELD(method),
     "0 GETMe adaptive, 1 smart Laplace (the baseline)"},
    {"max_iter", GETME_PARAM_INT, 1000, 0, 1e9, 0, FIELD(max_iter),
     "iterations over both stages"},
    {"tol", GETME_PARAM_REAL, 1e-4, 0, HUGE_VAL, 0, FIELD(tol),
     "end the q_mean stage (and Laplace) when an iteration gains less"},
    {"sigma", GETME_PARAM_REAL, 1.5, 0, HUGE_VAL, 1, FIELD(sigma),
     "transformation parameter (paper: 3/2)"},
    {"max_no_min_improve", GETME_PARAM_INT, 5, 1, 1e6, 0,
     FIELD(max_no_min_improve),
     "iterations without q*min gain that end a q*min cycle"},
    {"min_tol", GETME_PARAM_REAL, 1e-5, 0, HUGE_VAL, 0, FIELD(min_tol),
     "a q*min gain counts only above this"},
    {"threshold_fraction", GETME_PARAM_REAL, DEFAULT_THRESHOLD_FRACTION, 0, 1,
     0, FIELD(threshold_fraction),
     "q*min cycles transform the elements below the quality at this "
     "position of the sorted free elements"},
    {"keep_best", GETME_PARAM_BOOL, 1, 0, 1, 0, FIELD(keep_best),
     "end on the best q*min mesh of the q*min stage"},
    {"finish", GETME_PARAM_BOOL, 1, 0, 1, 0, FIELD(finish),
     "finishing step after the q*min stage (0: the paper's method alone)"},
    {"finish_fraction", GETME_PARAM_REAL, 0.001, 0, 1, 0,
     FIELD(finish_fraction),
     "finishing passes work on the elements below the quality at this "
     "position (at least 64)"},
    {"finish_max_passes", GETME_PARAM_INT, 100, 0, 1e6, 0,
     FIELD(finish_max_passes), "at most this many finishing passes"},
    {"corner_guard", GETME_PARAM_BOOL, 1, 0, 1, 0, FIELD(corner_guard),
     "no hex/prism/pyramid/quad corner ends below max(input's worst, "
     "corner_floor)"},
    {"corner_floor", GETME_PARAM_REAL, 0, -1, 1, 0, FIELD(corner_floor),
     "floor of the corner guard (scaled Jacobian)"},
    {"num_threads", GETME_PARAM_INT, 0, 0, 4096, 0, FIELD(num_threads),
     "OpenMP threads (0: OpenMP's default); results do not depend on it"},
    {"renumber", GETME_PARAM_BOOL, 1, 0, 1, 0, FIELD(renumber),
     "reorder internally for cache locality"},
    {"untangle", GETME_PARAM_BOOL, 1, 0, 1, 0, FIELD(untangle),
     "untangle an input with invalid elements first (0: refuse it)"},
};
#define NUM_PARAMS ((int)(sizeof PARAMS / sizeof *PARAMS))

int getme_param_count(void) { return NUM_PARAMS; }

const getme_param_info *getme_param_at(int i)
{
    return i >= 0 && i < NUM_PARAMS ? &PARAMS[i] : NULL;
}

const getme_param_info *getme_param_find(const char *name)
{
    for (int i = 0; name && i < NUM_PARAMS; i++)
        if (!strcmp(PARAMS[i].name, name))
            return &PARAMS[i];
    return NULL;
}

/* Is v a value parameter d may take? */
static int in_range(const getme_param_info *d, double v)
{
    if (isnan(v) || (d->type == GETME_PARAM_REAL && !isfinite(v)))
        return 0;
    if (d->type != GETME_PARAM_REAL && v != floor(v))
        return 0;
    return (d->open_min ? v > d->min : v >= d->min) && v <= d->max;
}

/* The field of parameter d in p: every non-REAL parameter is an int (the
   method enum has int's representation). */
static void store(getme_params *p, const getme_param_info *d, double v)
{
    char *f = (char *)p + d->offset;
    if (d->type == GETME_PARAM_REAL) {
        memcpy(f, &v, sizeof v);
    } else {
        int i = (int)v;
        memcpy(f, &i, sizeof i);
    }
}

static double load(const getme_params *p, const getme_param_info *d)
{
    const char *f = (const char *)p + d->offset;
    if (d->type == GETME_PARAM_REAL) {
        double v;
        memcpy(&v, f, sizeof v);
        return v;
    }
    int i;
    memcpy(&i, f, sizeof i);
    return i;
}

void getme_params_init(getme_params *p)
{
    static const double rmean[] = {1.0, 0.25, 0.0625, 0.0};
    static const double rmin[] = {0.5, 0.25, 0.1, 0.01, 0.0};
    memset(p, 0, sizeof *p);
    for (int i = 0; i < NUM_PARAMS; i++)
        store(p, &PARAMS[i], PARAMS[i].default_value);
    p->num_relax_mean = 4;
    memcpy(p->relax_mean, rmean, sizeof rmean);
    p->num_relax_min = 5;
    memcpy(p->relax_min, rmin, sizeof rmin);
}

size_t getme_params_sizeof(void) { return sizeof(getme_params); }

getme_status getme_params_set(getme_params *p, const char *name, double v)
{
    const getme_param_info *d = getme_param_find(name);
    if (!p || !d || !in_range(d, v))
        return GETME_ERR_ARGUMENT;
    store(p, d, v);
    return GETME_OK;
}

getme_status getme_params_get(const getme_params *p, const char *name,
                              double *value)
{
    const getme_param_info *d = getme_param_find(name);
    if (!p || !d || !value)
        return GETME_ERR_ARGUMENT;
    *value = load(p, d);
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

static const char *relax_problem(const getme_params *p);

/* Check a parameter set as a whole (callers may fill the struct directly):
   0 if it is usable, else -1 with what is wrong in buf. */
int getme__params_problem(const getme_params *p, char *buf, size_t size)
{
    for (int i = 0; i < NUM_PARAMS; i++) {
        const getme_param_info *d = &PARAMS[i];
        if (!in_range(d, load(p, d))) {
            snprintf(buf, size, "%s = %g is out of its range %c%g, %g]",
                     d->name, load(p, d), d->open_min ? '(' : '[', d->min,
                     d->max);
            return -1;
        }
    }
    const char *problem = relax_problem(p);
    if (problem)
        snprintf(buf, size, "%s", problem);
    return problem ? -1 : 0;
}

/* The relaxation tables' rules (getme_params_set_relax), or NULL. */
static const char *relax_problem(const getme_params *p)
{
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
