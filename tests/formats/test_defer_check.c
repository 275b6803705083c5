/*
 * test_defer_check.c -- getme_doc_options.defer_check with getme_doc_check
 * (the getme command's read: the validity check takes the qualities of
 * its measures sweep, cli/log.c cli_open_measured) against the check
 * getme_doc_open makes itself:
 *  - a deferred open returns OK and has no statistics yet, whatever the
 *    file's elements;
 *  - getme_doc_check from the qualities of getme_mesh_element_qualities,
 *    from those of getme_mesh_measure_all_qualities, or from NULL gives
 *    the status, the message and the statistics of the undeferred open,
 *    for 1, 2 and 3 threads: a valid deck, decks with 1 and with more
 *    inverted tets than the message names (ids from the file, not
 *    positions), and a degenerate element, which the adapter refuses
 *    before any check.
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"

#include "kuhn_cube.h"
#include "getme_formats.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The kuhn cube as an Abaqus deck, element ids 10 + 2e; the tets listed
   in flip are written inverted (two corners swapped), dup (if >= 0) with
   a node twice. */
static int write_inp(const char *path, const long *flip, int nflip, long dup)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fputs("*NODE\n", f);
    for (int i = 0; i < NN; i++)
        fprintf(f, "%d, %.17g, %.17g, %.17g\n", i + 1, xyz[3 * i],
                xyz[3 * i + 1], xyz[3 * i + 2]);
    fputs("*ELEMENT, TYPE=C3D4\n", f);
    for (long e = 0; e < NE; e++) {
        int32_t c[4] = {tet[e][0], tet[e][1], tet[e][2], tet[e][3]};
        for (int k = 0; k < nflip; k++)
            if (flip[k] == e) {
                int32_t t = c[2];
                c[2] = c[3];
                c[3] = t;
            }
        if (e == dup)
            c[3] = c[0];
        fprintf(f, "%ld, %d, %d, %d, %d\n", 10 + 2 * e, c[0] + 1, c[1] + 1,
                c[2] + 1, c[3] + 1);
    }
    return fclose(f);
}

static int same_stats(const getme_quality_stats *a, const getme_quality_stats *b)
{
    int same = a->num_elements == b->num_elements &&
               a->num_invalid == b->num_invalid && a->num_free == b->num_free &&
               a->q_min == b->q_min && a->q_min_star == b->q_min_star &&
               a->q_mean == b->q_mean && a->q_max == b->q_max &&
               a->num_below_04 == b->num_below_04 &&
               a->num_below_01 == b->num_below_01 &&
               a->num_reported_invalid == b->num_reported_invalid;
    for (int k = 0; same && k < GETME_HIST_BINS; k++)
        same = a->histogram[k] == b->histogram[k];
    for (int k = 0; same && k < a->num_reported_invalid; k++)
        same = a->first_invalid[k] == b->first_invalid[k];
    return same;
}

enum { FROM_ELEMENT, FROM_MEASURES, FROM_NULL, NUM_FROM };

/* The undeferred open of path against a deferred one checked with the
   qualities of each source; want: the undeferred status. */
static void compare(const char *path, getme_formats_status want,
                    const char *fragment)
{
    getme_doc_options o;
    getme_doc_options_init(&o);
    getme_doc *ref = NULL;
    getme_formats_status st = getme_doc_open(&ref, path, &o);
    CHECK_EQ_INT(st, want);
    CHECK(strstr(getme_doc_error(ref), fragment) != NULL);
    const getme_quality_stats *rs = getme_doc_stats(ref);
    /* the adapter refused it: no mesh was checked, deferred or not */
    int checked = want == GETME_FORMATS_OK || rs != NULL;
    o.defer_check = 1;
    for (int from = 0; from < NUM_FROM; from++) {
        getme_doc *doc = NULL;
        getme_formats_status sd = getme_doc_open(&doc, path, &o);
        if (!checked) {
            CHECK_EQ_INT(sd, want);
            CHECK(strcmp(getme_doc_error(doc), getme_doc_error(ref)) == 0);
            getme_doc_close(doc);
            continue;
        }
        CHECK_EQ_INT(sd, GETME_FORMATS_OK);
        CHECK(getme_doc_stats(doc) == NULL);
        getme_mesh *m = getme_doc_mesh(doc);
        int32_t ne = getme_mesh_num_elements(m);
        double *q = malloc((size_t)ne * sizeof *q);
        getme_measure_stats ms[GETME_NUM_TYPES * GETME_NUM_MEASURES];
        if (from == FROM_ELEMENT)
            CHECK(getme_mesh_element_qualities(m, q) == GETME_OK);
        else if (from == FROM_MEASURES)
            CHECK(getme_mesh_measure_all_qualities(m, ms, q) == GETME_OK);
        sd = getme_doc_check(doc, from == FROM_NULL ? NULL : q);
        CHECK_EQ_INT(sd, want);
        CHECK(strcmp(getme_doc_error(doc), getme_doc_error(ref)) == 0);
        CHECK(getme_doc_stats(doc) != NULL && rs != NULL &&
              same_stats(getme_doc_stats(doc), rs));
        free(q);
        getme_doc_close(doc);
    }
    getme_doc_close(ref);
}

int main(void)
{
    const char *path = "defer_check.inp";
    make_mesh(5);
    long one[] = {777};
    long many[GETME_MAX_REPORTED_INVALID + 3];
    for (int k = 0; k < GETME_MAX_REPORTED_INVALID + 3; k++)
        many[k] = NE - 1 - 997L * k;
    static const int threads[] = {1, 2, 3};
    for (int t = 0; t < 3; t++) {
        omp_set_num_threads(threads[t]);
        CHECK(write_inp(path, NULL, 0, -1) == 0);
        compare(path, GETME_FORMATS_OK, "");
        CHECK(write_inp(path, one, 1, -1) == 0);
        compare(path, GETME_FORMATS_ERR_INVALID,
                "1 invalid (inverted or degenerate) element, first: 1564;");
        CHECK(write_inp(path, many, GETME_MAX_REPORTED_INVALID + 3, -1) == 0);
        compare(path, GETME_FORMATS_ERR_INVALID, ", ...; getme smooths");
        CHECK(write_inp(path, NULL, 0, 4242) == 0);
        compare(path, GETME_FORMATS_ERR_INVALID, "is degenerate: node");
    }
    /* no document, or one without a mesh */
    CHECK_EQ_INT(getme_doc_check(NULL, NULL), GETME_FORMATS_ERR_INTERNAL);
    unlink(path);
    return check_summary("test_defer_check");
}
