/*
 * cgns_load.c -- the CGNS adapter as libgetme_formats sees it: the probe
 * (extension and magic bytes, no libcgns) and an adapter that loads the
 * real one, the module libgetme_cgns.so beside this library, when a CGNS
 * file is opened.
 *
 * Why a module: libcgns brings HDF5 and, through it, curl, GnuTLS,
 * OpenSSL, Kerberos and LDAP, some 40 libraries and ~6 MiB resident
 * (docs/bench.md, session 15), and their loading, into every program that
 * links libgetme_formats, also for the MSH and INP files that never call
 * them.  Loaded with dlopen() per document (reference-counted by the
 * loader, kept in memory once loaded: RTLD_NODELETE, as HDF5 registers
 * exit handlers), so no state of ours is global.
 */
#define _GNU_SOURCE /* dladdr, RTLD_NODELETE */
#include "adapter.h"
#include "cgns_magic.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CGNS_MODULE "libgetme_cgns.so"

/* ---- probe -------------------------------------------------------------- */

static int has_extension(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext);
    if (n <= m || path[n - m - 1] != '.')
        return 0;
    for (size_t i = 0; i < m; i++) {
        char c = path[n - m + i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != ext[i])
            return 0;
    }
    return 1;
}

static int cgns_probe(const char *path)
{
    if (has_extension(path, "cgns") || has_extension(path, "cgn"))
        return 1;
    int kind = cgns_magic(path);
    return kind == MAGIC_ADF || kind == MAGIC_HDF5_CGNS;
}

/* ---- the module ---------------------------------------------------------- */

/* Load the module for doc (once per document): from the folder of this
   library, then the loader's search path. */
static getme_formats_status load(getme_doc *doc)
{
    if (doc->module_format)
        return GETME_FORMATS_OK;
    char path[PATH_MAX + sizeof CGNS_MODULE];
    Dl_info info;
    void *h = NULL;
    if (dladdr((const void *)&getme__format_cgns, &info) && info.dli_fname) {
        const char *slash = strrchr(info.dli_fname, '/');
        int len = slash ? (int)(slash - info.dli_fname) + 1 : 0;
        if (len < PATH_MAX) {
            snprintf(path, sizeof path, "%.*s%s", len, info.dli_fname,
                     CGNS_MODULE);
            h = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
        }
    }
    if (!h)
        h = dlopen(CGNS_MODULE, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    const getme_format *f = h ? dlsym(h, "getme_cgns_module") : NULL;
    if (!f) {
        const char *why = dlerror();
        if (h)
            dlclose(h);
        return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "%s: CGNS support is not installed (%s: %s)",
                              doc->path, CGNS_MODULE, why ? why : "not found");
    }
    doc->module = h;
    doc->module_format = f;
    return GETME_FORMATS_OK;
}

static getme_formats_status cgns_open(getme_doc *doc,
                                      const getme_doc_options *opts)
{
    getme_formats_status st = load(doc);
    return st == GETME_FORMATS_OK ? doc->module_format->open(doc, opts) : st;
}

static getme_formats_status cgns_write(getme_doc *doc, const char *out_path)
{
    if (!doc->module_format)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                              "%s: document was not read", doc->path);
    return doc->module_format->write(doc, out_path);
}

static void cgns_close(getme_doc *doc)
{
    if (!doc->module_format)
        return;
    doc->module_format->close(doc);
    dlclose(doc->module);
    doc->module = NULL;
    doc->module_format = NULL;
}

static const char *cgns_file(const getme_doc *doc, size_t i)
{
    return doc->module_format && doc->module_format->file
               ? doc->module_format->file(doc, i)
               : NULL;
}

const getme_format getme__format_cgns = {
    "cgns",
    "CGNS (ADF and HDF5; unstructured zones, via libcgns)",
    cgns_probe,
    cgns_open,
    cgns_write,
    cgns_close,
    ".cgns .cgn",
    cgns_file,
};
