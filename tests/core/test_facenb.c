/*
 * test_facenb.c -- facenb.c's 2-byte face table: every entry reads back as
 * the int32 table had it (random tables over mixed element types, with
 * the skin, irregular faces, an element across from itself, differences
 * at and just past the int16 range, and chunks made only of escapes);
 * packing (in place) on 1, 3 and 7 threads gives the same bytes; the number of
 * escapes is exactly the entries the int16 cannot hold; and on real
 * workspaces the packed table the smoother keeps equals getme__ws_faces'.
 */
#define N 12
#include "check.h"
#include "facenb.h"
#include "gen_mesh.h"

#include <stdlib.h>
#include <string.h>

static uint64_t rng = 0x2545f4914f6cdd1du;
static uint32_t next32(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (uint32_t)rng;
}

/* A workspace with only type ranges: counts[t] elements of type t. */
static void fake_ws(getme_ws *ws, const int32_t *counts, int nt)
{
    memset(ws, 0, sizeof *ws);
    ws->nt = nt;
    ws->tstart[0] = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        ws->tstart[t + 1] = ws->tstart[t] + counts[t];
    ws->ne = ws->tstart[GETME_NUM_TYPES];
}

/* One entry of element e: a near or far neighbour, the skin, irregular,
   e itself, or a difference at the int16 range's edges. */
static int32_t random_nb(int32_t e, int32_t ne, int far_only)
{
    uint32_t r = next32() % 16;
    int64_t nb;
    if (far_only || r == 0)
        nb = next32() % (uint32_t)ne;
    else if (r == 1)
        return -1;
    else if (r == 2)
        return GETME_FACE_IRREGULAR;
    else if (r == 3)
        return e;
    else if (r == 4)
        nb = (int64_t)e + (next32() % 2 ? INT16_MAX : -INT16_MAX);
    else if (r == 5)
        nb = (int64_t)e + (next32() % 2 ? INT16_MAX + 1 : INT16_MIN);
    else if (r == 6) /* the lowest direct code and the escape just below */
        nb = (int64_t)e + GETME_FNB_ESCAPE + GETME_FNB_CHUNK - (next32() % 2);
    else
        nb = (int64_t)e + (int32_t)(next32() % 4001) - 2000;
    return nb >= 0 && nb < ne ? (int32_t)nb : -1;
}

static int fits(int32_t e, int32_t nb)
{
    int64_t d = (int64_t)nb - e;
    return nb == -1 || (nb >= 0 && d != 0 &&
                        d >= GETME_FNB_ESCAPE + GETME_FNB_CHUNK && d <= INT16_MAX);
}

static int same_packed(const getme_facenb *a, const getme_facenb *b)
{
    int64_t nc = (a->n + GETME_FNB_CHUNK - 1) / GETME_FNB_CHUNK;
    if (a->n != b->n || memcmp(a->d, b->d, (size_t)a->n * 2) ||
        memcmp(a->cptr, b->cptr, (size_t)(nc + 1) * 8))
        return 0;
    int64_t ne = a->cptr[nc];
    return !memcmp(a->enb, b->enb, (size_t)ne * 4);
}

