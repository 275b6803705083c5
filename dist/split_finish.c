/*
 * split_finish.c -- what the per-rank input needs around the finishing
 * step on a sub-mesh (dist/finish_sub.c; docs/distributed.md §3,
 * "Finishing"): global node ids and element indices from the parts, the
 * whole mesh's quality statistics reduced over the parts, and for one
 * partitioned file the final positions on rank 0 for the write.
 *
 * Why no whole mesh: rank 0 used to gather every element and node to run
 * getme_smooth_finish on one process, so a mesh that outgrows one machine
 * could not be finished.  finish_sub.c needs only per element a key (type,
 * Morton code in the whole mesh's box, index in the single-process order)
 * and per node a global id, which each rank computes for its own part.
 */
#include "dist.h"
#include "cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* 128-bit integers for getme_finish_rest's exact sum (gcc, clang) */
__extension__ typedef __int128 i128;
__extension__ typedef unsigned __int128 u128;

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Every rank's n int64 on rank 0 (counts and offsets there too). */
static int64_t *gather_i64(dist_ctx *c, const int64_t *mine, int n,
                           int **counts, int **displs, int *total)
{
    *counts = *displs = NULL;
    *total = 0;
    if (c->rank == 0) {
        *counts = dist_xalloc((size_t)c->size * sizeof **counts);
        *displs = dist_xalloc((size_t)c->size * sizeof **displs);
    }
    MPI_Gather(&n, 1, MPI_INT, *counts, 1, MPI_INT, 0, c->comm);
    int64_t t = 0;
    for (int q = 0; c->rank == 0 && q < c->size; q++) {
        (*displs)[q] = (int)t;
        t += (*counts)[q];
        if (t > INT32_MAX)
            dist_stop("too many elements to number on rank 0");
    }
    *total = (int)t;
    int64_t *all = c->rank == 0
                       ? dist_xalloc((size_t)(t ? t : 1) * sizeof *all)
                       : NULL;
    MPI_Gatherv(mine, n, MPI_INT64_T, all, *counts, *displs, MPI_INT64_T, 0,
                c->comm);
    return all;
}

/* Element tags not one dense run: each owned element's rank among all
   element tags, computed on rank 0 (16 bytes per element of the whole
   mesh there, for this call only). */
static void rank_tags(dist_split *s, dist_ctx *c)
{
    int64_t *mine = dist_xalloc((size_t)(s->own_ne ? s->own_ne : 1) *
                                sizeof *mine);
    for (int32_t e = 0; e < s->own_ne; e++)
        mine[e] = s->elem[e].tag;
    int *counts, *displs, total;
    int64_t *all = gather_i64(c, mine, s->own_ne, &counts, &displs, &total);
    int32_t *idx = NULL;
    if (c->rank == 0) {
        int64_t *sorted = dist_xalloc((size_t)(total ? total : 1) *
                                      sizeof *sorted);
        memcpy(sorted, all, (size_t)total * sizeof *sorted);
        qsort(sorted, (size_t)total, sizeof *sorted, cmp_i64);
        idx = dist_xalloc((size_t)(total ? total : 1) * sizeof *idx);
        for (int i = 0; i < total; i++) {
            int lo = 0, hi = total - 1;
            while (lo < hi) { /* tags are distinct */
                int mid = lo + (hi - lo) / 2;
                if (sorted[mid] < all[i])
                    lo = mid + 1;
                else
                    hi = mid;
            }
            idx[i] = lo;
        }
        free(sorted);
    }
    MPI_Scatterv(idx, counts, displs, MPI_INT32_T, c->egid, s->own_ne,
                 MPI_INT32_T, 0, c->comm);
    free(mine), free(all), free(idx), free(counts), free(displs);
}

/* Node ids and element indices for the keys (collective).  The
   single-process order is the unpartitioned file's: nodes and elements in
   ascending tag (Gmsh numbers both in its file order; getme smooth on the
   merged partitioned input reads them so, checked by the tests with
   --param renumber=0, where the index alone orders the elements). */
int dist_split_ids(dist_split *s, dist_ctx *c, char *msg, size_t size)
{
    int bad = 0;
    for (int32_t i = 0; i < s->nn; i++) {
        bad |= s->node[i].tag > (uint64_t)INT32_MAX;
        c->gid[i] = (int32_t)s->node[i].tag; /* ascending, as the part */
    }
    MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_MAX, c->comm);
    if (bad) {
        snprintf(msg, size, "node tags above 2^31-1 (32-bit node ids)");
        return -1;
    }
    c->egid = dist_xalloc((size_t)(s->ne ? s->ne : 1) * sizeof *c->egid);
    for (int32_t e = s->own_ne; e < s->ne; e++)
        c->egid[e] = -1; /* ghosts: their owners key them */
    /* GETME_MPI_RANK_TAGS=1 (tests): rank the tags even when dense */
    const char *force = getenv("GETME_MPI_RANK_TAGS");
    if (s->dense_tags && !(force && atoi(force) == 1))
        for (int32_t e = 0; e < s->own_ne; e++)
            c->egid[e] = (int32_t)(s->elem[e].tag - s->tag_min);
    else
        rank_tags(s, c);
    free(s->elem), free(s->optr), free(s->orank); /* the set-up's tables */
    s->elem = NULL, s->optr = NULL, s->orank = NULL;
    return 0;
}

