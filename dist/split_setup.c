/*
 * split_setup.c -- the per-rank input's set-up (docs/distributed.md §3):
 * from the parts the ranks read, the distributed parts getme_smooth_part
 * takes -- skin and interfaces (faces hashed to home ranks), fixed marks
 * and holders (a hashed node directory), the one ghost layer, neighbour
 * lists and counted copies -- in rounds of one MPI_Alltoallv each.
 */
#include "dist.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef dist_node node_rec;

enum { MAXV = 8 };

static int home(uint64_t key, int p)
{
    key ^= key >> 33; /* splitmix64's finaliser: tags are often dense */
    key *= 0xff51afd7ed558ccdull;
    key ^= key >> 33;
    key *= 0xc4ceb9fe1a85ec53ull;
    key ^= key >> 33;
    return (int)(key % (uint64_t)p);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* ---- records to their ranks ---------------------------------------------- */

/* n records of variable width (data[ptr[i] .. ptr[i+1]), to rank dest[i])
   are exchanged; *recv / *rcount as dist_a2a; order[k] = the record that
   was k-th in the send buffer (grouped by rank, record order inside), so
   that an answer coming back in the same order is matched to its record.
   -1 (every rank) if an exchange could not be set up. */
static int exchange(dist_ctx *c, int64_t n, const int *dest,
                    const int64_t *ptr, const int64_t *data, int64_t **recv,
                    int **rcount, int64_t **order)
{
    int p = c->size;
    int64_t *pos = dist_xalloc(((size_t)p + 1) * sizeof *pos);
    int64_t *rpos = dist_xalloc(((size_t)p + 1) * sizeof *rpos);
    int *scount = dist_xalloc((size_t)p * sizeof *scount);
    int64_t *send = dist_xalloc((size_t)ptr[n] * sizeof *send);
    *order = dist_xalloc((size_t)n * sizeof **order);
    memset(pos, 0, ((size_t)p + 1) * sizeof *pos);
    memset(rpos, 0, ((size_t)p + 1) * sizeof *rpos);
    for (int64_t i = 0; i < n; i++) {
        pos[dest[i] + 1] += ptr[i + 1] - ptr[i];
        rpos[dest[i] + 1]++;
    }
    int too_big = 0;
    for (int q = 0; q < p; q++) {
        too_big |= pos[q + 1] > INT32_MAX;
        scount[q] = (int)pos[q + 1];
        pos[q + 1] += pos[q];
        rpos[q + 1] += rpos[q];
    }
    for (int64_t i = 0; i < n; i++) {
        int q = dest[i];
        int64_t w = ptr[i + 1] - ptr[i];
        memcpy(send + pos[q], data + ptr[i], (size_t)w * sizeof *data);
        pos[q] += w;
        (*order)[rpos[q]++] = i;
    }
    if (too_big)
        memset(scount, 0, (size_t)p * sizeof *scount);
    int rc = dist_a2a(c, send, scount, recv, rcount);
    int bad = too_big, any = 0;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, c->comm);
    free(pos), free(rpos), free(scount), free(send);
    return rc == 0 && !any ? 0 : -1;
}

/* Fixed-width records: ptr = w * i. */
static int64_t *widths(int64_t n, int w)
{
    int64_t *ptr = dist_xalloc(((size_t)n + 1) * sizeof *ptr);
    for (int64_t i = 0; i <= n; i++)
        ptr[i] = w * i;
    return ptr;
}

/* ---- 1. faces: skin and interfaces -------------------------------------- */

typedef struct face {
    uint64_t k[4];  /* sorted node tags, 0-padded */
    int64_t region; /* at home: the record's index */
} face;

static int cmp_face(const void *a, const void *b)
{
    const face *x = a, *y = b;
    for (int i = 0; i < 4; i++)
        if (x->k[i] != y->k[i])
            return x->k[i] < y->k[i] ? -1 : 1;
    return (x->region > y->region) - (x->region < y->region);
}

