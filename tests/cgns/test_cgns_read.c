/*
 * test_cgns_read.c -- the CGNS adapter reading files written by libcgns:
 * node/element counts, fixed-node counts with BCs, families, zones,
 * sections, --fix/--free names, 2-D planar zones, structured zones, and
 * malformed or unsupported inputs with their messages.
 */
#include "cgns_fixture.h"
#include "check.h"
#include "getme_formats.h"

#include <cgns_io.h>

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char dir[512];

static const char *path_of(const char *name)
{
    static char buf[4][640];
    static int k = 0;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

/* Open with fix/free lists; returns the status, fills *fixed. */
static getme_formats_status open_with(const char *path, int nfix,
                                 const char *const *fix, int nfree,
                                 const char *const *freed, int fix_skin,
                                 int32_t *fixed, char *err, size_t errsize)
{
    getme_doc_options o;
    getme_doc *doc;
    getme_doc_options_init(&o);
    o.num_fix = nfix;
    o.fix = fix;
    o.num_free = nfree;
    o.free_sets = freed;
    o.fix_skin = fix_skin;
    getme_formats_status st = getme_doc_open(&doc, path, &o);
    if (fixed)
        *fixed = st == GETME_FORMATS_OK ? getme_mesh_num_fixed(getme_doc_mesh(doc)) : -1;
    if (err)
        snprintf(err, errsize, "%s", getme_doc_error(doc));
    getme_doc_close(doc);
    return st;
}

static void test_counts(const char *path)
{
    getme_doc *doc;
    getme_formats_status st = getme_doc_open(&doc, path, NULL);
    CHECK_EQ_INT(st, GETME_FORMATS_OK);
    if (st != GETME_FORMATS_OK) {
        fprintf(stderr, "%s\n", getme_doc_error(doc));
        getme_doc_close(doc);
        return;
    }
    getme_mesh *m = getme_doc_mesh(doc);
    CHECK_EQ_INT(getme_mesh_dim(m), 3);
    CHECK_EQ_INT(getme_mesh_num_nodes(m), FIX_NODES);
    CHECK_EQ_INT(getme_mesh_num_elements(m), FIX_ELEMS);
    CHECK_EQ_INT(getme_mesh_num_elements_of_type(m, GETME_HEX), 64);
    CHECK_EQ_INT(getme_mesh_num_elements_of_type(m, GETME_TET), 162);
    CHECK_EQ_INT(getme_mesh_num_fixed(m), FIX_FIXED_DEFAULT);
    /* element ids are the CGNS element numbers of each zone */
    CHECK_EQ_INT(getme_doc_element_id(doc, 0), 1);
    CHECK_EQ_INT(getme_doc_element_id(doc, 63), 64);
    CHECK_EQ_INT(getme_doc_element_id(doc, 64), 1);
    CHECK_EQ_INT(getme_doc_element_id(doc, FIX_ELEMS - 1), 162);
    /* node 0 of zone Tets starts at 125, x = 10 */
    CHECK_NEAR(getme_mesh_coords(m)[3 * 125], 10.0, 0.0);
    /* the interior node (1,1,1) of Block is a "probe" BC node: fixed */
    uint8_t mask[FIX_NODES];
    getme_mesh_get_fixed_mask(m, mask);
    CHECK_EQ_INT(mask[1 + 5 * (1 + 5 * 1)], 1);
    CHECK_EQ_INT(mask[2 + 5 * (2 + 5 * 1)], 0);  /* interior, free */
    CHECK_EQ_INT(mask[2 + 5 * (2 + 5 * 2)], 1);  /* on the baffle */
    CHECK(strstr(getme_doc_info(doc), "2 zones") != NULL);
    CHECK(strstr(getme_doc_info(doc), "3 of 3 BCs") != NULL);
    getme_doc_close(doc);
}

static void test_names(const char *path)
{
    int32_t fixed;
    char err[1024];
    const char *probe[] = {"probe"}, *probefam[] = {"ProbeFam"},
               *baffle_sec[] = {"Baffle"}, *tets[] = {"Tets"},
               *tetfam[] = {"TetFam"}, *bad[] = {"Probe"},
               *outfam[] = {"OutFam"};

    CHECK_EQ_INT(open_with(path, 0, NULL, 1, probe, 1, &fixed, NULL, 0),
                 GETME_FORMATS_OK);
    CHECK_EQ_INT(fixed, FIX_FIXED_DEFAULT - 2);
    CHECK_EQ_INT(open_with(path, 0, NULL, 1, probefam, 1, &fixed, NULL, 0),
                 GETME_FORMATS_OK);
    CHECK_EQ_INT(fixed, FIX_FIXED_DEFAULT - 2);
    CHECK_EQ_INT(open_with(path, 0, NULL, 1, baffle_sec, 1, &fixed, NULL, 0),
                 GETME_FORMATS_OK);
    CHECK_EQ_INT(fixed, FIX_FIXED_DEFAULT - 9);
    CHECK_EQ_INT(open_with(path, 1, tets, 0, NULL, 1, &fixed, NULL, 0),
                 GETME_FORMATS_OK);
    CHECK_EQ_INT(fixed, FIX_FIXED_DEFAULT + 8);
    CHECK_EQ_INT(open_with(path, 1, tetfam, 0, NULL, 1, &fixed, NULL, 0),
                 GETME_FORMATS_OK);
    CHECK_EQ_INT(fixed, FIX_FIXED_DEFAULT + 8);
    /* freeing a skin BC changes nothing: skin nodes stay fixed */
    CHECK_EQ_INT(open_with(path, 0, NULL, 1, outfam, 1, &fixed, NULL, 0),
                 GETME_FORMATS_OK);
    CHECK_EQ_INT(fixed, FIX_FIXED_DEFAULT);
    /* two zones: the skin stays fixed even when asked not to */
    CHECK_EQ_INT(open_with(path, 0, NULL, 0, NULL, 0, &fixed, NULL, 0),
                 GETME_FORMATS_OK);
    CHECK_EQ_INT(fixed, FIX_FIXED_DEFAULT);
    /* names are case-sensitive; the message lists what exists */
    CHECK_EQ_INT(open_with(path, 1, bad, 0, NULL, 1, NULL, err, sizeof err),
                 GETME_FORMATS_ERR_ARGUMENT);
    CHECK(strstr(err, "'Probe'") && strstr(err, "BCs: inlet, floor, probe") &&
          strstr(err, "zones: Block, Tets"));
    CHECK_EQ_INT(open_with(path, 1, probe, 1, probe, 1, NULL, err, sizeof err),
                 GETME_FORMATS_ERR_ARGUMENT);
    CHECK(strstr(err, "both fixed and freed") != NULL);
}

static void test_2d(void)
{
    const char *p = path_of("plane.cgns");
    getme_doc *doc;
    CHECK_EQ_INT(fixture_write_2d(p), 0);
    getme_formats_status st = getme_doc_open(&doc, p, NULL);
    CHECK_EQ_INT(st, GETME_FORMATS_OK);
    if (st == GETME_FORMATS_OK) {
        getme_mesh *m = getme_doc_mesh(doc);
        CHECK_EQ_INT(getme_mesh_dim(m), 2);
        CHECK_EQ_INT(getme_mesh_num_elements_of_type(m, GETME_QUAD), 6);
        CHECK_EQ_INT(getme_mesh_num_elements_of_type(m, GETME_TRI), 6);
        CHECK_EQ_INT(getme_mesh_num_fixed(m), 12);
        CHECK_NEAR(getme_mesh_coords(m)[3 * 5 + 2], 0.5, 0.0);
    } else {
        fprintf(stderr, "%s\n", getme_doc_error(doc));
    }
    getme_doc_close(doc);
}

/* Open must fail with status want and a message holding every needle. */
static void expect_fail(const char *path, getme_formats_status want,
                        const char *needle1, const char *needle2)
{
    char err[1024];
    getme_formats_status st = open_with(path, 0, NULL, 0, NULL, 1, NULL, err,
                                   sizeof err);
    CHECK_EQ_INT(st, want);
    CHECK(strstr(err, path) != NULL);
    CHECK(needle1 == NULL || strstr(err, needle1) != NULL);
    CHECK(needle2 == NULL || strstr(err, needle2) != NULL);
    CHECK(strchr(err, '\n') == NULL);
    if (st != want || (needle1 && !strstr(err, needle1)) ||
        (needle2 && !strstr(err, needle2)))
        fprintf(stderr, "  got: %s\n", err);
}

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite(data, 1, n, f);
        fclose(f);
    }
}

