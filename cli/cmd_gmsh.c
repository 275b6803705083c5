/*
 * cmd_gmsh.c -- `getme gmsh`: mesh a .geo / .step / .brep with Gmsh (or
 * open a .msh), smooth it with GETMe adaptive through the Gmsh plugin, and
 * write the result, all in one process with Gmsh's own terminal output on
 * for reading and meshing.
 *
 *   getme gmsh model.geo|model.step|model.msh [-2|-3] [-clmax X] [-clmin X]
 *              [-o out.msh] [-format msh22|msh41] [-bin] [smooth options]
 *
 * The smooth options are `getme smooth`'s, parsed by the same code
 * (smooth_opts.c), and the smoothing logs the same lines.  Exit codes as
 * the rest of the getme command (cli.h).
 */
#include "cli.h"
#include "getme_gmsh.h"

#include <gmshc.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char GMSH_HELP[] =
    "usage: getme gmsh INPUT [options]\n"
    "  INPUT                 .geo, .step/.stp, .brep (meshed by Gmsh first) or .msh\n"
    "  -2, -3                generate a 2-D / 3-D mesh (default: the model's\n"
    "                        dimension when INPUT has no mesh yet)\n"
    "  -clmax X, -clmin X    Gmsh's Mesh.MeshSizeMax / Mesh.MeshSizeMin\n"
    "  -o FILE               output (default INPUT with .msh, or -smooth.msh for\n"
    "                        a .msh input); any format Gmsh writes (.msh, .inp,\n"
    "                        .vtk, .unv, ...), chosen by its extension\n"
    "  -format msh22|msh41   MSH version of the output (default 4.1)\n"
    "  -bin                  binary MSH\n"
    "  --topology            when some of the worst tets have no free node (no\n"
    "                        node move can fix them), run Gmsh's optimize(\"\")\n"
    "                        (edge/face swaps) first, then GETMe adaptive\n"
    "smooth options (as getme smooth; --fix also takes GROUP,GROUP,...):\n";

static const char GMSH_HELP_TAIL[] =
    "  --sigma S, --threshold-fraction F   short for --param sigma=S ...\n";

typedef struct gmsh_args {
    const char *input, *output;
    int dim;
    double clmax, clmin, msh_version;
    int binary, topology;
    cli_smooth_opts o;
} gmsh_args;

static int parse_format(gmsh_args *a, const char *v)
{
    if (v && (!strcmp(v, "msh22") || !strcmp(v, "msh2")))
        a->msh_version = 2.2;
    else if (v && (!strcmp(v, "msh41") || !strcmp(v, "msh4") ||
                   !strcmp(v, "msh")))
        a->msh_version = 4.1;
    else {
        cli_error("-format expects msh22 or msh41, got '%s'", v ? v : "");
        return -1;
    }
    return 0;
}

/* One Gmsh option at argv[*i]; advances *i past its value.  0 ok, -1
   error. */
static int parse_one(gmsh_args *a, int argc, char **argv, int *i)
{
    const char *o = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    double x;
    if (!strcmp(o, "-2") || !strcmp(o, "-3")) {
        a->dim = o[1] - '0';
        return 0;
    }
    if (!strcmp(o, "-bin") || !strcmp(o, "--topology")) {
        *(o[1] == 'b' ? &a->binary : &a->topology) = 1;
        return 0;
    }
    static const char *const with_value[] = {
        "-o", "-clmax", "-clmin", "-format", "--sigma", "--threshold-fraction"};
    int known = 0;
    for (size_t k = 0; k < sizeof with_value / sizeof *with_value; k++)
        known |= !strcmp(o, with_value[k]);
    if (!known) {
        cli_error("unknown option '%s' (see getme gmsh --help)", o);
        return -1;
    }
    if (!v) {
        cli_error("option %s needs a value (see getme gmsh --help)", o);
        return -1;
    }
    ++*i;
    if (!strcmp(o, "-o"))
        a->output = v;
    else if (!strcmp(o, "-clmax"))
        return cli_parse_double(o, v, &a->clmax);
    else if (!strcmp(o, "-clmin"))
        return cli_parse_double(o, v, &a->clmin);
    else if (!strcmp(o, "-format"))
        return parse_format(a, v);
    else { /* --sigma, --threshold-fraction (getme.geo uses them) */
        if (cli_parse_double(o, v, &x) != 0)
            return -1;
        if (getme_params_set(&a->o.params,
                             o[2] == 's' ? "sigma" : "threshold_fraction",
                             x) != GETME_OK) {
            cli_error("%s %s: value out of range", o, v);
            return -1;
        }
    }
    return 0;
}

