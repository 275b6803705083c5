/*
 * fuzz_inp.c -- libFuzzer harness for the INP adapter (built only when
 * clang with -fsanitize=fuzzer is found; see tests/inp/CMakeLists.txt).
 * Each input is written to a file (the adapter streams from files) and
 * opened; a deck that opens is written back.  Crashes, leaks and undefined
 * behaviour are the findings; refused decks are fine.
 */
#define _POSIX_C_SOURCE 200809L
#include "getme_formats.h"

#include <stdint.h>
#include <stdio.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char in[64], out[64];
    snprintf(in, sizeof in, "/tmp/getme-fuzz-%d.inp", (int)getpid());
    snprintf(out, sizeof out, "/tmp/getme-fuzz-%d-out.inp", (int)getpid());
    FILE *f = fopen(in, "wb");
    if (!f)
        return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    getme_doc *doc;
    if (getme_doc_open(&doc, in, NULL) == GETME_FORMATS_OK)
        getme_doc_write(doc, out);
    getme_doc_close(doc);
    remove(out);
    return 0;
}
