/*
 * test_binpar.c -- the binary MSH 4.1 element records, decoded and stored
 * on several threads (msh41_reader.c read_binary_elements), against what
 * the one-record-at-a-time reader gave:
 *  - a plain file (two blocks, one of more records than a read chunk)
 *    gives the same mesh for 1, 2, 3 and 7 threads;
 *  - one or two bad records (a node not in $Nodes, a node twice) at random
 *    places, or a file cut short, give one error, the same text for every
 *    thread count, naming the first bad element in file order and the
 *    byte offset the earlier reader named (the end of the 4096-record
 *    piece holding it; for a cut file, the file's end).
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"

#include "doc_read.h"
#include "kuhn_cube.h"
#include "getme_formats.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define SPLIT 70000 /* first block's records: more than one 65,536 chunk */
#define PIECE 4096  /* the earlier reader's records per read */

/* ---- writing ------------------------------------------------------------- */

enum { BAD_NONE, BAD_MISSING, BAD_TWICE };

typedef struct damage {
    long at[2];   /* element records to damage (-1: none)        */
    int kind[2];
    long cut;     /* bytes to drop from the file's end (0: none) */
} damage;

static void put_u64(FILE *f, uint64_t v) { fwrite(&v, 8, 1, f); }
static void put_i32(FILE *f, int32_t v) { fwrite(&v, 4, 1, f); }

/* Writes the file; *data: offset of each element block's first record. */
static long write_msh(const char *path, const damage *d, long data[2])
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    fputs("$MeshFormat\n4.1 1 8\n", f);
    put_i32(f, 1);
    fputs("\n$EndMeshFormat\n$Nodes\n", f);
    put_u64(f, 1), put_u64(f, NN), put_u64(f, 1), put_u64(f, NN);
    put_i32(f, 3), put_i32(f, 1), put_i32(f, 0), put_u64(f, NN);
    for (uint64_t i = 1; i <= NN; i++)
        put_u64(f, i);
    fwrite(xyz, sizeof *xyz, 3 * NN, f);
    fputs("\n$EndNodes\n$Elements\n", f);
    put_u64(f, 2), put_u64(f, NE), put_u64(f, 1), put_u64(f, NE);
    long e = 0;
    for (int b = 0; b < 2; b++) {
        long count = b == 0 ? SPLIT : NE - SPLIT;
        put_i32(f, 3), put_i32(f, 1), put_i32(f, 4), put_u64(f, (uint64_t)count);
        data[b] = ftell(f);
        for (long j = 0; j < count; j++, e++) {
            uint64_t rec[5] = {(uint64_t)e + 1};
            for (int k = 0; k < 4; k++)
                rec[1 + k] = (uint64_t)tet[e][k] + 1;
            for (int q = 0; q < 2; q++)
                if (d->at[q] == e)
                    rec[3] = d->kind[q] == BAD_MISSING ? NN + 5 : rec[1];
            fwrite(rec, 8, 5, f);
        }
    }
    fputs("\n$EndElements\n", f);
    long size = ftell(f);
    fclose(f);
    if (d->cut && truncate(path, size - d->cut) != 0)
        return -1;
    return size - d->cut;
}

/* ---- reading ------------------------------------------------------------- */

static const int THREADS[] = {1, 2, 3, 7};
#define NT ((int)(sizeof THREADS / sizeof *THREADS))

/* The earlier reader's message for bad element e (0-based, file order). */
static void want_error(char *buf, size_t size, const char *path, long e,
                       int kind, const long data[2])
{
    int b = e >= SPLIT;
    long j = e - (b ? SPLIT : 0), count = b ? NE - SPLIT : SPLIT;
    long end = (j / PIECE + 1) * PIECE;
    end = end < count ? end : count;
    long byte = data[b] + end * 40;
    if (kind == BAD_MISSING)
        snprintf(buf, size,
                 "'%s': element %ld uses node %d, which is not in $Nodes "
                 "(byte %ld)",
                 path, e + 1, NN + 5, byte);
    else
        snprintf(buf, size,
                 "'%s': element %ld is degenerate: node %d appears twice; "
                 "getme smooths valid meshes only (byte %ld)",
                 path, e + 1, tet[e][0] + 1, byte);
}

