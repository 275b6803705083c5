/*
 * test_stars.c -- stars.c's packed node stars: every star reads back as it
 * was (random stars with empty ones, repeated elements and values of 1 to
 * 4 bytes, all of 4 bytes); packing on 1, 3 and 7 threads gives the
 * same bytes; the packed sizes are the LEB128 sizes of the differences;
 * stars whose elements would need 5 bytes stay plain; and on a real
 * workspace the element and node maps still unpack into the packed stars'
 * block.
 */
#define N 12
#include "check.h"
#include "gen_mesh.h"
#include "stars.h"

#include <stdlib.h>
#include <string.h>

static uint64_t rng = 0x9e3779b97f4a7c15u;
static uint32_t next32(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (uint32_t)rng;
}

/* A workspace holding only stars: nn nodes, elements below ne. */
typedef struct fake {
    getme_ws ws;
    int32_t *ptr0, *star0; /* the plain stars, kept to compare */
    int64_t leb;           /* their packed size                */
} fake;

static int leb_bytes(uint32_t v)
{
    return v < (1u << 7) ? 1 : v < (1u << 14) ? 2 : v < (1u << 21) ? 3 : 4;
}

/* Stars of 0 to 40 elements: differences of 0 (an element twice), small,
   or of up to 2^scale_bits. */
static void make_fake(fake *f, int32_t nn, int scale_bits, int nt)
{
    memset(f, 0, sizeof *f);
    f->ws.nn = nn;
    f->ws.ne = (1 << 28) - 1;
    f->ws.nt = nt;
    f->ptr0 = malloc(((size_t)nn + 1) * sizeof *f->ptr0);
    f->ptr0[0] = 0;
    for (int32_t v = 0; v < nn; v++)
        f->ptr0[v + 1] = f->ptr0[v] + (int32_t)(next32() % 41 * (v % 7 != 3));
    int64_t total = f->ptr0[nn];
    f->star0 = malloc((size_t)(total ? total : 1) * sizeof *f->star0);
    for (int32_t v = 0; v < nn; v++) {
        int32_t e = (int32_t)(next32() % (1u << scale_bits));
        for (int32_t k = f->ptr0[v]; k < f->ptr0[v + 1]; k++) {
            uint32_t r = next32() % 8;
            int32_t d = r == 0 ? 0 : r < 6 ? (int32_t)(next32() % 200)
                                           : (int32_t)(next32() % (1u << scale_bits));
            if (k > f->ptr0[v]) {
                if ((int64_t)e + d >= f->ws.ne)
                    d = 0;
                e += d;
            }
            f->star0[k] = e;
            f->leb += leb_bytes((uint32_t)(e - (k > f->ptr0[v] ? f->star0[k - 1] : 0)));
        }
    }
    f->ws.star_ptr = malloc(((size_t)nn + 1) * sizeof *f->ws.star_ptr);
    f->ws.star = malloc((size_t)(total ? total : 1) * sizeof *f->ws.star);
    memcpy(f->ws.star_ptr, f->ptr0, ((size_t)nn + 1) * sizeof *f->ptr0);
    memcpy(f->ws.star, f->star0, (size_t)total * sizeof *f->star0);
}

static void free_fake(fake *f)
{
    free(f->ptr0), free(f->star0), free(f->ws.star_ptr), free(f->ws.star);
    getme__offs_free(&f->ws.star_offs);
}

/* Every star of ws reads back as the plain one; sizes and bounds. */
static void check_reads(const getme_ws *ws, const int32_t *ptr0,
                        const int32_t *star0)
{
    for (int32_t v = 0; v < ws->nn; v++) {
        getme_star_it it = getme__star_open(ws, v);
        int32_t k = ptr0[v], e;
        while (getme__star_next(&it, &e)) {
            CHECK(k < ptr0[v + 1]);
            CHECK(e == star0[k]);
            k++;
        }
        CHECK(k == ptr0[v + 1]);
        CHECK(getme__star_size(ws, v) == ptr0[v + 1] - ptr0[v]);
        CHECK(getme__star_bound(ws, v) >= ptr0[v + 1] - ptr0[v]);
    }
}

