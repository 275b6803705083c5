/*
 * cgns_sections.c -- Elements_t sections of one CGNS zone: element types,
 * validation of the connectivity, the smoothed elements added to the mesh,
 * the nodes of lower-dimensional (boundary) sections fixed.
 *
 * CGNS numbers the nodes of TETRA_4, PYRA_5, PENTA_6, HEXA_8, TRI_3 and
 * QUAD_4 exactly as getme (and Gmsh) do, so connectivity is copied as is
 * (docs/design.md §1; tests/cgns/test_cgns_interop.py checks it for the
 * volume types on a file converted by the CGNS project's aflr3_to_cgns).
 */
#include "cgns_internal.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

int cgns_type_dim(cgns_elem_t type)
{
    /* Classify by the SIDS name: every linear and high-order variant of a
       shape shares its prefix (TETRA_4 ... TETRA_35). */
    static const struct { const char *prefix; int dim; } table[] = {
        {"NODE", 0},  {"BAR_", 1},  {"TRI_", 2},   {"QUAD_", 2},
        {"NGON_n", 2}, {"TETRA_", 3}, {"PYRA_", 3}, {"PENTA_", 3},
        {"HEXA_", 3}, {"NFACE_n", 3}};
    const char *name;

    if (type == CGNS_ENUMV(MIXED) || (int)type < 0 ||
        (int)type >= NofValidElementTypes)
        return -1;
    name = cg_ElementTypeName(type);
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (strncmp(name, table[i].prefix, strlen(table[i].prefix)) == 0)
            return table[i].dim;
    return -1;
}

int cgns_getme_type(cgns_elem_t type)
{
    switch (type) {
    case CGNS_ENUMV(TETRA_4): return GETME_TET;
    case CGNS_ENUMV(PYRA_5):  return GETME_PYRAMID;
    case CGNS_ENUMV(PENTA_6): return GETME_PRISM;
    case CGNS_ENUMV(HEXA_8):  return GETME_HEX;
    case CGNS_ENUMV(TRI_3):   return GETME_TRI;
    case CGNS_ENUMV(QUAD_4):  return GETME_QUAD;
    default:                  return -1;
    }
}

/* getme_elem_type, CGNS_HO + getme_ho_type (second order), or -1. */
static int smooth_kind(cgns_elem_t type)
{
    int ho = cgns_ho_type(type);
    return ho >= 0 ? CGNS_HO + ho : cgns_getme_type(type);
}

static int kind_nodes(int kind)
{
    return kind >= CGNS_HO ? getme_ho_type_num_nodes((getme_ho_type)(kind - CGNS_HO))
                           : getme_type_num_nodes((getme_elem_type)kind);
}

static int is_poly(cgns_elem_t type)
{
    return type == CGNS_ENUMV(MIXED) || type == CGNS_ENUMV(NGON_n) ||
           type == CGNS_ENUMV(NFACE_n);
}

/* Element i (0-based in its section): type, first node, node count.  For
   NFACE_n the "nodes" are face numbers. */
static void element_at(const cgns_section *sec, cgsize_t i, cgns_elem_t *type,
                       const cgsize_t **nodes, int *count)
{
    if (!sec->offset) {
        *type = sec->type;
        *nodes = sec->data + (size_t)i * (size_t)sec->npe;
        *count = sec->npe;
    } else if (sec->type == CGNS_ENUMV(MIXED)) {
        const cgsize_t *p = sec->data + sec->offset[i];
        *type = (cgns_elem_t)p[0];
        *nodes = p + 1;
        *count = (int)(sec->offset[i + 1] - sec->offset[i] - 1);
    } else {
        *type = sec->type;
        *nodes = sec->data + sec->offset[i];
        *count = (int)(sec->offset[i + 1] - sec->offset[i]);
    }
}

int cgns_element_nodes(const cgns_section *sections, int num_sections,
                       cgsize_t e, const cgsize_t **nodes, int *count)
{
    for (int s = 0; s < num_sections; s++) {
        const cgns_section *sec = &sections[s];
        cgns_elem_t type;
        if (e < sec->start || e > sec->end || sec->type == CGNS_ENUMV(NFACE_n))
            continue;
        element_at(sec, e - sec->start, &type, nodes, count);
        return 0;
    }
    return -1;
}

void cgns_free_sections(cgns_section *sections, int num_sections)
{
    if (!sections)
        return;
    for (int s = 0; s < num_sections; s++) {
        free(sections[s].data);
        free(sections[s].offset);
    }
    free(sections);
}

