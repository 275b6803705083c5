/*
 * gmsh_format.c -- MSH files through the Gmsh SDK: the adapter this plugin
 * provides to libgetme_formats (getme_gmsh_format(); the getme command
 * passes it in getme_doc_options.adapters).  It reads the files the native
 * MSH reader declines -- MSH 4.0, parametric nodes, partitioned meshes,
 * planar meshes outside a plane z = const, element types the native reader
 * does not know -- and every MSH file with GETME_MSH_READER=gmsh.
 *
 * Before Gmsh reads a file, check_msh_file refuses what Gmsh's reader would
 * accept damaged.  The model goes through the same model builder as a file
 * read natively (getme_gmsh_model_read -> formats/model).
 *
 * Gmsh is process-global: the adapter initializes it once if nobody did
 * (with General.Terminal = 0: adapters never print), opens each document as
 * its own Gmsh model, and removes that model on close, so several documents
 * can be opened one after the other in one process.  Options it changes
 * (Terminal, MshFileVersion, Binary, SaveAll) are restored after each call.
 *
 * Writing keeps the input's MSH version and ASCII/binary flavour, its node
 * and element tags and its physical groups; only coordinates of moved nodes
 * differ.  MSH 4.1 and 2.2 are the input copied with new coordinates in
 * $Nodes (patch_file), as is MSH 4.0 ASCII; binary MSH 4.0 goes through
 * Gmsh's writer (gmshWrite); when the input has physical groups but also elements
 * outside of them, Mesh.SaveAll is set so that no element is dropped.
 *
 * Split partition files (Mesh.PartitionSplitMeshFiles=1: NAME_1.msh ..
 * NAME_N.msh): opening NAME_1.msh of a partitioned model merges NAME_2.msh,
 * NAME_3.msh ... while they exist, so the document is the whole mesh
 * (Gmsh joins the parts by node tag; partition boundaries are not fixed,
 * gmsh_fixed.c).  Writing it to OUT.msh writes OUT_1.msh .. OUT_N.msh the
 * same way (each through a temporary file + rename), never OUT.msh itself.  MSH 2.2 is written by copying the
 * input with new coordinates in $Nodes (see msh2_nodes: Gmsh's MSH 2 writer
 * would renumber the nodes).
 */
#define _POSIX_C_SOURCE 200809L /* getline */
#include "getme_formats_adapter.h"
#include "gmsh_internal.h"

#include <gmshc.h>

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

typedef getme_formats_status fstatus;

typedef struct msh_impl {
    getme_gmsh_model *model;
    char model_name[256];
    double version;      /* 2.2, 4.1 ... as in $MeshFormat */
    int binary;
    int save_all;
    int split_parts;     /* > 0: read from this many split files NAME_K.msh */
} msh_impl;

typedef struct saved_options {
    double terminal, version, binary, save_all, split;
} saved_options;

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
    if (!gg_gmsh_initialized()) {
        int ierr = 0;
        gmshInitialize(0, NULL, 0, &ierr);
        set_number("General.Terminal", 0);
    }
    s->terminal = get_number("General.Terminal");
    s->version = get_number("Mesh.MshFileVersion");
    s->binary = get_number("Mesh.Binary");
    s->save_all = get_number("Mesh.SaveAll");
    s->split = get_number("Mesh.PartitionSplitMeshFiles");
    set_number("General.Terminal", 0);
}

