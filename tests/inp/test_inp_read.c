/*
 * test_inp_read.c -- the INP adapter on hand-written decks: counts, sets,
 * sections, fixed nodes, parts/instances/includes, planar decks, and the
 * write-back contract (only moved node lines change, bit-exact re-read).
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"
#include "inp_test_util.h"

#include <math.h>

/* 3x3x3 unit hexes, node (i,j,k) has id 10*(i+4j+16k)+7; CRLF line ends,
   mixed case, continuation lines, sections on x-layers, a beam between two
   interior nodes and a shell on the skin. */
static int nid(int i, int j, int k) { return 10 * (i + 4 * j + 16 * k) + 7; }

static void hex_deck(const char *name)
{
    char *b = malloc(1 << 16);
    size_t n = 0;
#define OUT(...) n += (size_t)sprintf(b + n, __VA_ARGS__)
    OUT("*HEADING\r\n hand-written 3x3x3 hex block\r\n** a comment\r\n");
    OUT("*Node, nset=AllNodes\r\n");
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++)
                OUT("  %d,  %d.0, %d.,%d\r\n", nid(i, j, k), i, j, k);
    for (int i = 0; i < 3; i++) {
        if (i == 0)
            OUT("*element , type = c3d8r, elset = Layer0\r\n");
        else
            OUT("* ELEMENT, TYPE=C3D8I\r\n");
        for (int m = 0; m < 9; m++) {
            int j = m % 3, k = m / 3;
            OUT("%d, %d, %d, %d, %d,\r\n   %d, %d, %d, %d\r\n",
                1000 + (i * 9 + m) * 3, nid(i, j, k), nid(i + 1, j, k),
                nid(i + 1, j + 1, k), nid(i, j + 1, k), nid(i, j, k + 1),
                nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1),
                nid(i, j + 1, k + 1));
        }
    }
    OUT("*Element, type=B31, elset=Beam\r\n5000, %d, %d\r\n", nid(2, 1, 1),
        nid(2, 2, 1));
    OUT("*Element, type=S4R, elset=Skin\r\n6000, %d, %d, %d, %d\r\n",
        nid(0, 0, 0), nid(0, 1, 0), nid(1, 1, 0), nid(1, 0, 0));
    OUT("*ELSET, ELSET=Layer1, GENERATE\r\n 1027, 1051, 3\r\n");
    OUT("*Elset, elset=Layer2\r\n1054, 1057, 1060, 1063, 1066, 1069, 1072,"
        "\r\n1075, 1078\r\n");
    OUT("*ELSET,ELSET=Rest\r\nLayer1, LAYER2\r\n");
    OUT("*NSET, NSET=Center\r\n%d\r\n", nid(1, 1, 1));
    /* a range far wider than the mesh, and a set naming itself */
    OUT("*NSET, NSET=Wide, GENERATE\r\n7, 2147483647, 10\r\n");
    OUT("*NSET, NSET=Loop\r\nLoop, Center\r\n");
    OUT("*Material, name=Steel\r\n*Elastic\r\n210000., 0.3\r\n");
    OUT("*Solid Section, elset=Layer0, material=Steel\r\n,\r\n");
    OUT("*SOLID SECTION, ELSET=REST, MATERIAL=Steel\r\n,\r\n");
    OUT("*Step\r\n*Static\r\n*Boundary\r\nCenter, 1, 3\r\n*End Step\r\n");
#undef OUT
    put_file(name, b, n);
    free(b);
}

static int32_t fixed_count(const char *name, int ifaces, int nfix,
                           const char *const *fix, getme_formats_status *st)
{
    getme_doc *doc;
    *st = open_deck(&doc, name, ifaces, nfix, fix);
    int32_t n = *st == GETME_FORMATS_OK ? getme_mesh_num_fixed(getme_doc_mesh(doc))
                                   : -1;
    if (*st)
        fprintf(stderr, "open: %s\n", getme_doc_error(doc));
    getme_doc_close(doc);
    return n;
}

