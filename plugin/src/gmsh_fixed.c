/*
 * gmsh_fixed.c -- which nodes of a Gmsh model must not move.
 *
 * docs/design.md §5 for Gmsh models: a node may move only if it is
 * classified on one of the entities being smoothed.  Nodes classified on
 * lower-dimensional entities (bounding surfaces, interfaces between
 * volumes, curves, points, embedded entities) carry the geometry and stay
 * put, as do the nodes of the physical groups the user names.
 */
#include "gmsh_internal.h"

#include <gmshc.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Mark the nodes classified on entity (dim, tag) as free (OWN). */
static void own_nodes(int dim, int tag, const getme__nodemap *all,
                      uint8_t *flags)
{
    size_t *tags = NULL, nt = 0, nc = 0, np = 0;
    double *coord = NULL, *param = NULL;
    int ierr = 0;
    gmshModelMeshGetNodes(&tags, &nt, &coord, &nc, &param, &np, dim, tag, 0,
                          0, &ierr);
    for (size_t i = 0; !ierr && i < nt; i++) {
        int32_t k = getme__nodemap_find(all, tags[i]);
        if (k >= 0)
            flags[k] |= GETME__NODE_OWN;
    }
    gmshFree(tags);
    gmshFree(coord);
    gmshFree(param);
}

/* The model entity a partitioned entity (gmsh -part) belongs to, or the
   entity itself when it has no parent. */
static void parent_of(int dim, int tag, int *pdim, int *ptag)
{
    int ierr = 0;
    *pdim = -1;
    *ptag = -1;
    gmshModelGetParent(dim, tag, pdim, ptag, &ierr);
    if (ierr || *pdim < 0) {
        *pdim = dim;
        *ptag = tag;
    }
}

getme_status gg_fix_classified(const getme_gmsh_model *model,
                               const getme__nodemap *all, uint8_t *flags,
                               gg_msg *msg)
{
    for (int e = 0; e < model->num_entities; e++)
        own_nodes(model->entities[2 * e], model->entities[2 * e + 1], all,
                  flags);
    /* A partitioned model (gmsh -part): the boundaries between partitions
       are entities of lower dimension whose parent is a smoothed entity
       (the volume they cut), not a model surface or curve.  They are no
       geometry: their nodes move as the rest of the volume's.  Pieces of
       model surfaces and curves have those as parents and stay fixed. */
    int *parents = malloc(((size_t)model->num_entities + 1) * sizeof *parents);
    if (!parents)
        return gg_fail(msg, GETME_ERR_NOMEM, "Out of memory");
    int np = 0;
    for (int e = 0; e < model->num_entities; e++) {
        int sdim, stag;
        parent_of(model->entities[2 * e], model->entities[2 * e + 1], &sdim,
                  &stag);
        if (sdim == model->dim)
            parents[np++] = stag;
    }
    int *dt = NULL;
    size_t n = 0;
    int ierr = 0;
    gmshModelGetEntities(&dt, &n, -1, &ierr);
    for (size_t i = 0; !ierr && np && i + 1 < n; i += 2) {
        if (dt[i] >= model->dim)
            continue;
        int pdim, ptag;
        parent_of(dt[i], dt[i + 1], &pdim, &ptag);
        if (pdim != model->dim)
            continue;
        for (int e = 0; e < np; e++)
            if (parents[e] == ptag) {
                own_nodes(dt[i], dt[i + 1], all, flags);
                break;
            }
    }
    free(parents);
    gmshFree(dt);
    return GETME_OK;
}

/* All physical groups as (dim, tag) pairs (gmsh-allocated). */
static void list_groups(int **dt, size_t *n)
{
    int ierr = 0;
    *dt = NULL;
    *n = 0;
    gmshModelGetPhysicalGroups(dt, n, -1, &ierr);
    if (ierr) {
        gmshFree(*dt);
        *dt = NULL;
        *n = 0;
    }
}

