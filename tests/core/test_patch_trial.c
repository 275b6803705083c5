/*
 * test_patch_trial.c -- patch.c's trials take a cached lane group's
 * qualities straight from the lane kernel (and compute a hex's worst
 * corner only where the corner guard needs it) instead of going through
 * group_q.  A patch without the lane cache (lx NULL) still evaluates every
 * trial through group_q, so on random stars of tets, of hexes and of
 * both mixed, with the corner guard on and off and with either loss, the
 * two must climb and move toward targets identically: the same return
 * values, coordinates, qualities, budget and allowed_max, bit for bit.
 * Built from the core's sources (patch.c is private).
 */
#include "patch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A fixed xorshift sequence: the same cases on every run. */
static uint64_t rng = 0x9e3779b97f4a7c15ull;
static double urand(void) /* in [0, 1) */
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1p-53;
}
static double srand1(void) { return 2.0 * urand() - 1.0; }

/* A 3 x 3 x 3 grid of nodes (the centre is node 13), jittered; its 8
   hexes, and each hex split into 6 tets around its main diagonal. */
#define NN 27
static int32_t hexes[8][8], tets[48][4];

static int32_t gid(int i, int j, int k) { return i + 3 * j + 9 * k; }

static void grid_elements(void)
{
    static const int tet_paths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                        {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int h = 0, t = 0;
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++, h++) {
                int32_t *c = hexes[h];
                c[0] = gid(i, j, k), c[1] = gid(i + 1, j, k);
                c[2] = gid(i + 1, j + 1, k), c[3] = gid(i, j + 1, k);
                c[4] = gid(i, j, k + 1), c[5] = gid(i + 1, j, k + 1);
                c[6] = gid(i + 1, j + 1, k + 1), c[7] = gid(i, j + 1, k + 1);
                /* Kuhn: walk from (i,j,k) to the opposite corner, one axis
                   per step in each of the 6 orders (positive volume for
                   the even permutations; the odd ones are swapped) */
                for (int p = 0; p < 6; p++, t++) {
                    int a[3] = {i, j, k};
                    int32_t v[4];
                    v[0] = gid(a[0], a[1], a[2]);
                    for (int s = 0; s < 3; s++) {
                        a[tet_paths[p][s]]++;
                        v[s + 1] = gid(a[0], a[1], a[2]);
                    }
                    int odd = p == 1 || p == 2 || p == 5;
                    tets[t][0] = v[0], tets[t][3] = v[3];
                    tets[t][1] = odd ? v[2] : v[1];
                    tets[t][2] = odd ? v[1] : v[2];
                }
            }
}

static int contains(const int32_t *c, int nv, int32_t node)
{
    for (int j = 0; j < nv; j++)
        if (c[j] == node)
            return 1;
    return 0;
}

/* Star of node (elements containing it) of kind: 0 tets, 1 hexes, 2 both
   interleaved (mixed lane groups). */
static void add_star(getme_patch *p, int kind, int32_t node)
{
    int32_t id = 0, it = 0, ih = 0;
    getme__patch_clear(p);
    while (it < 48 || ih < 8) {
        int take_hex = kind == 1 || (kind == 2 && (id % 3 == 2 || it == 48));
        if (kind == 0 && it == 48)
            break;
        if (kind == 1 && ih == 8)
            break;
        if (take_hex && ih < 8) {
            if (contains(hexes[ih], 8, node))
                getme__patch_add(p, GETME_HEX, hexes[ih], id++);
            ih++;
        } else if (it < 48) {
            if (contains(tets[it], 4, node))
                getme__patch_add(p, GETME_TET, tets[it], id++);
            it++;
        } else {
            ih++;
        }
    }
}

