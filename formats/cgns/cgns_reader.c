/*
 * cgns_reader.c -- read a CGNS file (opened with cg_open MODE_READ) into
 * one getme_mesh: scan bases and zones, read coordinates, then sections and
 * BCs zone by zone, then mark the fixed nodes and check the input is valid.
 */
#include "cgns_internal.h"
#include "getme_alloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *cgns_error(void)
{
    const char *msg = cg_get_error();
    return msg && msg[0] ? msg : "unknown libcgns error";
}

void cgns_zone_path(const cgns_impl *impl, int z, char *buf, size_t size)
{
    snprintf(buf, size, "/%s/%s", impl->zones[z].base_name,
             impl->zones[z].name);
}

static getme_formats_status oom(getme_doc *doc)
{
    return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "%s: out of memory",
                          doc->path);
}

/* ---- pass 1: what is in the file (no bulk data) ------------------------- */

static getme_formats_status scan_sections(getme_doc *doc, cgns_impl *impl, int fn,
                                     const cgns_zone *zone)
{
    int ns = 0;
    char name[CGNS_NAME_LEN];
    cgns_elem_t type;
    cgsize_t start, end;
    int nbndry, parent;
    cgns_fams fams;
    getme_formats_status st;

    if (cg_nsections(fn, zone->base, zone->zone, &ns) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE, "%s: /%s/%s: %s",
                              doc->path, zone->base_name, zone->name,
                              cgns_error());
    for (int s = 1; s <= ns; s++) {
        if (cg_section_read(fn, zone->base, zone->zone, s, name, &type, &start,
                            &end, &nbndry, &parent) != CG_OK)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                                  "%s: /%s/%s: section %d: %s", doc->path,
                                  zone->base_name, zone->name, s, cgns_error());
        if ((st = cgns_add_set(doc, impl, CGNS_SET_SECTION, name)) != GETME_FORMATS_OK)
            return st;
        if (cg_goto(fn, zone->base, "Zone_t", zone->zone, "Elements_t", s,
                    "end") == CG_OK &&
            (st = cgns_read_fams(doc, impl, &fams)) != GETME_FORMATS_OK)
            return st;
        if (end >= start && (type == CGNS_ENUMV(MIXED) ||
                             cgns_type_dim(type) == impl->dim))
            impl->max_elems += (int64_t)(end - start + 1);
    }
    return GETME_FORMATS_OK;
}

static getme_formats_status scan_bcs(getme_doc *doc, cgns_impl *impl, int fn,
                                const cgns_zone *zone)
{
    int nb = 0, normal_index[3], ndataset;
    char name[CGNS_NAME_LEN];
    CGNS_ENUMT(BCType_t) type;
    CGNS_ENUMT(PointSetType_t) ptset;
    CGNS_ENUMT(DataType_t) normal_type;
    cgsize_t npnts, normal_size;
    cgns_fams fams;
    getme_formats_status st;

    if (cg_nbocos(fn, zone->base, zone->zone, &nb) != CG_OK)
        nb = 0; /* reported with its path when the BCs are read */
    for (int bc = 1; bc <= nb; bc++) {
        if (cg_boco_info(fn, zone->base, zone->zone, bc, name, &type, &ptset,
                         &npnts, normal_index, &normal_size, &normal_type,
                         &ndataset) != CG_OK)
            continue;
        if ((st = cgns_add_set(doc, impl, CGNS_SET_BC, name)) != GETME_FORMATS_OK)
            return st;
        if (cg_goto(fn, zone->base, "Zone_t", zone->zone, "ZoneBC_t", 1,
                    "BC_t", bc, "end") == CG_OK &&
            (st = cgns_read_fams(doc, impl, &fams)) != GETME_FORMATS_OK)
            return st;
    }
    return GETME_FORMATS_OK;
}