static void pack_three(int scale, int all_wide)
{
    static const int threads[3] = {1, 3, 7};
    fake f[3];
    uint64_t seed = rng;
    for (int i = 0; i < 3; i++) {
        rng = seed;
        make_fake(&f[i], 3001, scale, threads[i]);
        if (all_wide) /* every value 4 bytes: packs to the same size */
            for (int32_t v = 0; v < f[i].ws.nn; v++)
                for (int32_t k = f[i].ptr0[v]; k < f[i].ptr0[v + 1]; k++)
                    f[i].ws.star[k] = f[i].star0[k] =
                        (1 << 21) * (int32_t)(1 + k - f[i].ptr0[v]) + v % 3;
        if (all_wide)
            f[i].leb = 4 * (int64_t)f[i].ptr0[f[i].ws.nn];
        getme__stars_pack(&f[i].ws);
        CHECK(f[i].ws.stars_packed);
        CHECK(getme__ws_star_at(&f[i].ws, f[i].ws.nn) == f[i].leb);
        CHECK(!f[i].ws.star_ptr); /* the offsets packed too */
        check_reads(&f[i].ws, f[0].ptr0, f[0].star0);
    }
    for (int i = 1; i < 3; i++) { /* the same bytes for any thread count */
        int64_t diff = 0;
        for (int32_t v = 0; v <= f[0].ws.nn; v++)
            diff += getme__ws_star_at(&f[0].ws, v) != getme__ws_star_at(&f[i].ws, v);
        CHECK(diff == 0);
        CHECK(!memcmp(f[0].ws.star, f[i].ws.star, (size_t)f[0].leb));
    }
    getme__stars_pack(&f[0].ws); /* packing twice changes nothing */
    check_reads(&f[0].ws, f[0].ptr0, f[0].star0);
    for (int i = 0; i < 3; i++)
        free_fake(&f[i]);
}

static void random_stars(void)
{
    for (int scale = 6; scale <= 27; scale += 7)
        pack_three(scale, 0);
    pack_three(6, 1);
}

/* Element indices of 2^28 and more would need 5 bytes: left plain. */
static void too_wide(void)
{
    fake f;
    make_fake(&f, 50, 6, 2);
    f.ws.ne = 1 << 28;
    getme__stars_pack(&f.ws);
    CHECK(!f.ws.stars_packed);
    CHECK(!memcmp(f.ws.star, f.star0,
                  (size_t)f.ptr0[f.ws.nn] * sizeof *f.star0));
    check_reads(&f.ws, f.ptr0, f.star0);
    free_fake(&f);
}

/* A real workspace: the stars read back, and the maps, packed before the
   stars, unpack into the packed stars' block as they were. */
static void real_workspace(int kind, int nt)
{
    gen g = make_mesh(kind);
    getme_mesh *mesh = distorted(&g);
    getme_ws ws;
    CHECK(getme__ws_build(&ws, mesh, 1, nt) == GETME_OK);
    int32_t nn = ws.nn, ne = ws.ne;
    int64_t total = getme__ws_star_at(&ws, nn);
    int32_t *ptr0 = malloc(((size_t)nn + 1) * sizeof *ptr0);
    int32_t *star0 = malloc((size_t)total * sizeof *star0);
    int32_t *eo = malloc((size_t)ne * sizeof *eo);
    int32_t *no = malloc((size_t)nn * sizeof *no);
    memcpy(ptr0, ws.star_ptr, ((size_t)nn + 1) * sizeof *ptr0);
    memcpy(star0, ws.star, (size_t)total * sizeof *star0);
    memcpy(eo, ws.elem_orig, (size_t)ne * sizeof *eo);
    memcpy(no, ws.node_orig, (size_t)nn * sizeof *no);
    getme__ws_pack_map(&ws);
    getme__stars_pack(&ws);
    CHECK(ws.stars_packed);
    CHECK(getme__ws_star_at(&ws, nn) < 3 * total);
    check_reads(&ws, ptr0, star0);
    getme__ws_unpack_map(&ws);
    CHECK(!memcmp(ws.elem_orig, eo, (size_t)ne * sizeof *eo));
    CHECK(!memcmp(ws.node_orig, no, (size_t)nn * sizeof *no));
    getme__ws_free(&ws);
    free(ptr0), free(star0), free(eo), free(no);
    getme_mesh_free(mesh);
    free_gen(&g);
}

/* offsets.h on its own: random nondecreasing tables of every length
   around the group size read back entry by entry, packed; a table with
   a group spanning 65536 stays plain and reads back too. */
static void check_offsets(void)
{
    for (int64_t n = 1; n < 70; n += 3) {
        for (int wide = 0; wide <= 1; wide++) {
            int32_t *t = malloc((size_t)n * sizeof *t), *want = malloc((size_t)n * sizeof *t);
            int64_t x = next32() % 1000;
            for (int64_t v = 0; v < n; v++) {
                x += wide && v == n / 2 ? 65536 : next32() % 5000;
                t[v] = want[v] = (int32_t)x;
            }
            getme_offsets o;
            getme__offs_take(&o, t, n);
            /* packed exactly when no group spans 65536 or more */
            int64_t span = 0;
            for (int64_t v = 0; v < n; v++) {
                int64_t d = (int64_t)want[v] - want[v / GETME_OFFS_GROUP * GETME_OFFS_GROUP];
                span = d > span ? d : span;
            }
            CHECK((o.plain == NULL) == (span <= UINT16_MAX));
            int64_t bad = 0;
            for (int64_t v = 0; v < n; v++)
                bad += getme__offs_at(&o, v) != want[v];
            CHECK(bad == 0);
            getme__offs_free(&o);
            free(want);
        }
    }
}

int main(void)
{
    check_offsets();
    random_stars();
    too_wide();
    for (int kind = 0; kind <= 4; kind++)
        for (int nt = 1; nt <= 3; nt += 2)
            real_workspace(kind, nt);
    return check_summary("test_stars");
}
