/*
 * cgns_tool.c -- test driver for the python-hosted CGNS tests (not the
 * CLI, so that these tests depend on the adapter only):
 *   cgns_tool dump IN              counts, then "q <CGNS element number>
 *                                  <quality>" per element, then the info line
 *   cgns_tool smooth IN OUT [--fix NAME]... [--free NAME]...
 *   cgns_tool fixture OUT          the meshio-style tet file (Base/Zone1/
 *                                  GridElements), interior jittered
 * Errors: one "Error   : ..." line on stderr, exit status = the getme
 * command's exit code for the status (3 open, 4 parse, 2 argument...).
 */
#include "cgns_fixture.h"
#include "getme_formats.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(getme_doc *doc, getme_formats_status st)
{
    /* the CLI's exit codes (cli/exit.c), which the tests know */
    static const int code[] = {
        [GETME_FORMATS_OK] = 0,          [GETME_FORMATS_ERR_OPEN] = 3,
        [GETME_FORMATS_ERR_PARSE] = 4,   [GETME_FORMATS_ERR_UNSUPPORTED] = 5,
        [GETME_FORMATS_ERR_INVALID] = 6, [GETME_FORMATS_ERR_WRITE] = 7,
        [GETME_FORMATS_ERR_ARGUMENT] = 2, [GETME_FORMATS_ERR_INTERNAL] = 1};
    fprintf(stderr, "Error   : %s\n", getme_doc_error(doc));
    getme_doc_close(doc);
    return (unsigned)st < sizeof code / sizeof *code ? code[st] : 1;
}

static int dump(const char *in)
{
    getme_doc *doc;
    getme_formats_status st = getme_doc_open(&doc, in, NULL);
    if (st != GETME_FORMATS_OK)
        return fail(doc, st);
    getme_mesh *m = getme_doc_mesh(doc);
    int32_t ne = getme_mesh_num_elements(m);
    double *q = malloc((size_t)ne * sizeof *q);
    getme_mesh_element_qualities(m, q);
    printf("nodes %d elements %d fixed %d\n", getme_mesh_num_nodes(m), ne,
           getme_mesh_num_fixed(m));
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        printf("type %s %d\n", getme_type_name((getme_elem_type)t),
               getme_mesh_num_elements_of_type(m, (getme_elem_type)t));
    for (int32_t e = 0; e < ne; e++)
        printf("q %lld %.17g\n", (long long)getme_doc_element_id(doc, e), q[e]);
    printf("info %s\n", getme_doc_info(doc));
    free(q);
    getme_doc_close(doc);
    return 0;
}

static int smooth(int argc, char **argv)
{
    const char *fix[16], *freed[16];
    getme_doc_options o;
    getme_doc *doc;
    getme_doc_options_init(&o);
    for (int i = 4; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--fix") == 0 && o.num_fix < 16)
            fix[o.num_fix++] = argv[i + 1];
        else if (strcmp(argv[i], "--free") == 0 && o.num_free < 16)
            freed[o.num_free++] = argv[i + 1];
    }
    o.fix = fix;
    o.free_sets = freed;
    getme_formats_status st = getme_doc_open(&doc, argv[2], &o);
    if (st != GETME_FORMATS_OK)
        return fail(doc, st);
    getme_result r;
    if (getme_smooth(getme_doc_mesh(doc), NULL, &r) != GETME_OK) {
        fprintf(stderr, "Error   : %s\n", getme_mesh_error(getme_doc_mesh(doc)));
        getme_doc_close(doc);
        return 1;
    }
    printf("q_min* %.6f -> %.6f, q_mean %.6f -> %.6f\n", r.q_min_star_initial,
           r.q_min_star, r.q_mean_initial, r.q_mean);
    st = getme_doc_write(doc, argv[3]);
    if (st != GETME_FORMATS_OK)
        return fail(doc, st);
    getme_doc_close(doc);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 3 && strcmp(argv[1], "dump") == 0)
        return dump(argv[2]);
    if (argc >= 4 && strcmp(argv[1], "smooth") == 0)
        return smooth(argc, argv);
    if (argc >= 3 && strcmp(argv[1], "fixture") == 0)
        return fixture_write_meshio_style(argv[2]) == 0 ? 0 : 1;
    fprintf(stderr, "usage: cgns_tool dump IN | smooth IN OUT [--fix N] "
                    "[--free N] | fixture OUT\n");
    return 2;
}
