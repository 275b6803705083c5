/*
 * cgns_writer.c -- write a smoothed CGNS document.
 *
 * The output is the input file copied byte for byte, in which only the
 * data of the GridCoordinates/Coordinate{X,Y[,Z]} arrays of the smoothed
 * zones is overwritten, in place, in the data type the file stores
 * (RealSingle stays RealSingle).  Everything else -- flow solutions, BCs,
 * families, user data, links, the order of the nodes in the tree -- is the
 * input's.
 *
 * Why cgio and not cg_open(MODE_MODIFY) + cg_coord_write: libcgns 3.4
 * upgrades files written by older versions when it opens them for
 * modification (it adds ElementStartOffset to MIXED sections and rewrites
 * CGNSLibraryVersion), which would change nodes we promise to keep.  The
 * cgio layer (same library) writes the array data and nothing else.  The
 * result is then opened with cg_open(MODE_READ) and its coordinates read
 * back and compared before the file is renamed into place.
 *
 * RealSingle: a moved node is rounded to float.  Rounding can in principle
 * invert a nearly flat element, so every element of such a zone is checked
 * and the nodes of an element that became invalid are put back to their
 * input position until none is (the input was valid, so this ends).  A
 * fixed node is its input float converted to double and back, so it is
 * written bit-identical.
 */
#define _POSIX_C_SOURCE 200809L /* open flags, fsync, st_mtim */

#include "cgns_internal.h"
#include "getme_alloc.h"

#include <cgns_io.h>
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define COPY_CHUNK (1 << 20)

static const char *const coord_names[3] = {"CoordinateX", "CoordinateY",
                                           "CoordinateZ"};

static getme_formats_status oom(getme_doc *doc)
{
    return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "%s: out of memory",
                          doc->path);
}

/* ---- links -------------------------------------------------------------- */

/* Writing through a link would modify another file: refuse files whose
   coordinates (or a node above them) are links. */
getme_formats_status cgns_check_links(getme_doc *doc, const cgns_impl *impl, int fn)
{
    int cgio;
    double root, id;
    char path[CGNS_PATH_LEN + 32];

    if (cg_get_cgio(fn, &cgio) != CG_OK || cg_root_id(fn, &root) != CG_OK)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL, "%s: %s", doc->path,
                              cgns_error());
    for (int z = 0; z < impl->num_zones; z++) {
        const cgns_zone *zone = &impl->zones[z];
        for (int level = 0; level < 3 + zone->num_coords; level++) {
            int len = 0;
            if (level == 0)
                snprintf(path, sizeof path, "/%s", zone->base_name);
            else if (level == 1)
                snprintf(path, sizeof path, "/%s/%s", zone->base_name,
                         zone->name);
            else if (level == 2)
                snprintf(path, sizeof path, "/%s/%s/GridCoordinates",
                         zone->base_name, zone->name);
            else
                snprintf(path, sizeof path, "/%s/%s/GridCoordinates/%s",
                         zone->base_name, zone->name, coord_names[level - 3]);
            if (cgio_get_node_id(cgio, root, path, &id) == 0 &&
                cgio_is_link(cgio, id, &len) == 0 && len > 0)
                return getme_doc_fail(doc, GETME_FORMATS_ERR_UNSUPPORTED,
                                      "%s: %s is a link to another file: "
                                      "getme does not write through links",
                                      doc->path, path);
        }
    }
    return GETME_FORMATS_OK;
}

/* ---- RealSingle rounding ------------------------------------------------ */

static double element_quality(int type, const int32_t *nodes, int nv,
                              const double *xyz, int mirror)
{
    double x[3 * 8];
    for (int a = 0; a < nv; a++)
        for (int k = 0; k < 3; k++)
            x[3 * a + k] = xyz[3 * (size_t)nodes[a] + (size_t)k];
    if (mirror) /* planar elements given clockwise (as the core accepts) */
        for (int a = 0; a < nv; a++)
            x[3 * a + 1] = -x[3 * a + 1];
    return getme_element_quality((getme_elem_type)type, x);
}

/* Put the nodes of zone elements that rounding made invalid back to their
   input position; returns how many nodes were put back. */
