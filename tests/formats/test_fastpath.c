/*
 * test_fastpath.c -- the ASCII fast paths (formats/linepar.c, MSH
 * msh41_fast.c, INP inp_fast.c) against the readers' own line and token
 * paths, on meshes large enough for runs to be split across threads
 * (82,944 tets: megabytes of element lines, runs of up to 8 MiB):
 *  - property (INP also with a *NSET of every third node, fixed by name):
 *    a file whose lines are randomly reshaped (blanks, tabs,
 *    CRLF, '+' signs, exponents, records split over two lines or joined,
 *    blank and comment lines; each such line is refused by the fast path
 *    and read by the token / line reader) gives exactly the mesh of the
 *    plain file, for 1, 2, 3 and 7 threads, with one line in 8, 500 or
 *    20000 reshaped (so the places where the fast path stops and resumes,
 *    and so the pieces the threads get, move around);
 *  - writing (INP): decks plain and reshaped, every other node moved,
 *    written with 1, 2, 3 and 7 threads (the node lines are rewritten in
 *    pieces on several threads): the same bytes, the moved coordinates
 *    read back (to Abaqus' 20 characters), every other line kept byte for
 *    byte;
 *  - damage: one or two bad records at random lines give one error, the
 *    same text for every thread count, naming the file and the first bad
 *    line in file order (INP: bad numbers, and elements naming nodes that
 *    are not in *NODE, which the build looks up in parallel).
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"

#include "doc_read.h"
#include "kuhn_cube.h"
#include "getme_formats.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- writing the files, with reshaped and damaged lines ----------------- */

enum { PLAIN, RESHAPE, DAMAGE };

typedef struct out {
    FILE *f;
    int mode;
    long line;         /* lines written so far                          */
    long bad_line[2];  /* lines damaged (mode DAMAGE), in file order      */
    int nbad;
    long damage_at[2]; /* record numbers to damage                       */
    uint32_t one_in;   /* RESHAPE: one line in this many                  */
    int undefined;     /* DAMAGE of INP elements: a node id not in *NODE
                          (read, then refused by the build) instead of 0
                          (refused by the line reader)                    */
} out;

static void put_line(out *o, const char *s)
{
    fputs(s, o->f);
    fputc('\n', o->f);
    o->line++;
}

/* A record's line: reshaped now and then (every shape is one that the
   fast path refuses or that still holds one record per line).  split:
   the record may go over two lines; join: the next record may follow on
   the same line (MSH tags and elements: the token reader reads them). */
static void put_record(out *o, const char *tok[], int ntok, int msh,
                       int split, int join)
{
    char line[1024];
    size_t n = 0;
    int shape = o->mode == RESHAPE && rnd() % o->one_in == 0
                    ? 1 + (int)(rnd() % 7)
                    : 0;
    if ((shape == 3 && !split) || (shape == 7 && !join))
        shape = 0;
    if (shape == 7) {
        for (int t = 0; t < ntok; t++)
            fprintf(o->f, "%s ", tok[t]);
        return;
    }
    if (shape == 5) { /* a blank line (INP: a comment) before it */
        put_line(o, msh ? "" : "** a comment");
        shape = 0;
    }
    for (int t = 0; t < ntok; t++) {
        const char *sep = t == 0 ? "" : msh ? " " : ", ";
        if (shape == 1)
            sep = t == 0 ? "  " : msh ? " \t " : " ,\t";
        if (shape == 3 && t == ntok / 2 && ntok > 1) /* split over 2 lines */
            sep = msh ? "\n" : ",\n";
        n += (size_t)snprintf(line + n, sizeof line - n, "%s%s%s", sep,
                              shape == 4 && t == 0 ? "+" : "", tok[t]);
    }
    if (shape == 2)
        n += (size_t)snprintf(line + n, sizeof line - n, "\r");
    if (shape == 6)
        n += (size_t)snprintf(line + n, sizeof line - n, msh ? "  " : " ");
    o->line += shape == 3 && ntok > 1;
    put_line(o, line);
}

/* Record r of the file: damage it if asked to. */
static int damaged(out *o, long r)
{
    for (int k = 0; k < 2; k++)
        if (o->mode == DAMAGE && o->damage_at[k] == r) {
            o->bad_line[o->nbad++] = o->line + 1;
            return 1;
        }
    return 0;
}

static void real_text(char *buf, double v)
{
    /* %.17g, or an exponent form of the same value */
    snprintf(buf, 40, rnd() % 16 == 0 ? "%.17e" : "%.17g", v);
}

