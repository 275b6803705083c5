/*
 * getme_formats.h -- file adapters of getme (libgetme_formats).
 *
 * Each adapter reads one file format into a core getme_mesh with its fixed
 * nodes already marked, keeps whatever it needs to write the same file back,
 * and writes back a copy in which only node coordinates differ.
 *
 *   getme_doc *doc;
 *   if (getme_doc_open(&doc, "part.inp", &opts) != GETME_IO_OK) {
 *       fprintf(stderr, "Error   : %s\n", getme_doc_error(doc)); ...
 *   }
 *   getme_smooth(getme_doc_mesh(doc), &params, &result);
 *   getme_doc_write(doc, "part-smooth.inp");
 *   getme_doc_close(doc);
 *
 * Writers never touch the input and never leave a partial output: they write
 * to a temporary file next to the output and rename it (getme_io_tmp_path /
 * getme_io_commit).  Errors are one line naming the file and, where there is
 * one, the line number (INP), the CGNS node path, or the element/node id as
 * written in the file.
 */
#ifndef GETME_FORMATS_H
#define GETME_FORMATS_H

#include "getme.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Error categories; the CLI turns them into its exit codes (README). */
typedef enum getme_io_status {
    GETME_IO_OK = 0,
    GETME_IO_ERR_OPEN = 3,        /* missing / unreadable file                */
    GETME_IO_ERR_PARSE = 4,       /* malformed content                        */
    GETME_IO_ERR_UNSUPPORTED = 5, /* element type or feature not supported    */
    GETME_IO_ERR_INVALID = 6,     /* the mesh has invalid (inverted) elements */
    GETME_IO_ERR_WRITE = 7,       /* output could not be written              */
    GETME_IO_ERR_TANGLED = 8,     /* invalid elements that untangling could not
                                     repair (named by their file ids)         */
    GETME_IO_ERR_USAGE = 2,       /* bad option, unknown set name...          */
    GETME_IO_ERR_INTERNAL = 1     /* out of memory, library failure           */
} getme_io_status;

typedef struct getme_doc_options {
    int fix_skin;        /* 1 (default): fix nodes on the mesh skin           */
    int fix_interfaces;  /* 1 (default): fix nodes on interfaces between
                            regions (physical volumes, sections, zones...)   */
    int num_fix;         /* names of extra sets to fix: Gmsh physical group
                            names (or "dim:tag"), INP NSET/ELSET, CGNS BC or
                            family names                                     */
    const char *const *fix;
    int num_free;        /* names of sets that are NOT fixed by default
                            (CGNS BCs / families)                            */
    const char *const *free_sets;
    int verbose;         /* 0 quiet; adapters never print, this only lets
                            them keep more detail in getme_doc_info()        */
} getme_doc_options;

/* Fill options with the defaults (fix skin and interfaces, no names). */
void getme_doc_options_init(getme_doc_options *opts);

typedef struct getme_doc getme_doc;

/* One adapter. */
typedef struct getme_format {
    const char *name;        /* "msh", "inp", "cgns"                          */
    const char *description; /* "Gmsh MSH 2.2/4.1 (via the Gmsh SDK)" ...    */
    /* 1 if this adapter takes the file (by extension and/or magic bytes). */
    int (*probe)(const char *path);
    /* Read doc->path; build doc->mesh with fixed nodes set; keep private
       state in doc->impl.  On failure set the message with getme_doc_fail()
       and return its status. */
    getme_io_status (*open)(getme_doc *doc, const getme_doc_options *opts);
    /* Write the document with the current coordinates of doc->mesh to
       out_path (through a temporary file + rename). */
    getme_io_status (*write)(getme_doc *doc, const char *out_path);
    /* Free doc->impl. */
    void (*close)(getme_doc *doc);
    /* Extensions of the format, space-separated, with the dot (".inp"):
       an output must end with one of them (getme_format_has_extension). */
    const char *extensions;
    /* The i-th file (i >= 1) the document was read from besides doc->path
       (INP *INCLUDE files), NULL past the last; NULL if there are none. */
    const char *(*file)(const getme_doc *doc, size_t i);
} getme_format;

