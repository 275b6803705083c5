/*
 * cgns_names.c -- the names a user can give to --fix / --free for a CGNS
 * file: BC names, family names (Family_t, FamilyName and
 * AdditionalFamilyName of BCs, zones and sections), zone names and section
 * names.  CGNS names are case-sensitive, so is the matching here.
 */
#include "cgns_internal.h"
#include "getme_alloc.h"

#include <stdlib.h>
#include <string.h>

getme_formats_status cgns_add_set(getme_doc *doc, cgns_impl *impl,
                             cgns_set_kind kind, const char *name)
{
    if (name[0] == '\0')
        return GETME_FORMATS_OK;
    for (int i = 0; i < impl->num_sets; i++)
        if (impl->sets[i].kind == kind && strcmp(impl->sets[i].name, name) == 0)
            return GETME_FORMATS_OK;
    if (impl->num_sets == impl->cap_sets) {
        int cap = impl->cap_sets ? 2 * impl->cap_sets : 32;
        cgns_set_name *s = getme__realloc(impl->sets, (size_t)cap * sizeof *s);
        if (!s)
            return getme_doc_fail(doc, GETME_FORMATS_ERR_INTERNAL,
                                  "%s: out of memory", doc->path);
        impl->sets = s;
        impl->cap_sets = cap;
    }
    impl->sets[impl->num_sets].kind = kind;
    snprintf(impl->sets[impl->num_sets].name, CGNS_NAME_LEN, "%s", name);
    impl->num_sets++;
    return GETME_FORMATS_OK;
}

getme_formats_status cgns_read_fams(getme_doc *doc, cgns_impl *impl,
                               cgns_fams *fams)
{
    char name[CGNS_NAME_LEN], fam[CGNS_NAME_LEN];
    int n = 0;

    fams->count = 0;
    /* cg_famname_read: CG_NODE_NOT_FOUND simply means "no family". */
    if (cg_famname_read(fam) == CG_OK && fam[0] != '\0')
        snprintf(fams->name[fams->count++], CGNS_NAME_LEN, "%s", fam);
    if (cg_nmultifam(&n) != CG_OK)
        n = 0;
    for (int i = 1; i <= n && fams->count < CGNS_MAX_FAMS; i++)
        if (cg_multifam_read(i, name, fam) == CG_OK && fam[0] != '\0')
            snprintf(fams->name[fams->count++], CGNS_NAME_LEN, "%s", fam);
    for (int i = 0; i < fams->count; i++) {
        getme_formats_status st = cgns_add_set(doc, impl, CGNS_SET_FAMILY,
                                          fams->name[i]);
        if (st != GETME_FORMATS_OK)
            return st;
    }
    return GETME_FORMATS_OK;
}

static int name_exists(const cgns_impl *impl, const char *name)
{
    for (int i = 0; i < impl->num_sets; i++)
        if (strcmp(impl->sets[i].name, name) == 0)
            return 1;
    return 0;
}

/* Append s to buf (len bytes used); -1 when it does not fit. */
static int append(char *buf, size_t size, size_t *len, const char *s)
{
    size_t n = strlen(s);
    if (*len + n + 1 > size)
        return -1;
    memcpy(buf + *len, s, n + 1);
    *len += n;
    return 0;
}

/* "BCs: inlet, wall; families: ...; zones: ...; sections: ..." into buf,
   cut with "..." when it does not fit. */
static void list_available(const cgns_impl *impl, char *buf, size_t size)
{
    static const char *const title[CGNS_SET_KINDS] = {"BCs: ", "families: ",
                                                      "zones: ", "sections: "};
    size_t len = 0;
    int err = 0;

    buf[0] = '\0';
    for (int k = 0; k < CGNS_SET_KINDS && !err; k++) {
        int first = 1;
        for (int i = 0; i < impl->num_sets && !err; i++) {
            if ((int)impl->sets[i].kind != k)
                continue;
            if (first && len)
                err |= append(buf, size, &len, "; ");
            err |= append(buf, size, &len, first ? title[k] : ", ");
            err |= append(buf, size, &len, impl->sets[i].name);
            first = 0;
        }
    }
    if (err && size > 4)
        strcpy(buf + (len + 4 < size ? len : size - 4), "...");
    else if (len == 0)
        snprintf(buf, size, "none");
}

getme_formats_status cgns_check_names(getme_doc *doc, const cgns_impl *impl,
                                 const getme_doc_options *opts)
{
    char avail[640];

    for (int pass = 0; pass < 2; pass++) {
        int n = pass ? opts->num_free : opts->num_fix;
        const char *const *list = pass ? opts->free_sets : opts->fix;
        for (int i = 0; i < n; i++) {
            if (!list || !list[i])
                return getme_doc_fail(doc, GETME_FORMATS_ERR_ARGUMENT,
                                      "%s: empty set name", doc->path);
            if (name_exists(impl, list[i]))
                continue;
            list_available(impl, avail, sizeof avail);
            return getme_doc_fail(doc, GETME_FORMATS_ERR_ARGUMENT,
                                  "%s: no BC, family, zone or section named "
                                  "'%s' (names are case-sensitive; "
                                  "available: %s)",
                                  doc->path, list[i], avail);
        }
    }
    for (int i = 0; i < opts->num_fix; i++)
        if (cgns_named(opts->fix[i], NULL, opts->num_free, opts->free_sets))
            return getme_doc_fail(doc, GETME_FORMATS_ERR_ARGUMENT,
                                  "%s: '%s' is both fixed and freed",
                                  doc->path, opts->fix[i]);
    return GETME_FORMATS_OK;
}

int cgns_named(const char *name, const cgns_fams *fams, int count,
               const char *const *list)
{
    for (int i = 0; i < count; i++) {
        if (!list[i])
            continue;
        if (name && name[0] && strcmp(name, list[i]) == 0)
            return 1;
        for (int f = 0; fams && f < fams->count; f++)
            if (strcmp(fams->name[f], list[i]) == 0)
                return 1;
    }
    return 0;
}

int cgns_default_fixed(const char *name, const cgns_fams *fams,
                       const getme_doc_options *opts)
{
    if (cgns_named(name, fams, opts->num_fix, opts->fix))
        return 1;
    return !cgns_named(name, fams, opts->num_free, opts->free_sets);
}