/* Element e's tokens: its number and its four node numbers. */
static void element_tokens(int e, char tbuf[5][40], const char *tok[5])
{
    snprintf(tbuf[0], 40, "%d", e + 1);
    for (int k = 0; k < 4; k++)
        snprintf(tbuf[k + 1], 40, "%d", tet[e][k] + 1);
    for (int k = 0; k < 5; k++)
        tok[k] = tbuf[k];
}

static void start_file(const char *path, out *o)
{
    o->f = fopen(path, "wb");
    o->line = 0;
    o->nbad = 0;
}

static void write_msh(const char *path, out *o)
{
    char tbuf[5][40];
    const char *tok[5];
    start_file(path, o);
    put_line(o, "$MeshFormat\n4.1 0 8\n$EndMeshFormat");
    put_line(o, "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities");
    o->line += 5;
    fprintf(o->f, "$Nodes\n1 %d 1 %d\n3 1 0 %d\n", NN, NN, NN);
    o->line += 3;
    long rec = 0;
    for (int i = 0; i < NN; i++, rec++) {
        snprintf(tbuf[0], sizeof tbuf[0], "%d", i + 1);
        tok[0] = tbuf[0];
        if (damaged(o, rec))
            tok[0] = "7x";
        put_record(o, tok, 1, 1, 0, i + 1 < NN);
    }
    for (int i = 0; i < NN; i++, rec++) {
        for (int k = 0; k < 3; k++) {
            real_text(tbuf[k], xyz[3 * i + k]);
            tok[k] = tbuf[k];
        }
        if (damaged(o, rec))
            tok[1] = "0.5q";
        put_record(o, tok, 3, 1, 1, 0);
    }
    put_line(o, "$EndNodes");
    fprintf(o->f, "$Elements\n1 %d 1 %d\n3 1 4 %d\n", NE, NE, NE);
    o->line += 3;
    for (int e = 0; e < NE; e++, rec++) {
        element_tokens(e, tbuf, tok);
        if (damaged(o, rec))
            tok[3] = "999999";
        put_record(o, tok, 5, 1, 1, e + 1 < NE);
    }
    put_line(o, "$EndElements");
    fclose(o->f);
}

static void write_inp(const char *path, out *o)
{
    char tbuf[5][40];
    const char *tok[5];
    start_file(path, o);
    put_line(o, "*HEADING\nfast path test\n*NODE");
    o->line += 2;
    long rec = 0;
    for (int i = 0; i < NN; i++, rec++) {
        snprintf(tbuf[0], sizeof tbuf[0], "%d", i + 1);
        for (int k = 0; k < 3; k++) {
            real_text(tbuf[k + 1], xyz[3 * i + k]);
            tok[k + 1] = tbuf[k + 1];
        }
        tok[0] = tbuf[0];
        if (damaged(o, rec))
            tok[2] = "abc";
        put_record(o, tok, 4, 0, 0, 0);
    }
    put_line(o, "*ELEMENT, TYPE=C3D4, ELSET=Block");
    for (int e = 0; e < NE; e++, rec++) {
        element_tokens(e, tbuf, tok);
        char undef[40];
        snprintf(undef, sizeof undef, "%d", NN + 1 + e % 1000);
        if (damaged(o, rec))
            tok[2] = o->undefined ? undef : "0";
        put_record(o, tok, 5, 0, 1, 0);
    }
    /* every third node pinned, listed 12 times (a set may repeat ids:
       over 256 KiB of lines, so runs split across threads), 16 ids a line
       (every third line with a trailing comma, as Abaqus and Gmsh write
       them), reshaped as above; the last line shorter */
    put_line(o, "*NSET, NSET=Pinned");
    char ib[16][24];
    const char *it[16];
    int n = 0;
    long setline = 0;
    for (long k = 0; k < 12L * ((NN + 2) / 3); k++) {
        int i = 1 + 3 * (int)(k % ((NN + 2) / 3));
        snprintf(ib[n], sizeof ib[n], "%d", i);
        it[n] = ib[n];
        n++;
        if (n == 16 || k + 1 == 12L * ((NN + 2) / 3)) {
            if (setline++ % 3 == 0)
                strcat(ib[n - 1], ",");
            put_record(o, it, n, 0, 1, 0);
            n = 0;
        }
    }
    put_line(o, "*SOLID SECTION, ELSET=Block, MATERIAL=Steel\n,");
    fclose(o->f);
}

/* ---- reading -------------------------------------------------------------- */

static const int THREADS[] = {1, 2, 3, 7};
#define NT ((int)(sizeof THREADS / sizeof *THREADS))