/* Append zone Z of base B (unstructured, cell dimension impl->dim). */
static getme_formats_status scan_zone(getme_doc *doc, cgns_impl *impl, int fn,
                                 int B, const char *base_name, int phys_dim,
                                 int Z, int64_t *total_nodes)
{
    cgsize_t size[3];
    cgns_zone *zone;
    getme_formats_status st;

    cgns_zone *zones = getme__realloc(impl->zones,
                                      (size_t)(impl->num_zones + 1) * sizeof *zones);
    if (!zones)
        return oom(doc);
    impl->zones = zones;
    zone = &zones[impl->num_zones];
    memset(zone, 0, sizeof *zone);
    zone->base = B;
    zone->zone = Z;
    snprintf(zone->base_name, CGNS_NAME_LEN, "%s", base_name);
    if (cg_zone_read(fn, B, Z, zone->name, size) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE, "%s: /%s: zone %d: %s",
                              doc->path, base_name, Z, cgns_error());
    impl->num_zones++;
    if (size[0] < 1)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: /%s/%s: zone has no vertices", doc->path,
                              base_name, zone->name);
    if (*total_nodes + size[0] > INT32_MAX)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "%s: more than %ld nodes in all zones",
                              doc->path, (long)INT32_MAX);
    zone->node_offset = (int32_t)*total_nodes;
    zone->num_nodes = (int32_t)size[0];
    *total_nodes += size[0];
    zone->num_coords = impl->dim;
    zone->phys_dim = phys_dim;
    if ((st = cgns_add_set(doc, impl, CGNS_SET_ZONE, zone->name)) != GETME_FORMATS_OK)
        return st;
    if (cg_goto(fn, B, "Zone_t", Z, "end") == CG_OK &&
        (st = cgns_read_fams(doc, impl, &zone->fams)) != GETME_FORMATS_OK)
        return st;
    if ((st = scan_sections(doc, impl, fn, zone)) != GETME_FORMATS_OK)
        return st;
    return scan_bcs(doc, impl, fn, zone);
}

static getme_formats_status scan_base(getme_doc *doc, cgns_impl *impl, int fn,
                                 int B, int64_t *total_nodes)
{
    char base_name[CGNS_NAME_LEN], name[CGNS_NAME_LEN];
    int cell_dim, phys_dim, nfam = 0, nz = 0, nboco, ngeo;
    getme_formats_status st;

    if (cg_base_read(fn, B, base_name, &cell_dim, &phys_dim) != CG_OK ||
        cg_nzones(fn, B, &nz) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE, "%s: base %d: %s",
                              doc->path, B, cgns_error());
    if (cg_nfamilies(fn, B, &nfam) != CG_OK)
        nfam = 0;
    for (int f = 1; f <= nfam; f++)
        if (cg_family_read(fn, B, f, name, &nboco, &ngeo) == CG_OK &&
            (st = cgns_add_set(doc, impl, CGNS_SET_FAMILY, name)) != GETME_FORMATS_OK)
            return st;
    for (int Z = 1; Z <= nz; Z++) {
        CGNS_ENUMT(ZoneType_t) type;
        if (cg_zone_type(fn, B, Z, &type) != CG_OK)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE, "%s: /%s: zone %d: %s",
                                  doc->path, base_name, Z, cgns_error());
        if (type != CGNS_ENUMV(Unstructured)) {
            /* Structured blocks are left as they are: their nodes are not in
               the mesh, and every unstructured zone's skin (which holds any
               interface with them) is fixed. */
            if (impl->num_skipped++ == 0 &&
                cg_zone_read(fn, B, Z, name, (cgsize_t[9]){0}) == CG_OK)
                snprintf(impl->skipped, CGNS_NAME_LEN, "%s", name);
            continue;
        }
        if (cell_dim != 2 && cell_dim != 3)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                                  "%s: /%s: cell dimension %d: getme smooths "
                                  "volume (3) and planar (2) meshes",
                                  doc->path, base_name, cell_dim);
        if (phys_dim < cell_dim)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                                  "%s: /%s: physical dimension %d is below the "
                                  "cell dimension %d", doc->path, base_name,
                                  phys_dim, cell_dim);
        if (impl->dim && impl->dim != cell_dim)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                                  "%s: /%s: cell dimension %d differs from the "
                                  "%d of an earlier base", doc->path, base_name,
                                  cell_dim, impl->dim);
        impl->dim = cell_dim;
        if ((st = scan_zone(doc, impl, fn, B, base_name, phys_dim, Z,
                            total_nodes)) !=
            GETME_FORMATS_OK)
            return st;
    }
    return GETME_FORMATS_OK;
}

static getme_formats_status scan(getme_doc *doc, cgns_impl *impl, int fn,
                            int64_t *total_nodes)
{
    int nb = 0;
    getme_formats_status st;

    if (cg_nbases(fn, &nb) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE, "%s: %s", doc->path,
                              cgns_error());
    if (nb < 1)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: no CGNSBase_t node", doc->path);
    for (int B = 1; B <= nb; B++)
        if ((st = scan_base(doc, impl, fn, B, total_nodes)) != GETME_FORMATS_OK)
            return st;
    if (impl->num_zones == 0 && impl->num_skipped > 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "%s: only structured zones (e.g. '%s'): getme "
                              "smooths unstructured zones only", doc->path,
                              impl->skipped);
    if (impl->num_zones == 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE, "%s: no zones",
                              doc->path);
    return GETME_FORMATS_OK;
}

