/*
 * highorder.c -- the getme command's line about second-order elements:
 * their quality numbers are the corner elements' (docs/highorder.md), so
 * this line adds what the corners do not show, the worst ratio of the
 * smallest to the largest Jacobian determinant over an element's nodes.
 */
#include "cli.h"

void cli_ho_log(const cli_log *log, getme_doc *doc, const char *when)
{
    getme_mesh *mesh = getme_doc_mesh(doc);
    int32_t n = getme_mesh_num_elements_ho(mesh), e = -1;
    double r = 1.0;
    if (n == 0 || getme_mesh_jacobian_ratio_min(mesh, &r, &e) != GETME_OK ||
        e < 0)
        return;
    cli_info(log, "Second order (%s): %ld elements, worst node Jacobian ratio "
                  "%.4f (element %lld)",
             when, (long)n, r, (long long)getme_doc_element_id(doc, e));
}
