/*
 * doc.c -- the format-independent side of the adapters: choosing an
 * adapter, checking the mesh it built, temp-file-and-rename writing.
 */
#define _XOPEN_SOURCE 700
#include "adapter.h"
#include "getme_alloc.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static const getme_format *const FORMATS[] = {
    &getme__format_msh,
    &getme__format_inp,
#ifdef GETME_HAVE_FORMAT_CGNS
    &getme__format_cgns,
#endif
    NULL};

const getme_format *const *getme_formats(void) { return FORMATS; }

const getme_format *getme_format_for(const char *path)
{
    for (int i = 0; FORMATS[i]; i++)
        if (FORMATS[i]->probe(path))
            return FORMATS[i];
    return NULL;
}

const char *getme_format_name(const getme_format *format)
{
    return format ? format->name : "";
}

const char *getme_format_description(const getme_format *format)
{
    return format ? format->description : "";
}

const char *getme_format_extensions(const getme_format *format)
{
    return format && format->extensions ? format->extensions : "";
}

const char *getme_formats_status_string(getme_formats_status st)
{
    switch (st) {
    case GETME_FORMATS_OK: return "ok";
    case GETME_FORMATS_ERR_OPEN: return "cannot open the input";
    case GETME_FORMATS_ERR_PARSE: return "malformed input";
    case GETME_FORMATS_ERR_UNSUPPORTED: return "unsupported content";
    case GETME_FORMATS_ERR_INVALID: return "invalid elements";
    case GETME_FORMATS_ERR_WRITE: return "cannot write the output";
    case GETME_FORMATS_ERR_ARGUMENT: return "bad argument";
    case GETME_FORMATS_ERR_INTERNAL: return "internal error";
    }
    return "unknown status";
}

void getme_doc_options_init(getme_doc_options *opts)
{
    memset(opts, 0, sizeof *opts);
    opts->fix_skin = 1;
    opts->fix_interfaces = 1;
}

getme_formats_status getme_doc_fail(getme_doc *doc, getme_formats_status status,
                               const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(doc->error, sizeof doc->error, fmt, ap);
    va_end(ap);
    return status;
}

void getme_doc_set_info(getme_doc *doc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(doc->info, sizeof doc->info, fmt, ap);
    va_end(ap);
}

void getme_doc_set_mesh(getme_doc *doc, getme_mesh *mesh, int64_t *elem_ids)
{
    getme_mesh_free(doc->mesh);
    free(doc->elem_ids);
    doc->mesh = mesh;
    doc->elem_ids = elem_ids;
    doc->elem_id_shift = 0;
}

void getme_doc_set_impl(getme_doc *doc, void *impl) { doc->impl = impl; }

void *getme_doc_impl(const getme_doc *doc) { return doc ? doc->impl : NULL; }

const char *getme_doc_error(const getme_doc *doc)
{
    return doc ? doc->error : "out of memory";
}

const char *getme_doc_info(const getme_doc *doc) { return doc ? doc->info : ""; }

const char *getme_doc_warning(const getme_doc *doc)
{
    return doc ? doc->warning : "";
}

getme_mesh *getme_doc_mesh(getme_doc *doc) { return doc ? doc->mesh : NULL; }

const getme_format *getme_doc_format(const getme_doc *doc)
{
    return doc ? doc->format : NULL;
}

const char *getme_doc_path(const getme_doc *doc)
{
    return doc && doc->path ? doc->path : "";
}

const getme_quality_stats *getme_doc_stats(const getme_doc *doc)
{
    return doc && doc->have_stats ? &doc->stats : NULL;
}

uint64_t getme_doc_node_id(const getme_doc *doc, int32_t i)
{
    return doc->node_ids ? doc->node_ids[i] : 0;
}

int32_t getme_doc_element_region(const getme_doc *doc, int32_t e)
{
    return doc->elem_region ? doc->elem_region[e] : -1;
}

int getme_doc_num_partitions(const getme_doc *doc)
{
    return doc->num_partitions;
}

int64_t getme_doc_element_id(const getme_doc *doc, int32_t e)
{
    return doc->elem_ids ? doc->elem_ids[e]
                         : (int64_t)e + 1 + doc->elem_id_shift;
}