static int parse_args(gmsh_args *a, int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        int r = cli_smooth_option(&a->o, argc, argv, &i);
        if (r < 0)
            return -1;
        if (r > 0)
            continue;
        if (argv[i][0] == '-' && argv[i][1] != 0) {
            if (parse_one(a, argc, argv, &i) != 0)
                return -1;
        } else if (!a->input)
            a->input = argv[i];
        else {
            cli_error("more than one input file ('%s' and '%s')", a->input,
                      argv[i]);
            return -1;
        }
    }
    if (!a->input) {
        cli_error("no input file (see getme gmsh --help)");
        return -1;
    }
    return 0;
}

static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext);
    if (n < m)
        return 0;
    for (size_t i = 0; i < m; i++) {
        char c = path[n - m + i];
        if ((c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c) != ext[i])
            return 0;
    }
    return 1;
}

/* INPUT with its extension replaced by suffix. */
static void default_output(const char *input, const char *suffix, char *buf,
                           size_t size)
{
    const char *slash = strrchr(input, '/'), *dot = strrchr(input, '.');
    int stem = dot && (!slash || dot > slash) ? (int)(dot - input)
                                              : (int)strlen(input);
    snprintf(buf, size, "%.*s%s", stem, input, suffix);
}

static void set_number(const char *name, double v)
{
    int ierr = 0;
    gmshOptionSetNumber(name, v, &ierr);
}

static int model_has_mesh(void)
{
    for (int d = 2; d <= 3; d++) {
        int *types = NULL, ierr = 0;
        size_t n = 0;
        gmshModelMeshGetElementTypes(&types, &n, d, -1, &ierr);
        gmshFree(types);
        if (n)
            return 1;
    }
    return 0;
}

static int open_and_mesh(const gmsh_args *a)
{
    FILE *f = fopen(a->input, "rb");
    if (!f) {
        cli_error("cannot open '%s': %s", a->input, strerror(errno));
        return CLI_EXIT_OPEN;
    }
    fclose(f);
    if (a->clmax > 0)
        set_number("Mesh.MeshSizeMax", a->clmax);
    if (a->clmin > 0)
        set_number("Mesh.MeshSizeMin", a->clmin);
    int ierr = 0;
    gmshOpen(a->input, &ierr);
    if (ierr) {
        cli_error("Gmsh could not read '%s'", a->input);
        return CLI_EXIT_PARSE;
    }
    int dim = a->dim;
    if (!dim && !model_has_mesh())
        dim = gmshModelGetDimension(&ierr);
    if (dim >= 2) {
        gmshModelMeshGenerate(dim, &ierr);
        if (ierr) {
            cli_error("Gmsh could not mesh '%s'", a->input);
            return CLI_EXIT_UNSUPPORTED;
        }
    }
    return CLI_EXIT_OK;
}

static int exit_code(getme_status st, const getme_gmsh_report *rep)
{
    switch (st) {
    case GETME_OK: return 0;
    case GETME_ERR_ARGUMENT: return EXIT_USAGE;
    case GETME_ERR_INVALID_MESH: /* 8 if untangling ran and fell short */
        return rep->untangle.num_invalid_before ? CLI_EXIT_TANGLED
                                                : CLI_EXIT_INVALID;
    case GETME_ERR_STATE:
    case GETME_ERR_TOPOLOGY: return CLI_EXIT_UNSUPPORTED;
    default: return CLI_EXIT_INTERNAL;
    }
}

/* Gmsh's INP writer puts the name it was given into *Heading: give the
   output's name, not the temporary file's.  Copies src to dst with that
   line replaced; 0 or -1. */
static int fix_heading(const char *src, const char *dst, const char *tmp_name,
                       const char *out)
{
    FILE *in = fopen(src, "rb"), *f = fopen(dst, "wb");
    char line[8192];
    int rc = in && f ? 0 : -1, n = 0;
    while (rc == 0 && fgets(line, sizeof line, in)) {
        size_t len = strlen(line);
        if (n++ < 4 && line[0] == ' ' && len > 1 &&
            strncmp(line + 1, tmp_name, strlen(tmp_name)) == 0 &&
            (line[1 + strlen(tmp_name)] == '\n' ||
             line[1 + strlen(tmp_name)] == '\r'))
            rc = fprintf(f, " %s%s", out, line + 1 + strlen(tmp_name)) < 0;
        else
            rc = fwrite(line, 1, len, f) != len;
    }
    if (in)
        fclose(in);
    if (f && fclose(f) != 0)
        rc = -1;
    return rc;
}

