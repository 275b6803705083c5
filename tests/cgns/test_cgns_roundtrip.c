/*
 * test_cgns_roundtrip.c -- smooth the libcgns-written fixtures (HDF5 and
 * ADF, RealDouble and RealSingle) through the adapter and check the output:
 *  - the input file is byte-identical afterwards, no temporary file is left;
 *  - `cgnsdiff -d` (Debian cgns-convert) reports differences only in the
 *    GridCoordinates/Coordinate* arrays: flow solution, BCs, families,
 *    user data, sections are untouched;
 *  - `cgnscheck` says of the output exactly what it says of the input;
 *  - the coordinates, read back with libcgns in the stored data type, keep
 *    that type, fixed nodes are bit-identical, free nodes moved;
 *  - no element is inverted, by an independent determinant check;
 *  - the mean quality went up (recomputed by the core on the read-back).
 */
#define _POSIX_C_SOURCE 200809L /* popen, chmod */

#include "cgns_fixture.h"
#include "check.h"
#include "getme_formats.h"

#include <cgns_io.h>

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char dir[512];

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    *n = 0;
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    buf = malloc(len > 0 ? (size_t)len : 1);
    if (buf)
        *n = fread(buf, 1, (size_t)len, f);
    fclose(f);
    return buf;
}

/* Output of a shell command (stdout + stderr), malloc'ed. */
static char *run(const char *cmd)
{
    FILE *p = popen(cmd, "r");
    size_t cap = 1 << 16, len = 0;
    char *out = calloc(cap, 1);
    if (!p || !out)
        return out;
    while (len + 1 < cap) {
        size_t r = fread(out + len, 1, cap - 1 - len, p);
        if (r == 0)
            break;
        len += r;
    }
    pclose(p);
    return out;
}

/* det of the edge vectors (b - a, c - a, d - a) */
static double det4(const double *x, const int32_t *v, int a, int b, int c, int d)
{
    const double *p = x + 3 * v[a], *q = x + 3 * v[b], *r = x + 3 * v[c],
                 *s = x + 3 * v[d];
    double e1[3], e2[3], e3[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = q[k] - p[k];
        e2[k] = r[k] - p[k];
        e3[k] = s[k] - p[k];
    }
    return e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) -
           e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
           e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]);
}

/* Read the output with libcgns only; check every element with the paper's
   node simplices (hex) or its one simplex (tet).  Returns #inverted. */
static int count_inverted(const char *path, double *xyz_out, int single)
{
    static const int hexs[8][4] = {{0, 3, 4, 1}, {1, 0, 5, 2}, {2, 1, 6, 3},
                                   {3, 2, 7, 0}, {4, 7, 5, 0}, {5, 4, 6, 1},
                                   {6, 5, 7, 2}, {7, 6, 4, 3}};
    static const char *const names[3] = {"CoordinateX", "CoordinateY",
                                         "CoordinateZ"};
    int fn, bad = 0;
    if (cg_open(path, CG_MODE_READ, &fn) != CG_OK)
        return -1;
    for (int Z = 1; Z <= 2; Z++) {
        int off = Z == 1 ? 0 : 125, nn = Z == 1 ? 125 : 64;
        cgsize_t one = 1, n = nn;
        double buf[125];
        for (int k = 0; k < 3; k++) {
            CGNS_ENUMT(DataType_t) type;
            char name[33];
            cg_coord_info(fn, 1, Z, k + 1, &type, name);
            CHECK_EQ_INT(type, single ? CGNS_ENUMV(RealSingle) : CGNS_ENUMV(RealDouble));
            cg_coord_read(fn, 1, Z, names[k], CGNS_ENUMV(RealDouble), &one, &n, buf);
            for (int i = 0; i < nn; i++)
                xyz_out[3 * (off + i) + k] = buf[i];
        }
        cgsize_t size;
        cg_ElementDataSize(fn, 1, Z, 1, &size);
        cgsize_t *data = malloc((size_t)size * sizeof *data);
        cgsize_t *offs = malloc(200 * sizeof *offs);
        if (Z == 1)
            cg_elements_read(fn, 1, Z, 1, data, NULL);
        else
            cg_poly_elements_read(fn, 1, Z, 1, data, offs, NULL);
        int ne = Z == 1 ? 64 : 162;
        for (int e = 0; e < ne; e++) {
            int32_t v[8];
            const cgsize_t *p = Z == 1 ? data + 8 * e : data + offs[e] + 1;
            for (int a = 0; a < (Z == 1 ? 8 : 4); a++)
                v[a] = (int32_t)(p[a] - 1 + off);
            if (Z == 1) {
                for (int s = 0; s < 8; s++)
                    bad += det4(xyz_out, v, hexs[s][0], hexs[s][1], hexs[s][2],
                                hexs[s][3]) <= 0.0;
            } else {
                bad += det4(xyz_out, v, 0, 1, 2, 3) <= 0.0;
            }
        }
        free(data);
        free(offs);
    }
    cg_close(fn);
    return bad;
}