/* ---- reading and validating one section --------------------------------- */

typedef struct zone_ctx {
    getme_doc *doc;
    cgns_impl *impl;
    int z;                          /* index into impl->zones */
    char path[CGNS_PATH_LEN];       /* "/Base/Zone" */
    const getme_doc_options *opts;
    uint8_t *fixed;
    int64_t *elem_ids;
} zone_ctx;

static getme_formats_status oom(const zone_ctx *c)
{
    return getme_doc_fail(c->doc, GETME_FORMATS_ERR_INTERNAL, "%s: out of memory",
                          c->doc->path);
}

/* Offsets of a MIXED / NGON_n / NFACE_n section must grow and end at the
   data size; MIXED entries must be fixed-size types of the right length. */
static getme_formats_status check_offsets(const zone_ctx *c, const cgns_section *sec,
                                     cgsize_t size)
{
    cgsize_t n = sec->end - sec->start + 1;

    if (sec->offset[0] != 0 || sec->offset[n] != size)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s/%s: ElementStartOffset does not match "
                              "the connectivity size", c->doc->path, c->path,
                              sec->name);
    for (cgsize_t i = 0; i < n; i++) {
        cgsize_t len = sec->offset[i + 1] - sec->offset[i];
        int npe = 0;
        if (len < 1)
            return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                                  "%s: %s/%s: element %ld has no nodes",
                                  c->doc->path, c->path, sec->name,
                                  (long)(sec->start + i));
        if (sec->type != CGNS_ENUMV(MIXED))
            continue;
        cgns_elem_t t = (cgns_elem_t)sec->data[sec->offset[i]];
        if ((int)t <= CGNS_ENUMV(ElementTypeUserDefined) ||
            (int)t >= NofValidElementTypes || is_poly(t) ||
            cg_npe(t, &npe) != CG_OK || npe <= 0 || len != npe + 1)
            return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                                  "%s: %s/%s: element %ld has an invalid "
                                  "MIXED entry (type code %ld, %ld values)",
                                  c->doc->path, c->path, sec->name,
                                  (long)(sec->start + i), (long)t, (long)len);
    }
    return GETME_FORMATS_OK;
}

/* Every node number must lie in 1..num_nodes of the zone. */
static getme_formats_status check_nodes(const zone_ctx *c, const cgns_section *sec)
{
    cgsize_t n = sec->end - sec->start + 1;
    int32_t nn = c->impl->zones[c->z].num_nodes;

    if (sec->type == CGNS_ENUMV(NFACE_n))
        return GETME_FORMATS_OK; /* face numbers, refused later anyway */
    for (cgsize_t i = 0; i < n; i++) {
        cgns_elem_t t;
        const cgsize_t *nodes;
        int count;
        element_at(sec, i, &t, &nodes, &count);
        for (int k = 0; k < count; k++)
            if (nodes[k] < 1 || nodes[k] > nn)
                return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                                      "%s: %s/%s: element %ld refers to node "
                                      "%ld, the zone has %ld nodes",
                                      c->doc->path, c->path, sec->name,
                                      (long)(sec->start + i), (long)nodes[k],
                                      (long)nn);
    }
    return GETME_FORMATS_OK;
}