static void check_errors(const char *path, const char *want)
{
    for (int t = 0; t < NT; t++) {
        doc_read r = doc_read_file(path, THREADS[t]);
        CHECK(r.st != GETME_FORMATS_OK);
        CHECK(strcmp(r.error, want) == 0);
        if (strcmp(r.error, want) != 0)
            fprintf(stderr, "%d threads: got  %s\n           want %s\n",
                    THREADS[t], r.error, want);
        doc_read_free(&r);
    }
}

int main(void)
{
    const char *path = "binpar.msh";
    long data[2];
    make_mesh(11);
    damage d = {{-1, -1}, {0, 0}, 0};
    CHECK(write_msh(path, &d, data) > 0);
    doc_read plain = doc_read_file(path, 1);
    CHECK(plain.st == GETME_FORMATS_OK);
    CHECK_EQ_INT(plain.nn, NN);
    CHECK_EQ_INT(plain.ne, NE);
    for (int t = 1; t < NT; t++) {
        doc_read r = doc_read_file(path, THREADS[t]);
        CHECK(r.st == GETME_FORMATS_OK && r.nn == plain.nn && r.ne == plain.ne);
        if (r.st == GETME_FORMATS_OK && plain.st == GETME_FORMATS_OK) {
            CHECK(memcmp(r.x, plain.x, (size_t)NN * 3 * sizeof *r.x) == 0);
            CHECK(memcmp(r.conn, plain.conn,
                         (size_t)NE * 8 * sizeof *r.conn) == 0);
        }
        doc_read_free(&r);
    }
    doc_read_free(&plain);
    /* bad records: the first in file order is named, at its piece's end;
       the last records of a chunk and of a block, and the first ones */
    rng_state = 2024;
    long fixed_at[] = {0, PIECE - 1, PIECE, 65535, 65536, SPLIT - 1, SPLIT,
                       NE - 1};
    int nfixed = (int)(sizeof fixed_at / sizeof *fixed_at);
    for (int s = 0; s < nfixed + 8; s++) {
        d.at[0] = s < nfixed ? fixed_at[s] : (long)(rnd() % NE);
        d.at[1] = s % 2 ? (long)(rnd() % NE) : -1;
        d.kind[0] = s % 3 ? BAD_MISSING : BAD_TWICE;
        d.kind[1] = s % 3 ? BAD_TWICE : BAD_MISSING;
        d.cut = 0;
        CHECK(write_msh(path, &d, data) > 0);
        int q = d.at[1] >= 0 && d.at[1] < d.at[0];
        char want[1024];
        want_error(want, sizeof want, path, d.at[q], d.kind[q], data);
        check_errors(path, want);
    }
    /* a cut file (the counts still fit in it): the file's end; with a bad
       record in the whole pieces before the cut, that record */
    d.at[0] = d.at[1] = -1;
    long full = write_msh(path, &d, data);
    long keep[] = {NE - SPLIT - 1, 2 * PIECE + 5, 3 * PIECE, 1};
    for (int s = 0; s < 4; s++) {
        d.at[0] = -1;
        d.cut = full - (data[1] + 40 * keep[s] + 17);
        long size = write_msh(path, &d, data);
        CHECK(size == full - d.cut);
        char want[1024];
        snprintf(want, sizeof want,
                 "'%s': unexpected end of file in $Elements (truncated "
                 "file?) (byte %ld)",
                 path, size);
        check_errors(path, want);
        /* a bad record in the last whole piece before the cut */
        long pieces = keep[s] / PIECE;
        if (pieces == 0)
            continue;
        d.at[0] = SPLIT + (pieces - 1) * PIECE + 7;
        d.kind[0] = BAD_MISSING;
        CHECK(write_msh(path, &d, data) == size);
        want_error(want, sizeof want, path, d.at[0], d.kind[0], data);
        check_errors(path, want);
        /* one in the cut piece is not reached */
        d.at[0] = SPLIT + pieces * PIECE + 2;
        if (d.at[0] >= SPLIT + keep[s])
            continue;
        CHECK(write_msh(path, &d, data) == size);
        snprintf(want, sizeof want,
                 "'%s': unexpected end of file in $Elements (truncated "
                 "file?) (byte %ld)",
                 path, size);
        check_errors(path, want);
    }
    unlink(path);
    return check_summary("test_binpar");
}