static void test_hex_counts(void)
{
    hex_deck("hex.inp");
    getme_doc *doc;
    CHECK_EQ_INT(open_deck(&doc, "hex.inp", 1, 0, NULL), GETME_FORMATS_OK);
    getme_mesh *m = getme_doc_mesh(doc);
    CHECK_EQ_INT(getme_mesh_dim(m), 3);
    CHECK_EQ_INT(getme_mesh_num_nodes(m), 64);
    CHECK_EQ_INT(getme_mesh_num_elements(m), 27);
    CHECK_EQ_INT(getme_mesh_num_elements_of_type(m, GETME_HEX), 27);
    /* 56 skin + 4 on the section interface x = 1 + 2 beam nodes. */
    CHECK_EQ_INT(getme_mesh_num_fixed(m), 62);
    CHECK(getme_doc_element_id(doc, 0) == 1000 && getme_doc_element_id(doc, 26) == 1078);
    CHECK(strstr(getme_doc_info(doc), "64 nodes") != NULL);
    getme_doc_close(doc);

    getme_formats_status st;
    CHECK_EQ_INT(fixed_count("hex.inp", 0, 0, NULL, &st), 58);
    const char *center[] = {"center"};
    CHECK_EQ_INT(fixed_count("hex.inp", 0, 1, center, &st), 59);
    const char *layer1[] = {"LAYER1"}; /* GENERATE: all 8 interior nodes */
    CHECK_EQ_INT(fixed_count("hex.inp", 0, 1, layer1, &st), 64);
    const char *rest[] = {"Rest"};     /* set of sets */
    CHECK_EQ_INT(fixed_count("hex.inp", 0, 1, rest, &st), 64);
    const char *wide[] = {"Wide"};
    CHECK_EQ_INT(fixed_count("hex.inp", 0, 1, wide, &st), 64);
    const char *loop[] = {"loop"};
    CHECK_EQ_INT(fixed_count("hex.inp", 0, 1, loop, &st), 59);
    const char *all[] = {"allnodes"};
    CHECK_EQ_INT(fixed_count("hex.inp", 0, 1, all, &st), 64);
    const char *bad[] = {"NoSuchSet"};
    CHECK_EQ_INT(open_deck(&doc, "hex.inp", 1, 1, bad), GETME_FORMATS_ERR_ARGUMENT);
    CHECK(strstr(getme_doc_error(doc), "NoSuchSet") != NULL);
    CHECK(strstr(getme_doc_error(doc), "Layer0") != NULL);
    getme_doc_close(doc);
}

/* Lines of a and b that differ; the first differing line of b in *line. */
static int diff_lines(const char *a, const char *b, char *line, size_t sz)
{
    int ndiff = 0;
    while (*a || *b) {
        const char *ea = strchr(a, '\n'), *eb = strchr(b, '\n');
        size_t na = ea ? (size_t)(ea - a + 1) : strlen(a);
        size_t nb = eb ? (size_t)(eb - b + 1) : strlen(b);
        if (na != nb || memcmp(a, b, na) != 0) {
            if (!ndiff++ && line)
                snprintf(line, sz, "%.*s", (int)nb, b);
        }
        a += na;
        b += nb;
    }
    return ndiff;
}

static void test_hex_write(void)
{
    getme_doc *doc;
    CHECK_EQ_INT(open_deck(&doc, "hex.inp", 1, 0, NULL), GETME_FORMATS_OK);
    getme_mesh *m = getme_doc_mesh(doc);
    double *x = malloc(64 * 3 * sizeof *x);
    getme_mesh_get_coords(m, x);
    int free_node = 2 + 4 * 1 + 16 * 2; /* (2,1,2): read order index */
    x[3 * free_node] = 2.1;
    x[3 * free_node + 2] = 7.0 / 3.0;
    getme_mesh_set_coords(m, x);
    CHECK_EQ_INT(getme_doc_write(doc, tpath("hex-out.inp")), GETME_FORMATS_OK);
    CHECK_EQ_INT(getme_doc_write(doc, tpath("hex.inp")), GETME_FORMATS_ERR_ARGUMENT);
    getme_doc_close(doc);

    char *in = get_file(tpath("hex.inp"), NULL);
    char *out = get_file(tpath("hex-out.inp"), NULL);
    char line[256] = "";
    CHECK(in && out);
    CHECK_EQ_INT(diff_lines(in, out, line, sizeof line), 1);
    /* Only the coordinate fields change; spacing and CRLF stay. */
    CHECK(strcmp(line, "  387,  2.1, 1.,2.3333333333333335\r\n") == 0);
    fprintf(stderr, "changed line: %s", line);
    free(in);
    free(out);

    /* Re-reading the output gives exactly the coordinates written. */
    CHECK_EQ_INT(open_deck(&doc, "hex-out.inp", 1, 0, NULL), GETME_FORMATS_OK);
    const double *y = getme_mesh_coords(getme_doc_mesh(doc));
    CHECK(memcmp(x, y, 64 * 3 * sizeof *x) == 0);
    getme_doc_close(doc);
    free(x);
}