static void run_format(int msh)
{
    const char *name = msh ? "fast.msh" : "fast.inp";
    const char *fix = msh ? NULL : "Pinned"; /* INP: the *NSET's nodes */
    out o;
    memset(&o, 0, sizeof o);
    o.mode = PLAIN;
    (msh ? write_msh : write_inp)(name, &o);
    doc_read plain = doc_read_file_fix(name, 1, fix);
    CHECK(plain.st == GETME_FORMATS_OK);
    CHECK_EQ_INT(plain.nn, NN);
    CHECK_EQ_INT(plain.ne, NE);
    /* the plain file is the mesh that was written */
    int exact = plain.st == GETME_FORMATS_OK && plain.nn == NN;
    for (int i = 0; exact && i < 3 * NN; i++)
        exact = plain.x[i] == xyz[i];
    CHECK(exact);
    /* INP: the set's nodes are fixed */
    int pinned = plain.st == GETME_FORMATS_OK && plain.nn == NN;
    for (int i = 0; !msh && pinned && i < NN; i += 3)
        pinned = plain.fixed[i] != 0;
    CHECK(pinned);
    for (int t = 1; t < NT; t++) {
        doc_read r = doc_read_file_fix(name, THREADS[t], fix);
        CHECK(doc_read_same(&plain, &r));
        doc_read_free(&r);
    }
    /* few reshaped lines: long runs, split across threads; many: the
       fast path stops and resumes every few lines */
    static const uint32_t one_in[] = {8, 500, 20000};
    for (int seed = 1; seed <= 3; seed++) {
        rng_state = 1000 + (uint64_t)seed + 100 * (uint64_t)msh;
        o.mode = RESHAPE;
        o.one_in = one_in[seed - 1];
        (msh ? write_msh : write_inp)(name, &o);
        for (int t = 0; t < NT; t++) {
            doc_read r = doc_read_file_fix(name, THREADS[t], fix);
            CHECK(doc_read_same(&plain, &r));
            if (r.st != GETME_FORMATS_OK)
                fprintf(stderr, "reshaped %s seed %d: %s\n", name, seed,
                        r.error);
            doc_read_free(&r);
        }
    }
    long nrec = msh ? 2L * NN + NE : (long)NN + NE;
    for (int seed = 1; seed <= 6; seed++) {
        rng_state = 2000 + (uint64_t)seed + 100 * (uint64_t)msh;
        o.mode = DAMAGE;
        /* INP, seeds 4-6: elements name missing nodes, which the build
           finds (in parallel: the first one in file order is named) */
        o.undefined = !msh && seed > 3;
        o.damage_at[0] = (long)(rnd() % (uint32_t)nrec);
        o.damage_at[1] = seed % 2 ? (long)(rnd() % (uint32_t)nrec) : -1;
        (msh ? write_msh : write_inp)(name, &o);
        long first = o.bad_line[0];
        for (int k = 1; k < o.nbad; k++)
            if (o.bad_line[k] < first)
                first = o.bad_line[k];
        char want[600];
        if (msh)
            snprintf(want, sizeof want, "'%s', line %ld: ", name,
                     first);
        else
            snprintf(want, sizeof want, "%s:%ld: ", name, first);
        char first_error[1024] = "";
        for (int t = 0; t < NT; t++) {
            doc_read r = doc_read_file_fix(name, THREADS[t], fix);
            CHECK(r.st != GETME_FORMATS_OK);
            CHECK(strstr(r.error, want) == r.error);
            if (t == 0)
                snprintf(first_error, sizeof first_error, "%s", r.error);
            CHECK(strcmp(r.error, first_error) == 0);
            if (strstr(r.error, want) != r.error)
                fprintf(stderr, "%s seed %d, %d threads: %s (want '%s')\n",
                        name, seed, THREADS[t], r.error, want);
            doc_read_free(&r);
        }
    }
    doc_read_free(&plain);
}

/* ---- writing INP node lines ------------------------------------------- */

static char *slurp(const char *path, long *size)
{
    FILE *f = fopen(path, "rb");
    char *b = NULL;
    *size = 0;
    if (f && fseek(f, 0, SEEK_END) == 0 && (*size = ftell(f)) >= 0) {
        rewind(f);
        b = malloc((size_t)*size + 1);
        if (b && fread(b, 1, (size_t)*size, f) != (size_t)*size) {
            free(b);
            b = NULL;
        }
        if (b)
            b[*size] = '\0';
    }
    if (f)
        fclose(f);
    return b;
}

/* Node i's new position: two in three nodes move (some in one coordinate
   only, by amounts whose text is long), the others stay. */
