/*
 * cmd_gmsh.c -- `getme gmsh`: mesh a .geo / .step / .brep with Gmsh (or
 * open a .msh), smooth it with GETMe adaptive through the Gmsh plugin, and
 * write the result, all in one process with Gmsh's own terminal output on.
 *
 *   getme gmsh model.geo|model.step|model.msh [-2|-3] [-clmax X] [-clmin X]
 *              [-o out.msh] [-format msh22|msh41] [-bin] [--method getme|
 *              laplace] [--fix GROUP]... [--threads N] [--sigma S]
 *              [--max-iter N] [--threshold-fraction F] [--free-interfaces]
 *              [--topology] [--no-untangle] [--allow-invalid] [--quiet]
 *
 * Exit codes as the rest of the getme command (cli.h).
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
    "  --method getme|laplace   GETMe adaptive (default) or smart Laplace\n"
    "  --fix GROUP[,GROUP]   keep the nodes of physical groups (names or dim:tag)\n"
    "                        fixed; repeatable\n"
    "  --free-interfaces     do not fix faces between physical groups (nodes on\n"
    "                        Gmsh interface surfaces stay fixed regardless)\n"
    "  --topology            when some of the worst tets have no free node (no\n"
    "                        node move can fix them), run Gmsh's optimize(\"\")\n"
    "                        (edge/face swaps) first, then GETMe adaptive\n"
    "  --no-untangle         refuse a mesh with inverted elements (exit 6)\n"
    "                        instead of untangling it first\n"
    "  --allow-invalid       if untangling leaves inverted elements, still\n"
    "                        write the partly untangled mesh (exit code 8)\n"
    "  --threads N           OpenMP threads (0: default)\n"
    "  --sigma S, --max-iter N, --threshold-fraction F   GETMe parameters\n"
    "  --quiet               only errors\n";

typedef struct gmsh_args {
    const char *input, *output;
    int dim;
    double clmax, clmin, msh_version;
    int binary, quiet, allow_invalid;
    getme_gmsh_options *opt;
} gmsh_args;

static int set_param(gmsh_args *a, const char *name, const char *opt,
                     const char *value)
{
    double v;
    if (cli_parse_double(opt, value, &v) != 0)
        return -1;
    if (getme_gmsh_options_set(a->opt, name, v) != GETME_OK) {
        cli_error("%s: %s", opt, getme_gmsh_options_error(a->opt));
        return -1;
    }
    return 0;
}

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

static int takes_value(const char *o)
{
    static const char *const names[] = {
        "-o", "-clmax", "-clmin", "-format", "--method", "--fix", "--threads",
        "--sigma", "--max-iter", "--threshold-fraction"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++)
        if (!strcmp(o, names[i]))
            return 1;
    return 0;
}

/* --fix takes one name or a comma-separated list ("clamp,bolt holes"). */
static int add_fixed_groups(gmsh_args *a, const char *list)
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
        if (name[0] &&
            getme_gmsh_options_add_fixed_group(a->opt, name) != GETME_OK) {
            cli_error("out of memory");
            return -1;
        }
        list += n + (list[n] == ',');
    }
    return 0;
}

/* One option at argv[*i]; advances *i past its value.  0 ok, -1 error. */
static int parse_one(gmsh_args *a, int argc, char **argv, int *i)
{
    const char *o = argv[*i], *v = *i + 1 < argc ? argv[*i + 1] : NULL;
    int takes = 1, rc = 0;
    if (!strcmp(o, "-2") || !strcmp(o, "-3")) {
        a->dim = o[1] - '0';
        takes = 0;
    } else if (!strcmp(o, "-bin")) {
        a->binary = 1;
        takes = 0;
    } else if (!strcmp(o, "--quiet") || !strcmp(o, "-q")) {
        a->quiet = 1;
        takes = 0;
    } else if (!strcmp(o, "--free-interfaces")) {
        getme_gmsh_options_set(a->opt, "fix_interfaces", 0);
        takes = 0;
    } else if (!strcmp(o, "--no-untangle")) {
        getme_gmsh_options_set(a->opt, "untangle", 0);
        takes = 0;
    } else if (!strcmp(o, "--topology")) {
        getme_gmsh_options_set(a->opt, "topology", 1);
        takes = 0;
    } else if (!strcmp(o, "--allow-invalid")) {
        getme_gmsh_options_set(a->opt, "allow_invalid", 1);
        a->allow_invalid = 1;
        takes = 0;
    } else if (!takes_value(o)) {
        cli_error("unknown option '%s' (see getme gmsh --help)", o);
        return -1;
    } else if (!v) {
        cli_error("option %s needs a value (see getme gmsh --help)", o);
        return -1;
    } else if (!strcmp(o, "-o"))
        a->output = v;
    else if (!strcmp(o, "-clmax"))
        rc = cli_parse_double(o, v, &a->clmax);
    else if (!strcmp(o, "-clmin"))
        rc = cli_parse_double(o, v, &a->clmin);
    else if (!strcmp(o, "-format"))
        rc = parse_format(a, v);
    else if (!strcmp(o, "--method")) {
        if (getme_gmsh_options_set_method(a->opt, v) != GETME_OK) {
            cli_error("--method: %s", getme_gmsh_options_error(a->opt));
            rc = -1;
        }
    } else if (!strcmp(o, "--fix"))
        rc = add_fixed_groups(a, v);
    else if (!strcmp(o, "--threads"))
        rc = set_param(a, "num_threads", o, v);
    else if (!strcmp(o, "--sigma"))
        rc = set_param(a, "sigma", o, v);
    else if (!strcmp(o, "--max-iter"))
        rc = set_param(a, "max_iter", o, v);
    else if (!strcmp(o, "--threshold-fraction"))
        rc = set_param(a, "threshold_fraction", o, v);
    *i += takes;
    return rc;
}