/* ---- coordinates -------------------------------------------------------- */

static getme_formats_status read_coord(getme_doc *doc, cgns_impl *impl, int fn,
                                  int z, int k, double *coords, double *buf)
{
    static const char *const names[3] = {"CoordinateX", "CoordinateY",
                                         "CoordinateZ"};
    cgns_zone *zone = &impl->zones[z];
    char path[CGNS_PATH_LEN], name[CGNS_NAME_LEN];
    int nc = 0, found = 0;
    cgsize_t one = 1, n = zone->num_nodes;

    cgns_zone_path(impl, z, path, sizeof path);
    if (cg_ncoords(fn, zone->base, zone->zone, &nc) != CG_OK)
        nc = 0;
    for (int c = 1; c <= nc && !found; c++) {
        cgns_data_t type;
        if (cg_coord_info(fn, zone->base, zone->zone, c, &type, name) == CG_OK &&
            strcmp(name, names[k]) == 0) {
            found = 1;
            zone->coord_type[k] = type;
        }
    }
    if (!found)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s/GridCoordinates/%s is missing (getme "
                              "needs Cartesian coordinates)", doc->path, path,
                              names[k]);
    if (zone->coord_type[k] != CGNS_ENUMV(RealDouble) &&
        zone->coord_type[k] != CGNS_ENUMV(RealSingle))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s/GridCoordinates/%s has data type %s, "
                              "not RealSingle or RealDouble", doc->path, path,
                              names[k], cg_DataTypeName(zone->coord_type[k]));
    if (cg_coord_read(fn, zone->base, zone->zone, names[k],
                      CGNS_ENUMV(RealDouble), &one, &n, buf) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s/GridCoordinates/%s: %s", doc->path, path,
                              names[k], cgns_error());
    for (cgsize_t i = 0; i < n; i++) {
        if (!isfinite(buf[i]))
            return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                                  "%s: %s/GridCoordinates/%s: node %ld is not "
                                  "a finite number", doc->path, path, names[k],
                                  (long)(i + 1));
        coords[3 * ((size_t)zone->node_offset + (size_t)i) + (size_t)k] = buf[i];
    }
    if (zone->coord_type[k] == CGNS_ENUMV(RealSingle))
        zone->single = 1;
    return GETME_FORMATS_OK;
}

/* Rind planes would shift the arrays against the node numbers. */
static getme_formats_status check_rind(getme_doc *doc, cgns_impl *impl, int fn,
                                  int z)
{
    const cgns_zone *zone = &impl->zones[z];
    char path[CGNS_PATH_LEN];
    int rind[2] = {0, 0};

    cgns_zone_path(impl, z, path, sizeof path);
    if (cg_goto(fn, zone->base, "Zone_t", zone->zone, "GridCoordinates_t", 1,
                "end") != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s/GridCoordinates is missing", doc->path,
                              path);
    if (cg_rind_read(rind) == CG_OK && (rind[0] || rind[1]))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "%s: %s/GridCoordinates has rind points, which "
                              "getme does not handle", doc->path, path);
    return GETME_FORMATS_OK;
}

/* A planar mesh must lie in a plane z = const (the core smooths x, y). */
static getme_formats_status check_planar(getme_doc *doc, const double *coords,
                                    int32_t n)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY};
    double hi[3] = {-INFINITY, -INFINITY, -INFINITY};

    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], coords[3 * (size_t)i + (size_t)k]);
            hi[k] = fmax(hi[k], coords[3 * (size_t)i + (size_t)k]);
        }
    double extent = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    if (hi[2] - lo[2] > 1e-12 * fmax(extent, fmax(fabs(lo[2]), fabs(hi[2]))))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "%s: the 2-D mesh is not planar in z (z from %g "
                              "to %g): getme smooths 2-D meshes lying in a "
                              "plane z = const", doc->path, lo[2], hi[2]);
    return GETME_FORMATS_OK;
}