static void truncate_copy(const char *from, const char *to, double frac)
{
    FILE *f = fopen(from, "rb");
    char *buf = malloc(1 << 20);
    size_t n = f ? fread(buf, 1, 1 << 20, f) : 0;
    if (f)
        fclose(f);
    write_bytes(to, buf, (size_t)(n * frac));
    free(buf);
}

static void test_malformed(const char *good_h5, const char *good_adf)
{
    expect_fail(path_of("missing.cgns"), GETME_FORMATS_ERR_OPEN,
                "No such file", NULL);
    write_bytes(path_of("text.cgns"), "hello world\n", 12);
    expect_fail(path_of("text.cgns"), GETME_FORMATS_ERR_PARSE, "not a CGNS file",
                NULL);
    write_bytes(path_of("empty.cgns"), "", 0);
    expect_fail(path_of("empty.cgns"), GETME_FORMATS_ERR_PARSE, "empty", NULL);
    truncate_copy(good_h5, path_of("trunc.cgns"), 0.5);
    expect_fail(path_of("trunc.cgns"), GETME_FORMATS_ERR_PARSE, "libcgns", NULL);
    truncate_copy(good_adf, path_of("trunc_adf.cgns"), 0.3);
    expect_fail(path_of("trunc_adf.cgns"), GETME_FORMATS_ERR_PARSE, "libcgns", NULL);

    /* node 999 in a 64-node zone */
    cgsize_t tet_bad[4] = {1, 2, 999, 17};
    fixture_write_custom(path_of("range.cgns"), CGNS_ENUMV(TETRA_4), 1,
                         tet_bad, 0);
    expect_fail(path_of("range.cgns"), GETME_FORMATS_ERR_PARSE,
                "/Base/Zone/Elem_TETRA_4: element 28 refers to node 999", NULL);
    /* second-order pyramids (the volume types getme does not smooth; the
       others: tests/highorder) are refused with the node path */
    cgsize_t pyra13[13] = {1, 2, 5, 4, 17, 3, 6, 7, 8, 9, 10, 11, 12};
    fixture_write_custom(path_of("pyra13.cgns"), CGNS_ENUMV(PYRA_13), 1, pyra13, 0);
    expect_fail(path_of("pyra13.cgns"), GETME_FORMATS_ERR_UNSUPPORTED,
                "/Base/Zone/Elem_PYRA_13", "PYRA_13");
    /* a TRI_6 boundary section only fixes its nodes */
    cgsize_t tri6[6] = {1, 2, 5, 3, 4, 6};
    fixture_write_custom(path_of("tri6.cgns"), CGNS_ENUMV(TRI_6), 1, tri6, 0);
    int32_t fixed;
    CHECK_EQ_INT(open_with(path_of("tri6.cgns"), 0, NULL, 0, NULL, 1, &fixed,
                           NULL, 0), GETME_FORMATS_OK);
    CHECK_EQ_INT(fixed, 64 - 8);
    /* an inverted tet: 1,5,2,17 is the mirror of 1,2,5,17 */
    cgsize_t inv[4] = {1, 5, 2, 17};
    fixture_write_custom(path_of("inverted.cgns"), CGNS_ENUMV(TETRA_4), 1, inv, 0);
    expect_fail(path_of("inverted.cgns"), GETME_FORMATS_ERR_INVALID,
                "/Base/Zone/Elem_TETRA_4 element 28", "1 invalid");
    /* a repeated node */
    cgsize_t rep[4] = {1, 2, 2, 17};
    fixture_write_custom(path_of("repeat.cgns"), CGNS_ENUMV(TETRA_4), 1, rep, 0);
    expect_fail(path_of("repeat.cgns"), GETME_FORMATS_ERR_INVALID,
                "element 28 is degenerate: node 2 appears twice", NULL);
    /* no GridCoordinates */
    fixture_write_custom(path_of("nocoords.cgns"), CGNS_ENUMV(TETRA_4), 0, NULL, 1);
    expect_fail(path_of("nocoords.cgns"), GETME_FORMATS_ERR_PARSE,
                "/Base/Zone/GridCoordinates", "missing");
    /* structured zones: alone refused, next to an unstructured one skipped */
    fixture_write_structured(path_of("struct.cgns"), 1);
    expect_fail(path_of("struct.cgns"), GETME_FORMATS_ERR_UNSUPPORTED,
                "structured", "'Struct'");
    fixture_write_structured(path_of("struct2.cgns"), 0);
    getme_doc *doc;
    CHECK_EQ_INT(getme_doc_open(&doc, path_of("struct2.cgns"), NULL), GETME_FORMATS_OK);
    CHECK_EQ_INT(getme_mesh_num_nodes(getme_doc_mesh(doc)), 64);
    CHECK(strstr(getme_doc_info(doc), "1 structured zone left unchanged") != NULL);
    getme_doc_close(doc);
}