static void quiet_end(const saved_options *s)
{
    set_number("Mesh.MshFileVersion", s->version);
    set_number("Mesh.Binary", s->binary);
    set_number("Mesh.SaveAll", s->save_all);
    set_number("Mesh.PartitionSplitMeshFiles", s->split);
    set_number("General.Terminal", s->terminal);
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

static fstatus scan_fail(scan *s, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static fstatus scan_fail(scan *s, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return getme_doc_fail(s->doc, GETME_FORMATS_ERR_PARSE, "'%s', line %ld: %s",
                          getme_doc_path(s->doc), s->lineno, msg);
}

static fstatus scan_eof(scan *s, const char *section)
{
    return getme_doc_fail(s->doc, GETME_FORMATS_ERR_PARSE,
                          "'%s', line %ld: the file ends inside $%s (no "
                          "$End%s): truncated or damaged",
                          getme_doc_path(s->doc), s->lineno, section, section);
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

static fstatus scan_count(scan *s, const char *section, long *count)
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
    return GETME_FORMATS_OK;
}

/* Entry i of the n that $section declares: its line in s->line. */
static fstatus scan_entry(scan *s, const char *section, long n)
{
    if (scan_line(s) != 0)
        return scan_eof(s, section);
    if (s->line[0] == '$')
        return scan_fail(s, "$%s declares %ld entries, it has fewer",
                         section, n);
    return GETME_FORMATS_OK;
}

/* The lines of $Nodes ("tag x y z") or $Elements ("tag type ntags tags...
   nodes..."). */
static fstatus scan_entries(scan *s, int nodes)
{
    const char *section = nodes ? "Nodes" : "Elements";
    long n = 0;
    fstatus st = scan_count(s, section, &n);
    for (long i = 0; st == GETME_FORMATS_OK && i < n; i++) {
        double v[64];
        int bad;
        if ((st = scan_entry(s, section, n)) != GETME_FORMATS_OK)
            return st;
        int nf = fields(s->line, v, 64, &bad);
        if (nodes && (nf != 4 || bad))
            return scan_fail(s, "bad node line '%s' (want: tag x y z)",
                             s->line);
        if (nodes && (!isfinite(v[1]) || !isfinite(v[2]) || !isfinite(v[3])))
            return scan_fail(s, "node %ld has a coordinate that is not a "
                                "finite number", (long)v[0]);
        int nv = !nodes && nf >= 3 ? getme__msh_type_nodes((int)v[1], NULL) : 0;
        if (!nodes && (bad || nf < 3 || v[2] < 0 ||
                       (nv > 0 && nf != 3 + (int)v[2] + nv)))
            return scan_fail(s, "bad element line '%s' (want: tag type "
                                "number-of-tags tags... nodes...)",
                             s->line);
    }
    return st;
}

/* The last line of the file (after trailing blanks) starts with "$End". */
static fstatus check_last_line(getme_doc *doc, FILE *f, int binary)
{
    char tail[256];
    if (fseek(f, 0, SEEK_END) != 0)
        return GETME_FORMATS_OK;
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
        return GETME_FORMATS_OK;
    if (binary)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "'%s': the file ends at byte %ld without a "
                              "closing $End line: truncated or damaged",
                              getme_doc_path(doc), size);
    long lines = 1;
    int c;
    rewind(f);
    while ((c = getc(f)) != EOF)
        lines += c == '\n';
    return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                          "'%s', line %ld: the file ends without a closing "
                          "$End line: truncated or damaged",
                          getme_doc_path(doc), lines - (size > 0 && tail[0] == 0));
}

