/*
 * test_gmsh_optimize.c -- getme_gmsh_optimize() on a live two-material OCC
 * model: distorted interior, then smoothed; every node on surfaces, curves,
 * points and in the fixed group bit-identical, tags unchanged, q*min up,
 * every tet valid by a mean ratio computed here independently; bad uses
 * fail with the model unchanged.
 */
#include "check.h"
#include "getme_gmsh.h"

#include <gmshc.h>

#include "gmsh_boxes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct snap {
    size_t *tags;
    double *xyz;
    size_t n;
} snap;

static snap take_snap(int dim, int tag)
{
    snap s = {0};
    double *p = NULL;
    size_t nc = 0, np = 0;
    int ierr = 0;
    gmshModelMeshGetNodes(&s.tags, &s.n, &s.xyz, &nc, &p, &np, dim, tag, 0, 0,
                          &ierr);
    gmshFree(p);
    return s;
}

static void free_snap(snap *s)
{
    gmshFree(s->tags);
    gmshFree(s->xyz);
}

static int same_snap(const snap *a, const snap *b)
{
    return a->n == b->n && !memcmp(a->tags, b->tags, a->n * sizeof(size_t)) &&
           !memcmp(a->xyz, b->xyz, 3 * a->n * sizeof(double));
}

/* Nodes of all entities of dim < 3, concatenated in entity order. */
static snap boundary_snap(void)
{
    snap all = {0};
    for (int d = 0; d < 3; d++) {
        int *ents = NULL, ierr = 0;
        size_t ne = 0;
        gmshModelGetEntities(&ents, &ne, d, &ierr);
        for (size_t i = 0; i < ne; i += 2) {
            snap s = take_snap(d, ents[i + 1]);
            all.tags = realloc(all.tags, (all.n + s.n) * sizeof(size_t));
            all.xyz = realloc(all.xyz, 3 * (all.n + s.n) * sizeof(double));
            memcpy(all.tags + all.n, s.tags, s.n * sizeof(size_t));
            memcpy(all.xyz + 3 * all.n, s.xyz, 3 * s.n * sizeof(double));
            all.n += s.n;
            free_snap(&s);
        }
        gmshFree(ents);
    }
    return all;
}

/* Independent tet mean ratio: 12 (3 V)^(2/3) / sum of squared edges. */
static double tet_q(const double *a, const double *b, const double *c,
                    const double *d)
{
    double u[3], v[3], w[3], l2 = 0;
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    double det = u[0] * (v[1] * w[2] - v[2] * w[1]) -
                 u[1] * (v[0] * w[2] - v[2] * w[0]) +
                 u[2] * (v[0] * w[1] - v[1] * w[0]);
    const double *p[4] = {a, b, c, d};
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++)
            for (int k = 0; k < 3; k++)
                l2 += (p[i][k] - p[j][k]) * (p[i][k] - p[j][k]);
    if (det <= 0)
        return 0;
    return 12.0 * pow(3.0 * det / 6.0, 2.0 / 3.0) / l2;
}

/* min and count of invalid tets over the model, from Gmsh's data only. */
static double min_tet_quality(int *invalid)
{
    int *types = NULL, ierr = 0;
    size_t nt = 0, **et = NULL, *etn = NULL, etnn = 0, **nt2 = NULL,
           *ntn = NULL, ntnn = 0;
    gmshModelMeshGetElements(&types, &nt, &et, &etn, &etnn, &nt2, &ntn, &ntnn,
                             3, -1, &ierr);
    double qmin = 1;
    *invalid = 0;
    for (size_t t = 0; t < nt; t++) {
        for (size_t e = 0; types[t] == 4 && e < etn[t]; e++) {
            double x[4][3];
            for (int k = 0; k < 4; k++) {
                double *c = NULL, *p = NULL;
                size_t nc = 0, np = 0;
                gmshModelMeshGetNode(nt2[t][4 * e + k], &c, &nc, &p, &np,
                                     &ierr);
                memcpy(x[k], c, sizeof x[k]);
                gmshFree(c);
                gmshFree(p);
            }
            double q = tet_q(x[0], x[1], x[2], x[3]);
            *invalid += q <= 0;
            qmin = fmin(qmin, q);
        }
        gmshFree(et[t]);
        gmshFree(nt2[t]);
    }
    gmshFree(types);
    gmshFree(et);
    gmshFree(etn);
    gmshFree(nt2);
    gmshFree(ntn);
    return qmin;
}