static int same_key(const face *x, const face *y)
{
    return !memcmp(x->k, y->k, sizeof x->k);
}

/* The faces of the linear volume types as corner lists (-1 ends; the same
   in Gmsh's and getme's numbering). */
static const int8_t FACES[4][6][5] = {
    /* tet */ {{0, 1, 2, -1}, {0, 1, 3, -1}, {0, 2, 3, -1}, {1, 2, 3, -1},
               {-1}, {-1}},
    /* hex */ {{0, 1, 2, 3, -1}, {4, 5, 6, 7, -1}, {0, 1, 5, 4, -1},
               {1, 2, 6, 5, -1}, {2, 3, 7, 6, -1}, {3, 0, 4, 7, -1}},
    /* prism */ {{0, 1, 2, -1}, {3, 4, 5, -1}, {0, 1, 4, 3, -1},
                 {1, 2, 5, 4, -1}, {2, 0, 3, 5, -1}, {-1}},
    /* pyramid */ {{0, 1, 2, 3, -1}, {0, 1, 4, -1}, {1, 2, 4, -1},
                   {2, 3, 4, -1}, {3, 0, 4, -1}, {-1}}};

static void fix_face(dist_split *s, const face *f)
{
    for (int i = 0; i < 4 && f->k[i]; i++)
        s->node[dist_find_node(s, f->k[i])].fixed = 1;
}

/* The flag of every face record received at home: 1 skin (once in the
   mesh), 2 interface (twice, different regions), else 0. */
static int64_t *face_flags(const face *hf, int64_t nr)
{
    face *t = dist_xalloc((size_t)nr * sizeof *t);
    int64_t *flag = dist_xalloc((size_t)nr * sizeof *flag);
    for (int64_t i = 0; i < nr; i++) {
        t[i] = hf[i];
        t[i].region = i;
    }
    qsort(t, (size_t)nr, sizeof *t, cmp_face);
    for (int64_t i = 0, j; i < nr; i = j) {
        int diff = 0;
        for (j = i + 1; j < nr && same_key(&t[i], &t[j]); j++)
            diff |= hf[t[j].region].region != hf[t[i].region].region;
        for (int64_t k = i; k < j; k++)
            flag[t[k].region] = j - i == 1 ? 1 : diff ? 2 : 0;
    }
    free(t);
    return flag;
}

