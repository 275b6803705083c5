/*
 * paths.c -- the one place that decides whether the getme command may
 * write an output or report file (every command that writes calls it), and
 * the signal guard around writing.
 *
 * Files are compared by device and inode, not by name: "in.msh",
 * "./in.msh", a hard link and a symbolic link to it are all the input.  A
 * file that does not exist yet is identified by its directory's device and
 * inode plus its name.
 */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <string.h>
#include <sys/stat.h>

typedef struct file_id {
    int exists;
    dev_t dev;
    ino_t ino;
    const char *name; /* last path component, when !exists */
} file_id;

static int identify(const char *path, file_id *id)
{
    struct stat sb;
    memset(id, 0, sizeof *id);
    if (stat(path, &sb) == 0) {
        id->exists = 1;
        id->dev = sb.st_dev;
        id->ino = sb.st_ino;
        return 0;
    }
    const char *slash = strrchr(path, '/');
    char dir[4096];
    getme_io_dirname(path, dir, sizeof dir);
    id->name = slash ? slash + 1 : path;
    if (stat(dir, &sb) != 0)
        return -1;
    id->dev = sb.st_dev;
    id->ino = sb.st_ino;
    return 0;
}

int cli_same_file(const char *a, const char *b)
{
    file_id x, y;
    if (!a || !b || identify(a, &x) != 0 || identify(b, &y) != 0)
        return 0;
    if (x.exists != y.exists || x.dev != y.dev || x.ino != y.ino)
        return 0;
    return x.exists || strcmp(x.name, y.name) == 0;
}

/* One file to be written: special files refused, symbolic links followed,
   directory writable. */
static int check_target(const char *what, const char *path, char *resolved,
                        size_t size)
{
    char msg[1200];
    getme_formats_status st =
        getme_io_output_path(path, resolved, size, msg, sizeof msg);
    if (st != GETME_FORMATS_OK)
        cli_error("%s %s", what, msg);
    return cli_exit_code(st);
}

int cli_check_paths(cli_paths *p)
{
    int code = 0;
    if (p->output && (code = check_target("output", p->output, p->out,
                                          sizeof p->out)) != 0)
        return code;
    if (p->report && (code = check_target("report", p->report, p->rep,
                                          sizeof p->rep)) != 0)
        return code;
    const getme_format *format = p->input ? getme_format_for(p->input) : NULL;
    if (p->output && format && !getme_format_has_extension(format, p->output)) {
        cli_error("output %s: the input is a %s file, so the output must be "
                  "one too (%s); getme does not convert formats",
                  p->output, getme_format_name(format),
                  getme_format_extensions(format));
        return EXIT_USAGE;
    }
    if (p->output && cli_same_file(p->input, p->out)) {
        cli_error("output %s: refusing to overwrite the input; choose another "
                  "output file", p->output);
        return EXIT_USAGE;
    }
    if (p->report && cli_same_file(p->input, p->rep)) {
        cli_error("report %s: refusing to overwrite the input; choose another "
                  "report file", p->report);
        return EXIT_USAGE;
    }
    if (p->report && p->output && cli_same_file(p->out, p->rep)) {
        cli_error("report %s: it is the output file; choose another report "
                  "file", p->report);
        return EXIT_USAGE;
    }
    return 0;
}

int cli_check_read_files(const cli_paths *p, const getme_doc *doc)
{
    for (size_t i = 1; i < getme_doc_num_files(doc); i++) {
        const char *f = getme_doc_file(doc, i);
        if (p->output && cli_same_file(f, p->out)) {
            cli_error("output %s: refusing to overwrite '%s', which the input "
                      "includes; choose another output file", p->output, f);
            return EXIT_USAGE;
        }
        if (p->report && cli_same_file(f, p->rep)) {
            cli_error("report %s: refusing to overwrite '%s', which the input "
                      "includes; choose another report file", p->report, f);
            return EXIT_USAGE;
        }
    }
    return 0;
}

void cli_stamp(const char *path, cli_file_stamp *s)
{
    struct stat sb;
    memset(s, 0, sizeof *s);
    if (path && stat(path, &sb) == 0) {
        s->exists = 1;
        s->dev = (uint64_t)sb.st_dev;
        s->ino = (uint64_t)sb.st_ino;
    }
}

int cli_replaced(const char *path, const cli_file_stamp *before)
{
    cli_file_stamp now;
    cli_stamp(path, &now);
    return now.exists && (!before->exists || now.dev != before->dev ||
                          now.ino != before->ino);
}

/* Termination signals wait while files are written, so that a Ctrl-C or
   kill leaves either the complete output or nothing (never a temporary
   file); they take their usual effect once writing ends.  Only SIGKILL and
   a power loss can leave a temporary file (".<output>.getme-tmp.<pid>.<n>");
   the next write of that output removes it.

   Blocking the signals with sigprocmask is not enough: the mask is per
   thread, and a signal sent to the process goes to any thread that does
   not block it (the OpenMP workers).  So a handler decides, in whatever
   thread it runs.  Its two flags are the command's only process-wide
   state: a signal handler has no other way to reach its caller. */
static volatile sig_atomic_t writing, pending;

static const int SIGNALS[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

static void die_now(int sig)
{
    signal(sig, SIG_DFL);
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, sig);
    pthread_sigmask(SIG_UNBLOCK, &set, NULL);
    raise(sig);
}

static void on_signal(int sig)
{
    if (writing)
        pending = sig;
    else
        die_now(sig);
}

void cli_write_guard(cli_guard *g, int on)
{
    if (on) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigfillset(&sa.sa_mask);
        g->active = 1;
        for (size_t i = 0; i < sizeof SIGNALS / sizeof *SIGNALS; i++) {
            struct sigaction old;
            /* a signal the user's shell ignores (nohup) stays ignored */
            if (sigaction(SIGNALS[i], NULL, &old) == 0 &&
                old.sa_handler != SIG_IGN)
                sigaction(SIGNALS[i], &sa, NULL);
        }
        writing = 1;
    } else if (g->active) {
        writing = 0;
        g->active = 0;
        int sig = pending;
        if (sig)
            die_now(sig);
        for (size_t i = 0; i < sizeof SIGNALS / sizeof *SIGNALS; i++) {
            struct sigaction old;
            if (sigaction(SIGNALS[i], NULL, &old) == 0 &&
                old.sa_handler == on_signal)
                signal(SIGNALS[i], SIG_DFL);
        }
    }
}
