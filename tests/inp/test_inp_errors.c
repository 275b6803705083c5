/*
 * test_inp_errors.c -- every malformed deck gives one clear message with
 * the file and line, the expected status, and leaves nothing behind.
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"
#include "inp_test_util.h"

#define TET_NODES "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n"

typedef struct bad_case {
    const char *deck;
    getme_formats_status status;
    const char *fragment; /* expected in the message */
} bad_case;

static const bad_case cases[] = {
    {"", GETME_FORMATS_ERR_PARSE, "no *NODE data"},
    {"*HEADING\nempty\n", GETME_FORMATS_ERR_PARSE, "no *NODE data"},
    /* data before the first keyword is ignored (as CalculiX does), so a
       file that is not a deck ends without *NODE data */
    {"hello world\n", GETME_FORMATS_ERR_PARSE, "bad.inp: no *NODE data"},
    {TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 9\n", GETME_FORMATS_ERR_PARSE,
     "bad.inp:7: element 1 (C3D4) references undefined node 9"},
    {TET_NODES "3, 5, 5, 5\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n",
     GETME_FORMATS_ERR_PARSE, "bad.inp:6: node 3 defined twice (first at "},
    {TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n1, 1, 2, 3, 4\n",
     GETME_FORMATS_ERR_PARSE, "bad.inp:8: element 1 defined twice"},
    {TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3\n", GETME_FORMATS_ERR_PARSE,
     "bad.inp:7: element 1 of type C3D4 has 3 nodes, C3D4 needs 4"},
    {TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2,\n", GETME_FORMATS_ERR_PARSE,
     "file ends inside element 1"},
    {TET_NODES "*ELEMENT, TYPE=C3D13\n1, 1, 2, 3, 4, 1, 2, 3, 4, 1, 2, 3, 4, 1\n",
     GETME_FORMATS_ERR_UNSUPPORTED, "bad.inp:6: element type C3D13 is second order (13 nodes), a pyramid "
                                     "that Abaqus and CalculiX do not define"},
    /* CPS8 is read (second order, tests/highorder); a repeated node is not */
    {TET_NODES "*ELEMENT, TYPE=CPS8\n1, 1, 2, 3, 1, 2, 3, 1, 2\n",
     GETME_FORMATS_ERR_INVALID, "bad.inp:7: element 1 is degenerate: node 1 appears twice"},
    {TET_NODES "*ELEMENT, TYPE=B31\n1, 1, 2\n", GETME_FORMATS_ERR_UNSUPPORTED,
     "no linear solid"},
    {"*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 1\n*ELEMENT, TYPE=CPS3\n"
     "1, 1, 2, 3\n",
     GETME_FORMATS_ERR_UNSUPPORTED, "not in the plane"},
    {"*NODE\n1, 0, 0, 0\n2, 1x, 0, 0\n", GETME_FORMATS_ERR_PARSE,
     "bad.inp:3: node 2: bad coordinate '1x'"},
    {"*NODE\n1, 0, 0, nan\n", GETME_FORMATS_ERR_PARSE, "bad coordinate 'nan'"},
    {"*NODE\n-4, 0, 0, 0\n", GETME_FORMATS_ERR_PARSE, "bad node number '-4'"},
    {"*NODE\n99999999999, 0, 0, 0\n", GETME_FORMATS_ERR_PARSE, "bad node number"},
    {TET_NODES "*ELEMENT\n1, 1, 2, 3, 4\n", GETME_FORMATS_ERR_PARSE,
     "bad.inp:6: *ELEMENT without TYPE="},
    {TET_NODES "*INCLUDE, INPUT=missing.inp\n", GETME_FORMATS_ERR_OPEN,
     "bad.inp:6: cannot open *INCLUDE file"},
    {TET_NODES "*INCLUDE, INPUT=bad.inp\n", GETME_FORMATS_ERR_PARSE,
     "*INCLUDE cycle"},
    {TET_NODES "*NSET, NSET=A\n1, Nope\n", GETME_FORMATS_ERR_PARSE,
     "bad.inp:7: unknown node set 'Nope'"},
    {TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*NSET, NSET=A, GENERATE\n"
     "5, 1\n",
     GETME_FORMATS_ERR_PARSE, "bad.inp:9: GENERATE needs"},
    {TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n"
     "*SOLID SECTION, ELSET=Nope, MATERIAL=M\n",
     GETME_FORMATS_ERR_PARSE, "bad.inp:8: *SOLID SECTION refers to unknown element "
                         "set 'Nope'"},
    {"*SYSTEM\n0, 0, 0\n" TET_NODES, GETME_FORMATS_ERR_UNSUPPORTED,
     "bad.inp:1: *SYSTEM is not supported"},
    {"*NODE, SYSTEM=C\n1, 1, 0, 0\n", GETME_FORMATS_ERR_UNSUPPORTED, "SYSTEM=C"},
    {TET_NODES "*NGEN\n1, 4\n", GETME_FORMATS_ERR_UNSUPPORTED, "*NGEN is not"},
    {"*INSTANCE, NAME=I, PART=Ghost\n", GETME_FORMATS_ERR_PARSE,
     "unknown part 'Ghost'"},
    {"*PART, NAME=P\n*END PART\n*PART, NAME=p\n", GETME_FORMATS_ERR_PARSE,
     "bad.inp:3: part 'p' defined twice"},
    /* inverted tet: the adapter reads it, doc.c refuses it by element id */
    {"*NODE\n1, 0, 0, 0\n2, 0, 1, 0\n3, 1, 0, 0\n4, 0, 0, 1\n"
     "*ELEMENT, TYPE=C3D4\n77, 1, 2, 3, 4\n",
     GETME_FORMATS_ERR_INVALID, "first: 77"},
};

