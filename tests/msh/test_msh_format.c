/*
 * test_msh_format.c -- the MSH adapter: MSH 2.2 and 4.1, ASCII and binary
 * round trips through getme_doc_open / distort / getme_doc_write.  The
 * written file has the input's header, node tags, element tags and
 * connectivity, physical groups (names included) and elements outside any
 * physical group; only coordinates of free nodes differ.  Two documents
 * are opened one after the other in the same process.
 */
#include "check.h"
#include "getme_formats.h"

#include <gmshc.h>

#include "gmsh_boxes.h"

#include <stdlib.h>
#include <string.h>

static void build_files(void)
{
    int ierr = 0;
    gmshInitialize(0, NULL, 0, &ierr);
    gmshOptionSetNumber("General.Terminal", 0, &ierr);
    two_material_boxes("src", 1); /* volume 3 in no group */
    gmshOptionSetNumber("Mesh.MeshSizeMax", 0.25, &ierr);
    gmshModelMeshGenerate(3, &ierr);
    const char *names[4] = {"in22a.msh", "in22b.msh", "in41a.msh",
                            "in41b.msh"};
    for (int i = 0; i < 4; i++) {
        gmshOptionSetNumber("Mesh.MshFileVersion", i < 2 ? 2.2 : 4.1, &ierr);
        gmshOptionSetNumber("Mesh.Binary", i % 2, &ierr);
        /* MSH 2.2 with SaveAll drops physical tags: write it as users do. */
        gmshOptionSetNumber("Mesh.SaveAll", i < 2 ? 0 : 1, &ierr);
        gmshWrite(names[i], &ierr);
        CHECK_EQ_INT(ierr, 0);
    }
    gmshOptionSetNumber("Mesh.SaveAll", 0, &ierr);
    gmshOptionSetNumber("Mesh.Binary", 0, &ierr);
    gmshModelRemove(&ierr);
}

typedef struct mesh_dump {
    size_t *ntags, nn;
    double *xyz;
    size_t *etags, ne, *conn, nconn;
    int *groups;
    size_t ng;
    char names[512];
} mesh_dump;

/* Nodes sorted by tag would need a sort; Gmsh returns them per entity in a
   stable order for one file, so compare through a tag-indexed table. */
static void dump(const char *path, mesh_dump *d)
{
    int ierr = 0;
    memset(d, 0, sizeof *d);
    gmshModelAdd("check", &ierr);
    gmshOpen(path, &ierr);
    CHECK_EQ_INT(ierr, 0);
    double *p = NULL;
    size_t nc = 0, np = 0;
    gmshModelMeshGetNodes(&d->ntags, &d->nn, &d->xyz, &nc, &p, &np, -1, -1, 0,
                          0, &ierr);
    gmshFree(p);
    gmshModelMeshGetElementsByType(4, &d->etags, &d->ne, &d->conn, &d->nconn,
                                   -1, 0, 1, &ierr);
    gmshModelGetPhysicalGroups(&d->groups, &d->ng, -1, &ierr);
    for (size_t i = 0; i < d->ng; i += 2) {
        char *name = NULL;
        gmshModelGetPhysicalName(d->groups[i], d->groups[i + 1], &name, &ierr);
        strncat(d->names, name, sizeof d->names - strlen(d->names) - 2);
        strcat(d->names, ";");
        gmshFree(name);
    }
    gmshModelRemove(&ierr);
}

static void free_dump(mesh_dump *d)
{
    gmshFree(d->ntags);
    gmshFree(d->xyz);
    gmshFree(d->etags);
    gmshFree(d->conn);
    gmshFree(d->groups);
}

static const double *coord_of(const mesh_dump *d, size_t tag)
{
    for (size_t i = 0; i < d->nn; i++)
        if (d->ntags[i] == tag)
            return d->xyz + 3 * i;
    return NULL;
}

static void header(const char *path, char *buf, size_t size)
{
    FILE *f = fopen(path, "rb");
    buf[0] = 0;
    if (f) {
        char a[64], b[64];
        if (fgets(a, sizeof a, f) && fgets(b, sizeof b, f))
            snprintf(buf, size, "%s%s", a, b);
        fclose(f);
    }
}

static void round_trip(const char *in, const char *out)
{
    getme_doc *doc = NULL;
    getme_doc_options opts;
    getme_doc_options_init(&opts);
    CHECK_EQ_INT(getme_doc_open(&doc, in, &opts), GETME_FORMATS_OK);
    if (!doc || !getme_doc_mesh(doc)) {
        fprintf(stderr, "open %s: %s\n", in, doc ? getme_doc_error(doc) : "");
        getme_doc_close(doc);
        return;
    }
    getme_mesh *mesh = getme_doc_mesh(doc);
    CHECK(getme_mesh_num_fixed(mesh) > 0);
    CHECK_EQ_INT(getme_mesh_distort(mesh, 3, 0.3, 0, 3), GETME_OK);
    CHECK_EQ_INT(getme_doc_write(doc, out), GETME_FORMATS_OK);
    getme_doc_close(doc);

    char h1[160], h2[160];
    header(in, h1, sizeof h1);
    header(out, h2, sizeof h2);
    CHECK(strcmp(h1, h2) == 0);
    mesh_dump a, b;
    dump(in, &a);
    dump(out, &b);
    CHECK_EQ_INT(a.nn, b.nn);
    CHECK_EQ_INT(a.ne, b.ne);
    CHECK(a.ne > 0 && a.ne == b.ne &&
          !memcmp(a.etags, b.etags, a.ne * sizeof(size_t)) &&
          !memcmp(a.conn, b.conn, a.nconn * sizeof(size_t)));
    CHECK(a.ng == b.ng && !memcmp(a.groups, b.groups, a.ng * sizeof(int)));
    CHECK(strcmp(a.names, b.names) == 0);
    CHECK(strstr(a.names, "steel") && strstr(a.names, "alu"));
    size_t moved = 0, missing = 0;
    for (size_t i = 0; i < a.nn; i++) {
        const double *q = coord_of(&b, a.ntags[i]);
        if (!q)
            missing++;
        else
            moved += memcmp(q, a.xyz + 3 * i, 24) != 0;
    }
    CHECK_EQ_INT(missing, 0);
    CHECK(moved > 10);
    printf("%s -> %s: %zu nodes, %zu tets, %zu moved, groups %s\n", in, out,
           a.nn, a.ne, moved, a.names);
    free_dump(&a);
    free_dump(&b);
}

int main(void)
{
    build_files();
    CHECK(strcmp(getme_format_name(getme_format_for("in22a.msh")), "msh") == 0);
    round_trip("in22a.msh", "out22a.msh");
    round_trip("in22b.msh", "out22b.msh");
    round_trip("in41a.msh", "out41a.msh");
    round_trip("in41b.msh", "out41b.msh");

    /* Errors: a missing file and a file that is not MSH. */
    getme_doc *doc = NULL;
    CHECK_EQ_INT(getme_doc_open(&doc, "missing.msh", NULL), GETME_FORMATS_ERR_OPEN);
    getme_doc_close(doc);
    FILE *f = fopen("junk.msh", "w");
    fputs("hello\n", f);
    fclose(f);
    CHECK_EQ_INT(getme_doc_open(&doc, "junk.msh", NULL), GETME_FORMATS_ERR_PARSE);
    CHECK(strstr(getme_doc_error(doc), "junk.msh") != NULL);
    getme_doc_close(doc);
    int ierr = 0;
    gmshFinalize(&ierr);
    return check_summary("plugin_msh_format");
}
