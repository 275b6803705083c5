/*
 * msh41_internal.h -- the native MSH 4.1 path of the MSH adapter (private).
 *
 * msh_format.c reads MSH 4.1 and 2.2 files in one streaming pass without
 * a Gmsh model (msh41_reader.c, then msh41_build.c hands them to the model
 * builder of formats/model), and writes by copying the input with new
 * coordinates in $Nodes (msh41_writer.c).  Files it does not handle (parametric nodes,
 * partitioned meshes, big-endian binary, element types it does not know,
 * planar meshes outside a plane z = const...) are declined as "not
 * eligible" and go to the next adapter: Gmsh's reader through the Gmsh
 * plugin (plugin/src/gmsh_format.c) when the application registered it.
 *
 * msh41_input is the buffered byte reader both sides share: ASCII tokens
 * with line counting, binary records, and an optional echo that copies
 * every consumed byte to an output file (that is how the writer copies
 * the input byte for byte while parsing it).
 */
#ifndef GETME_MSH41_INTERNAL_H
#define GETME_MSH41_INTERNAL_H

#include "adapter.h"
#include "model.h"

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* ---- buffered input (msh41_input.c) ------------------------------------- */

typedef struct msh41_input {
    FILE *f;
    unsigned char *buf;
    size_t pos, len;     /* next byte, bytes in buf                   */
    int64_t base;        /* file offset of buf[0]                     */
    long line;           /* 1 + newlines consumed (ASCII messages)    */
    FILE *echo;          /* consumed bytes are copied here if set     */
    size_t echo_from;    /* first byte of buf not yet echoed          */
    int werr;            /* an echo write failed                      */
} msh41_input;

int msh41_in_open(msh41_input *in, const char *path);
void msh41_in_close(msh41_input *in);
/* File offset of the next byte. */
int64_t msh41_in_offset(const msh41_input *in);
/* Next byte (-1 at end of file). */
int msh41_in_getc(msh41_input *in);
int msh41_in_peek(msh41_input *in);
/* Exactly n bytes into dst (dst may be NULL: skip); 0 or -1 (short). */
int msh41_in_read(msh41_input *in, void *dst, size_t n);
/* As msh41_in_read into dst, but returns how many bytes it read (fewer
   than n only at the end of the file). */
size_t msh41_in_read_some(msh41_input *in, void *dst, size_t n);
/* One line without its end ("\n" or "\r\n"), cut to size-1 bytes (the
   rest is consumed); -1 at end of file with nothing read. */
int msh41_in_line(msh41_input *in, char *buf, size_t size);
/* The next whitespace-separated token: its length, 0 at end of file, -1
   if longer than size-1. */
int msh41_in_token(msh41_input *in, char *tok, size_t size);
/* Skip spaces, tabs and CRs; 1 if a newline (consumed) or the end of the
   file follows, else 0. */
int msh41_in_eol(msh41_input *in);
/* Skip whitespace including newlines. */
void msh41_in_skip_space(msh41_input *in);
/* Start / stop copying consumed bytes to out (NULL stops). */
void msh41_in_echo(msh41_input *in, FILE *out);
/* The unread bytes, want of them (at most the buffer) if the file still
   has them: *avail gets how many are there.  The text is not NUL-ended. */
const char *msh41_in_window(msh41_input *in, size_t want, size_t *avail);
/* Consume bytes of the window, holding lines newlines. */
void msh41_in_consume(msh41_input *in, size_t bytes, long lines);

/* ---- element types and node tags: the shared model code (formats/model) */

static inline int msh41_type_nodes(int msh_type, int *order)
{
    return getme__msh_type_nodes(msh_type, order);
}

typedef getme__nodemap msh41_nodemap;

/* Index of tag, -1 if absent. */
static inline int32_t msh41_map_find(const msh41_nodemap *map, uint64_t tag)
{
    return getme__nodemap_find(map, tag);
}

static inline void msh41_map_free(msh41_nodemap *map)
{
    getme__nodemap_free(map);
}

/* ---- what stays open between reading and writing ------------------------ */

typedef struct msh41_doc {
    int binary;
    int64_t nodes_offset;   /* first byte after the "$Nodes" line      */
    int64_t size, mtime_ns; /* identity of the input when it was read  */
    uint64_t dev, ino;
    int v22;                /* MSH 2.2 (else 4.1)                        */
    msh41_nodemap map;      /* node tag -> mesh node, -1 if not in it   */
} msh41_doc;

/*
 * Read doc->path (MSH 4.1, header already checked by the caller) into
 * doc->mesh / doc->elem_ids / doc->info and *out.  If the file is outside
 * what this reader handles, *eligible is set to 0, why says what, the
 * document is left as it was and GETME_FORMATS_OK is returned.
 */
getme_formats_status msh41_open(getme_doc *doc, const getme_doc_options *opts,
                           msh41_doc **out, int *eligible, char *why,
                           size_t why_size);
getme_formats_status msh41_write(getme_doc *doc, const msh41_doc *m,
                            const char *out_path);
void msh41_free(msh41_doc *m);


/* ---- reader state (msh41_reader.c parses, msh41_build.c builds) -------- */

/* Status of a reader step that declines the file (not an error: the
   caller falls back to Gmsh's reader). */
#define MSH41_DECLINED ((getme_formats_status)99)

typedef struct msh41_pname {  /* $PhysicalNames entry */
    int dim, tag;
    char *name;
} msh41_pname;