/* The whole mesh's quality statistics on rank 0, as
   getme_mesh_quality_stats gives them (counts, minima, maximum, histogram,
   exact fixed-point sum for q_mean), reduced over the owned elements of
   the parts.  first_invalid is not filled.  0, or -1 on every rank (out
   of memory). */
int dist_split_stats(dist_ctx *c, getme_mesh *part, getme_quality_stats *out)
{
    getme_quality_stats s;
    memset(&s, 0, sizeof s);
    double *q = malloc((size_t)(c->ne ? c->ne : 1) * sizeof *q);
    int ok = q && getme_mesh_element_qualities(part, q) == GETME_OK;
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, c->comm);
    if (!ok) {
        free(q);
        return -1;
    }
    double mins[2] = {1.0, 1.0}, qmax = 0.0;
    int64_t off = 0;
    for (int32_t e = 0; e < c->ne; e++) {
        int nv = getme_type_num_nodes((getme_elem_type)c->etype[e]);
        const int32_t *cn = c->conn + off;
        off += nv;
        double v = q[e];
        if (!(v > 0.0))
            v = 0.0; /* an invalid element counts as 0 (stats.c) */
        q[e] = v; /* the exact sum below adds these */
        if (!c->owned[e])
            continue;
        int has_free = 0;
        for (int i = 0; i < nv; i++)
            has_free |= !c->fixed[cn[i]];
        s.num_elements++;
        if (v > 0.0) {
            int bin = (int)(v * GETME_HIST_BINS);
            s.histogram[bin >= GETME_HIST_BINS ? GETME_HIST_BINS - 1 : bin]++;
        } else {
            s.num_invalid++;
        }
        mins[0] = v < mins[0] ? v : mins[0];
        qmax = v > qmax ? v : qmax;
        if (has_free) {
            s.num_free++;
            mins[1] = v < mins[1] ? v : mins[1];
        }
        s.num_below_04 += v <= 0.4;
        s.num_below_01 += v < 0.1;
    }
    /* the exact sum: getme_finish_rest's (the same fixed point as q_mean) */
    getme_finish_rest rest, *all = NULL;
    getme_finish_rest_init(&rest);
    getme_finish_rest_add(&rest, part, c->owned, q);
    free(q);
    if (c->rank == 0)
        all = dist_xalloc((size_t)c->size * sizeof *all);
    MPI_Gather(&rest, (int)sizeof rest, MPI_BYTE, all, (int)sizeof rest,
               MPI_BYTE, 0, c->comm);
    int64_t counts[5 + GETME_HIST_BINS] = {s.num_elements, s.num_invalid,
                                           s.num_free, s.num_below_04,
                                           s.num_below_01};
    memcpy(counts + 5, s.histogram, sizeof s.histogram);
    MPI_Allreduce(MPI_IN_PLACE, counts, 5 + GETME_HIST_BINS, MPI_INT64_T,
                  MPI_SUM, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, mins, 2, MPI_DOUBLE, MPI_MIN, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, &qmax, 1, MPI_DOUBLE, MPI_MAX, c->comm);
    if (c->rank == 0) {
        for (int r = 1; r < c->size; r++)
            getme_finish_rest_merge(&all[0], &all[r]);
        memset(out, 0, sizeof *out);
        out->num_elements = counts[0], out->num_invalid = counts[1];
        out->num_free = counts[2], out->num_below_04 = counts[3];
        out->num_below_01 = counts[4];
        memcpy(out->histogram, counts + 5, sizeof out->histogram);
        out->q_min = mins[0], out->q_min_star = mins[1], out->q_max = qmax;
        /* q_sum * 2^-90 rounded once to double (exact.h's conversion) */
        i128 sum = (i128)(((u128)all[0].q_sum[1] << 64) | all[0].q_sum[0]);
        out->q_mean = out->num_elements
                          ? (double)sum * 0x1p-90 / (double)out->num_elements
                          : 0.0;
        if (out->num_elements == 0)
            out->q_min = out->q_max = 0.0;
    }
    free(all);
    return 0;
}

/* One partitioned file: the counted nodes' final positions on rank 0 in
   ascending tag (s->whole_tag, *xyz; 32 bytes per node of the whole mesh,
   which the write's re-read of the whole file on rank 0 needs anyway). */