static size_t *element_tags(size_t *n)
{
    size_t *tags = NULL, *ntags = NULL, nn = 0;
    int ierr = 0;
    gmshModelMeshGetElementsByType(4, &tags, n, &ntags, &nn, -1, 0, 1, &ierr);
    gmshFree(ntags);
    return tags;
}

static void build_model(void)
{
    int ierr = 0, out_n = 0;
    (void)out_n;
    two_material_boxes("two_materials", 0);
    int *faces = NULL;
    size_t nf = 0;
    gmshModelGetEntitiesInBoundingBox(-0.01, -0.01, -0.01, 0.01, 1.01, 1.01,
                                      &faces, &nf, 2, &ierr);
    gmshModelAddPhysicalGroup(2, faces + 1, 1, 10, &ierr);
    gmshModelSetPhysicalName(2, 10, "clamp", &ierr);
    gmshFree(faces);
    gmshOptionSetNumber("Mesh.MeshSizeMax", 0.12, &ierr);
    gmshModelMeshGenerate(3, &ierr);
}

/* Distort the interior with libgetme's validity-preserving random moves. */
static void distort_model(void)
{
    getme_gmsh_model *m = NULL;
    char msg[512];
    CHECK_EQ_INT(getme_gmsh_model_read(&m, NULL, 0, NULL, msg, sizeof msg),
                 GETME_OK);
    getme_mesh *mesh = getme_gmsh_model_mesh(m);
    CHECK_EQ_INT(getme_mesh_distort(mesh, 7, 0.45, 0, 8), GETME_OK);
    int32_t moved = 0;
    CHECK_EQ_INT(getme_gmsh_model_apply(m, getme_mesh_coords(mesh), &moved,
                                        msg, sizeof msg),
                 GETME_OK);
    CHECK(moved > 100);
    getme_gmsh_model_free(m);
}

