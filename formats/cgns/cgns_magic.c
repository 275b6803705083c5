/*
 * cgns_magic.c -- which container a file is, from its first bytes: the
 * probe (cgns_load.c, in libgetme_formats) and the module's input check
 * (cgns_format.c) both ask, so both are built with it.
 */
#include "cgns_magic.h"
#include "getme_alloc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Which container the file is, from its first bytes.  An ADF file starts
   with "@(#)" (high bits set) + "ADF Database Version"; an HDF5 file with
   its 8-byte signature; an HDF5 file written by libcgns names its
   CGNSLibraryVersion node near the start. */
int cgns_magic(const char *path)
{
    static const unsigned char hdf5[8] = {0x89, 'H', 'D', 'F', '\r', '\n',
                                          0x1a, '\n'};
    enum { HEAD = 65536 };
    unsigned char *buf = getme__malloc(HEAD);
    FILE *f = fopen(path, "rb");
    size_t n = 0;
    int kind = MAGIC_NONE;

    if (f && buf)
        n = fread(buf, 1, HEAD, f);
    if (f)
        fclose(f);
    if (n >= 24 && memcmp(buf + 4, "ADF Database Version", 20) == 0)
        kind = MAGIC_ADF;
    else if (n >= 8 && memcmp(buf, hdf5, 8) == 0) {
        static const char key[] = "CGNSLibraryVersion";
        kind = MAGIC_HDF5;
        for (size_t i = 0; i + sizeof key - 1 <= n; i++)
            if (buf[i] == 'C' && memcmp(buf + i, key, sizeof key - 1) == 0) {
                kind = MAGIC_HDF5_CGNS;
                break;
            }
    }
    free(buf);
    return kind;
}

