/*
 * test_inp_fuzz.c -- deterministic mutation fuzzing of the INP reader and
 * writer (runs under ASan+UBSan in CI).  Seed decks cover every keyword the
 * adapter handles; each of a few thousand mutants (byte flips, deleted or
 * duplicated spans, inserted tokens, truncation) must either open with a
 * mesh and write back, or fail with a status and a one-line message.
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"
#include "fuzz_check.h"
#include "inp_test_util.h"

static const char *const seeds[] = {
    "*HEADING\ntitle\n*NODE, NSET=All\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n"
    "4, 0, 1, 0\n5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n"
    "9, 0.5, 0.5, 2\n*ELEMENT, TYPE=C3D8R, ELSET=Hex\n1, 1, 2, 3, 4,\n"
    " 5, 6, 7, 8\n*ELEMENT, TYPE=C3D5, ELSET=Pyr\n2, 5, 6, 7, 8, 9\n"
    "*ELSET, ELSET=Both\nHex, Pyr\n*NSET, NSET=G, GENERATE\n1, 9, 2\n"
    "*SOLID SECTION, ELSET=Hex, MATERIAL=M\n,\n*SOLID SECTION, ELSET=Pyr, "
    "MATERIAL=M\n*MATERIAL, NAME=M\n*ELASTIC\n1e5, 0.3\n",
    "*Part, name=P\n*Node\n10, 0., 0., 0.\n20, 1., 0., 0.\n30, 0., 1., 0.\n"
    "40, 0., 0., 1.\n50, 1., 1., 1.\n*Element, type=C3D4, elset=T\n"
    "1, 10, 20, 30, 40\n2, 20, 30, 40, 50\n*Element, type=S3\n3, 10, 20, 30\n"
    "*End Part\n*Assembly, name=A\n*Instance, name=I, part=P\n1., 2., 3.\n"
    "*End Instance\n*Nset, nset=N, instance=I\n10, 50\n*Elset, elset=E, "
    "instance=I\n1\n*End Assembly\n",
    "*NODE\r\n1, 0, 0\r\n2, 1, 0\r\n3, 1, 1\r\n4, 0, 1\r\n5, 2, 0\r\n"
    "6, 2, 1\r\n*ELEMENT, TYPE=CPS4\r\n1, 1, 2, 3, 4\r\n*ELEMENT, TYPE=CPE3\r\n"
    "2, 2, 5, 6\r\n3, 2, 6, 3\r\n*ELEMENT, TYPE=T2D2\r\n4, 1, 4\r\n",
};

static uint64_t rng = 0x9e3779b97f4a7c15ULL;
static uint64_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

static const char *const tokens[] = {
    ",", "*", "**", "\n", "\r\n", "\r", "0", "-1", "99999999999", "1e308",
    "1D3", "nan", ".", "=", "\"", "*NODE\n", "*ELEMENT, TYPE=C3D8\n",
    "*ELEMENT, TYPE=C3D10\n", "*INCLUDE, INPUT=fuzz.inp\n", "*NSET, NSET=All\n",
    "*ELSET, ELSET=Both, GENERATE\n", "*END PART\n", "*INSTANCE, NAME=J, PART=P\n",
    "All", "Hex", ",\n", "\t", "\0", "2147483647", "*SYSTEM\n",
};

static size_t mutate(char *buf, size_t n, size_t cap)
{
    int rounds = 1 + (int)(next() % 4);
    for (int r = 0; r < rounds; r++) {
        size_t pos = n ? next() % (n + 1) : 0;
        switch (next() % 6) {
        case 0: /* flip a byte */
            if (n)
                buf[pos % n] = (char)(next() & 0xff);
            break;
        case 1: { /* delete a span */
            size_t len = next() % 16;
            if (pos + len > n)
                len = n - pos;
            memmove(buf + pos, buf + pos + len, n - pos - len);
            n -= len;
            break;
        }
        case 2: { /* duplicate a span */
            size_t len = next() % 40;
            if (pos + len > n)
                len = n - pos;
            if (n + len < cap) {
                memmove(buf + pos + len, buf + pos, n - pos);
                n += len;
            }
            break;
        }
        case 3: case 4: { /* insert a token */
            const char *t = tokens[next() % (sizeof tokens / sizeof *tokens)];
            size_t len = t[0] ? strlen(t) : 1;
            if (n + len < cap) {
                memmove(buf + pos + len, buf + pos, n - pos);
                memcpy(buf + pos, t, len);
                n += len;
            }
            break;
        }
        default: /* truncate */
            n = pos;
        }
    }
    return n;
}

int main(int argc, char **argv)
{
    int iters = argc > 1 ? atoi(argv[1]) : 3000;
    scratch_init("inp_fuzz");
    static char buf[8192];
    int opened = 0, failed = 0;
    int nseeds = (int)(sizeof seeds / sizeof *seeds);
    for (int it = 0; it < iters; it++) {
        const char *seed = seeds[it % nseeds];
        size_t n = strlen(seed);
        memcpy(buf, seed, n);
        n = mutate(buf, n, sizeof buf);
        put_file("fuzz.inp", buf, n);
        const char *fix[] = {"All"};
        getme_doc *doc;
        getme_formats_status st = open_deck(&doc, "fuzz.inp", (int)(it & 1),
                                       (int)(it % 3 == 0), fix);
        fuzz_outcome(doc, st, tpath("fuzz-out.inp"), it, &opened, &failed);
    }
    printf("fuzz: %d inputs, %d opened and written, %d refused with a "
           "message\n", iters, opened, failed);
    CHECK(opened > 0 && failed > 0);
    scratch_done(check_failed_ == 0);
    return check_summary("test_inp_fuzz");
}