static void test_optimize(void)
{
    distort_model();
    snap bnd = boundary_snap();
    size_t *clamp = NULL, nclamp = 0, nc = 0;
    double *clamp_xyz = NULL;
    int ierr = 0, inv = 0;
    gmshModelMeshGetNodesForPhysicalGroup(2, 10, &clamp, &nclamp, &clamp_xyz,
                                          &nc, &ierr);
    snap all0 = take_snap(-1, -1);
    size_t ne0 = 0, *et0 = element_tags(&ne0);
    double q0 = min_tet_quality(&inv);
    CHECK_EQ_INT(inv, 0);

    getme_gmsh_options *opt = getme_gmsh_options_new();
    CHECK_EQ_INT(getme_gmsh_options_add_fixed_group(opt, "clamp"), GETME_OK);
    CHECK_EQ_INT(getme_gmsh_options_set(opt, "log", 1), GETME_OK);
    getme_gmsh_report rep;
    CHECK_EQ_INT(getme_gmsh_optimize(0, NULL, 0, opt, &rep), GETME_OK);
    CHECK_EQ_INT(rep.dim, 3);
    CHECK_EQ_INT(rep.num_entities, 2);
    CHECK(rep.num_moved > 0);
    CHECK(rep.after.q_min_star > rep.before.q_min_star + 0.05);
    CHECK(rep.after.q_mean > rep.before.q_mean);
    CHECK_NEAR(getme_gmsh_report_value(&rep, "after_q_mean"),
               rep.after.q_mean, 0);

    snap bnd1 = boundary_snap();
    CHECK(same_snap(&bnd, &bnd1)); /* surfaces, curves, points untouched */
    snap all1 = take_snap(-1, -1);
    CHECK_EQ_INT(all1.n, all0.n);
    CHECK(!memcmp(all0.tags, all1.tags, all0.n * sizeof(size_t)));
    size_t moved = 0;
    for (size_t i = 0; i < all0.n; i++)
        moved += memcmp(all0.xyz + 3 * i, all1.xyz + 3 * i, 24) != 0;
    CHECK_EQ_INT(moved, rep.num_moved);
    for (size_t i = 0; i < nclamp; i++) {
        double *c = NULL, *p = NULL;
        size_t n3 = 0, np = 0;
        gmshModelMeshGetNode(clamp[i], &c, &n3, &p, &np, &ierr);
        CHECK(!memcmp(c, clamp_xyz + 3 * i, 24));
        gmshFree(c);
        gmshFree(p);
    }
    size_t ne1 = 0, *et1 = element_tags(&ne1);
    CHECK(ne0 == ne1 && !memcmp(et0, et1, ne0 * sizeof(size_t)));
    double q1 = min_tet_quality(&inv);
    CHECK_EQ_INT(inv, 0);
    CHECK(q1 > q0);
    CHECK_NEAR(q1, rep.after.q_min, 1e-9);
    printf("two-material box: q*min %.4f -> %.4f, qmean %.4f -> %.4f, "
           "%d iterations, %d nodes moved\n",
           rep.before.q_min_star, rep.after.q_min_star, rep.before.q_mean,
           rep.after.q_mean, rep.result.iterations, rep.num_moved);
    gmshOptionSetNumber("Mesh.MshFileVersion", 4.1, &ierr);
    gmshWrite("plugin_c_out.msh", &ierr);
    CHECK_EQ_INT(ierr, 0);
    gmshWrite("plugin_c_out.inp", &ierr);
    CHECK_EQ_INT(ierr, 0);
    getme_gmsh_options_free(opt);
    free_snap(&bnd);
    free_snap(&bnd1);
    free_snap(&all0);
    free_snap(&all1);
    gmshFree(et0);
    gmshFree(et1);
    gmshFree(clamp);
    gmshFree(clamp_xyz);
}

/* Every bad use: nonzero status, a message, the model unchanged. */
/* A refused call leaves the model as it was; off (may be NULL) names an
   option set to 0 for the call. */
static void expect_refused_with(const int *dt, size_t n, getme_status want,
                                const char *words, const char *off)
{
    snap a = take_snap(-1, -1);
    getme_gmsh_report rep;
    getme_gmsh_options *opt = getme_gmsh_options_new();
    getme_gmsh_options_set(opt, "log", 0);
    if (off)
        CHECK_EQ_INT(getme_gmsh_options_set(opt, off, 0), GETME_OK);
    getme_status st = getme_gmsh_optimize(0, dt, n, opt, &rep);
    CHECK_EQ_INT(st, want);
    CHECK(strstr(rep.message, words) != NULL);
    if (!strstr(rep.message, words))
        fprintf(stderr, "  message was: %s\n", rep.message);
    snap b = take_snap(-1, -1);
    CHECK(same_snap(&a, &b));
    free_snap(&a);
    free_snap(&b);
    getme_gmsh_options_free(opt);
}

static void expect_refused(const int *dt, size_t n, getme_status want,
                           const char *words)
{
    expect_refused_with(dt, n, want, words, NULL);
}

/* Inverted tets: untangled and smoothed by default; refused with
   untangle = 0; named by their tags when every node is fixed. */