/* cgnscheck output without its first line (which names the file). */
static char *check_report(const char *path)
{
    char cmd[1400];
    snprintf(cmd, sizeof cmd, "cgnscheck '%s' 2>&1 | tail -n +2", path);
    return run(cmd);
}

/* Make the fixture look written by CGNS 3.1: no ElementStartOffset under
   the MIXED section, CGNSLibraryVersion 3.1.  libcgns 3.4 would add the
   offsets back if the file were opened with cg_open(MODE_MODIFY). */
static int make_old(const char *path)
{
    int cg;
    double root, id, pid;
    float version = 3.1f;
    if (cgio_open_file(path, CGIO_MODE_MODIFY, CGIO_FILE_NONE, &cg) ||
        cgio_get_root_id(cg, &root) ||
        cgio_get_node_id(cg, root, "/Base/Tets/TetMix", &pid) ||
        cgio_get_node_id(cg, root, "/Base/Tets/TetMix/ElementStartOffset", &id) ||
        cgio_delete_node(cg, pid, id) ||
        cgio_get_node_id(cg, root, "/CGNSLibraryVersion", &id) ||
        cgio_write_all_data(cg, id, &version) || cgio_close_file(cg))
        return -1;
    return 0;
}

static int has_node(const char *path, const char *node)
{
    int cg, found;
    double root, id;
    if (cgio_open_file(path, CGIO_MODE_READ, CGIO_FILE_NONE, &cg))
        return -1;
    cgio_get_root_id(cg, &root);
    found = cgio_get_node_id(cg, root, node, &id) == 0;
    cgio_close_file(cg);
    return found;
}

