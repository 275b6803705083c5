/*
 * msh_file.c -- what both MSH readers (native and Gmsh SDK) ask of a file
 * before reading it: is it MSH, and which version and encoding.
 */
#include "model.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

static int has_msh_extension(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && tolower((unsigned char)path[n - 4]) == '.' &&
           tolower((unsigned char)path[n - 3]) == 'm' &&
           tolower((unsigned char)path[n - 2]) == 's' &&
           tolower((unsigned char)path[n - 1]) == 'h';
}

int getme__msh_probe(const char *path)
{
    if (has_msh_extension(path))
        return 1;
    FILE *f = fopen(path, "rb");
    char line[16] = "";
    if (!f)
        return 0;
    int ok = fgets(line, sizeof line, f) && !strncmp(line, "$MeshFormat", 11);
    fclose(f);
    return ok;
}

/* Lines before "$MeshFormat" looked at: Gmsh skips sections it does not
   know ($Comments...) wherever they are, so they may come first; a mesh
   section first, or this many lines of something else, is not MSH. */
#define HEADER_SCAN_LINES 100000

int getme__msh_header(const char *path, double *version, int *binary)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    char line[128] = "";
    int b = 0, ok = 0, at_start = 1;
    for (long n = 0; !ok && n < HEADER_SCAN_LINES &&
                     fgets(line, sizeof line, f);
         n++) {
        /* only at a line's start (a long line comes in pieces) */
        int start = at_start;
        at_start = strchr(line, '\n') != NULL;
        if (!start || line[0] != '$')
            continue;
        if (!strncmp(line, "$MeshFormat", 11)) {
            ok = fgets(line, sizeof line, f) &&
                 sscanf(line, "%lf %d", version, &b) == 2;
            break;
        }
        if (!strncmp(line, "$Nodes", 6) || !strncmp(line, "$Elements", 9) ||
            !strncmp(line, "$Entities", 9))
            break;
    }
    fclose(f);
    *binary = b != 0;
    return ok ? 0 : -2;
}