static void test_untangle(void)
{
    int ierr = 0;
    snap all = take_snap(-1, -1);
    snap vol = take_snap(3, 1);
    size_t tag = vol.tags[0];
    double far[3] = {vol.xyz[0] + 5, vol.xyz[1], vol.xyz[2]};
    gmshModelMeshSetNode(tag, far, 3, NULL, 0, &ierr);
    expect_refused_with(NULL, 0, GETME_ERR_INVALID_MESH, "invalid",
                        "untangle");
    int invalid = 0;
    min_tet_quality(&invalid);
    CHECK(invalid > 0);
    snap bnd0 = boundary_snap();
    getme_gmsh_report rep;
    getme_gmsh_options *opt = getme_gmsh_options_new();
    getme_gmsh_options_set(opt, "log", 1);
    CHECK_EQ_INT(getme_gmsh_optimize(0, NULL, 0, opt, &rep), GETME_OK);
    CHECK_EQ_INT(rep.untangle.num_invalid_before, invalid);
    CHECK_EQ_INT(rep.untangle.num_invalid_after, 0);
    CHECK(rep.untangle.sweeps > 0);
    CHECK_EQ_INT(getme_gmsh_report_value(&rep, "untangle_invalid_before"),
                 invalid);
    CHECK_EQ_INT(rep.result.num_invalid_initial, invalid);
    CHECK_EQ_INT(rep.after.num_invalid, 0);
    CHECK(min_tet_quality(&invalid) > 0.1);
    CHECK_EQ_INT(invalid, 0);
    snap bnd1 = boundary_snap();
    CHECK(same_snap(&bnd0, &bnd1));
    free_snap(&bnd0);
    free_snap(&bnd1);

    /* A tet whose 4 nodes are all fixed (classified on the boundary),
       turned inside out by mirroring one node through the opposite face:
       named by its tag; the model is unchanged, except with
       allow_invalid = 1 (partly untangled coordinates). */
    for (size_t i = 0; i < all.n; i++)
        gmshModelMeshSetNode(all.tags[i], all.xyz + 3 * i, 3, NULL, 0, &ierr);
    snap bnd = boundary_snap();
    size_t *etags = NULL, etn = 0, *enodes = NULL, enn = 0;
    gmshModelMeshGetElementsByType(4, &etags, &etn, &enodes, &enn, -1, 0, 1,
                                   &ierr);
    size_t stuck = 0;
    for (size_t e = 0; e < etn && !stuck; e++) {
        int on = 0;
        for (int v = 0; v < 4; v++)
            for (size_t k = 0; k < bnd.n; k++)
                on += bnd.tags[k] == enodes[4 * e + v];
        if (on < 4)
            continue;
        stuck = etags[e];
        double x[4][3], pc[3], pd;
        for (int v = 0; v < 4; v++) {
            double *c = NULL, *pp = NULL;
            size_t nc = 0, np = 0;
            gmshModelMeshGetNode(enodes[4 * e + v], &c, &nc, &pp, &np, &ierr);
            memcpy(x[v], c, sizeof x[v]);
            gmshFree(c);
            gmshFree(pp);
        }
        /* n = (x1 - x0) x (x2 - x0); x3 -> x3 - 2 ((x3 - x0).n / n.n) n */
        double u[3], w[3], nrm[3];
        for (int d = 0; d < 3; d++)
            u[d] = x[1][d] - x[0][d], w[d] = x[2][d] - x[0][d];
        nrm[0] = u[1] * w[2] - u[2] * w[1];
        nrm[1] = u[2] * w[0] - u[0] * w[2];
        nrm[2] = u[0] * w[1] - u[1] * w[0];
        pd = 0.0;
        double nn = 0.0;
        for (int d = 0; d < 3; d++)
            pd += (x[3][d] - x[0][d]) * nrm[d], nn += nrm[d] * nrm[d];
        for (int d = 0; d < 3; d++)
            pc[d] = x[3][d] - 2.0 * pd / nn * nrm[d];
        gmshModelMeshSetNode(enodes[4 * e + 3], pc, 3, NULL, 0, &ierr);
    }
    gmshFree(etags);
    gmshFree(enodes);
    free_snap(&bnd);
    CHECK(stuck != 0);
    char want[64];
    snprintf(want, sizeof want, "tet %zu ", stuck);
    expect_refused(NULL, 0, GETME_ERR_INVALID_MESH, "could not be untangled");
    expect_refused(NULL, 0, GETME_ERR_INVALID_MESH, want);
    /* plus the free node pushed out again: its tets untangle, so the
       partly untangled coordinates differ from the input */
    gmshModelMeshSetNode(tag, far, 3, NULL, 0, &ierr);
    snap before = take_snap(-1, -1);
    getme_gmsh_options_set(opt, "log", 0);
    CHECK_EQ_INT(getme_gmsh_options_set(opt, "allow_invalid", 1), GETME_OK);
    CHECK_EQ_INT(getme_gmsh_optimize(0, NULL, 0, opt, &rep),
                 GETME_ERR_INVALID_MESH);
    CHECK(rep.untangle.num_invalid_after >= 1);
    CHECK(rep.untangle.num_stuck >= 1);
    CHECK(rep.num_moved > 0);
    snap after = take_snap(-1, -1);
    CHECK(!same_snap(&before, &after));
    free_snap(&before);
    free_snap(&after);
    for (size_t i = 0; i < all.n; i++)
        gmshModelMeshSetNode(all.tags[i], all.xyz + 3 * i, 3, NULL, 0, &ierr);
    free_snap(&all);
    free_snap(&vol);
    getme_gmsh_options_free(opt);
}

