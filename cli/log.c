/*
 * log.c -- Gmsh-style log lines and common parsing for the getme command.
 */
#include "cli.h"
#include "getme_alloc.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

static void vline(FILE *f, const char *tag, const char *fmt, va_list ap)
{
    fputs(tag, f);
    vfprintf(f, fmt, ap);
    fputc('\n', f);
    fflush(f);
}

void cli_info(const cli_log *log, const char *fmt, ...)
{
    if (log && log->quiet)
        return;
    va_list ap;
    va_start(ap, fmt);
    vline(stdout, "Info    : ", fmt, ap);
    va_end(ap);
}

void cli_warning(const cli_log *log, const char *fmt, ...)
{
    if (log && log->quiet)
        return;
    va_list ap;
    va_start(ap, fmt);
    vline(stdout, "Warning : ", fmt, ap);
    va_end(ap);
}

void cli_error(const char *fmt, ...)
{
    fflush(stdout);
    va_list ap;
    va_start(ap, fmt);
    vline(stderr, "Error   : ", fmt, ap);
    va_end(ap);
}

const char *cli_q_min_star(const getme_quality_stats *s, char *buf,
                           size_t size)
{
    if (s->num_free == 0)
        snprintf(buf, size, "- (no element has a free node)");
    else
        snprintf(buf, size, "%.4f", s->q_min_star);
    return buf;
}

void cli_print_stats(const cli_log *log, const char *title,
                     const getme_quality_stats *s)
{
    char qs[64];
    cli_info(log, "%s: q*min %s, qmin %.4f, qmean %.4f, %lld elements "
                  "(%lld with q <= 0.4, %lld with q < 0.1, %lld invalid)",
             title, cli_q_min_star(s, qs, sizeof qs), s->q_min, s->q_mean,
             (long long)s->num_elements, (long long)s->num_below_04,
             (long long)s->num_below_01, (long long)s->num_invalid);
    if (log && !log->verbose)
        return;
    for (int b = 0; b < GETME_HIST_BINS; b++)
        cli_info(log, "%.2f < quality < %.2f : %9lld elements",
                 b / (double)GETME_HIST_BINS, (b + 1) / (double)GETME_HIST_BINS,
                 (long long)s->histogram[b]);
}

int cli_parse_int(const char *opt, const char *s, long min, long max, long *out)
{
    char *end;
    errno = 0;
    long v = s ? strtol(s, &end, 10) : 0;
    if (!s || !*s || *end || errno || v < min || v > max) {
        cli_error("%s expects an integer in [%ld, %ld], got '%s'", opt, min,
                  max, s ? s : "");
        return -1;
    }
    *out = v;
    return 0;
}

int cli_parse_double(const char *opt, const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = s ? strtod(s, &end) : 0.0;
    if (!s || !*s || *end || errno || !isfinite(v)) {
        cli_error("%s expects a number, got '%s'", opt, s ? s : "");
        return -1;
    }
    *out = v;
    return 0;
}

void cli_describe_mesh(getme_mesh *mesh, char *buf, size_t size)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int32_t n = getme_mesh_num_elements_of_type(mesh, (getme_elem_type)t);
        if (n && len < size)
            len += (size_t)snprintf(buf + len, size - len, "%s%d %s%s",
                                    len ? ", " : "", (int)n,
                                    getme_type_name((getme_elem_type)t),
                                    n == 1 ? "" : "s");
    }
    if (len < size)
        snprintf(buf + len, size - len, "; %d nodes (%d fixed)",
                 (int)getme_mesh_num_nodes(mesh), (int)getme_mesh_num_fixed(mesh));
}

/* The measures and qualities of the mesh just read into mb, then the
   document's validity check from those qualities. */
static getme_formats_status check_measured(getme_doc *doc, cli_measured *mb)
{
    getme_mesh *mesh = getme_doc_mesh(doc);
    int32_t ne = getme_mesh_num_elements(mesh);
    /* one double per element, written in the measures' sweep: on huge
       pages (getme_alloc.h), or its first touch was 4 KiB page faults */
    mb->q = getme__malloc((size_t)(ne ? ne : 1) * sizeof *mb->q);
    mb->ok = cli_measures_compute(mesh, &mb->m, mb->q) == 0;
    if (!mb->ok) {
        free(mb->q);
        mb->q = NULL;
    }
    return getme_doc_check(doc, mb->q);
}

static getme_doc *open_doc(const char *path, const getme_doc_options *opts,
                           int allow_invalid, int *code, const cli_log *log,
                           cli_measured *mb)
{
    getme_doc *doc = NULL;
    getme_doc_options with_gmsh;
    if (opts)
        with_gmsh = *opts;
    else
        getme_doc_options_init(&with_gmsh);
    /* MSH files the native reader declines: read through the Gmsh SDK,
       loaded only then (gmsh_load.c) */
    const getme_format *adapters[] = {cli_gmsh_adapter(), NULL};
    if (adapters[0])
        with_gmsh.adapters = adapters;
    with_gmsh.defer_check = mb != NULL;
    getme_formats_status st = getme_doc_open(&doc, path, &with_gmsh);
    if (mb) {
        mb->q = NULL;
        mb->ok = 0;
        if (st == GETME_FORMATS_OK)
            st = check_measured(doc, mb);
    }
    *code = cli_exit_code(st);
    /* allow_invalid: inverted elements found in a complete mesh (to be
       untangled or reported on); not elements an adapter refused as
       degenerate (a node twice), which no node move repairs */
    if (st == GETME_FORMATS_OK ||
        (allow_invalid && st == GETME_FORMATS_ERR_INVALID &&
         getme_doc_mesh(doc) && getme_doc_stats(doc) &&
         getme_doc_stats(doc)->num_invalid > 0)) {
        if (getme_doc_warning(doc)[0])
            cli_warning(log, "%s", getme_doc_warning(doc));
        return doc;
    }
    cli_error("%s", getme_doc_error(doc));
    getme_doc_close(doc);
    if (mb) {
        free(mb->q);
        mb->q = NULL;
    }
    return NULL;
}

getme_doc *cli_open(const char *path, const getme_doc_options *opts,
                    int allow_invalid, int *code, const cli_log *log)
{
    return open_doc(path, opts, allow_invalid, code, log, NULL);
}

getme_doc *cli_open_measured(const char *path, const getme_doc_options *opts,
                             int allow_invalid, int *code, const cli_log *log,
                             cli_measured *out)
{
    return open_doc(path, opts, allow_invalid, code, log, out);
}

void cli_param_range(const getme_param_info *p, char *buf, size_t size)
{
    if (isinf(p->max))
        snprintf(buf, size, "%s %g", p->open_min ? ">" : ">=", p->min);
    else
        snprintf(buf, size, "%c%g, %g]", p->open_min ? '(' : '[', p->min,
                 p->max);
}

void cli_print_params(FILE *out)
{
    static const char *const kind[] = {"real", "integer", "0/1", "code"};
    fputs("\nparameters (--param NAME=VALUE; the library's table, getme.h):\n",
          out);
    for (int i = 0; i < getme_param_count(); i++) {
        const getme_param_info *p = getme_param_at(i);
        char range[64];
        cli_param_range(p, range, sizeof range);
        fprintf(out, "  %-19s %-7s default %-6g %-13s %s\n", p->name,
                kind[p->type], p->default_value, range, p->help);
    }
}
