/*
 * cgns_internal.h -- private declarations of the CGNS adapter
 * (cgns_format.c, cgns_reader.c, cgns_sections.c, cgns_bc.c, cgns_names.c,
 * cgns_writer.c).  Not installed.
 *
 * The adapter reads every unstructured zone of every base into one
 * getme_mesh: zone k owns the node range [node_offset, node_offset +
 * num_nodes) and the element range [first_elem, first_elem + num_elems).
 * Zones never share nodes (CGNS stores interface nodes once per zone), so
 * each zone's skin is fixed and zone interfaces stay conforming.
 *
 * libcgns keeps process-wide state (open file table, last error), so the
 * adapter is not thread-safe: open and write CGNS documents from one thread
 * at a time.
 */
#ifndef GETME_CGNS_INTERNAL_H
#define GETME_CGNS_INTERNAL_H

#include "adapter.h"

#include <cgnslib.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* CGNS names are at most 32 characters. */
#define CGNS_NAME_LEN 33
/* Longest node path we print: /Base/Zone/ZoneBC/BC (4 names + slashes). */
#define CGNS_PATH_LEN (5 * CGNS_NAME_LEN + 8)
/* FamilyName + AdditionalFamilyName entries we look at per node. */
#define CGNS_MAX_FAMS 4

typedef CGNS_ENUMT(ElementType_t) cgns_elem_t;
typedef CGNS_ENUMT(DataType_t) cgns_data_t;

/* What a name given to --fix / --free can designate. */
typedef enum cgns_set_kind {
    CGNS_SET_BC = 0,
    CGNS_SET_FAMILY = 1,
    CGNS_SET_ZONE = 2,
    CGNS_SET_SECTION = 3,
    CGNS_SET_KINDS = 4
} cgns_set_kind;

/* One named thing of the file (a BC, family, zone or section), collected
   once while scanning; the list is short (not per node or element). */
typedef struct cgns_set_name {
    cgns_set_kind kind;
    char name[CGNS_NAME_LEN];
} cgns_set_name;

/* The FamilyName and AdditionalFamilyName values under one node. */
typedef struct cgns_fams {
    int count;
    char name[CGNS_MAX_FAMS][CGNS_NAME_LEN];
} cgns_fams;

/* One unstructured zone that goes into the mesh. */
typedef struct cgns_zone {
    int base, zone;                 /* 1-based CGNS indices                */
    char base_name[CGNS_NAME_LEN];
    char name[CGNS_NAME_LEN];
    cgns_fams fams;                 /* the zone's families                 */
    int32_t node_offset, num_nodes;
    int32_t first_elem, num_elems;  /* smoothed elements of this zone      */
    int phys_dim;                   /* of the zone's base                  */
    int num_coords;                 /* coordinate arrays written back: 2|3 */
    cgns_data_t coord_type[3];      /* as stored: RealSingle / RealDouble  */
    int single;                     /* 1 if any coordinate is RealSingle   */
    /* Connectivity of the smoothed elements, kept only for zones with
       RealSingle coordinates (see cgns_writer.c): CSR over the zone's
       elements, zero-based global node indices. */
    int32_t *conn_offset;           /* num_elems + 1, or NULL              */
    int32_t *conn;
    uint8_t *conn_type;             /* getme_elem_type per element         */
} cgns_zone;

/* Where a block of added elements came from, for messages. */
typedef struct cgns_block {
    int32_t first;                  /* global index of its first element   */
    int zone;                       /* index into impl->zones              */
    char section[CGNS_NAME_LEN];
} cgns_block;

/* A region id per (zone, section family): faces between different regions
   are interfaces (fixed unless --free-interfaces). */
typedef struct cgns_region {
    int zone;
    char family[CGNS_NAME_LEN];
} cgns_region;

/* The adapter's private state (doc->impl). */
typedef struct cgns_impl {
    int file_type;                  /* CG_FILE_ADF / CG_FILE_HDF5 / ...    */
    int dim;                        /* smoothed dimension, 2 or 3          */
    int num_zones;
    cgns_zone *zones;
    int num_skipped;                /* structured zones left untouched     */
    char skipped[CGNS_NAME_LEN];    /* the first of them, for the info line */
    int num_blocks, cap_blocks;
    cgns_block *blocks;
    int num_regions, cap_regions;
    cgns_region *regions;
    int num_sets, cap_sets;
    cgns_set_name *sets;            /* names available to --fix / --free   */
    int64_t max_elems;              /* upper bound of smoothed elements    */
    int num_bcs;                    /* BC patches read                     */
    int num_bcs_fixed;              /* of them fixed (not freed)           */
    int num_bnd_sections;           /* lower-dimensional sections fixed    */
    double *orig;                   /* input coordinates (3 per node) when a
                                       zone is RealSingle, else NULL       */
    /* identity of the input when it was read: the writer copies it again
       and refuses if it changed in between */
    int64_t in_size;
    uint64_t in_dev, in_ino;
    int64_t in_mtime_ns;
} cgns_impl;