static int32_t repair_zone(const cgns_zone *zone, const double *orig,
                           double *out)
{
    int32_t restored = 0, changed;

    do {
        changed = 0;
        for (int32_t e = 0; e < zone->num_elems; e++) {
            const int32_t *nodes = zone->conn + zone->conn_offset[e];
            int nv = zone->conn_offset[e + 1] - zone->conn_offset[e];
            int type = zone->conn_type[e];
            int mirror = element_quality(type, nodes, nv, orig, 0) <= 0.0;
            if (element_quality(type, nodes, nv, out, mirror) > 0.0)
                continue;
            for (int a = 0; a < nv; a++) {
                double *p = out + 3 * (size_t)nodes[a];
                const double *o = orig + 3 * (size_t)nodes[a];
                if (memcmp(p, o, 3 * sizeof *p) != 0) {
                    memcpy(p, o, 3 * sizeof *p);
                    changed++;
                }
            }
        }
        restored += changed;
    } while (changed > 0);
    return restored;
}

/* Round RealSingle coordinates to float and keep the zone valid. */
static int32_t round_single(const cgns_impl *impl, double *out)
{
    int32_t restored = 0;

    for (int z = 0; z < impl->num_zones; z++) {
        const cgns_zone *zone = &impl->zones[z];
        if (!zone->single)
            continue;
        for (int32_t i = 0; i < zone->num_nodes; i++)
            for (int k = 0; k < zone->num_coords; k++)
                if (zone->coord_type[k] == CGNS_ENUMV(RealSingle)) {
                    double *v = &out[3 * ((size_t)zone->node_offset + (size_t)i) +
                                     (size_t)k];
                    *v = (double)(float)*v;
                }
        if (impl->orig && zone->conn)
            restored += repair_zone(zone, impl->orig, out);
    }
    return restored;
}

/* ---- copying the input -------------------------------------------------- */

static getme_formats_status write_all(getme_doc *doc, int fd, const char *buf,
                                 size_t n, const char *tmp)
{
    while (n > 0) {
        ssize_t w = write(fd, buf, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "%s: %s", tmp,
                                  strerror(errno ? errno : EIO));
        buf += w;
        n -= (size_t)w;
    }
    return GETME_FORMATS_OK;
}

/* Input unchanged since it was read (same file, size and mtime)? */
static int same_input(const cgns_impl *impl, const struct stat *sb)
{
    int64_t mtime = (int64_t)sb->st_mtim.tv_sec * 1000000000 +
                    sb->st_mtim.tv_nsec;
    return (int64_t)sb->st_size == impl->in_size &&
           (uint64_t)sb->st_dev == impl->in_dev &&
           (uint64_t)sb->st_ino == impl->in_ino && mtime == impl->in_mtime_ns;
}

static getme_formats_status copy_input(getme_doc *doc, const cgns_impl *impl,
                                  const char *tmp)
{
    struct stat sb;
    getme_formats_status st = GETME_FORMATS_OK;
    int in = open(doc->path, O_RDONLY | O_CLOEXEC), out;
    char *buf;

    if (in < 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "%s: %s", doc->path,
                              strerror(errno));
    if (fstat(in, &sb) != 0 || !same_input(impl, &sb)) {
        close(in);
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "%s: the input file changed since it was read; "
                              "nothing written", doc->path);
    }
    /* getme_io_tmp_path created the (empty) file: truncate it, do not race */
    out = open(tmp, O_WRONLY | O_TRUNC | O_CLOEXEC);
    /* mkstemp made it 0600: give the copy the input's permissions */
    if (out >= 0)
        (void)fchmod(out, sb.st_mode & 07777);
    buf = getme__malloc(COPY_CHUNK);
    if (out < 0 || !buf) {
        st = out < 0 ? getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "%s: %s", tmp,
                                      strerror(errno))
                     : oom(doc);
        goto done;
    }
    for (;;) {
        ssize_t r = read(in, buf, COPY_CHUNK);
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0) {
            st = getme_doc_fail(doc, GETME_FORMATS_ERR_OPEN, "%s: %s", doc->path,
                                strerror(errno));
            break;
        }
        if (r == 0)
            break;
        if ((st = write_all(doc, out, buf, (size_t)r, tmp)) != GETME_FORMATS_OK)
            break;
    }