static int mark_faces(dist_split *s, dist_ctx *c, unsigned flags)
{
    int64_t nf = 0;
    for (int32_t e = 0; e < s->own_ne; e++)
        for (int f = 0; f < 6 && FACES[s->elem[e].type][f][0] >= 0; f++)
            nf++;
    face *fs = dist_xalloc((size_t)nf * sizeof *fs);
    nf = 0;
    for (int32_t e = 0; e < s->own_ne; e++) {
        const dist_elem *el = &s->elem[e];
        for (int f = 0; f < 6 && FACES[el->type][f][0] >= 0; f++) {
            face *x = &fs[nf++];
            int n = 0;
            for (; n < 4 && FACES[el->type][f][n] >= 0; n++)
                x->k[n] = el->node[FACES[el->type][f][n]];
            for (int i = n; i < 4; i++)
                x->k[i] = 0;
            qsort(x->k, (size_t)n, sizeof *x->k, cmp_u64);
            x->region = el->region;
        }
    }
    qsort(fs, (size_t)nf, sizeof *fs, cmp_face);
    /* faces twice in the rank's parts: interfaces if the regions differ;
       faces once go home */
    int64_t nsend = 0;
    for (int64_t i = 0, j; i < nf; i = j) {
        for (j = i + 1; j < nf && same_key(&fs[i], &fs[j]); j++)
            ;
        if (j - i == 1)
            fs[nsend++] = fs[i];
        else if ((flags & GETME_FIX_INTERFACES) &&
                 fs[i].region != fs[j - 1].region)
            fix_face(s, &fs[i]);
    }
    int *dest = dist_xalloc((size_t)nsend * sizeof *dest);
    for (int64_t i = 0; i < nsend; i++)
        dest[i] = home(fs[i].k[0] ^ fs[i].k[1] * 0x9e3779b97f4a7c15ull ^
                           fs[i].k[2] * 0xbf58476d1ce4e5b9ull ^
                           fs[i].k[3] * 0x94d049bb133111ebull,
                       c->size);
    int64_t *ptr = widths(nsend, 5), *recv = NULL, *order = NULL;
    int *rcount = NULL;
    int rc = exchange(c, nsend, dest, ptr, (const int64_t *)(void *)fs, &recv,
                      &rcount, &order);
    if (rc == 0) {
        int64_t nr = 0;
        for (int q = 0; q < c->size; q++)
            nr += rcount[q] / 5;
        int64_t *flag = face_flags((const face *)(void *)recv, nr);
        /* answers go back in the order the records came */
        int *bdest = dist_xalloc((size_t)nr * sizeof *bdest);
        for (int q = 0, k = 0; q < c->size; q++)
            for (int i = 0; i < rcount[q] / 5; i++)
                bdest[k++] = q;
        int64_t *bptr = widths(nr, 1), *ans = NULL, *border = NULL;
        int *acount = NULL;
        rc = exchange(c, nr, bdest, bptr, flag, &ans, &acount, &border);
        for (int64_t k = 0; rc == 0 && k < nsend; k++)
            if ((ans[k] == 1 && (flags & GETME_FIX_SKIN)) ||
                (ans[k] == 2 && (flags & GETME_FIX_INTERFACES)))
                fix_face(s, &fs[order[k]]);
        free(flag), free(bdest), free(bptr), free(ans), free(acount);
        free(border);
    }
    free(fs), free(dest), free(ptr), free(recv), free(rcount), free(order);
    return rc;
}

/* ---- 2. and 3. node directory ------------------------------------------- */

/* Every node of the table goes home as (tag, fixed); home ORs the fixed
   marks of its copies and answers each copy with (fixed, number of other
   holders, their ranks).  The answers land in s->node[].fixed and the CSR
   s->optr / s->orank (other holders per node). */
