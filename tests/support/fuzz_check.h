/*
 * fuzz_check.h -- what the mutation fuzz tests of the readers (tests/msh,
 * tests/inp) require of every mutated input: it opens and is written back,
 * or it is refused with a one-line message.  Include after check.h.
 */
#ifndef GETME_TEST_FUZZ_CHECK_H
#define GETME_TEST_FUZZ_CHECK_H

#include "getme_formats.h"

#include <stdio.h>
#include <string.h>

/* Check one outcome of getme_doc_open (st) and close doc; counts it. */
static inline void fuzz_outcome(getme_doc *doc, getme_formats_status st,
                                const char *out_path, int iteration,
                                int *opened, int *failed)
{
    if (st == GETME_FORMATS_OK) {
        (*opened)++;
        getme_formats_status ws = getme_doc_write(doc, out_path);
        CHECK(ws == GETME_FORMATS_OK || getme_doc_error(doc)[0] != '\0');
    } else {
        (*failed)++;
        const char *msg = getme_doc_error(doc);
        if (!msg[0])
            fprintf(stderr, "iteration %d: status %d without message\n",
                    iteration, (int)st);
        CHECK(msg[0] != '\0');
        CHECK(strchr(msg, '\n') == NULL);
    }
    getme_doc_close(doc);
}

#endif /* GETME_TEST_FUZZ_CHECK_H */