/* A file whose /Base/Block/GridCoordinates is a link into another file:
   writing it would modify that other file, so it is refused. */
static void test_link(const char *target)
{
    char linked[640];
    int cg;
    double root, id, pid;
    snprintf(linked, sizeof linked, "%s", path_of("linked.cgns"));
    fixture_opts o = {CG_FILE_HDF5, 0, 0.25};
    CHECK_EQ_INT(fixture_write(linked, &o), 0);
    int ok = cgio_open_file(linked, CGIO_MODE_MODIFY, CGIO_FILE_NONE, &cg) == 0 &&
             cgio_get_root_id(cg, &root) == 0 &&
             cgio_get_node_id(cg, root, "/Base/Block", &pid) == 0 &&
             cgio_get_node_id(cg, root, "/Base/Block/GridCoordinates", &id) == 0 &&
             cgio_delete_node(cg, pid, id) == 0 &&
             cgio_create_link(cg, pid, "GridCoordinates", target,
                              "/Base/Block/GridCoordinates", &id) == 0 &&
             cgio_close_file(cg) == 0;
    CHECK(ok);
    expect_fail(linked, GETME_FORMATS_ERR_UNSUPPORTED,
                "/Base/Block/GridCoordinates is a link", NULL);
}

int main(void)
{
    const char *base = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    snprintf(dir, sizeof dir, "%s/getme-cgns-read-%ld", base, (long)getpid());
    mkdir(dir, 0700);

    char h5[640], h5s[640], adf[640]; /* path_of's buffers rotate */
    snprintf(h5, sizeof h5, "%s", path_of("fixture.cgns"));
    snprintf(h5s, sizeof h5s, "%s", path_of("fixture_single.cgns"));
    snprintf(adf, sizeof adf, "%s", path_of("fixture_adf.cgns"));
    fixture_opts o = {CG_FILE_HDF5, 0, 0.25};
    CHECK_EQ_INT(fixture_write(h5, &o), 0);
    o.single = 1;
    CHECK_EQ_INT(fixture_write(h5s, &o), 0);
    o.single = 0;
    o.file_type = CG_FILE_ADF;
    CHECK_EQ_INT(fixture_write(adf, &o), 0);

    test_counts(h5);
    test_counts(h5s);
    test_counts(adf);
    test_names(h5);
    test_2d();
    test_malformed(h5, adf);
    test_link(h5);
    /* adapter selection by content as well as by extension */
    CHECK(getme_format_for(h5) != NULL &&
          strcmp(getme_format_name(getme_format_for(h5)), "cgns") == 0);

    if (check_failed_ == 0) { /* keep the files of a failed run */
        char cmd[700];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "could not remove %s\n", dir);
    }
    return check_summary("test_cgns_read");
}