static fstatus check_msh_file(getme_doc *doc, const msh_impl *impl)
{
    scan s = {doc, fopen(getme_doc_path(doc), "rb"), NULL, 0, 0};
    if (!s.f)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "Cannot open '%s': %s",
                              getme_doc_path(doc), strerror(errno));
    fstatus st = GETME_FORMATS_OK;
    if (impl->binary || impl->version != 2.2) {
        st = check_last_line(doc, s.f, impl->binary);
        fclose(s.f);
        return st;
    }
    char section[64] = "";
    while (st == GETME_FORMATS_OK && scan_line(&s) == 0) {
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
        while (st == GETME_FORMATS_OK) {
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
static fstatus check_model_coords(getme_doc *doc)
{
    size_t *tags = NULL, nt = 0, nc = 0, np = 0;
    double *xyz = NULL, *par = NULL;
    int ierr = 0;
    gmshModelMeshGetNodes(&tags, &nt, &xyz, &nc, &par, &np, -1, -1, 0, 0,
                          &ierr);
    fstatus st = GETME_FORMATS_OK;
    for (size_t i = 0; i < nt && 3 * i + 2 < nc && st == GETME_FORMATS_OK; i++)
        if (!isfinite(xyz[3 * i]) || !isfinite(xyz[3 * i + 1]) ||
            !isfinite(xyz[3 * i + 2]))
            st = getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                                "'%s': node %zu has a coordinate that is not "
                                "a finite number",
                                getme_doc_path(doc), tags[i]);
    gmshFree(tags);
    gmshFree(xyz);
    gmshFree(par);
    return st;
}

/* --free names must name physical groups ("name" or "dim:tag"), as --fix
   names must (no group is fixed by default: nothing else happens). */
static fstatus check_free_names(getme_doc *doc,
                                        const getme_doc_options *opts)
{
    char msg[512];
    if (!opts || opts->num_free == 0 ||
        getme_gmsh_check_groups(opts->free_sets, opts->num_free, "free", msg,
                                sizeof msg) == GETME_OK)
        return GETME_FORMATS_OK;
    return getme_doc_fail(doc, GETME_FORMATS_ERR_ARGUMENT, "'%s': %s", getme_doc_path(doc), msg);
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

static fstatus io_status(getme_status st)
{
    switch (st) {
    case GETME_ERR_ARGUMENT: return GETME_FORMATS_ERR_ARGUMENT;
    case GETME_ERR_TOPOLOGY: return GETME_FORMATS_ERR_UNSUPPORTED;
    case GETME_ERR_STATE: return GETME_FORMATS_ERR_UNSUPPORTED;
    case GETME_ERR_INVALID_MESH: return GETME_FORMATS_ERR_INVALID;
    default: return GETME_FORMATS_ERR_INTERNAL;
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

static fstatus extract(getme_doc *doc, msh_impl *impl,
                       const getme_doc_options *opts)
{
    getme_gmsh_options *g = make_options(opts);
    char msg[512] = "";
    if (!g)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "Out of memory");
    getme_status st = getme_gmsh_model_read(&impl->model, NULL, 0, g, msg,
                                            sizeof msg);
    getme_gmsh_options_free(g);
    if (st != GETME_OK)
        return getme_doc_fail(doc, io_status(st), "'%s': %s",
                              getme_doc_path(doc), msg);
    int32_t ne = impl->model->num_elements;
    int64_t *ids = malloc((ne ? (size_t)ne : 1) * sizeof *ids);
    if (!ids)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "Out of memory");
    for (int32_t e = 0; e < ne; e++)
        ids[e] = (int64_t)impl->model->elem_tags[e];
    getme_doc_set_mesh(doc, gg_model_take_mesh(impl->model), ids);
    return GETME_FORMATS_OK;
}

static void describe(getme_doc *doc, const msh_impl *impl)
{
    int n = impl->model->num_entities;
    int dim = impl->model->dim;
    getme_mesh *mesh = getme_doc_mesh(doc);
    getme_doc_set_info(doc,
                       "MSH %.1f %s, model '%s': %d %s%s, %ld elements, %ld "
                       "nodes (%ld fixed)",
                       impl->version, impl->binary ? "binary" : "ASCII",
                       impl->model_name, n, dim == 3 ? "volume" : "surface",
                       n > 1 ? "s" : "", (long)getme_mesh_num_elements(mesh),
                       (long)getme_mesh_num_nodes(mesh),
                       (long)getme_mesh_num_fixed(mesh));
}

/* ---- split partition files ------------------------------------------- */

/* The part of path before its "_1.msh" ending in stem (length returned),
   or -1 when path does not end so. */
static int split_stem(const char *path, char *stem, size_t size)
{
    size_t n = strlen(path);
    if (n < 6 || strcmp(path + n - 6, "_1.msh") != 0 || n - 6 + 1 > size)
        return -1;
    memcpy(stem, path, n - 6);
    stem[n - 6] = '\0';
    return (int)(n - 6);
}

/* Just opened NAME_1.msh of a partitioned model: merge NAME_2.msh,
   NAME_3.msh ... while they exist (impl->split_parts = how many files). */
static fstatus merge_split_parts(getme_doc *doc, msh_impl *impl)
{
    char stem[4096], part[4200];
    if (split_stem(getme_doc_path(doc), stem, sizeof stem) < 0 ||
        !gg_model_partitioned())
        return GETME_FORMATS_OK;
    int k = 2;
    for (;; k++) {
        snprintf(part, sizeof part, "%s_%d.msh", stem, k);
        FILE *f = fopen(part, "rb");
        if (!f)
            break;
        /* Gmsh's reader takes a truncated file as whole (check_msh_file) */
        double version = 0;
        int binary = 0;
        int bad = getme__msh_header(part, &version, &binary) != 0 ||
                  check_last_line(doc, f, binary) != GETME_FORMATS_OK;
        fclose(f);
        if (bad)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                                  "'%s': not a whole MSH file (no header or "
                                  "no closing $End line): truncated or "
                                  "damaged split partition file", part);
        int ierr = 0;
        gmshMerge(part, &ierr);
        if (ierr)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                                  "'%s': Gmsh could not read this split "
                                  "partition file", part);
    }
    impl->split_parts = k - 1;
    return GETME_FORMATS_OK;
}

