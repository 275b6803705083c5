/*
 * gmsh_options.c -- the options handle of getme_gmsh_optimize(): GETMe
 * parameters, logging level, fixed-node policy and named groups.
 */
#include "gmsh_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void gg_options_defaults(getme_gmsh_options *opt)
{
    memset(opt, 0, sizeof *opt);
    getme_params_init(&opt->params);
    opt->log = 2;
    opt->fix_skin = 1;
    opt->fix_interfaces = 1;
    opt->worst = GETME_GMSH_MAX_WORST;
}

getme_gmsh_options *getme_gmsh_options_new(void)
{
    getme_gmsh_options *opt = malloc(sizeof *opt);
    if (opt)
        gg_options_defaults(opt);
    return opt;
}

void getme_gmsh_options_free(getme_gmsh_options *opt)
{
    if (!opt)
        return;
    for (int i = 0; i < opt->num_fix; i++)
        free(opt->fix[i]);
    free(opt->fix);
    free(opt);
}

static getme_status bad(getme_gmsh_options *opt, const char *fmt,
                        const char *name, double value)
{
    snprintf(opt->error, sizeof opt->error, fmt, name, value);
    return GETME_ERR_ARGUMENT;
}

/* Our own names take 0/1 (fix_*, topology, allow_invalid), 0..2 (log) or
   0..GETME_GMSH_MAX_WORST (worst); the rest is libgetme's. */
getme_status getme_gmsh_options_set(getme_gmsh_options *opt, const char *name,
                                    double value)
{
    if (!opt || !name)
        return GETME_ERR_ARGUMENT;
    opt->error[0] = 0;
    int *flag = strcmp(name, "log") == 0              ? &opt->log
                : strcmp(name, "fix_skin") == 0       ? &opt->fix_skin
                : strcmp(name, "fix_interfaces") == 0 ? &opt->fix_interfaces
                : strcmp(name, "topology") == 0       ? &opt->topology
                : strcmp(name, "worst") == 0          ? &opt->worst
                : strcmp(name, "allow_invalid") == 0  ? &opt->allow_invalid
                                                      : NULL;
    if (flag) {
        double hi = flag == &opt->log     ? 2
                    : flag == &opt->worst ? GETME_GMSH_MAX_WORST
                                          : 1;
        if (!(value >= 0 && value <= hi) || value != (int)value)
            return bad(opt, "Option '%s' must be an integer in [0, %g]", name,
                       hi);
        *flag = (int)value;
        return GETME_OK;
    }
    if (getme_params_set(&opt->params, name, value) != GETME_OK)
        return bad(opt, "Unknown GETMe parameter '%s' or value %g out of range",
                   name, value);
    return GETME_OK;
}

getme_status getme_gmsh_options_set_method(getme_gmsh_options *opt,
                                           const char *method)
{
    if (!opt || !method)
        return GETME_ERR_ARGUMENT;
    opt->error[0] = 0;
    if (strcmp(method, "getme") == 0 || strcmp(method, "adaptive") == 0)
        opt->params.method = GETME_METHOD_ADAPTIVE;
    else if (strcmp(method, "laplace") == 0)
        opt->params.method = GETME_METHOD_SMART_LAPLACE;
    else {
        snprintf(opt->error, sizeof opt->error,
                 "Unknown method '%s' (use 'getme' or 'laplace')", method);
        return GETME_ERR_ARGUMENT;
    }
    return GETME_OK;
}

getme_status getme_gmsh_options_add_fixed_group(getme_gmsh_options *opt,
                                                const char *group)
{
    if (!opt || !group || !*group)
        return GETME_ERR_ARGUMENT;
    opt->error[0] = 0;
    if (opt->num_fix == opt->cap_fix) {
        int cap = opt->cap_fix ? 2 * opt->cap_fix : 4;
        char **f = realloc(opt->fix, (size_t)cap * sizeof *f);
        if (!f)
            return GETME_ERR_NOMEM;
        opt->fix = f;
        opt->cap_fix = cap;
    }
    size_t len = strlen(group) + 1;
    char *copy = malloc(len);
    if (!copy)
        return GETME_ERR_NOMEM;
    memcpy(copy, group, len);
    opt->fix[opt->num_fix++] = copy;
    return GETME_OK;
}

getme_params *getme_gmsh_options_params(getme_gmsh_options *opt)
{
    return opt ? &opt->params : NULL;
}

const char *getme_gmsh_options_error(const getme_gmsh_options *opt)
{
    return opt ? opt->error : "options is NULL";
}