static void roundtrip(const char *name, int file_type, int single, int old)
{
    char in[640], out[640], cmd[1400];
    fixture_opts o = {file_type, single, 0.25};
    snprintf(in, sizeof in, "%s/%s.cgns", dir, name);
    snprintf(out, sizeof out, "%s/%s-smooth.cgns", dir, name);
    CHECK_EQ_INT(fixture_write(in, &o), 0);
    if (old)
        CHECK_EQ_INT(make_old(in), 0);
    chmod(in, 0640); /* the output gets the input's permissions */
    size_t n_before, n_after;
    char *before = slurp(in, &n_before);

    getme_doc *doc;
    getme_formats_status st = getme_doc_open(&doc, in, NULL);
    CHECK_EQ_INT(st, GETME_FORMATS_OK);
    if (st != GETME_FORMATS_OK) {
        fprintf(stderr, "%s\n", getme_doc_error(doc));
        getme_doc_close(doc);
        free(before);
        return;
    }
    getme_mesh *m = getme_doc_mesh(doc);
    double *xyz_in = malloc(3 * FIX_NODES * sizeof *xyz_in);
    double *xyz_out = malloc(3 * FIX_NODES * sizeof *xyz_out);
    uint8_t fixed[FIX_NODES];
    getme_mesh_get_coords(m, xyz_in);
    getme_mesh_get_fixed_mask(m, fixed);
    getme_result res;
    CHECK_EQ_INT(getme_smooth(m, NULL, &res), GETME_OK);
    CHECK(res.q_mean > res.q_mean_initial + 0.01);
    CHECK(res.q_min_star > res.q_min_star_initial);
    CHECK_EQ_INT(getme_doc_write(doc, out), GETME_FORMATS_OK);
    getme_doc_close(doc);
    struct stat sb;
    CHECK(stat(out, &sb) == 0 && (sb.st_mode & 0777) == 0640);
    if (old) /* the old layout is kept: nothing was "upgraded" */
        CHECK_EQ_INT(has_node(out, "/Base/Tets/TetMix/ElementStartOffset"), 0);

    char *after = slurp(in, &n_after);
    CHECK(before && after && n_before == n_after &&
          memcmp(before, after, n_before) == 0);
    free(before);
    free(after);

    /* only the coordinate arrays differ, in both zones */
    snprintf(cmd, sizeof cmd, "cgnsdiff -d '%s' '%s' 2>&1", in, out);
    char *diff = run(cmd);
    int lines = 0, coord_lines = 0;
    for (char *line = strtok(diff, "\n"); line; line = strtok(NULL, "\n")) {
        lines++;
        coord_lines += strstr(line, "/GridCoordinates/Coordinate") != NULL;
        if (!strstr(line, "/GridCoordinates/Coordinate"))
            fprintf(stderr, "unexpected cgnsdiff line: %s\n", line);
    }
    CHECK_EQ_INT(lines, coord_lines);
    CHECK_EQ_INT(coord_lines, 6);
    free(diff);

    /* cgnscheck: the same report for input and output */
    char *ci = check_report(in), *co = check_report(out);
    CHECK(strlen(ci) > 100 && strcmp(ci, co) == 0);
    CHECK(strstr(co, "ERROR") == NULL);
    free(ci);
    free(co);

    /* read back with libcgns: stored type kept, fixed bit-identical */
    CHECK_EQ_INT(count_inverted(out, xyz_out, single), 0);
    int same_fixed = 1, moved = 0;
    for (int i = 0; i < FIX_NODES; i++)
        for (int k = 0; k < 3; k++) {
            double a = xyz_in[3 * i + k], b = xyz_out[3 * i + k];
            if (fixed[i])
                same_fixed &= memcmp(&a, &b, sizeof a) == 0;
            else
                moved += a != b;
        }
    CHECK(same_fixed);
    CHECK(moved > 20);

    /* the read-back has the quality the smoother reported */
    st = getme_doc_open(&doc, out, NULL);
    CHECK_EQ_INT(st, GETME_FORMATS_OK);
    if (st == GETME_FORMATS_OK) {
        getme_quality_stats s;
        getme_mesh_quality_stats(getme_doc_mesh(doc), -1, &s);
        CHECK_NEAR(s.q_mean, res.q_mean, single ? 1e-5 : 1e-12);
        CHECK_EQ_INT(s.num_invalid, 0);
    }
    getme_doc_close(doc);

    /* the output directory holds no leftover temporary file */
    snprintf(cmd, sizeof cmd, "ls -a '%s' | grep -c '\\.tmp\\.'", dir);
    char *tmps = run(cmd);
    CHECK(atoi(tmps) == 0);
    free(tmps);
    free(xyz_in);
    free(xyz_out);
}

/* Node g at c + t (orig_g - c), every other node at its input position. */
static void place(double *trial, const double *orig, int g, const double *c,
                  double t)
{
    memcpy(trial, orig, 3 * FIX_NODES * sizeof *trial);
    for (int k = 0; k < 3; k++)
        trial[3 * g + k] = c[k] + t * (orig[3 * g + k] - c[k]);
}

/* Are the tets around g valid as given, and how many are not once
   rounded to float? */