static int directory(dist_split *s, dist_ctx *c)
{
    int64_t n = s->nn;
    int *dest = dist_xalloc((size_t)n * sizeof *dest);
    int64_t *data = dist_xalloc((size_t)n * 2 * sizeof *data);
    for (int64_t i = 0; i < n; i++) {
        dest[i] = home(s->node[i].tag, c->size);
        data[2 * i] = (int64_t)s->node[i].tag;
        data[2 * i + 1] = s->node[i].fixed;
    }
    int64_t *ptr = widths(n, 2), *recv = NULL, *order = NULL;
    int *rcount = NULL;
    int rc = exchange(c, n, dest, ptr, data, &recv, &rcount, &order);
    free(data), free(ptr);
    if (rc != 0) {
        free(dest);
        return -1;
    }
    /* at home: (tag, source rank, record) sorted */
    int64_t nr = 0;
    for (int q = 0; q < c->size; q++)
        nr += rcount[q] / 2;
    int64_t (*t)[3] = dist_xalloc((size_t)nr * sizeof *t);
    int *src = dist_xalloc((size_t)nr * sizeof *src);
    for (int q = 0, k = 0; q < c->size; q++)
        for (int i = 0; i < rcount[q] / 2; i++, k++) {
            t[k][0] = recv[2 * k];
            t[k][1] = q;
            t[k][2] = k;
            src[k] = q;
        }
    qsort(t, (size_t)nr, sizeof *t, cmp_u64); /* by tag (first word) */
    /* stable by source within a tag: sort each tag's run by rank */
    int64_t *aptr = dist_xalloc(((size_t)nr + 1) * sizeof *aptr);
    int64_t *gfirst = dist_xalloc((size_t)nr * sizeof *gfirst);
    int64_t *glen = dist_xalloc((size_t)nr * sizeof *glen);
    int64_t *gfix = dist_xalloc((size_t)nr * sizeof *gfix);
    for (int64_t i = 0, j; i < nr; i = j) {
        int64_t fx = 0;
        for (j = i; j < nr && t[j][0] == t[i][0]; j++)
            fx |= recv[2 * t[j][2] + 1];
        for (int64_t a = i + 1; a < j; a++) /* few copies: insertion */
            for (int64_t b = a; b > i && t[b][1] < t[b - 1][1]; b--) {
                int64_t tmp[3];
                memcpy(tmp, t[b], sizeof tmp);
                memcpy(t[b], t[b - 1], sizeof tmp);
                memcpy(t[b - 1], tmp, sizeof tmp);
            }
        for (int64_t k = i; k < j; k++) {
            gfirst[t[k][2]] = i;
            glen[t[k][2]] = j - i;
            gfix[t[k][2]] = fx;
        }
    }
    aptr[0] = 0;
    for (int64_t k = 0; k < nr; k++)
        aptr[k + 1] = aptr[k] + 1 + glen[k];
    int64_t *ans = dist_xalloc((size_t)aptr[nr] * sizeof *ans);
    for (int64_t k = 0; k < nr; k++) {
        int64_t *a = ans + aptr[k], m = 0;
        a[0] = gfix[k];
        a[1] = glen[k] - 1;
        for (int64_t g = gfirst[k]; g < gfirst[k] + glen[k]; g++)
            if (t[g][2] != k)
                a[2 + m++] = t[g][1];
    }
    free(t), free(gfirst), free(glen), free(gfix), free(recv), free(rcount);
    int64_t *back = NULL, *border = NULL;
    int *bcount = NULL;
    rc = exchange(c, nr, src, aptr, ans, &back, &bcount, &border);
    free(src), free(aptr), free(ans), free(border);
    if (rc == 0) {
        /* answers come grouped by home rank in the order sent: order[] */
        free(s->optr), free(s->orank);
        s->optr = dist_xalloc(((size_t)n + 1) * sizeof *s->optr);
        int64_t total = 0, at = 0;
        for (int64_t k = 0; k < n; k++) {
            total += back[at + 1];
            at += 2 + back[at + 1];
        }
        s->orank = dist_xalloc((size_t)total * sizeof *s->orank);
        int64_t *cnt = dist_xalloc((size_t)n * sizeof *cnt), *pos = NULL;
        at = 0;
        for (int64_t k = 0; k < n; k++) {
            cnt[order[k]] = at;
            at += 2 + back[at + 1];
        }
        s->optr[0] = 0;
        for (int64_t i = 0; i < n; i++) {
            const int64_t *a = back + cnt[i];
            s->node[i].fixed = a[0];
            s->optr[i + 1] = s->optr[i] + a[1];
            for (int64_t m = 0; m < a[1]; m++)
                s->orank[s->optr[i] + m] = (int)a[2 + m];
        }
        free(cnt), free(pos);
    }
    free(back), free(bcount), free(order), free(dest);
    return rc;
}

/* ---- the ghost layer ---------------------------------------------------- */

/* Each own element touching a node other ranks hold goes to them (once
   per rank): (tag, type, region, nv, then per node tag, x, y, z, fixed). */