static getme_formats_status read_section(const zone_ctx *c, int fn, int S,
                                    cgns_section *sec)
{
    const cgns_zone *zone = &c->impl->zones[c->z];
    int nbndry, parent_flag;
    cgsize_t size;
    getme_formats_status st;

    if (cg_section_read(fn, zone->base, zone->zone, S, sec->name, &sec->type,
                        &sec->start, &sec->end, &nbndry, &parent_flag) != CG_OK)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s: section %d: %s", c->doc->path, c->path,
                              S, cgns_error());
    if (sec->start < 1 || sec->end < sec->start)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s/%s: invalid ElementRange %ld..%ld",
                              c->doc->path, c->path, sec->name,
                              (long)sec->start, (long)sec->end);
    if (cg_goto(fn, zone->base, "Zone_t", zone->zone, "Elements_t", S,
                "end") != CG_OK)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE, "%s: %s/%s: %s",
                              c->doc->path, c->path, sec->name, cgns_error());
    st = cgns_read_fams(c->doc, c->impl, &sec->fams);
    if (st != GETME_FORMATS_OK)
        return st;
    if (cg_ElementDataSize(fn, zone->base, zone->zone, S, &size) != CG_OK ||
        size < 1)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s/%s: no ElementConnectivity (%s)",
                              c->doc->path, c->path, sec->name, cgns_error());
    sec->data = getme__malloc((size_t)size * sizeof *sec->data);
    if (!sec->data)
        return oom(c);
    cgsize_t n = sec->end - sec->start + 1;
    int rc;
    if (is_poly(sec->type)) {
        sec->offset = getme__malloc((size_t)(n + 1) * sizeof *sec->offset);
        if (!sec->offset)
            return oom(c);
        rc = cg_poly_elements_read(fn, zone->base, zone->zone, S, sec->data,
                                   sec->offset, NULL);
    } else {
        if (cg_npe(sec->type, &sec->npe) != CG_OK || sec->npe <= 0)
            return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                                  "%s: %s/%s: unknown element type %d",
                                  c->doc->path, c->path, sec->name,
                                  (int)sec->type);
        if (size != n * sec->npe)
            return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                                  "%s: %s/%s: ElementConnectivity has %ld "
                                  "values, %ld %s elements need %ld",
                                  c->doc->path, c->path, sec->name, (long)size,
                                  (long)n, cg_ElementTypeName(sec->type),
                                  (long)(n * sec->npe));
        rc = cg_elements_read(fn, zone->base, zone->zone, S, sec->data, NULL);
    }
    if (rc != CG_OK)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s/%s: cannot read the connectivity: %s",
                              c->doc->path, c->path, sec->name, cgns_error());
    if (sec->offset && (st = check_offsets(c, sec, size)) != GETME_FORMATS_OK)
        return st;
    return check_nodes(c, sec);
}

/* ---- what each element becomes ------------------------------------------ */

/* Refuse an element of the smoothed dimension (or higher) that getme cannot
   smooth: second-order, polyhedral, or of a higher dimension. */
static getme_formats_status refuse(const zone_ctx *c, const cgns_section *sec,
                              cgns_elem_t t, cgsize_t number)
{
    int d = cgns_type_dim(t);
    const char *why = d > c->impl->dim
        ? "elements of a higher dimension than the base's cell dimension"
        : (t == CGNS_ENUMV(NGON_n) || t == CGNS_ENUMV(NFACE_n))
            ? "polygonal/polyhedral elements are not smoothed"
            : "only TETRA_4, PYRA_5, PENTA_6, HEXA_8, TETRA_10, HEXA_20, "
              "HEXA_27, PENTA_15, PENTA_18, PYRA_13, PYRA_14 (3-D) and "
              "TRI_3, QUAD_4, TRI_6, QUAD_8, QUAD_9 (2-D) elements are "
              "smoothed";
    return getme_doc_fail(c->doc, GETME_FORMATS_ERR_UNSUPPORTED,
                          "%s: %s/%s: element %ld is %s: %s", c->doc->path,
                          c->path, sec->name, (long)number,
                          cg_ElementTypeName(t), why);
}

static void mark_nodes(const zone_ctx *c, const cgsize_t *nodes, int count)
{
    int32_t off = c->impl->zones[c->z].node_offset;
    for (int k = 0; k < count; k++)
        c->fixed[off + nodes[k] - 1] = 1;
}

/* Region id of the zone's elements of a section with these families. */
static int region_id(const zone_ctx *c, const cgns_fams *fams)
{
    cgns_impl *impl = c->impl;
    const char *fam = fams->count ? fams->name[0] : "";

    for (int r = 0; r < impl->num_regions; r++)
        if (impl->regions[r].zone == c->z &&
            strcmp(impl->regions[r].family, fam) == 0)
            return r;
    if (impl->num_regions == impl->cap_regions) {
        int cap = impl->cap_regions ? 2 * impl->cap_regions : 16;
        cgns_region *r = getme__realloc(impl->regions, (size_t)cap * sizeof *r);
        if (!r)
            return -1;
        impl->regions = r;
        impl->cap_regions = cap;
    }
    impl->regions[impl->num_regions].zone = c->z;
    snprintf(impl->regions[impl->num_regions].family, CGNS_NAME_LEN, "%s", fam);
    return impl->num_regions++;
}