/* Name the first invalid elements by their ids in the file. */
getme_formats_status getme_doc_check(getme_doc *doc, const double *q)
{
    if (!doc || !doc->mesh)
        return GETME_FORMATS_ERR_INTERNAL;
    getme_quality_stats *sp = &doc->stats;
    if ((q ? getme_mesh_quality_stats_from(doc->mesh, q, -1, sp)
           : getme_mesh_quality_stats(doc->mesh, -1, sp)) != GETME_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "%s: out of memory",
                              doc->path);
    doc->have_stats = 1;
    if (sp->num_invalid == 0)
        return GETME_FORMATS_OK;
    char list[256] = "";
    size_t len = 0;
    for (int i = 0; i < sp->num_reported_invalid && len < sizeof list; i++) {
        long long id = (long long)getme_doc_element_id(doc, sp->first_invalid[i]);
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%lld",
                                i ? ", " : "", id);
    }
    return getme_doc_fail(doc, GETME_FORMATS_ERR_INVALID,
                          "%s: %lld invalid (inverted or degenerate) element%s, "
                          "first: %s%s; getme smooths valid meshes only",
                          doc->path, (long long)sp->num_invalid,
                          sp->num_invalid == 1 ? "" : "s", list,
                          sp->num_invalid > sp->num_reported_invalid ? ", ..." : "");
}

/* Forget what a declining adapter left in the document. */
static void reset(getme_doc *doc)
{
    if (doc->format && doc->format->close)
        doc->format->close(doc);
    getme_doc_set_mesh(doc, NULL, NULL);
    free(doc->node_ids);
    free(doc->elem_region);
    doc->node_ids = NULL;
    doc->elem_region = NULL;
    doc->num_partitions = 0;
    doc->impl = NULL;
    doc->format = NULL;
    doc->info[0] = doc->warning[0] = 0;
}

/* The built-in adapters, then the caller's, in order: the first that takes
   the path and does not decline the file opens it. */
static getme_formats_status open_with_adapters(getme_doc *doc,
                                          const getme_doc_options *opts)
{
    const getme_format *const *extra = opts->adapters;
    int declined = 0;
    for (int k = 0;; k++) {
        const getme_format *f = NULL;
        int nb = (int)(sizeof FORMATS / sizeof *FORMATS) - 1;
        if (k < nb)
            f = FORMATS[k];
        else if (extra && extra[k - nb])
            f = extra[k - nb];
        else
            break;
        if (!f->probe(doc->path))
            continue;
        doc->format = f;
        getme_formats_status st = f->open(doc, opts);
        if (st != GETME_FORMATS_DECLINED)
            return st;
        reset(doc);
        declined = 1;
    }
    if (declined) /* the message of the last adapter that declined */
        return GETME_FORMATS_ERR_UNSUPPORTED;
    char names[128] = "";
    size_t len = 0;
    for (int i = 0; FORMATS[i] && len < sizeof names; i++)
        len += (size_t)snprintf(names + len, sizeof names - len, "%s%s",
                                i ? ", " : "", FORMATS[i]->name);
    return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                          "%s: unknown file format (supported: %s)",
                          doc->path, names);
}

/* Element ids that are one consecutive run (the usual case: Gmsh numbers
   a volume's elements in order) need no table; the table is 64-bit per
   element and would otherwise stay allocated through the smoothing. */
static void compact_ids(getme_doc *doc)
{
    int32_t n = getme_mesh_num_elements(doc->mesh);
    /* second-order meshes keep the table (their ids index it otherwise) */
    if (!doc->elem_ids || n <= 0 || getme_mesh_num_elements_ho(doc->mesh))
        return;
    int64_t shift = doc->elem_ids[0] - 1;
    for (int32_t e = 1; e < n; e++)
        if (doc->elem_ids[e] - e - 1 != shift)
            return;
    free(doc->elem_ids);
    doc->elem_ids = NULL;
    doc->elem_id_shift = shift;
}

getme_formats_status getme_doc_open(getme_doc **out, const char *path,
                               const getme_doc_options *opts)
{
    getme_doc_options defaults;
    if (!opts) {
        getme_doc_options_init(&defaults);
        opts = &defaults;
    }
    getme_doc *doc = getme__calloc(1, sizeof *doc);
    *out = doc;
    if (!doc)
        return GETME_FORMATS_ERR_INTERNAL;
    doc->path = strdup(path ? path : "");
    if (!doc->path)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "out of memory");
    struct stat sb;
    if (stat(path, &sb) != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "%s: %s", path,
                              strerror(errno));
    if (S_ISDIR(sb.st_mode))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "%s: is a directory",
                              path);
    if (access(path, R_OK) != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "%s: %s", path,
                              strerror(errno));
    getme_formats_status st = open_with_adapters(doc, opts);
    if (st != GETME_FORMATS_OK)
        return st;
    if (!doc->mesh)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                              "%s: the %s adapter built no mesh", path,
                              doc->format->name);
    compact_ids(doc);
    return opts->defer_check ? GETME_FORMATS_OK : getme_doc_check(doc, NULL);
}

