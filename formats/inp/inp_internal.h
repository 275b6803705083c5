/*
 * inp_internal.h -- private declarations of the Abaqus INP adapter.
 *
 * The adapter works in three passes, each in its own file:
 *   inp_reader.c   one streaming pass over the deck and its *INCLUDE files
 *                  into flat arrays (inp_deck): nodes, elements with raw
 *                  file ids, sets as chunks of an id pool, sections;
 *   inp_build.c    ids -> indices, sets, sections -> regions, fixed nodes,
 *                  the getme_mesh;
 *   inp_writer.c   re-reads every file and copies it line by line, patching
 *                  only the coordinate fields of moved nodes and the INPUT=
 *                  value of *INCLUDE lines.
 * Nothing is allocated per line, node or element: every array grows by
 * doubling.  Only the file paths, the byte offsets of *NODE blocks and the
 * node ids are kept between open and write, not the text of the deck.
 */
#ifndef GETME_INP_INTERNAL_H
#define GETME_INP_INTERNAL_H

#include "adapter.h"

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define INP_MAX_LINE (1 << 20) /* longest line accepted (Abaqus: 256)   */
#define INP_MAX_DEPTH 32       /* *INCLUDE nesting                       */
#define INP_MAX_PARAMS 32      /* parameters on one keyword line         */
#define INP_MAX_VALUE 256      /* parameter value length, with the NUL   */
#define INP_MAX_TOKEN 64       /* one number                             */
#define INP_MAX_NV 64          /* nodes of one element of any type       */

/* ---- growing arrays (inp_util.c) ---------------------------------------- */

/* Make room for need elements of size sz in *p (capacity *cap, doubled).
   0 or -1 on overflow / out of memory. */
int inp_reserve(void **p, size_t *cap, size_t need, size_t sz);
#define INP_RESERVE(arr, cap, need) \
    inp_reserve((void **)&(arr), &(cap), (size_t)(need), sizeof *(arr))

/* Case-insensitive comparison of ASCII names. */
int inp_name_eq(const char *a, const char *b);

/* ---- line reader (inp_lines.c) ------------------------------------------ */

typedef struct inp_lines {
    FILE *fp;
    char *buf;
    size_t cap, beg, end;
    int eof;
    int64_t offset;      /* byte offset of the current line                */
    int64_t next_offset; /* byte offset of the line after it               */
    uint32_t lineno;     /* 1-based number of the current line             */
    char *text;          /* current line without terminator, NUL-ended     */
    size_t len;
    const char *term;    /* its terminator as found: "\n", "\r\n" or ""    */
    int bom;             /* the file starts with a UTF-8 byte order mark,
                            which is not part of line 1's text            */
} inp_lines;

/* 0, or -1 with errno set. */
int inp_lines_open(inp_lines *r, const char *path);
/* 1: a line is in r->text; 0: end of file; -1: read error; -2: a line
   longer than INP_MAX_LINE. */
int inp_lines_next(inp_lines *r);
void inp_lines_close(inp_lines *r);

/* The unread bytes of the buffer, want of them if the file has them (the
   buffer grows to want): *avail gets how many there are.  For the fast
   path (inp_fast.c), which consumes whole lines with inp_lines_consume. */
const char *inp_lines_window(inp_lines *r, size_t want, size_t *avail);
void inp_lines_consume(inp_lines *r, size_t bytes, size_t lines);
/* For the writer: the bytes from the next line's start up to byte offset
   to of the file, copied to out as they are (no line is split; the line
   count follows).  to = INT64_MAX: to the end of the file.  0; 1 if the
   file ends before to, or to is not at a line's start (the file is not
   the one read); -1 on a read or write error. */
int inp_lines_copy(inp_lines *r, int64_t to, FILE *out);

enum { INP_LINE_BLANK, INP_LINE_COMMENT, INP_LINE_KEYWORD, INP_LINE_DATA };
int inp_line_kind(const char *text, size_t len);

/* One comma-separated field of a data line, blanks trimmed. */
typedef struct inp_field {
    const char *s;
    size_t n;
} inp_field;

/* Next field of [*p, end): 1 and advance *p past its comma, or 0 when the
   line is used up.  "a,b," gives "a", "b", "" (the empty last field is how a
   trailing comma shows). */