/* Keep the connectivity of a RealSingle zone (see cgns_writer.c). */
static getme_formats_status keep_conn(const zone_ctx *c, int type, int32_t count,
                                 const int32_t *conn, int32_t have)
{
    cgns_zone *zone = &c->impl->zones[c->z];
    int nv = getme_type_num_nodes((getme_elem_type)type);
    int32_t used = zone->conn_offset ? zone->conn_offset[have] : 0;
    int32_t *off = getme__realloc(zone->conn_offset,
                                  (size_t)(have + count + 1) * sizeof *off);
    if (!off)
        return oom(c);
    zone->conn_offset = off;
    int32_t *cn = getme__realloc(zone->conn,
                                 ((size_t)used + (size_t)count * (size_t)nv) * sizeof *cn);
    uint8_t *ty =
        cn ? getme__realloc(zone->conn_type, (size_t)(have + count)) : NULL;
    if (cn)
        zone->conn = cn;
    if (!ty)
        return oom(c);
    zone->conn_type = ty;
    off[0] = 0;
    memcpy(cn + used, conn, (size_t)count * (size_t)nv * sizeof *cn);
    for (int32_t i = 0; i < count; i++) {
        off[have + i + 1] = used + (i + 1) * nv;
        ty[have + i] = (uint8_t)type;
    }
    return GETME_FORMATS_OK;
}

/* Add count elements of one getme type: conn holds 1-based zone node
   numbers, numbers[] their CGNS element numbers. */
static getme_formats_status add_block(const zone_ctx *c, const cgns_section *sec,
                                 int type, int32_t count, int32_t *conn,
                                 const cgsize_t *numbers)
{
    cgns_impl *impl = c->impl;
    int nv = kind_nodes(type);
    int32_t off = impl->zones[c->z].node_offset;
    int32_t first = getme_mesh_num_elements(c->doc->mesh);
    int region = region_id(c, &sec->fams);
    int32_t *regions = getme__malloc((size_t)count * sizeof *regions);
    getme_formats_status st = GETME_FORMATS_OK;

    if (!regions || region < 0) {
        free(regions);
        return oom(c);
    }
    for (int32_t i = 0; i < count; i++) {
        const int32_t *e = conn + (size_t)i * (size_t)nv;
        for (int a = 0; a < nv; a++)
            for (int b = a + 1; b < nv; b++)
                if (e[a] == e[b]) {
                    free(regions);
                    return getme_doc_fail(c->doc, GETME_FORMATS_ERR_INVALID,
                                          "%s: %s/%s: element %ld is "
                                          "degenerate: node %ld appears "
                                          "twice; getme smooths valid meshes "
                                          "only", c->doc->path, c->path,
                                          sec->name, (long)numbers[i],
                                          (long)e[a]);
                }
        regions[i] = region;
        c->elem_ids[first + i] = numbers[i];
    }
    for (size_t k = 0; k < (size_t)count * (size_t)nv; k++)
        conn[k] += off - 1;
    getme_status gs =
        type >= CGNS_HO
            ? getme_mesh_add_elements_ho(c->doc->mesh,
                                         (getme_ho_type)(type - CGNS_HO),
                                         count, conn, regions)
            : getme_mesh_add_elements(c->doc->mesh, (getme_elem_type)type,
                                      count, conn, regions);
    if (gs != GETME_OK)
        st = getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE, "%s: %s/%s: %s",
                            c->doc->path, c->path, sec->name,
                            getme_mesh_error(c->doc->mesh));
    free(regions);
    if (st == GETME_FORMATS_OK && impl->zones[c->z].single && type >= CGNS_HO) {
        /* the float rounding repair checks the corners only (README) */
        int lin = getme_ho_type_linear((getme_ho_type)(type - CGNS_HO));
        int nl = getme_type_num_nodes((getme_elem_type)lin);
        for (int32_t i = 0; i < count; i++) /* in place: nl <= nv */
            for (int a = 0; a < nl; a++)
                conn[(size_t)i * nl + a] = conn[(size_t)i * nv + a];
        st = keep_conn(c, lin, count, conn,
                       first - impl->zones[c->z].first_elem);
    } else if (st == GETME_FORMATS_OK && impl->zones[c->z].single)
        st = keep_conn(c, type, count, conn,
                       first - impl->zones[c->z].first_elem);
    if (st != GETME_FORMATS_OK)
        return st;
    if (impl->num_blocks == impl->cap_blocks) {
        int cap = impl->cap_blocks ? 2 * impl->cap_blocks : 16;
        cgns_block *b = getme__realloc(impl->blocks, (size_t)cap * sizeof *b);
        if (!b)
            return oom(c);
        impl->blocks = b;
        impl->cap_blocks = cap;
    }
    impl->blocks[impl->num_blocks].first = first;
    impl->blocks[impl->num_blocks].zone = c->z;
    snprintf(impl->blocks[impl->num_blocks].section, CGNS_NAME_LEN, "%s",
             sec->name);
    impl->num_blocks++;
    return GETME_FORMATS_OK;
}