static void test_cases(void)
{
    int n = (int)(sizeof cases / sizeof cases[0]);
    for (int i = 0; i < n; i++) {
        put_text("bad.inp", cases[i].deck);
        getme_doc *doc;
        getme_formats_status st = open_deck(&doc, "bad.inp", 1, 0, NULL);
        const char *msg = getme_doc_error(doc);
        if (st != cases[i].status || !strstr(msg, cases[i].fragment))
            fprintf(stderr, "case %d: status %d, message '%s'\n", i, (int)st,
                    msg);
        CHECK_EQ_INT(st, cases[i].status);
        CHECK(strstr(msg, cases[i].fragment) != NULL);
        CHECK(strchr(msg, '\n') == NULL); /* one line */
        getme_doc_close(doc);
    }
}

/* More node ids on an element line than the type has: CalculiX reads the
   first ones, so do we, with a warning naming file and line. */
static void test_extra_ids(void)
{
    put_text("extra.inp", TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4, 1\n");
    getme_doc *doc;
    CHECK_EQ_INT(open_deck(&doc, "extra.inp", 1, 0, NULL), GETME_FORMATS_OK);
    CHECK(strstr(getme_doc_warning(doc), "extra.inp:7: element 1 has more "
                                         "node ids than its type needs") != NULL);
    CHECK_EQ_INT(getme_mesh_num_elements(getme_doc_mesh(doc)), 1);
    getme_doc_close(doc);
    put_text("extra.inp", TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n");
    CHECK_EQ_INT(open_deck(&doc, "extra.inp", 1, 0, NULL), GETME_FORMATS_OK);
    CHECK_EQ_INT((int)strlen(getme_doc_warning(doc)), 0);
    getme_doc_close(doc);
}

static void test_missing_file(void)
{
    getme_doc *doc;
    CHECK_EQ_INT(open_deck(&doc, "no-such.inp", 1, 0, NULL), GETME_FORMATS_ERR_OPEN);
    CHECK(strstr(getme_doc_error(doc), "no-such.inp") != NULL);
    getme_doc_close(doc);
}

/* The input changes between open and write: refuse, write nothing. */
static void test_changed_input(void)
{
    put_text("ok.inp", TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n");
    getme_doc *doc;
    CHECK_EQ_INT(open_deck(&doc, "ok.inp", 1, 0, NULL), GETME_FORMATS_OK);
    put_text("ok.inp", TET_NODES "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n** x\n");
    CHECK_EQ_INT(getme_doc_write(doc, tpath("ok-out.inp")), GETME_FORMATS_ERR_WRITE);
    CHECK(strstr(getme_doc_error(doc), "changed since it was read") != NULL);
    CHECK(access(tpath("ok-out.inp"), F_OK) != 0);
    getme_doc_close(doc);
    /* an output directory that does not exist */
    CHECK_EQ_INT(open_deck(&doc, "ok.inp", 1, 0, NULL), GETME_FORMATS_OK);
    CHECK_EQ_INT(getme_doc_write(doc, tpath("nodir/x.inp")), GETME_FORMATS_ERR_WRITE);
    getme_doc_close(doc);
}

int main(void)
{
    scratch_init("inp_errors");
    test_cases();
    test_missing_file();
    test_extra_ids();
    test_changed_input();
    scratch_done(check_failed_ == 0);
    return check_summary("test_inp_errors");
}
