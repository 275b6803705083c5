/*
 * doc.c -- the format-independent side of the adapters: choosing an
 * adapter, checking the mesh it built, temp-file-and-rename writing.
 */
#define _POSIX_C_SOURCE 200809L
#include "getme_formats.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static const getme_format *const FORMATS[] = {
#ifdef GETME_HAVE_FORMAT_MSH
    &getme_format_msh,
#endif
#ifdef GETME_HAVE_FORMAT_INP
    &getme_format_inp,
#endif
#ifdef GETME_HAVE_FORMAT_CGNS
    &getme_format_cgns,
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

void getme_doc_options_init(getme_doc_options *opts)
{
    memset(opts, 0, sizeof *opts);
    opts->fix_skin = 1;
    opts->fix_interfaces = 1;
}

getme_io_status getme_doc_fail(getme_doc *doc, getme_io_status status,
                               const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(doc->error, sizeof doc->error, fmt, ap);
    va_end(ap);
    return status;
}

const char *getme_doc_error(const getme_doc *doc)
{
    return doc ? doc->error : "out of memory";
}

const char *getme_doc_info(const getme_doc *doc) { return doc ? doc->info : ""; }

getme_mesh *getme_doc_mesh(getme_doc *doc) { return doc ? doc->mesh : NULL; }

int64_t getme_doc_element_id(const getme_doc *doc, int32_t e)
{
    return doc->elem_ids ? doc->elem_ids[e] : (int64_t)e + 1;
}

/* Name the first invalid elements by their ids in the file. */
static getme_io_status check_valid(getme_doc *doc)
{
    getme_quality_stats *sp = &doc->stats;
    if (getme_mesh_quality_stats(doc->mesh, -1, sp) != GETME_OK)
        return getme_doc_fail(doc, GETME_IO_ERR_INTERNAL, "%s: out of memory",
                              doc->path);
    if (sp->num_invalid == 0)
        return GETME_IO_OK;
    char list[256] = "";
    size_t len = 0;
    for (int i = 0; i < sp->num_reported_invalid && len < sizeof list; i++) {
        long long id = (long long)getme_doc_element_id(doc, sp->first_invalid[i]);
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%lld",
                                i ? ", " : "", id);
    }
    return getme_doc_fail(doc, GETME_IO_ERR_INVALID,
                          "%s: %lld invalid (inverted or degenerate) element%s, "
                          "first: %s%s; getme smooths valid meshes only",
                          doc->path, (long long)sp->num_invalid,
                          sp->num_invalid == 1 ? "" : "s", list,
                          sp->num_invalid > sp->num_reported_invalid ? ", ..." : "");
}

getme_io_status getme_doc_open(getme_doc **out, const char *path,
                               const getme_doc_options *opts)
{
    getme_doc_options defaults;
    if (!opts) {
        getme_doc_options_init(&defaults);
        opts = &defaults;
    }
    getme_doc *doc = calloc(1, sizeof *doc);
    *out = doc;
    if (!doc)
        return GETME_IO_ERR_INTERNAL;
    doc->path = strdup(path ? path : "");
    if (!doc->path)
        return getme_doc_fail(doc, GETME_IO_ERR_INTERNAL, "out of memory");
    struct stat sb;
    if (stat(path, &sb) != 0)
        return getme_doc_fail(doc, GETME_IO_ERR_OPEN, "%s: %s", path,
                              strerror(errno));
    if (S_ISDIR(sb.st_mode))
        return getme_doc_fail(doc, GETME_IO_ERR_OPEN, "%s: is a directory",
                              path);
    if (access(path, R_OK) != 0)
        return getme_doc_fail(doc, GETME_IO_ERR_OPEN, "%s: %s", path,
                              strerror(errno));
    doc->format = getme_format_for(path);
    if (!doc->format) {
        char names[128] = "";
        size_t len = 0;
        for (int i = 0; FORMATS[i] && len < sizeof names; i++)
            len += (size_t)snprintf(names + len, sizeof names - len, "%s%s",
                                    i ? ", " : "", FORMATS[i]->name);
        return getme_doc_fail(doc, GETME_IO_ERR_UNSUPPORTED,
                              "%s: unknown file format (supported: %s)", path,
                              names);
    }
    getme_io_status st = doc->format->open(doc, opts);
    if (st != GETME_IO_OK)
        return st;
    if (!doc->mesh)
        return getme_doc_fail(doc, GETME_IO_ERR_INTERNAL,
                              "%s: the %s adapter built no mesh", path,
                              doc->format->name);
    return check_valid(doc);
}

getme_io_status getme_doc_write(getme_doc *doc, const char *out_path)
{
    if (!doc || !doc->format || !doc->mesh)
        return GETME_IO_ERR_INTERNAL;
    if (getme_io_same_file(doc->path, out_path))
        return getme_doc_fail(doc, GETME_IO_ERR_USAGE,
                              "%s: refusing to overwrite the input; choose "
                              "another output file", out_path);
    return doc->format->write(doc, out_path);
}

void getme_doc_close(getme_doc *doc)
{
    if (!doc)
        return;
    if (doc->format && doc->format->close)
        doc->format->close(doc);
    getme_mesh_free(doc->mesh);
    free(doc->elem_ids);
    free(doc->path);
    free(doc);
}

int getme_io_tmp_path(const char *out_path, char *buf, size_t size)
{
    /* Same directory as the output, so rename() is atomic and never crosses
       file systems; hidden.  O_EXCL makes the name ours even with concurrent
       writers; mode 0666 lets the umask decide the output's permissions as
       for any new file (mkstemp would leave 0600).  The empty file is
       overwritten by the adapter (or removed by getme_io_commit). */
    const char *slash = strrchr(out_path, '/');
    int dirlen = slash ? (int)(slash - out_path) + 1 : 0;
    const char *base = slash ? slash + 1 : out_path;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    for (unsigned attempt = 0; attempt < 100; attempt++) {
        unsigned long tag = (unsigned long)ts.tv_nsec + attempt * 7919ul;
        int len = snprintf(buf, size, "%.*s.%s.tmp.%ld.%lu", dirlen, out_path,
                           base, (long)getpid(), tag);
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
    if (rename(tmp, out) == 0)
        return 0;
    int saved = errno;
    remove(tmp);
    errno = saved;
    return -1;
}

int getme_io_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!a || !b || stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}