done:
    free(buf);
    close(in);
    if (out >= 0 && close(out) != 0 && st == GETME_FORMATS_OK)
        st = getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "%s: %s", tmp,
                            strerror(errno));
    return st;
}

/* ---- coordinates into the copy ------------------------------------------ */

/* One coordinate array of a zone as the file stores it (float or double). */
static void pack(const cgns_zone *zone, int k, const double *xyz, void *buf)
{
    for (int32_t i = 0; i < zone->num_nodes; i++) {
        double v = xyz[3 * ((size_t)zone->node_offset + (size_t)i) + (size_t)k];
        if (zone->coord_type[k] == CGNS_ENUMV(RealSingle))
            ((float *)buf)[i] = (float)v;
        else
            ((double *)buf)[i] = v;
    }
}

static getme_formats_status cgio_fail(getme_doc *doc, const char *tmp,
                                 const char *what)
{
    char msg[CGIO_MAX_ERROR_LENGTH + 1] = "";
    cgio_error_message(msg);
    return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "%s: %s: %s", tmp, what,
                          msg[0] ? msg : "cgio error");
}

static getme_formats_status write_array(getme_doc *doc, const cgns_zone *zone,
                                   int k, int cg, double root, const char *tmp,
                                   void *buf, const double *xyz)
{
    char path[CGNS_PATH_LEN + 32], type[CGIO_MAX_DATATYPE_LENGTH + 1];
    const char *want = zone->coord_type[k] == CGNS_ENUMV(RealSingle) ? "R4" : "R8";
    cgsize_t dims[CGIO_MAX_DIMENSIONS];
    int ndim = 0;
    double id;

    snprintf(path, sizeof path, "/%s/%s/GridCoordinates/%s", zone->base_name,
             zone->name, coord_names[k]);
    if (cgio_get_node_id(cg, root, path, &id) != 0)
        return cgio_fail(doc, tmp, path);
    if (cgio_get_data_type(cg, id, type) != 0 ||
        cgio_get_dimensions(cg, id, &ndim, dims) != 0)
        return cgio_fail(doc, tmp, path);
    if (strcmp(type, want) != 0 || ndim != 1 || dims[0] != zone->num_nodes)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "%s: %s is not the %s array of %ld values that "
                              "was read", tmp, path, want,
                              (long)zone->num_nodes);
    pack(zone, k, xyz, buf);
    if (cgio_write_all_data(cg, id, buf) != 0)
        return cgio_fail(doc, tmp, path);
    return GETME_FORMATS_OK;
}

static size_t max_zone_nodes(const cgns_impl *impl)
{
    size_t n = 1;
    for (int z = 0; z < impl->num_zones; z++)
        if ((size_t)impl->zones[z].num_nodes > n)
            n = (size_t)impl->zones[z].num_nodes;
    return n;
}

static getme_formats_status write_coords(getme_doc *doc, const cgns_impl *impl,
                                    const char *tmp, const double *xyz)
{
    int cg;
    double root;
    getme_formats_status st = GETME_FORMATS_OK;
    void *buf = getme__malloc(max_zone_nodes(impl) * sizeof(double));

    if (!buf)
        return oom(doc);
    if (cgio_open_file(tmp, CGIO_MODE_MODIFY, CGIO_FILE_NONE, &cg) != 0) {
        free(buf);
        return cgio_fail(doc, tmp, "cannot open the copy");
    }
    if (cgio_get_root_id(cg, &root) != 0)
        st = cgio_fail(doc, tmp, "no root node");
    for (int z = 0; z < impl->num_zones && st == GETME_FORMATS_OK; z++)
        for (int k = 0; k < impl->zones[z].num_coords && st == GETME_FORMATS_OK; k++)
            st = write_array(doc, &impl->zones[z], k, cg, root, tmp, buf, xyz);
    if (cgio_close_file(cg) != 0 && st == GETME_FORMATS_OK)
        st = cgio_fail(doc, tmp, "close");
    free(buf);
    return st;
}

/* Read the copy back through the mid-level library: it must open, and its
   coordinates must be exactly what we wrote. */
