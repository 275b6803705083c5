/*
 * msh_format.c -- the Gmsh MSH adapter (MSH 2.2 / 4.x, ASCII or binary).
 *
 * Two readers:
 *  - MSH 4.1 and 2.2 (ASCII or binary) are read natively by
 *    msh41_reader.c in one streaming pass, without a Gmsh model (a Gmsh
 *    model of a 4M-tet mesh costs about 1 GiB), and written by
 *    msh41_writer.c as a copy of the input with new coordinates in $Nodes.
 *    Fixed nodes, regions and element order are those the Gmsh path gives
 *    for the same file.
 *  - Everything else (MSH 4.0, and the files the native reader declines:
 *    parametric nodes, partitioned meshes, planar meshes outside a plane
 *    z = const, element types it does not know...) goes through Gmsh's own
 *    reader via the C API and libgetme_gmsh's model extraction, after
 *    check_msh_file refused what Gmsh's reader would accept damaged.
 * The environment variable GETME_MSH_READER=gmsh forces the Gmsh path,
 * GETME_MSH_READER=native forces the native one (a file it declines is then
 * an error); anything else, or unset, means "native if it can".  A
 * document is written by the path that opened it.
 *
 * Gmsh path: Gmsh is process-global: the adapter initializes it once if
 * nobody did (with General.Terminal = 0: adapters never print), opens each
 * document as its own Gmsh model, and removes that model on close, so
 * several documents can be opened one after the other in one process.
 * Options it changes (Terminal, MshFileVersion, Binary, SaveAll) are
 * restored after each call.
 *
 * Gmsh path writing keeps the input's MSH version and ASCII/binary flavour,
 * its node and element tags and its physical groups; only coordinates of
 * moved nodes differ.  MSH 4.x goes through Gmsh's writer (gmshWrite); when
 * the input has physical groups but also elements outside of them,
 * Mesh.SaveAll is set so that no element is dropped.  MSH 2.2 is written by
 * copying the input with new coordinates in $Nodes (see patch_msh2: Gmsh's
 * MSH 2 writer would renumber the nodes).
 */
#define _POSIX_C_SOURCE 200809L /* getline */
#include "getme_formats.h"
#include "getme_gmsh.h"
#include "msh41_internal.h"

#include <gmshc.h>

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct msh_impl {
    msh41_doc *native;   /* set when the native MSH 4.1 reader opened it */
    getme_gmsh_model *model;
    char model_name[256];
    double version;      /* 2.2, 4.1 ... as in $MeshFormat */
    int binary;
    int save_all;
} msh_impl;

typedef struct saved_options {
    double terminal, version, binary, save_all;
} saved_options;

static int msh_initialized(void)
{
    double v = -12345.0;
    int ierr = 0;
    gmshOptionGetNumber("General.Terminal", &v, &ierr);
    return ierr == 0 && v != -12345.0;
}

static double get_number(const char *name)
{
    double v = 0;
    int ierr = 0;
    gmshOptionGetNumber(name, &v, &ierr);
    return v;
}

static void set_number(const char *name, double v)
{
    int ierr = 0;
    gmshOptionSetNumber(name, v, &ierr);
}

/* Initialize Gmsh if needed and silence it for the duration of a call. */
static void quiet_begin(saved_options *s)
{
    if (!msh_initialized()) {
        int ierr = 0;
        gmshInitialize(0, NULL, 0, &ierr);
        set_number("General.Terminal", 0);
    }
    s->terminal = get_number("General.Terminal");
    s->version = get_number("Mesh.MshFileVersion");
    s->binary = get_number("Mesh.Binary");
    s->save_all = get_number("Mesh.SaveAll");
    set_number("General.Terminal", 0);
}

static void quiet_end(const saved_options *s)
{
    set_number("Mesh.MshFileVersion", s->version);
    set_number("Mesh.Binary", s->binary);
    set_number("Mesh.SaveAll", s->save_all);
    set_number("General.Terminal", s->terminal);
}

