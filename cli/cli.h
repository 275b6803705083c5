/*
 * cli.h -- the getme command: shared pieces of its subcommands.
 *
 * Exit codes (stable, for scripts): 0 success, 1 internal error, 2 usage,
 * 3 cannot read the input, 4 malformed input, 5 unsupported content,
 * 6 invalid (inverted) elements in the input (with --no-untangle), 7 cannot
 * write the output, 8 invalid elements that untangling could not repair.
 * libgetme_formats has status codes of its own: cli_exit_code (exit.c)
 * maps them.
 */
#ifndef GETME_CLI_H
#define GETME_CLI_H

#include "getme.h"
#include "getme_formats.h"

#include <stdio.h>

/* Exit codes (README, `getme --help`, tests/cli): never renumber. */
enum {
    CLI_EXIT_OK = 0,
    CLI_EXIT_INTERNAL = 1,
    EXIT_USAGE = 2,
    CLI_EXIT_OPEN = 3,
    CLI_EXIT_PARSE = 4,
    CLI_EXIT_UNSUPPORTED = 5,
    CLI_EXIT_INVALID = 6,
    CLI_EXIT_WRITE = 7,
    CLI_EXIT_TANGLED = 8
};

/* The exit code for a libgetme_formats status. */
int cli_exit_code(getme_formats_status st);

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

/* Per element type statistics of the analysts' measures (measures.c):
   stats[type][measure], num_elements 0 for absent types and undefined
   measures. */
typedef struct cli_measures {
    getme_measure_stats stats[GETME_NUM_TYPES][GETME_NUM_MEASURES];
} cli_measures;

/* 0 on success, -1 if the library failed (out of memory).  q: NULL, or
   num_elements doubles receiving every element's quality from the same
   sweep (for getme_mesh_quality_stats_from and cli_worst). */
int cli_measures_compute(getme_mesh *mesh, cli_measures *m, double *q);
/* One line per element type: "TITLE (tet): dihedral 12.34 to 160.21 deg,
   scaled Jacobian min .. mean .., gamma ..., SICN ...". */
void cli_print_measures(const cli_log *log, const char *title,
                        const cli_measures *m);
/* Compute and print; on failure warn (the statistics stay empty). */
void cli_measures_log(const cli_log *log, getme_mesh *mesh, const char *title,
                      cli_measures *m);
/* Second-order meshes (highorder.c): "Second order (WHEN): N elements,
   worst node Jacobian ratio R (element ID)"; nothing for a linear mesh. */
/* The worst node Jacobian ratio of a mesh's second-order elements
   (cli/highorder.c): n = 0 when it has none. */
typedef struct cli_ho_ratio {
    int32_t n;
    double ratio;
    long long id; /* the element's id in the file */
} cli_ho_ratio;
/* Log it (when: "before"/"after") and store it in out (may be NULL). */
void cli_ho_log(const cli_log *log, getme_doc *doc, const char *when,
                cli_ho_ratio *out);
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
   CLI_EXIT_INVALID) so that it can still be reported on.  The
   document's warning, if any, is printed through log. */
getme_doc *cli_open(const char *path, const getme_doc_options *opts,
                    int allow_invalid, int *code, const cli_log *log);

/* The mesh as read, measured in the sweep that also makes the document's
   validity check (cli_open_measured). */
typedef struct cli_measured {
    cli_measures m; /* valid if ok                                     */
    int ok;         /* 0: the measures failed (out of memory)          */
    double *q;      /* every element's quality (the caller frees it);
                       NULL if it could not be allocated or !ok        */
} cli_measured;

/* cli_open, but the document's validity check (getme_doc_check) takes
   its qualities from the measures' sweep, which the caller reports
   anyway: every element is evaluated once, not twice.  The same
   messages, codes and statistics as cli_open; out is filled whenever a
   document is returned. */
getme_doc *cli_open_measured(const char *path, const getme_doc_options *opts,
                             int allow_invalid, int *code, const cli_log *log,
                             cli_measured *out);

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

/* A file's identity at one moment (device, inode; or absent). */
typedef struct cli_file_stamp {
    int exists;
    uint64_t dev, ino;
} cli_file_stamp;
void cli_stamp(const char *path, cli_file_stamp *s);
/* 1 if path now exists and is not the file it was at the stamp: something
   (a writer's rename) created or replaced it since. */
int cli_replaced(const char *path, const cli_file_stamp *before);

/* Hold termination signals while files are written (on = 1), deliver them
   after (on = 0): a Ctrl-C leaves the whole output or none. */
typedef struct cli_guard {
    int active;
} cli_guard;
void cli_write_guard(cli_guard *g, int on);

/* Before the getme command re-executes itself (main.c): widen the
   initial thread's CPU mask, which libgomp bound to its first place when
   OMP_PROC_BIND or OMP_PLACES asked for binding, back to the union of its
   places (affinity.c).  Nothing happens without binding. */
void cli_affinity_unbind(void);

int cli_smooth(int argc, char **argv);
int cli_quality(int argc, char **argv);
int cli_distort(int argc, char **argv);
/* `getme gmsh ...` (cmd_gmsh.c, in the program getme-gmsh, present when
   the Gmsh plugin is built). */
int getme_cli_gmsh(int argc, char **argv);

/* The Gmsh plugin, loaded on first use (gmsh_load.c): its MSH adapter
   (NULL if it cannot be loaded or was not built); an adapter for
   getme_doc_options.adapters that loads it only when asked; and `getme
   gmsh ARGS` as getme-gmsh ARGS (argv[0] is replaced; returns only on
   failure). */
struct getme_format;
const struct getme_format *cli_gmsh_format(void);
const struct getme_format *cli_gmsh_adapter(void);
int cli_run_gmsh(char **argv);