static int parse_args(gmsh_args *a, int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
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
        return GETME_IO_ERR_OPEN;
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
        return GETME_IO_ERR_PARSE;
    }
    int dim = a->dim;
    if (!dim && !model_has_mesh())
        dim = gmshModelGetDimension(&ierr);
    if (dim >= 2) {
        gmshModelMeshGenerate(dim, &ierr);
        if (ierr) {
            cli_error("Gmsh could not mesh '%s'", a->input);
            return GETME_IO_ERR_UNSUPPORTED;
        }
    }
    return GETME_IO_OK;
}

static int exit_code(getme_status st, const getme_gmsh_report *rep)
{
    switch (st) {
    case GETME_OK: return 0;
    case GETME_ERR_ARGUMENT: return GETME_IO_ERR_USAGE;
    case GETME_ERR_INVALID_MESH: /* 8 if untangling ran and fell short */
        return rep->untangle.num_invalid_before ? GETME_IO_ERR_TANGLED
                                                : GETME_IO_ERR_INVALID;
    case GETME_ERR_STATE:
    case GETME_ERR_TOPOLOGY: return GETME_IO_ERR_UNSUPPORTED;
    default: return GETME_IO_ERR_INTERNAL;
    }
}

/* Gmsh picks the writer from the extension: the temporary file keeps it. */
static int write_output(const gmsh_args *a, const char *out)
{
    char tmp[4096], tmp_ext[4200];
    const char *dot = strrchr(out, '.'), *slash = strrchr(out, '/');
    const char *ext = dot && (!slash || dot > slash) ? dot : ".msh";
    if (getme_io_tmp_path(out, tmp, sizeof tmp) != 0) {
        cli_error("cannot create a temporary file next to '%s'", out);
        return GETME_IO_ERR_WRITE;
    }
    snprintf(tmp_ext, sizeof tmp_ext, "%s%s", tmp, ext);
    remove(tmp);
    set_number("Mesh.MshFileVersion", a->msh_version);
    set_number("Mesh.Binary", a->binary);
    int ierr = 0;
    gmshWrite(tmp_ext, &ierr);
    FILE *f = ierr ? NULL : fopen(tmp_ext, "rb");
    if (f)
        fclose(f);
    if (!f || getme_io_commit(tmp_ext, out) != 0) {
        remove(tmp_ext);
        cli_error("cannot write '%s'", out);
        return GETME_IO_ERR_WRITE;
    }
    return 0;
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
    if (getme_io_same_file(a->input, out)) {
        cli_error("the output '%s' is the input: getme never overwrites its "
                  "input",
                  out);
        return GETME_IO_ERR_USAGE;
    }
    int ierr = 0;
    gmshInitialize(0, NULL, 0, &ierr);
    set_number("General.Terminal", a->quiet ? 0 : 1);
    getme_gmsh_options_set(a->opt, "log", a->quiet ? 0 : 2);
    int rc = open_and_mesh(a);
    if (rc == 0) {
        getme_gmsh_report rep;
        getme_status st = getme_gmsh_optimize(0, NULL, 0, a->opt, &rep);
        if (st != GETME_OK && a->quiet)
            cli_error("%s", rep.message);
        rc = exit_code(st, &rep);
    }
    if (rc == 0 || (rc == GETME_IO_ERR_TANGLED && a->allow_invalid)) {
        int wrc = write_output(a, out);
        rc = rc ? rc : wrc;
    }
    if (rc == 0 && !a->quiet) {
        char line[4200];
        snprintf(line, sizeof line, "Wrote '%s'", out);
        gmshLoggerWrite(line, "info", &ierr);
    }
    gmshFinalize(&ierr);
    return rc;
}

int getme_cli_gmsh(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            fputs(GMSH_HELP, stdout);
            return 0;
        }
    gmsh_args a;
    memset(&a, 0, sizeof a);
    a.msh_version = 4.1;
    a.opt = getme_gmsh_options_new();
    if (!a.opt) {
        cli_error("out of memory");
        return GETME_IO_ERR_INTERNAL;
    }
    int rc = parse_args(&a, argc, argv) != 0 ? GETME_IO_ERR_USAGE : run(&a);
    getme_gmsh_options_free(a.opt);
    return rc;
}