static getme_formats_status verify(getme_doc *doc, const cgns_impl *impl,
                              const char *tmp, const double *xyz)
{
    size_t n = max_zone_nodes(impl);
    void *want = getme__malloc(n * sizeof(double));
    void *got = getme__malloc(n * sizeof(double));
    getme_formats_status st = GETME_FORMATS_OK;
    int fn;

    if (!want || !got) {
        free(want);
        free(got);
        return oom(doc);
    }
    if (cg_open(tmp, CG_MODE_READ, &fn) != CG_OK) {
        st = getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                            "%s: the written file does not open: %s", tmp,
                            cgns_error());
        goto done;
    }
    for (int z = 0; z < impl->num_zones && st == GETME_FORMATS_OK; z++) {
        const cgns_zone *zone = &impl->zones[z];
        cgsize_t one = 1, nn = zone->num_nodes;
        for (int k = 0; k < zone->num_coords && st == GETME_FORMATS_OK; k++) {
            size_t bytes = (size_t)nn * (zone->coord_type[k] ==
                                         CGNS_ENUMV(RealSingle) ? 4 : 8);
            pack(zone, k, xyz, want);
            if (cg_coord_read(fn, zone->base, zone->zone, coord_names[k],
                              zone->coord_type[k], &one, &nn, got) != CG_OK ||
                memcmp(want, got, bytes) != 0)
                st = getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                                    "%s: /%s/%s/GridCoordinates/%s does not "
                                    "read back as written", tmp,
                                    zone->base_name, zone->name,
                                    coord_names[k]);
        }
    }
    cg_close(fn);
done:
    free(want);
    free(got);
    return st;
}

static getme_formats_status sync_file(getme_doc *doc, const char *tmp)
{
    int fd = open(tmp, O_RDONLY | O_CLOEXEC);
    if (fd < 0 || fsync(fd) != 0) {
        int err = errno;
        if (fd >= 0)
            close(fd);
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "%s: %s", tmp,
                              strerror(err));
    }
    close(fd);
    return GETME_FORMATS_OK;
}

/* ---- the adapter's write ------------------------------------------------ */

getme_formats_status cgns_write(getme_doc *doc, const char *out_path)
{
    cgns_impl *impl = doc->impl;
    int32_t n = getme_mesh_num_nodes(doc->mesh), restored = 0;
    char tmp[4096];
    getme_formats_status st;

    cgns_quiet();
    if (getme_io_same_file(doc->path, out_path))
        return getme_doc_fail(doc, GETME_FORMATS_ERR_ARGUMENT,
                              "%s: the output is the input file; getme never "
                              "overwrites its input", out_path);
    errno = 0;
    if (getme_io_tmp_path(out_path, tmp, sizeof tmp) != 0)
        return getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE,
                              "%s: cannot create a temporary file next to "
                              "it: %s", out_path,
                              errno ? strerror(errno) : "path too long");
    double *xyz = getme__malloc(3 * (size_t)n * sizeof *xyz);
    if (!xyz || getme_mesh_get_coords(doc->mesh, xyz) != GETME_OK) {
        free(xyz);
        return oom(doc);
    }
    restored = round_single(impl, xyz);
    st = copy_input(doc, impl, tmp);
    if (st == GETME_FORMATS_OK)
        st = write_coords(doc, impl, tmp, xyz);
    if (st == GETME_FORMATS_OK)
        st = verify(doc, impl, tmp, xyz);
    if (st == GETME_FORMATS_OK)
        st = sync_file(doc, tmp);
    if (st == GETME_FORMATS_OK && getme_io_commit(tmp, out_path) != 0)
        st = getme_doc_fail(doc, GETME_FORMATS_ERR_WRITE, "%s: cannot rename %s: %s",
                            out_path, tmp, strerror(errno));
    if (st != GETME_FORMATS_OK)
        unlink(tmp); /* no partial output; ENOENT after a failed commit */
    /* The mesh now holds exactly what the file holds (rounded floats). */
    if (st == GETME_FORMATS_OK && impl->orig)
        getme_mesh_set_coords(doc->mesh, xyz);
    if (st == GETME_FORMATS_OK && restored > 0) {
        size_t len = strlen(doc->info);
        snprintf(doc->info + len, sizeof doc->info - len,
                 "; %ld nodes kept at their input position so that no element "
                 "inverts when rounded to RealSingle", (long)restored);
    }
    free(xyz);
    return st;
}