getme_formats_status getme_doc_write(getme_doc *doc, const char *out_path)
{
    if (!doc || !doc->format || !doc->mesh)
        return GETME_FORMATS_ERR_INTERNAL;
    char target[4096], msg[sizeof doc->error];
    getme_formats_status st =
        getme_io_output_path(out_path, target, sizeof target, msg, sizeof msg);
    if (st != GETME_FORMATS_OK)
        return getme_doc_fail(doc, st, "%s", msg);
    for (size_t i = 0; i < getme_doc_num_files(doc); i++)
        if (getme_io_same_file(getme_doc_file(doc, i), target))
            return getme_doc_fail(doc, GETME_FORMATS_ERR_ARGUMENT,
                                  "%s: refusing to overwrite the input%s%s; "
                                  "choose another output file", out_path,
                                  i ? " file " : "", i ? getme_doc_file(doc, i) : "");
    return doc->format->write(doc, target);
}

size_t getme_doc_num_files(const getme_doc *doc)
{
    if (!doc || !doc->path)
        return 0;
    size_t n = 1;
    if (doc->format && doc->format->file && doc->impl)
        while (doc->format->file(doc, n))
            n++;
    return n;
}

const char *getme_doc_file(const getme_doc *doc, size_t i)
{
    if (!doc || !doc->path)
        return NULL;
    if (i == 0)
        return doc->path;
    return doc->format && doc->format->file && doc->impl
               ? doc->format->file(doc, i)
               : NULL;
}

int getme_format_has_extension(const getme_format *format, const char *path)
{
    if (!format || !format->extensions || !path)
        return 0;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot || dot == base)
        return 0;
    size_t n = strlen(dot);
    for (const char *e = format->extensions; *e;) {
        size_t m = strcspn(e, " ");
        if (m == n && strncasecmp(e, dot, n) == 0)
            return 1;
        e += m;
        while (*e == ' ')
            e++;
    }
    return 0;
}

void getme_doc_close(getme_doc *doc)
{
    if (!doc)
        return;
    if (doc->format && doc->format->close)
        doc->format->close(doc);
    getme_mesh_free(doc->mesh);
    free(doc->elem_ids);
    free(doc->node_ids);
    free(doc->elem_region);
    free(doc->path);
    free(doc);
}

void getme_io_dirname(const char *path, char *buf, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(buf, size, ".");
    else
        snprintf(buf, size, "%.*s", slash == path ? 1 : (int)(slash - path),
                 path);
}

/* "<dir>/.<base>.getme-tmp.<pid>.<n>" (the Gmsh path appends ".msh"). */
static const char TMP_TAG[] = ".getme-tmp.";

/* A temporary file of ours for base (".<base>.getme-tmp.<pid>.<n>[.ext]")
   whose process is gone: left by a process that was killed (SIGKILL, power
   loss) while writing.  Returns its pid, or 0 if name is not such a file. */
static long stale_tmp(const char *name, const char *base, size_t blen)
{
    size_t tlen = sizeof TMP_TAG - 1;
    if (name[0] != '.' || strncmp(name + 1, base, blen) != 0 ||
        strncmp(name + 1 + blen, TMP_TAG, tlen) != 0)
        return 0;
    const char *p = name + 1 + blen + tlen;
    char *end;
    errno = 0;
    long pid = strtol(p, &end, 10);
    if (errno || end == p || *end != '.' || pid <= 0 || pid == (long)getpid())
        return 0;
    p = end + 1;
    strtoul(p, &end, 10);
    if (end == p || (*end && *end != '.'))
        return 0;
    if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
        return 0; /* alive (or not ours to judge) */
    return pid;
}

/* Remove the temporary files a killed getme left next to out_path. */
static void remove_stale_tmps(const char *out_path, const char *base)
{
    char dir[4096], path[4096 + 256];
    getme_io_dirname(out_path, dir, sizeof dir);
    DIR *d = opendir(dir);
    if (!d)
        return;
    size_t blen = strlen(base);
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (stale_tmp(e->d_name, base, blen) &&
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name) <
                (int)sizeof path)
            unlink(path);
    closedir(d);
}