/* Gmsh picks the writer from the extension: the temporary file keeps it. */
static int write_output(const gmsh_args *a, const char *out, const char *name)
{
    char tmp[4096], tmp_ext[4200], tmp2[4096];
    const char *dot = strrchr(out, '.'), *slash = strrchr(out, '/');
    const char *ext = dot && (!slash || dot > slash) ? dot : ".msh";
    if (getme_io_tmp_path(out, tmp, sizeof tmp) != 0) {
        cli_error("cannot create a temporary file next to '%s': %s", out,
                  strerror(errno));
        return CLI_EXIT_WRITE;
    }
    snprintf(tmp_ext, sizeof tmp_ext, "%s%s", tmp, ext);
    remove(tmp);
    set_number("Mesh.MshFileVersion", a->msh_version);
    set_number("Mesh.Binary", a->binary);
    cli_info(&a->o.log, "Writing '%s'...", name);
    set_number("General.Terminal", 0); /* it would name the temporary file */
    int ierr = 0;
    gmshWrite(tmp_ext, &ierr);
    set_number("General.Terminal", a->o.log.quiet ? 0 : 1);
    FILE *f = ierr ? NULL : fopen(tmp_ext, "rb");
    if (f)
        fclose(f);
    const char *final = tmp_ext;
    if (f && has_ext(out, ".inp")) {
        if (getme_io_tmp_path(out, tmp2, sizeof tmp2) != 0 ||
            fix_heading(tmp_ext, tmp2, tmp_ext, name) != 0) {
            remove(tmp2);
            f = NULL;
        } else
            final = tmp2;
        remove(tmp_ext);
    }
    if (!f || getme_io_commit(final, out) != 0) {
        remove(final);
        cli_error("cannot write '%s'", out);
        return CLI_EXIT_WRITE;
    }
    return 0;
}

/* --fix GROUP,GROUP,... */
static int add_fixed_groups(getme_gmsh_options *opt, const char *list)
{
    char name[256];
    while (*list) {
        size_t n = strcspn(list, ",");
        while (n && *list == ' ') {
            list++;
            n--;
        }
        snprintf(name, sizeof name, "%.*s", (int)(n < 255 ? n : 255), list);
        for (size_t k = strlen(name); k && name[k - 1] == ' ';)
            name[--k] = 0;
        if (name[0] && getme_gmsh_options_add_fixed_group(opt, name) != GETME_OK)
            return -1;
        list += n + (list[n] == ',');
    }
    return 0;
}

/* What getme_gmsh_optimize smooths: element counts per type of dim. */
static void count_model(int dim, const getme_gmsh_report *rep,
                        cli_mesh_counts *c)
{
    static const int gmsh_type[GETME_NUM_TYPES] = {4, 5, 6, 7, 2, 3};
    memset(c, 0, sizeof *c);
    c->nodes = rep->num_nodes;
    c->fixed = rep->num_fixed;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        size_t *tags = NULL, *nodes = NULL, nt = 0, nn = 0;
        int ierr = 0;
        if ((t < 4) != (dim == 3))
            continue;
        gmshModelMeshGetElementsByType(gmsh_type[t], &tags, &nt, &nodes, &nn,
                                       -1, 0, 1, &ierr);
        c->elements[t] = ierr ? 0 : (int32_t)nt;
        gmshFree(tags);
        gmshFree(nodes);
    }
}

typedef struct gmsh_result {
    getme_quality_stats before;
    getme_gmsh_report rep;
    cli_mesh_counts counts;
    cli_measures mbefore, mafter;
} gmsh_result;