static fstatus open_model(getme_doc *doc, msh_impl *impl)
{
    int ierr = 0;
    fstatus st0;
    gmshOpen(getme_doc_path(doc), &ierr);
    if (ierr) {
        char *err = NULL;
        gmshLoggerGetLastError(&err, &ierr);
        fstatus st = getme_doc_fail(
            doc, GETME_FORMATS_ERR_PARSE, "'%s': %s", getme_doc_path(doc),
            err && *err ? err : "Gmsh could not read the file");
        gmshFree(err);
        return st;
    }
    if ((st0 = merge_split_parts(doc, impl)) != GETME_FORMATS_OK)
        return st0;
    current_model(impl->model_name, sizeof impl->model_name);
    if (model_exists(impl->model_name) > 1)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_ARGUMENT,
                              "'%s': another open document already uses the "
                              "Gmsh model name '%s'",
                              getme_doc_path(doc), impl->model_name);
    return GETME_FORMATS_OK;
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
    getme__nodemap map; /* tag -> index */
} node_table;

static int load_nodes(node_table *t)
{
    double *p = NULL;
    size_t nc = 0, np = 0;
    int ierr = 0;
    uint64_t repeated;
    memset(t, 0, sizeof *t);
    gmshModelMeshGetNodes(&t->tags, &t->n, &t->xyz, &nc, &p, &np, -1, -1, 0,
                          0, &ierr);
    gmshFree(p);
    if (ierr)
        return -1;
    return getme__nodemap_build(&t->map, (const uint64_t *)t->tags, t->n,
                                &repeated) == GETME_OK
               ? 0
               : -1;
}

static void free_nodes(node_table *t)
{
    gmshFree(t->tags);
    gmshFree(t->xyz);
    getme__nodemap_free(&t->map);
}