struct getme_doc {
    const getme_format *format;
    char *path;          /* input path (owned)                               */
    getme_mesh *mesh;    /* the mesh to smooth (owned)                       */
    void *impl;          /* adapter private state                            */
    /* element ids as written in the file, per global element index (may be
       NULL); used in messages about invalid elements                       */
    int64_t *elem_ids;
    getme_quality_stats stats; /* all elements as read (set by
                            getme_doc_open, which needs them for its validity
                            check; callers need not compute them again)      */
    char info[1024];     /* one line the CLI may log: zones, sets, fixed...  */
    char error[1024];    /* the last error, one line                         */
    char warning[1024];  /* input accepted with a caveat (the CLI prints it
                            as a warning), one line; empty if none           */
};

/* The registered adapters, NULL-terminated. */
const getme_format *const *getme_formats(void);
/* The adapter for a path (probe order: by extension first), or NULL. */
const getme_format *getme_format_for(const char *path);

/*
 * Open a document; on failure *doc is still set (so getme_doc_error() can be
 * read) and must be closed.  Checks that the mesh is valid: an input with
 * invalid elements gives GETME_IO_ERR_INVALID with how many and the first
 * few file ids.
 */
getme_io_status getme_doc_open(getme_doc **doc, const char *path,
                               const getme_doc_options *opts);
/* Write the document to out_path: refused (GETME_IO_ERR_USAGE) if out_path
   is one of the files read (by device and inode) or is not a regular file
   (see getme_io_output_path: a symbolic link is followed). */
getme_io_status getme_doc_write(getme_doc *doc, const char *out_path);
/* The files the document was read from: 0 is the input, then the files it
   includes (INP *INCLUDE), in the order they were read. */
size_t getme_doc_num_files(const getme_doc *doc);
const char *getme_doc_file(const getme_doc *doc, size_t i);
/* 1 if path ends with one of format's extensions (case-insensitive). */
int getme_format_has_extension(const getme_format *format, const char *path);
void getme_doc_close(getme_doc *doc);
getme_mesh *getme_doc_mesh(getme_doc *doc);
const char *getme_doc_error(const getme_doc *doc);
const char *getme_doc_info(const getme_doc *doc);
const char *getme_doc_warning(const getme_doc *doc);

/* The id of mesh element e as written in the file (1-based position if
   the format has no ids). */
int64_t getme_doc_element_id(const getme_doc *doc, int32_t e);

/* Set doc->error (printf style) and return status. */
getme_io_status getme_doc_fail(getme_doc *doc, getme_io_status status,
                               const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* ---- helpers for adapters ----------------------------------------------- */

/* Create an empty file with a unique name next to out_path
   ("<dir>/.<name>.getme-tmp.<pid>.<n>") and put its path into buf; the adapter
   overwrites it.  Returns 0, or -1 (buf too small, directory not writable:
   errno tells). */
int getme_io_tmp_path(const char *out_path, char *buf, size_t size);
/* Rename tmp to out (same directory); on failure remove tmp. 0 or -1.
   Refuses (errno EEXIST) when out exists and is not a regular file: a
   device, FIFO, directory or symbolic link is never replaced.
   Adapters that fail after getme_io_tmp_path must remove(tmp) themselves. */
int getme_io_commit(const char *tmp, const char *out);
/* Where out_path may be written, checked before anything is read or
   written: the path to write goes to buf (out_path itself, or for a
   symbolic link the file it points to: the link is followed and stays).
   GETME_IO_ERR_USAGE if out_path exists and is not a regular file
   (character or block device, FIFO, socket, directory) or is a link to a
   missing file; GETME_IO_ERR_WRITE if its directory is missing or not
   writable.  msg gets the one-line reason, naming out_path. */
getme_io_status getme_io_output_path(const char *out_path, char *buf,
                                     size_t size, char *msg, size_t msg_size);
/* The directory part of path ("." if none, "/" for "/x"), into buf. */
void getme_io_dirname(const char *path, char *buf, size_t size);
/* 1 if a and b name the same existing file (used to refuse -o == input). */
int getme_io_same_file(const char *a, const char *b);

/* The adapters (each in its own file). */
extern const getme_format getme_format_msh;  /* msh_format.c  */
extern const getme_format getme_format_inp;  /* inp_format.c  */
extern const getme_format getme_format_cgns; /* cgns_format.c */

#ifdef __cplusplus
}
#endif

#endif /* GETME_FORMATS_H */