void dist_split_gather(dist_split *s, dist_ctx *c, const double *part_xyz,
                       double **xyz)
{
    int64_t n = 0;
    for (int32_t i = 0; i < s->nn; i++)
        n += c->counted[i];
    if (4 * n > INT32_MAX)
        dist_stop("a part too large to gather");
    int64_t *mine = dist_xalloc((size_t)(n ? n : 1) * 4 * sizeof *mine);
    int64_t w = 0;
    for (int32_t i = 0; i < s->nn; i++) /* ascending tag */
        if (c->counted[i]) {
            mine[w++] = (int64_t)s->node[i].tag;
            memcpy(mine + w, part_xyz + 3 * (size_t)i, 3 * sizeof *mine);
            w += 3;
        }
    int *counts, *displs, total;
    int64_t *all = gather_i64(c, mine, (int)w, &counts, &displs, &total);
    free(mine), free(counts), free(displs);
    *xyz = NULL;
    if (c->rank != 0)
        return;
    /* each rank's run ascends: sort the records by tag */
    int32_t nn = total / 4;
    qsort(all, (size_t)nn, 4 * sizeof *all, cmp_i64);
    s->whole_nn = nn;
    s->whole_tag = dist_xalloc((size_t)(nn ? nn : 1) * sizeof *s->whole_tag);
    *xyz = dist_xalloc((size_t)(nn ? nn : 1) * 3 * sizeof **xyz);
    for (int32_t i = 0; i < nn; i++) {
        s->whole_tag[i] = (uint64_t)all[4 * (size_t)i];
        memcpy(*xyz + 3 * (size_t)i, all + 4 * (size_t)i + 1, 3 * sizeof **xyz);
    }
    free(all);
}

/* getme smooth's "Measures" lines, reduced over the parts' owned elements:
   per element type the dihedral range and each measure's minimum (and
   negative count), which are exact.  Their means are not printed: getme
   smooth sums the values in element order in doubles, a sum the parts
   cannot reproduce bit for bit.  Collective; rank 0 logs. */
void dist_split_measures(dist_ctx *c, getme_mesh *part, const cli_log *log,
                         const char *title)
{
    enum { T = GETME_NUM_TYPES, M = GETME_NUM_MEASURES };
    /* per type and measure: -min, max (one MPI_MAX), count, negatives */
    double ext[2 * T * M];
    int64_t cnt[2 * T * M];
    for (int i = 0; i < T * M; i++)
        ext[2 * i] = ext[2 * i + 1] = -1e308, cnt[2 * i] = cnt[2 * i + 1] = 0;
    double *v = malloc((size_t)(c->ne ? c->ne : 1) * sizeof *v);
    int ok = v != NULL;
    for (int k = GETME_MEASURE_MIN_DIHEDRAL; ok && k < M; k++) {
        if (getme_mesh_element_measures(part, (getme_measure)k, v) !=
            GETME_OK) {
            ok = 0;
            break;
        }
        for (int32_t e = 0; e < c->ne; e++) {
            if (!c->owned[e] || v[e] != v[e])
                continue; /* a ghost, or not defined (NaN) */
            int i = c->etype[e] * M + k;
            ext[2 * i] = -v[e] > ext[2 * i] ? -v[e] : ext[2 * i];
            ext[2 * i + 1] = v[e] > ext[2 * i + 1] ? v[e] : ext[2 * i + 1];
            cnt[2 * i]++;
            cnt[2 * i + 1] += v[e] < 0.0;
        }
    }
    free(v);
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, c->comm);
    if (!ok) {
        cli_warning(log, "%s: out of memory", title);
        return;
    }
    MPI_Allreduce(MPI_IN_PLACE, ext, 2 * T * M, MPI_DOUBLE, MPI_MAX, c->comm);
    MPI_Allreduce(MPI_IN_PLACE, cnt, 2 * T * M, MPI_INT64_T, MPI_SUM,
                  c->comm);
    static const char *const label[M] = {"", "", "", "scaled Jacobian",
                                         "gamma", "SICN"};
    for (int t = 0; c->rank == 0 && t < T; t++) {
        const double *x = ext + 2 * t * M;
        const int64_t *n = cnt + 2 * t * M;
        if (!n[2 * GETME_MEASURE_MIN_DIHEDRAL])
            continue;
        char line[512];
        int used = snprintf(line, sizeof line, "dihedral %.2f to %.2f deg",
                            -x[2 * GETME_MEASURE_MIN_DIHEDRAL],
                            x[2 * GETME_MEASURE_MAX_DIHEDRAL + 1]);
        for (int k = GETME_MEASURE_SCALED_JACOBIAN; k < M; k++) {
            if (!n[2 * k] || used >= (int)sizeof line)
                continue;
            used += snprintf(line + used, sizeof line - (size_t)used,
                             ", %s min %.4f", label[k], -x[2 * k]);
            if (n[2 * k + 1] && used < (int)sizeof line)
                used += snprintf(line + used, sizeof line - (size_t)used,
                                 " (%lld negative)", (long long)n[2 * k + 1]);
        }
        cli_info(log, "%s (%s): %s", title,
                 getme_type_name((getme_elem_type)t), line);
    }
}