static const double *find_node(const node_table *t, size_t tag)
{
    int32_t i = getme__nodemap_find(&t->map, tag);
    return i >= 0 ? t->xyz + 3 * (size_t)i : NULL;
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

/* "x y z" with the shortest of %.15g / %.16g / %.17g that reads back to
   each double (what the native writer prints, so both paths write the
   same bytes; %.17g always reads back). */
static int print_xyz(FILE *out, const double *x)
{
    for (int k = 0; k < 3; k++) {
        char buf[40];
        for (int digits = 15; digits <= 17; digits++) {
            snprintf(buf, sizeof buf, "%.*g", digits, x[k]);
            if (strtod(buf, NULL) == x[k])
                break;
        }
        if (fprintf(out, k ? " %s" : "%s", buf) < 0)
            return -1;
    }
    return 0;
}

static int patch_ascii_nodes(FILE *in, FILE *out, const node_table *t,
                             long count)
{
    char line[512];
    for (long i = 0; i < count; i++) {
        if (!fgets(line, sizeof line, in))
            return -1;
        char *p;
        unsigned long long tag = strtoull(line, &p, 10);
        double old[3];
        for (int k = 0; k < 3; k++)
            old[k] = strtod(p, &p);
        const double *x = find_node(t, (size_t)tag);
        if (x && memcmp(x, old, sizeof old) != 0) { /* moved: new text */
            if (fprintf(out, "%llu ", tag) < 0 || print_xyz(out, x) != 0 ||
                fputs(p, out) == EOF) /* p: the line's end, as it was */
                return -1;
        } else if (fputs(line, out) == EOF) {
            return -1;
        }
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

/* The copy of in_path to out_path with $Nodes' body rewritten by body()
   (after the "$Nodes" line); 0 or -1. */
typedef int (*nodes_body)(FILE *in, FILE *out, const node_table *t, int binary);

static int patch_file(const char *in_path, const char *out_path, int binary,
                      nodes_body body)
{
    node_table t;
    FILE *in = fopen(in_path, "rb"), *out = fopen(out_path, "wb");
    int rc = in && out && load_nodes(&t) == 0 ? 0 : -1;
    int loaded = rc == 0;
    char line[512];
    /* MSH 2.2 ASCII with Mesh.SaveParametric has "$ParametricNodes"
       instead, lines "tag x y z dim entity [u [v]]": the coordinates are
       patched the same way, the rest of each line kept */
    while (rc == 0 && (rc = copy_line(in, out, line, sizeof line)) == 0)
        if (strncmp(line, "$Nodes", 6) == 0 ||
            (!binary && strncmp(line, "$ParametricNodes", 16) == 0))
            break;
    if (rc == 0)
        rc = body(in, out, &t, binary);
    size_t n;
    while (rc == 0 && (n = fread(line, 1, sizeof line, in)) > 0)
        rc = fwrite(line, 1, n, out) == n ? 0 : -1;
    if (loaded)
        free_nodes(&t);
    if (in)
        fclose(in);
    if (out && fclose(out) != 0)
        rc = -1;
    return rc;
}

/* MSH 2.2: the node count line, then "tag x y z" lines or records. */
static int msh2_nodes(FILE *in, FILE *out, const node_table *t, int binary)
{
    char line[512];
    long count = 0;
    if (copy_line(in, out, line, sizeof line) != 0 ||
        sscanf(line, "%ld", &count) != 1)
        return -1;
    return binary ? patch_binary_nodes(in, out, t, count)
                  : patch_ascii_nodes(in, out, t, count);
}

/* ---- MSH 4.1: patched in place too --------------------------------------
 * Gmsh's MSH 4 writer re-serializes the model it read, and in a binary
 * file writes the entities' bounding boxes as zeros (Gmsh 4.8, found by
 * tests/conformance on a partitioned tutorial mesh, docs/conformance.md).
 * So MSH 4.1 is copied like MSH 2.2: in each $Nodes block (entityDim
 * entityTag parametric n; n tags; n records of x y z and, if parametric,
 * entityDim parametric coordinates) only x y z of the nodes whose
 * coordinates changed are rewritten.  Parametric coordinates stay as they
 * are, as gmshModelMeshSetNode without them leaves them.  -1 if the file
 * is not laid out as expected (the caller then lets Gmsh write it). */
static int patch41_ascii(FILE *in, FILE *out, const node_table *t,
                         size_t blocks)
{
    char line[1024];
    for (size_t b = 0; b < blocks; b++) {
        int dim, tag, param;
        size_t n;
        if (copy_line(in, out, line, sizeof line) != 0 ||
            sscanf(line, "%d %d %d %zu", &dim, &tag, &param, &n) != 4)
            return -1;
        size_t *tags = malloc((n ? n : 1) * sizeof *tags);
        int rc = tags ? 0 : -1;
        for (size_t i = 0; i < n && rc == 0; i++)
            rc = copy_line(in, out, line, sizeof line) == 0 &&
                         sscanf(line, "%zu", &tags[i]) == 1
                     ? 0
                     : -1;
        for (size_t i = 0; i < n && rc == 0; i++) {
            if (!fgets(line, sizeof line, in)) {
                rc = -1;
                break;
            }
            double old[3];
            char *p = line;
            for (int k = 0; k < 3; k++)
                old[k] = strtod(p, &p);
            const double *x = find_node(t, tags[i]);
            /* p: the rest of the line (parametric coordinates, line end) */
            if (!x || memcmp(x, old, sizeof old) == 0)
                rc = fputs(line, out) == EOF ? -1 : 0;
            else
                rc = print_xyz(out, x) != 0 || fputs(p, out) == EOF ? -1 : 0;
        }
        free(tags);
        if (rc != 0)
            return -1;
    }
    return 0;
}

static int patch41_binary(FILE *in, FILE *out, const node_table *t,
                          size_t blocks)
{
    for (size_t b = 0; b < blocks; b++) {
        int head[3]; /* entityDim, entityTag, parametric */
        size_t n;
        if (fread(head, sizeof head, 1, in) != 1 || fread(&n, sizeof n, 1, in) != 1 ||
            fwrite(head, sizeof head, 1, out) != 1 ||
            fwrite(&n, sizeof n, 1, out) != 1 || head[0] < 0 || head[0] > 3)
            return -1;
        size_t rec = 3 + (head[2] ? (size_t)head[0] : 0);
        if (n > ((size_t)1 << 40))
            return -1;
        size_t *tags = malloc((n ? n : 1) * sizeof *tags);
        double *xyz = malloc((n ? n : 1) * rec * sizeof *xyz);
        int rc = tags && xyz && fread(tags, sizeof *tags, n, in) == n &&
                         fread(xyz, rec * sizeof *xyz, n, in) == n
                     ? 0
                     : -1;
        for (size_t i = 0; i < n && rc == 0; i++) {
            const double *x = find_node(t, tags[i]);
            if (x)
                memcpy(xyz + rec * i, x, 3 * sizeof *x);
        }
        if (rc == 0 && (fwrite(tags, sizeof *tags, n, out) != n ||
                        fwrite(xyz, rec * sizeof *xyz, n, out) != n))
            rc = -1;
        free(tags);
        free(xyz);
        if (rc != 0)
            return -1;
    }
    return 0;
}

/* MSH 4.1: numEntityBlocks numNodes minNodeTag maxNodeTag, then blocks. */
static int msh41_nodes(FILE *in, FILE *out, const node_table *t, int binary)
{
    char line[512];
    size_t head[4];
    if (binary)
        return fread(head, sizeof head, 1, in) == 1 &&
                       fwrite(head, sizeof head, 1, out) == 1
                   ? patch41_binary(in, out, t, head[0])
                   : -1;
    return copy_line(in, out, line, sizeof line) == 0 &&
                   sscanf(line, "%zu", &head[0]) == 1
               ? patch41_ascii(in, out, t, head[0])
               : -1;
}

/* Write input part in_part (opened again as its own Gmsh model) with the
   document's coordinates, by node tag, to tmp_msh; 0 or -1 (message). */
static int write_part(msh_impl *impl, const getme__nodemap *map,
                      const double *coords, const char *in_part,
                      const char *tmp_msh, char *msg, size_t size)
{
    int ierr = 0;
    gmshOpen(in_part, &ierr);
    if (ierr) {
        snprintf(msg, size, "Gmsh could not read '%.400s' again", in_part);
        return -1;
    }
    size_t *tags = NULL, n = 0, nc = 0, np = 0;
    double *xyz = NULL, *param = NULL;
    gmshModelMeshGetNodes(&tags, &n, &xyz, &nc, &param, &np, -1, -1, 0, 0,
                          &ierr);
    const getme_gmsh_model *m = impl->model;
    int rc = ierr ? -1 : 0;
    for (size_t i = 0; i < n && rc == 0; i++) {
        int32_t k = getme__nodemap_find(map, tags[i]);
        if (k < 0) {
            snprintf(msg, size, "'%.400s': node %zu is not in the mesh read",
                     in_part, tags[i]);
            rc = -1;
            break;
        }
        const double *p = coords + 3 * (size_t)k;
        if (memcmp(p, m->coords0 + 3 * (size_t)k, 3 * sizeof *p) == 0)
            continue; /* unmoved: the bits as read */
        double g[3];
        getme__frame_to_global(&m->frame, p, g);
        gmshModelMeshSetNode(tags[i], g, 3, NULL, 0, &ierr);
        if (ierr) {
            snprintf(msg, size, "'%.400s': could not set node %zu", in_part,
                     tags[i]);
            rc = -1;
        }
    }
    gmshFree(tags);
    gmshFree(xyz);
    gmshFree(param);
    if (rc == 0) {
        set_number("Mesh.SaveAll", needs_save_all());
        set_number("Mesh.PartitionSplitMeshFiles", 0);
        gmshWrite(tmp_msh, &ierr);
        if (ierr) {
            snprintf(msg, size, "Gmsh's writer failed on '%.400s'", in_part);
            rc = -1;
        }
    }
    gmshModelRemove(&ierr);
    return rc;
}

/* A document read from split files: each input part NAME_K.msh is opened
   again, given the new coordinates by node tag and written to a temporary
   file; only when all are written are they renamed to OUT_K.msh
   (out_path = "OUT.msh"), so a failing part leaves nothing behind. */
static fstatus write_split(getme_doc *doc, msh_impl *impl, const char *tmp,
                           const char *out_path)
{
    char in_stem[4096], out_stem[4096], part[4200], in_part[4200],
        msg[512] = "";
    size_t n = strlen(out_path);
    int k, nparts = impl->split_parts;
    if (impl->version < 3 || n < 5 || strcmp(out_path + n - 4, ".msh") != 0 ||
        n - 4 >= sizeof out_stem ||
        split_stem(getme_doc_path(doc), in_stem, sizeof in_stem) < 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "Cannot write '%s': split partition files are "
                              "written as MSH 4 to an output named *.msh",
                              out_path);
    memcpy(out_stem, out_path, n - 4);
    out_stem[n - 4] = '\0';
    for (k = 1; k <= nparts; k++)
        for (int j = 1; j <= nparts; j++) {
            snprintf(part, sizeof part, "%s_%d.msh", out_stem, k);
            snprintf(in_part, sizeof in_part, "%s_%d.msh", in_stem, j);
            if (getme_io_same_file(part, in_part))
                return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                                      "Cannot write '%s': it is the input "
                                      "part '%s'; choose another output name",
                                      part, in_part);
        }
    getme__nodemap map;
    uint64_t dup = 0;
    const getme_gmsh_model *m = impl->model;
    if (getme__nodemap_build(&map, (const uint64_t *)m->node_tags,
                             (size_t)m->num_nodes, &dup) != GETME_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "Out of memory");
    const double *coords = getme_mesh_coords(getme_doc_mesh(doc));
    int rc = 0;
    for (k = 1; k <= nparts && rc == 0; k++) {
        snprintf(in_part, sizeof in_part, "%s_%d.msh", in_stem, k);
        snprintf(part, sizeof part, "%s_%d.msh", tmp, k);
        rc = write_part(impl, &map, coords, in_part, part, msg, sizeof msg);
    }
    getme__nodemap_free(&map);
    int err = 0, written = rc == 0 ? nparts : k - 1;
    for (k = 1; k <= written; k++) {
        snprintf(part, sizeof part, "%s_%d.msh", tmp, k);
        snprintf(in_part, sizeof in_part, "%s_%d.msh", out_stem, k);
        if (rc != 0)
            remove(part);
        else if (getme_io_commit(part, in_part) != 0)
            rc = -1, err = errno;
    }
    if (rc != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "Cannot write '%s_K.msh': %s", out_stem,
                              msg[0] ? msg : strerror(err));
    return GETME_FORMATS_OK;
}

/* MSH 4.0 ASCII: numEntityBlocks numNodes, then per block "tagEntity
   dimEntity parametric numNodes" and numNodes lines "tag x y z [u v w]",
   patched as MSH 2.2's (Gmsh's writer would zero the entities' bounding
   boxes, as for 4.1 above).  Binary 4.0 files: -1, Gmsh writes them. */
static int msh40_nodes(FILE *in, FILE *out, const node_table *t, int binary)
{
    char line[512];
    size_t blocks, total;
    if (binary || copy_line(in, out, line, sizeof line) != 0 ||
        sscanf(line, "%zu %zu", &blocks, &total) != 2)
        return -1;
    for (size_t b = 0; b < blocks; b++) {
        int tag, dim, param;
        long n;
        if (copy_line(in, out, line, sizeof line) != 0 ||
            sscanf(line, "%d %d %d %ld", &tag, &dim, &param, &n) != 4 ||
            n < 0 || patch_ascii_nodes(in, out, t, n) != 0)
            return -1;
    }
    return 0;
}

static fstatus write_model(getme_doc *doc, msh_impl *impl,
                                   const char *out_path)
{
    char msg[512] = "", tmp[4096], tmp_msh[4200];
    int ierr = 0;
    gmshModelSetCurrent(impl->model_name, &ierr);
    /* Split files: the merged model is not written (each node of a
       partition boundary is in it once per file), the parts are. */
    getme_status gs = impl->split_parts > 0 ? GETME_OK : getme_gmsh_model_apply(
        impl->model, getme_mesh_coords(getme_doc_mesh(doc)), NULL, msg, sizeof msg);
    if (gs != GETME_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "%s", msg);
    if (getme_io_tmp_path(out_path, tmp, sizeof tmp) != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "Cannot create a temporary file next to '%s'",
                              out_path);
    /* Gmsh picks the format from the extension: write "<tmp>.msh". */
    snprintf(tmp_msh, sizeof tmp_msh, "%s.msh", tmp);
    remove(tmp);
    set_number("Mesh.MshFileVersion", impl->version);
    set_number("Mesh.Binary", impl->binary);
    set_number("Mesh.SaveAll", impl->save_all);
    if (impl->split_parts > 0)
        return write_split(doc, impl, tmp, out_path);
    if (impl->version < 3)
        ierr = patch_file(getme_doc_path(doc), tmp_msh, impl->binary,
                          msh2_nodes) != 0;
    else if (patch_file(getme_doc_path(doc), tmp_msh, impl->binary,
                        impl->version == 4.0 ? msh40_nodes : msh41_nodes) != 0)
        gmshWrite(tmp_msh, &ierr); /* binary 4.0, or a file laid out otherwise */
    FILE *check = ierr ? NULL : fopen(tmp_msh, "rb");
    if (check)
        fclose(check);
    if (!check || getme_io_commit(tmp_msh, out_path) != 0) {
        int err = errno;
        remove(tmp_msh);
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "Cannot write '%s': %s",
                              out_path, check ? strerror(err)
                                              : "Gmsh's writer failed");
    }
    return GETME_FORMATS_OK;
}


/* ---- the adapter -------------------------------------------------------- */

static fstatus msh_open(getme_doc *doc, const getme_doc_options *opts)
{
    msh_impl *impl = calloc(1, sizeof *impl);
    if (!impl)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "Out of memory");
    getme_doc_set_impl(doc, impl);
    /* the native adapter checked the header before it declined the file */
    if (getme__msh_header(getme_doc_path(doc), &impl->version,
                          &impl->binary) != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "'%s', line 1: not a Gmsh MSH file (no "
                              "$MeshFormat header)",
                              getme_doc_path(doc));
    fstatus st = check_msh_file(doc, impl);
    if (st != GETME_FORMATS_OK)
        return st;
    saved_options saved;
    quiet_begin(&saved);
    st = open_model(doc, impl);
    if (st == GETME_FORMATS_OK)
        st = check_model_coords(doc);
    if (st == GETME_FORMATS_OK)
        st = check_free_names(doc, opts);
    if (st == GETME_FORMATS_OK) {
        impl->save_all = needs_save_all();
        st = extract(doc, impl, opts);
    }
    if (st == GETME_FORMATS_OK)
        describe(doc, impl);
    quiet_end(&saved);
    return st;
}

