/*
 * adapter.h -- the built-in adapters' view of a document (private to
 * libgetme_formats): the fields of getme_doc, the adapters of doc.c, and
 * the short status names the adapters use.
 */
#ifndef GETME_FORMATS_PRIVATE_ADAPTER_H
#define GETME_FORMATS_PRIVATE_ADAPTER_H

#include "getme_formats_adapter.h"

#include <stdint.h>

struct getme_doc {
    const getme_format *format;
    char *path;          /* input path (owned)                               */
    getme_mesh *mesh;    /* the mesh to smooth (owned)                       */
    void *impl;          /* adapter private state                            */
    /* element ids as written in the file, per global element index (may be
       NULL); used in messages about invalid elements                       */
    int64_t *elem_ids;
    /* when elem_ids was one run (id = e + 1 + elem_id_shift for every e) it
       is freed after the read: 8 bytes per element less through smoothing */
    int64_t elem_id_shift;
    /* one part of a partitioned MSH file (getme_doc_options.one_part):
       node tags per mesh node, region keys per element, partitions     */
    uint64_t *node_ids;
    int32_t *elem_region;
    int num_partitions;
    getme_quality_stats stats; /* all elements as read (getme_doc_open)     */
    int have_stats;
    char info[1024];     /* one line the CLI may log: zones, sets, fixed...  */
    char error[1024];    /* the last error, one line                         */
    char warning[1024];  /* input accepted with a caveat, one line           */
    /* an adapter loaded as a module for this document (cgns/cgns_load.c):
       its dlopen handle and its adapter, or NULL                          */
    void *module;
    const getme_format *module_format;
};

/* The built-in adapters (each in its own folder). */
extern const getme_format getme__format_msh;  /* msh/msh_format.c   */
extern const getme_format getme__format_inp;  /* inp/inp_format.c   */
extern const getme_format getme__format_cgns; /* cgns/cgns_load.c   */

#endif /* GETME_FORMATS_PRIVATE_ADAPTER_H */