static void test_hex_smooth(void)
{
    getme_doc *doc;
    CHECK_EQ_INT(open_deck(&doc, "hex.inp", 0, 0, NULL), GETME_FORMATS_OK);
    getme_mesh *m = getme_doc_mesh(doc);
    /* Distort the 6 free nodes, smooth, write: fixed nodes keep their
       text, the moved ones are the only lines that differ. */
    CHECK_EQ_INT(getme_mesh_distort(m, 7, 0.3, 0, 5), GETME_OK);
    getme_result r;
    CHECK_EQ_INT(getme_smooth(m, NULL, &r), GETME_OK);
    double *x = malloc(64 * 3 * sizeof *x);
    uint8_t fixed[64];
    getme_mesh_get_coords(m, x);
    getme_mesh_get_fixed_mask(m, fixed);
    CHECK_EQ_INT(getme_doc_write(doc, tpath("hex-smooth.inp")), GETME_FORMATS_OK);
    getme_doc_close(doc);
    char *in = get_file(tpath("hex.inp"), NULL);
    char *out = get_file(tpath("hex-smooth.inp"), NULL);
    int nfree = 0;
    for (int i = 0; i < 64; i++)
        nfree += !fixed[i];
    CHECK_EQ_INT(nfree, 6);
    CHECK(diff_lines(in, out, NULL, 0) <= 6);
    CHECK_EQ_INT(open_deck(&doc, "hex-smooth.inp", 0, 0, NULL), GETME_FORMATS_OK);
    CHECK(memcmp(x, getme_mesh_coords(getme_doc_mesh(doc)),
                 64 * 3 * sizeof *x) == 0);
    getme_quality_stats s;
    getme_mesh_quality_stats(getme_doc_mesh(doc), -1, &s);
    CHECK_EQ_INT(s.num_invalid, 0);
    getme_doc_close(doc);
    free(in);
    free(out);
    free(x);
}

/* ---- parts, instances, includes ------------------------------------------ */

static int bid(int i, int j, int k) { return 100000 * (1 + i + 3 * j + 9 * k); }

static void parts_deck(void)
{
    char *b = malloc(1 << 16);
    size_t n = 0;
#define OUT(...) n += (size_t)sprintf(b + n, __VA_ARGS__)
    /* nodes: first 14 in sub/block_nodes.inp, the rest in a nested include
       holding data lines only */
    for (int q = 0; q < 27; q++) {
        if (q == 14) {
            OUT("** the rest comes from another file\n"
                "*include, input=block_nodes2.inp\n");
            put_file("sub/block_nodes.inp", b, n);
            n = 0;
        }
        int i = q % 3, j = (q / 3) % 3, k = q / 9;
        OUT("%d, %d, %d, %d\n", bid(i, j, k), i, j, k);
    }
    put_file("sub/block_nodes2.inp", b, n);
    n = 0;
    OUT("*Heading\n** parts, instances and includes\n");
    OUT("*Part, name=Block\n*Node\n*INCLUDE, INPUT=sub/block_nodes.inp\n");
    OUT("*Element, type=C3D8, elset=All\n");
    for (int e = 0; e < 8; e++) {
        int i = e % 2, j = (e / 2) % 2, k = e / 4;
        OUT("%d, %d, %d, %d, %d, %d, %d, %d, %d\n", e + 1, bid(i, j, k),
            bid(i + 1, j, k), bid(i + 1, j + 1, k), bid(i, j + 1, k),
            bid(i, j, k + 1), bid(i + 1, j, k + 1), bid(i + 1, j + 1, k + 1),
            bid(i, j + 1, k + 1));
    }
    OUT("*Solid Section, elset=All, material=Steel\n,\n*End Part\n");
    OUT("*Part, name=Plate\n*Node\n1, 0, 0, 5\n2, 1, 0, 5\n3, 1, 1, 5\n"
        "4, 0, 1, 5\n*Element, type=S4\n1, 1, 2, 3, 4\n*End Part\n");
    OUT("*Assembly, name=Assembly\n*Instance, name=B1, part=Block\n"
        "*End Instance\n*Instance, name=B2, part=Block\n 10., 0., 0.\n"
        " 10., 0., 0., 10., 0., 1., 90.\n*End Instance\n"
        "*Instance, name=P1, part=Plate\n*End Instance\n"
        "*Nset, nset=Corner, instance=B1\n %d\n*End Assembly\n",
        bid(1, 1, 1));
    OUT("*INCLUDE, INPUT=\"materials.inp\"\n*Step\n*Static\n*End Step\n");
    put_file("parts.inp", b, n);
    put_text("materials.inp", "*Material, name=Steel\n*Elastic\n210000., 0.3\n");
#undef OUT
    free(b);
}