static fstatus msh_write(getme_doc *doc, const char *out_path)
{
    msh_impl *impl = getme_doc_impl(doc);
    if (!impl || !impl->model || !getme_doc_mesh(doc))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                              "MSH document is not open");
    saved_options saved;
    char previous[256];
    quiet_begin(&saved);
    current_model(previous, sizeof previous);
    fstatus st = write_model(doc, impl, out_path);
    int ierr = 0;
    if (model_exists(previous))
        gmshModelSetCurrent(previous, &ierr);
    quiet_end(&saved);
    return st;
}

static void msh_close(getme_doc *doc)
{
    msh_impl *impl = getme_doc_impl(doc);
    if (!impl)
        return;
    if (impl->model_name[0] && gg_gmsh_initialized() &&
        model_exists(impl->model_name) == 1) {
        int ierr = 0;
        gmshModelSetCurrent(impl->model_name, &ierr);
        gmshModelRemove(&ierr);
    }
    getme_gmsh_model_free(impl->model);
    free(impl);
    getme_doc_set_impl(doc, NULL);
}

static const getme_format GMSH_FORMAT = {
    "msh",
    "Gmsh MSH 2.2/4.0/4.1 through the Gmsh SDK (the files the native reader "
    "declines)",
    getme__msh_probe,
    msh_open, msh_write, msh_close, ".msh", NULL};

const getme_format *getme_gmsh_format(void) { return &GMSH_FORMAT; }