int inp_next_field(const char **p, const char *end, inp_field *f, int *last);
/* Integer / real field: 0 or -1.  An empty real field is 0 (Abaqus). */
int inp_parse_int(const inp_field *f, int64_t *v);
int inp_parse_real(const inp_field *f, double *v);
/* 1 if the field holds a text label (starts with a letter or '_'). */
int inp_is_label(const inp_field *f);

/* ---- keyword lines (inp_keyword.c) -------------------------------------- */

typedef struct inp_param {
    char key[32];            /* upper case, blanks removed                 */
    char val[INP_MAX_VALUE]; /* as written, trimmed, quotes removed; "" for
                                a flag parameter                           */
    int64_t line_offset;     /* byte offset of the line holding the value  */
    int val_col, val_len;    /* value position in that line (with quotes)  */
} inp_param;

typedef struct inp_keyword {
    char name[48];           /* upper case, blanks and '*' removed         */
    int nparams;
    inp_param p[INP_MAX_PARAMS];
    int continued;           /* the line ended with ',': parameters go on   */
} inp_keyword;

/* Parse a keyword line (first = 1) or a continuation of its parameters
   (first = 0).  0, or -1 with a message in err. */
int inp_keyword_parse(inp_keyword *kw, const char *text, size_t len,
                      int64_t offset, int first, char *err, size_t errsz);
/* Value of a parameter (NULL if absent). */
const inp_param *inp_keyword_param(const inp_keyword *kw, const char *key);
const char *inp_keyword_get(const inp_keyword *kw, const char *key);

/* What an element type is to the smoother (inp_types.c). */
typedef enum inp_kind {
    INP_KIND_OTHER = 0,  /* kept, its nodes fixed (beam, shell in 3-D...)  */
    INP_KIND_SOLID = 1,  /* linear tet/hex/prism/pyramid                  */
    INP_KIND_PLANAR = 2, /* linear tri/quad (plane stress/strain, shells)  */
    INP_KIND_SOLID2 = 3, /* second-order solid: refused                    */
    INP_KIND_PLANAR2 = 4 /* second-order planar: refused when smoothed     */
} inp_kind;

/* Classify an upper-case Abaqus element type name; *gtype and *nv get the
   getme type and node count for the known kinds (nv 0 = any). */
inp_kind inp_element_kind(const char *type, int *gtype, int *nv);
/* gtype of second-order solids: INP_HO + getme_ho_type (C3D10, C3D15,
   C3D20 and their variants); their node order in Gmsh's from Abaqus'. */
#define INP_HO 100
const int8_t *inp_ho_order(int ho_type);

/* ---- hash tables (inp_hash.c) ------------------------------------------- */

/* int64 -> int32, open addressing, no deletion. */
typedef struct inp_hash {
    int64_t *keys;
    int32_t *vals;
    size_t cap, count;
} inp_hash;

/* 0 inserted, 1 key present (*old gets its value), -1 out of memory. */
int inp_hash_put(inp_hash *h, int64_t key, int32_t val, int32_t *old);
int32_t inp_hash_get(const inp_hash *h, int64_t key); /* -1 if absent */
void inp_hash_free(inp_hash *h);

/* Case-insensitive string interning: the same id for "Fix" and "FIX"; the
   spelling seen first is kept for messages. */
typedef struct inp_strtab {
    char *arena;
    size_t len, cap;
    size_t *offs;
    size_t count, cap_offs;
    int32_t *slots; /* id + 1, 0 = empty */
    size_t nslots;
} inp_strtab;

int32_t inp_str_intern(inp_strtab *t, const char *s); /* -1: no memory */
int32_t inp_str_find(const inp_strtab *t, const char *s);
const char *inp_str(const inp_strtab *t, int32_t id);
void inp_strtab_free(inp_strtab *t);

/* ---- the deck as read (inp_reader.c) ------------------------------------ */

typedef struct inp_file {     /* one file occurrence: deck or *INCLUDE      */
    char *path;               /* as opened (include paths resolved)        */
    int parent;               /* including occurrence, -1 for the deck      */
    uint32_t parent_line;     /* line of the *INCLUDE in the parent        */
    int64_t size, mtime_sec, mtime_nsec;
} inp_file;

typedef struct inp_include {  /* an *INCLUDE line to patch when writing   */
    int file;                 /* occurrence holding the line                */
    int64_t offset;           /* byte offset of the line with the value     */
    int col, len;             /* the value's position in that line          */
    int child;                /* occurrence it reads                        */
} inp_include;