typedef struct msh41_entity { /* $Entities entry */
    int dim, tag;
    size_t phys_first, phys_count; /* into msh41_reader.phys */
    int fix;                       /* in a group named by --fix */
    /* partitioned files ($PartitionedEntities, one_part only): */
    int parent_dim, parent_tag;    /* the model entity it is a piece of */
    int skip;                      /* not in the partition being read   */
    int32_t region;                /* getme_doc_element_region's key    */
} msh41_entity;

typedef struct msh41_nblock { /* one $Nodes entity block (file order) */
    int dim, tag;
    size_t first, count;
} msh41_nblock;

/* One $Elements block of the top dimension: entity tag, MSH type, count,
   node indices (file order, later mesh; NULL for a type GETMe cannot
   smooth), element tags -- the model builder's block. */
typedef getme__model_block msh41_eblock;

enum { MSH41_FIXGRP = GETME__NODE_FIXGRP }; /* msh41_reader.flag bit */

typedef struct msh41_reader {
    getme_doc *doc;
    const getme_doc_options *opts;
    msh41_input in;
    int binary;
    int64_t file_size;
    const char *section;      /* for messages */
    char why[160];            /* why the file was declined */
    msh41_pname *names;
    size_t nnames;
    msh41_entity *ents;       /* sorted by (dim, tag) */
    size_t nents;
    /* a partitioned file read as one part (opts->one_part): ents are then
       the $PartitionedEntities, model_ents the model's $Entities */
    int partitioned, num_partitions;
    msh41_entity *model_ents;
    size_t nmodel_ents;
    int *phys;
    size_t nphys;
    int *fix_found;           /* groups matched per --fix word */
    int groups_ready, have_nodes, have_elements;
    int64_t nodes_offset;
    size_t nnodes;            /* file order: */
    uint64_t *tags;
    double *xyz;
    uint8_t *flag;
    msh41_nblock *nb;
    size_t nnb;
    msh41_nodemap map;        /* tag -> file index (later mesh index) */
    int tags_run;             /* tags[i] == tags[0] + i (4.1 elements)   */
    msh41_eblock *eb;
    size_t neb, cap_eb;
    int top_dim;
    /* MSH 2.2: no $Entities and no node blocks; both are derived from the
       elements' (physical, elementary) tags as Gmsh's MSH 2 reader does */
    int v22;
    uint8_t *ndim;            /* per node: lowest dimension of an element
                                 using it (4: none) ...                    */
    int *netag;               /* ... and the lowest elementary tag there   */
    int (*ent22)[3];          /* (dim, elementary, physical) seen         */
    size_t nent22, cap_ent22;
    size_t cap_cur;           /* room in the last element block            */
    int phys_cur;             /* the physical tag of its elements          */
    int64_t repeated22;       /* elements dropped as repeats (finish22)    */
    int threads;              /* for the ASCII fast path                   */
    size_t fast_want;         /* its window (msh41_fast.c)                 */
    /* binary: the offset a message names when it is not where the input
       stands (read_binary_elements reads ahead of the record it names) */
    int64_t msg_offset;
    int msg_offset_set;
} msh41_reader;

/* Error at the current position: "'file', line N: ..." (ASCII) or
   "'file': ... (byte N)" (binary). */
getme_formats_status msh41_fail(msh41_reader *r, getme_formats_status st,
                           const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
getme_formats_status msh41_decline(msh41_reader *r, const char *why);
msh41_entity *msh41_find_entity(const msh41_reader *r, int dim, int tag);
/* $PhysicalNames name of group (dim, tag), NULL if it has none. */
const char *msh41_group_name(const msh41_reader *r, int dim, int tag);
/* Everything after parsing: mesh, fixed nodes, regions, ids, info. */
getme_formats_status msh41_build(msh41_reader *r, msh41_doc *m);
/* Store element i of block b (NULL: a dropped block) from rec = tag + nv
   node tags, flagging its nodes if fix: 0, or 1 + k if node k repeats an
   earlier one of a kept element, or -(1 + k) if node k is not in $Nodes. */
int msh41_store_element(msh41_reader *r, msh41_eblock *b, size_t i,
                        const uint64_t *rec, int nv, int fix);

/* ---- ASCII fast path (msh41_fast.c) -------------------------------------- */

enum { MSH41_FAST_TAGS, MSH41_FAST_COORDS, MSH41_FAST_ELEMENTS };
#define MSH41_MAX_REC 128 /* element tag + node tags of one ASCII record */

typedef struct msh41_fast_job {
    int kind;                 /* MSH41_FAST_*                               */
    uint64_t *tags;           /* TAGS: node tags of the block               */
    double *xyz;              /* COORDS: 3 per node of the block            */
    msh41_eblock *b;          /* ELEMENTS: the block (NULL: dropped)        */
    int nv, fix;              /* ELEMENTS: nodes per element, --fix group    */
} msh41_fast_job;

/* Read records first, first + 1, ... (at most n) of an ASCII run, one per
   line, from the current position, on r->threads threads; stops before
   the first line that is not one plain record (the token reader takes
   it).  Returns how many were read. */
size_t msh41_fast(msh41_reader *r, const msh41_fast_job *job, size_t first,
                  size_t n);

/* Node tag -> index of tags[0..n) (tag 0 and repeated tags refused). */
getme_formats_status msh41_map_build(msh41_reader *r, msh41_nodemap *map,
                                const uint64_t *tags, size_t n);

#endif /* GETME_MSH41_INTERNAL_H */
