/*
 * cgns_bc.c -- boundary conditions (ZoneBC_t/BC_t) of an unstructured zone:
 * the nodes of every BC patch are fixed unless the user frees the BC (by
 * its name or family).  A patch is a PointList or PointRange of vertices
 * (GridLocation Vertex) or of element numbers (FaceCenter, EdgeCenter,
 * CellCenter, or the old ElementList / ElementRange point sets); element
 * numbers are resolved through the zone's sections.
 */
#include "cgns_internal.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

typedef struct bc_ctx {
    getme_doc *doc;
    const cgns_zone *zone;
    char path[CGNS_PATH_LEN];       /* "/Base/Zone/ZoneBC/name" */
    uint8_t *fixed;
    const cgns_section *sections;
    int num_sections;
} bc_ctx;

static getme_formats_status fix_vertex(const bc_ctx *c, cgsize_t v)
{
    if (v < 1 || v > c->zone->num_nodes)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s: point %ld is not a node of the zone "
                              "(1..%ld)", c->doc->path, c->path, (long)v,
                              (long)c->zone->num_nodes);
    c->fixed[c->zone->node_offset + v - 1] = 1;
    return GETME_FORMATS_OK;
}

static getme_formats_status fix_element(const bc_ctx *c, cgsize_t e)
{
    const cgsize_t *nodes;
    int count;

    if (cgns_element_nodes(c->sections, c->num_sections, e, &nodes, &count))
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                              "%s: %s: element %ld is in no section of the "
                              "zone", c->doc->path, c->path, (long)e);
    for (int k = 0; k < count; k++)
        c->fixed[c->zone->node_offset + nodes[k] - 1] = 1;
    return GETME_FORMATS_OK;
}

/* Fix the points of one patch: a range (2 values) or a list. */
static getme_formats_status fix_points(const bc_ctx *c, const cgsize_t *pnts,
                                  cgsize_t npnts, int range, int elements)
{
    getme_formats_status st = GETME_FORMATS_OK;

    if (range) {
        if (npnts != 2 || pnts[1] < pnts[0])
            return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE,
                                  "%s: %s: invalid point range", c->doc->path,
                                  c->path);
        for (cgsize_t p = pnts[0]; p <= pnts[1] && st == GETME_FORMATS_OK; p++)
            st = elements ? fix_element(c, p) : fix_vertex(c, p);
        return st;
    }
    for (cgsize_t i = 0; i < npnts && st == GETME_FORMATS_OK; i++)
        st = elements ? fix_element(c, pnts[i]) : fix_vertex(c, pnts[i]);
    return st;
}

static getme_formats_status read_bc(bc_ctx *c, cgns_impl *impl, int fn, int bc,
                               const getme_doc_options *opts)
{
    const cgns_zone *zone = c->zone;
    char name[CGNS_NAME_LEN];
    CGNS_ENUMT(BCType_t) type;
    CGNS_ENUMT(PointSetType_t) ptset;
    CGNS_ENUMT(GridLocation_t) loc;
    CGNS_ENUMT(DataType_t) normal_type;
    cgsize_t npnts, normal_size;
    int normal_index[3], ndataset;
    cgns_fams fams;
    getme_formats_status st;

    if (cg_boco_info(fn, zone->base, zone->zone, bc, name, &type, &ptset,
                     &npnts, normal_index, &normal_size, &normal_type,
                     &ndataset) != CG_OK ||
        cg_boco_gridlocation_read(fn, zone->base, zone->zone, bc, &loc) != CG_OK)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE, "%s: %s/ZoneBC: BC %d: %s",
                              c->doc->path, c->path, bc, cgns_error());
    cgns_zone_path(impl, (int)(zone - impl->zones), c->path, sizeof c->path);
    snprintf(c->path + strlen(c->path), sizeof c->path - strlen(c->path),
             "/ZoneBC/%s", name);
    if (cg_goto(fn, zone->base, "Zone_t", zone->zone, "ZoneBC_t", 1, "BC_t", bc,
                "end") != CG_OK)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE, "%s: %s: %s",
                              c->doc->path, c->path, cgns_error());
    if ((st = cgns_read_fams(c->doc, impl, &fams)) != GETME_FORMATS_OK)
        return st;
    impl->num_bcs++;
    if (!cgns_default_fixed(name, &fams, opts))
        return GETME_FORMATS_OK;
    impl->num_bcs_fixed++;

    int range = ptset == CGNS_ENUMV(PointRange) || ptset == CGNS_ENUMV(ElementRange);
    int list = ptset == CGNS_ENUMV(PointList) || ptset == CGNS_ENUMV(ElementList);
    int elements = ptset == CGNS_ENUMV(ElementRange) ||
                   ptset == CGNS_ENUMV(ElementList) || loc != CGNS_ENUMV(Vertex);
    if (!range && !list)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_UNSUPPORTED,
                              "%s: %s: point set type %s is not supported",
                              c->doc->path, c->path, cg_PointSetTypeName(ptset));
    if (npnts <= 0)
        return GETME_FORMATS_OK;
    cgsize_t *pnts = getme__malloc((size_t)npnts * sizeof *pnts);
    if (!pnts)
        return getme_doc_fail(c->doc, GETME_FORMATS_ERR_INTERNAL, "%s: out of memory",
                              c->doc->path);
    if (cg_boco_read(fn, zone->base, zone->zone, bc, pnts, NULL) != CG_OK)
        st = getme_doc_fail(c->doc, GETME_FORMATS_ERR_PARSE, "%s: %s: %s",
                            c->doc->path, c->path, cgns_error());
    else
        st = fix_points(c, pnts, npnts, range, elements);
    free(pnts);
    return st;
}

getme_formats_status cgns_read_bcs(getme_doc *doc, cgns_impl *impl, int fn, int z,
                              const getme_doc_options *opts, uint8_t *fixed,
                              const cgns_section *sections, int num_sections)
{
    bc_ctx c = {doc, &impl->zones[z], "", fixed, sections, num_sections};
    int nb = 0;
    getme_formats_status st = GETME_FORMATS_OK;

    cgns_zone_path(impl, z, c.path, sizeof c.path);
    if (cg_nbocos(fn, c.zone->base, c.zone->zone, &nb) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_PARSE, "%s: %s/ZoneBC: %s",
                              doc->path, c.path, cgns_error());
    for (int bc = 1; bc <= nb && st == GETME_FORMATS_OK; bc++) {
        cgns_zone_path(impl, z, c.path, sizeof c.path);
        st = read_bc(&c, impl, fn, bc, opts);
    }
    return st;
}