/* Gather the section's elements of one getme type and add them. */
static getme_formats_status add_type(const zone_ctx *c, const cgns_section *sec,
                                int type, int32_t count)
{
    int nv = kind_nodes(type);
    const int8_t *order =
        type >= CGNS_HO ? cgns_ho_order(type - CGNS_HO) : NULL;
    int32_t *conn = getme__malloc((size_t)count * (size_t)nv * sizeof *conn);
    cgsize_t *numbers = getme__malloc((size_t)count * sizeof *numbers);
    cgsize_t n = sec->end - sec->start + 1;
    int32_t k = 0;
    getme_formats_status st;

    if (!conn || !numbers) {
        free(conn);
        free(numbers);
        return oom(c);
    }
    for (cgsize_t i = 0; i < n; i++) {
        cgns_elem_t t;
        const cgsize_t *nodes;
        int cnt;
        element_at(sec, i, &t, &nodes, &cnt);
        if (smooth_kind(t) != type)
            continue;
        for (int a = 0; a < nv; a++)
            conn[(size_t)k * (size_t)nv + (size_t)a] =
                (int32_t)nodes[order ? order[a] : a];
        numbers[k++] = sec->start + i;
    }
    st = add_block(c, sec, type, count, conn, numbers);
    free(conn);
    free(numbers);
    return st;
}

/* Sort the section's elements: smoothed ones are added per type, lower-
   dimensional ones fix their nodes, anything else is refused. */
static getme_formats_status use_section(const zone_ctx *c, const cgns_section *sec)
{
    int32_t counts[CGNS_HO + GETME_NUM_HO_TYPES] = {0};
    cgsize_t n = sec->end - sec->start + 1;
    int fix_boundary = cgns_default_fixed(sec->name, &sec->fams, c->opts);
    int fix_all = cgns_named(sec->name, &sec->fams, c->opts->num_fix,
                             c->opts->fix);
    int boundary = 0;

    for (cgsize_t i = 0; i < n; i++) {
        cgns_elem_t t;
        const cgsize_t *nodes;
        int cnt;
        element_at(sec, i, &t, &nodes, &cnt);
        int d = cgns_type_dim(t), g = smooth_kind(t);
        if (d >= 0 && d < c->impl->dim) {
            boundary = 1;
            if (fix_boundary)
                mark_nodes(c, nodes, cnt);
            continue;
        }
        if (d != c->impl->dim || g < 0)
            return refuse(c, sec, t, sec->start + i);
        counts[g]++;
        if (fix_all)
            mark_nodes(c, nodes, cnt);
    }
    if (boundary && fix_boundary)
        c->impl->num_bnd_sections++;
    for (int g = 0; g < CGNS_HO + GETME_NUM_HO_TYPES; g++) {
        if (counts[g] == 0)
            continue;
        getme_formats_status st = add_type(c, sec, g, counts[g]);
        if (st != GETME_FORMATS_OK)
            return st;
    }
    return GETME_FORMATS_OK;
}

getme_formats_status cgns_read_sections(getme_doc *doc, cgns_impl *impl, int fn,
                                   int z, const getme_doc_options *opts,
                                   uint8_t *fixed, int64_t *elem_ids,
                                   cgns_section **sections, int *num_sections)
{
    zone_ctx c = {doc, impl, z, "", opts, fixed, elem_ids};
    cgns_zone *zone = &impl->zones[z];
    int ns = 0;
    getme_formats_status st = GETME_FORMATS_OK;

    cgns_zone_path(impl, z, c.path, sizeof c.path);
    *sections = NULL;
    *num_sections = 0;
    if (cg_nsections(fn, zone->base, zone->zone, &ns) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE, "%s: %s: %s", doc->path,
                              c.path, cgns_error());
    cgns_section *secs = getme__calloc(ns > 0 ? (size_t)ns : 1, sizeof *secs);
    if (!secs)
        return oom(&c);
    zone->first_elem = getme_mesh_num_elements(doc->mesh);
    for (int s = 0; s < ns && st == GETME_FORMATS_OK; s++) {
        st = read_section(&c, fn, s + 1, &secs[s]);
        if (st == GETME_FORMATS_OK)
            st = use_section(&c, &secs[s]);
    }
    zone->num_elems = getme_mesh_num_elements(doc->mesh) - zone->first_elem;
    if (st != GETME_FORMATS_OK) {
        cgns_free_sections(secs, ns);
        return st;
    }
    *sections = secs;
    *num_sections = ns;
    return GETME_FORMATS_OK;
}
