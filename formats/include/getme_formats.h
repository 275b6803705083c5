/*
 * getme_formats.h -- file adapters of getme (libgetme_formats).
 *
 * Each adapter reads one file format into a core getme_mesh with its fixed
 * nodes already marked, keeps whatever it needs to write the same file back,
 * and writes back a copy in which only node coordinates differ.
 *
 *   getme_doc *doc;
 *   if (getme_doc_open(&doc, "part.inp", &opts) != GETME_FORMATS_OK) {
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
 *
 * The document and the adapters are opaque; what an adapter implements is
 * in getme_formats_adapter.h (the Gmsh plugin provides one: MSH files the
 * native reader declines, read through the Gmsh SDK; see
 * getme_doc_options.adapters).  Built-in adapters: MSH (native), INP, and
 * CGNS when built with GETME_WITH_CGNS.  Status codes are this library's
 * own (getme_formats_status); the getme command maps them to its exit
 * codes (cli/exit.c).
 */
#ifndef GETME_FORMATS_H
#define GETME_FORMATS_H

#include "getme.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define GETME_FORMATS_API __attribute__((visibility("default")))
#else
#define GETME_FORMATS_API
#endif

/* What went wrong, by category. */
typedef enum getme_formats_status {
    GETME_FORMATS_OK = 0,
    GETME_FORMATS_ERR_OPEN,        /* missing / unreadable file                */
    GETME_FORMATS_ERR_PARSE,       /* malformed content                        */
    GETME_FORMATS_ERR_UNSUPPORTED, /* element type or feature not supported    */
    GETME_FORMATS_ERR_INVALID,     /* the mesh has invalid (inverted or
                                      degenerate) elements                     */
    GETME_FORMATS_ERR_WRITE,       /* output could not be written              */
    GETME_FORMATS_ERR_ARGUMENT,    /* bad option, unknown set name, refused
                                      output path...                           */
    GETME_FORMATS_ERR_INTERNAL     /* out of memory, library failure           */
} getme_formats_status;

/* "ok", "cannot open", ... (a static string; "unknown status" if st is
   none of the above). */
GETME_FORMATS_API const char *getme_formats_status_string(getme_formats_status st);

typedef struct getme_format getme_format; /* one adapter (opaque) */
typedef struct getme_doc getme_doc;       /* one open document (opaque) */

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
    /* More adapters, NULL-terminated (may be NULL): tried after the
       built-in ones, and when a built-in adapter declines a file it takes
       (the native MSH reader declines MSH 4.0, parametric nodes...).  The
       getme command passes getme_gmsh_format() of libgetme_gmsh here. */
    const getme_format *const *adapters;
    /* Threads the ASCII readers parse with (0: OpenMP's default, 1: the
       calling thread only).  The document is the same for any value. */
    int num_threads;
    /* 1: read one part of a Gmsh-partitioned MSH 4.1 file (a split file
       NAME_k.msh, or the part numbered partition of one partitioned file)
       natively, for a distributed caller (getme-mpi): only that part's
       elements; nodes on the partition boundaries (entities whose parent
       is a smoothed volume) are free; the skin and interface rules are
       the caller's to apply across all parts (fix_skin / fix_interfaces
       are ignored); node tags and region keys are kept
       (getme_doc_node_id, getme_doc_element_region).  0 (default):
       partitioned files are declined by the native reader (the Gmsh
       plugin reads them whole). */
    int one_part;
    int partition;       /* with one_part, for a file holding several
                            partitions: the one to read (1-based); 0 = all
                            of the file's elements (a split file)         */
    /* 1: getme_doc_open leaves out its validity check, a sweep evaluating
       every element; the caller makes it with getme_doc_check from the
       qualities it computes anyway (the getme command's measures sweep
       gives them), so that the mesh is not evaluated twice.  0 (default):
       getme_doc_open checks. */
    int defer_check;
} getme_doc_options;

/* Fill options with the defaults (fix skin and interfaces, no names, no
   extra adapters). */
GETME_FORMATS_API void getme_doc_options_init(getme_doc_options *opts);

/* The built-in adapters, NULL-terminated. */
GETME_FORMATS_API const getme_format *const *getme_formats(void);
/* The built-in adapter for a path (probe order: by extension first), or
   NULL. */
GETME_FORMATS_API const getme_format *getme_format_for(const char *path);
/* "msh", "inp", "cgns". */
GETME_FORMATS_API const char *getme_format_name(const getme_format *format);
/* One line: "Abaqus / CalculiX INP ...". */
GETME_FORMATS_API const char *
getme_format_description(const getme_format *format);
/* Its extensions, space-separated, with the dot: ".inp .INP"... */
GETME_FORMATS_API const char *
getme_format_extensions(const getme_format *format);
/* 1 if path ends with one of format's extensions (case-insensitive). */
GETME_FORMATS_API int getme_format_has_extension(const getme_format *format,
                                                 const char *path);

/*
 * Open a document; on failure *doc is still set (so getme_doc_error() can be
 * read) and must be closed.  Checks that the mesh is valid: an input with
 * invalid elements gives GETME_FORMATS_ERR_INVALID with how many and the
 * first few file ids; the mesh stays readable (getme_doc_mesh) so that a
 * caller may untangle it.
 */
