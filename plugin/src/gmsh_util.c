/*
 * gmsh_util.c -- small helpers around Gmsh's C API: initialization probe,
 * entity words, element type names, error strings.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

getme_status gg_fail(gg_msg *msg, getme_status status, const char *fmt, ...)
{
    if (msg) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg->text, sizeof msg->text, fmt, ap);
        va_end(ap);
    }
    return status;
}

/* Gmsh 4.8's API functions silently do nothing before gmshInitialize() (no
   message, ierr 0), so an option read leaves our sentinel untouched; after
   initialization General.Terminal is 0 or 1. */
int gg_gmsh_initialized(void)
{
    double v = -12345.0;
    int ierr = 0;
    gmshOptionGetNumber("General.Terminal", &v, &ierr);
    return ierr == 0 && v != -12345.0;
}

const char *gg_dim_word(int dim)
{
    static const char *const w[] = {"point", "curve", "surface", "volume"};
    return dim >= 0 && dim <= 3 ? w[dim] : "entity";
}

const char *gg_dim_Word(int dim)
{
    static const char *const w[] = {"Point", "Curve", "Surface", "Volume"};
    return dim >= 0 && dim <= 3 ? w[dim] : "Entity";
}

void gg_gmsh_last_error(char *buf, size_t size)
{
    char *err = NULL;
    int ierr = 0;
    gmshLoggerGetLastError(&err, &ierr);
    snprintf(buf, size, "%s", err && *err ? err : "unknown Gmsh error");
    gmshFree(err);
}

/* Gmsh MSH element types: 2 tri3, 3 quad4, 4 tet4, 5 hex8, 6 prism6,
   7 pyramid5 (the MSH format's element type table). */
int gg_getme_type(int gmsh_type)
{
    switch (gmsh_type) {
    case 2: return GETME_TRI;
    case 3: return GETME_QUAD;
    case 4: return GETME_TET;
    case 5: return GETME_HEX;
    case 6: return GETME_PRISM;
    case 7: return GETME_PYRAMID;
    default: return -1;
    }
}

/* Second-order volume types smoothed with their corners
   (getme_mesh_add_elements_ho takes Gmsh's node order): 11 tet10, 17
   hex20, 12 hex27, 18 prism15, 13 prism18; -1 otherwise. */
int gg_ho_type(int gmsh_type)
{
    switch (gmsh_type) {
    case 11: return GETME_TET10;
    case 17: return GETME_HEX20;
    case 12: return GETME_HEX27;
    case 18: return GETME_PRISM15;
    case 13: return GETME_PRISM18;
    default: return -1;
    }
}

static void lower_first(char *s)
{
    if (s[0] >= 'A' && s[0] <= 'Z')
        s[0] = (char)(s[0] - 'A' + 'a');
}

/* Gmsh names types "Tetrahedron 10", "Hexahedron 27"...; say "10-node
   tetrahedron" as a user reads it. */
void gg_gmsh_type_name(int gmsh_type, char *buf, size_t size)
{
    char *name = NULL, family[64] = "";
    double *local = NULL;
    size_t local_n = 0;
    int dim = 0, order = 0, nn = 0, np = 0, ierr = 0, num = 0;
    gmshModelMeshGetElementProperties(gmsh_type, &name, &dim, &order, &nn,
                                      &local, &local_n, &np, &ierr);
    gmshFree(local);
    if (ierr || !name) {
        snprintf(buf, size, "element type %d", gmsh_type);
        gmshFree(name);
        return;
    }
    if (sscanf(name, "%63s %d", family, &num) == 2 && order > 1)
        snprintf(buf, size, "%d-node %s", nn, family);
    else
        snprintf(buf, size, "%s", family[0] ? family : name);
    lower_first(buf[0] >= '0' && buf[0] <= '9' ? strchr(buf, ' ') + 1 : buf);
    gmshFree(name);
}

int gg_gmsh_type_order(int gmsh_type)
{
    char *name = NULL;
    double *local = NULL;
    size_t local_n = 0;
    int dim = 0, order = 0, nn = 0, np = 0, ierr = 0;
    gmshModelMeshGetElementProperties(gmsh_type, &name, &dim, &order, &nn,
                                      &local, &local_n, &np, &ierr);
    gmshFree(local);
    gmshFree(name);
    return ierr ? 0 : order;
}