static getme_formats_status read_coords(getme_doc *doc, cgns_impl *impl, int fn,
                                   double *coords, int32_t total)
{
    getme_formats_status st = GETME_FORMATS_OK;
    int32_t max_n = 0;

    for (int z = 0; z < impl->num_zones; z++)
        if (impl->zones[z].num_nodes > max_n)
            max_n = impl->zones[z].num_nodes;
    double *buf = getme__malloc((size_t)max_n * sizeof *buf);
    if (!buf)
        return oom(doc);
    for (int z = 0; z < impl->num_zones && st == GETME_FORMATS_OK; z++) {
        int ncoord = impl->dim == 3 ? 3 : 2;
        st = check_rind(doc, impl, fn, z);
        for (int k = 0; k < ncoord && st == GETME_FORMATS_OK; k++)
            st = read_coord(doc, impl, fn, z, k, coords, buf);
        /* A 2-D zone in 3-D space carries z through untouched (it is not
           written back); read it only to check the mesh is planar. */
        if (st == GETME_FORMATS_OK && impl->dim == 2 && impl->zones[z].phys_dim == 3) {
            int single = impl->zones[z].single;
            st = read_coord(doc, impl, fn, z, 2, coords, buf);
            impl->zones[z].single = single;
        }
    }
    free(buf);
    if (st == GETME_FORMATS_OK && impl->dim == 2)
        st = check_planar(doc, coords, total);
    return st;
}

/* ---- pass 2: elements, BCs, fixed nodes --------------------------------- */

static void mark_zone(const cgns_zone *zone, uint8_t *fixed)
{
    memset(fixed + zone->node_offset, 1, (size_t)zone->num_nodes);
}

static getme_formats_status read_zones(getme_doc *doc, cgns_impl *impl, int fn,
                                  const getme_doc_options *opts, uint8_t *fixed)
{
    getme_formats_status st = GETME_FORMATS_OK;

    for (int z = 0; z < impl->num_zones && st == GETME_FORMATS_OK; z++) {
        cgns_section *secs = NULL;
        int ns = 0;
        st = cgns_read_sections(doc, impl, fn, z, opts, fixed, doc->elem_ids,
                                &secs, &ns);
        if (st == GETME_FORMATS_OK)
            st = cgns_read_bcs(doc, impl, fn, z, opts, fixed, secs, ns);
        cgns_free_sections(secs, ns);
        if (cgns_named(impl->zones[z].name, &impl->zones[z].fams,
                       opts->num_fix, opts->fix))
            mark_zone(&impl->zones[z], fixed);
    }
    return st;
}

/* "/Base/Zone/Section element 17" for global element e. */
static void describe_element(const getme_doc *doc, const cgns_impl *impl,
                             int32_t e, char *buf, size_t size)
{
    int lo = 0, hi = impl->num_blocks - 1;
    char path[CGNS_PATH_LEN];

    while (lo < hi) { /* last block with first <= e */
        int mid = (lo + hi + 1) / 2;
        if (impl->blocks[mid].first <= e)
            lo = mid;
        else
            hi = mid - 1;
    }
    cgns_zone_path(impl, impl->blocks[lo].zone, path, sizeof path);
    snprintf(buf, size, "%s/%s element %lld", path, impl->blocks[lo].section,
             (long long)doc->elem_ids[e]);
}

static getme_formats_status check_valid(getme_doc *doc, const cgns_impl *impl)
{
    int32_t ne = getme_mesh_num_elements(doc->mesh), bad = 0;
    double *q = getme__malloc((size_t)ne * sizeof *q);
    char list[600] = "", one[2 * CGNS_PATH_LEN];

    if (!q)
        return oom(doc);
    if (getme_mesh_element_qualities(doc->mesh, q) != GETME_OK) {
        free(q);
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "%s: %s", doc->path,
                              getme_mesh_error(doc->mesh));
    }
    for (int32_t e = 0; e < ne; e++) {
        if (q[e] > 0.0)
            continue;
        if (bad++ < 4) {
            describe_element(doc, impl, e, one, sizeof one);
            size_t len = strlen(list);
            snprintf(list + len, sizeof list - len, "%s%s", len ? ", " : "",
                     one);
        }
    }
    free(q);
    if (bad == 0)
        return GETME_FORMATS_OK;
    return getme_doc_fail(doc, GETME_FORMATS_ERR_INVALID,
                          "%s: %ld invalid (inverted or degenerate) element%s, "
                          "first: %s%s", doc->path, (long)bad,
                          bad == 1 ? "" : "s", list, bad > 4 ? ", ..." : "");
}