int getme_io_tmp_path(const char *out_path, char *buf, size_t size)
{
    /* Same directory as the output, so rename() is atomic and never crosses
       file systems; hidden, and named ".<output name>.getme-tmp.<pid>.<n>"
       so that one left by a killed process is recognisable (the next write
       of the same output removes those whose process is gone).  O_EXCL
       makes the name ours even with concurrent writers; mode 0666 lets the
       umask decide the output's permissions as for any new file (mkstemp
       would leave 0600).  The empty file is overwritten by the adapter (or
       removed by getme_io_commit). */
    const char *slash = strrchr(out_path, '/');
    int dirlen = slash ? (int)(slash - out_path) + 1 : 0;
    const char *base = slash ? slash + 1 : out_path;
    remove_stale_tmps(out_path, base);
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    for (unsigned attempt = 0; attempt < 100; attempt++) {
        unsigned long tag = (unsigned long)ts.tv_nsec + attempt * 7919ul;
        int len = snprintf(buf, size, "%.*s.%s%s%ld.%lu", dirlen, out_path,
                           base, TMP_TAG, (long)getpid(), tag);
        if (len < 0 || (size_t)len >= size)
            return -1;
        int fd = open(buf, O_WRONLY | O_CREAT | O_EXCL, 0666);
        if (fd >= 0) {
            close(fd);
            return 0;
        }
        if (errno != EEXIST)
            return -1;
    }
    return -1;
}

int getme_io_commit(const char *tmp, const char *out)
{
    /* Never replace anything but a regular file: a device, a FIFO, a
       directory or a symbolic link named as an output stays as it is. */
    struct stat sb;
    if (lstat(out, &sb) == 0 && !S_ISREG(sb.st_mode)) {
        remove(tmp);
        errno = EEXIST;
        return -1;
    }
    if (rename(tmp, out) == 0)
        return 0;
    int saved = errno;
    remove(tmp);
    errno = saved;
    return -1;
}

static const char *kind_of(mode_t m)
{
    return S_ISCHR(m)    ? "a character device"
           : S_ISBLK(m)  ? "a block device"
           : S_ISFIFO(m) ? "a FIFO"
           : S_ISSOCK(m) ? "a socket"
           : S_ISDIR(m)  ? "a directory"
                         : "not a regular file";
}

getme_formats_status getme_io_output_path(const char *out_path, char *buf,
                                     size_t size, char *msg, size_t msg_size)
{
    struct stat sb;
    if (!out_path || !*out_path) {
        snprintf(msg, msg_size, "empty output file name");
        return GETME_FORMATS_ERR_ARGUMENT;
    }
    if (snprintf(buf, size, "%s", out_path) >= (int)size) {
        snprintf(msg, msg_size, "%s: path too long", out_path);
        return GETME_FORMATS_ERR_ARGUMENT;
    }
    if (lstat(out_path, &sb) == 0 && S_ISLNK(sb.st_mode)) {
        /* A symbolic link is followed: the file it points to is written
           (through a temporary file next to it), the link stays. */
        char *real = realpath(out_path, NULL);
        if (!real) {
            snprintf(msg, msg_size,
                     "%s: a symbolic link to a missing file; give the "
                     "path of the file to write", out_path);
            return GETME_FORMATS_ERR_ARGUMENT;
        }
        int len = snprintf(buf, size, "%s", real);
        free(real);
        if (len >= (int)size) {
            snprintf(msg, msg_size, "%s: path too long", out_path);
            return GETME_FORMATS_ERR_ARGUMENT;
        }
    }
    if (stat(buf, &sb) == 0 && !S_ISREG(sb.st_mode)) {
        snprintf(msg, msg_size,
                 "%s: is %s; getme writes regular files only (it writes a "
                 "temporary file and renames it)",
                 out_path, kind_of(sb.st_mode));
        return GETME_FORMATS_ERR_ARGUMENT;
    }
    char dir[4096];
    getme_io_dirname(buf, dir, sizeof dir);
    if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode) ||
        access(dir, W_OK | X_OK) != 0) {
        int e = errno;
        snprintf(msg, msg_size,
                 "%s: cannot create a temporary file next to it: %s",
                 out_path, strerror(stat(dir, &sb) == 0 && !S_ISDIR(sb.st_mode)
                                        ? ENOTDIR
                                        : e));
        return GETME_FORMATS_ERR_WRITE;
    }
    return GETME_FORMATS_OK;
}

int getme_io_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!a || !b || stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}
