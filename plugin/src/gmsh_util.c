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

const char *gg_dim_word(int dim) { return getme__dim_word(dim, 0); }

const char *gg_dim_Word(int dim) { return getme__dim_word(dim, 1); }

void gg_gmsh_last_error(char *buf, size_t size)
{
    char *err = NULL;
    int ierr = 0;
    gmshLoggerGetLastError(&err, &ierr);
    snprintf(buf, size, "%s", err && *err ? err : "unknown Gmsh error");
    gmshFree(err);
}

int gg_model_partitioned(void)
{
    int *dt = NULL, ierr = 0, found = 0;
    size_t n = 0;
    gmshModelGetEntities(&dt, &n, -1, &ierr);
    for (size_t i = 0; !ierr && i + 1 < n && !found; i += 2) {
        int *parts = NULL;
        size_t np = 0;
        gmshModelGetPartitions(dt[i], dt[i + 1], &parts, &np, &ierr);
        found = np > 0;
        gmshFree(parts);
    }
    gmshFree(dt);
    return found;
}