/* The one line the CLI may log. */
static void make_info(getme_doc *doc, const cgns_impl *impl, unsigned flags)
{
    static const char *const ft[] = {"none", "ADF", "HDF5", "ADF2"};
    char types[160] = "";
    size_t len = 0;

    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int32_t n = getme_mesh_num_elements_of_type(doc->mesh,
                                                    (getme_elem_type)t);
        if (n > 0 && len < sizeof types)
            len += (size_t)snprintf(types + len, sizeof types - len, "%s%ld %s",
                                    len ? ", " : "", (long)n,
                                    getme_type_name((getme_elem_type)t));
    }
    len = (size_t)snprintf(doc->info, sizeof doc->info,
                           "CGNS %s, %d-D, %d zone%s, %ld nodes, %s; fixed %ld "
                           "nodes (%s%s%d of %d BCs, %d boundary section%s)",
                           impl->file_type >= 0 && impl->file_type <= 3
                               ? ft[impl->file_type] : "?",
                           impl->dim, impl->num_zones,
                           impl->num_zones == 1 ? "" : "s",
                           (long)getme_mesh_num_nodes(doc->mesh), types,
                           (long)getme_mesh_num_fixed(doc->mesh),
                           flags & GETME_FIX_SKIN ? "skin, " : "",
                           flags & GETME_FIX_INTERFACES ? "interfaces, " : "",
                           impl->num_bcs_fixed, impl->num_bcs,
                           impl->num_bnd_sections,
                           impl->num_bnd_sections == 1 ? "" : "s");
    if (impl->num_skipped > 0 && len < sizeof doc->info)
        snprintf(doc->info + len, sizeof doc->info - len,
                 "; %d structured zone%s left unchanged (e.g. '%s')",
                 impl->num_skipped, impl->num_skipped == 1 ? "" : "s",
                 impl->skipped);
}

static getme_formats_status build_mesh(getme_doc *doc, cgns_impl *impl, int fn,
                                  const getme_doc_options *opts,
                                  int32_t total)
{
    uint8_t *fixed = getme__calloc((size_t)total, 1);
    unsigned flags = 0;
    getme_formats_status st;

    doc->elem_ids =
        getme__malloc((size_t)(impl->max_elems > 0 ? impl->max_elems : 1) *
                      sizeof *doc->elem_ids);
    if (!fixed || !doc->elem_ids) {
        free(fixed);
        return oom(doc);
    }
    st = read_zones(doc, impl, fn, opts, fixed);
    if (st == GETME_FORMATS_OK && getme_mesh_num_elements(doc->mesh) == 0)
        st = getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                            "%s: no %d-D elements to smooth", doc->path,
                            impl->dim);
    /* Zones hold separate copies of their interface nodes: only fixing
       every zone's skin keeps them conforming, so --free-skin is honoured
       for single-zone files only. */
    if (opts->fix_skin || impl->num_zones > 1)
        flags |= GETME_FIX_SKIN;
    if (opts->fix_interfaces)
        flags |= GETME_FIX_INTERFACES;
    if (st == GETME_FORMATS_OK &&
        (getme_mesh_set_fixed_mask(doc->mesh, fixed) != GETME_OK ||
         getme_mesh_fix_boundary(doc->mesh, flags, NULL) != GETME_OK))
        st = getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "%s: %s", doc->path,
                            getme_mesh_error(doc->mesh));
    free(fixed);
    if (st == GETME_FORMATS_OK)
        st = check_valid(doc, impl);
    if (st == GETME_FORMATS_OK)
        make_info(doc, impl, flags);
    return st;
}

getme_formats_status cgns_read(getme_doc *doc, cgns_impl *impl, int fn,
                          const getme_doc_options *opts)
{
    int64_t total = 0;
    getme_formats_status st = scan(doc, impl, fn, &total);
    int single = 0;

    if (st == GETME_FORMATS_OK)
        st = cgns_check_names(doc, impl, opts);
    if (st != GETME_FORMATS_OK)
        return st;
    double *coords = getme__calloc((size_t)total * 3, sizeof *coords);
    if (!coords)
        return oom(doc);
    st = read_coords(doc, impl, fn, coords, (int32_t)total);
    if (st != GETME_FORMATS_OK) {
        free(coords);
        return st;
    }
    for (int z = 0; z < impl->num_zones; z++)
        single |= impl->zones[z].single;
    /* The mesh takes the coordinates (no copy), unless they are kept for
       the RealSingle rounding check; a failed take frees them. */
    getme_status gs =
        single ? getme_mesh_create(&doc->mesh, impl->dim, (int32_t)total,
                                   coords)
               : getme_mesh_create_take(&doc->mesh, impl->dim,
                                        (int32_t)total, coords);
    if (single && gs == GETME_OK)
        impl->orig = coords;
    else if (single)
        free(coords);
    if (gs != GETME_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                              "%s: cannot create the mesh", doc->path);
    return build_mesh(doc, impl, fn, opts, (int32_t)total);
}
