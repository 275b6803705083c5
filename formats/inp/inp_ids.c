/*
 * inp_ids.c -- file id -> index lookup for nodes and elements, per scope
 * (each Abaqus part numbers its nodes from 1 again).  Where a scope's ids
 * are dense, as Gmsh and most pre-processors write them, a direct table of
 * 4 bytes per id; where they are sparse, one shared open-addressing hash.
 */
#include "inp_internal.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

static int64_t key(int scope, int64_t id)
{
    return ((int64_t)scope << 32) | (int64_t)(uint32_t)id;
}

static int scan_ranges(inp_ids *m, const int32_t *id, const inp_run *runs,
                       size_t nruns, int64_t *count)
{
    for (size_t s = 0; s < m->nscopes; s++) {
        m->min[s] = INT64_MAX;
        m->range[s] = INT64_MIN; /* max for now */
    }
    for (size_t r = 0; r < nruns; r++) {
        int s = runs[r].scope;
        for (int32_t i = runs[r].first; i < runs[r].first + runs[r].count; i++) {
            if (id[i] < m->min[s])
                m->min[s] = id[i];
            if (id[i] > m->range[s])
                m->range[s] = id[i];
        }
        count[s] += runs[r].count;
    }
    return 0;
}

int inp_ids_build(inp_ids *m, size_t nscopes, const int32_t *id,
                  const inp_run *runs, size_t nruns, int32_t *dup_first,
                  int32_t *dup_second)
{
    memset(m, 0, sizeof *m);
    m->nscopes = nscopes;
    m->min = getme__calloc(nscopes ? nscopes : 1, sizeof *m->min);
    m->range = getme__calloc(nscopes ? nscopes : 1, sizeof *m->range);
    m->table = getme__calloc(nscopes ? nscopes : 1, sizeof *m->table);
    int64_t *count = getme__calloc(nscopes ? nscopes : 1, sizeof *count);
    if (!m->min || !m->range || !m->table || !count) {
        free(count);
        return -1;
    }
    scan_ranges(m, id, runs, nruns, count);
    for (size_t s = 0; s < nscopes; s++) {
        int64_t span = count[s] ? m->range[s] - m->min[s] + 1 : 0;
        /* Dense enough: a table costs at most about twice the hash. */
        m->range[s] = span > 0 && span <= 4 * count[s] + 1024 ? span : 0;
        if (!m->range[s])
            continue;
        m->table[s] = getme__malloc((size_t)span * sizeof **m->table);
        if (!m->table[s]) {
            free(count);
            return -1;
        }
        memset(m->table[s], 0xff, (size_t)span * sizeof **m->table);
    }
    free(count);
    for (size_t r = 0; r < nruns; r++) {
        int s = runs[r].scope;
        for (int32_t i = runs[r].first; i < runs[r].first + runs[r].count; i++) {
            int32_t old = -1;
            if (m->range[s]) {
                int32_t *slot = &m->table[s][id[i] - m->min[s]];
                old = *slot;
                if (old < 0)
                    *slot = i;
            } else {
                int rc = inp_hash_put(&m->sparse, key(s, id[i]), i, &old);
                if (rc < 0)
                    return -1;
                if (rc == 0)
                    old = -1;
            }
            if (old >= 0) {
                *dup_first = old;
                *dup_second = i;
                return 1;
            }
        }
    }
    return 0;
}

int32_t inp_ids_get(const inp_ids *m, int scope, int64_t id)
{
    if (scope < 0 || (size_t)scope >= m->nscopes)
        return -1;
    if (m->range[scope]) {
        int64_t k = id - m->min[scope];
        return k >= 0 && k < m->range[scope] ? m->table[scope][k] : -1;
    }
    return inp_hash_get(&m->sparse, key(scope, id));
}

void inp_ids_free(inp_ids *m)
{
    for (size_t s = 0; m->table && s < m->nscopes; s++)
        free(m->table[s]);
    free(m->table);
    free(m->min);
    free(m->range);
    inp_hash_free(&m->sparse);
    memset(m, 0, sizeof *m);
}