/* Report JSON (report.c). */
typedef struct cli_history {
    getme_progress *items;
    int count, cap;
} cli_history;

/* ---- smoothing options shared by smooth and gmsh (smooth_opts.c) ---- */

typedef struct cli_smooth_opts {
    const char **fix, **free_sets;
    int num_fix, num_free, free_interfaces;
    int allow_invalid;   /* --allow-invalid: write a partly untangled mesh */
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

/* The arguments getme smooth and getme-mpi smooth take alike. */
typedef struct cli_smooth_args {
    const char *input, *output;
    long worst;
    cli_smooth_opts o;
} cli_smooth_args;

/* How one of those commands names itself in its help and messages. */
typedef struct cli_smooth_usage {
    const char *name;      /* "getme smooth" */
    const char *help_cmd;  /* the command whose --help to point to */
    const char *help_head, *help_tail; /* around the options; tail may be NULL */
} cli_smooth_usage;

/* Parse argv[first..] (a->o initialised): smoothing options, -o / --output,
   --worst N and one input.  -1 after printing --help, 0 with an input and an
   output, else EXIT_USAGE (printed).  One parser keeps getme-mpi smooth's
   command line the same as getme smooth's. */
int cli_smooth_parse_args(cli_smooth_args *a, int argc, char **argv,
                          int first, const cli_smooth_usage *u);

/* Before smoothing: progress lines and history on, the thread count
   decided, "Optimizing mesh (...)..." logged; the parameters are copied to
   *params when that is not o->params. */
void cli_smooth_begin(cli_smooth_opts *o, getme_params *params);
/* The thread count decided (OMP_NUM_THREADS or every core) if not given. */
void cli_smooth_threads(cli_smooth_opts *o);
/* The progress callback cli_smooth_begin installs (data: the
   cli_smooth_opts): one log line per iteration, appended to the history. */
int cli_smooth_progress(const getme_progress *p, void *data);
/* Untangle doc's mesh (untangle.c): a warning with the counts, the elements
   that stay invalid named by their file ids in an error.  0,
   CLI_EXIT_TANGLED or CLI_EXIT_INTERNAL. */
int cli_untangle(cli_smooth_opts *o, const char *input, getme_doc *doc,
                 getme_untangle_result *ur);
/* "N invalid (inverted or degenerate) elements in the input, M remain
   after untangling (...)". */
void cli_untangle_warning(const cli_log *log, const getme_untangle_result *ur);
/* "Done optimizing mesh (Wall ...): N + M iterations (K q*min cycles)". */
void cli_smooth_done(const cli_smooth_opts *o, const getme_result *res);

/* What the report says about the mesh. */
typedef struct cli_mesh_counts {
    int32_t nodes, fixed;
    int32_t elements[GETME_NUM_TYPES];
} cli_mesh_counts;
void cli_count_mesh(getme_mesh *mesh, cli_mesh_counts *c);

/* The worst elements of a document (worst.c). */
typedef struct cli_worst_list {
    getme_worst_element *items;
    int32_t count;
} cli_worst_list;

long long cli_element_tag(const getme_doc *doc, int32_t e);
/* Fill w with the max_count worst elements ranked by q (the mesh's
   element qualities); 0, or -1 after printing an error.  Free w->items. */
int cli_worst(getme_doc *doc, const double *q, int32_t max_count,
              unsigned flags, cli_worst_list *w);
/* which: "" or " with a free node". */
void cli_print_worst(const cli_log *log, const getme_doc *doc,
                     const cli_worst_list *w, const char *which);
void cli_json_worst(FILE *f, const getme_doc *doc, const cli_worst_list *w);
/* After smoothing: worst corner line, worst lists (-v) and the warning when
   the worst elements have no free node; 0, or -1 if out of memory. */
int cli_log_after(const cli_log *log, getme_doc *doc, const double *q,
                  int32_t max_count, const getme_quality_stats *after,
                  const getme_result *res, cli_worst_list *worst,
                  cli_worst_list *worst_free);

/* More for the report: measures (smooth and gmsh), the worst elements
   (smooth only: they need the document); NULL members are left out. */
typedef struct cli_report_extra {
    const getme_doc *doc;
    const cli_worst_list *worst, *worst_free;
    const cli_measures *measures_before, *measures_after;
    const cli_ho_ratio *ho_before, *ho_after; /* "second_order" if n > 0 */
} cli_report_extra;

int cli_write_report(const char *path, const char *input, const char *output,
                     const getme_params *params, const cli_mesh_counts *mesh,
                     const getme_quality_stats *before,
                     const getme_quality_stats *after,
                     const getme_result *result, const cli_history *history,
                     const char *format_name, const cli_report_extra *extra);

/* The end of a smoothing command (smooth_end.c), after the library's last
   call: "Done optimizing", the quality and measure lines after, the worst
   elements, OUT written under the write guard, then the --report file
   (never over a file OUT just wrote).  The exit code, 0 on success. */
typedef struct cli_smooth_end {
    const char *input, *output;           /* as the user named them       */
    const cli_paths *paths;               /* checked by cli_check_paths   */
    getme_doc *doc;                       /* the smoothed document        */
    const getme_quality_stats *before;
    const cli_measures *mbefore;
    const cli_ho_ratio *ho_before;        /* NULL: none in the report     */
    int32_t worst;                        /* --worst N                    */
} cli_smooth_end;
int cli_smooth_end_run(const cli_smooth_opts *so, const cli_smooth_end *e,
                       const getme_result *res);
/* "Writing WHAT'OUT'...", the document to paths->out, "Done writing": 0,
   or the exit code after printing the error. */
int cli_write_doc(const cli_log *log, getme_doc *doc, const cli_paths *paths,
                  const char *output, const char *what);

#endif /* GETME_CLI_H */
