/*
 * split_common.c -- what the per-rank input's files share (split.c,
 * split_setup.c, split_finish.c; docs/distributed.md §3): the set-up's
 * allocation (a failure there stops the run), the node table's lookup and
 * merge by tag.
 */
#include "dist.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef dist_node node_rec;


/* A failure inside the set-up's exchanges (out of memory, limits) stops
   the run: other ranks may be inside a collective call; there is no
   output yet. */
void dist_stop(const char *why)
{
    fprintf(stderr, "Error   : %s setting up the parts; no output "
                    "written\n", why);
    MPI_Abort(MPI_COMM_WORLD, 1);
}

void *dist_xalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p)
        dist_stop("out of memory");
    return p;
}

int dist_cmp_node(const void *a, const void *b)
{
    const node_rec *x = a, *y = b;
    return (x->tag > y->tag) - (x->tag < y->tag);
}

/* Index of tag among n records sorted by tag, the tag the first 8 bytes
   of each stride-byte record; -1 if absent. */
static int32_t tag_index(const void *recs, size_t stride, int32_t n,
                         uint64_t tag)
{
    int32_t lo = 0, hi = n;
    uint64_t t;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        memcpy(&t, (const char *)recs + (size_t)mid * stride, sizeof t);
        if (t < tag)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo < n)
        memcpy(&t, (const char *)recs + (size_t)lo * stride, sizeof t);
    return lo < n && t == tag ? lo : -1;
}

int32_t dist_find_node(const dist_split *s, uint64_t tag)
{
    return tag_index(s->node, sizeof *s->node, s->nn, tag);
}

int32_t whole_index(const dist_split *s, uint64_t tag)
{
    return tag_index(s->whole_tag, sizeof *s->whole_tag, s->whole_nn, tag);
}

/* Sort the node table by tag and merge the copies of a node (the fixed
   marks ORed; copies must have the same coordinates).  0 or -1 (msg). */
int dist_merge_nodes(dist_split *s, char *msg, size_t size)
{
    qsort(s->node, (size_t)s->nn, sizeof *s->node, dist_cmp_node);
    int32_t k = 0;
    for (int32_t i = 0; i < s->nn; i++) {
        if (k > 0 && s->node[k - 1].tag == s->node[i].tag) {
            if (memcmp(s->node[k - 1].x, s->node[i].x, sizeof s->node[i].x)) {
                snprintf(msg, size, "node %llu has different coordinates "
                         "in two parts", (unsigned long long)s->node[i].tag);
                return -1;
            }
            s->node[k - 1].fixed |= s->node[i].fixed;
        } else {
            s->node[k++] = s->node[i];
        }
    }
    s->nn = k;
    return 0;
}