/* ---- cgns_format.c ------------------------------------------------------ */

/* Install the silent libcgns error handler (libcgns prints warnings to
   stderr otherwise); errors are read back with cg_get_error(). */
void cgns_quiet(void);

/* ---- cgns_names.c ------------------------------------------------------- */

/* Remember a name (duplicates of the same kind are stored once). */
getme_formats_status cgns_add_set(getme_doc *doc, cgns_impl *impl,
                             cgns_set_kind kind, const char *name);
/* Read the FamilyName / AdditionalFamilyName children of the node cg_goto
   last went to, and remember them as family names. */
getme_formats_status cgns_read_fams(getme_doc *doc, cgns_impl *impl,
                               cgns_fams *fams);
/* Check that every name in opts->fix and opts->free_sets exists and that no
   name is both fixed and freed; GETME_FORMATS_ERR_ARGUMENT with the list of
   available names otherwise. */
getme_formats_status cgns_check_names(getme_doc *doc, const cgns_impl *impl,
                                 const getme_doc_options *opts);
/* 1 if name or one of fams (either may be NULL) is in the list. */
int cgns_named(const char *name, const cgns_fams *fams, int count,
               const char *const *list);
/* Whether a set that is fixed by default (BC patch, boundary section)
   stays fixed: named by --fix, or not freed by --free. */
int cgns_default_fixed(const char *name, const cgns_fams *fams,
                       const getme_doc_options *opts);

/* ---- cgns_reader.c ------------------------------------------------------ */

/* Read the whole file into doc->mesh with fixed nodes marked. */
getme_formats_status cgns_read(getme_doc *doc, cgns_impl *impl, int fn,
                          const getme_doc_options *opts);
/* "/Base/Zone" of zone z into buf. */
void cgns_zone_path(const cgns_impl *impl, int z, char *buf, size_t size);
/* libcgns' last error, without trailing newline. */
const char *cgns_error(void);

/* ---- cgns_sections.c ---------------------------------------------------- */

/* Dimension of a CGNS element type (0 node, 1 bar, 2 face, 3 cell), -1 for
   MIXED or an unknown type. */
int cgns_type_dim(cgns_elem_t type);
/* The getme type of a supported linear CGNS type, or -1. */
int cgns_getme_type(cgns_elem_t type);
/* Second-order volume types (cgns_highorder.c): the getme_ho_type or -1;
   Gmsh's node k of the type is CGNS node order[k]. */
int cgns_ho_type(cgns_elem_t type);
const int8_t *cgns_ho_order(int ho_type);
/* What an element becomes in the mesh: a getme_elem_type, CGNS_HO + a
   getme_ho_type, or -1 (cgns_sections.c). */
#define CGNS_HO 100

/* The sections of one zone, kept in memory while the zone is read so that
   BCs can refer to element numbers. */
typedef struct cgns_section {
    char name[CGNS_NAME_LEN];
    cgns_fams fams;
    cgns_elem_t type;
    cgsize_t start, end;            /* element numbers (1-based, in zone) */
    cgsize_t *data;                 /* connectivity as stored (1-based)    */
    cgsize_t *offset;               /* MIXED/NGON/NFACE: start offsets, or
                                       NULL for a fixed-size type          */
    int npe;                        /* nodes per element (fixed-size)      */
} cgns_section;

/* Read all sections of zone z: add its smoothed elements to doc->mesh,
   mark the nodes of lower-dimensional (boundary) sections in fixed unless
   freed, and the nodes of sections named by opts->fix.  On success the
   caller owns *sections (free with cgns_free_sections). */
getme_formats_status cgns_read_sections(getme_doc *doc, cgns_impl *impl, int fn,
                                   int z, const getme_doc_options *opts,
                                   uint8_t *fixed, int64_t *elem_ids,
                                   cgns_section **sections,
                                   int *num_sections);
void cgns_free_sections(cgns_section *sections, int num_sections);
/* Nodes (1-based, in zone) of element number e of the zone: *nodes points
   into the section data.  0 on success, -1 if no section holds e. */
int cgns_element_nodes(const cgns_section *sections, int num_sections,
                       cgsize_t e, const cgsize_t **nodes, int *count);

/* ---- cgns_bc.c ---------------------------------------------------------- */

/* Mark the nodes of every BC patch of zone z in fixed (unless freed by
   opts->free_sets and not named by opts->fix). */
getme_formats_status cgns_read_bcs(getme_doc *doc, cgns_impl *impl, int fn, int z,
                              const getme_doc_options *opts, uint8_t *fixed,
                              const cgns_section *sections, int num_sections);

/* ---- cgns_writer.c ------------------------------------------------------ */

getme_formats_status cgns_write(getme_doc *doc, const char *out_path);
/* Refuse files whose coordinates (or a node above them) are links: the
   writer would modify the linked file. */
getme_formats_status cgns_check_links(getme_doc *doc, const cgns_impl *impl, int fn);

#endif /* GETME_CGNS_INTERNAL_H */
