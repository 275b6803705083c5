/*
 * test_msh41.c -- the native MSH 4.1 reader and writer without Gmsh
 * (GETME_MSH_READER=native, so it also runs under ASan+UBSan):
 *  - a small ASCII and binary file open with the expected mesh, fixed
 *    nodes, element ids; a moved node is written back and nothing else
 *    changes (binary: same size, only its 24 bytes);
 *  - errors: every truncation of both files, bad $MeshFormat, a missing
 *    node, third-order tets, unknown --fix name: status and one line
 *    naming the file (and the line for ASCII);
 *  - mutation fuzzing: thousands of mutants open or fail with a message.
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"
#include "fuzz_check.h"

#include "getme_formats.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char dir[256];

static const char *tpath(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void put_file(const char *name, const void *data, size_t n)
{
    FILE *f = fopen(tpath(name), "wb");
    if (f) {
        fwrite(data, 1, n, f);
        fclose(f);
    }
}

static size_t get_file(const char *name, char *buf, size_t cap)
{
    FILE *f = fopen(tpath(name), "rb");
    size_t n = f ? fread(buf, 1, cap, f) : 0;
    if (f)
        fclose(f);
    return n;
}

/* Two tets in volumes 1 and 2 (physical 7 "a" and 8 "b"), a boundary
   triangle on surface 1, an extra section to skip. */
static const char ascii_seed[] =
    "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
    "$PhysicalNames\n2\n3 7 \"a\"\n3 8 \"b\"\n$EndPhysicalNames\n"
    "$Entities\n0 0 1 2\n"
    "1 0 0 0 1 1 0 0 0\n"
    "1 0 0 0 1 1 1 1 7 1 1\n"
    "2 0 0 0 1 1 1 1 8 1 1\n$EndEntities\n"
    "$Nodes\n3 5 1 5\n"
    "2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n"
    "3 1 0 1\n4\n0 0 1\n"
    "3 2 0 1\n5\n1 1 1\n$EndNodes\n"
    "$Elements\n3 3 1 3\n"
    "2 1 2 1\n1 1 2 3\n"
    "3 1 4 1\n2 1 2 3 4\n"
    "3 2 4 1\n3 2 3 4 5\n$EndElements\n"
    "$Comments\nanything $End\n$EndComments\n";

/* The same mesh as MSH 2.2: entities and groups from the element tags. */
static const char ascii22_seed[] =
    "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
    "$PhysicalNames\n2\n3 7 \"a\"\n3 8 \"b\"\n$EndPhysicalNames\n"
    "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n$EndNodes\n"
    "$Elements\n3\n"
    "1 2 2 0 1 1 2 3\n"
    "2 4 2 7 1 1 2 3 4\n"
    "3 4 2 8 2 2 3 4 5\n$EndElements\n";

typedef struct bytes {
    unsigned char d[4096];
    size_t n;
} bytes;

static void b_raw(bytes *b, const void *p, size_t n)
{
    memcpy(b->d + b->n, p, n);
    b->n += n;
}
static void b_str(bytes *b, const char *s) { b_raw(b, s, strlen(s)); }
static void b_int(bytes *b, int32_t v)
{
    for (int i = 0; i < 4; i++)
        b->d[b->n++] = (unsigned char)((uint32_t)v >> (8 * i));
}
static void b_u64(bytes *b, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        b->d[b->n++] = (unsigned char)(v >> (8 * i));
}
static void b_dbl(bytes *b, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    b_u64(b, u);
}

static void b_entity(bytes *b, int tag, int phys)
{
    b_int(b, tag);
    for (int k = 0; k < 6; k++)
        b_dbl(b, k < 3 ? 0 : 1);
    b_u64(b, phys ? 1 : 0);
    if (phys)
        b_int(b, phys);
    b_u64(b, 1);
    b_int(b, 1); /* one bounding entity */
}

