/*
 * cgns_magic.h -- which container a file is (cgns_magic.c).  Not installed.
 */
#ifndef GETME_CGNS_MAGIC_H
#define GETME_CGNS_MAGIC_H

enum { MAGIC_NONE = 0, MAGIC_ADF = 1, MAGIC_HDF5 = 2, MAGIC_HDF5_CGNS = 3 };

/* MAGIC_ADF, MAGIC_HDF5_CGNS (HDF5 written by libcgns), MAGIC_HDF5 (any
   other HDF5 file) or MAGIC_NONE (also for a file that cannot be read). */
int cgns_magic(const char *path);

#endif /* GETME_CGNS_MAGIC_H */