static void test_parts(void)
{
    char sub[300];
    snprintf(sub, sizeof sub, "%s/sub", tdir);
    mkdir(sub, 0777);
    snprintf(sub, sizeof sub, "%s/out", tdir);
    mkdir(sub, 0777);
    parts_deck();
    getme_doc *doc;
    CHECK_EQ_INT(open_deck(&doc, "parts.inp", 1, 0, NULL), GETME_FORMATS_OK);
    fprintf(stderr, "%s\n", getme_doc_error(doc));
    getme_mesh *m = getme_doc_mesh(doc);
    CHECK_EQ_INT(getme_mesh_num_nodes(m), 31);
    CHECK_EQ_INT(getme_mesh_num_elements(m), 8);
    CHECK_EQ_INT(getme_mesh_num_fixed(m), 30); /* all but the centre */
    double *x = malloc(31 * 3 * sizeof *x);
    getme_mesh_get_coords(m, x);
    x[3 * 13 + 1] = 1.25; /* the centre, in block_nodes.inp */
    x[3 * 20 + 0] = 7.5;  /* a (fixed) node in block_nodes2.inp */
    getme_mesh_set_coords(m, x);
    CHECK_EQ_INT(getme_doc_write(doc, tpath("out/res.inp")), GETME_FORMATS_OK);
    getme_doc_close(doc);

    char *main = get_file(tpath("out/res.inp"), NULL);
    char *n1 = get_file(tpath("out/res.block_nodes.inp"), NULL);
    char *n2 = get_file(tpath("out/res.block_nodes2.inp"), NULL);
    char *mat = get_file(tpath("out/res.materials.inp"), NULL);
    CHECK(main && n1 && n2 && mat);
    CHECK(main && strstr(main, "*INCLUDE, INPUT=res.block_nodes.inp\n"));
    CHECK(main && strstr(main, "*INCLUDE, INPUT=\"res.materials.inp\"\n"));
    CHECK(n1 && strstr(n1, "*include, input=res.block_nodes2.inp\n"));
    CHECK(n1 && strstr(n1, "\n1400000, 1, 1.25, 1\n"));
    CHECK(n2 && strstr(n2, "\n2100000, 7.5, 0, 2\n"));
    free(main);
    free(n1);
    free(n2);
    free(mat);
    CHECK_EQ_INT(open_deck(&doc, "out/res.inp", 1, 0, NULL), GETME_FORMATS_OK);
    CHECK(memcmp(x, getme_mesh_coords(getme_doc_mesh(doc)), 31 * 3 * 8) == 0);
    getme_doc_close(doc);
    free(x);

    getme_formats_status st;
    const char *corner[] = {"corner"};
    CHECK_EQ_INT(fixed_count("parts.inp", 1, 1, corner, &st), 31);
    const char *qual[] = {"Block.All"};
    CHECK_EQ_INT(fixed_count("parts.inp", 1, 1, qual, &st), 31);
}

static void test_planar(void)
{
    char *b = malloc(1 << 14);
    size_t n = 0;
#define OUT(...) n += (size_t)sprintf(b + n, __VA_ARGS__)
    OUT("\xEF\xBB\xBF*NODE\n"); /* with a UTF-8 byte order mark */
    for (int q = 0; q < 16; q++)
        OUT("%d, %d., %d., 2.5\n", q + 1, q % 4, q / 4);
    OUT("*ELEMENT, TYPE=CPS4R, ELSET=Plate\n");
    for (int e = 0; e < 9; e++) {
        int i = e % 3, j = e / 3, a = 1 + i + 4 * j;
        OUT("%d, %d, %d, %d, %d\n", e + 1, a, a + 1, a + 5, a + 4);
    }
    OUT("*ELEMENT, TYPE=T2D2\n20, 6, 7\n");
#undef OUT
    put_file("plane.inp", b, n);
    free(b);
    getme_doc *doc;
    CHECK_EQ_INT(open_deck(&doc, "plane.inp", 1, 0, NULL), GETME_FORMATS_OK);
    getme_mesh *m = getme_doc_mesh(doc);
    CHECK_EQ_INT(getme_mesh_dim(m), 2);
    CHECK_EQ_INT(getme_mesh_num_elements_of_type(m, GETME_QUAD), 9);
    CHECK_EQ_INT(getme_mesh_num_fixed(m), 14); /* 12 skin + 2 truss nodes */
    double x[48];
    getme_mesh_get_coords(m, x);
    x[3 * 9 + 1] = 2.25; /* node 10, interior */
    getme_mesh_set_coords(m, x);
    CHECK_EQ_INT(getme_doc_write(doc, tpath("plane-out.inp")), GETME_FORMATS_OK);
    getme_doc_close(doc);
    char *out = get_file(tpath("plane-out.inp"), NULL);
    CHECK(out && memcmp(out, "\xEF\xBB\xBF*NODE\n1, 0., 0., 2.5\n", 21) == 0);
    CHECK(out && strstr(out, "\n10, 1., 2.25, 2.5\n") != NULL);
    free(out);
}

int main(void)
{
    scratch_init("inp_read");
    test_hex_counts();
    test_hex_write();
    test_hex_smooth();
    test_parts();
    test_planar();
    scratch_done(check_failed_ == 0);
    return check_summary("test_inp_read");
}