static int smooth_model(gmsh_args *a, gmsh_result *res)
{
    cli_smooth_opts *so = &a->o;
    getme_gmsh_options *opt = getme_gmsh_options_new();
    char msg[600];
    int rc = 0;
    if (!opt) {
        cli_error("out of memory");
        return CLI_EXIT_INTERNAL;
    }
    getme_gmsh_options_set(opt, "log", 0);
    getme_gmsh_options_set(opt, "fix_interfaces", !so->free_interfaces);
    getme_gmsh_options_set(opt, "allow_invalid", so->allow_invalid);
    getme_gmsh_options_set(opt, "topology", a->topology);
    for (int i = 0; i < so->num_fix && rc == 0; i++)
        rc = add_fixed_groups(opt, so->fix[i]);
    if (rc == 0 && so->num_free &&
        getme_gmsh_check_groups(so->free_sets, so->num_free, "free", msg,
                                sizeof msg) != GETME_OK) {
        cli_error("'%s': %s", a->input, msg);
        getme_gmsh_options_free(opt);
        return EXIT_USAGE;
    }
    getme_gmsh_report *rep = &res->rep;
    memset(rep, 0, sizeof *rep);
    getme_status st = rc == 0 ? getme_gmsh_quality(NULL, 0, opt, rep)
                              : GETME_ERR_NOMEM;
    if (st == GETME_OK) {
        res->before = rep->before;
        memcpy(res->mbefore.stats, rep->measures_before,
               sizeof res->mbefore.stats);
        cli_print_stats(&so->log, "Quality before", &res->before);
        cli_print_measures(&so->log, "Measures before", &res->mbefore);
        cli_smooth_begin(so, getme_gmsh_options_params(opt));
        st = getme_gmsh_optimize(0, NULL, 0, opt, rep);
        if (rep->untangle.num_invalid_before)
            cli_untangle_warning(&so->log, &rep->untangle);
        if (st == GETME_OK) {
            cli_smooth_done(so, &rep->result);
            cli_print_stats(&so->log, "Quality after ", &rep->after);
            memcpy(res->mafter.stats, rep->measures_after,
                   sizeof res->mafter.stats);
            cli_print_measures(&so->log, "Measures after ", &res->mafter);
            count_model(rep->dim, rep, &res->counts);
        }
    }
    if (st != GETME_OK) {
        cli_error("%s", rep->message[0] ? rep->message : getme_status_string(st));
        rc = exit_code(st, rep);
    }
    getme_gmsh_options_free(opt);
    return rc;
}

static int run(gmsh_args *a)
{
    char out[4096];
    if (a->output)
        snprintf(out, sizeof out, "%s", a->output);
    else
        default_output(a->input, has_ext(a->input, ".msh") ? "-smooth.msh"
                                                           : ".msh",
                       out, sizeof out);
    /* any format Gmsh writes: no extension check, the rest as smooth */
    cli_paths paths = {NULL, out, a->o.report, "", ""};
    int rc = cli_check_paths(&paths);
    if (rc)
        return rc;
    if (cli_same_file(a->input, paths.out) ||
        (a->o.report && cli_same_file(a->input, paths.rep))) {
        cli_error("%s: refusing to overwrite the input; choose another "
                  "file", cli_same_file(a->input, paths.out) ? out
                                                            : a->o.report);
        return EXIT_USAGE;
    }
    int ierr = 0;
    gmshInitialize(0, NULL, 0, &ierr);
    set_number("General.Terminal", a->o.log.quiet ? 0 : 1);
    rc = open_and_mesh(a);
    gmsh_result res;
    if (rc == 0)
        rc = smooth_model(a, &res);
    cli_guard guard = {0};
    cli_write_guard(&guard, 1);
    if (rc == 0 ||
        (rc == CLI_EXIT_TANGLED && a->o.allow_invalid)) {
        /* --allow-invalid: the partly untangled mesh, exit code kept */
        int wrc = write_output(a, paths.out, out);
        rc = rc ? rc : wrc;
    }
    if (rc == 0 && a->o.report &&
        cli_write_report(paths.rep, a->input, out, &a->o.params, &res.counts,
                         &res.before, &res.rep.after, &res.rep.result,
                         &a->o.history, "gmsh",
                         &(cli_report_extra){NULL, NULL, NULL, &res.mbefore,
                                             &res.mafter}) != 0) {
        cli_error("%s: cannot write the report: %s", a->o.report,
                  strerror(errno));
        rc = CLI_EXIT_WRITE;
    }
    cli_write_guard(&guard, 0);
    if (rc == 0)
        cli_info(&a->o.log, "Done writing '%s'", out);
    gmshFinalize(&ierr);
    return rc;
}

int getme_cli_gmsh(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            fputs(GMSH_HELP, stdout);
            fputs(CLI_SMOOTH_OPTIONS_HELP, stdout);
            fputs(GMSH_HELP_TAIL, stdout);
            cli_print_params(stdout);
            return 0;
        }
    gmsh_args a;
    memset(&a, 0, sizeof a);
    a.msh_version = 4.1;
    if (cli_smooth_opts_init(&a.o, argc) != 0) {
        cli_error("out of memory");
        return CLI_EXIT_INTERNAL;
    }
    int rc = parse_args(&a, argc, argv) != 0 ? EXIT_USAGE : run(&a);
    cli_smooth_opts_free(&a.o);
    return rc;
}