typedef struct inp_node_block { /* consecutive node lines of one file     */
    int file;
    int scope;
    int64_t offset;           /* byte offset of its first data line         */
    int32_t first, count;     /* node indices [first, first + count)        */
} inp_node_block;

typedef struct inp_elem_block { /* consecutive elements of one *ELEMENT   */
    int file;
    int scope;
    inp_kind kind;
    int gtype, nv;            /* nv 0: variable (conn holds n, ids...)      */
    char type[24];            /* as written, for messages                   */
    int32_t elset;            /* ELSET= name id, -1 if none                 */
    int32_t first, count;     /* element indices in read order              */
    int64_t conn_beg, conn_end;
} inp_elem_block;

enum { INP_SCOPE_MODEL, INP_SCOPE_ASSEMBLY, INP_SCOPE_PART,
       INP_SCOPE_INSTANCE };

typedef struct inp_scope {
    int kind;
    int32_t name;             /* name id, -1 for the model                  */
    int node_scope;           /* scope whose nodes its ids refer to         */
} inp_scope;

enum { INP_SET_NODE = 0, INP_SET_ELEM = 1 };

typedef struct inp_set {
    int kind;                 /* INP_SET_NODE / INP_SET_ELEM                */
    int ns;                   /* namespace (scope) it is defined in         */
    int32_t name;
    int32_t head, tail;       /* chunk list                                 */
} inp_set;

/* A piece of a set: ids items[beg, end) of the pool (a range is stored as
   -first, last, step), or a whole node / element block, or the nodes of an
   element set, or another set named in a data line (visited once per
   traversal, so chains and cycles of references cost linear time). */
typedef struct inp_chunk {
    int scope;                /* scope the ids refer to                     */
    int file;
    uint32_t line;
    int64_t beg, end;
    int32_t nblock, eblock;   /* whole block, or -1                         */
    int32_t elset;            /* *NSET, ELSET=: that element set, or -1     */
    int32_t setref;           /* a set named in a data line, or -1          */
    int32_t next;
} inp_chunk;

typedef struct inp_section {
    int ns;
    int32_t elset;            /* name id                                    */
    int file;
    uint32_t line;
} inp_section;

typedef struct inp_deck {
    inp_file *files;          size_t nfiles, cap_files;
    inp_include *incs;        size_t nincs, cap_incs;

    int32_t nnodes;           size_t cap_nodes;
    double *xyz;              /* 3 per node                                 */
    int32_t *node_id;
    uint32_t *node_line;
    inp_node_block *nblocks;  size_t nnblocks, cap_nblocks;

    int32_t nelems;           size_t cap_elems;
    int32_t *elem_id;
    uint32_t *elem_line;
    int32_t *conn;            int64_t nconn; size_t cap_conn;
    inp_elem_block *eblocks;  size_t neblocks, cap_eblocks;

    inp_scope *scopes;        size_t nscopes, cap_scopes;
    inp_set *sets;            size_t nsets, cap_sets;
    inp_chunk *chunks;        size_t nchunks, cap_chunks;
    int32_t *items;           int64_t nitems; size_t cap_items;
    inp_section *sections;    size_t nsections, cap_sections;
    inp_strtab names;
    inp_hash lookup;          /* (what, scope, name id) -> set / scope      */

    /* first second-order planar element (refused only if planar elements
       are what gets smoothed) */
    int planar2_file;
    uint32_t planar2_line;
    char planar2_type[24];
    int32_t count_kind[5];    /* elements per inp_kind                      */
} inp_deck;

/* Key of the lookup table. */
enum { INP_LOOKUP_NSET = 0, INP_LOOKUP_ELSET = 1, INP_LOOKUP_PART = 2,
       INP_LOOKUP_INSTANCE = 3 };
int64_t inp_lookup_key(int what, int scope, int32_t name);

/* Read path and its includes into deck, plain data lines on threads
   threads (inp_fast.c).  On failure the message (one line,
   "file:line: ...") is in doc->error. */
getme_formats_status inp_read(inp_deck *deck, const char *path, getme_doc *doc,
                              int threads);
/* Room for n nodes / elements in the deck's per-node / per-element arrays
   (they grow together): 0 or -1. */
int inp_reserve_nodes(inp_deck *deck, size_t n);
int inp_reserve_elems(inp_deck *deck, size_t n);
/* Parse the plain *NODE (nv 0) or *ELEMENT (nv nodes each) data lines at
   the reader's position into the deck, on threads threads; stops before
   the first other line.  Returns how many lines were taken (the caller
   counts them into its open block).  *want is the window size, kept by
   the caller between calls. */