GETME_FORMATS_API getme_formats_status
getme_doc_open(getme_doc **doc, const char *path, const getme_doc_options *opts);
/* The validity check of getme_doc_open (see defer_check): the statistics
   of q, every element's quality with getme_mesh_element_qualities' bits
   (NULL: computed here), kept for getme_doc_stats; then
   GETME_FORMATS_ERR_INVALID with getme_doc_open's message if any element
   is invalid, else GETME_FORMATS_OK. */
GETME_FORMATS_API getme_formats_status getme_doc_check(getme_doc *doc,
                                                       const double *q);
/* Write the document to out_path: refused (GETME_FORMATS_ERR_ARGUMENT) if
   out_path is one of the files read (by device and inode) or is not a
   regular file (see getme_io_output_path: a symbolic link is followed). */
GETME_FORMATS_API getme_formats_status getme_doc_write(getme_doc *doc,
                                                       const char *out_path);
GETME_FORMATS_API void getme_doc_close(getme_doc *doc);
/* The mesh to smooth (owned by the document); NULL before it was built. */
GETME_FORMATS_API getme_mesh *getme_doc_mesh(getme_doc *doc);
/* The adapter that opened the document (NULL if none took the file). */
GETME_FORMATS_API const getme_format *getme_doc_format(const getme_doc *doc);
/* The input path as given. */
GETME_FORMATS_API const char *getme_doc_path(const getme_doc *doc);
/* Quality of all elements as read (getme_doc_open computes them for its
   validity check; callers need not compute them again); NULL before. */
GETME_FORMATS_API const getme_quality_stats *
getme_doc_stats(const getme_doc *doc);
/* The last error, one line naming the file. */
GETME_FORMATS_API const char *getme_doc_error(const getme_doc *doc);
/* One line a program may log: zones, sets, fixed nodes... ("" if none). */
GETME_FORMATS_API const char *getme_doc_info(const getme_doc *doc);
/* Input accepted with a caveat, one line; "" if none. */
GETME_FORMATS_API const char *getme_doc_warning(const getme_doc *doc);
/* The files the document was read from: 0 is the input, then the files it
   includes (INP *INCLUDE), in the order they were read. */
GETME_FORMATS_API size_t getme_doc_num_files(const getme_doc *doc);
GETME_FORMATS_API const char *getme_doc_file(const getme_doc *doc, size_t i);
/* The id of mesh element e as written in the file (1-based position if
   the format has no ids). */
GETME_FORMATS_API int64_t getme_doc_element_id(const getme_doc *doc, int32_t e);
/* With getme_doc_options.one_part: the file's tag of mesh node i, and a
   region key of mesh element e that is the same in every part of the
   partitioned model (elements of the same non-empty set of physical
   groups, or of the same model volume when in none, share it); the number
   of partitions of the model.  Else 0, -1 and 0. */
GETME_FORMATS_API uint64_t getme_doc_node_id(const getme_doc *doc, int32_t i);
GETME_FORMATS_API int32_t getme_doc_element_region(const getme_doc *doc,
                                                   int32_t e);
GETME_FORMATS_API int getme_doc_num_partitions(const getme_doc *doc);

/* ---- safe writing (used by the adapters and by programs) --------------- */

/* Create an empty file with a unique name next to out_path
   ("<dir>/.<name>.getme-tmp.<pid>.<n>") and put its path into buf; the
   caller overwrites it.  Returns 0, or -1 (buf too small, directory not
   writable: errno tells). */
GETME_FORMATS_API int getme_io_tmp_path(const char *out_path, char *buf,
                                        size_t size);
/* Rename tmp to out (same directory); on failure remove tmp. 0 or -1.
   Refuses (errno EEXIST) when out exists and is not a regular file: a
   device, FIFO, directory or symbolic link is never replaced.
   Callers that fail after getme_io_tmp_path must remove(tmp) themselves. */
GETME_FORMATS_API int getme_io_commit(const char *tmp, const char *out);
/* Where out_path may be written, checked before anything is read or
   written: the path to write goes to buf (out_path itself, or for a
   symbolic link the file it points to: the link is followed and stays).
   GETME_FORMATS_ERR_ARGUMENT if out_path exists and is not a regular file
   (character or block device, FIFO, socket, directory) or is a link to a
   missing file; GETME_FORMATS_ERR_WRITE if its directory is missing or not
   writable.  msg gets the one-line reason, naming out_path. */
GETME_FORMATS_API getme_formats_status
getme_io_output_path(const char *out_path, char *buf, size_t size, char *msg,
                     size_t msg_size);
/* The directory part of path ("." if none, "/" for "/x"), into buf. */
GETME_FORMATS_API void getme_io_dirname(const char *path, char *buf,
                                        size_t size);
/* 1 if a and b name the same existing file (used to refuse -o == input). */
GETME_FORMATS_API int getme_io_same_file(const char *a, const char *b);

#ifdef __cplusplus
}
#endif

#endif /* GETME_FORMATS_H */