static void moved_xyz(const double *x, int32_t nn, double *y)
{
    for (int32_t i = 0; i < nn; i++)
        for (int k = 0; k < 3; k++)
            y[3 * i + k] = x[3 * i + k] +
                           (i % 3 == 0 ? 0.0
                            : i % 3 == 1 && k != 1 ? 0.0
                                                   : 1e-3 / (1 + i % 7 + k));
}

/* The reshaped INP decks written with moved nodes (the writer's node lines
   run in pieces on several threads): the same bytes for every thread
   count; read back, exactly the moved coordinates; every line but the
   moved nodes' the input's, byte for byte. */
static void write_format(void)
{
    const char *name = "fastw.inp";
    out o;
    memset(&o, 0, sizeof o);
    static const uint32_t one_in[] = {0, 8, 500};
    for (int seed = 0; seed < 3; seed++) {
        rng_state = 3000 + (uint64_t)seed;
        o.mode = seed ? RESHAPE : PLAIN;
        o.one_in = one_in[seed];
        write_inp(name, &o);
        long in_size;
        char *in_text = slurp(name, &in_size);
        char *first = NULL;
        long first_size = 0;
        for (int t = 0; t < NT; t++) {
            getme_doc_options opt;
            getme_doc_options_init(&opt);
            opt.num_threads = THREADS[t];
            getme_doc *doc = NULL;
            CHECK(getme_doc_open(&doc, name, &opt) == GETME_FORMATS_OK);
            getme_mesh *m = doc ? getme_doc_mesh(doc) : NULL;
            int32_t nn = m ? getme_mesh_num_nodes(m) : 0;
            CHECK_EQ_INT(nn, NN);
            double *x = malloc(3 * (size_t)NN * sizeof *x);
            double *y = malloc(3 * (size_t)NN * sizeof *y);
            if (m && nn == NN) {
                getme_mesh_get_coords(m, x);
                moved_xyz(x, NN, y);
                CHECK(getme_mesh_set_coords(m, y) == GETME_OK);
                CHECK(getme_doc_write(doc, "fastw-out.inp") == GETME_FORMATS_OK);
            }
            getme_doc_close(doc);
            long size;
            char *text = slurp("fastw-out.inp", &size);
            CHECK(text != NULL);
            if (t == 0) {
                first = text;
                first_size = size;
                /* read back: the moved coordinates (to the digits that
                   Abaqus' 20-character fields hold: 0.000333333333333333
                   for 0.00033333333333333332), the others exactly */
                doc_read r = doc_read_file("fastw-out.inp", 1);
                int ok = r.st == GETME_FORMATS_OK && r.nn == NN;
                for (int i = 0; ok && i < 3 * NN; i++) {
                    ok = (i / 3) % 3 == 0 ? r.x[i] == y[i]
                                          : fabs(r.x[i] - y[i]) <=
                                                1e-15 * (1 + fabs(y[i]));
                    if (!ok)
                        fprintf(stderr, "node %d: %.17g read back as %.17g\n",
                                i / 3 + 1, y[i], r.x[i]);
                }
                CHECK(ok);
                doc_read_free(&r);
                /* line by line: only moved nodes' lines differ, and keep
                   their node number */
                char *a = in_text, *b = text;
                long differ = 0, bad = 0;
                while (a && b && *a && *b) {
                    char *ea = strchr(a, '\n'), *eb = strchr(b, '\n');
                    if (!ea || !eb)
                        break;
                    size_t la = (size_t)(ea - a), lb = (size_t)(eb - b);
                    if (la != lb || memcmp(a, b, la) != 0) {
                        differ++;
                        long ida = strtol(a, NULL, 10), idb = strtol(b, NULL, 10);
                        bad += ida != idb || ida < 1 || (ida - 1) % 3 == 0;
                    }
                    a = ea + 1;
                    b = eb + 1;
                }
                CHECK(a && b && strcmp(a, b) == 0); /* the same last bytes */
                CHECK_EQ_INT(bad, 0);
                CHECK_EQ_INT(differ, NN - (NN + 2) / 3);
            } else {
                CHECK(text && size == first_size &&
                      memcmp(text, first, (size_t)size) == 0);
                free(text);
            }
            free(x);
            free(y);
        }
        free(first);
        free(in_text);
    }
}

int main(void)
{
    /* the files go to a folder of their own, named in the messages */
    char dir[64], cmd[128];
    snprintf(dir, sizeof dir, "fastpath-%ld", (long)getpid());
    snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
    if (system(cmd) != 0 || chdir(dir) != 0)
        return 1;
    make_mesh(7);
    run_format(1);
    run_format(0);
    write_format();
    snprintf(cmd, sizeof cmd, "cd .. && rm -rf %s", dir);
    if (system(cmd) != 0)
        return 1;
    return check_summary("test_fastpath");
}