static int same(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

int main(void)
{
    grid_elements();
    getme_patch a, b;
    double xa[3 * NN], xb[3 * NN], x0[3 * NN];
    int failures = 0, cases = 0, moved = 0, rejected_corner = 0;
    for (int it = 0; it < 600; it++) {
        int kind = it % 3, guard = (it / 3) % 2, op = (it / 6) % 2;
        double jitter = 0.15 + 0.25 * urand();
        for (int k = 0, n = 0; k < 3; k++)
            for (int j = 0; j < 3; j++)
                for (int i = 0; i < 3; i++, n++) {
                    x0[3 * n] = i + jitter * srand1();
                    x0[3 * n + 1] = j + jitter * srand1();
                    x0[3 * n + 2] = k + jitter * srand1();
                }
        /* move the centre away, so climbs have somewhere to go */
        for (int d = 0; d < 3; d++)
            x0[3 * 13 + d] += 0.3 * srand1();
        memcpy(xa, x0, sizeof xa);
        memcpy(xb, x0, sizeof xb);
        if (getme__patch_init(&a, 64) != GETME_OK ||
            getme__patch_init(&b, 64) != GETME_OK)
            return 1;
        /* b without the lane cache: its trials go through group_q */
        free(b.lx);
        b.lx = NULL;
        getme_patch *ps[2] = {&a, &b};
        for (int s = 0; s < 2; s++) {
            getme_patch *p = ps[s];
            p->x = s ? xb : xa;
            p->guard = guard;
            p->floor = 0.7 + 0.29 * urand();
            p->skip_q[GETME_HEX] = 0.8 + 0.2 * urand();
            p->loss = it % 4 < 2 ? 0.0 : 1.0;
            p->budget = it % 5 ? 0.01 * urand() : 0.0;
            p->allowed_max = -INFINITY;
            add_star(p, kind, 13);
            if (s == 1) { /* the same random draws as a */
                p->floor = a.floor;
                p->skip_q[GETME_HEX] = a.skip_q[GETME_HEX];
                p->loss = a.loss;
                p->budget = a.budget;
            }
            getme__patch_eval(p);
        }
        double budget0 = a.budget;
        int32_t mv[1] = {13};
        int ra, rb;
        if (op == 0) {
            ra = getme__patch_climb(&a, mv, 1, 8, 1);
            rb = getme__patch_climb(&b, mv, 1, 8, 1);
        } else {
            double tg[3] = {1.0, 1.0, 1.0}; /* the undisturbed centre */
            ra = getme__patch_toward(&a, mv, 1, tg);
            rb = getme__patch_toward(&b, mv, 1, tg);
        }
        int ok = ra == rb && memcmp(xa, xb, sizeof xa) == 0 &&
                 a.n == b.n && same(a.budget, b.budget) &&
                 same(a.allowed_max, b.allowed_max);
        for (int32_t i = 0; ok && i < a.n; i++)
            ok = same(a.q[i], b.q[i]) && same(a.sj[i], b.sj[i]);
        if (!ok) {
            fprintf(stderr, "case %d (kind %d guard %d op %d): %d vs %d\n", it,
                    kind, guard, op, ra, rb);
            failures++;
        }
        cases++;
        moved += ra > 0;
        /* how often the guard mattered: the same climb without it moves
           differently (so the corner path is exercised) */
        if (guard && op == 0 && kind == 1) {
            getme_patch c;
            double xc[3 * NN];
            memcpy(xc, x0, sizeof xc);
            if (getme__patch_init(&c, 64) != GETME_OK)
                return 1;
            c.x = xc;
            c.loss = a.loss, c.budget = budget0, c.allowed_max = -INFINITY;
            add_star(&c, kind, 13);
            getme__patch_eval(&c);
            getme__patch_climb(&c, mv, 1, 8, 1);
            rejected_corner += memcmp(xc, xa, sizeof xc) != 0;
            getme__patch_free(&c);
        }
        getme__patch_free(&a);
        getme__patch_free(&b);
    }
    printf("%d cases, %d moved, %d where the corner guard changed the climb, "
           "%d mismatches\n",
           cases, moved, rejected_corner, failures);
    /* a test that exercised nothing could not fail */
    if (moved < cases / 10 || rejected_corner == 0)
        return 1;
    return failures != 0;
}