static int group_name_is(int dim, int tag, const char *want)
{
    char *name = NULL;
    int ierr = 0;
    gmshModelGetPhysicalName(dim, tag, &name, &ierr);
    int same = !ierr && name && strcmp(name, want) == 0;
    gmshFree(name);
    return same;
}

/* "a" (3:1), "b" (2:5)... for the error message. */
static void describe_groups(const int *dt, size_t n, char *buf, size_t size)
{
    size_t used = 0;
    buf[0] = 0;
    for (size_t i = 0; i + 1 < n && used + 1 < size; i += 2) {
        char *name = NULL;
        int ierr = 0;
        gmshModelGetPhysicalName(dt[i], dt[i + 1], &name, &ierr);
        int w = snprintf(buf + used, size - used, "%s\"%s\" (%d:%d)",
                         i ? ", " : "", name ? name : "", dt[i], dt[i + 1]);
        gmshFree(name);
        if (w < 0)
            break;
        used += (size_t)w;
    }
    if (!n)
        snprintf(buf, size, "the model has no physical groups");
}

static void fix_group_nodes(int dim, int tag, const getme__nodemap *all,
                            uint8_t *flags)
{
    size_t *tags = NULL, nt = 0, nc = 0;
    double *coord = NULL;
    int ierr = 0;
    gmshModelMeshGetNodesForPhysicalGroup(dim, tag, &tags, &nt, &coord, &nc,
                                          &ierr);
    for (size_t i = 0; !ierr && i < nt; i++) {
        int32_t k = getme__nodemap_find(all, tags[i]);
        if (k >= 0)
            flags[k] |= GETME__NODE_FIXGRP;
    }
    gmshFree(tags);
    gmshFree(coord);
}

/* Fix the groups matching one user word; 0 if none matched. */
static int fix_one(const char *word, const int *dt, size_t n,
                   const getme__nodemap *all, uint8_t *flags)
{
    int dim, tag, used = 0, found = 0;
    int by_tag = sscanf(word, "%d:%d%n", &dim, &tag, &used) == 2 &&
                 word[used] == 0;
    for (size_t i = 0; i + 1 < n; i += 2) {
        int match = by_tag ? (dt[i] == dim && dt[i + 1] == tag)
                           : group_name_is(dt[i], dt[i + 1], word);
        if (match) {
            if (flags)
                fix_group_nodes(dt[i], dt[i + 1], all, flags);
            found++;
        }
    }
    return found;
}

getme_status gg_fix_groups(const getme_gmsh_options *opt,
                           const getme__nodemap *all, uint8_t *flags,
                           gg_msg *msg)
{
    if (!opt || opt->num_fix == 0)
        return GETME_OK;
    int *dt = NULL;
    size_t n = 0;
    list_groups(&dt, &n);
    getme_status st = GETME_OK;
    for (int g = 0; g < opt->num_fix && st == GETME_OK; g++) {
        if (fix_one(opt->fix[g], dt, n, all, flags))
            continue;
        char known[300];
        describe_groups(dt, n, known, sizeof known);
        st = gg_fail(msg, GETME_ERR_ARGUMENT,
                     "Unknown physical group '%s' to fix (%s)", opt->fix[g],
                     known);
    }
    gmshFree(dt);
    return st;
}

getme_status getme_gmsh_check_groups(const char *const *names, int n,
                                     const char *what, char *msg, size_t size)
{
    int *dt = NULL;
    size_t nd = 0;
    list_groups(&dt, &nd);
    getme_status st = GETME_OK;
    if (msg && size)
        msg[0] = 0;
    for (int g = 0; g < n && st == GETME_OK; g++) {
        if (fix_one(names[g], dt, nd, NULL, NULL))
            continue;
        char known[300];
        describe_groups(dt, nd, known, sizeof known);
        if (msg && size)
            snprintf(msg, size, "Unknown physical group '%s' to %s (%s)",
                     names[g], what ? what : "use", known);
        st = GETME_ERR_ARGUMENT;
    }
    gmshFree(dt);
    return st;
}