static void check_star(const double *trial, const cgsize_t *data,
                       const cgsize_t *offs, int g, int *valid, int *flips)
{
    *valid = 1;
    *flips = 0;
    for (int f = 0; f < 162; f++) {
        double x[12], xr[12];
        int has = 0;
        for (int a = 0; a < 4; a++) {
            int32_t n = (int32_t)(data[offs[f] + 1 + a] - 1 + 125);
            has |= n == g;
            for (int k = 0; k < 3; k++) {
                x[3 * a + k] = trial[3 * n + k];
                xr[3 * a + k] = (double)(float)trial[3 * n + k];
            }
        }
        if (!has)
            continue;
        *valid &= getme_element_quality(GETME_TET, x) > 0.0;
        *flips += getme_element_quality(GETME_TET, xr) <= 0.0;
    }
}

/* RealSingle: a free node moved so close to the opposite face of one of its
   tets that the tet is (barely) valid in double but not once the node is
   rounded to float.  The writer must put the node back to its input
   position and say so. */
static void rounding_repair(void)
{
    char in[640], out[640];
    fixture_opts o = {CG_FILE_HDF5, 1, 0.25};
    snprintf(in, sizeof in, "%s/round.cgns", dir);
    snprintf(out, sizeof out, "%s/round-smooth.cgns", dir);
    CHECK_EQ_INT(fixture_write(in, &o), 0);
    int fn;
    cgsize_t size, offs[181], *data;
    CHECK_EQ_INT(cg_open(in, CG_MODE_READ, &fn), CG_OK);
    cg_ElementDataSize(fn, 1, 2, 1, &size);
    data = malloc((size_t)size * sizeof *data);
    cg_poly_elements_read(fn, 1, 2, 1, data, offs, NULL);
    cg_close(fn);

    getme_doc *doc;
    CHECK_EQ_INT(getme_doc_open(&doc, in, NULL), GETME_FORMATS_OK);
    getme_mesh *m = getme_doc_mesh(doc);
    double xyz[3 * FIX_NODES], orig[3 * FIX_NODES];
    getme_mesh_get_coords(m, xyz);
    memcpy(orig, xyz, sizeof xyz);
    const int g = 125 + 21; /* grid point (1,1,1) of zone Tets: free */
    int found = 0;
    for (int e = 0; e < 162 && !found; e++) {
        int32_t v[4], at = -1;
        for (int a = 0; a < 4; a++) {
            v[a] = (int32_t)(data[offs[e] + 1 + a] - 1 + 125);
            if (v[a] == g)
                at = a;
        }
        if (at < 0)
            continue;
        double c[3] = {0, 0, 0};
        for (int a = 0; a < 4; a++)
            for (int k = 0; a != at && k < 3; k++)
                c[k] += orig[3 * v[a] + k] / 3.0;
        /* Move g towards the face: find by bisection where the tet stops
           counting as valid, then step just above that point until the
           float-rounded position is invalid while the double one is not. */
        double lo = 0.0, hi = 1.0, trial[3 * FIX_NODES];
        int valid, flips;
        for (int it = 0; it < 60; it++) {
            double t = 0.5 * (lo + hi);
            place(trial, orig, g, c, t);
            check_star(trial, data, offs, g, &valid, &flips);
            if (valid)
                hi = t;
            else
                lo = t;
        }
        for (int k = 0; k < 400 && !found; k++) {
            place(trial, orig, g, c, hi + k * 2e-9);
            check_star(trial, data, offs, g, &valid, &flips);
            if (valid && flips > 0) {
                found = 1;
                memcpy(xyz, trial, sizeof xyz);
            }
        }
    }
    free(data);
    CHECK(found);
    CHECK_EQ_INT(getme_mesh_set_coords(m, xyz), GETME_OK);
    CHECK_EQ_INT(getme_doc_write(doc, out), GETME_FORMATS_OK);
    CHECK(strstr(getme_doc_info(doc), "; 1 nodes kept at their input position") != NULL);
    getme_doc_close(doc);
    double back[3 * FIX_NODES];
    CHECK_EQ_INT(count_inverted(out, back, 1), 0);
    CHECK(memcmp(back + 3 * g, orig + 3 * g, 3 * sizeof(double)) == 0);
}

