/*
 * msh_format.c -- the native Gmsh MSH adapter: MSH 4.1 and 2.2, ASCII or
 * binary, read by msh41_reader.c in one streaming pass without a Gmsh model
 * (a Gmsh model of a 4M-tet mesh costs about 1 GiB) and written by
 * msh41_writer.c as a copy of the input with new coordinates in $Nodes.
 * Fixed nodes, regions and element order come from the model builder the
 * Gmsh-SDK path uses too (formats/model), so both paths smooth a file alike.
 *
 * Files it does not read (MSH 4.0, parametric nodes, partitioned meshes,
 * planar meshes outside a plane z = const, element types it does not
 * know...) are declined: getme_doc_open hands them to the next adapter, the
 * Gmsh plugin's (plugin/src/gmsh_format.c) when the program passed it in
 * getme_doc_options.adapters, as the getme command does.
 * The environment variable GETME_MSH_READER=gmsh declines every file (the
 * Gmsh path reads it), GETME_MSH_READER=native makes a file it would
 * decline an error; anything else, or unset, means "native if it can".
 */
#include "msh41_internal.h"
#include "getme_alloc.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct msh_impl {
    msh41_doc *native;
    double version;      /* 2.2, 4.1 ... as in $MeshFormat */
    int binary;
} msh_impl;

/* "$MeshFormat" then "version file-type data-size". */
static getme_formats_status read_header(getme_doc *doc, msh_impl *impl)
{
    int rc = getme__msh_header(doc->path, &impl->version, &impl->binary);
    if (rc == -1)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "Cannot open '%s': %s",
                              doc->path, strerror(errno));
    if (rc != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "'%s', line 1: not a Gmsh MSH file (no "
                              "$MeshFormat header)",
                              doc->path);
    if (impl->version != 2.2 && impl->version != 4.0 && impl->version != 4.1)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "'%s': MSH version %g is not supported (2.2, "
                              "4.0 and 4.1 are)",
                              doc->path, impl->version);
    return GETME_FORMATS_OK;
}

/* GETME_MSH_READER: 'g' = gmsh only, 'n' = native only, 0 = native if it
   can, else Gmsh. */
static char reader_choice(void)
{
    const char *v = getenv("GETME_MSH_READER");
    if (v && strcmp(v, "gmsh") == 0)
        return 'g';
    if (v && strcmp(v, "native") == 0)
        return 'n';
    return 0;
}

/* The native reader; GETME_FORMATS_DECLINED (with the reason as the
   message) for a file it does not read. */
static getme_formats_status open_native(getme_doc *doc, msh_impl *impl,
                                   const getme_doc_options *opts, char choice)
{
    char why[160] = "";
    int eligible = 1;
    int native = impl->version == 4.1 || impl->version == 2.2;
    if (!native)
        snprintf(why, sizeof why, "MSH %g", impl->version);
    getme_formats_status st =
        native
            ? msh41_open(doc, opts, &impl->native, &eligible, why, sizeof why)
            : GETME_FORMATS_OK;
    if (native && eligible)
        return st;
    if (choice == 'n')
        return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "'%s': the native MSH reader reads MSH 4.1 and "
                              "2.2 only, without %s (GETME_MSH_READER=native)",
                              doc->path, why);
    getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                   "'%s': the native MSH reader reads MSH 4.1 and 2.2 only, "
                   "without %s; this program reads no other MSH files (it "
                   "was built without the Gmsh plugin)",
                   doc->path, why);
    return GETME_FORMATS_DECLINED;
}

static getme_formats_status msh_open(getme_doc *doc, const getme_doc_options *opts)
{
    msh_impl *impl = getme__calloc(1, sizeof *impl);
    if (!impl)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "Out of memory");
    doc->impl = impl;
    getme_formats_status st = read_header(doc, impl);
    if (st != GETME_FORMATS_OK)
        return st;
    char choice = reader_choice();
    if (choice == 'g') {
        getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                       "'%s': GETME_MSH_READER=gmsh, but this program reads "
                       "MSH files natively only (it was built without the "
                       "Gmsh plugin)",
                       doc->path);
        return GETME_FORMATS_DECLINED;
    }
    return open_native(doc, impl, opts, choice);
}

static getme_formats_status msh_write(getme_doc *doc, const char *out_path)
{
    msh_impl *impl = doc->impl;
    if (!impl || !impl->native || !doc->mesh)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                              "MSH document is not open");
    return msh41_write(doc, impl->native, out_path);
}

static void msh_close(getme_doc *doc)
{
    msh_impl *impl = doc->impl;
    if (!impl)
        return;
    msh41_free(impl->native);
    free(impl);
    doc->impl = NULL;
}

const getme_format getme__format_msh = {
    "msh",
    "Gmsh MSH 2.2/4.1, ASCII or binary (read natively)",
    getme__msh_probe,
    msh_open, msh_write, msh_close, ".msh", NULL};