static int ghosts(dist_split *s, dist_ctx *c)
{
    int64_t n = 0, words = 0;
    int ranks[MAXV * 64];
    for (int pass = 0; pass < 2; pass++) {
        int *dest = pass ? dist_xalloc((size_t)n * sizeof *dest) : NULL;
        int64_t *ptr = pass ? dist_xalloc(((size_t)n + 1) * sizeof *ptr) : NULL;
        int64_t *data = pass ? dist_xalloc((size_t)words * sizeof *data) : NULL;
        int64_t k = 0, w = 0;
        if (pass)
            ptr[0] = 0;
        for (int32_t e = 0; e < s->own_ne; e++) {
            const dist_elem *el = &s->elem[e];
            int nr = 0;
            for (int j = 0; j < el->nv; j++) {
                int32_t i = dist_find_node(s, el->node[j]);
                for (int64_t h = s->optr[i]; h < s->optr[i + 1]; h++) {
                    int q = s->orank[h], seen = 0;
                    for (int m = 0; m < nr && !seen; m++)
                        seen = ranks[m] == q;
                    if (!seen && nr == MAXV * 64)
                        dist_stop("an element's nodes have more than 512 other "
                             "holders");
                    if (!seen)
                        ranks[nr++] = q;
                }
            }
            for (int m = 0; m < nr; m++) {
                int64_t rw = 4 + 5 * (int64_t)el->nv;
                if (pass) {
                    int64_t *r = data + w;
                    dest[k] = ranks[m];
                    r[0] = el->tag, r[1] = el->type, r[2] = el->region;
                    r[3] = el->nv;
                    for (int j = 0; j < el->nv; j++) {
                        const node_rec *nd =
                            &s->node[dist_find_node(s, el->node[j])];
                        int64_t *x = r + 4 + 5 * j;
                        x[0] = (int64_t)nd->tag;
                        memcpy(x + 1, nd->x, 3 * sizeof *x);
                        x[4] = nd->fixed;
                    }
                    ptr[k + 1] = ptr[k] + rw;
                }
                k++;
                w += rw;
            }
        }
        if (!pass) {
            n = k;
            words = w;
            continue;
        }
        int64_t *recv = NULL, *order = NULL;
        int *rcount = NULL;
        int rc = exchange(c, n, dest, ptr, data, &recv, &rcount, &order);
        free(dest), free(ptr), free(data), free(order);
        if (rc != 0)
            return -1;
        int64_t total = 0, ng = 0, nnew = 0;
        for (int q = 0; q < c->size; q++)
            total += rcount[q];
        for (int64_t at = 0; at < total; at += 4 + 5 * recv[at + 3]) {
            ng++;
            nnew += recv[at + 3];
        }
        dist_elem *el = realloc(s->elem, ((size_t)s->ne + (size_t)ng + 1) *
                                             sizeof *el);
        node_rec *nd = realloc(s->node, ((size_t)s->nn + (size_t)nnew + 1) *
                                            sizeof *nd);
        if (!el || !nd)
            dist_stop("out of memory");
        s->elem = el, s->node = nd;
        for (int64_t at = 0; at < total; at += 4 + 5 * recv[at + 3]) {
            dist_elem *g = &s->elem[s->ne++];
            g->tag = recv[at], g->type = (int)recv[at + 1];
            g->region = (int32_t)recv[at + 2], g->nv = (int)recv[at + 3];
            for (int j = 0; j < g->nv; j++) {
                const int64_t *x = recv + at + 4 + 5 * j;
                node_rec *r = &s->node[s->nn++];
                g->node[j] = r->tag = (uint64_t)x[0];
                memcpy(r->x, x + 1, sizeof r->x);
                r->fixed = x[4];
            }
        }
        free(recv), free(rcount);
    }
    char msg[200];
    int bad = dist_merge_nodes(s, msg, sizeof msg) != 0, any = 0;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, c->comm);
    return any ? -1 : 0;
}

/* ---- the part ------------------------------------------------------------ */