static int has_msh_extension(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && tolower((unsigned char)path[n - 4]) == '.' &&
           tolower((unsigned char)path[n - 3]) == 'm' &&
           tolower((unsigned char)path[n - 2]) == 's' &&
           tolower((unsigned char)path[n - 1]) == 'h';
}

static int msh_probe(const char *path)
{
    if (has_msh_extension(path))
        return 1;
    FILE *f = fopen(path, "rb");
    char line[16] = "";
    if (!f)
        return 0;
    int ok = fgets(line, sizeof line, f) && !strncmp(line, "$MeshFormat", 11);
    fclose(f);
    return ok;
}

/* "$MeshFormat" then "version file-type data-size". */
static getme_io_status read_header(getme_doc *doc, msh_impl *impl)
{
    FILE *f = fopen(doc->path, "rb");
    if (!f)
        return getme_doc_fail(doc, GETME_IO_ERR_OPEN, "Cannot open '%s': %s",
                              doc->path, strerror(errno));
    char line[128] = "";
    int binary = 0, ok = fgets(line, sizeof line, f) &&
                         !strncmp(line, "$MeshFormat", 11) &&
                         fgets(line, sizeof line, f) &&
                         sscanf(line, "%lf %d", &impl->version, &binary) == 2;
    fclose(f);
    if (!ok)
        return getme_doc_fail(doc, GETME_IO_ERR_PARSE,
                              "'%s', line 1: not a Gmsh MSH file (no "
                              "$MeshFormat header)",
                              doc->path);
    impl->binary = binary != 0;
    if (impl->version != 2.2 && impl->version != 4.0 && impl->version != 4.1)
        return getme_doc_fail(doc, GETME_IO_ERR_UNSUPPORTED,
                              "'%s': MSH version %g is not supported (2.2, "
                              "4.0 and 4.1 are)",
                              doc->path, impl->version);
    return GETME_IO_OK;
}

/* ---- files Gmsh's readers would take although they are damaged ----------
 * Gmsh's MSH readers stop at the end of the file without complaint, so a
 * truncated file is read as if it were whole (its last element wrong).
 * Before Gmsh reads a file it is checked here:
 *  - MSH 2.2 ASCII, line by line: every section is closed by its $End line,
 *    $Nodes and $Elements hold the number of lines they declare, node lines
 *    have 4 numbers with finite coordinates, element lines as many fields as
 *    their type needs (tag, type, number of tags, tags, nodes);
 *  - every other file (binary, MSH 4.0/4.1 given to Gmsh): its last line
 *    is a closing "$End..." line.
 * Errors name the file and the line (binary: the byte).
 */
typedef struct scan {
    getme_doc *doc;
    FILE *f;
    char *line;
    size_t cap;
    long lineno;
} scan;

static int scan_line(scan *s)
{
    ssize_t n = getline(&s->line, &s->cap, s->f);
    if (n < 0)
        return -1;
    while (n > 0 && (s->line[n - 1] == '\n' || s->line[n - 1] == '\r'))
        s->line[--n] = 0;
    s->lineno++;
    return 0;
}