/* A planar zone in 3-D space: only CoordinateX and CoordinateY change. */
static void roundtrip_2d(void)
{
    char in[640], out[640], cmd[1400];
    snprintf(in, sizeof in, "%s/plane.cgns", dir);
    snprintf(out, sizeof out, "%s/plane-smooth.cgns", dir);
    CHECK_EQ_INT(fixture_write_2d(in), 0);
    getme_doc *doc;
    CHECK_EQ_INT(getme_doc_open(&doc, in, NULL), GETME_FORMATS_OK);
    getme_result res;
    CHECK_EQ_INT(getme_smooth(getme_doc_mesh(doc), NULL, &res), GETME_OK);
    CHECK(res.q_mean > res.q_mean_initial);
    CHECK_EQ_INT(getme_doc_write(doc, out), GETME_FORMATS_OK);
    getme_doc_close(doc);
    snprintf(cmd, sizeof cmd, "cgnsdiff -d '%s' '%s' 2>&1", in, out);
    char *diff = run(cmd);
    CHECK(strstr(diff, "/Plane/Sheet/GridCoordinates/CoordinateX") != NULL);
    CHECK(strstr(diff, "/Plane/Sheet/GridCoordinates/CoordinateY") != NULL);
    CHECK(strstr(diff, "CoordinateZ") == NULL);
    int lines = 0;
    for (char *p = diff; *p; p++)
        lines += *p == '\n';
    CHECK_EQ_INT(lines, 2);
    free(diff);
}

/* Writing onto the input, or into a missing directory, fails cleanly. */
static void write_errors(void)
{
    char in[640], bad[700];
    fixture_opts o = {CG_FILE_HDF5, 0, 0.25};
    snprintf(in, sizeof in, "%s/w.cgns", dir);
    fixture_write(in, &o);
    getme_doc *doc;
    CHECK_EQ_INT(getme_doc_open(&doc, in, NULL), GETME_FORMATS_OK);
    CHECK_EQ_INT(getme_doc_write(doc, in), GETME_FORMATS_ERR_ARGUMENT);
    snprintf(bad, sizeof bad, "%s/no/such/dir/out.cgns", dir);
    CHECK_EQ_INT(getme_doc_write(doc, bad), GETME_FORMATS_ERR_WRITE);
    CHECK(strstr(getme_doc_error(doc), "out.cgns: cannot create a temporary "
                                       "file next to it: No such file") != NULL);
    /* the input changed since it was read: refuse */
    FILE *f = fopen(in, "ab");
    if (f) {
        fputc(0, f);
        fclose(f);
    }
    snprintf(bad, sizeof bad, "%s/changed.cgns", dir);
    CHECK_EQ_INT(getme_doc_write(doc, bad), GETME_FORMATS_ERR_WRITE);
    CHECK(strstr(getme_doc_error(doc), "changed since it was read") != NULL);
    CHECK(access(bad, F_OK) != 0);
    getme_doc_close(doc);
}

int main(void)
{
    const char *base = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    snprintf(dir, sizeof dir, "%s/getme-cgns-rt-%ld", base, (long)getpid());
    mkdir(dir, 0700);
    roundtrip("hdf5", CG_FILE_HDF5, 0, 0);
    roundtrip("hdf5-single", CG_FILE_HDF5, 1, 0);
    roundtrip("adf", CG_FILE_ADF, 0, 0);
    roundtrip("adf-single", CG_FILE_ADF, 1, 0);
    roundtrip("hdf5-v31", CG_FILE_HDF5, 0, 1);
    roundtrip("adf-v31", CG_FILE_ADF, 0, 1);
    roundtrip_2d();
    rounding_repair();
    write_errors();
    if (check_failed_ == 0) {
        char cmd[700];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "could not remove %s\n", dir);
    }
    return check_summary("test_cgns_roundtrip");
}