size_t inp_fast_run(inp_deck *deck, inp_lines *in, int nv, int threads,
                    size_t *want);
/* Inside a *NSET or *ELSET block (not GENERATE): the plain data lines at
   the reader's position that hold as many ids as the first of them (1 to
   64 numbers, blanks and a trailing comma allowed) appended to the pool of
   set items, on threads threads; stops before the first other line (a set
   name, another count, the block's last, shorter line...).  Returns how
   many lines were taken. */
size_t inp_fast_set(inp_deck *deck, inp_lines *in, int threads, size_t *want);
void inp_deck_free(inp_deck *deck);

/* Where an element / node was read, for messages: "file:line". */
const char *inp_file_name(const inp_deck *deck, int file);

/* ---- ids, sets, mesh (inp_build.c, inp_ids.c) ---------------------------- */

/* Id -> index lookup per scope: a direct table where ids are dense, a hash
   where they are sparse. */
typedef struct inp_ids {
    size_t nscopes;
    int64_t *min;             /* per scope                                  */
    int64_t *range;           /* table length, 0: use the hash              */
    int32_t **table;
    inp_hash sparse;          /* (scope << 32 | id) -> index                */
} inp_ids;

/* A run of consecutive entries [first, first + count) in one scope. */
typedef struct inp_run {
    int scope;
    int32_t first, count;
} inp_run;

/* Build from the ids of nruns runs.  On a duplicate returns 1 with
   *dup_first / *dup_second the two entry indices; -1 out of memory. */
int inp_ids_build(inp_ids *m, size_t nscopes, const int32_t *id,
                  const inp_run *runs, size_t nruns, int32_t *dup_first,
                  int32_t *dup_second);
int32_t inp_ids_get(const inp_ids *m, int scope, int64_t id);
void inp_ids_free(inp_ids *m);

/* State kept from open to write. */
typedef struct inp_doc {
    inp_file *files;
    size_t nfiles;
    inp_include *incs;
    size_t nincs;
    inp_node_block *nblocks;
    size_t nnblocks;
    int32_t *node_id;         /* per node, to check the file did not change */
    int32_t nnodes;
    int threads;              /* the writer's node lines (the reader's)      */
} inp_doc;

getme_formats_status inp_build(inp_deck *deck, getme_doc *doc,
                          const getme_doc_options *opts);
getme_formats_status inp_write(getme_doc *doc, const inp_doc *st,
                          const char *out_path);
void inp_doc_free(inp_doc *st);

/* %.15g if that reads back to v, else %.17g, within Abaqus' 20-character
   field limit (else the most digits that fit).  Returns the length written
   to buf (size >= 32). */
int inp_format_real(double v, char *buf);

/* ---- the writer's node lines (inp_write_nodes.c) ------------------------- */

/* Bytes a node line may grow by: three coordinates of up to 31 characters
   replaced or appended with ", " (and inp_format_real's NUL, overwritten
   by what follows it). */
#define INP_NODE_GROW 128

typedef struct inp_node_out {
    const int32_t *node_id; /* per node: its number in the deck          */
    const double *xyz;      /* the smoothed coordinates                   */
    double keep_tol;        /* moves up to this keep the line's text      */
    int threads;
    char *buf;              /* a run's output (grown as needed, owned)    */
    size_t cap;
} inp_node_out;

/* Node node's data line text[0..len) (no terminator) as it is written,
   into dst (room for len + INP_NODE_GROW bytes): its length, or -1 if the
   line is not that node's (the file changed).  *moved counts the lines
   whose coordinates change. */
long inp_node_text(const inp_node_out *o, const char *text, size_t len,
                   int32_t node, char *dst, int32_t *moved);

/* Inside a node block: the next plain node data lines of in (at most
   *remain; nodes *node, *node + 1...) rewritten to out, on o->threads
   threads, the same bytes as one by one; *node and *remain advance.  1 if
   it took lines, 0 if the next line is for the line-by-line path (not a
   plain data line of its node, or no memory), -1 on a write error. */
int inp_node_run(inp_node_out *o, inp_lines *in, int32_t *node,
                 int32_t *remain, FILE *out, int32_t *moved);

#endif /* GETME_INP_INTERNAL_H */
