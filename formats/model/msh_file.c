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

int getme__msh_header(const char *path, double *version, int *binary)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    char line[128] = "";
    int b = 0, ok = fgets(line, sizeof line, f) &&
                    !strncmp(line, "$MeshFormat", 11) &&
                    fgets(line, sizeof line, f) &&
                    sscanf(line, "%lf %d", version, &b) == 2;
    fclose(f);
    *binary = b != 0;
    return ok ? 0 : -2;
}