static void check_random(const int32_t *counts, int far_only)
{
    getme_ws ws;
    fake_ws(&ws, counts, 1);
    int64_t foff[GETME_NUM_TYPES];
    int64_t n = getme__ws_face_offsets(&ws, foff);
    int32_t *table = malloc((size_t)(n ? n : 1) * sizeof *table);
    int64_t want_esc = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nf = getme__faces[t].num_faces;
        for (int32_t e = ws.tstart[t]; e < ws.tstart[t + 1]; e++)
            for (int j = 0; j < nf; j++) {
                int64_t k = foff[t] + (int64_t)(e - ws.tstart[t]) * nf + j;
                table[k] = random_nb(e, ws.ne, far_only);
                want_esc += !fits(e, table[k]);
            }
    }
    getme_facenb fb[3];
    const int threads[3] = {1, 3, 7};
    for (int i = 0; i < 3; i++) {
        ws.nt = threads[i];
        int32_t *copy = malloc((size_t)(n ? n : 1) * sizeof *copy);
        memcpy(copy, table, (size_t)n * sizeof *copy);
        CHECK(getme__facenb_pack(&fb[i], &ws, foff, copy) == GETME_OK);
    }
    CHECK(fb[0].n == n);
    int64_t nc = (n + GETME_FNB_CHUNK - 1) / GETME_FNB_CHUNK;
    CHECK(fb[0].cptr[nc] == want_esc);
    CHECK(same_packed(&fb[0], &fb[1]));
    CHECK(same_packed(&fb[0], &fb[2]));
    int64_t bad = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nf = getme__faces[t].num_faces;
        for (int32_t e = ws.tstart[t]; e < ws.tstart[t + 1]; e++) {
            int32_t f[6];
            getme__facenb_elem(&fb[1], &ws, foff, t, e, f);
            for (int j = 0; j < nf; j++)
                bad += f[j] != table[foff[t] + (int64_t)(e - ws.tstart[t]) * nf + j];
        }
    }
    CHECK(bad == 0);
    for (int i = 0; i < 3; i++)
        getme__facenb_free(&fb[i]);
    free(table);
}

/* getme__ws_faces' int32 table packs and reads back on real meshes (a
   skin, several types); and the packed table getme_mesh_fix_boundary
   leaves on the mesh for the smoother (build() calls it) is the same. */
static void check_mesh(int kind, int nt)
{
    gen g = make_mesh(kind);
    /* distorted: other coordinates, another element order */
    getme_mesh *m = nt == 1 ? build(&g) : distorted(&g);
    getme_ws ws;
    CHECK(getme__ws_build(&ws, m, 1, nt) == GETME_OK);
    if (nt == 1)
        CHECK(ws.faces.d != NULL); /* fix_boundary's, taken over */
    int64_t foff[GETME_NUM_TYPES];
    int64_t n = getme__ws_face_offsets(&ws, foff);
    int32_t *table = malloc((size_t)(n ? n : 1) * sizeof *table);
    CHECK(getme__ws_faces(&ws, foff, table) == GETME_OK);
    getme_facenb fb;
    int32_t *copy = malloc((size_t)(n ? n : 1) * sizeof *copy);
    memcpy(copy, table, (size_t)n * sizeof *copy);
    CHECK(getme__facenb_pack(&fb, &ws, foff, copy) == GETME_OK);
    if (ws.faces.d)
        CHECK(same_packed(&fb, &ws.faces));
    int64_t bad = 0, skin = 0;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int nf = getme__faces[t].num_faces;
        for (int32_t e = ws.tstart[t]; e < ws.tstart[t + 1]; e++) {
            int32_t f[6];
            getme__facenb_elem(&fb, &ws, foff, t, e, f);
            for (int j = 0; j < nf; j++) {
                int32_t want = table[foff[t] + (int64_t)(e - ws.tstart[t]) * nf + j];
                bad += f[j] != want;
                skin += want == -1;
            }
        }
    }
    CHECK(bad == 0);
    CHECK(skin > 0);
    getme__facenb_free(&fb);
    free(table);
    getme__ws_free(&ws);
    getme_mesh_free(m);
    free_gen(&g);
}

int main(void)
{
    /* tets, hexes, prisms, pyramids and planar types side by side; one
       type alone; nothing; chunks of escapes only */
    int32_t mixed[GETME_NUM_TYPES] = {0};
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        mixed[t] = 3000 + 1000 * t;
    check_random(mixed, 0);
    int32_t one[GETME_NUM_TYPES] = {0};
    one[GETME_HEX] = 70001;
    check_random(one, 0);
    check_random(one, 1);
    int32_t none[GETME_NUM_TYPES] = {0};
    check_random(none, 0);
    int32_t gaps[GETME_NUM_TYPES] = {0};
    gaps[0] = 1, gaps[GETME_NUM_TYPES - 1] = 5000;
    check_random(gaps, 0);

    for (int kind = 0; kind <= 4; kind++)
        for (int nt = 1; nt <= 3; nt += 2)
            check_mesh(kind, nt);
    return check_summary("test_facenb");
}
