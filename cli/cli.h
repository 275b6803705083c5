/*
 * cli.h -- the getme command: shared pieces of its subcommands.
 *
 * Exit codes (stable, for scripts): 0 success, 1 internal error, 2 usage,
 * 3 cannot read the input, 4 malformed input, 5 unsupported content,
 * 6 invalid (inverted) elements in the input (with --no-untangle), 7 cannot
 * write the output, 8 invalid elements that untangling could not repair.
 * They equal getme_io_status values.
 */
#ifndef GETME_CLI_H
#define GETME_CLI_H

#include "getme.h"
#include "getme_formats.h"

#include <stdio.h>

enum { EXIT_USAGE = 2 };

/* Gmsh-style log lines: "Info    : ...", "Warning : ...", "Error   : ...".
   Info and warnings go to stdout (as Gmsh does), errors to stderr. */
typedef struct cli_log {
    int quiet;   /* only errors */
    int verbose; /* more detail */
} cli_log;

void cli_info(const cli_log *log, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
void cli_warning(const cli_log *log, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
void cli_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Gmsh-like histogram and summary of stats, one line each. */
void cli_print_stats(const cli_log *log, const char *title,
                     const getme_quality_stats *s);

/* Per element type statistics of the analysts' measures (measures.c):
   stats[type][measure], num_elements 0 for absent types and undefined
   measures. */
typedef struct cli_measures {
    getme_measure_stats stats[GETME_NUM_TYPES][GETME_NUM_MEASURES];
} cli_measures;

/* 0 on success, -1 if the library failed (out of memory). */
int cli_measures_compute(getme_mesh *mesh, cli_measures *m);
/* One line per element type: "TITLE (tet): dihedral 12.34 to 160.21 deg,
   scaled Jacobian min .. mean .., gamma ..., SICN ...". */
void cli_print_measures(const cli_log *log, const char *title,
                        const cli_measures *m);
/* Compute and print; on failure warn (the statistics stay empty). */
void cli_measures_log(const cli_log *log, getme_mesh *mesh, const char *title,
                      cli_measures *m);
/* Summary and 10-bin histogram of every measure but the mean ratio. */
void cli_print_measure_histograms(const cli_log *log, const cli_measures *m,
                                  int type);
/* {"tet": {"mean_ratio": {...}, "min_dihedral": {...}, ...}, ...} */
void cli_json_measures(FILE *f, const cli_measures *m);

/* The smoothing parameters of libgetme's table (getme_param_at): name,
   default, range and help, one per line, for --help. */
void cli_print_params(FILE *out);
/* "[0, 1]", "> 0", ">= 0": a parameter's range for messages. */
void cli_param_range(const getme_param_info *p, char *buf, size_t size);

/* Parse helpers: return 0 on success, print an error and return -1. */
int cli_parse_int(const char *opt, const char *s, long min, long max, long *out);
int cli_parse_double(const char *opt, const char *s, double *out);

/* Open a document; on failure print its one-line error, close it and
   return NULL with the exit code in *code.  With allow_invalid, an input
   whose only problem is invalid elements is returned (*code =
   GETME_IO_ERR_INVALID) so that it can still be reported on. */
getme_doc *cli_open(const char *path, const getme_doc_options *opts,
                    int allow_invalid, int *code);

/* Mesh summary: "195070 tets, 12 prisms; 37012 nodes (8123 fixed)". */
void cli_describe_mesh(getme_mesh *mesh, char *buf, size_t size);

int cli_smooth(int argc, char **argv);
int cli_quality(int argc, char **argv);
int cli_distort(int argc, char **argv);
/* `getme gmsh ...` (cmd_gmsh.c, present when the Gmsh plugin is built). */
int getme_cli_gmsh(int argc, char **argv);

/* Report JSON (report.c). */
typedef struct cli_history {
    getme_progress *items;
    int count, cap;
} cli_history;

/* The worst elements of a document (worst.c). */
typedef struct cli_worst_list {
    getme_worst_element *items;
    int32_t count;
} cli_worst_list;

long long cli_element_tag(const getme_doc *doc, int32_t e);
/* Fill w with the max_count worst elements; 0, or -1 after printing an
   error.  Free w->items. */
int cli_worst(getme_doc *doc, int32_t max_count, unsigned flags,
              cli_worst_list *w);
/* which: "" or " with a free node". */
void cli_print_worst(const cli_log *log, const getme_doc *doc,
                     const cli_worst_list *w, const char *which);
void cli_json_worst(FILE *f, const getme_doc *doc, const cli_worst_list *w);

int cli_write_report(const char *path, const char *input, const char *output,
                     const getme_params *params, getme_mesh *mesh,
                     const getme_quality_stats *before,
                     const getme_quality_stats *after,
                     const getme_result *result, const cli_history *history,
                     const getme_doc *doc, const cli_worst_list *worst,
                     const cli_worst_list *worst_free,
                     const cli_measures *measures_before,
                     const cli_measures *measures_after);

#endif /* GETME_CLI_H */
