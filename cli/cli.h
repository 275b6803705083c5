/*
 * cli.h -- the getme command: shared pieces of its subcommands.
 *
 * Exit codes (stable, for scripts): 0 success, 1 internal error, 2 usage,
 * 3 cannot read the input, 4 malformed input, 5 unsupported content,
 * 6 invalid (inverted) elements in the input, 7 cannot write the output.
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

/* q*min of stats as printed: "0.1919", or "- (no element has a free
   node)" when it is undefined (every node fixed), never a made-up 1. */
const char *cli_q_min_star(const getme_quality_stats *s, char *buf,
                           size_t size);

/* Gmsh-like histogram and summary of stats, one line each. */
void cli_print_stats(const cli_log *log, const char *title,
                     const getme_quality_stats *s);

/* Parse helpers: return 0 on success, print an error and return -1. */
int cli_parse_int(const char *opt, const char *s, long min, long max, long *out);
int cli_parse_double(const char *opt, const char *s, double *out);

/* Open a document; on failure print its one-line error, close it and
   return NULL with the exit code in *code.  With allow_invalid, an input
   whose only problem is invalid elements is returned (*code =
   GETME_IO_ERR_INVALID) so that it can still be reported on.  The
   document's warning, if any, is printed through log. */
getme_doc *cli_open(const char *path, const getme_doc_options *opts,
                    int allow_invalid, int *code, const cli_log *log);

/* Mesh summary: "195070 tets, 12 prisms; 37012 nodes (8123 fixed)". */
void cli_describe_mesh(getme_mesh *mesh, char *buf, size_t size);

/* ---- files written (paths.c) ---- */

/* 1 if a and b are the same file (device and inode; a file that does not
   exist yet: same directory and name). */
int cli_same_file(const char *a, const char *b);

typedef struct cli_paths {
    const char *input;          /* as given                                  */
    const char *output, *report; /* as given, NULL if none                   */
    char out[4096], rep[4096];  /* what to write (symbolic links followed)   */
} cli_paths;

/* Before anything is read: the output has the input format's extension,
   output and report are regular files or new (never a device, FIFO...),
   their directories are writable, and neither is the input nor the other.
   Prints the error and returns the exit code (2 or 7), or 0. */
int cli_check_paths(cli_paths *p);
/* After reading: neither output nor report is a file the input includes.
   0 or EXIT_USAGE (printed). */
int cli_check_read_files(const cli_paths *p, const getme_doc *doc);

/* Hold termination signals while files are written (on = 1), deliver them
   after (on = 0): a Ctrl-C leaves the whole output or none. */
typedef struct cli_guard {
    int active;
} cli_guard;
void cli_write_guard(cli_guard *g, int on);

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

/* ---- smoothing options shared by smooth and gmsh (smooth_opts.c) ---- */

typedef struct cli_smooth_opts {
    const char **fix, **free_sets;
    int num_fix, num_free, free_interfaces;
    const char *report;
    getme_params params;
    cli_log log;
    cli_history history; /* filled by the progress callback */
} cli_smooth_opts;

/* Their --help lines. */
extern const char CLI_SMOOTH_OPTIONS_HELP[];
/* Defaults (getme_params_init); room for argc names.  0 or -1 (memory). */
int cli_smooth_opts_init(cli_smooth_opts *o, int argc);
void cli_smooth_opts_free(cli_smooth_opts *o);
/* argv[*i] if it is a smoothing option (advancing *i past its value):
   1 taken, 0 not a smoothing option, -1 bad value (printed). */
int cli_smooth_option(cli_smooth_opts *o, int argc, char **argv, int *i);
/* The document options the smoothing options imply. */
void cli_smooth_doc_options(const cli_smooth_opts *o, getme_doc_options *d);
/* Before smoothing: progress lines and history on, the thread count
   decided, "Optimizing mesh (...)..." logged; the parameters are copied to
   *params when that is not o->params. */
void cli_smooth_begin(cli_smooth_opts *o, getme_params *params);
/* "Done optimizing mesh (Wall ...): N + M iterations (K q*min cycles)". */
void cli_smooth_done(const cli_smooth_opts *o, const getme_result *res);

/* What the report says about the mesh. */
typedef struct cli_mesh_counts {
    int32_t nodes, fixed;
    int32_t elements[GETME_NUM_TYPES];
} cli_mesh_counts;
void cli_count_mesh(getme_mesh *mesh, cli_mesh_counts *c);

int cli_write_report(const char *path, const char *input, const char *output,
                     const getme_params *params, const cli_mesh_counts *mesh,
                     const getme_quality_stats *before,
                     const getme_quality_stats *after,
                     const getme_result *result, const cli_history *history,
                     const char *format_name);

#endif /* GETME_CLI_H */
