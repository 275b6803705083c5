/*
 * cgns_format.c -- the CGNS adapter (the module libgetme_cgns.so, which
 * cgns_load.c loads): unstructured zones of ADF and HDF5 CGNS files, read
 * through libcgns (Debian libcgns-dev 3.4), written back by overwriting
 * only the coordinate arrays of a byte copy.
 * See docs/cgns.md for what is read, what is fixed and what is refused.
 */
#define _POSIX_C_SOURCE 200809L /* fstat's st_mtim */

#include "cgns_internal.h"
#include "getme_alloc.h"
#include "cgns_magic.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* libcgns calls this for errors (is_error = 1) and warnings (0).  Without a
   handler it prints warnings to stderr; errors are read back with
   cg_get_error() where they happen, so there is nothing to do here. */
static void cgns_silent(int is_error, char *msg)
{
    (void)is_error;
    (void)msg;
}

void cgns_quiet(void)
{
    cg_error_handler(cgns_silent);
}

/* ---- open / close ------------------------------------------------------- */

static void free_impl(cgns_impl *impl)
{
    if (!impl)
        return;
    for (int z = 0; z < impl->num_zones; z++) {
        free(impl->zones[z].conn_offset);
        free(impl->zones[z].conn);
        free(impl->zones[z].conn_type);
    }
    free(impl->zones);
    free(impl->blocks);
    free(impl->regions);
    free(impl->sets);
    free(impl->orig);
    free(impl);
}

/* The file must exist, be a regular readable file, and look like CGNS,
   before libcgns sees it (its messages for these cases are cryptic). */
static getme_formats_status check_input(getme_doc *doc, cgns_impl *impl)
{
    struct stat sb;
    FILE *f;

    if (stat(doc->path, &sb) != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "%s: %s", doc->path,
                              strerror(errno));
    if (!S_ISREG(sb.st_mode))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "%s: not a regular file",
                              doc->path);
    if (!(f = fopen(doc->path, "rb")))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "%s: %s", doc->path,
                              strerror(errno));
    fclose(f);
    impl->in_size = (int64_t)sb.st_size;
    impl->in_dev = (uint64_t)sb.st_dev;
    impl->in_ino = (uint64_t)sb.st_ino;
    impl->in_mtime_ns = (int64_t)sb.st_mtim.tv_sec * 1000000000 +
                        sb.st_mtim.tv_nsec;
    switch (cgns_magic(doc->path)) {
    case MAGIC_NONE:
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: not a CGNS file (%s)", doc->path,
                              sb.st_size == 0 ? "empty"
                                              : "neither ADF nor HDF5");
    case MAGIC_HDF5:
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: an HDF5 file without a CGNSLibraryVersion "
                              "node: not a CGNS file (meshio's CGNS writer, "
                              "for one, writes such files)", doc->path);
    default:
        return GETME_FORMATS_OK;
    }
}

static getme_formats_status cgns_open(getme_doc *doc, const getme_doc_options *opts)
{
    cgns_impl *impl = getme__calloc(1, sizeof *impl);
    getme_formats_status st;
    int fn;

    if (!impl)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "%s: out of memory",
                              doc->path);
    doc->impl = impl;
    cgns_quiet();
    if ((st = check_input(doc, impl)) != GETME_FORMATS_OK)
        return st;
    if (cg_open(doc->path, CG_MODE_READ, &fn) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: libcgns cannot read the file (truncated or "
                              "damaged?): %s", doc->path, cgns_error());
    if (cg_get_file_type(fn, &impl->file_type) != CG_OK)
        impl->file_type = CG_FILE_NONE;
    st = cgns_read(doc, impl, fn, opts);
    if (st == GETME_FORMATS_OK)
        st = cgns_check_links(doc, impl, fn);
    cg_close(fn);
    return st;
}

static getme_formats_status cgns_write_doc(getme_doc *doc, const char *out_path)
{
    if (!doc->impl || !doc->mesh)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                              "%s: document was not read", doc->path);
    return cgns_write(doc, out_path);
}

static void cgns_close(getme_doc *doc)
{
    free_impl(doc->impl);
    doc->impl = NULL;
}

/* The module's adapter (cgns_load.c loads it; its probe and names are
   cgns_load.c's). */
__attribute__((visibility("default"))) const getme_format getme_cgns_module = {
    "cgns",
    "CGNS (ADF and HDF5; unstructured zones, via libcgns)",
    NULL,
    cgns_open,
    cgns_write_doc,
    cgns_close,
    ".cgns .cgn",
    NULL,
};