/* The rank's part into c (the arrays partition.c fills otherwise). */
static void fill_ctx(const dist_split *s, dist_ctx *c)
{
    c->nn = s->nn;
    c->ne = s->ne;
    c->coords = dist_xalloc((size_t)s->nn * 3 * sizeof *c->coords);
    c->fixed = dist_xalloc((size_t)s->nn);
    c->gid = dist_xalloc((size_t)s->nn * sizeof *c->gid);
    c->counted = dist_xalloc((size_t)s->nn);
    c->etype = dist_xalloc((size_t)s->ne);
    c->owned = dist_xalloc((size_t)s->ne);
    c->nconn = 0;
    for (int32_t e = 0; e < s->ne; e++)
        c->nconn += s->elem[e].nv;
    c->conn = dist_xalloc((size_t)c->nconn * sizeof *c->conn);
    for (int32_t i = 0; i < s->nn; i++) {
        memcpy(c->coords + 3 * (size_t)i, s->node[i].x, 3 * sizeof(double));
        c->fixed[i] = s->node[i].fixed != 0;
        c->gid[i] = i;
        int lowest = 1;
        for (int64_t h = s->optr[i]; h < s->optr[i + 1]; h++)
            lowest &= s->orank[h] > c->rank;
        c->counted[i] = (uint8_t)lowest;
    }
    int64_t m = 0;
    for (int32_t e = 0; e < s->ne; e++) {
        c->etype[e] = (uint8_t)s->elem[e].type;
        c->owned[e] = e < s->own_ne;
        for (int j = 0; j < s->elem[e].nv; j++)
            c->conn[m++] = dist_find_node(s, s->elem[e].node[j]);
    }
    /* neighbours: per rank, the shared nodes in ascending tag */
    if (dist_neighbours(c, s->nn, s->optr, s->orank) != 0)
        dist_stop("out of memory");
}

/* What an element order of the whole mesh needs on every rank (the
   finishing step on gathered patches breaks ties by the Morton key of an
   element's first node in the whole mesh's box, then by its index in the
   single-process order): the box, and whether the element tags are one
   dense run (Gmsh numbers a file's volume elements consecutively in its
   order), in which case that index is tag - tag_min. */
static void order_keys(dist_split *s, dist_ctx *c)
{
    double lo[3] = {1e308, 1e308, 1e308}, hi[3] = {-1e308, -1e308, -1e308};
    for (int32_t i = 0; i < s->nn; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = s->node[i].x[k] < lo[k] ? s->node[i].x[k] : lo[k];
            hi[k] = s->node[i].x[k] > hi[k] ? s->node[i].x[k] : hi[k];
        }
    MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPI_DOUBLE, MPI_MIN, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPI_DOUBLE, MPI_MAX, c->comm);
    int64_t tmin = INT64_MAX, tmax = INT64_MIN, n = s->own_ne;
    for (int32_t e = 0; e < s->own_ne; e++) {
        tmin = s->elem[e].tag < tmin ? s->elem[e].tag : tmin;
        tmax = s->elem[e].tag > tmax ? s->elem[e].tag : tmax;
    }
    MPI_Allreduce(MPI_IN_PLACE, &tmin, 1, MPI_INT64_T, MPI_MIN, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, &tmax, 1, MPI_INT64_T, MPI_MAX, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT64_T, MPI_SUM, c->comm);
    for (int k = 0; k < 3; k++) {
        s->box[k] = lo[k];
        s->box[3 + k] = hi[k];
    }
    s->tag_min = tmin;
    s->dense_tags = tmax - tmin + 1 == n; /* tags are distinct */
}

int dist_split_setup(dist_split *s, dist_ctx *c, unsigned fix_flags)
{
    if (mark_faces(s, c, fix_flags) != 0 || directory(s, c) != 0 ||
        ghosts(s, c) != 0 || directory(s, c) != 0)
        return -1;
    fill_ctx(s, c);
    int64_t mine[2] = {0, s->ne - s->own_ne}, all[2];
    for (int32_t i = 0; i < s->nn; i++)
        mine[0] += c->counted[i] && s->optr[i + 1] > s->optr[i];
    MPI_Allreduce(mine, all, 2, MPI_INT64_T, MPI_SUM, c->comm);
    c->interface_nodes = all[0];
    c->ghost_elements = all[1];
    order_keys(s, c);
    return 0;
}