static void b_nodes(bytes *b, int dim, int tag, int first, int n,
                    const double *xyz)
{
    b_int(b, dim);
    b_int(b, tag);
    b_int(b, 0);
    b_u64(b, (uint64_t)n);
    for (int i = 0; i < n; i++)
        b_u64(b, (uint64_t)(first + i));
    for (int i = 0; i < 3 * n; i++)
        b_dbl(b, xyz[i]);
}

static void b_elems(bytes *b, int dim, int tag, int type, uint64_t id,
                    const uint64_t *nodes, int nv)
{
    b_int(b, dim);
    b_int(b, tag);
    b_int(b, type);
    b_u64(b, 1);
    b_u64(b, id);
    for (int k = 0; k < nv; k++)
        b_u64(b, nodes[k]);
}

/* The same mesh as ascii_seed, binary. */
static void binary_seed(bytes *b)
{
    static const double x3[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const double x4[] = {0, 0, 1}, x5[] = {1, 1, 1};
    static const uint64_t tri[] = {1, 2, 3}, t1[] = {1, 2, 3, 4},
                          t2[] = {2, 3, 4, 5};
    b->n = 0;
    b_str(b, "$MeshFormat\n4.1 1 8\n");
    b_int(b, 1);
    b_str(b, "\n$EndMeshFormat\n$PhysicalNames\n2\n3 7 \"a\"\n3 8 \"b\"\n"
             "$EndPhysicalNames\n$Entities\n");
    b_u64(b, 0);
    b_u64(b, 0);
    b_u64(b, 1);
    b_u64(b, 2);
    b_entity(b, 1, 0);
    b_entity(b, 1, 7);
    b_entity(b, 2, 8);
    b_str(b, "\n$EndEntities\n$Nodes\n");
    b_u64(b, 3);
    b_u64(b, 5);
    b_u64(b, 1);
    b_u64(b, 5);
    b_nodes(b, 2, 1, 1, 3, x3);
    b_nodes(b, 3, 1, 4, 1, x4);
    b_nodes(b, 3, 2, 5, 1, x5);
    b_str(b, "\n$EndNodes\n$Elements\n");
    b_u64(b, 3);
    b_u64(b, 3);
    b_u64(b, 1);
    b_u64(b, 3);
    b_elems(b, 2, 1, 2, 1, tri, 3);
    b_elems(b, 3, 1, 4, 2, t1, 4);
    b_elems(b, 3, 2, 4, 3, t2, 4);
    b_str(b, "\n$EndElements\n$NodeData\n1\n\"x\"\n");
    b_u64(b, 12345); /* binary payload */
    b_str(b, "\n$EndNodeData\n");
}

/* ascii22_seed in binary: int32 records after text count lines. */
static void binary22_seed(bytes *b)
{
    static const double x[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0,
                                 0, 0, 1, 1, 1, 1};
    b->n = 0;
    b_str(b, "$MeshFormat\n2.2 1 8\n");
    b_int(b, 1);
    b_str(b, "\n$EndMeshFormat\n$Nodes\n5\n");
    for (int i = 0; i < 5; i++) {
        b_int(b, i + 1);
        b_raw(b, x + 3 * i, 24);
    }
    b_str(b, "\n$EndNodes\n$Elements\n3\n");
    static const int32_t tri[] = {2, 1, 2, 1, 0, 1, 1, 2, 3};
    static const int32_t tets[] = {4, 2, 2, 2, 7, 1, 1, 2, 3, 4,
                                   3, 8, 2, 2, 3, 4, 5};
    b_raw(b, tri, sizeof tri);
    b_raw(b, tets, sizeof tets);
    b_str(b, "\n$EndElements\n");
}

static getme_formats_status open_file(getme_doc **doc, const char *name,
                                 int nfix, const char *const *fix)
{
    getme_doc_options o;
    getme_doc_options_init(&o);
    o.num_fix = nfix;
    o.fix = fix;
    return getme_doc_open(doc, tpath(name), &o);
}

/* ---- good files --------------------------------------------------------- */

/* moved: the ASCII line node 5 gets ("x y z" in 4.1, "tag x y z" in 2.2) */
static void check_seed(const char *name, const void *data, size_t n,
                       int binary, const char *moved)
{
    put_file(name, data, n);
    getme_doc *doc;
    getme_formats_status st = open_file(&doc, name, 0, NULL);
    CHECK_EQ_INT(st, GETME_FORMATS_OK);
    if (st != GETME_FORMATS_OK) {
        fprintf(stderr, "%s\n", getme_doc_error(doc));
        getme_doc_close(doc);
        return;
    }
    getme_mesh *m = getme_doc_mesh(doc);
    CHECK_EQ_INT(getme_mesh_num_elements(m), 2);
    CHECK_EQ_INT(getme_mesh_num_nodes(m), 5);
    CHECK_EQ_INT(getme_mesh_num_fixed(m), 5);
    CHECK_EQ_INT(getme_doc_element_id(doc, 0), 2);
    CHECK_EQ_INT(getme_doc_element_id(doc, 1), 3);
    CHECK(strstr(getme_doc_info(doc), "2 volumes") != NULL);
    /* move node 5 (mesh index 4: Gmsh order puts it last) and write */
    double xyz[15];
    getme_mesh_get_coords(m, xyz);
    CHECK(xyz[12] == 1 && xyz[13] == 1 && xyz[14] == 1);
    xyz[12] = 0.9;
    xyz[14] = 1.0 / 3.0;
    getme_mesh_set_coords(m, xyz);
    CHECK_EQ_INT(getme_doc_write(doc, tpath("out.msh")), GETME_FORMATS_OK);
    getme_doc_close(doc);
    static char out[8192];
    size_t no = get_file("out.msh", out, sizeof out);
    if (binary) {
        CHECK_EQ_INT(no, n);
        size_t diff = 0;
        for (size_t i = 0; i < n && i < no; i++)
            diff += ((const char *)data)[i] != out[i];
        CHECK(diff > 0 && diff <= 16);
    } else {
        CHECK(strstr(out, moved) != NULL);
        const char *tail = strstr(out, "$EndNodes");
        CHECK(tail && strcmp(tail, strstr((const char *)data, "$EndNodes")) == 0);
    }
    /* the output reads back with the new coordinates */
    CHECK_EQ_INT(open_file(&doc, "out.msh", 0, NULL), GETME_FORMATS_OK);
    if (getme_doc_mesh(doc)) {
        const double *x = getme_mesh_coords(getme_doc_mesh(doc));
        CHECK(x[12] == 0.9 && x[14] == 1.0 / 3.0);
    }
    getme_doc_close(doc);
}

/* ---- errors ------------------------------------------------------------- */

static void expect(const char *name, const void *data, size_t n,
                   getme_formats_status want, const char *text, int nfix,
                   const char *const *fix)
{
    put_file(name, data, n);
    getme_doc *doc;
    getme_formats_status st = open_file(&doc, name, nfix, fix);
    const char *msg = getme_doc_error(doc);
    CHECK_EQ_INT(st, want);
    CHECK(strstr(msg, tpath(name)) != NULL);
    CHECK(strchr(msg, '\n') == NULL);
    if (text && !strstr(msg, text)) {
        fprintf(stderr, "%s: want '%s' in '%s'\n", name, text, msg);
        CHECK(0);
    }
    getme_doc_close(doc);
}

static void replace(char *s, const char *from, const char *to)
{
    char *p = strstr(s, from);
    if (!p)
        return;
    memmove(p + strlen(to), p + strlen(from), strlen(p + strlen(from)) + 1);
    memcpy(p, to, strlen(to));
}

/* Every truncation before $EndElements fails as malformed (a cut inside
   the version number, "4." = 4.0, is unsupported by the native reader). */
static void truncations(const char *name, const void *data, size_t end,
                        int ascii)
{
    for (size_t k = 0; k < end; k++) {
        put_file(name, data, k);
        getme_doc *doc;
        getme_formats_status st = open_file(&doc, name, 0, NULL);
        const char *msg = getme_doc_error(doc);
        /* a cut between two sections leaves a valid file without a mesh */
        int empty = st == GETME_FORMATS_ERR_UNSUPPORTED &&
                    strstr(msg, "No volume or surface mesh") != NULL;
        CHECK(st == GETME_FORMATS_ERR_PARSE || empty ||
              (k < 20 && st == GETME_FORMATS_ERR_UNSUPPORTED));
        CHECK(strstr(msg, tpath(name)) != NULL && !strchr(msg, '\n'));
        CHECK(!ascii || empty || strstr(msg, "line ") != NULL);
        if (st != GETME_FORMATS_ERR_PARSE && k >= 20 && !empty)
            fprintf(stderr, "%s cut at %zu: %d %s\n", name, k, (int)st, msg);
        getme_doc_close(doc);
    }
}

static void check_errors(const bytes *bin)
{
    size_t na = strlen(ascii_seed);
    truncations("cut.msh", ascii_seed,
                (size_t)(strstr(ascii_seed, "$EndElements") - ascii_seed), 1);
    size_t end_b = 0;
    for (size_t i = 0; i + 12 < bin->n; i++)
        if (memcmp(bin->d + i, "$EndElements", 12) == 0)
            end_b = i;
    truncations("cutb.msh", bin->d, end_b, 0);
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", ascii_seed);
    replace(buf, "4.1 0 8", "4.1 0 x");
    expect("fmt.msh", buf, strlen(buf), GETME_FORMATS_ERR_PARSE, "line 2", 0,
           NULL);
    snprintf(buf, sizeof buf, "%s", ascii_seed);
    replace(buf, "3 2 3 4 5", "3 2 3 4 77");
    expect("missing.msh", buf, strlen(buf), GETME_FORMATS_ERR_PARSE,
           "line 38: element 3 uses node 77", 0, NULL);
    snprintf(buf, sizeof buf, "%s", ascii_seed);
    /* order 3 (second order is smoothed: tests/highorder) */
    replace(buf, "3 1 4 1\n2 1 2 3 4\n",
            "3 1 29 1\n2 1 2 3 4 1 2 3 4 1 2 3 4 1 2 3 4 1 2 3 4\n");
    expect("order3.msh", buf, strlen(buf), GETME_FORMATS_ERR_UNSUPPORTED,
           "Volume 1 has elements of order 3 (20-node tetrahedron)", 0,
           NULL);
    const char *fix[] = {"a", "nosuch"};
    expect("fix.msh", ascii_seed, na, GETME_FORMATS_ERR_ARGUMENT,
           "Unknown physical group 'nosuch' to fix (\"a\" (3:7), \"b\" (3:8))",
           2, fix);
    bytes b2 = *bin;
    b2.d[strlen("$MeshFormat\n4.1 1 ")] = '4';
    expect("size4.msh", b2.d, b2.n, GETME_FORMATS_ERR_UNSUPPORTED, "data size 4",
           0, NULL);
    snprintf(buf, sizeof buf, "%s", ascii_seed);
    replace(buf, "3 1 0 1\n4", "3 1 1 1\n4");
    expect("param.msh", buf, strlen(buf), GETME_FORMATS_ERR_UNSUPPORTED,
           "native", 0, NULL);
}

/* ---- fuzz --------------------------------------------------------------- */

static uint64_t rng = 0x2545f4914f6cdd1dULL;
static uint64_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

static const char *const tokens[] = {
    " ", "\n", "$", "$Nodes\n", "$EndNodes\n", "$Elements\n", "0", "-1",
    "18446744073709551615", "2147483648", "1e308", "nan", "4", "11", "\"",
    "$PhysicalNames\n1\n", "$Entities\n", "\r\n", "\0\0\0\0\0\0\0\x80",
    "\xff\xff\xff\xff", "3 1 0 1\n",
};

static size_t mutate(char *buf, size_t n, size_t cap)
{
    int rounds = 1 + (int)(next() % 3);
    for (int r = 0; r < rounds; r++) {
        size_t pos = n ? next() % (n + 1) : 0, len;
        switch (next() % 6) {
        case 0:
            if (n)
                buf[pos % n] = (char)(next() & 0xff);
            break;
        case 1: /* small integer change of a byte */
            if (n)
                buf[pos % n] = (char)(buf[pos % n] + (int)(next() % 5) - 2);
            break;
        case 2:
            len = next() % 16;
            len = pos + len > n ? n - pos : len;
            memmove(buf + pos, buf + pos + len, n - pos - len);
            n -= len;
            break;
        case 3:
            len = next() % 24;
            len = pos + len > n ? n - pos : len;
            if (n + len < cap) {
                memmove(buf + pos + len, buf + pos, n - pos);
                n += len;
            }
            break;
        case 4: {
            const char *t = tokens[next() % (sizeof tokens / sizeof *tokens)];
            len = t[0] ? strlen(t) : 8;
            if (n + len < cap) {
                memmove(buf + pos + len, buf + pos, n - pos);
                memcpy(buf + pos, t, len);
                n += len;
            }
            break;
        }
        default:
            if (next() % 4 == 0)
                n = pos;
        }
    }
    return n;
}

static void fuzz(const bytes *bin, const bytes *bin22, int iters)
{
    static char buf[8192];
    int opened = 0, failed = 0;
    for (int it = 0; it < iters; it++) {
        /* MSH 4.1 ASCII, 4.1 binary, 2.2 ASCII, 2.2 binary in turn */
        const char *seed = it % 4 == 0   ? ascii_seed
                           : it % 4 == 1 ? (const char *)bin->d
                           : it % 4 == 2 ? ascii22_seed
                                         : (const char *)bin22->d;
        size_t n = it % 4 == 0   ? strlen(ascii_seed)
                   : it % 4 == 1 ? bin->n
                   : it % 4 == 2 ? strlen(ascii22_seed)
                                 : bin22->n;
        memcpy(buf, seed, n);
        n = mutate(buf, n, sizeof buf);
        put_file("fuzz.msh", buf, n);
        const char *fix[] = {it % 3 ? "a" : "3:8"};
        getme_doc *doc;
        getme_formats_status st = open_file(&doc, "fuzz.msh", it % 5 == 0, fix);
        fuzz_outcome(doc, st, tpath("fuzz-out.msh"), it, &opened, &failed);
    }
    printf("fuzz: %d inputs, %d opened and written, %d refused with a "
           "message\n",
           iters, opened, failed);
    CHECK(opened > 0 && failed > 0);
}

int main(int argc, char **argv)
{
    int iters = argc > 1 ? atoi(argv[1]) : 4000;
    setenv("GETME_MSH_READER", "native", 1);
    snprintf(dir, sizeof dir, "msh41_test.%ld", (long)getpid());
    if (!mkdtemp(strcpy(dir, "/tmp/msh41_test.XXXXXX")))
        return 1;
    static bytes bin, bin22;
    binary_seed(&bin);
    binary22_seed(&bin22);
    static const char moved41[] = "\n0.9 1 0.3333333333333333\n";
    static const char moved22[] = "\n5 0.9 1 0.3333333333333333\n";
    check_seed("seed-ascii.msh", ascii_seed, strlen(ascii_seed), 0, moved41);
    check_seed("seed-bin.msh", bin.d, bin.n, 1, NULL);
    check_seed("seed-22a.msh", ascii22_seed, strlen(ascii22_seed), 0, moved22);
    check_seed("seed-22b.msh", bin22.d, bin22.n, 1, NULL);
    check_errors(&bin);
    fuzz(&bin, &bin22, iters);
    static const char *const names[] = {
        "seed-ascii.msh", "seed-bin.msh", "seed-22a.msh", "seed-22b.msh",
        "out.msh", "cut.msh", "cutb.msh",
        "fmt.msh", "missing.msh", "order2.msh", "fix.msh", "size4.msh",
        "param.msh", "fuzz.msh", "fuzz-out.msh"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++)
        remove(tpath(names[i]));
    if (rmdir(dir) != 0)
        fprintf(stderr, "note: %s not empty\n", dir);
    return check_summary("test_msh41");
}
