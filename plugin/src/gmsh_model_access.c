/*
 * gmsh_model_access.c -- the mesh of a getme_gmsh_model and the element
 * descriptions used in messages.
 */
#include "gmsh_internal.h"

#include <stdio.h>

getme_mesh *getme_gmsh_model_mesh(getme_gmsh_model *m)
{
    return m ? m->mesh : NULL;
}

getme_mesh *gg_model_take_mesh(getme_gmsh_model *m)
{
    if (!m)
        return NULL;
    getme_mesh *mesh = m->mesh;
    m->mesh = NULL;
    return mesh;
}

/* Block holding element e (blocks are in element order): bisection. */
static const gg_block *find_block(const getme_gmsh_model *m, int32_t e)
{
    int lo = 0, hi = m->num_blocks - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (m->blocks[mid].first <= e)
            lo = mid;
        else
            hi = mid - 1;
    }
    return m->num_blocks ? &m->blocks[lo] : NULL;
}

void gg_describe_element(const getme_gmsh_model *m, int32_t e, char *buf,
                         size_t size)
{
    if (!buf || !size)
        return;
    if (!m || e < 0 || e >= m->num_elements) {
        snprintf(buf, size, "element #%ld", (long)e);
        return;
    }
    const gg_block *b = find_block(m, e);
    snprintf(buf, size, "%s %zu in %s %d",
             getme_type_name((getme_elem_type)b->type), m->elem_tags[e],
             gg_dim_word(b->dim), b->tag);
}
