/*
 * getme_formats_adapter.h -- what a file adapter of libgetme_formats
 * implements (for adapter authors: the Gmsh plugin's MSH adapter; programs
 * that only read and write files need getme_formats.h alone).
 *
 * An adapter reads one file format into a core getme_mesh with its fixed
 * nodes marked, keeps what it needs to write the same file back in its
 * private state, and writes a copy in which only node coordinates differ.
 * A program hands extra adapters to getme_doc_open through
 * getme_doc_options.adapters; nothing is registered globally.
 */
#ifndef GETME_FORMATS_ADAPTER_H
#define GETME_FORMATS_ADAPTER_H

#include "getme_formats.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* An adapter's open may return this when a file it probed is not one it
   reads after all (the native MSH reader and MSH 4.0): getme_doc_open then
   resets the document and tries the next adapter that takes the path.  The
   message set with getme_doc_fail says why, for when no other adapter
   takes it (the document then fails with GETME_FORMATS_ERR_UNSUPPORTED). */
#define GETME_FORMATS_DECLINED ((getme_formats_status)100)

struct getme_format {
    const char *name;        /* "msh", "inp", "cgns"                          */
    const char *description; /* one line for `getme formats`                  */
    /* 1 if this adapter takes the file (by extension and/or magic bytes). */
    int (*probe)(const char *path);
    /* Read getme_doc_path(doc); build the mesh with its fixed nodes set
       (getme_doc_set_mesh); keep private state with getme_doc_set_impl.
       On failure set the message with getme_doc_fail() and return its
       status. */
    getme_formats_status (*open)(getme_doc *doc, const getme_doc_options *opts);
    /* Write the document with the current coordinates of its mesh to
       out_path (through a temporary file + rename: getme_io_tmp_path,
       getme_io_commit). */
    getme_formats_status (*write)(getme_doc *doc, const char *out_path);
    /* Free the private state. */
    void (*close)(getme_doc *doc);
    /* Extensions of the format, space-separated, with the dot (".inp"):
       an output must end with one of them (getme_format_has_extension). */
    const char *extensions;
    /* The i-th file (i >= 1) the document was read from besides its path
       (INP *INCLUDE files), NULL past the last; NULL if there are none. */
    const char *(*file)(const getme_doc *doc, size_t i);
};

/* Set the document's error (printf style) and return status. */
GETME_FORMATS_API getme_formats_status
getme_doc_fail(getme_doc *doc, getme_formats_status status, const char *fmt,
               ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Set the one-line summary getme_doc_info() returns (printf style). */
GETME_FORMATS_API void getme_doc_set_info(getme_doc *doc, const char *fmt,
                                          ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Hand the document its mesh and, optionally, the file's element id per
   mesh element (malloc'd; both owned by the document from now on). */
GETME_FORMATS_API void getme_doc_set_mesh(getme_doc *doc, getme_mesh *mesh,
                                          int64_t *elem_ids);
/* The adapter's private state (NULL until set). */
GETME_FORMATS_API void getme_doc_set_impl(getme_doc *doc, void *impl);
GETME_FORMATS_API void *getme_doc_impl(const getme_doc *doc);

#ifdef __cplusplus
}
#endif

#endif /* GETME_FORMATS_ADAPTER_H */