static getme_io_status scan_fail(scan *s, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static getme_io_status scan_fail(scan *s, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return getme_doc_fail(s->doc, GETME_IO_ERR_PARSE, "'%s', line %ld: %s",
                          s->doc->path, s->lineno, msg);
}

static getme_io_status scan_eof(scan *s, const char *section)
{
    return getme_doc_fail(s->doc, GETME_IO_ERR_PARSE,
                          "'%s', line %ld: the file ends inside $%s (no "
                          "$End%s): truncated or damaged",
                          s->doc->path, s->lineno, section, section);
}

/* Whitespace-separated fields of s->line as numbers, up to max. */
static int fields(const char *line, double *v, int max, int *bad)
{
    int n = 0;
    *bad = 0;
    for (const char *p = line;;) {
        while (*p == ' ' || *p == '\t')
            p++;
        if (!*p)
            return n;
        char *end;
        double x = strtod(p, &end);
        if (end == p || (*end && *end != ' ' && *end != '\t')) {
            *bad = 1;
            return n;
        }
        if (n < max)
            v[n] = x;
        n++;
        p = end;
    }
}

static getme_io_status scan_count(scan *s, const char *section, long *count)
{
    char *end;
    if (scan_line(s) != 0)
        return scan_eof(s, section);
    *count = strtol(s->line, &end, 10);
    while (*end == ' ' || *end == '\t')
        end++;
    if (end == s->line || *end || *count < 0)
        return scan_fail(s, "bad number of entries '%s' in $%s", s->line,
                         section);
    return GETME_IO_OK;
}

/* Entry i of the n that $section declares: its line in s->line. */
static getme_io_status scan_entry(scan *s, const char *section, long n)
{
    if (scan_line(s) != 0)
        return scan_eof(s, section);
    if (s->line[0] == '$')
        return scan_fail(s, "$%s declares %ld entries, it has fewer",
                         section, n);
    return GETME_IO_OK;
}

/* The lines of $Nodes ("tag x y z") or $Elements ("tag type ntags tags...
   nodes..."). */
static getme_io_status scan_entries(scan *s, int nodes)
{
    const char *section = nodes ? "Nodes" : "Elements";
    long n = 0;
    getme_io_status st = scan_count(s, section, &n);
    for (long i = 0; st == GETME_IO_OK && i < n; i++) {
        double v[64];
        int bad;
        if ((st = scan_entry(s, section, n)) != GETME_IO_OK)
            return st;
        int nf = fields(s->line, v, 64, &bad);
        if (nodes && (nf != 4 || bad))
            return scan_fail(s, "bad node line '%s' (want: tag x y z)",
                             s->line);
        if (nodes && (!isfinite(v[1]) || !isfinite(v[2]) || !isfinite(v[3])))
            return scan_fail(s, "node %ld has a coordinate that is not a "
                                "finite number", (long)v[0]);
        int nv = !nodes && nf >= 3 ? msh41_type_nodes((int)v[1], NULL) : 0;
        if (!nodes && (bad || nf < 3 || v[2] < 0 ||
                       (nv > 0 && nf != 3 + (int)v[2] + nv)))
            return scan_fail(s, "bad element line '%s' (want: tag type "
                                "number-of-tags tags... nodes...)",
                             s->line);
    }
    return st;
}

/* The last line of the file (after trailing blanks) starts with "$End". */
static getme_io_status check_last_line(getme_doc *doc, FILE *f, int binary)
{
    char tail[256];
    if (fseek(f, 0, SEEK_END) != 0)
        return GETME_IO_OK;
    long size = ftell(f);
    long from = size > (long)sizeof tail - 1 ? size - (long)sizeof tail + 1 : 0;
    fseek(f, from, SEEK_SET);
    size_t n = fread(tail, 1, (size_t)(size - from), f);
    tail[n] = 0;
    while (n > 0 && (tail[n - 1] == '\n' || tail[n - 1] == '\r' ||
                     tail[n - 1] == ' ' || tail[n - 1] == '\t'))
        tail[--n] = 0;
    size_t start = n;
    while (start > 0 && tail[start - 1] != '\n')
        start--;
    if (n > 0 && strncmp(tail + start, "$End", 4) == 0)
        return GETME_IO_OK;
    if (binary)
        return getme_doc_fail(doc, GETME_IO_ERR_PARSE,
                              "'%s': the file ends at byte %ld without a "
                              "closing $End line: truncated or damaged",
                              doc->path, size);
    long lines = 1;
    int c;
    rewind(f);
    while ((c = getc(f)) != EOF)
        lines += c == '\n';
    return getme_doc_fail(doc, GETME_IO_ERR_PARSE,
                          "'%s', line %ld: the file ends without a closing "
                          "$End line: truncated or damaged",
                          doc->path, lines - (size > 0 && tail[0] == 0));
}

static getme_io_status check_msh_file(getme_doc *doc, const msh_impl *impl)
{
    scan s = {doc, fopen(doc->path, "rb"), NULL, 0, 0};
    if (!s.f)
        return getme_doc_fail(doc, GETME_IO_ERR_OPEN, "Cannot open '%s': %s",
                              doc->path, strerror(errno));
    getme_io_status st = GETME_IO_OK;
    if (impl->binary || impl->version != 2.2) {
        st = check_last_line(doc, s.f, impl->binary);
        fclose(s.f);
        return st;
    }
    char section[64] = "";
    while (st == GETME_IO_OK && scan_line(&s) == 0) {
        if (s.line[0] != '$')
            continue; /* Gmsh ignores anything between sections */
        snprintf(section, sizeof section, "%s", s.line + 1);
        if (strncmp(section, "End", 3) == 0) {
            st = scan_fail(&s, "%s without its section", s.line);
            break;
        }
        if (strcmp(section, "Nodes") == 0 || strcmp(section, "Elements") == 0)
            st = scan_entries(&s, section[0] == 'N');
        /* up to the closing line */
        while (st == GETME_IO_OK) {
            if (scan_line(&s) != 0) {
                st = scan_eof(&s, section);
                break;
            }
            if (s.line[0] == '$' && strncmp(s.line + 1, "End", 3) == 0) {
                if (strcmp(s.line + 4, section) != 0)
                    st = scan_fail(&s, "%s closes $%s", s.line, section);
                break;
            }
            if (strcmp(section, "Nodes") == 0 ||
                strcmp(section, "Elements") == 0) {
                st = scan_fail(&s, "$%s holds more entries than it declares",
                               section);
                break;
            }
        }
    }
    free(s.line);
    fclose(s.f);
    return st;
}

/* Gmsh's model: every node coordinate finite (files the scan above did not
   read line by line). */
static getme_io_status check_model_coords(getme_doc *doc)
{
    size_t *tags = NULL, nt = 0, nc = 0, np = 0;
    double *xyz = NULL, *par = NULL;
    int ierr = 0;
    gmshModelMeshGetNodes(&tags, &nt, &xyz, &nc, &par, &np, -1, -1, 0, 0,
                          &ierr);
    getme_io_status st = GETME_IO_OK;
    for (size_t i = 0; i < nt && 3 * i + 2 < nc && st == GETME_IO_OK; i++)
        if (!isfinite(xyz[3 * i]) || !isfinite(xyz[3 * i + 1]) ||
            !isfinite(xyz[3 * i + 2]))
            st = getme_doc_fail(doc, GETME_IO_ERR_PARSE,
                                "'%s': node %zu has a coordinate that is not "
                                "a finite number",
                                doc->path, tags[i]);
    gmshFree(tags);
    gmshFree(xyz);
    gmshFree(par);
    return st;
}

/* --free names must name physical groups ("name" or "dim:tag"), as --fix
   names must (no group is fixed by default: nothing else happens). */
static getme_io_status check_free_names(getme_doc *doc,
                                        const getme_doc_options *opts)
{
    char msg[512];
    if (!opts || opts->num_free == 0 ||
        getme_gmsh_check_groups(opts->free_sets, opts->num_free, "free", msg,
                                sizeof msg) == GETME_OK)
        return GETME_IO_OK;
    return getme_doc_fail(doc, GETME_IO_ERR_USAGE, "'%s': %s", doc->path, msg);
}

static int model_exists(const char *name)
{
    char **names = NULL;
    size_t n = 0;
    int ierr = 0, found = 0;
    gmshModelList(&names, &n, &ierr);
    for (size_t i = 0; i < n; i++) {
        found += strcmp(names[i], name) == 0;
        gmshFree(names[i]);
    }
    gmshFree(names);
    return found;
}

static void current_model(char *buf, size_t size)
{
    char *name = NULL;
    int ierr = 0;
    gmshModelGetCurrent(&name, &ierr);
    snprintf(buf, size, "%s", name ? name : "");
    gmshFree(name);
}

/* Elements outside every physical group would be dropped by Gmsh's writer
   (Mesh.SaveAll = 0) as soon as the model has physical groups. */
static int needs_save_all(void)
{
    int *groups = NULL, ierr = 0, *ents = NULL, need = 0;
    size_t ng = 0, ne = 0;
    gmshModelGetPhysicalGroups(&groups, &ng, -1, &ierr);
    gmshFree(groups);
    if (ng == 0)
        return 0;
    gmshModelGetEntities(&ents, &ne, -1, &ierr);
    for (size_t i = 0; i + 1 < ne && !need; i += 2) {
        int *types = NULL, *phys = NULL;
        size_t nt = 0, np = 0;
        gmshModelMeshGetElementTypes(&types, &nt, ents[i], ents[i + 1], &ierr);
        gmshModelGetPhysicalGroupsForEntity(ents[i], ents[i + 1], &phys, &np,
                                            &ierr);
        need = nt > 0 && np == 0;
        gmshFree(types);
        gmshFree(phys);
    }
    gmshFree(ents);
    return need;
}

static getme_io_status io_status(getme_status st)
{
    switch (st) {
    case GETME_ERR_ARGUMENT: return GETME_IO_ERR_USAGE;
    case GETME_ERR_TOPOLOGY: return GETME_IO_ERR_UNSUPPORTED;
    case GETME_ERR_STATE: return GETME_IO_ERR_UNSUPPORTED;
    case GETME_ERR_INVALID_MESH: return GETME_IO_ERR_INVALID;
    default: return GETME_IO_ERR_INTERNAL;
    }
}

static getme_gmsh_options *make_options(const getme_doc_options *o)
{
    getme_gmsh_options *g = getme_gmsh_options_new();
    if (!g)
        return NULL;
    getme_gmsh_options_set(g, "log", 0);
    getme_gmsh_options_set(g, "fix_skin", o && !o->fix_skin ? 0 : 1);
    getme_gmsh_options_set(g, "fix_interfaces",
                           o && !o->fix_interfaces ? 0 : 1);
    for (int i = 0; o && i < o->num_fix; i++)
        getme_gmsh_options_add_fixed_group(g, o->fix[i]);
    return g;
}

static getme_io_status extract(getme_doc *doc, msh_impl *impl,
                               const getme_doc_options *opts)
{
    getme_gmsh_options *g = make_options(opts);
    char msg[512] = "";
    if (!g)
        return getme_doc_fail(doc, GETME_IO_ERR_INTERNAL, "Out of memory");
    getme_status st = getme_gmsh_model_read(&impl->model, NULL, 0, g, msg,
                                            sizeof msg);
    getme_gmsh_options_free(g);
    if (st != GETME_OK)
        return getme_doc_fail(doc, io_status(st), "'%s': %s", doc->path, msg);
    int32_t ne = getme_gmsh_model_num_elements(impl->model);
    doc->elem_ids = malloc((ne ? (size_t)ne : 1) * sizeof *doc->elem_ids);
    if (!doc->elem_ids)
        return getme_doc_fail(doc, GETME_IO_ERR_INTERNAL, "Out of memory");
    const size_t *tags = getme_gmsh_model_element_tags(impl->model);
    for (int32_t e = 0; e < ne; e++)
        doc->elem_ids[e] = (int64_t)tags[e];
    doc->mesh = getme_gmsh_model_take_mesh(impl->model);
    return GETME_IO_OK;
}

static void describe(getme_doc *doc, const msh_impl *impl)
{
    int n = getme_gmsh_model_num_entities(impl->model);
    int dim = getme_gmsh_model_dim(impl->model);
    snprintf(doc->info, sizeof doc->info,
             "MSH %.1f %s, model '%s': %d %s%s, %ld elements, %ld nodes "
             "(%ld fixed)",
             impl->version, impl->binary ? "binary" : "ASCII",
             impl->model_name, n, dim == 3 ? "volume" : "surface",
             n > 1 ? "s" : "", (long)getme_mesh_num_elements(doc->mesh),
             (long)getme_mesh_num_nodes(doc->mesh),
             (long)getme_mesh_num_fixed(doc->mesh));
}

static getme_io_status open_model(getme_doc *doc, msh_impl *impl)
{
    int ierr = 0;
    gmshOpen(doc->path, &ierr);
    if (ierr) {
        char *err = NULL;
        gmshLoggerGetLastError(&err, &ierr);
        getme_io_status st = getme_doc_fail(
            doc, GETME_IO_ERR_PARSE, "'%s': %s", doc->path,
            err && *err ? err : "Gmsh could not read the file");
        gmshFree(err);
        return st;
    }
    current_model(impl->model_name, sizeof impl->model_name);
    if (model_exists(impl->model_name) > 1)
        return getme_doc_fail(doc, GETME_IO_ERR_USAGE,
                              "'%s': another open document already uses the "
                              "Gmsh model name '%s'",
                              doc->path, impl->model_name);
    return GETME_IO_OK;
}

/* GETME_MSH_READER: 'g' = gmsh only, 'n' = native only, 0 = native if it
   can, else Gmsh. */
static char reader_choice(void)
{
    const char *v = getenv("GETME_MSH_READER");
    if (v && strcmp(v, "gmsh") == 0)
        return 'g';
    if (v && strcmp(v, "native") == 0)
        return 'n';
    return 0;
}

/* The native reader; *done = 0 if it declined the file (doc untouched). */
static getme_io_status open_native(getme_doc *doc, msh_impl *impl,
                                   const getme_doc_options *opts, char choice,
                                   int *done)
{
    char why[160] = "";
    int eligible = 1;
    *done = 1;
    int native = impl->version == 4.1 || impl->version == 2.2;
    if (!native)
        snprintf(why, sizeof why, "MSH %g", impl->version);
    getme_io_status st =
        native
            ? msh41_open(doc, opts, &impl->native, &eligible, why, sizeof why)
            : GETME_IO_OK;
    if (native && eligible)
        return st;
    if (choice == 'n')
        return getme_doc_fail(doc, GETME_IO_ERR_UNSUPPORTED,
                              "'%s': the native MSH reader reads MSH 4.1 and "
                              "2.2 only, without %s (GETME_MSH_READER=native)",
                              doc->path, why);
    *done = 0;
    return GETME_IO_OK;
}

static getme_io_status msh_open(getme_doc *doc, const getme_doc_options *opts)
{
    msh_impl *impl = calloc(1, sizeof *impl);
    if (!impl)
        return getme_doc_fail(doc, GETME_IO_ERR_INTERNAL, "Out of memory");
    doc->impl = impl;
    getme_io_status st = read_header(doc, impl);
    if (st != GETME_IO_OK)
        return st;
    char choice = reader_choice();
    int done = 0;
    if (choice != 'g') {
        st = open_native(doc, impl, opts, choice, &done);
        if (done)
            return st;
    }
    st = check_msh_file(doc, impl);
    if (st != GETME_IO_OK)
        return st;
    saved_options saved;
    quiet_begin(&saved);
    st = open_model(doc, impl);
    if (st == GETME_IO_OK)
        st = check_model_coords(doc);
    if (st == GETME_IO_OK)
        st = check_free_names(doc, opts);
    if (st == GETME_IO_OK) {
        impl->save_all = needs_save_all();
        st = extract(doc, impl, opts);
    }
    if (st == GETME_IO_OK)
        describe(doc, impl);
    quiet_end(&saved);
    return st;
}

/* ---- MSH 2.2: patch the input's $Nodes section -------------------------
 * Gmsh 4.8's MSH 2 writer renumbers nodes in its own entity order, which
 * would change node tags of a file that Gmsh did not write in that order.
 * For MSH 2.2 we therefore copy the input and rewrite only the coordinates
 * of the nodes in $Nodes (ASCII lines "tag x y z", or binary records
 * int tag + 3 doubles), taking them from the updated Gmsh model.
 */
typedef struct node_table {
    size_t *tags;  /* gmsh-allocated */
    double *xyz;
    size_t n;
    size_t *order; /* indices sorted by tag */
} node_table;

static const size_t *sort_tags_base;

static int cmp_by_tag(const void *a, const void *b)
{
    size_t x = sort_tags_base[*(const size_t *)a];
    size_t y = sort_tags_base[*(const size_t *)b];
    return x < y ? -1 : x > y;
}

static int load_nodes(node_table *t)
{
    double *p = NULL;
    size_t nc = 0, np = 0;
    int ierr = 0;
    memset(t, 0, sizeof *t);
    gmshModelMeshGetNodes(&t->tags, &t->n, &t->xyz, &nc, &p, &np, -1, -1, 0,
                          0, &ierr);
    gmshFree(p);
    t->order = malloc((t->n ? t->n : 1) * sizeof *t->order);
    if (ierr || !t->order)
        return -1;
    for (size_t i = 0; i < t->n; i++)
        t->order[i] = i;
    sort_tags_base = t->tags; /* qsort has no context argument in C11 */
    qsort(t->order, t->n, sizeof *t->order, cmp_by_tag);
    return 0;
}

static void free_nodes(node_table *t)
{
    gmshFree(t->tags);
    gmshFree(t->xyz);
    free(t->order);
}

static const double *find_node(const node_table *t, size_t tag)
{
    size_t lo = 0, hi = t->n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (t->tags[t->order[mid]] < tag)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < t->n && t->tags[t->order[lo]] == tag
               ? t->xyz + 3 * t->order[lo]
               : NULL;
}

/* Copy one line byte by byte (binary files hold NULs before newlines, as
   the int 1 after a binary $MeshFormat line); keep its start in buf. */
static int copy_line(FILE *in, FILE *out, char *buf, size_t size)
{
    size_t n = 0;
    int c;
    while ((c = getc(in)) != EOF) {
        if (n + 1 < size)
            buf[n++] = (char)c;
        if (putc(c, out) == EOF)
            return -1;
        if (c == '\n')
            break;
    }
    buf[n] = 0;
    return c == EOF && n == 0 ? -1 : 0;
}

static int patch_ascii_nodes(FILE *in, FILE *out, const node_table *t,
                             long count)
{
    char line[512];
    for (long i = 0; i < count; i++) {
        if (!fgets(line, sizeof line, in))
            return -1;
        unsigned long long tag = strtoull(line, NULL, 10);
        const double *x = find_node(t, (size_t)tag);
        if (x)
            fprintf(out, "%llu %.17g %.17g %.17g\n", tag, x[0], x[1], x[2]);
        else
            fputs(line, out);
    }
    return 0;
}

static int patch_binary_nodes(FILE *in, FILE *out, const node_table *t,
                              long count)
{
    for (long i = 0; i < count; i++) {
        int32_t tag;
        double xyz[3];
        if (fread(&tag, sizeof tag, 1, in) != 1 ||
            fread(xyz, sizeof xyz, 1, in) != 1)
            return -1;
        const double *x = tag > 0 ? find_node(t, (size_t)tag) : NULL;
        if (fwrite(&tag, sizeof tag, 1, out) != 1 ||
            fwrite(x ? x : xyz, sizeof xyz, 1, out) != 1)
            return -1;
    }
    return 0;
}

static int patch_msh2(const char *in_path, const char *out_path, int binary)
{
    node_table t;
    FILE *in = fopen(in_path, "rb"), *out = fopen(out_path, "wb");
    int rc = in && out && load_nodes(&t) == 0 ? 0 : -1;
    char line[512];
    while (rc == 0 && (rc = copy_line(in, out, line, sizeof line)) == 0)
        if (strncmp(line, "$Nodes", 6) == 0)
            break;
    long count = 0;
    if (rc == 0)
        rc = copy_line(in, out, line, sizeof line) == 0 &&
                     sscanf(line, "%ld", &count) == 1
                 ? 0
                 : -1;
    if (rc == 0)
        rc = binary ? patch_binary_nodes(in, out, &t, count)
                    : patch_ascii_nodes(in, out, &t, count);
    size_t n;
    while (rc == 0 && (n = fread(line, 1, sizeof line, in)) > 0)
        rc = fwrite(line, 1, n, out) == n ? 0 : -1;
    if (in && out)
        free_nodes(&t);
    if (in)
        fclose(in);
    if (out && fclose(out) != 0)
        rc = -1;
    return rc;
}

static getme_io_status write_model(getme_doc *doc, msh_impl *impl,
                                   const char *out_path)
{
    char msg[512] = "", tmp[4096], tmp_msh[4200];
    int ierr = 0;
    gmshModelSetCurrent(impl->model_name, &ierr);
    getme_status gs = getme_gmsh_model_apply(
        impl->model, getme_mesh_coords(doc->mesh), NULL, msg, sizeof msg);
    if (gs != GETME_OK)
        return getme_doc_fail(doc, GETME_IO_ERR_INTERNAL, "%s", msg);
    if (getme_io_tmp_path(out_path, tmp, sizeof tmp) != 0)
        return getme_doc_fail(doc, GETME_IO_ERR_WRITE,
                              "Cannot create a temporary file next to '%s'",
                              out_path);
    /* Gmsh picks the format from the extension: write "<tmp>.msh". */
    snprintf(tmp_msh, sizeof tmp_msh, "%s.msh", tmp);
    remove(tmp);
    set_number("Mesh.MshFileVersion", impl->version);
    set_number("Mesh.Binary", impl->binary);
    set_number("Mesh.SaveAll", impl->save_all);
    if (impl->version < 3)
        ierr = patch_msh2(doc->path, tmp_msh, impl->binary) != 0;
    else
        gmshWrite(tmp_msh, &ierr);
    FILE *check = ierr ? NULL : fopen(tmp_msh, "rb");
    if (check)
        fclose(check);
    if (!check || getme_io_commit(tmp_msh, out_path) != 0) {
        int err = errno;
        remove(tmp_msh);
        return getme_doc_fail(doc, GETME_IO_ERR_WRITE, "Cannot write '%s': %s",
                              out_path, check ? strerror(err)
                                              : "Gmsh's writer failed");
    }
    return GETME_IO_OK;
}

static getme_io_status msh_write(getme_doc *doc, const char *out_path)
{
    msh_impl *impl = doc->impl;
    if (impl && impl->native && doc->mesh)
        return msh41_write(doc, impl->native, out_path);
    if (!impl || !impl->model || !doc->mesh)
        return getme_doc_fail(doc, GETME_IO_ERR_INTERNAL,
                              "MSH document is not open");
    saved_options saved;
    char previous[256];
    quiet_begin(&saved);
    current_model(previous, sizeof previous);
    getme_io_status st = write_model(doc, impl, out_path);
    int ierr = 0;
    if (model_exists(previous))
        gmshModelSetCurrent(previous, &ierr);
    quiet_end(&saved);
    return st;
}

static void msh_close(getme_doc *doc)
{
    msh_impl *impl = doc->impl;
    if (!impl)
        return;
    if (impl->model_name[0] && msh_initialized() &&
        model_exists(impl->model_name) == 1) {
        int ierr = 0;
        gmshModelSetCurrent(impl->model_name, &ierr);
        gmshModelRemove(&ierr);
    }
    getme_gmsh_model_free(impl->model);
    msh41_free(impl->native);
    free(impl);
    doc->impl = NULL;
}

const getme_format getme_format_msh = {
    "msh",
    "Gmsh MSH 2.2/4.1, ASCII or binary (2.2 and 4.1 read natively, others via the "
    "Gmsh SDK)",
    msh_probe,
    msh_open, msh_write, msh_close, ".msh", NULL};