static void test_bad_uses(void)
{
    int ierr = 0;
    int missing[2] = {3, 99}, curve[2] = {1, 1};
    expect_refused(missing, 2, GETME_ERR_ARGUMENT, "does not exist");
    expect_refused(curve, 2, GETME_ERR_ARGUMENT, "only volumes");
    getme_gmsh_options *opt = getme_gmsh_options_new();
    getme_gmsh_options_add_fixed_group(opt, "nope");
    getme_gmsh_report rep;
    getme_gmsh_options_set(opt, "log", 0);
    CHECK_EQ_INT(getme_gmsh_optimize(0, NULL, 0, opt, &rep),
                 GETME_ERR_ARGUMENT);
    CHECK(strstr(rep.message, "\"clamp\" (2:10)") != NULL);
    getme_gmsh_options_free(opt);

    gmshModelMeshSetOrder(3, &ierr); /* order 2 is smoothed (tests/highorder) */
    expect_refused(NULL, 0, GETME_ERR_TOPOLOGY, "order 3");
    gmshModelMeshSetOrder(1, &ierr);

    /* An entity without elements: a new volume added after meshing. */
    int b = gmshModelOccAddBox(5, 5, 5, 1, 1, 1, -1, &ierr);
    gmshModelOccSynchronize(&ierr);
    int empty[2] = {3, b};
    expect_refused(empty, 2, GETME_ERR_STATE, "no mesh elements");

    /* A model without a mesh. */
    gmshModelAdd("no_mesh", &ierr);
    gmshModelOccAddSphere(0, 0, 0, 1, -1, -1.5707963267948966, 1.5707963267948966, 6.283185307179586,
                          &ierr);
    gmshModelOccSynchronize(&ierr);
    expect_refused(NULL, 0, GETME_ERR_STATE, "No volume or surface mesh");
}

int main(void)
{
    getme_gmsh_report rep;
    /* Before gmshInitialize(): refused, and nothing printed by Gmsh. */
    CHECK_EQ_INT(getme_gmsh_optimize(0, NULL, 0, NULL, &rep), GETME_ERR_STATE);
    CHECK(strstr(rep.message, "not initialized") != NULL);
    int ierr = 0;
    gmshInitialize(0, NULL, 0, &ierr);
    gmshOptionSetNumber("General.Terminal", 1, &ierr);
    build_model();
    test_optimize();
    test_untangle();
    test_bad_uses();
    gmshFinalize(&ierr);
    return check_summary("plugin_gmsh_optimize");
}
